//! The real board on embassy-stm32: clocks, the two USARTs, the encoder
//! timer, the foot switches, flash, watchdog, cycle counter, and the table's
//! memory. Which peripheral and pin does which job, and the clocks, are the
//! chip's (`super::chip`: `f40x.rs` or `f429.rs`); the drivers here are the
//! same for every chip.
//!
//! Each type here implements one of `pada_firmware::io`'s traits (or
//! `pada_core::checkpoint::CheckpointStore`) and does nothing else.

use super::chip::{self, Irqs, Resources};
use super::Parts;
use core::task::Poll;
use embassy_stm32::gpio::{Input, Level, Output, Pull, Speed};
use embassy_stm32::mode::Async;
use embassy_stm32::timer::qei::{Qei, QeiMode};
use embassy_stm32::usart::{self, RingBufferedUartRx, Uart, UartTx};
use embassy_stm32::wdg::IndependentWatchdog;
use embassy_stm32::{flash, peripherals};
use embassy_time::{with_deadline, Instant};
use pada_core::checkpoint::CheckpointStore;
use pada_firmware::io::{self, PortError};
use static_cell::StaticCell;
// defmt over RTT (probe-rs shows it), and panics printed there before the
// core halts; the watchdog then resets the chip. An emulated board picks
// its own (semihosting).
use {defmt_rtt as _, panic_probe as _};

pub use chip::CPU_HZ;
/// The servo bus's baud rate (Dynamixel's 1 Mbps, Baud Rate register 1).
pub const SERVO_BAUD: u32 = 1_000_000;
/// The telemetry link's baud rate.
pub const TELEMETRY_BAUD: u32 = 921_600;
/// Watchdog timeout in normal operation \[µs\].
pub const WATCHDOG_US: u32 = 250_000;
/// Watchdog timeout while a flash sector is erased: up to 2 s per 128 KiB
/// sector (datasheets, t_ERASE128KB), during which the F405 stalls its CPU
/// and every chip waits in the blocking erase \[µs\].
pub const WATCHDOG_FLASH_US: u32 = 8_000_000;

/// Bytes of the servo bus's circular DMA receive buffer.
const SERVO_RX_BUF: usize = 256;
/// Bytes of the telemetry link's circular DMA receive buffer: a whole batch
/// of a restore's chunks, even if the board reads none until it has all
/// arrived (the wire's).
const TELEMETRY_RX_BUF: usize = pada_core::wire::CHIP_RX_BUFFER;

/// Everything the tasks get from the board ([`Parts`]).
pub type Board = Parts<ServoPort, TelemetryTx, TelemetryRx, BoardSensors, FlashStore, Watchdog, Cycles, Led>;

impl Board {
    /// Clocks, pins and peripherals, and the memory `table` of the image's
    /// weight table (its profile's). Call once.
    pub fn init(table: pada_core::profile::Memory) -> Board {
        // The reset cause, before anything clears it.
        let csr = embassy_stm32::pac::RCC.csr().read();
        let watchdog_reset = csr.wdgrstf();
        embassy_stm32::pac::RCC.csr().modify(|w| w.set_rmvf(true));

        let p = embassy_stm32::init(chip::clock_config());
        let (r, table_memory_pins): (Resources, chip::TableMemoryPins) = chip::split(p);
        // Before anything else may touch the table (it needs the token).
        let table_memory = chip::start_table_memory(table_memory_pins, table);

        // Servo bus: 1 Mbps, RX pulled up (the transceiver's
        // receiver is off while the driver is on).
        let mut servo_config = usart::Config::default();
        servo_config.baudrate = SERVO_BAUD;
        servo_config.rx_pull = Pull::Up;
        let (servo_tx_pin, servo_rx_pin, servo_de_pin) = r.servo_pins;
        let servo = Uart::new(
            r.servo_uart,
            servo_rx_pin,
            servo_tx_pin,
            r.servo_dma.0,
            r.servo_dma.1,
            Irqs,
            servo_config,
        )
        .unwrap_or_else(|_| defmt::panic!("servo bus USART configuration"));
        let (servo_tx, servo_rx) = servo.split();
        static SERVO_BUF: StaticCell<[u8; SERVO_RX_BUF]> = StaticCell::new();
        let servo_rx = servo_rx.into_ring_buffered(SERVO_BUF.init([0; SERVO_RX_BUF]));
        let de = Output::new(servo_de_pin, Level::Low, Speed::VeryHigh);

        // Telemetry.
        let mut tele_config = usart::Config::default();
        tele_config.baudrate = TELEMETRY_BAUD;
        tele_config.rx_pull = Pull::Up;
        let (tele_tx_pin, tele_rx_pin) = r.tele_pins;
        let tele = Uart::new(r.tele_uart, tele_rx_pin, tele_tx_pin, r.tele_dma.0, r.tele_dma.1, Irqs, tele_config)
            .unwrap_or_else(|_| defmt::panic!("telemetry USART configuration"));
        let (tele_tx, tele_rx) = tele.split();
        static TELE_BUF: StaticCell<[u8; TELEMETRY_RX_BUF]> = StaticCell::new();
        let tele_rx = tele_rx.into_ring_buffered(TELE_BUF.init([0; TELEMETRY_RX_BUF]));

        // Encoder: encoder mode 3 (both edges of both channels).
        let mut qei_config = embassy_stm32::timer::qei::Config::default();
        qei_config.mode = QeiMode::Mode3;
        qei_config.ch1_pull = Pull::Up;
        qei_config.ch2_pull = Pull::Up;
        let qei = Qei::new(r.encoder_timer, r.encoder_pins.0, r.encoder_pins.1, qei_config);
        let [c0, c1, c2, c3] = r.contacts;
        let contacts = [c0, c1, c2, c3].map(|pin| Input::new(pin, Pull::Up));

        let led = Led {
            pin: Output::new(r.led, if chip::LED_ACTIVE_HIGH { Level::Low } else { Level::High }, Speed::Low),
        };

        Board {
            servo_port: ServoPort { tx: servo_tx, rx: servo_rx, de },
            telemetry_tx: TelemetryTx { tx: tele_tx },
            telemetry_rx: TelemetryRx { rx: tele_rx },
            sensors: BoardSensors { qei, contacts },
            flash: FlashStore::new(flash::Flash::new_blocking(r.flash)),
            watchdog: Watchdog { iwdg: IndependentWatchdog::new(r.iwdg, WATCHDOG_FLASH_US) },
            cycles: Cycles::start(),
            led,
            watchdog_reset,
            table_memory,
            seed: pada_firmware::config::DEFAULT_SEED,
        }
    }
}

