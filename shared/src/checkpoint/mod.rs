//! Saved learning: the weight table and the learner's state in two
//! alternating slots, so that a reset or power cut during a save keeps the
//! last good checkpoint, and a board that resets continues learning where it
//! was.
//!
//! # Slot layout (format 3, little endian)
//!
//! | offset | size | field |
//! |---|---|---|
//! | 0 | 4 | magic `"PDCK"` |
//! | 4 | 2 | format version ([`FORMAT_VERSION`], 3) |
//! | 6 | 2 | header length (32) |
//! | 8 | 4 | configuration hash ([`config_hash`] of the caller's description) |
//! | 12 | 4 | weight count `n` |
//! | 16 | 4 | generation (1 for the first save, +1 per save, wrapping: compared in serial-number arithmetic, [`is_newer`]) |
//! | 20 | 4 | CRC-32 of the payload: the state record and the weights |
//! | 24 | 2 | length `s` of the learner-state record ([`STATE_LEN`], 1024) |
//! | 26 | 2 | bytes `b` per stored weight (4: [`Q16`] as `i32`, 2: 16-bit; [`crate::weights::WeightFormat`]) |
//! | 28 | 4 | CRC-32 of bytes 0–27 |
//! | 32 | s | the learner-state record (below) |
//! | 32 + s | b·n | the weights as the table stores them ([`crate::weights::WeightStore::stored_le`]), little endian |
//! | 32 + s + b·n | 0–3 | zeros up to a multiple of 4 bytes |
//!
//! Format 2 (4-byte weights only, a 4-byte state length at 24) and format 1
//! (weights without the learner's state) are refused as
//! [`LoadOutcome::UnsupportedVersion`]. The weight format is part of the
//! configuration hash too, so a table saved in another format is refused as
//! a configuration mismatch.
//!
//! The header's own CRC covers the payload CRC, so the two CRCs together
//! cover header, state and weights: a flipped bit anywhere makes the slot
//! invalid.
//!
//! # Learner-state record (record version [`STATE_VERSION`], 2)
//!
//! Offsets from the record's start (slot offset 32). Every reserved byte is
//! written 0 and must read 0.
//!
//! | offset | size | field |
//! |---|---|---|
//! | 0 | 2 | record version ([`STATE_VERSION`]) |
//! | 2 | 1 | mode: 0 learning, 1 testing ([`Mode`]) |
//! | 3 | 1 | policy kind built: 0 sarsa, 1 lowpass, 2 markov-lowpass, 3 integrator, 4 markov-integrator, 5 pada ([`kind_code`]) |
//! | 4 | 4 | its parameter, `f32`: α of the low-pass filters, Δ of the others, 0 for SARSA |
//! | 8 | 1 | switched back to SARSA: 0 no, 1 yes |
//! | 9 | 1 | fatigue joints in use `j`, 0–[`MAX_JOINTS`] |
//! | 10 | 4 | previous action: level per action dimension, 4 × `u8` (0 unused) |
//! | 14 | 2 | reserved |
//! | 16 | 16 | previous output (filter/integrator memory), 4 × `f32` (0 unused) |
//! | 32 | 4 | ε, `f32` |
//! | 36 | 4 | last TD error, raw [`Q16`] as `i32` |
//! | 40 | 8 | agent steps (decisions), `u64` |
//! | 48 | 8 | SARSA updates, `u64` |
//! | 56 | 8 | exploratory decisions, `u64` |
//! | 64 | 4 | episodes started, `u32` |
//! | 68 | 4 | weight saturations, `u32` |
//! | 72 | 4 | trace drops, `u32` |
//! | 76 | 4 | reserved |
//! | 80 | 8 | generator state ([`RngState::state`]), `u64` |
//! | 88 | 8 | generator increment ([`RngState::increment`], odd), `u64` |
//! | 96 | 16 | user counters, 4 × `u32` ([`USER_COUNTERS`], the caller's) |
//! | 112 | 48 × 8 | fatigue per joint ([`JointFatigueState`]), [`MAX_JOINTS`] entries, the first `j` in use, the others all 0 |
//!
//! | 496 | 8 | erases of slot 0's and slot 1's sector, 2 × `u32` ([`FlashWear`], written by [`save`]) |
//! | 504 | 8 | operating seconds when saved, `u64` ([`FlashWear::operating_s`]) |
//!
//! Each fatigue entry: +0 last sign (`i8`: −1, 0, +1), +1 seven reserved
//! bytes, +8 steps, +16 re-engagements, +24 damage (Q16.48), +32 window
//! re-engagements, +40 window damage (Q16.48), each a `u64`.
//!
//! The record holds what a learner carries between episodes
//! ([`AgentState`]), not the eligibility trace: restoring ends the episode
//! (see [`crate::agent::Agent::restore_state`]). Decoding
//! ([`LearnerState::from_bytes`]) checks only what the bytes can mean
//! (version, enum codes, flags, reserved zeros); the ranges that depend on
//! the running learner are the restorer's to check
//! ([`crate::agent::Agent::check_state`],
//! [`crate::fatigue::FatigueCounter::check_state`], [`RngState::check`]).
//!
//! # Why a torn write is harmless
//!
//! [`save`] writes into the slot that does *not* hold the newest valid
//! checkpoint: it erases that slot, writes the state record and the weights,
//! and writes the header last. Until the header's last byte (its own CRC) is
//! written the slot has no valid header, so [`load`] ignores it and takes
//! the other slot. An erased slot reads `0xFF`, which never forms a valid
//! header. Every write is 4-byte aligned and a multiple of 4 bytes long,
//! which suits STM32F4 flash programming.
//!
//! [`find`] checks each header's magic, version and CRC, then the payload's
//! CRC, picks the valid slot with the higher generation, and only then
//! compares the configuration hash and size and decodes the state record;
//! [`load`] writes the caller's state and weights only when the outcome is
//! [`LoadOutcome::Loaded`]. A format-1 slot (weights only) is refused as
//! [`LoadOutcome::UnsupportedVersion`] `{ found: 1 }`, never loaded without
//! its state; a record of version 1 (496 bytes, before the flash wear) is
//! refused as [`LoadOutcome::InvalidState`].
//!
//! The newer of two valid slots is the one whose generation is ahead in
//! serial-number arithmetic ([`is_newer`]), so saving goes on past
//! `u32::MAX`. A store too small for a header that reads as erased flash
//! holds no checkpoint ([`LoadOutcome::NoCheckpoint`]).
//!
//! # Flash wear
//!
//! Every record counts the erases of both sectors ([`FlashWear`]): [`save`]
//! takes the newest valid record's counts (whatever its configuration),
//! adds its own erase, and writes them into the record it saves, so the
//! count survives resets, configuration changes and re-flashing. An erase
//! whose save is cut by a power loss is not counted (at most one per power
//! cut). [`save_within`] refuses a save that would take a sector beyond its
//! [`WearBudget`] (module [`wear`]: at most 10 000 erases within ten years
//! of operation).
//!
//! # Modules
//!
//! [`slots`] (header, slot selection, save and load), [`record`] (the
//! learner-state record), [`store`] (the medium), [`wear`] (the erase
//! budget). CRC-32 is [`crate::crc::CRC32`], shared with the telemetry
//! frames.
//!
//! [`Q16`]: crate::fixed::Q16
//! [`Mode`]: crate::agent::Mode
//! [`kind_code`]: crate::policy::kind_code
//! [`AgentState`]: crate::agent::AgentState
//! [`JointFatigueState`]: crate::fatigue::JointFatigueState
//! [`RngState::check`]: crate::rng::RngState::check
//! [`RngState::increment`]: crate::rng::RngState::increment
//! [`RngState::state`]: crate::rng::RngState::state

pub mod record;
pub mod slots;
pub mod store;
pub mod wear;

pub use crate::crc::{config_hash, crc32, ConfigHasher, CRC32};
pub use record::{LearnerState, MAX_JOINTS, STATE_LEN, STATE_VERSION, USER_COUNTERS};
pub use slots::{
    find, inspect, is_newer, load, read_weights, save, save_within, slot_len, stored_wear, Found, Header,
    HeaderError, LoadOutcome, SaveError, Saved, SlotStatus, FORMAT_VERSION, HEADER_LEN, MAGIC, SLOTS,
};
pub use store::{CheckpointStore, OutOfRange, RamStore};
pub use wear::{FlashWear, WearBudget, WearRefusal, SECTOR_ENDURANCE};
