//! The telemetry and command protocol between the chip and the host.
//!
//! Both ends import these types, so the host decodes exactly what the chip
//! encodes (the layout of postcard-rpc's "icd" crates). The host's own
//! simulation runs speak the same format, so one capture path serves
//! simulation, emulation and hardware.
//!
//! # Messages
//!
//! | message | direction | payload | when |
//! |---|---|---|---|
//! | [`ToHost::Hello`] | chip → host | [`Hello`] | at boot and in answer to `Ping` |
//! | [`ToHost::Step`] | chip → host | [`Step`] | every control period |
//! | [`ToHost::Episode`] | chip → host | [`Episode`] | at the end of every episode |
//! | [`ToHost::Health`] | chip → host | [`Health`] | periodically |
//! | [`ToHost::State`] | chip → host | [`StateChange`] | on every safety state change |
//! | [`ToHost::Fault`] | chip → host | [`Fault`] | on entering Fault |
//! | [`ToHost::Checkpoint`] | chip → host | [`CheckpointReport`] | after a save or load |
//! | [`ToHost::Log`] | chip → host | [`Log`] | free text |
//! | [`ToHost::Warning`] | chip → host | [`Warning`] | e.g. a checkpoint ignored at boot |
//! | [`ToHost::Weights`] | chip → host | [`WeightsChunk`] | in answer to `ReadWeights` |
//! | [`ToHost::Ack`] | chip → host | [`Ack`] | a command was carried out |
//! | [`ToHost::Nack`] | chip → host | [`Nack`] | a command was refused |
//! | [`ToHost::Policy`] | chip → host | [`PolicyReport`] | after `Hello`, whenever the policy or its α/Δ changes, and after every episode while a wear governor runs |
//! | [`ToHost::CheckpointChunk`] | chip → host | [`Chunk`](crate::checkpoint::stream::Chunk) | a save of a checkpoint the host keeps (no flash holds it), body first, header last |
//! | [`ToHost::RestoreWanted`] | chip → host | [`RestoreRequest`] | at boot, and after each batch of a restore |
//! | [`ToHost::Restored`] | chip → host | [`RestoreOutcome`] | the restore's end: loaded, or fresh and why |
//! | [`ToChip::Ping`] | host → chip | — | answered by `Hello` |
//! | [`ToChip::Start`] | host → chip | [`RunMode`] | learn or test, torque on |
//! | [`ToChip::Stop`] | host → chip | — | to Idle, torque off |
//! | [`ToChip::Pause`] | host → chip | — | to Paused, torque off |
//! | [`ToChip::SetPolicy`] | host → chip | [`PolicySpec`] | one of the policies and its parameters |
//! | [`ToChip::SwitchToSarsa`] | host → chip | — | end of the exploration phase (Section VIII) |
//! | [`ToChip::SetEpsilon`] | host → chip | `f32` | exploration rate |
//! | [`ToChip::SaveCheckpoint`] | host → chip | — | weights and learner state to flash |
//! | [`ToChip::LoadCheckpoint`] | host → chip | — | weights and learner state from flash |
//! | [`ToChip::ReadWeights`] | host → chip | offset `u32`, count `u32` | answered by `Weights` chunks |
//! | [`ToChip::ClearFault`] | host → chip | — | Fault → Idle |
//! | [`ToChip::SetMtbfBudget`] | host → chip | `Option<f32>` | start (or stop) the wear governor with this MTBF budget \[s\] |
//! | [`ToChip::RestoreChunk`] | host → chip | [`Chunk`](crate::checkpoint::stream::Chunk) | up to [`RESTORE_BATCH`] per `RestoreWanted`, header first |
//! | [`ToChip::RestoreNone`] | host → chip | [`RestoreDenied`] | the host keeps no checkpoint for this board |
//!
//! Every command is answered by exactly one `Ack` or `Nack` carrying the
//! command frame's sequence number, after any data it asks for (`Hello`,
//! `Weights`, `Checkpoint`); the restore's answers (`RestoreChunk`,
//! `RestoreNone`) are not commands and are not acknowledged: the board's
//! next `RestoreWanted` or its `Restored` is the answer.
//!
//! # Frames ([`frame`])
//!
//! ```text
//! frame   = COBS( body ‖ crc32_le(body) ) ‖ 0x00
//! body    = postcard( (seq: u32, message: ToHost | ToChip) )
//!           seq: varint, 1–5 bytes; message: variant index (varint) then fields
//! crc32   = CRC-32/ISO-HDLC of body, 4 bytes little endian
//! ```
//!
//! Each direction numbers its frames 0, 1, 2, … (wrapping); the receiver
//! counts a gap whenever a sequence number is not the one expected, and
//! a jump of more than [`MAX_SEQ_GAP`] as a resynchronisation rather than
//! as frames missed. COBS removes every 0x00 from the frame, so 0x00 only
//! ever delimits frames: a receiver that joins mid-stream or sees garbage
//! loses at most the frame in progress and resynchronises at the next
//! 0x00. [`FrameDecoder`] counts every loss in [`LinkStats`], once, and
//! [`FrameDecoder::finish`] counts a frame cut off by the end of the input.
//! Only canonical frames are accepted: an accepted frame re-encodes to the
//! bytes received. A frame's body is at most [`MAX_BODY`] bytes and a
//! frame on the wire at most [`MAX_FRAME_LEN`].
//!
//! The messages are in [`messages`], the framing in [`frame`] (the SIL
//! clock link reuses the framing with messages of its own); the CRC-32 is
//! [`crate::crc::CRC32`], shared with the checkpoints.

pub mod frame;
pub mod messages;

pub use frame::{
    cobs_max_len, encode_frame, hello_protocol, ChipDecoder, Decoded, FrameDecoder, FrameEncoder, FrameError, FrameFeed, HostDecoder,
    LinkStats, SeqGap, WireError, CRC_LEN, MAX_BODY, MAX_FRAME_LEN, MAX_SEQ_GAP,
};
pub use messages::*;