/// The servo bus: a USART with a software driver-enable line.
pub struct ServoPort {
    tx: UartTx<'static, Async>,
    rx: RingBufferedUartRx<'static>,
    de: Output<'static>,
}

impl io::BusPort for ServoPort {
    fn discard_input(&mut self) {
        let mut buf = [0u8; 32];
        // Whatever is in the ring buffer now; an error (overrun) restarts
        // the receiver on the next read.
        for _ in 0..(SERVO_RX_BUF / 32 + 1) {
            match embassy_futures::poll_once(self.rx.read(&mut buf)) {
                Poll::Ready(Ok(n)) if n > 0 => continue,
                _ => break,
            }
        }
    }

    async fn send(&mut self, bytes: &[u8]) -> Result<(), PortError> {
        self.de.set_high();
        let written = self.tx.write(bytes).await;
        // The DMA is done when the last byte is in the shift register; the
        // line is free only after its stop bit (TC), 10 µs later at 1 Mbps.
        let flushed = self.tx.blocking_flush();
        self.de.set_low();
        written.and(flushed).map_err(|_| PortError::Transmit)
    }

    async fn receive(&mut self, buf: &mut [u8], deadline_us: u64) -> Result<usize, PortError> {
        match with_deadline(Instant::from_micros(deadline_us), self.rx.read(buf)).await {
            Ok(Ok(n)) => Ok(n),
            Ok(Err(_)) => Err(PortError::Line),
            Err(_) => Ok(0),
        }
    }

    fn now_us(&self) -> u64 {
        Instant::now().as_micros()
    }
}

/// Telemetry out: a USART's TX with DMA.
pub struct TelemetryTx {
    tx: UartTx<'static, Async>,
}

impl io::ByteSink for TelemetryTx {
    async fn write_all(&mut self, bytes: &[u8]) -> Result<(), PortError> {
        self.tx.write(bytes).await.map_err(|_| PortError::Transmit)
    }
}

/// Commands in: a USART's RX into a circular DMA buffer.
pub struct TelemetryRx {
    rx: RingBufferedUartRx<'static>,
}

impl io::ByteSource for TelemetryRx {
    async fn read(&mut self, buf: &mut [u8]) -> Result<usize, PortError> {
        self.rx.read(buf).await.map_err(|_| PortError::Line)
    }
}

/// The encoder timer and the foot switches.
pub struct BoardSensors {
    qei: Qei<'static, chip::EncoderTimer>,
    contacts: [Input<'static>; 4],
}

impl io::Sensors for BoardSensors {
    async fn encoder_count(&mut self) -> Option<u16> {
        Some(self.qei.count())
    }

    async fn contacts(&mut self) -> u8 {
        // Switches close to ground: low = contact.
        self.contacts.iter().enumerate().fold(0, |bits, (i, pin)| bits | ((pin.is_low() as u8) << i))
    }
}

/// The DWT cycle counter.
pub struct Cycles(());

impl Cycles {
    fn start() -> Cycles {
        // SAFETY: only the trace-enable bit of DEMCR and DWT's CYCCNTENA are
        // set, once at boot; nothing else uses the DCB or DWT.
        let mut cp = unsafe { cortex_m::Peripherals::steal() };
        cp.DCB.enable_trace();
        cp.DWT.set_cycle_count(0);
        cp.DWT.enable_cycle_counter();
        Cycles(())
    }
}

impl io::CycleCounter for Cycles {
    fn cycles(&self) -> u32 {
        cortex_m::peripheral::DWT::cycle_count()
    }
}

/// The emulated boards' hang injection (`pada sil --fault hang`): nothing
/// on a real board.
#[inline(always)]
pub fn injected_hang() {}

/// The independent watchdog. Started with a prescaler that reaches
/// [`WATCHDOG_FLASH_US`], then run at [`WATCHDOG_US`]; [`extend`] switches
/// between the two by the reload register alone.
///
/// [`extend`]: Watchdog::extend
pub struct Watchdog {
    iwdg: IndependentWatchdog<'static, peripherals::IWDG>,
}

impl Watchdog {
    /// Starts the watchdog at the normal timeout.
    pub fn start(&mut self) {
        self.iwdg.unleash();
        self.extend(false);
    }

