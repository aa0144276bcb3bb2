//! Dynamixel Protocol 1.0 codec and the RX-28 control table.
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
//! # Packet format (Robotis e-Manual, "DYNAMIXEL Protocol 1.0")
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
//! RX-28 control table.

pub mod decoder;
pub mod packet;
pub mod table;

pub use decoder::{DecodeError, Decoder, DecoderStats, Feed, FromRaw, InstructionDecoder, Reply, StatusDecoder};
pub use packet::*;
