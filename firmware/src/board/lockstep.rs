//! The emulated boards' common layer: the lock-step clock, the servo bus,
//! telemetry and the checkpoint slots, all carried to the host over one
//! semihosting channel ([`pada_firmware::sil`]), for the software-in-the-loop
//! run (`pada sil`). The machine underneath — QEMU's `netduinoplus2`
//! ([`super::qemu`], an STM32F405) or `mps2-an386` ([`super::mps2`], a
//! Cortex-M4 with 16 MB of PSRAM) — adds only its instruction counter and
//! its clock rate.
//!
//! The same type names as the real board ([`hw`](super)), implementing the
//! same `pada_firmware::io` traits, so `tasks.rs` and everything above it
//! (control loop, agent, fatigue counter, codec, telemetry, safety machine)
//! are the real board's code. What differs, and why:
//!
//! | here | real board | why |
//! |---|---|---|
//! | servo bus and telemetry bytes in clock frames over semihosting | USARTs with DMA | QEMU's serial models move one received byte per main-loop turn (~60 µs) and one system call per sent byte; no RCC/PWR either, so `embassy_stm32::init` never returns |
//! | lock-step time driver: the host advances the clock | TIM2/TIM5 at 1 MHz | deterministic runs, faster than real time |
//! | an executor loop that reports when it is idle | thread-mode executor (WFE/SEV) | the idle moment is when the clock may advance |
//! | encoder and foot switches: device [`SENSOR_ID`] on the servo bus | timer in encoder mode, GPIO | QEMU emulates neither |
//! | cycle counter: lock-step time × the real chip's clock + instructions executed (`-icount`) | DWT CYCCNT | QEMU has no DWT; instructions stand in for cycles |
//! | checkpoints in a file on the host, in slots of one flash sector | flash sectors | QEMU's flash is read-only |
//! | the learner's seed from the host ([`ToBoard::Configure`]) | `DEFAULT_SEED` | a run chooses its seed, as `pada run --seed` does |
//! | mps2-an386: the CMSDK watchdog (`cmsdk_watchdog.rs`); netduinoplus2: none (QEMU models none) | IWDG | a hung loop spins, and QEMU's clock counts its instructions |
//! | defmt and panics over semihosting, exit code 1 on a panic | RTT, probe-rs | no debug probe |
//!
//! Forecasts ([`pada_firmware::sil`], "Forecasts"): a bus request that is
//! byte for byte the host's forecast, sent at its instant with nothing else
//! written since the last report, is answered here without an exchange;
//! and while nothing but such requests is unreported, a timer that expires
//! before the host's next event fires without one.

use super::machine;
use super::{MemoryFault, TableMemory};
use crate::table::PROFILE;
use core::cell::RefCell;
use core::sync::atomic::{AtomicBool, Ordering};
use core::task::{Poll, Waker};
use critical_section::Mutex;
use embassy_executor::{raw, Spawner};
use embassy_time::{with_deadline, Instant};
use embassy_time_queue_utils::Queue;
use heapless::{Deque, Vec};
use pada_core::checkpoint::{self, CheckpointStore};
use pada_core::wire::{encode_frame, FrameDecoder};
use pada_firmware::bus::{BusConfig, ServoBus};
use pada_firmware::io::{self, PortError};
use pada_firmware::sil::{self, Channel, FromBoard, ToBoard, CHUNK_LEN, CLOCK_FRAME_LEN, SENSOR_ID};
// defmt over semihosting (QEMU writes it to its standard output).
use defmt_semihosting as _;

pub use machine::CPU_HZ;

/// Cycles per microsecond of lock-step time.
const CYCLES_PER_US: u64 = CPU_HZ as u64 / 1_000_000;

/// Bytes of the servo bus's receive buffer.
const SERVO_RX_BUF: usize = 256;
/// Bytes of the command receive buffer.
const TELEMETRY_RX_BUF: usize = 512;
/// Bus writes buffered until the next report (a LEO period writes 8 reads,
/// a SYNC_WRITE and a torque broadcast).
const BUS_CHUNKS: usize = 16;
/// Telemetry bytes buffered until the next report (a period's frames; the
/// weights of a `ReadWeights` go four chunks per period).
const TELEMETRY_OUT: usize = 2048;
/// Clock frames buffered for one semihosting write.
const WRITE_BUF: usize = 4096;
/// Forecasts held at once (LEO's period reads eight).
const FORECASTS: usize = 16;