    /// Reloads the counter.
    pub fn feed(&mut self) {
        self.iwdg.pet();
    }

    /// Switches to the long timeout (`true`, for flash erases) or back.
    pub fn extend(&mut self, long: bool) {
        use embassy_stm32::pac::iwdg::vals::Key;
        // The prescaler `new` chose for WATCHDOG_FLASH_US is /64: one
        // reload count is 64 / 32 kHz = 2 ms.
        const US_PER_COUNT: u32 = 2_000;
        let us = if long { WATCHDOG_FLASH_US } else { WATCHDOG_US };
        let reload = (us / US_PER_COUNT).clamp(1, 0x1000) - 1;
        let iwdg = embassy_stm32::pac::IWDG;
        iwdg.kr().write(|w| w.set_key(Key::ENABLE));
        iwdg.rlr().write(|w| w.set_rl(reload as u16));
        // Wait until the new reload value reached the watchdog's clock domain.
        while iwdg.sr().read().rvu() {}
        self.iwdg.pet();
    }
}

/// The status LED.
pub struct Led {
    pin: Output<'static>,
}

impl Led {
    /// Lights or darkens it.
    pub fn set(&mut self, on: bool) {
        self.pin.set_level(if on == chip::LED_ACTIVE_HIGH { Level::High } else { Level::Low });
    }
}

/// The two checkpoint flash sectors (`memory.x`, `memory-f429.x`:
/// `__checkpoint_slot_a`, `__checkpoint_slot_b`, `__checkpoint_slot_size`).
pub struct FlashStore {
    flash: flash::Flash<'static, flash::Blocking>,
    slots: [u32; 2],
    size: usize,
}

unsafe extern "C" {
    static __checkpoint_slot_a: u8;
    static __checkpoint_slot_b: u8;
    static __checkpoint_slot_size: u8;
}

/// Errors of the flash store.
#[derive(Debug, Clone, Copy, PartialEq, Eq, defmt::Format)]
pub enum FlashError {
    /// Offset or length outside the slot, or a slot number other than 0/1.
    OutOfRange,
    /// The flash controller reported an error.
    Flash,
}

impl FlashStore {
    fn new(flash: flash::Flash<'static, flash::Blocking>) -> Self {
        // Only the symbols' addresses are used; nothing is read through them.
        let a = core::ptr::addr_of!(__checkpoint_slot_a) as u32;
        let b = core::ptr::addr_of!(__checkpoint_slot_b) as u32;
        let size = core::ptr::addr_of!(__checkpoint_slot_size) as usize;
        FlashStore { flash, slots: [a, b], size }
    }

    fn range(&self, slot: u8, offset: usize, len: usize) -> Result<u32, FlashError> {
        let base = *self.slots.get(slot as usize).ok_or(FlashError::OutOfRange)?;
        if offset.checked_add(len).is_none_or(|end| end > self.size) {
            return Err(FlashError::OutOfRange);
        }
        Ok(base + offset as u32)
    }
}

/// Flash addresses start here; embassy's flash API takes offsets from it.
const FLASH_BASE: u32 = 0x0800_0000;

impl CheckpointStore for FlashStore {
    type Error = FlashError;

    fn capacity(&self) -> usize {
        self.size
    }

    fn read(&self, slot: u8, offset: usize, buf: &mut [u8]) -> Result<(), FlashError> {
        let addr = self.range(slot, offset, buf.len())?;
        // SAFETY: the range lies inside a checkpoint sector (checked above),
        // which is memory-mapped flash that no Rust object occupies; no
        // erase or write runs concurrently (the store is borrowed).
        let bytes = unsafe { core::slice::from_raw_parts(addr as *const u8, buf.len()) };
        buf.copy_from_slice(bytes);
        Ok(())
    }

    fn erase(&mut self, slot: u8) -> Result<(), FlashError> {
        let addr = self.range(slot, 0, self.size)?;
        let from = addr - FLASH_BASE;
        self.flash.blocking_erase(from, from + self.size as u32).map_err(|_| FlashError::Flash)
    }

    fn write(&mut self, slot: u8, offset: usize, data: &[u8]) -> Result<(), FlashError> {
        let addr = self.range(slot, offset, data.len())?;
        self.flash.blocking_write(addr - FLASH_BASE, data).map_err(|_| FlashError::Flash)
    }
}
