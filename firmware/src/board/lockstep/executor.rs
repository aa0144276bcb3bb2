//! The lock-step time driver and the executor: embassy's timers run on
//! the host's clock, and when no task is woken the idle loop runs the
//! lock-step exchange (answers a forecast here, skips to a timer, or
//! reports and waits for the host's `Advance`).

use super::link::{link, wait_for_advance, Inbox};
use super::panic::exit_failure;
use core::cell::RefCell;
use core::sync::atomic::{AtomicBool, Ordering};
use core::task::Waker;
use critical_section::Mutex;
use embassy_executor::{raw, Spawner};
use embassy_time_queue_utils::Queue;
use heapless::Deque;
use pada_core::wire::FrameDecoder;
use pada_firmware::sil::FromBoard;

static QUEUE: Mutex<RefCell<Queue>> = Mutex::new(RefCell::new(Queue::new()));
/// Set by the executor's pender: a task was woken.
static PENDED: AtomicBool = AtomicBool::new(false);
/// Set by `Board::init` once the link is open.
pub(super) static LINK_OPEN: AtomicBool = AtomicBool::new(false);

struct LockstepDriver;

impl embassy_time_driver::Driver for LockstepDriver {
    fn now(&self) -> u64 {
        link(|l| l.now_us)
    }

    fn schedule_wake(&self, at: u64, waker: &Waker) {
        // Expired entries are woken by the idle loop before it reports the
        // next expiry, so nothing more is needed here.
        critical_section::with(|cs| {
            QUEUE.borrow_ref_mut(cs).schedule_wake(at, waker);
        });
    }
}

embassy_time_driver::time_driver_impl!(static DRIVER: LockstepDriver = LockstepDriver);

#[unsafe(export_name = "__pender")]
fn __pender(_context: *mut ()) {
    PENDED.store(true, Ordering::SeqCst);
}

/// Wakes the timers that expired by `now`; the next expiry.
fn expire(now: u64) -> u64 {
    critical_section::with(|cs| QUEUE.borrow_ref_mut(cs).next_expiration(now))
}

/// The executor: polls while tasks are woken; when none is, runs the
/// lock-step exchange ([`idle`]).
pub struct Executor {
    inner: raw::Executor,
}

impl Executor {
    /// An executor (the context pointer is unused: one executor, one pender).
    #[allow(clippy::new_without_default)]
    pub fn new() -> Self {
        Executor { inner: raw::Executor::new(core::ptr::null_mut()) }
    }

    /// Spawns the tasks `init` spawns and runs forever.
    pub fn run(&'static mut self, init: impl FnOnce(Spawner)) -> ! {
        init(self.inner.spawner());
        let mut inbox = Inbox { decoder: FrameDecoder::new(), pending: Deque::new() };
        loop {
            PENDED.store(false, Ordering::SeqCst);
            // SAFETY: not reentrant: `poll` is called only here, and the
            // pender only sets a flag.
            unsafe { self.inner.poll() };
            if !PENDED.load(Ordering::SeqCst) {
                // `Board::init` runs in the main task's first poll.
                if !LINK_OPEN.load(Ordering::SeqCst) {
                    defmt::error!("idle before Board::init");
                    exit_failure()
                }
                idle(&mut inbox);
            }
        }
    }
}

/// Nothing to run: wake expired timers; if none, answer a forecast
/// request here or tell the host until when the board is idle and wait
/// for its `Advance`.
fn idle(inbox: &mut Inbox) {
    link(|l| l.pause());
    let until = expire(link(|l| l.now_us));
    if PENDED.load(Ordering::SeqCst) {
        // A timer had expired: its task runs first.
        link(|l| l.resume());
        return;
    }
    if link(|l| l.answer_locally(until) || l.skip_to_timer(until)) {
        expire(link(|l| l.now_us));
        link(|l| l.resume());
        return;
    }
    link(|l| {
        l.report_output();
        let idle = FromBoard::Idle { now_us: l.now_us, until_us: until, instructions: l.busy };
        l.queue(&idle);
        l.flush_writes();
    });
    wait_for_advance(inbox);
    expire(link(|l| l.now_us));
    link(|l| l.resume());
}
