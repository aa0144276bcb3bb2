//! Dynamixel transactions on a [`BusPort`], in the protocol each servo
//! speaks, with bounded timeouts and retries.
//!
//! The packets come from `pada_core::dynamixel` (Protocol 1.0),
//! `pada_core::dynamixel::v2` (Protocol 2.0) and `pada_core::feetech`
//! (Feetech, on Protocol 1.0's framing); this module adds the
//! conversation: send an instruction, listen for the status packet of the
//! servo that was asked until a deadline, retry a bounded number of times,
//! and report every timeout, checksum error, error bit and hardware alert
//! so the safety machine can count them (`pada_core::safety`).
//!
//! | file | its one job |
//! |---|---|
//! | `mod.rs` | the bus: its port, decoders, buffers, timing and counters |
//! | `v1.rs` | Protocol 1.0 (RX-28, MX-28): READ, PING, WRITE, SYNC_WRITE of Moving Speed, wheel-mode set-up |
//! | `v2.rs` | Protocol 2.0 (X series): PING, READ, WRITE, SYNC_WRITE of Goal PWM, (fast) sync read of the present block, PWM-mode set-up, the Bus Watchdog |
//! | `ft.rs` | Feetech (STS series) on Protocol 1.0's framing and transactions: SYNC READ of the present block, SYNC WRITE of torque and command, the set-up |
//! | `parts.rs` | the interface of one protocol's part of a robot's bus (stop, set up, read, write), and its implementations |
//! | `robot.rs` | one robot's period on the bus: every joint read and commanded in its servo's protocol, the sensor device, the boot |
//! | `timing.rs` | the bytes each period's transactions put on the wire, and their time at a baud rate |
//!
//! The same code runs on the chip (embassy, its USART) and on a PC (`pada
//! drive`, a USB serial adapter), whose port blocks instead of awaiting.

pub mod ft;
pub mod parts;
mod v1;
pub mod robot;
pub mod timing;
pub mod v2;

pub use robot::{OperatorCall, RobotBus};

use crate::io::{BusPort, PortError};
use pada_core::dynamixel::control_table::x_series::HardwareError;
use pada_core::dynamixel::{v2 as dxl2, ErrorFlags, StatusDecoder, StatusPacket};
use pada_core::servo::Present;

/// Longest Protocol 1.0 status packet the firmware reads (header to
/// checksum).
pub const STATUS_LEN: usize = 32;
/// A Protocol 1.0 status packet as the bus returns it.
pub type Status = StatusPacket<STATUS_LEN>;
/// Longest Protocol 2.0 status packet the firmware reads: the fast sync
/// read's reply of every servo's present block (`v2::fast_reply_len`),
/// checked at build time in `v2.rs`.
pub const STATUS2_LEN: usize = dxl2::DEFAULT_PACKET_LEN;
/// A Protocol 2.0 status packet as the bus returns it.
pub type Status2 = dxl2::StatusPacket<STATUS2_LEN>;

/// Return delay the servos are set to: 25 × 2 µs = 50 µs, time for the
/// driver-enable line to drop after the last stop bit (both protocols
/// count in 2 µs).
pub const RETURN_DELAY: u8 = 25;
/// Status return level: answer READ (and PING) only, so WRITE and
/// SYNC_WRITE never put a reply on the bus (value 1 in both protocols).
pub const STATUS_RETURN_LEVEL: u8 = 1;

/// Timing of the conversation.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct BusConfig {
    /// How long to wait for a status packet after the instruction \[µs\]
    /// (Protocol 1.0: the whole wait; Protocol 2.0: beyond the reply's own
    /// bytes, see `byte_us`).
    pub reply_timeout_us: u32,
    /// Attempts per request within one control period (1 + retries).
    pub attempts: u8,
    /// Time of one byte on the wire \[µs\] (10 bits at the baud rate: 10 at
    /// 1 Mbps): a Protocol 2.0 request also waits for the bytes of the
    /// reply it expects, whose length grows with the servos a sync read
    /// asks.
    pub byte_us: u32,
}

impl Default for BusConfig {
    fn default() -> Self {
        BusConfig { reply_timeout_us: 1000, attempts: 2, byte_us: 10 }
    }
}

/// Counters for health telemetry.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct BusStats {
    /// Instruction packets sent.
    pub requests: u32,
    /// Status packets received from the servo asked.
    pub replies: u32,
    /// Attempts without an answer before the deadline.
    pub timeouts: u32,
    /// Status packets with a bad checksum (or CRC).
    pub checksum_errors: u32,
    /// Status packets from another ID, or with an impossible length.
    pub stray_packets: u32,
    /// UART errors (overrun, framing, noise).
    pub line_errors: u32,
}

/// What one request to one servo came to, with everything the safety
/// machine counts.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Exchange {
    /// The servo's answer, if one came.
    pub status: Option<Status>,
    /// Attempts that ended without an answer.
    pub timeouts: u8,
    /// Bad checksums seen (received status packets).
    pub checksum_errors: u8,
}