// ---------------------------------------------------------------------------
// Semihosting
// ---------------------------------------------------------------------------

/// Semihosting operations (ARM's semihosting specification).
mod semi {
    use cortex_m_semihosting::{nr, syscall};

    /// Opens `path` (NUL-terminated) with an fopen mode of `nr::open`.
    pub fn open(path: &[u8], mode: usize) -> Option<usize> {
        // SAFETY: the path is NUL-terminated and outlives the call; the
        // length excludes the NUL, as SYS_OPEN wants.
        let h = unsafe { syscall!(OPEN, path.as_ptr(), mode, path.len() - 1) };
        (h as isize >= 0).then_some(h)
    }

    pub fn seek(h: usize, pos: usize) -> bool {
        // SAFETY: plain integers.
        unsafe { syscall!(SEEK, h, pos) == 0 }
    }

    /// Reads all of `buf`; false if the file ended or the host failed.
    pub fn read(h: usize, buf: &mut [u8]) -> bool {
        // SAFETY: the buffer is valid for writes of its length.
        unsafe { syscall!(READ, h, buf.as_mut_ptr(), buf.len()) == 0 }
    }

    pub fn write(h: usize, data: &[u8]) -> bool {
        // SAFETY: the data is valid for reads of its length.
        unsafe { syscall!(WRITE, h, data.as_ptr(), data.len()) == 0 }
    }

    pub fn len(h: usize) -> Option<usize> {
        // SAFETY: a plain integer.
        let n = unsafe { syscall!(FLEN, h) };
        (n as isize >= 0).then_some(n)
    }

    /// Reads what is there (blocking until something is), up to
    /// `buf.len()` bytes; 0 at the end of the file or on an error.
    pub fn read_some(h: usize, buf: &mut [u8]) -> usize {
        // SAFETY: the buffer is valid for writes of its length.
        let left = unsafe { syscall!(READ, h, buf.as_mut_ptr(), buf.len()) };
        buf.len().saturating_sub(left)
    }

    pub const READ: usize = nr::open::R_BINARY;
    pub const WRITE: usize = nr::open::W_TRUNC_BINARY;
    pub const READ_WRITE: usize = nr::open::RW_BINARY;
    pub const CREATE: usize = nr::open::RW_TRUNC_BINARY;
}

/// FIFO the board writes [`FromBoard`] frames to.
const CLOCK_OUT: &[u8] = b"clock-from-board\0";
const _: () = assert!(CLOCK_OUT.len() == sil::CLOCK_FROM_BOARD.len() + 1);
/// FIFO the board reads [`ToBoard`] frames from.
const CLOCK_IN: &[u8] = b"clock-to-board\0";
const _: () = assert!(CLOCK_IN.len() == sil::CLOCK_TO_BOARD.len() + 1);

// ---------------------------------------------------------------------------
// The link: clock frames both ways, the bytes of both streams
// ---------------------------------------------------------------------------

/// A servo-bus write not yet reported.
struct BusChunk {
    at_us: u64,
    bytes: Vec<u8, CHUNK_LEN>,
    /// Its answer came from a forecast.
    answered: bool,
}

/// A forecast of the host ([`ToBoard::Forecast`]).
struct Forecast {
    request_at_us: u64,
    request: Vec<u8, { sil::MAX_REQUEST }>,
    reply_at_us: u64,
    reply: Vec<u8, { sil::MAX_REPLY }>,
}

/// A receive buffer and the task waiting on it.
struct Rx<const N: usize> {
    bytes: Deque<u8, N>,
    /// Bytes lost because the buffer was full.
    overflows: u32,
    waker: Option<Waker>,
}

impl<const N: usize> Rx<N> {
    const fn new() -> Self {
        Rx { bytes: Deque::new(), overflows: 0, waker: None }
    }

    fn push(&mut self, bytes: &[u8]) {
        for &b in bytes {
            if self.bytes.push_back(b).is_err() {
                self.overflows = self.overflows.wrapping_add(1);
            }
        }
    }

