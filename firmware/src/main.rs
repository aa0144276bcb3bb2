//! pada firmware: the pada-core learner on an STM32F4, driving Dynamixel
//! servos (Protocol 1.0 or 2.0, as the robot's definition names them),
//! without breaking the robot while it learns.
//!
//! Boot: clocks, pins and the table's memory ([`board`]: the F429's SDRAM is
//! started and checked here), the weight table where the board's learner
//! profile puts it ([`table`]), the controller for the robot chosen at
//! build time, the checkpoint (weights and learner state) from flash if its
//! configuration matches (or, for a table that fits no flash, from the
//! host: [`host_kept`]), a fault if the watchdog reset the chip, then the
//! tasks of [`tasks`]. Logs go out over RTT (defmt), telemetry over the
//! telemetry USART (pada_core::wire frames).
//!
//! The servo-bus task starts first and switches the servos' torque off
//! before anything slow. If the table's memory fails its check, the board
//! tells the host (`Warning::Text`) and does nothing else: a learner on
//! broken memory would learn garbage.
#![no_std]
#![no_main]

mod board;
mod channels;
mod host_kept;
mod table;
mod tasks;

use core::fmt::Write as _;
use defmt::{info, unwrap};
use embassy_executor::Spawner;
use static_cell::StaticCell;
use pada_core::checkpoint::CheckpointStore;
use pada_core::policy::PolicyKind;
use pada_core::weights::WeightStore;
use pada_core::wire::{self, ToHost};
use table::{Ctl, PROFILE, ROBOT};

/// The policy at boot; the host chooses another with `SetPolicy`.
const BOOT_POLICY: PolicyKind = PolicyKind::Sarsa;

// The real boards run embassy's thread-mode executor; the emulated boards
// their own, which advances the lock-step clock when nothing is left to run.
#[cfg_attr(not(emulated), embassy_executor::main)]
#[cfg_attr(
    emulated,
    embassy_executor::main(entry = "cortex_m_rt::entry", executor = "crate::board::Executor")
)]
async fn main(spawner: Spawner) {
    let board = board::Board::init(PROFILE.memory);
    info!(
        "pada firmware {}: {} on board profile {}",
        env!("CARGO_PKG_VERSION"),
        ROBOT.name,
        PROFILE.board.name()
    );

    // Torque off before anything slow: whatever the servos did before this
    // boot (a watchdog reset leaves them turning at their last Moving
    // Speed), they stop before the weight table is filled — about 0.7 s on
    // the F429's 8 MiB table.
    spawner.spawn(unwrap!(tasks::servo_bus(board.servo_port, ROBOT)));
    tasks::SERVOS_OFF.wait().await;

    let table_memory = match board.table_memory {
        Ok(memory) => memory,
        Err(fault) => {
            defmt::error!(
                "the weight table's memory ({}) failed its check: wrote {=u32:#x} at {=u32:#x}, read {=u32:#x}; not starting",
                PROFILE.memory.name(),
                fault.wrote,
                fault.address,
                fault.read
            );
            spawner.spawn(unwrap!(tasks::telemetry_tx(board.telemetry_tx)));
            let mut text = heapless::String::new();
            // Fits MAX_TEXT (56 characters); cut short if it did not.
            let _ = write!(text, "table memory fault @{:08x} wrote {:08x} read {:08x}", fault.address, fault.wrote, fault.read);
            channels::send_reliable(ToHost::Warning(wire::Warning::Text(text))).await;
            loop {
                core::future::pending::<()>().await;
            }
        }
    };

    // DEFAULT_SEED on a real board; the emulated boards take the run's.
    // In a static, built in place (Controller::new_in says why).
    static CTL: StaticCell<Ctl> = StaticCell::new();
    let ctl: &'static mut Ctl = match Ctl::new_in(CTL.uninit(), table::this_robot(), PROFILE, BOOT_POLICY, table::take(table_memory), board.seed) {
        Ok(ctl) => ctl,
        // The profiles are constants checked by the host tests.
        Err(e) => defmt::panic!("controller configuration: {}", defmt::Debug2Format(&e)),
    };
    info!(
        "table: {=usize} entries ({=usize} bytes, {} weights, {=usize}-byte tags) in {}; configuration hash {=u32:x}",
        ctl.weights().len(),
        ctl.weights().len() * PROFILE.entry_bytes(),
        PROFILE.format,
        PROFILE.tag_bytes,
        PROFILE.memory.name(),
        ctl.config_hash()
    );

    channels::send_reliable(ToHost::Hello(ctl.hello())).await;
    // The telemetry link runs from here: a board whose table fits no flash
    // asks the host for its checkpoint.
    spawner.spawn(unwrap!(tasks::telemetry_tx(board.telemetry_tx)));
    spawner.spawn(unwrap!(tasks::telemetry_rx(board.telemetry_rx)));
    if ctl.host_keeps_checkpoint(board.flash.capacity()) {
        // The F429's LEO table (8 MiB) fits no flash sector: the host keeps
        // its checkpoint (host_kept).
        info!(
            "checkpoints kept by the host: one is {=usize} bytes, a flash slot holds {=usize}",
            ctl.checkpoint_bytes(),
            board.flash.capacity()
        );
        host_kept::restore_from_host(ctl).await;
    } else {
        tasks::boot_checkpoint(ctl, &board.flash).await;
    }
    // After the checkpoint, which may restore another policy or the switch.
    channels::send_reliable(ToHost::Policy(ctl.policy_report())).await;
    if board.watchdog_reset {
        let t = ctl.watchdog_reset();
        defmt::warn!("reset by the independent watchdog: Fault until the host clears it");
        channels::send_reliable(ToHost::State(wire::StateChange { step: 0, from: t.from, to: t.to })).await;
        if let Some(cause) = t.entered_fault() {
            channels::send_reliable(ToHost::Fault(wire::Fault { step: 0, time_ms: 0, cause })).await;
        }
    }

    spawner.spawn(unwrap!(tasks::watchdog(board.watchdog, board.led)));
    spawner.spawn(unwrap!(tasks::control(tasks::ControlLoop {
        ctl,
        sensors: board.sensors,
        flash: board.flash,
        cycles: board.cycles,
        cpu_hz: board::CPU_HZ,
    })));
}
