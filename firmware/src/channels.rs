//! The channels between the firmware's tasks that more than one module
//! sends on: the telemetry queue to the host, the commands from it, the
//! watchdog's requests ([`crate::tasks`] draws them; the checkpoint the
//! host keeps, [`crate::host_kept`], uses them too).

use embassy_sync::blocking_mutex::raw::CriticalSectionRawMutex;
use embassy_sync::channel::Channel;
use embassy_sync::signal::Signal;
use pada_core::wire::{ToChip, ToHost};

pub(crate) type Mutex = CriticalSectionRawMutex;

/// A message for the host, and how many were dropped before it (the
/// telemetry task skips that many sequence numbers, so the host sees the
/// gap).
pub struct Outgoing {
    pub(crate) msg: ToHost,
    pub(crate) skipped: u32,
}

/// What the watchdog task is told.
#[derive(Clone, Copy)]
pub enum WatchdogRequest {
    /// The control loop completed a period.
    Alive,
    /// A flash erase is about to stall the CPU: long timeout (`true`) or back.
    Extend(bool),
}

/// Anyone → telemetry.
pub static TO_HOST: Channel<Mutex, Outgoing, 16> = Channel::new();
/// Telemetry → control: (sequence number, command).
pub static FROM_HOST: Channel<Mutex, (u32, ToChip), 4> = Channel::new();
/// Control → watchdog.
pub static WATCHDOG: Channel<Mutex, WatchdogRequest, 2> = Channel::new();
/// Watchdog → control: the last `Extend` is in force.
pub static WATCHDOG_DONE: Signal<Mutex, ()> = Signal::new();

/// Sends a message the host must get (waits for room).
pub async fn send_reliable(msg: ToHost) {
    TO_HOST.send(Outgoing { msg, skipped: 0 }).await;
}

/// Switches the watchdog to its long timeout (`true`, for an operation
/// that stalls the loop: flash, a fresh learner, a checkpoint streamed to
/// the host) or back; the long one is in force when this returns.
pub async fn set_long_watchdog(long: bool) {
    if long {
        WATCHDOG_DONE.reset();
        WATCHDOG.send(WatchdogRequest::Extend(true)).await;
        WATCHDOG_DONE.wait().await;
    } else {
        WATCHDOG.send(WatchdogRequest::Extend(false)).await;
    }
}