    fn take(&mut self, buf: &mut [u8]) -> usize {
        let mut n = 0;
        while n < buf.len() {
            match self.bytes.pop_front() {
                Some(b) => {
                    buf[n] = b;
                    n += 1;
                }
                None => break,
            }
        }
        n
    }

    fn wake(&mut self) {
        if !self.bytes.is_empty() {
            if let Some(w) = self.waker.take() {
                w.wake();
            }
        }
    }

    /// Ready when bytes are there, else registers `waker`.
    fn poll(&mut self, waker: &Waker) -> Poll<()> {
        if self.bytes.is_empty() {
            self.waker = Some(waker.clone());
            Poll::Pending
        } else {
            Poll::Ready(())
        }
    }
}

/// Everything the emulated board shares between its tasks and its idle
/// loop.
struct Link {
    /// The semihosting handles of the two FIFOs.
    to_host: usize,
    from_host: usize,
    /// Current time \[µs\], set only by the host's `Advance` or a forecast.
    now_us: u64,
    /// The host's next event ([`ToBoard::Advance::horizon_us`]).
    horizon_us: u64,
    /// Instructions executed outside the transport, up to `mark`.
    busy: u64,
    /// The instruction counter when `busy` was last brought up to date.
    mark: u32,
    /// Sequence number of the next frame to the host.
    seq: u32,
    bus_out: Vec<BusChunk, BUS_CHUNKS>,
    telemetry_out: Vec<u8, TELEMETRY_OUT>,
    bus_rx: Rx<SERVO_RX_BUF>,
    telemetry_rx: Rx<TELEMETRY_RX_BUF>,
    forecasts: Deque<Forecast, FORECASTS>,
    /// The front forecast's request has been sent; its answer is due.
    matched: bool,
    /// Frames not yet written to the host.
    write: Vec<u8, WRITE_BUF>,
}

// All zero, so in .bss (the handles are set by `Board::init` before use).
static LINK: Mutex<RefCell<Link>> = Mutex::new(RefCell::new(Link {
    to_host: 0,
    from_host: 0,
    now_us: 0,
    horizon_us: 0,
    busy: 0,
    mark: 0,
    seq: 0,
    bus_out: Vec::new(),
    telemetry_out: Vec::new(),
    bus_rx: Rx::new(),
    telemetry_rx: Rx::new(),
    forecasts: Deque::new(),
    matched: false,
    write: Vec::new(),
}));

fn link<R>(f: impl FnOnce(&mut Link) -> R) -> R {
    critical_section::with(|cs| f(&mut LINK.borrow_ref_mut(cs)))
}

impl Link {
    /// Brings `busy` up to date: what ran since `mark` was the firmware's.
    fn pause(&mut self) {
        let t = machine::counter();
        self.busy += t.wrapping_sub(self.mark) as u64 * machine::INSTRUCTIONS_PER_COUNT as u64;
        self.mark = t;
    }

    /// From here on the firmware's instructions count again.
    fn resume(&mut self) {
        self.mark = machine::counter();
    }

    fn instructions_now(&self) -> u64 {
        self.busy + machine::counter().wrapping_sub(self.mark) as u64 * machine::INSTRUCTIONS_PER_COUNT as u64
    }

    /// Encodes `msg` into the write buffer (writing the buffer out first if
    /// it is full).
    fn queue(&mut self, msg: &FromBoard) {
        let mut frame = [0u8; CLOCK_FRAME_LEN];
        // The clock messages are bounded (their sizes are tested); they fit.
        let Ok(bytes) = encode_frame(msg, self.seq, &mut frame) else {
            defmt::error!("lock-step clock: a message did not fit its frame");
            exit_failure()
        };
        self.seq = self.seq.wrapping_add(1);
        if self.write.extend_from_slice(bytes).is_err() {
            self.flush_writes();
            // Empty now, and a frame is smaller than the buffer.
            let _ = self.write.extend_from_slice(bytes);
        }
    }

    /// Writes the buffered frames to the host.
    fn flush_writes(&mut self) {
        if !self.write.is_empty() && !semi::write(self.to_host, &self.write) {
            defmt::error!("lock-step clock: the host is gone");
            exit_failure()
        }
        self.write.clear();
    }

