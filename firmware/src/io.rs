//! What a board provides: the seams between the firmware's logic and the
//! peripherals.
//!
//! The real board (`src/board/`) implements these with embassy-stm32
//! drivers; the emulated board (QEMU, `pada sil`) implements them with a few PAC
//! register accesses and a lock-step clock; the host tests implement them
//! with byte buffers. Everything above them is the same code.

/// An error of a serial port.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PortError {
    /// The receiver lost bytes (overrun) or saw a framing, noise or parity
    /// error; the bytes of this exchange are unreliable.
    Line,
    /// The transmitter failed (DMA error).
    Transmit,
}

/// The half-duplex servo bus (RS-485 with a driver-enable line, or TTL
/// single wire): send a frame, then listen.
pub trait BusPort {
    /// Drops every byte received so far (a late reply, noise).
    fn discard_input(&mut self);

    /// Transmits `bytes` with the driver enabled and returns once the last
    /// stop bit has left the wire, with the driver disabled again, so that
    /// the servo's reply is not talked over.
    async fn send(&mut self, bytes: &[u8]) -> Result<(), PortError>;

    /// Waits at most until `deadline_us` (on [`BusPort::now_us`]'s clock)
    /// for received bytes and copies what is there into `buf`; returns 0 at
    /// the deadline.
    async fn receive(&mut self, buf: &mut [u8], deadline_us: u64) -> Result<usize, PortError>;

    /// Microseconds on the clock the deadlines refer to (monotonic).
    fn now_us(&self) -> u64;
}

/// The quadrature encoder of the torso (LEO's boom) or of the pendulum's
/// axis, and LEO's foot contacts: the sensors that are not on the servo bus.
///
/// On the real board the encoder is a timer in encoder mode and the contacts
/// are GPIO inputs; on the emulated board (QEMU) they are a device on the
/// emulated bus. Hence `async`.
pub trait Sensors {
    /// The encoder's counter (it wraps; [`crate::encoder::Unwrapper`]
    /// tracks whole turns), or `None` if it could not be read.
    async fn encoder_count(&mut self) -> Option<u16>;

    /// Foot contacts as a bit set of `pada_core::robot::leo::contact` bits (toe R,
    /// heel R, toe L, heel L); 0 on a robot without them.
    async fn contacts(&mut self) -> u8;
}

/// A free-running cycle counter (the Cortex-M DWT's CYCCNT on the chip).
pub trait CycleCounter {
    /// The counter; wraps at 2³².
    fn cycles(&self) -> u32;
}

/// A sink for telemetry bytes.
pub trait ByteSink {
    /// Writes all of `bytes`.
    async fn write_all(&mut self, bytes: &[u8]) -> Result<(), PortError>;
}

/// A source of command bytes from the host.
pub trait ByteSource {
    /// Waits for bytes and copies what is there into `buf` (at least one).
    async fn read(&mut self, buf: &mut [u8]) -> Result<usize, PortError>;
}