impl Exchange {
    /// The servo's error bits (empty without an answer).
    pub fn error(&self) -> ErrorFlags {
        self.status.as_ref().map_or(ErrorFlags::NONE, |s| s.error)
    }
}

/// One servo's part of a period's readings (what [`RobotBus::read`]
/// gives the controller; `crate::control` re-exports it).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct ServoRead {
    /// Present Position … Temperature in its model's units, if the servo
    /// answered.
    pub state: Option<Present>,
    /// Error bits of its answer (a Protocol 2.0 Error Number as Protocol
    /// 1.0's bits: [`v2::flags_of`]).
    pub error: ErrorFlags,
    /// A Protocol 2.0 servo's Alert: its Hardware Error Status (empty if
    /// that read failed); `None` without an alert.
    pub hardware_error: Option<HardwareError>,
    /// Attempts that got no answer.
    pub timeouts: u8,
    /// Answers with a bad checksum.
    pub checksum_errors: u8,
}

/// One servo's settings that the firmware relies on.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ServoSetup {
    /// Model number (28 for an RX-28, 1020 for an XM430-W350).
    pub model: u16,
    /// Firmware version (Protocol 2.0's PING; 0 where not read).
    pub firmware: u8,
    /// Whether anything had to be written (EEPROM writes are counted: they
    /// wear the servo's EEPROM, so only differences are written).
    pub wrote: bool,
}

/// Why a servo could not be set up.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SetupError {
    /// It did not answer.
    NoAnswer {
        /// Dynamixel ID.
        id: u8,
    },
    /// It answered with error bits (Protocol 1.0) or an error number or
    /// alert (Protocol 2.0, as Protocol 1.0's bits; [`v2::flags_of`]).
    Error {
        /// Dynamixel ID.
        id: u8,
        /// The bits.
        error: ErrorFlags,
    },
    /// A Protocol 2.0 servo raised its Alert bit: a hardware error, which
    /// only a reboot clears.
    Alert {
        /// Dynamixel ID.
        id: u8,
        /// Its Hardware Error Status.
        error: HardwareError,
    },
    /// It is another model than the robot's definition names.
    WrongModel {
        /// Dynamixel ID.
        id: u8,
        /// The model number it reported.
        found: u16,
        /// The model number of the definition's servo.
        expected: u16,
    },
}

/// The servo bus: a port, a decoder per protocol, the buffers and the
/// counters.
pub struct ServoBus<P> {
    port: P,
    config: BusConfig,
    decoder: StatusDecoder<STATUS_LEN>,
    decoder2: dxl2::StatusDecoder<STATUS2_LEN>,
    tx: [u8; 64],
    rx: [u8; 64],
    stats: BusStats,
}

impl<P: BusPort> ServoBus<P> {
    /// A bus on `port`.
    pub fn new(port: P, config: BusConfig) -> Self {
        ServoBus {
            port,
            config,
            decoder: StatusDecoder::new(),
            decoder2: dxl2::StatusDecoder::new(),
            tx: [0; 64],
            rx: [0; 64],
            stats: BusStats::default(),
        }
    }

    /// Counters since start.
    pub fn stats(&self) -> BusStats {
        self.stats
    }

    /// The timing in force.
    pub fn config(&self) -> BusConfig {
        self.config
    }

    /// The port (for the board's own checks).
    pub fn port_mut(&mut self) -> &mut P {
        &mut self.port
    }

    /// Waits until `deadline` (µs) for bytes into the receive buffer: how
    /// many came, or `None` at the deadline or on a line error (counted).
    async fn receive(&mut self, deadline: u64) -> Option<usize> {
        match self.port.receive(&mut self.rx, deadline).await {
            Ok(0) => None,
            Ok(got) => Some(got),
            Err(_) => {
                self.stats.line_errors = self.stats.line_errors.wrapping_add(1);
                None
            }
        }
    }

    /// Sends the first `n` bytes of the transmit buffer.
    async fn send(&mut self, n: usize) -> Result<(), PortError> {
        self.stats.requests = self.stats.requests.wrapping_add(1);
        let result = self.port.send(&self.tx[..n]).await;
        if result.is_err() {
            self.stats.line_errors = self.stats.line_errors.wrapping_add(1);
        }
        result
    }
}

/// The wire of the tests' fake buses: answers waiting in `inbox` are
/// handed out in chunks of at most `chunk` bytes, at 10 µs a byte; with
/// none, the clock `now` jumps to the deadline.
#[cfg(test)]
pub(crate) fn fake_receive(inbox: &mut std::collections::VecDeque<u8>, now: &mut u64, buf: &mut [u8], deadline_us: u64, chunk: usize) -> usize {
    if inbox.is_empty() {
        *now = (*now).max(deadline_us);
        return 0;
    }
    let n = buf.len().min(inbox.len()).min(chunk);
    for (b, byte) in buf.iter_mut().zip(inbox.drain(..n)) {
        *b = byte;
    }
    *now += n as u64 * 10;
    n
}