    /// Queues every unreported byte as [`FromBoard::Output`] frames; the
    /// forecasts left are void.
    fn report_output(&mut self) {
        self.forecasts.clear();
        self.matched = false;
        let chunks = core::mem::take(&mut self.bus_out);
        for c in &chunks {
            self.queue(&FromBoard::Output { channel: Channel::Bus, at_us: c.at_us, answered: c.answered, bytes: c.bytes.clone() });
        }
        let telemetry = core::mem::take(&mut self.telemetry_out);
        for piece in telemetry.chunks(CHUNK_LEN) {
            // A piece of at most CHUNK_LEN bytes fits.
            let bytes = Vec::from_slice(piece).unwrap_or_default();
            self.queue(&FromBoard::Output { channel: Channel::Telemetry, at_us: self.now_us, answered: false, bytes });
        }
    }

    /// A servo-bus write at the current instant.
    fn bus_write(&mut self, bytes: &[u8]) {
        let forecast = self.forecasts.front().is_some_and(|f| {
            f.request_at_us == self.now_us && f.request.as_slice() == bytes
        });
        let alone = self.telemetry_out.is_empty() && self.bus_out.iter().all(|c| c.answered);
        if forecast && alone && !self.matched {
            self.matched = true;
        } else {
            self.forecasts.clear();
            self.matched = false;
        }
        for piece in bytes.chunks(CHUNK_LEN) {
            let chunk = BusChunk { at_us: self.now_us, bytes: Vec::from_slice(piece).unwrap_or_default(), answered: false };
            if let Err(chunk) = self.bus_out.push(chunk) {
                // Full: report what is there (without an exchange).
                self.report_output();
                self.flush_writes();
                let _ = self.bus_out.push(chunk);
            }
        }
    }

    /// Telemetry bytes at the current instant: no forecast is used until
    /// they are reported (the host reacts to them at this instant).
    fn telemetry_write(&mut self, mut bytes: &[u8]) {
        self.forecasts.clear();
        self.matched = false;
        while !bytes.is_empty() {
            let room = TELEMETRY_OUT - self.telemetry_out.len();
            if room == 0 {
                self.report_output();
                self.flush_writes();
                continue;
            }
            let (now, rest) = bytes.split_at(room.min(bytes.len()));
            let _ = self.telemetry_out.extend_from_slice(now);
            bytes = rest;
        }
    }

    /// Delivers the matched forecast's answer if the board may take it
    /// without the host: nothing but answered requests unreported, the
    /// answer not after the next timer (`until`) and before the host's
    /// next event. Returns whether it did.
    fn answer_locally(&mut self, until: u64) -> bool {
        let Some(f) = self.forecasts.front() else { return false };
        let ready = self.matched
            && f.reply_at_us <= until
            && f.reply_at_us < self.horizon_us
            && f.reply_at_us >= self.now_us
            && self.telemetry_out.is_empty()
            && self.bus_out.last().is_some_and(|c| !c.answered && c.at_us == f.request_at_us);
        if !ready {
            return false;
        }
        let Some(f) = self.forecasts.pop_front() else { return false };
        self.matched = false;
        if let Some(c) = self.bus_out.last_mut() {
            c.answered = true;
        }
        self.now_us = f.reply_at_us;
        self.bus_rx.push(&f.reply);
        self.bus_rx.wake();
        true
    }

    /// Advances the clock to the next timer (`until`) without the host, if
    /// the host would do exactly that: nothing is unreported but answered
    /// requests (and perhaps the matched forecast's, whose answer is not
    /// due before the timer), and the timer expires before the host's next
    /// event. (Without this, every timer the firmware left behind — a reply
    /// deadline whose answer came first stays in embassy's queue until it
    /// expires — would cost an exchange, and cut a chain of forecasts.)
    /// Returns whether it did.
    fn skip_to_timer(&mut self, until: u64) -> bool {
        if until == sil::NEVER || until <= self.now_us || until >= self.horizon_us || !self.telemetry_out.is_empty() {
            return false;
        }
        let (last, earlier) = match self.bus_out.split_last() {
            Some((last, earlier)) => (Some(last), earlier),
            None => (None, &[][..]),
        };
        let last_ok = match last {
            None => true,
            Some(c) if c.answered => true,
            Some(c) => {
                self.matched && self.forecasts.front().is_some_and(|f| c.at_us == f.request_at_us && until <= f.reply_at_us)
            }
        };
        if !(last_ok && earlier.iter().all(|c| c.answered)) {
            return false;
        }
        self.now_us = until;
        true
    }

