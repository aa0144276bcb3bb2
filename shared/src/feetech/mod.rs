//! Feetech's serial-bus servo protocol (the SCS and STS/SMS series; the
//! STS3215 of the SO-100/SO-101 arm): packets, instructions, byte orders
//! and sign-magnitude values, and the STS3215's memory map as data
//! ([`control_table`]). Sources: docs/reference/feetech.md, which cites
//! Feetech's memory-table document and SDK, LeRobot's and rustypot's
//! tables, for each rule.
//!
//! # One framing with Dynamixel Protocol 1.0
//!
//! ```text
//! instruction: 0xFF 0xFF ID LENGTH INSTRUCTION PARAM_1 … PARAM_N CHECKSUM
//! status:      0xFF 0xFF ID LENGTH ERROR       PARAM_1 … PARAM_N CHECKSUM
//! LENGTH   = N + 2
//! CHECKSUM = !(ID + LENGTH + INSTRUCTION/ERROR + PARAM_1 + … + PARAM_N) (low byte)
//! ```
//!
//! This is Dynamixel Protocol 1.0's framing to the byte, so the packets,
//! their encoding, the checksum and the decoders are Protocol 1.0's
//! ([`crate::dynamixel`], on the shared skeleton [`crate::framing`]),
//! re-exported here: a Feetech bus and a Protocol 1.0 bus are decoded by
//! the same code. What is Feetech's own:
//!
//! - the instruction table ([`instruction`]): Protocol 1.0's rows but
//!   BULK READ, and SYNC READ (0x82), which each addressed servo answers
//!   with an ordinary status packet, in the order of the IDs;
//! - the byte order of two-byte values ([`ByteOrder`]): little endian on
//!   the STS/SMS series, big endian on the SCS series (Feetech's SDK
//!   switches on it, `SCS_END`; the STS memory table's address 2 reads 0
//!   for little endian);
//! - sign-magnitude values ([`value`]): a sign bit, not two's complement
//!   (bit 15 for speeds and positions, bit 11 for the homing offset,
//!   bit 10 for the load);
//! - the meaning of the status packet's ERROR bits ([`status`]);
//! - the memory maps ([`control_table`]);
//! - the present block a controller reads ([`present`]) and the command
//!   block it writes ([`command`]) every period.
//!
//! # A firmware bus task, in outline
//!
//! ```
//! use pada_core::feetech::{self, control_table::sts3215 as sts, ByteOrder};
//!
//! let mut tx = [0u8; 64];
//! // Every joint's Goal Position in one packet (no reply).
//! let goal = |counts: u16| ByteOrder::Little.u16_bytes(counts);
//! let pkt = feetech::sync_write(sts::GOAL_POSITION, 2, &[(1, &goal(2048)), (2, &goal(1000))], &mut tx).unwrap();
//! assert_eq!(pkt[2], feetech::BROADCAST_ID);
//! // Every joint's position in one SYNC READ: one status packet per servo.
//! let pkt = feetech::sync_read(sts::PRESENT_POSITION, 2, &[1, 2], &mut tx).unwrap();
//! assert_eq!(pkt[4], 0x82);
//! let mut rx = feetech::StatusDecoder::<64>::new();
//! rx.expect(Some(feetech::Reply { id: 1, params: 2 }));
//! # let reply = feetech::StatusPacket::<64>::new(1, feetech::ErrorFlags::NONE, &[0x00, 0x08]).unwrap();
//! # let mut wire = [0u8; 16];
//! # let bytes = reply.encode(&mut wire).unwrap();
//! let packet = rx.feed(bytes).next().unwrap().unwrap();
//! assert_eq!(ByteOrder::Little.u16_at(&packet.params, 0), Some(2048));
//! ```

pub mod command;
pub mod control_table;
pub mod instruction;
pub mod present;
pub mod status;
pub mod value;

pub use crate::dynamixel::{
    action, checksum, ping, read_data, reg_write, sync_write, write_data, DecodeError, Decoder, DecoderStats, EncodeError,
    ErrorFlags, Feed, InstructionDecoder, InstructionPacket, Reply, StatusDecoder, StatusPacket, BROADCAST_ID,
    DEFAULT_PACKET_LEN, HEADER, MAX_PARAMS, OVERHEAD,
};
pub use command::Command;
pub use instruction::{sync_read, Instruction, InstructionError};
pub use present::present;
pub use status::ServoStatus;
pub use value::ByteOrder;

/// The highest ID of a servo (0–253; Feetech's memory table: "0 ~ 253").
pub const MAX_ID: u8 = 0xFD;
