//! Saved learning: the weight table and the learner's state in two
//! alternating slots, so that a reset or power cut during a save keeps the
//! last good checkpoint, and a board that resets continues learning where it
//! was.
//!
//! # Slot layout (format 4, little endian)
//!
//! | offset | size | field |
//! |---|---|---|
//! | 0 | 4 | magic `"PDCK"` |
//! | 4 | 2 | format version ([`FORMAT_VERSION`], 4) |
//! | 6 | 2 | header length (32) |
//! | 8 | 4 | configuration hash ([`config_hash`] of the caller's description) |
//! | 12 | 4 | weight count `n` |
//! | 16 | 4 | generation (1 for the first save, +1 per save, wrapping: compared in serial-number arithmetic, [`is_newer`]) |
//! | 20 | 4 | CRC-32 of the payload: the state record and the weights |
//! | 24 | 2 | length `s` of the learner-state record ([`STATE_LEN`], 1024) |
//! | 26 | 2 | bytes `b` per stored entry: the weight's (4: [`Q16`] as `i32`, 2: 16-bit; [`crate::weights::WeightFormat`]) plus a claim table's tag (2 or 4; [`crate::claim_table`]): 2, 4 or 8 |
//! | 28 | 4 | CRC-32 of bytes 0–27 |
//! | 32 | s | the learner-state record (below) |
//! | 32 + s | b·n | the entries as the table stores them, each its weight then its tag ([`crate::weights::WeightStore::stored_le`]), little endian |
//! | 32 + s + b·n | 0–3 | zeros up to a multiple of 4 bytes |
//!
//! Format 3 (tables without claim tags, with a learner-state record of
//! version 3, which this crate refuses too), format 2
//! (4-byte weights only, a 4-byte state length at 24) and format 1
//! (weights without the learner's state) are refused as
//! [`LoadOutcome::UnsupportedVersion`]. The weight format is part of the
//! configuration hash too, so a table saved in another format is refused as
//! a configuration mismatch.
//!
//! The header's own CRC covers the payload CRC, so the two CRCs together
//! cover header, state and weights: a flipped bit anywhere makes the slot
//! invalid.
//!
//! # Learner-state record
//!
//! The 1024-byte record ([`STATE_LEN`], version [`STATE_VERSION`], 4) at
//! slot offset 32 holds what a learner carries between episodes: the agent's
//! counters, ε, mode and policy, the generator, each joint's fatigue
//! counters, the caller's counters, the flash wear and the wear governor's
//! state. Its layout is documented once, next to its offsets, in
//! [`record`]; a test checks that table against the offsets the code uses.
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
//! its state; a record of version 1 (496 bytes, before the flash wear) or
//! 2 (512 bytes, before the governor) is refused as
//! [`LoadOutcome::InvalidState`], but the wear of a version-2 record is
//! still read ([`stored_wear`]), so re-flashing keeps the erase counts.
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
//! count survives resets, configuration changes and re-flashing. A save
//! that fails after its erase returns the count ([`SaveError::erased`]) for
//! the caller to carry into its next save; an erase whose save is cut by a
//! power loss is not counted (at most one per power cut). A table whose
//! entries a slot cannot store ([`valid_entry_bytes`]) is refused before
//! anything is erased. [`save_within`] refuses a save that would take a
//! sector beyond its [`WearBudget`] (module [`wear`]: at most 10 000
//! erases within ten years of operation).
//!
//! # Modules
//!
//! [`slots`] (header, slot selection, save and load), [`record`] (the
//! learner-state record), [`store`] (the medium), [`wear`] (the erase
//! budget), [`stream`] (a slot's image sent as chunks over a link, for a
//! table that fits no flash). CRC-32 is [`crate::crc::CRC32`], shared with the telemetry
//! frames.
//!
//! [`Q16`]: crate::fixed::Q16

pub mod record;
pub mod slots;
pub mod store;
pub mod stream;
pub mod wear;

pub use crate::crc::{config_hash, crc32, ConfigHasher, CRC32};
pub use record::{LearnerState, RECORD_JOINTS, STATE_LEN, STATE_VERSION, USER_COUNTERS};
pub use slots::{
    find, inspect, is_newer, load, read_weights, save, save_within, slot_len, stored_wear, valid_entry_bytes, Found,
    Header, HeaderError, LoadOutcome, SaveError, Saved, SlotStatus, FORMAT_VERSION, HEADER_LEN, MAGIC, SLOTS,
};
pub use store::{CheckpointStore, OutOfRange, RamStore};
pub use wear::{FlashWear, WearBudget, WearRefusal, SECTOR_ENDURANCE};