    /// Blocks until the host's next message.
    fn receive(&mut self, decoder: &mut FrameDecoder<ToBoard, CLOCK_FRAME_LEN>, pending: &mut Deque<ToBoard, 8>) -> ToBoard {
        let mut buf = [0u8; CLOCK_FRAME_LEN];
        loop {
            if let Some(m) = pending.pop_front() {
                return m;
            }
            let n = semi::read_some(self.from_host, &mut buf);
            if n == 0 {
                defmt::error!("lock-step clock: the host is gone");
                exit_failure()
            }
            for frame in decoder.feed(&buf[..n]) {
                match frame {
                    Ok(frame) => {
                        if pending.push_back(frame.msg).is_err() {
                            defmt::error!("lock-step clock: more than 8 host messages in one read");
                            exit_failure()
                        }
                    }
                    // A FIFO does not damage frames; if one came, the host
                    // would time out waiting for the next Idle.
                    Err(_) => defmt::warn!("lock-step clock: a damaged frame from the host"),
                }
            }
        }
    }
}

/// The host's messages: decoder and what was decoded but not yet taken.
struct Inbox {
    decoder: FrameDecoder<ToBoard, CLOCK_FRAME_LEN>,
    pending: Deque<ToBoard, 8>,
}

/// Waits for the host's `Advance`, taking its `Input`s and `Forecast`s.
fn wait_for_advance(inbox: &mut Inbox) {
    loop {
        let msg = link(|l| l.receive(&mut inbox.decoder, &mut inbox.pending));
        match msg {
            ToBoard::Input { channel: Channel::Bus, bytes } => link(|l| l.bus_rx.push(&bytes)),
            ToBoard::Input { channel: Channel::Telemetry, bytes } => link(|l| l.telemetry_rx.push(&bytes)),
            ToBoard::Forecast { request_at_us, request, reply_at_us, reply } => link(|l| {
                // More than the board holds: the rest is simply not used.
                let _ = l.forecasts.push_back(Forecast { request_at_us, request, reply_at_us, reply });
            }),
            ToBoard::Advance { now_us, horizon_us } => {
                link(|l| {
                    l.now_us = l.now_us.max(now_us);
                    l.horizon_us = horizon_us;
                    l.bus_rx.wake();
                    l.telemetry_rx.wake();
                });
                return;
            }
            ToBoard::Configure { .. } => defmt::warn!("lock-step clock: Configure after boot ignored"),
            ToBoard::CutInSave { after_bytes } => super::injection::arm_cut(after_bytes),
            ToBoard::Hang => super::injection::request_hang(),
        }
    }
}

// ---------------------------------------------------------------------------
// Lock-step time driver and executor
// ---------------------------------------------------------------------------

static QUEUE: Mutex<RefCell<Queue>> = Mutex::new(RefCell::new(Queue::new()));
/// Set by the executor's pender: a task was woken.
static PENDED: AtomicBool = AtomicBool::new(false);
/// Set by `Board::init` once the link is open.
static LINK_OPEN: AtomicBool = AtomicBool::new(false);

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

/// Instructions counted over a loop of [`sil::CALIBRATION_INSTRUCTIONS`]
/// instructions (two per iteration: subtract, branch).
fn calibrate() -> u32 {
    let t0 = machine::counter();
    // SAFETY: a register-only countdown loop.
    unsafe {
        core::arch::asm!(
            "2:",
            "subs {n}, {n}, #1",
            "bne 2b",
            n = inout(reg) sil::CALIBRATION_INSTRUCTIONS / 2 => _,
            options(nomem, nostack),
        );
    }
    machine::counter().wrapping_sub(t0) * machine::INSTRUCTIONS_PER_COUNT
}

