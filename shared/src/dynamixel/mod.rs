//! Dynamixel servos: the Protocol 1.0 codec and the RX-28 control table
//! (this module's items, as before), the Protocol 2.0 codec ([`v2`]) and
//! the control tables of the Protocol 2.0 servos pada supports
//! ([`control_table`]: XM430-W350, XL430-W250, XL330-M288, MX-28(2.0)).
//! [`Protocol`] says which protocol a bus or a servo speaks.
//!
//! Pure codec: packets are encoded into caller buffers and decoded from bytes
//! fed one at a time or in chunks; the firmware does the IO (RS-485 half
//! duplex, driver-enable pin, timeouts and retries).
//!
//! Both directions are here, because the host's software-in-the-loop run
//! emulates RX-28 servos: the firmware encodes instruction packets
//! and decodes status packets ([`StatusDecoder`]); the bus emulator decodes
//! instruction packets ([`InstructionDecoder`]) and encodes status packets
//! ([`StatusPacket::encode`]).
//!
//! # Protocol 1.0 packet format (Robotis e-Manual, "DYNAMIXEL Protocol 1.0")
//!
//! ```text
//! instruction: 0xFF 0xFF ID LENGTH INSTRUCTION PARAM_1 … PARAM_N CHECKSUM
//! status:      0xFF 0xFF ID LENGTH ERROR       PARAM_1 … PARAM_N CHECKSUM
//! LENGTH   = N + 2
//! CHECKSUM = !(ID + LENGTH + INSTRUCTION/ERROR + PARAM_1 + … + PARAM_N) (low byte)
//! ```
//!
//! ID 0xFE is the broadcast ID (no servo answers); 0xFF is never an ID, which
//! is what lets a receiver resynchronise on `0xFF 0xFF`. Two-byte values are
//! little endian (low byte at the lower address).
//!
//! # Modules
//!
//! [`packet`]: the checksum, the packets and their encoding, the
//! instruction parser; [`decoder`]: the one incremental decoder of both
//! directions, which never panics and counts every byte it discards
//! (property-tested, and fuzzed by `cargo xtask fuzz`); [`table`]: the
//! RX-28 control table; [`v2`]: Protocol 2.0 (its own module docs);
//! [`control_table`]: the Protocol 2.0 control tables as data, with the
//! value checks a virtual servo makes.

pub mod control_table;
pub mod decoder;
pub mod packet;
pub mod status_packet;
pub mod table;
pub mod v2;

/// The Dynamixel protocol a servo or a bus speaks. Both use the same
/// half-duplex serial line; their packets differ in header, length field
/// and check (Protocol 1.0: `FF FF`, 8-bit LENGTH, checksum; Protocol 2.0:
/// `FF FF FD 00`, 16-bit LENGTH, CRC-16 and byte stuffing).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[derive(serde::Serialize, serde::Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Protocol {
    /// Protocol 1.0 (RX, AX, MX on 1.0 firmware): [`packet`], [`decoder`].
    V1,
    /// Protocol 2.0 (X series, MX(2.0), P series): [`v2`].
    V2,
    /// Feetech's SCS/STS protocol: Protocol 1.0's framing with Feetech's
    /// instruction table and byte orders ([`crate::feetech`]).
    Feetech,
}

pub use decoder::{DecodeError, Decoder, DecoderStats, Feed, FromRaw, InstructionDecoder, Reply, StatusDecoder};
pub use packet::*;
