//! The emulated board: QEMU's `netduinoplus2` (an STM32F405RG), for the
//! software-in-the-loop run (`pada sil`, issue 6).
//!
//! The same type names as the real board ([`hw`](super)), implementing the
//! same `pada_firmware::io` traits, so `tasks.rs` and everything above it
//! (control loop, agent, fatigue counter, codec, telemetry, safety machine)
//! are the real board's code. What differs, and why:
//!
//! | here | real board | why |
//! |---|---|---|
//! | USART1/2 through the PAC, read when the board is idle | embassy-stm32 with DMA | QEMU models no RCC/PWR: `embassy_stm32::init` never returns |
//! | lock-step time driver: the host advances the clock over two FIFOs ([`pada_firmware::sil`]) | TIM2 at 1 MHz | deterministic runs, faster than real time |
//! | an executor loop that reports when it is idle | thread-mode executor (WFE/SEV) | the idle moment is when the clock may advance |
//! | encoder and foot switches: device [`SENSOR_ID`] on the servo bus | TIM3 in encoder mode, GPIO | QEMU emulates neither |
//! | cycle counter: lock-step time × 168 MHz + instructions executed (TIM2 under `-icount`) | DWT CYCCNT | QEMU has no DWT; instructions stand in for cycles |
//! | checkpoints in a file on the host (semihosting) | flash sectors 10–11 | QEMU's flash is read-only |
//! | no watchdog | IWDG | nothing can hang the lock-step clock unnoticed: the host times out |
//! | defmt and panics over semihosting, exit code 1 on a panic | RTT, probe-rs | no debug probe |
//!
//! QEMU delivers a USART's received bytes one at a time, as the firmware
//! reads the data register, and never overruns; its transmitter sends a byte
//! at once when the data register is written. Bytes only ever arrive while
//! the board is idle and waiting for the host's `Advance`, which says how
//! many to expect, so nothing is polled outside the idle loop.

use core::cell::RefCell;
use core::sync::atomic::{AtomicBool, Ordering};
use core::task::{Poll, Waker};
use critical_section::Mutex;
use embassy_executor::{raw, Spawner};
use embassy_time::{with_deadline, Instant};
use embassy_time_queue_utils::Queue;
use heapless::Deque;
use pada_core::checkpoint::{self, CheckpointStore};
use pada_core::wire::{encode_frame, FrameDecoder};
use pada_firmware::bus::{BusConfig, ServoBus};
use super::{MemoryFault, TableMemory};
use crate::table::{PROFILE, WEIGHTS};
use pada_firmware::io::{self, PortError};
use pada_firmware::sil::{self, FromBoard, ToBoard, CLOCK_FRAME_LEN, SENSOR_ID};
use stm32_metapac::usart::Usart;
use stm32_metapac::{TIM2, USART1, USART2};
// defmt over semihosting (QEMU writes it to the chardev the host chose).
use defmt_semihosting as _;

/// The clock the cycle counts are converted with: the F405's 168 MHz, one
/// instruction taken as one cycle.
pub const CPU_HZ: u32 = 168_000_000;
/// Cycles per microsecond of lock-step time.
const CYCLES_PER_US: u64 = CPU_HZ as u64 / 1_000_000;

/// Bytes of the servo bus's receive buffer.
const SERVO_RX_BUF: usize = 256;
/// Bytes of the telemetry port's receive buffer.
const TELEMETRY_RX_BUF: usize = 512;

// ---------------------------------------------------------------------------
// Serial ports
// ---------------------------------------------------------------------------

/// One USART: its registers, the bytes received and not yet taken, and the
/// byte counts of the clock protocol.
struct Port<const N: usize> {
    regs: Usart,
    rx: Deque<u8, N>,
    /// Bytes received since boot.
    rx_count: u64,
    /// Bytes written since boot.
    tx_count: u64,
    /// Bytes lost because `rx` was full.
    overflows: u32,
    /// The task waiting for received bytes.
    waker: Option<Waker>,
}

impl<const N: usize> Port<N> {
    const fn new(regs: Usart) -> Self {
        Port { regs, rx: Deque::new(), rx_count: 0, tx_count: 0, overflows: 0, waker: None }
    }

    fn enable(&self) {
        // UE, TE, RE. QEMU ignores the baud rate; RCC's clock enables are
        // not modelled (writes are ignored), so none are needed.
        self.regs.cr1().write(|w| {
            w.set_ue(true);
            w.set_te(true);
            w.set_re(true);
        });
    }