// ---------------------------------------------------------------------------
// The board
// ---------------------------------------------------------------------------

/// Everything the tasks get from the board.
pub struct Board {
    /// The servo bus.
    pub servo_port: ServoPort,
    /// Telemetry out.
    pub telemetry_tx: TelemetryTx,
    /// Commands in.
    pub telemetry_rx: TelemetryRx,
    /// Encoder and foot switches (a device on the servo bus).
    pub sensors: BoardSensors,
    /// The checkpoint slots (a file on the host).
    pub flash: FlashStore,
    /// The machine's watchdog (none on netduinoplus2).
    pub watchdog: Watchdog,
    /// Lock-step time plus instructions.
    pub cycles: Cycles,
    /// No LED.
    pub led: Led,
    /// The watchdog reset the chip (mps2-an386; never on netduinoplus2).
    pub watchdog_reset: bool,
    /// The table's memory: internal SRAM and CCM, or the mps2's PSRAM,
    /// which QEMU models from reset.
    pub table_memory: Result<TableMemory, MemoryFault>,
    /// The learner's seed, as the host configured it.
    pub seed: u64,
}

impl Board {
    /// Counter, clock link, the Boot message and the host's configuration.
    /// Call once.
    pub fn init() -> Board {
        // Before anything writes RAM the record lives in.
        let reset = super::watchdog::reset_cause();
        machine::start_counter();
        let (to_host, from_host) = match (semi::open(CLOCK_OUT, semi::WRITE), semi::open(CLOCK_IN, semi::READ)) {
            (Some(a), Some(b)) => (a, b),
            _ => {
                defmt::error!("cannot open the lock-step clock FIFOs (run this image with `pada sil`)");
                exit_failure()
            }
        };
        let calibration = calibrate();
        let robot = <crate::table::ThisRobot as pada_firmware::robot::RobotAdapter>::ROBOT.code();
        let boot = FromBoard::Boot {
            protocol: sil::CLOCK_PROTOCOL,
            robot,
            board: heapless::String::try_from(PROFILE.board.name()).unwrap_or_default(),
            machine: heapless::String::try_from(machine::MACHINE).unwrap_or_default(),
            calibration,
            resolution: machine::INSTRUCTIONS_PER_COUNT as u16,
            watchdog_ms: super::watchdog::PERIOD_MS,
            reset,
        };
        link(|l| {
            l.to_host = to_host;
            l.from_host = from_host;
            l.queue(&boot);
            l.flush_writes();
        });
        let mut inbox = Inbox { decoder: FrameDecoder::new(), pending: Deque::new() };
        let seed = match link(|l| l.receive(&mut inbox.decoder, &mut inbox.pending)) {
            ToBoard::Configure { seed, now_us } => {
                link(|l| {
                    l.now_us = now_us;
                    l.horizon_us = now_us;
                });
                seed
            }
            _ => {
                defmt::error!("lock-step clock: the host did not answer Boot with Configure");
                exit_failure()
            }
        };
        LINK_OPEN.store(true, Ordering::SeqCst);
        link(|l| l.resume());

        Board {
            servo_port: ServoPort(()),
            telemetry_tx: TelemetryTx(()),
            telemetry_rx: TelemetryRx(()),
            sensors: BoardSensors { bus: ServoBus::new(ServoPort(()), BusConfig::default()), contacts: 0 },
            flash: FlashStore::open(),
            watchdog: Watchdog::new(),
            cycles: Cycles(()),
            led: Led(()),
            watchdog_reset: matches!(reset, sil::ResetCause::Watchdog { .. }),
            table_memory: Ok(TableMemory::ready()),
            seed,
        }
    }
}

/// The servo bus. Two handles share it (the servo-bus task's and the
/// sensors'); the control loop never runs their transactions at the same
/// time (it reads the sensors after the servo bus has answered).
pub struct ServoPort(());

impl io::BusPort for ServoPort {
    fn discard_input(&mut self) {
        link(|l| l.bus_rx.bytes.clear());
    }

    async fn send(&mut self, bytes: &[u8]) -> Result<(), PortError> {
        link(|l| {
            l.pause();
            l.bus_write(bytes);
            l.resume();
        });
        Ok(())
    }

