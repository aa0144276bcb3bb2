//! Dynamixel Protocol 2.0, the protocol of every Dynamixel on sale (X
//! series, MX series on 2.0 firmware, P series): packets, byte stuffing,
//! CRC-16, every instruction in both directions, the combined reply of the
//! fast reads, and the incremental decoders. Control tables are
//! [`super::control_table`]. Sources: docs/reference/dynamixel.md, which
//! cites the e-Manual page of each rule.
//!
//! # Why hand-written
//!
//! pada-core is `no_std` and allocation-free, and its codecs must never
//! panic on bytes from the bus and must count every byte they discard
//! (the 1.0 codec's contract, [`super::decoder`]). The released
//! `dynamixel2` crate (0.9) needs `std` (its `no_std` support is not
//! released, and a git dependency cannot be fetched here), and `rustypot`
//! is `std`-only too; neither exposes a byte-accounting decoder or the
//! servo's side (parsing instructions, building replies) that the bus
//! emulator needs. So this module is written here from the e-Manual, with
//! the `crc` crate (already a dependency) for the CRC-16: the
//! e-Manual's algorithm is the catalogued CRC-16/UMTS. The ROBOTIS SDK's
//! `protocol2_packet_handler` was read to cross-check the reading of the
//! e-Manual (stuffing range, fast-reply framing); no code was taken.
//!
//! # Packet format (e-Manual, "DYNAMIXEL Protocol 2.0")
//!
//! ```text
//! instruction: FF FF FD 00  ID  LEN_L LEN_H  INSTRUCTION        PARAMS…  CRC_L CRC_H
//! status:      FF FF FD 00  ID  LEN_L LEN_H  0x55        ERROR  PARAMS…  CRC_L CRC_H
//! ```
//!
//! - ID 0–252 is a servo, 0xFE the broadcast ID; 0xFD and 0xFF are never
//!   IDs.
//! - LENGTH (16 bits, little endian) counts INSTRUCTION to the CRC, after
//!   byte stuffing ([`stuffing`]): `FF FF FD` inside the payload is sent
//!   as `FF FF FD FD`.
//! - CRC: CRC-16, polynomial 0x8005, over everything before it ([`crc`]).
//! - ERROR: bit 7 Alert (read Hardware Error Status), bits 0–6 the Error
//!   Number ([`status`]).
//! - Multi-byte values are little endian; addresses and lengths are 16
//!   bits.
//!
//! # Modules
//!
//! - [`crc`]: the CRC-16;
//! - [`stuffing`]: byte stuffing and its removal;
//! - [`packet`]: the frame writer, [`StatusPacket`], [`InstructionPacket`];
//! - [`status`]: the ERROR byte, the PING reply;
//! - [`instruction`]: [`Instruction`], parsed and encoded both ways, with
//!   the table of instructions;
//! - [`encoders`]: the master's encoders from typed values;
//! - [`fast`]: the Fast Sync/Bulk Read combined reply, read and built;
//! - [`decoder`]: [`StatusDecoder`] and [`InstructionDecoder`], which never
//!   panic and count every byte they discard (property-tested, and fuzzed
//!   by `cargo xtask fuzz`).
//!
//! # A firmware bus task, in outline
//!
//! ```
//! use pada_core::dynamixel::control_table::x_series::{GOAL_PWM, PRESENT_POSITION};
//! use pada_core::dynamixel::v2::*;
//!
//! let mut tx = [0u8; 64];
//! // Every joint's Goal PWM in one packet (no reply).
//! let pkt = encoders::sync_write_values(GOAL_PWM, &[(1, 300i16.to_le_bytes()), (2, (-300i16).to_le_bytes())], &mut tx).unwrap();
//! assert_eq!(pkt[4], BROADCAST_ID);
//! // Every joint's position in one combined reply.
//! let ids = [1, 2];
//! encoders::fast_sync_read(PRESENT_POSITION, 4, &ids, &mut tx).unwrap();
//! let mut rx = StatusDecoder::<64>::new();
//! rx.expect(Some(Reply::status(BROADCAST_ID, fast::fast_sync_reply_params(ids.len(), 4).unwrap())));
//! // … feed the bytes received, then:
//! # let reply = StatusPacket::<64>::fast_reply(&[
//! #     fast::FastBlock { id: 1, error: StatusError::NONE, data: &[0, 8, 0, 0] },
//! #     fast::FastBlock { id: 2, error: StatusError::NONE, data: &[0, 4, 0, 0] },
//! # ]).unwrap();
//! # let mut wire = [0u8; 64];
//! # let bytes = reply.encode(&mut wire).unwrap();
//! let packet = rx.feed(bytes).next().unwrap().unwrap();
//! for block in packet.fast_blocks(fast::BlockLens::Uniform(4)) {
//!     let block = block.unwrap();
//!     let position = i32::from_le_bytes(block.data.try_into().unwrap());
//!     assert!(block.error.succeeded() && position > 0);
//! }
//! ```

pub mod crc;
pub mod decoder;
pub mod encoders;
pub mod fast;
pub mod instruction;
pub mod packet;
pub mod status;
pub mod stuffing;

pub use decoder::{DecodeError, Decoder, DecoderStats, Feed, FromFrame, InstructionDecoder, Reply, StatusDecoder};
pub use instruction::{BulkReadEntry, BulkWriteEntry, Instruction, InstructionCode, InstructionError, ResetMode};
pub use packet::{
    EncodeError, InstructionPacket, StatusPacket, BROADCAST_ID, DEFAULT_PACKET_LEN, HEADER, INSTRUCTION_OVERHEAD,
    MAX_ID, STATUS, STATUS_OVERHEAD,
};
pub use status::{ErrorNumber, PingReply, StatusError};