    fn write(&mut self, bytes: &[u8]) {
        for &b in bytes {
            while !self.regs.sr().read().txe() {}
            self.regs.dr().write(|w| w.set_dr(b as u16));
        }
        self.tx_count += bytes.len() as u64;
    }

    /// Moves what the USART holds into `rx`; true if a byte came.
    fn pump(&mut self) -> bool {
        let mut got = false;
        while self.regs.sr().read().rxne() {
            let b = self.regs.dr().read().dr() as u8;
            self.rx_count += 1;
            got = true;
            if self.rx.push_back(b).is_err() {
                self.overflows = self.overflows.wrapping_add(1);
            }
        }
        got
    }

    fn take(&mut self, buf: &mut [u8]) -> usize {
        let mut n = 0;
        while n < buf.len() {
            match self.rx.pop_front() {
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
        if !self.rx.is_empty() {
            if let Some(w) = self.waker.take() {
                w.wake();
            }
        }
    }

    /// Ready when bytes are there, else registers `waker`.
    fn poll_rx(&mut self, waker: &Waker) -> Poll<()> {
        if self.rx.is_empty() {
            self.waker = Some(waker.clone());
            Poll::Pending
        } else {
            Poll::Ready(())
        }
    }
}

static BUS: Mutex<RefCell<Port<SERVO_RX_BUF>>> = Mutex::new(RefCell::new(Port::new(USART1)));
static TELEMETRY: Mutex<RefCell<Port<TELEMETRY_RX_BUF>>> = Mutex::new(RefCell::new(Port::new(USART2)));

fn bus<R>(f: impl FnOnce(&mut Port<SERVO_RX_BUF>) -> R) -> R {
    critical_section::with(|cs| f(&mut BUS.borrow_ref_mut(cs)))
}

fn telemetry<R>(f: impl FnOnce(&mut Port<TELEMETRY_RX_BUF>) -> R) -> R {
    critical_section::with(|cs| f(&mut TELEMETRY.borrow_ref_mut(cs)))
}

/// The lock-step clock's channel to the host: two FIFOs in QEMU's working
/// directory, written and read through semihosting. A semihosting call
/// moves a whole message at once, where QEMU's USART model moves one byte
/// per turn of its main loop (about 60 µs each).
struct ClockLink {
    to_host: usize,
    from_host: usize,
}

/// FIFO the board writes [`FromBoard`] frames to.
const CLOCK_OUT: &[u8] = b"clock-from-board\0";
const _: () = assert!(CLOCK_OUT.len() == sil::CLOCK_FROM_BOARD.len() + 1);
/// FIFO the board reads [`ToBoard`] frames from.
const CLOCK_IN: &[u8] = b"clock-to-board\0";
const _: () = assert!(CLOCK_IN.len() == sil::CLOCK_TO_BOARD.len() + 1);

impl ClockLink {
    /// Opens both FIFOs; without them the board cannot run.
    fn open() -> ClockLink {
        let to_host = semi::open(CLOCK_OUT, semi::WRITE);
        let from_host = semi::open(CLOCK_IN, semi::READ);
        match (to_host, from_host) {
            (Some(to_host), Some(from_host)) => ClockLink { to_host, from_host },
            _ => {
                defmt::error!("cannot open the lock-step clock FIFOs (run this image with `pada sil`)");
                exit_failure()
            }
        }
    }

    fn send(&self, msg: &FromBoard, seq: &mut u32) {
        let mut buf = [0u8; CLOCK_FRAME_LEN];
        // The clock messages are a few integers; they always fit.
        if let Ok(frame) = encode_frame(msg, *seq, &mut buf) {
            if !semi::write(self.to_host, frame) {
                defmt::error!("lock-step clock: the host is gone");
                exit_failure()
            }
        }
        *seq = seq.wrapping_add(1);
    }

    /// Blocks until the host's next message.
    fn receive(&self, decoder: &mut FrameDecoder<ToBoard, CLOCK_FRAME_LEN>) -> ToBoard {
        let mut buf = [0u8; CLOCK_FRAME_LEN];
        loop {
            let n = semi::read_some(self.from_host, &mut buf);
            if n == 0 {
                defmt::error!("lock-step clock: the host is gone");
                exit_failure()
            }
            for frame in decoder.feed(&buf[..n]) {
                // A damaged frame cannot come through a FIFO; if one did,
                // the host would time out waiting for the next Idle.
                if let Ok(frame) = frame {
                    return frame.msg;
                }
            }
        }
    }
}

// ---------------------------------------------------------------------------
// Lock-step time driver and executor
// ---------------------------------------------------------------------------

/// The lock-step clock and the instruction count.
struct Clock {
    /// Current time \[µs\], set only by the host's `Advance`.
    now_us: u64,
    /// Instructions executed outside the idle loop, up to `mark`.
    busy: u64,
    /// TIM2's count when `busy` was last brought up to date.
    mark: u32,
    /// Sequence number of the next clock frame.
    seq: u32,
}

static CLOCK: Mutex<RefCell<Clock>> = Mutex::new(RefCell::new(Clock { now_us: 0, busy: 0, mark: 0, seq: 0 }));
static QUEUE: Mutex<RefCell<Queue>> = Mutex::new(RefCell::new(Queue::new()));
/// The clock link, opened by `Board::init`.
static mut CLOCK_LINK: Option<ClockLink> = None;
/// Set by the executor's pender: a task was woken.
static PENDED: AtomicBool = AtomicBool::new(false);

/// TIM2, free running at QEMU's 1 GHz timer clock: under `-icount shift=0`
/// one count per instruction executed.
fn tim2() -> u32 {
    TIM2.cnt().read()
}

/// TIM2's counts over a loop of [`sil::CALIBRATION_INSTRUCTIONS`]
/// instructions (two per iteration: subtract, branch).
fn calibrate() -> u32 {
    let t0 = tim2();
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
    tim2().wrapping_sub(t0)
}

fn instructions_now(c: &Clock) -> u64 {
    c.busy + tim2().wrapping_sub(c.mark) as u64
}

struct LockstepDriver;

impl embassy_time_driver::Driver for LockstepDriver {
    fn now(&self) -> u64 {
        critical_section::with(|cs| CLOCK.borrow_ref(cs).now_us)
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
        // SAFETY: set once by `Board::init` (called by the main task, which
        // `init` spawned and the first poll below runs); read only here.
        let mut link: Option<&ClockLink> = None;
        let mut decoder: FrameDecoder<ToBoard, CLOCK_FRAME_LEN> = FrameDecoder::new();
        loop {
            PENDED.store(false, Ordering::SeqCst);
            // SAFETY: not reentrant: `poll` is called only here, and the
            // pender only sets a flag.
            unsafe { self.inner.poll() };
            if !PENDED.load(Ordering::SeqCst) {
                if link.is_none() {
                    // SAFETY: see above; `Board::init` has run (the main
                    // task runs to its end in the first poll).
                    link = unsafe { (*core::ptr::addr_of!(CLOCK_LINK)).as_ref() };
                }
                match link {
                    Some(link) => idle(link, &mut decoder),
                    None => {
                        defmt::error!("idle before Board::init");
                        exit_failure()
                    }
                }
            }
        }
    }
}

/// Nothing to run: wake expired timers; if none, tell the host until when
/// the board is idle and wait for its `Advance`.
fn idle(link: &ClockLink, decoder: &mut FrameDecoder<ToBoard, CLOCK_FRAME_LEN>) {
    let now = critical_section::with(|cs| CLOCK.borrow_ref(cs).now_us);
    let until = critical_section::with(|cs| QUEUE.borrow_ref_mut(cs).next_expiration(now));
    if PENDED.load(Ordering::SeqCst) {
        // A timer had expired: its task runs first.
        return;
    }
    let (idle_msg, mut seq) = critical_section::with(|cs| {
        let mut c = CLOCK.borrow_ref_mut(cs);
        let t = tim2();
        c.busy += t.wrapping_sub(c.mark) as u64;
        c.mark = t;
        let msg = FromBoard::Idle {
            now_us: c.now_us,
            until_us: until,
            bus_tx: bus(|p| p.tx_count),
            telemetry_tx: telemetry(|p| p.tx_count),
            instructions: c.busy,
        };
        (msg, c.seq)
    });
    link.send(&idle_msg, &mut seq);
    let ToBoard::Advance { now_us, bus_rx, telemetry_rx } = link.receive(decoder);

    // The bytes the host sent before this Advance.
    loop {
        bus(|p| p.pump());
        telemetry(|p| p.pump());
        if bus(|p| p.rx_count) >= bus_rx && telemetry(|p| p.rx_count) >= telemetry_rx {
            break;
        }
        sleep_until_received();
    }
    critical_section::with(|cs| {
        let mut c = CLOCK.borrow_ref_mut(cs);
        c.now_us = c.now_us.max(now_us);
        c.seq = seq;
        c.mark = tim2();
    });
    bus(|p| p.wake());
    telemetry(|p| p.wake());
    let now = critical_section::with(|cs| CLOCK.borrow_ref(cs).now_us);
    critical_section::with(|cs| QUEUE.borrow_ref_mut(cs).next_expiration(now));
}

/// Sleeps (WFI) until USART1 or USART2 has received a byte.
///
/// Spinning on the status registers would starve QEMU's main loop, which
/// delivers each received byte and needs the lock the spinning CPU keeps
/// taking; a sleeping CPU leaves it free. The receive interrupts only wake
/// the core: [`DefaultHandler`] switches them off again.
fn sleep_until_received() {
    // With interrupts masked, the handler cannot run between enabling the
    // interrupts and WFI (it would switch them off, and WFI would sleep
    // forever); WFI still wakes on a pending interrupt, which is taken once
    // they are unmasked. A byte that came in since the last look pends its
    // interrupt at once, so WFI returns immediately; none is lost.
    cortex_m::interrupt::disable();
    for usart in [USART1, USART2] {
        usart.cr1().modify(|w| w.set_rxneie(true));
    }
    cortex_m::asm::wfi();
    // SAFETY: not inside a critical section (the idle loop holds none).
    unsafe { cortex_m::interrupt::enable() };
}

/// Every interrupt of the emulated board is a USART's receive interrupt,
/// enabled only by [`sleep_until_received`] to wake the core: switch them
/// off (the idle loop reads the bytes).
#[cortex_m_rt::exception]
unsafe fn DefaultHandler(_irqn: i16) {
    for usart in [USART1, USART2] {
        usart.cr1().modify(|w| w.set_rxneie(false));
    }
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
    /// No watchdog.
    pub watchdog: Watchdog,
    /// Lock-step time plus instructions.
    pub cycles: Cycles,
    /// No LED.
    pub led: Led,
    /// Never: there is no watchdog to reset the emulated chip.
    pub watchdog_reset: bool,
    /// The table's memory: CCM and SRAM, which QEMU 10 models from reset.
    pub table_memory: Result<TableMemory, MemoryFault>,
}

impl Board {
    /// Ports, timer, the Boot message. Call once.
    pub fn init() -> Board {
        // TIM2 free running from 0, no prescaler, full 32-bit range.
        TIM2.psc().write_value(0);
        TIM2.arr().write_value(u32::MAX);
        TIM2.egr().write(|w| w.set_ug(true));
        TIM2.cr1().write(|w| w.set_cen(true));
        critical_section::with(|cs| CLOCK.borrow_ref_mut(cs).mark = tim2());

        bus(|p| p.enable());
        telemetry(|p| p.enable());
        // The USARTs' interrupts (37, 38) wake the idle loop.
        // SAFETY: their handler only clears the receive-interrupt enables;
        // no critical section relies on them being masked.
        unsafe {
            let mut nvic = cortex_m::Peripherals::steal().NVIC;
            for irq in [Irq(37), Irq(38)] {
                nvic.set_priority(irq, 0);
                cortex_m::peripheral::NVIC::unmask(irq);
            }
        }
        let link = ClockLink::open();
        let mut seq = 0;
        let boot = FromBoard::Boot { protocol: sil::CLOCK_PROTOCOL, robot: <crate::table::ThisRobot as pada_firmware::robot::RobotAdapter>::ROBOT.code(), calibration: calibrate() };
        link.send(&boot, &mut seq);
        critical_section::with(|cs| CLOCK.borrow_ref_mut(cs).seq = seq);
        // SAFETY: `init` runs once, before the executor, which is the only
        // other user of the link.
        unsafe { *core::ptr::addr_of_mut!(CLOCK_LINK) = Some(link) };

        Board {
            servo_port: ServoPort(()),
            telemetry_tx: TelemetryTx(()),
            telemetry_rx: TelemetryRx(()),
            sensors: BoardSensors { bus: ServoBus::new(ServoPort(()), BusConfig::default()), contacts: 0 },
            flash: FlashStore::open(),
            watchdog: Watchdog(()),
            cycles: Cycles(()),
            led: Led(()),
            watchdog_reset: false,
            table_memory: Ok(TableMemory::ready()),
        }
    }
}

/// An interrupt number of the STM32F405 (RM0090, table 61).
#[derive(Clone, Copy)]
struct Irq(u16);

// SAFETY: 37 and 38 are USART1 and USART2, valid interrupt numbers of the chip.
unsafe impl cortex_m::interrupt::InterruptNumber for Irq {
    fn number(self) -> u16 {
        self.0
    }
}

/// The servo bus: USART1. Two handles share it (the servo-bus task's and
/// the sensors'); the control loop never runs their transactions at the
/// same time (it reads the sensors after the servo bus has answered).
pub struct ServoPort(());

impl io::BusPort for ServoPort {
    fn discard_input(&mut self) {
        bus(|p| p.rx.clear());
    }

    async fn send(&mut self, bytes: &[u8]) -> Result<(), PortError> {
        bus(|p| p.write(bytes));
        Ok(())
    }

    async fn receive(&mut self, buf: &mut [u8], deadline_us: u64) -> Result<usize, PortError> {
        let ready = core::future::poll_fn(|cx| bus(|p| p.poll_rx(cx.waker())));
        match with_deadline(Instant::from_micros(deadline_us), ready).await {
            Ok(()) => Ok(bus(|p| p.take(buf))),
            Err(_) => Ok(0),
        }
    }

    fn now_us(&self) -> u64 {
        Instant::now().as_micros()
    }
}

/// Telemetry out: USART2.
pub struct TelemetryTx(());

impl io::ByteSink for TelemetryTx {
    async fn write_all(&mut self, bytes: &[u8]) -> Result<(), PortError> {
        telemetry(|p| p.write(bytes));
        Ok(())
    }
}

/// Commands in: USART2.
pub struct TelemetryRx(());

impl io::ByteSource for TelemetryRx {
    async fn read(&mut self, buf: &mut [u8]) -> Result<usize, PortError> {
        core::future::poll_fn(|cx| telemetry(|p| p.poll_rx(cx.waker()))).await;
        Ok(telemetry(|p| p.take(buf)))
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
/// outside the idle loop (QEMU's `-icount`): the agent step's count is its
/// instruction count, a period's count its time on the bus plus its work.
pub struct Cycles(());

impl io::CycleCounter for Cycles {
    fn cycles(&self) -> u32 {
        critical_section::with(|cs| {
            let c = CLOCK.borrow_ref(cs);
            c.now_us.wrapping_mul(CYCLES_PER_US).wrapping_add(instructions_now(&c)) as u32
        })
    }
}

/// No watchdog on the emulated board (the host notices a hang).
pub struct Watchdog(());

impl Watchdog {
    /// Nothing to start.
    pub fn start(&mut self) {}
    /// Nothing to feed.
    pub fn feed(&mut self) {}
    /// Nothing to extend.
    pub fn extend(&mut self, _long: bool) {}
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
/// each [`checkpoint::slot_len`] bytes. Persists across boots of the same
/// run directory, as flash persists across resets.
const CHECKPOINT_FILE: &[u8] = b"pada-checkpoint.bin\0";
const _: () = assert!(CHECKPOINT_FILE.len() == sil::CHECKPOINT_FILE.len() + 1);
/// Bytes of each slot.
const SLOT_LEN: usize = checkpoint::slot_len(WEIGHTS, PROFILE.format.bytes());

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
        if !semi::seek(h, pos) {
            return Err(FlashError::Host);
        }
        let ff = [0xFFu8; 256];
        let mut left = SLOT_LEN;
        while left > 0 {
            let n = left.min(ff.len());
            if !semi::write(h, &ff[..n]) {
                return Err(FlashError::Host);
            }
            left -= n;
        }
        Ok(())
    }

    fn write(&mut self, slot: u8, offset: usize, data: &[u8]) -> Result<(), FlashError> {
        let (h, pos) = self.at(slot, offset, data.len())?;
        (semi::seek(h, pos) && semi::write(h, data)).then_some(()).ok_or(FlashError::Host)
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