    async fn receive(&mut self, buf: &mut [u8], deadline_us: u64) -> Result<usize, PortError> {
        let ready = core::future::poll_fn(|cx| link(|l| l.bus_rx.poll(cx.waker())));
        match with_deadline(Instant::from_micros(deadline_us), ready).await {
            Ok(()) => Ok(link(|l| l.bus_rx.take(buf))),
            Err(_) => Ok(0),
        }
    }

    fn now_us(&self) -> u64 {
        Instant::now().as_micros()
    }
}

/// Telemetry out.
pub struct TelemetryTx(());

impl io::ByteSink for TelemetryTx {
    async fn write_all(&mut self, bytes: &[u8]) -> Result<(), PortError> {
        link(|l| {
            l.pause();
            l.telemetry_write(bytes);
            l.resume();
        });
        Ok(())
    }
}

/// Commands in.
pub struct TelemetryRx(());

impl io::ByteSource for TelemetryRx {
    async fn read(&mut self, buf: &mut [u8]) -> Result<usize, PortError> {
        core::future::poll_fn(|cx| link(|l| l.telemetry_rx.poll(cx.waker()))).await;
        Ok(link(|l| l.telemetry_rx.take(buf)))
    }
}

/// The encoder and the foot switches: device [`SENSOR_ID`] on the servo
/// bus, read with one READ per period.
pub struct BoardSensors {
    bus: ServoBus<ServoPort>,
    contacts: u8,
}

impl io::Sensors for BoardSensors {
    async fn encoder_count(&mut self) -> Option<u16> {
        let exchange = self.bus.read(SENSOR_ID, sil::sensor_table::ENCODER_COUNT, sil::sensor_table::READ_LEN).await;
        let (count, contacts) = exchange.status.as_ref().and_then(|s| sil::parse_sensor_read(&s.params))?;
        self.contacts = contacts;
        Some(count)
    }

    async fn contacts(&mut self) -> u8 {
        // Read together with the encoder, just before.
        self.contacts
    }
}

/// Lock-step time in cycles of [`CPU_HZ`] plus the instructions executed
/// outside the transport (QEMU's `-icount`): the agent step's count is its
/// instruction count, a period's count its time on the bus plus its work.
pub struct Cycles(());

impl io::CycleCounter for Cycles {
    fn cycles(&self) -> u32 {
        link(|l| l.now_us.wrapping_mul(CYCLES_PER_US).wrapping_add(l.instructions_now()) as u32)
    }
}

pub use super::watchdog::Watchdog;

/// The board's clock \[µs\].
pub(super) fn lockstep_now_us() -> u64 {
    link(|l| l.now_us)
}

/// The armed power cut is here (`injection.rs`): report everything, say
/// so, and wait for the host to kill the emulator.
fn power_cut_now() -> ! {
    let from_host = link(|l| {
        l.report_output();
        let cut = FromBoard::PowerCut { now_us: l.now_us };
        l.queue(&cut);
        l.flush_writes();
        l.from_host
    });
    let mut buf = [0u8; 64];
    // The host ends QEMU on reading PowerCut; whatever comes meanwhile is
    // dropped, as the power is off.
    while semi::read_some(from_host, &mut buf) > 0 {}
    exit_failure()
}

/// Writes `data` at `pos` of the checkpoint file, up to an armed power cut.
fn flash_put(h: usize, pos: usize, data: &[u8]) -> bool {
    match super::injection::before_cut(data.len()) {
        Ok(_) => semi::seek(h, pos) && semi::write(h, data),
        Err(n) => {
            if n > 0 {
                let _ = semi::seek(h, pos) && semi::write(h, &data[..n]);
            }
            power_cut_now()
        }
    }
}

/// No LED.
pub struct Led(());

impl Led {
    /// Nothing to light.
    pub fn set(&mut self, _on: bool) {}
}

// ---------------------------------------------------------------------------
// Checkpoints: a file on the host, through semihosting
// ---------------------------------------------------------------------------

/// The checkpoint file in QEMU's working directory: slot A, then slot B,
/// each [`sil::CHECKPOINT_SLOT_LEN`] bytes (one flash sector, as on the
/// real boards). Persists across boots of the same run directory, as flash
/// persists across resets.
const CHECKPOINT_FILE: &[u8] = b"pada-checkpoint.bin\0";
const _: () = assert!(CHECKPOINT_FILE.len() == sil::CHECKPOINT_FILE.len() + 1);
/// Bytes of each slot.
const SLOT_LEN: usize = sil::CHECKPOINT_SLOT_LEN;

/// Errors of the checkpoint file.
#[derive(Debug, Clone, Copy, PartialEq, Eq, defmt::Format)]
pub enum FlashError {
    /// Offset or length outside the slot, or a slot number other than 0/1.
    OutOfRange,
    /// The host refused to open, read or write the file.
    Host,
}

/// The two checkpoint slots in a host file.
pub struct FlashStore {
    handle: Option<usize>,
}

impl FlashStore {
    fn open() -> FlashStore {
        let existing = semi::open(CHECKPOINT_FILE, semi::READ_WRITE)
            .filter(|&h| semi::len(h).is_some_and(|n| n >= 2 * SLOT_LEN));
        let handle = existing.or_else(|| {
            let h = semi::open(CHECKPOINT_FILE, semi::CREATE)?;
            let mut store = FlashStore { handle: Some(h) };
            (store.erase(0).is_ok() && store.erase(1).is_ok()).then_some(h)
        });
        if handle.is_none() {
            defmt::warn!("checkpoint file unavailable (semihosting); saves will fail");
        }
        FlashStore { handle }
    }

    fn at(&self, slot: u8, offset: usize, len: usize) -> Result<(usize, usize), FlashError> {
        let h = self.handle.ok_or(FlashError::Host)?;
        if slot >= checkpoint::SLOTS || offset.checked_add(len).is_none_or(|end| end > SLOT_LEN) {
            return Err(FlashError::OutOfRange);
        }
        Ok((h, slot as usize * SLOT_LEN + offset))
    }
}

/// An erased kilobyte, written in one semihosting call.
static ERASED: [u8; 1024] = [0xFF; 1024];

impl CheckpointStore for FlashStore {
    type Error = FlashError;

    fn capacity(&self) -> usize {
        SLOT_LEN
    }

    fn read(&self, slot: u8, offset: usize, buf: &mut [u8]) -> Result<(), FlashError> {
        let (h, pos) = self.at(slot, offset, buf.len())?;
        (semi::seek(h, pos) && semi::read(h, buf)).then_some(()).ok_or(FlashError::Host)
    }

    fn erase(&mut self, slot: u8) -> Result<(), FlashError> {
        let (h, pos) = self.at(slot, 0, SLOT_LEN)?;
        let mut done = 0;
        while done < SLOT_LEN {
            let n = (SLOT_LEN - done).min(ERASED.len());
            if !flash_put(h, pos + done, &ERASED[..n]) {
                return Err(FlashError::Host);
            }
            done += n;
        }
        Ok(())
    }

    fn write(&mut self, slot: u8, offset: usize, data: &[u8]) -> Result<(), FlashError> {
        let (h, pos) = self.at(slot, offset, data.len())?;
        flash_put(h, pos, data).then_some(()).ok_or(FlashError::Host)
    }
}

// ---------------------------------------------------------------------------
// Panics and faults: log, then end QEMU with a failure code
// ---------------------------------------------------------------------------

fn exit_failure() -> ! {
    cortex_m_semihosting::debug::exit(cortex_m_semihosting::debug::EXIT_FAILURE);
    // Only reached if semihosting is off: stop here.
    loop {
        cortex_m::asm::bkpt();
    }
}

#[panic_handler]
fn panic(info: &core::panic::PanicInfo) -> ! {
    defmt::error!("panic: {}", defmt::Display2Format(info));
    exit_failure()
}

#[defmt::panic_handler]
fn defmt_panic() -> ! {
    exit_failure()
}

#[cortex_m_rt::exception]
unsafe fn HardFault(frame: &cortex_m_rt::ExceptionFrame) -> ! {
    defmt::error!("HardFault at pc {=u32:#x}", frame.pc());
    exit_failure()
}
