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
//! | 16 | 4 | generation (1 for the first save, +1 per save) |
//! | 20 | 4 | CRC-32 of the payload: the state record and the weights |
//! | 24 | 2 | length `s` of the learner-state record ([`STATE_LEN`], 496) |
//! | 26 | 2 | bytes `b` per stored weight (4: [`Q16`] as `i32`, 2: 16-bit, [`crate::weights::WeightFormat`]) |
//! | 28 | 4 | CRC-32 of bytes 0–27 |
//! | 32 | s | the learner-state record (below) |
//! | 32 + s | b·n | the weights as the table stores them ([`WeightStore::stored_le`]), little endian |
//! | 32 + s + b·n | 0–3 | zeros up to a multiple of 4 bytes |
//!
//! Format 2 (4-byte weights only, a 4-byte state length at 24) and format
//! 1 (weights without the learner's state) are refused as
//! [`LoadOutcome::UnsupportedVersion`]. The weight format itself is part of
//! the configuration hash, so a table saved in another format is refused as
//! a configuration mismatch.
//!
//! The header's own CRC covers the payload CRC, so the two CRCs together
//! cover header, state and weights: a flipped bit anywhere makes the slot
//! invalid.
//!
//! # Learner-state record (record version [`STATE_VERSION`], 1)
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
//! its state.
//!
//! CRC-32 is CRC-32/ISO-HDLC (the zlib/Ethernet CRC) from the `crc` crate,
//! one 1 KB table in flash, shared with the telemetry frames.

use crate::action_space::MAX_ACTION_DIMS;
use crate::agent::{AgentState, AgentStats, Mode};
use crate::error::ConfigError;
use crate::fatigue::JointFatigueState;
use crate::fixed::Q16;
use crate::policy::{kind_code, kind_from_code, kind_parameter, PolicyKind, PolicyState};
use crate::rng::RngState;
use crate::weights::WeightStore;
use heapless::Vec;

/// CRC-32/ISO-HDLC (polynomial 0x04C11DB7 reflected, init and xor-out
/// 0xFFFFFFFF), used by checkpoints and telemetry frames.
pub static CRC32: crc::Crc<u32> = crc::Crc::<u32>::new(&crc::CRC_32_ISO_HDLC);

/// CRC-32 of `bytes` (see [`CRC32`]).
pub fn crc32(bytes: &[u8]) -> u32 {
    CRC32.checksum(bytes)
}

/// `"PDCK"` read as a little-endian `u32`.
pub const MAGIC: u32 = u32::from_le_bytes(*b"PDCK");
/// The format version this code writes and reads (1 held weights only).
pub const FORMAT_VERSION: u16 = 3;
/// Bytes of the header.
pub const HEADER_LEN: usize = 32;
/// Version of the learner-state record this code writes and reads.
pub const STATE_VERSION: u16 = 1;
/// Bytes of the learner-state record (a multiple of 4).
pub const STATE_LEN: usize = 496;
/// Fatigue joints the state record has room for.
pub const MAX_JOINTS: usize = 8;
/// Counters the state record keeps for the caller ([`LearnerState::user`]).
pub const USER_COUNTERS: usize = 4;
/// Number of slots.
pub const SLOTS: u8 = 2;

/// Offsets in the state record (see the module documentation).
mod at {
    pub const VERSION: usize = 0;
    pub const MODE: usize = 2;
    pub const KIND: usize = 3;
    pub const PARAMETER: usize = 4;
    pub const SWITCHED: usize = 8;
    pub const JOINTS: usize = 9;
    pub const PREVIOUS: usize = 10;
    pub const RESERVED_A: usize = 14;
    pub const OUTPUT: usize = 16;
    pub const EPSILON: usize = 32;
    pub const TD_ERROR: usize = 36;
    pub const STEPS: usize = 40;
    pub const UPDATES: usize = 48;
    pub const EXPLORATIONS: usize = 56;
    pub const EPISODES: usize = 64;
    pub const SATURATIONS: usize = 68;
    pub const TRACE_DROPS: usize = 72;
    pub const RESERVED_B: usize = 76;
    pub const RNG_STATE: usize = 80;
    pub const RNG_INCREMENT: usize = 88;
    pub const USER: usize = 96;
    pub const FATIGUE: usize = 112;
    /// Bytes per fatigue entry.
    pub const JOINT_LEN: usize = 48;
}

const _: () = assert!(at::FATIGUE + MAX_JOINTS * at::JOINT_LEN == STATE_LEN);
// The record has four action dimensions: previous levels and outputs.
const _: () = assert!(MAX_ACTION_DIMS == 4 && at::PREVIOUS + MAX_ACTION_DIMS <= at::RESERVED_A);
const _: () = assert!(at::OUTPUT + 4 * MAX_ACTION_DIMS == at::EPSILON);
const _: () = assert!(STATE_LEN % 4 == 0);
const _: () = assert!(at::USER + 4 * USER_COUNTERS == at::FATIGUE);

/// Bytes a slot needs for `weights` weights of `weight_bytes` bytes each
/// (header, state record, weights padded to a multiple of 4).
pub const fn slot_len(weights: usize, weight_bytes: usize) -> usize {
    HEADER_LEN + STATE_LEN + (weights * weight_bytes).div_ceil(4) * 4
}

/// Where checkpoints live: two slots of equal size, read and written at byte
/// offsets. On the chip, two flash sectors; in tests, RAM ([`RamStore`]).
pub trait CheckpointStore {
    /// What the medium reports when an operation fails.
    type Error;
    /// Bytes in each slot.
    fn capacity(&self) -> usize;
    /// Reads `buf.len()` bytes of `slot` from `offset`.
    fn read(&self, slot: u8, offset: usize, buf: &mut [u8]) -> Result<(), Self::Error>;
    /// Erases `slot` (to `0xFF`, as flash).
    fn erase(&mut self, slot: u8) -> Result<(), Self::Error>;
    /// Writes `data` into `slot` at `offset` (only erased bytes are written).
    fn write(&mut self, slot: u8, offset: usize, data: &[u8]) -> Result<(), Self::Error>;
}

/// The header of a checkpoint.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[derive(serde::Serialize, serde::Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Header {
    /// Format version.
    pub version: u16,
    /// Hash of the configuration the weights were learned with.
    pub config_hash: u32,
    /// Number of weights in the payload.
    pub weight_count: u32,
    /// Save counter: the newer of two valid slots has the higher one.
    pub generation: u32,
    /// CRC-32 of the payload bytes (state record and weights).
    pub payload_crc: u32,
    /// Bytes of the learner-state record ([`STATE_LEN`]).
    pub state_len: u32,
    /// Bytes per stored weight (4 or 2).
    pub weight_bytes: u16,
}

/// Why a slot's header is not valid.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[derive(serde::Serialize, serde::Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum HeaderError {
    /// Every byte is `0xFF`: an erased slot.
    Erased,
    /// Wrong magic, header length or header CRC.
    Corrupt,
    /// A valid header of a format this code does not read (1: weights
    /// without the learner's state).
    UnsupportedVersion {
        /// The version found.
        found: u16,
    },
}

impl Header {
    /// The 32 header bytes, CRC included.
    pub fn to_bytes(&self) -> [u8; HEADER_LEN] {
        let mut b = [0u8; HEADER_LEN];
        b[0..4].copy_from_slice(&MAGIC.to_le_bytes());
        b[4..6].copy_from_slice(&self.version.to_le_bytes());
        b[6..8].copy_from_slice(&(HEADER_LEN as u16).to_le_bytes());
        b[8..12].copy_from_slice(&self.config_hash.to_le_bytes());
        b[12..16].copy_from_slice(&self.weight_count.to_le_bytes());
        b[16..20].copy_from_slice(&self.generation.to_le_bytes());
        b[20..24].copy_from_slice(&self.payload_crc.to_le_bytes());
        b[24..26].copy_from_slice(&(self.state_len.min(u16::MAX as u32) as u16).to_le_bytes());
        b[26..28].copy_from_slice(&self.weight_bytes.to_le_bytes());
        let crc = crc32(&b[..28]);
        b[28..32].copy_from_slice(&crc.to_le_bytes());
        b
    }

    /// Parses and checks 32 header bytes.
    pub fn parse(b: &[u8; HEADER_LEN]) -> Result<Header, HeaderError> {
        if b.iter().all(|&x| x == 0xFF) {
            return Err(HeaderError::Erased);
        }
        let u32_at = |i: usize| u32::from_le_bytes([b[i], b[i + 1], b[i + 2], b[i + 3]]);
        let u16_at = |i: usize| u16::from_le_bytes([b[i], b[i + 1]]);
        if u32_at(0) != MAGIC || u16_at(6) as usize != HEADER_LEN || u32_at(28) != crc32(&b[..28]) {
            return Err(HeaderError::Corrupt);
        }
        let version = u16_at(4);
        if version != FORMAT_VERSION {
            return Err(HeaderError::UnsupportedVersion { found: version });
        }
        Ok(Header {
            version,
            config_hash: u32_at(8),
            weight_count: u32_at(12),
            generation: u32_at(16),
            payload_crc: u32_at(20),
            state_len: u16_at(24) as u32,
            weight_bytes: u16_at(26),
        })
    }

    /// Bytes of the slot this header describes, if that fits a `usize`.
    fn slot_bytes(&self) -> Option<usize> {
        if !matches!(self.weight_bytes, 2 | 4) {
            return None;
        }
        (self.weight_count as usize)
            .checked_mul(self.weight_bytes as usize)?
            .checked_next_multiple_of(4)?
            .checked_add(self.state_len as usize)?
            .checked_add(HEADER_LEN)
    }
}

/// Everything a learner saves besides its weights, as plain data with the
/// capacity in the type: the agent's state, the generator, each joint's
/// fatigue counters and a few counters of the caller's. Written and read as
/// the fixed-size record of the module documentation
/// ([`to_bytes`](Self::to_bytes), [`from_bytes`](Self::from_bytes)).
#[derive(Debug, Clone, PartialEq)]
pub struct LearnerState {
    /// Counters, ε, mode and policy ([`crate::agent::Agent::state`]).
    pub agent: AgentState,
    /// The agent's generator ([`crate::rng::Pcg32::state`]).
    pub rng: RngState,
    /// Fatigue counters, one per joint in joint order (at most
    /// [`MAX_JOINTS`]; [`crate::fatigue::FatigueCounter::state`]).
    pub joints: Vec<JointFatigueState, MAX_JOINTS>,
    /// The caller's counters (the firmware: episodes since the first boot,
    /// learning episodes since the last test episode).
    pub user: [u32; USER_COUNTERS],
}

impl Default for LearnerState {
    /// A placeholder to load into: a fresh SARSA agent's counters, no
    /// joints, a zero generator state (whose even increment
    /// [`RngState::check`] refuses).
    fn default() -> Self {
        LearnerState {
            agent: AgentState {
                stats: AgentStats::default(),
                epsilon: 0.0,
                mode: Mode::Learning,
                policy: PolicyState {
                    kind: PolicyKind::Sarsa,
                    switched: false,
                    previous: [0; MAX_ACTION_DIMS],
                    output: [0.0; MAX_ACTION_DIMS],
                },
            },
            rng: RngState::default(),
            joints: Vec::new(),
            user: [0; USER_COUNTERS],
        }
    }
}

/// Little-endian field access in a state record.
struct Record<'a>(&'a [u8; STATE_LEN]);

impl Record<'_> {
    fn u8(&self, i: usize) -> u8 {
        self.0[i]
    }
    fn u16(&self, i: usize) -> u16 {
        u16::from_le_bytes([self.0[i], self.0[i + 1]])
    }
    fn u32(&self, i: usize) -> u32 {
        u32::from_le_bytes([self.0[i], self.0[i + 1], self.0[i + 2], self.0[i + 3]])
    }
    fn u64(&self, i: usize) -> u64 {
        (self.u32(i) as u64) | ((self.u32(i + 4) as u64) << 32)
    }
    fn f32(&self, i: usize) -> f32 {
        f32::from_bits(self.u32(i))
    }
    fn zero(&self, i: usize, len: usize) -> bool {
        self.0[i..i + len].iter().all(|&b| b == 0)
    }
}

fn put(b: &mut [u8; STATE_LEN], i: usize, bytes: &[u8]) {
    b[i..i + bytes.len()].copy_from_slice(bytes);
}

impl LearnerState {
    /// The state record (module documentation), reserved bytes 0.
    pub fn to_bytes(&self) -> [u8; STATE_LEN] {
        let mut b = [0u8; STATE_LEN];
        let a = &self.agent;
        let p = &a.policy;
        put(&mut b, at::VERSION, &STATE_VERSION.to_le_bytes());
        b[at::MODE] = match a.mode {
            Mode::Learning => 0,
            Mode::Testing => 1,
        };
        b[at::KIND] = kind_code(&p.kind);
        put(&mut b, at::PARAMETER, &kind_parameter(&p.kind).to_le_bytes());
        b[at::SWITCHED] = p.switched as u8;
        b[at::JOINTS] = self.joints.len() as u8;
        put(&mut b, at::PREVIOUS, &p.previous);
        for (i, o) in p.output.iter().enumerate() {
            put(&mut b, at::OUTPUT + 4 * i, &o.to_le_bytes());
        }
        put(&mut b, at::EPSILON, &a.epsilon.to_le_bytes());
        put(&mut b, at::TD_ERROR, &a.stats.last_td_error.0.to_le_bytes());
        put(&mut b, at::STEPS, &a.stats.steps.to_le_bytes());
        put(&mut b, at::UPDATES, &a.stats.updates.to_le_bytes());
        put(&mut b, at::EXPLORATIONS, &a.stats.explorations.to_le_bytes());
        put(&mut b, at::EPISODES, &a.stats.episodes.to_le_bytes());
        put(&mut b, at::SATURATIONS, &a.stats.saturations.to_le_bytes());
        put(&mut b, at::TRACE_DROPS, &a.stats.trace_drops.to_le_bytes());
        put(&mut b, at::RNG_STATE, &self.rng.state.to_le_bytes());
        put(&mut b, at::RNG_INCREMENT, &self.rng.increment.to_le_bytes());
        for (i, u) in self.user.iter().enumerate() {
            put(&mut b, at::USER + 4 * i, &u.to_le_bytes());
        }
        for (j, f) in self.joints.iter().enumerate() {
            let o = at::FATIGUE + j * at::JOINT_LEN;
            b[o] = f.last_sign as u8;
            put(&mut b, o + 8, &f.steps.to_le_bytes());
            put(&mut b, o + 16, &f.reengagements.to_le_bytes());
            put(&mut b, o + 24, &f.damage_raw.to_le_bytes());
            put(&mut b, o + 32, &f.window_reengagements.to_le_bytes());
            put(&mut b, o + 40, &f.window_damage_raw.to_le_bytes());
        }
        b
    }

    /// Decodes a state record. Checks what the bytes can mean — the record
    /// version, the mode and policy codes, the switch flag, the joint count,
    /// reserved and unused bytes 0 — and names the field otherwise; ranges
    /// that depend on the running learner are checked when it is restored.
    pub fn from_bytes(bytes: &[u8; STATE_LEN]) -> Result<LearnerState, ConfigError> {
        let r = Record(bytes);
        let version = r.u16(at::VERSION);
        if version != STATE_VERSION {
            return Err(ConfigError::new("state.version", version as f32, "1"));
        }
        let mode = match r.u8(at::MODE) {
            0 => Mode::Learning,
            1 => Mode::Testing,
            m => return Err(ConfigError::new("mode", m as f32, "0 (learning) or 1 (testing)")),
        };
        let code = r.u8(at::KIND);
        let kind = kind_from_code(code, r.f32(at::PARAMETER)).ok_or(ConfigError::new(
            "policy.kind",
            code as f32,
            "0 sarsa, 1 lowpass, 2 markov-lowpass, 3 integrator, 4 markov-integrator, 5 pada",
        ))?;
        if kind == PolicyKind::Sarsa && r.u32(at::PARAMETER) != 0 {
            return Err(ConfigError::new("policy.parameter", r.f32(at::PARAMETER), "0 for sarsa"));
        }
        let switched = match r.u8(at::SWITCHED) {
            0 => false,
            1 => true,
            s => return Err(ConfigError::new("policy.switched", s as f32, "0 or 1")),
        };
        let joints = r.u8(at::JOINTS) as usize;
        if joints > MAX_JOINTS {
            return Err(ConfigError::new("joints", joints as f32, "0 ..= 8 fatigue joints"));
        }
        if !r.zero(at::RESERVED_A, 2) || !r.zero(at::RESERVED_B, 4) {
            return Err(ConfigError::new("state.reserved", 0.0, "reserved bytes 0"));
        }
        let mut previous = [0u8; MAX_ACTION_DIMS];
        previous.copy_from_slice(&bytes[at::PREVIOUS..at::PREVIOUS + MAX_ACTION_DIMS]);
        let output = core::array::from_fn(|i| r.f32(at::OUTPUT + 4 * i));
        let stats = AgentStats {
            steps: r.u64(at::STEPS),
            updates: r.u64(at::UPDATES),
            explorations: r.u64(at::EXPLORATIONS),
            episodes: r.u32(at::EPISODES),
            saturations: r.u32(at::SATURATIONS),
            trace_drops: r.u32(at::TRACE_DROPS),
            last_td_error: Q16(r.u32(at::TD_ERROR) as i32),
        };
        let mut fatigue = Vec::new();
        for j in 0..MAX_JOINTS {
            let o = at::FATIGUE + j * at::JOINT_LEN;
            if j >= joints {
                if !r.zero(o, at::JOINT_LEN) {
                    return Err(ConfigError::new("fatigue", j as f32, "unused fatigue entries all 0").at(j));
                }
                continue;
            }
            if !r.zero(o + 1, 7) {
                return Err(ConfigError::new("fatigue.reserved", 0.0, "reserved bytes 0").at(j));
            }
            let state = JointFatigueState {
                last_sign: r.u8(o) as i8,
                steps: r.u64(o + 8),
                reengagements: r.u64(o + 16),
                damage_raw: r.u64(o + 24),
                window_reengagements: r.u64(o + 32),
                window_damage_raw: r.u64(o + 40),
            };
            // Cannot fail: j < joints <= MAX_JOINTS.
            let _ = fatigue.push(state);
        }
        Ok(LearnerState {
            agent: AgentState {
                stats,
                epsilon: r.f32(at::EPSILON),
                mode,
                policy: PolicyState { kind, switched, previous, output },
            },
            rng: RngState { state: r.u64(at::RNG_STATE), increment: r.u64(at::RNG_INCREMENT) },
            joints: fatigue,
            user: core::array::from_fn(|i| r.u32(at::USER + 4 * i)),
        })
    }
}

/// What [`load`] found.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[derive(serde::Serialize, serde::Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum LoadOutcome {
    /// The weights and the learner's state were loaded from the newest
    /// valid checkpoint.
    Loaded {
        /// Its generation.
        generation: u32,
        /// The slot it was in.
        slot: u8,
    },
    /// Both slots are erased.
    NoCheckpoint,
    /// The newest valid checkpoint was learned with another configuration;
    /// weights and state unchanged.
    ConfigMismatch {
        /// The hash of the running configuration.
        expected: u32,
        /// The hash in the checkpoint.
        found: u32,
    },
    /// The newest valid checkpoint has another number of weights than the
    /// table; weights and state unchanged.
    SizeMismatch {
        /// The table's number of weights.
        expected: u32,
        /// The checkpoint's.
        found: u32,
    },
    /// The newest readable header is of another format version (1: a
    /// checkpoint of weights only, from before the learner's state was
    /// saved); weights and state unchanged.
    UnsupportedVersion {
        /// The version found.
        found: u16,
    },
    /// No slot holds a valid checkpoint, and not both are erased.
    Corrupt,
    /// The newest valid checkpoint's learner-state record was refused: a
    /// record of another length or version, a code it cannot hold, or a
    /// field out of range for the running learner; weights and state
    /// unchanged. (Appended last, so the earlier variants keep their wire
    /// encoding.)
    InvalidState,
}

/// Why [`save`] failed. The previous checkpoint is intact in every case.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum SaveError<E> {
    /// The weights do not fit a slot.
    TooLarge {
        /// Bytes needed.
        needed: usize,
        /// Bytes per slot.
        capacity: usize,
    },
    /// The store failed.
    Store(E),
    /// Reading back the written checkpoint did not give a valid one.
    VerifyFailed {
        /// The slot written.
        slot: u8,
    },
}

/// A successful save.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[derive(serde::Serialize, serde::Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Saved {
    /// Generation written.
    pub generation: u32,
    /// Slot written.
    pub slot: u8,
}

/// What one slot holds.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum SlotStatus {
    /// A checkpoint with a valid header and payload.
    Valid(Header),
    /// No valid checkpoint (the header error, or `Corrupt` for a payload
    /// whose CRC does not match or does not fit the slot).
    Invalid(HeaderError),
}

/// Bytes read at a time while checking a payload.
const CHUNK: usize = 64;

/// Reads and checks `slot`: its header and its payload CRC (state record
/// and weights).
pub fn inspect<S: CheckpointStore>(store: &S, slot: u8) -> Result<SlotStatus, S::Error> {
    let mut hb = [0u8; HEADER_LEN];
    if store.capacity() < HEADER_LEN {
        return Ok(SlotStatus::Invalid(HeaderError::Corrupt));
    }
    store.read(slot, 0, &mut hb)?;
    let header = match Header::parse(&hb) {
        Ok(h) => h,
        Err(e) => return Ok(SlotStatus::Invalid(e)),
    };
    let end = match header.slot_bytes() {
        Some(l) if l <= store.capacity() => l,
        _ => return Ok(SlotStatus::Invalid(HeaderError::Corrupt)),
    };
    let mut digest = CRC32.digest();
    let mut offset = HEADER_LEN;
    let mut buf = [0u8; CHUNK];
    while offset < end {
        let n = (end - offset).min(CHUNK);
        store.read(slot, offset, &mut buf[..n])?;
        digest.update(&buf[..n]);
        offset += n;
    }
    if digest.finalize() != header.payload_crc {
        return Ok(SlotStatus::Invalid(HeaderError::Corrupt));
    }
    Ok(SlotStatus::Valid(header))
}

/// The slot and header of the newest valid checkpoint, if any.
type Newest = Option<(u8, Header)>;

/// Both slots' status and the newest valid checkpoint.
fn newest<S: CheckpointStore>(store: &S) -> Result<([SlotStatus; 2], Newest), S::Error> {
    let status = [inspect(store, 0)?, inspect(store, 1)?];
    let mut best: Newest = None;
    for (i, s) in status.iter().enumerate() {
        if let SlotStatus::Valid(h) = s {
            if best.is_none_or(|(_, b)| h.generation > b.generation) {
                best = Some((i as u8, *h));
            }
        }
    }
    Ok((status, best))
}

/// Saves the learner's `state` and `weights` with `config_hash` into the
/// slot not holding the newest valid checkpoint — state record and weights
/// first, header last — then reads it back to verify.
pub fn save<S: CheckpointStore, W: WeightStore + ?Sized>(
    store: &mut S,
    config_hash: u32,
    state: &LearnerState,
    weights: &W,
) -> Result<Saved, SaveError<S::Error>> {
    let bytes = weights.format().bytes();
    let needed = slot_len(weights.len(), bytes);
    if needed > store.capacity() || weights.len() > u32::MAX as usize {
        return Err(SaveError::TooLarge { needed, capacity: store.capacity() });
    }
    let (_, best) = newest(store).map_err(SaveError::Store)?;
    let (slot, generation) = match best {
        Some((s, h)) => (1 - s, h.generation.saturating_add(1)),
        None => (0, 1),
    };
    store.erase(slot).map_err(SaveError::Store)?;
    let mut digest = CRC32.digest();
    let record = state.to_bytes();
    digest.update(&record);
    store.write(slot, HEADER_LEN, &record).map_err(SaveError::Store)?;
    let mut buf = [0u8; CHUNK];
    let mut offset = HEADER_LEN + STATE_LEN;
    let per_chunk = CHUNK / bytes;
    let mut i = 0;
    while i < weights.len() {
        let count = (weights.len() - i).min(per_chunk);
        for (k, dst) in buf.chunks_exact_mut(bytes).take(count).enumerate() {
            weights.stored_le(i + k, dst);
        }
        // The last chunk is padded with zeros to a multiple of 4 bytes.
        let used = count * bytes;
        let n = used.div_ceil(4) * 4;
        buf[used..n].fill(0);
        digest.update(&buf[..n]);
        store.write(slot, offset, &buf[..n]).map_err(SaveError::Store)?;
        offset += n;
        i += count;
    }
    let header = Header {
        version: FORMAT_VERSION,
        config_hash,
        weight_count: weights.len() as u32,
        generation,
        payload_crc: digest.finalize(),
        state_len: STATE_LEN as u32,
        weight_bytes: bytes as u16,
    };
    store.write(slot, 0, &header.to_bytes()).map_err(SaveError::Store)?;
    match inspect(store, slot).map_err(SaveError::Store)? {
        SlotStatus::Valid(h) if h == header => Ok(Saved { generation, slot }),
        _ => Err(SaveError::VerifyFailed { slot }),
    }
}

/// The newest valid checkpoint of the running configuration, with its
/// learner state decoded; nothing of the caller's is written yet
/// ([`find`]).
#[derive(Debug, Clone, PartialEq)]
pub struct Found {
    /// The slot it is in.
    pub slot: u8,
    /// Its header.
    pub header: Header,
    /// Its learner state, decoded ([`LearnerState::from_bytes`]) but not yet
    /// checked against the running learner.
    pub state: LearnerState,
}

/// Finds the newest valid checkpoint and, if it was saved with
/// `config_hash` and `weight_count` weights, decodes its learner state.
/// Writes nothing: the caller checks the state against its learner, then
/// copies the weights with [`read_weights`] (what [`load`] does without
/// the check). The inner `Err` is the outcome when there is nothing to
/// load.
pub fn find<S: CheckpointStore>(
    store: &S,
    config_hash: u32,
    weight_count: usize,
) -> Result<Result<Found, LoadOutcome>, S::Error> {
    let (status, best) = newest(store)?;
    let Some((slot, header)) = best else {
        let version = status.iter().find_map(|s| match s {
            SlotStatus::Invalid(HeaderError::UnsupportedVersion { found }) => Some(*found),
            _ => None,
        });
        let erased = status.iter().all(|s| *s == SlotStatus::Invalid(HeaderError::Erased));
        return Ok(Err(match (version, erased) {
            (Some(found), _) => LoadOutcome::UnsupportedVersion { found },
            (None, true) => LoadOutcome::NoCheckpoint,
            (None, false) => LoadOutcome::Corrupt,
        }));
    };
    if header.config_hash != config_hash {
        return Ok(Err(LoadOutcome::ConfigMismatch { expected: config_hash, found: header.config_hash }));
    }
    if header.weight_count as usize != weight_count {
        return Ok(Err(LoadOutcome::SizeMismatch { expected: weight_count as u32, found: header.weight_count }));
    }
    if header.state_len as usize != STATE_LEN {
        return Ok(Err(LoadOutcome::InvalidState));
    }
    // The record was checked by `inspect` (CRC); decode it.
    let mut record = [0u8; STATE_LEN];
    store.read(slot, HEADER_LEN, &mut record)?;
    match LearnerState::from_bytes(&record) {
        Ok(state) => Ok(Ok(Found { slot, header, state })),
        Err(_) => Ok(Err(LoadOutcome::InvalidState)),
    }
}

/// Copies the weights of a checkpoint [`find`] found into `weights`;
/// [`LoadOutcome::SizeMismatch`] (and nothing written) if `weights` has
/// another length than the checkpoint.
pub fn read_weights<S: CheckpointStore, W: WeightStore + ?Sized>(
    store: &S,
    found: &Found,
    weights: &mut W,
) -> Result<LoadOutcome, S::Error> {
    let header = &found.header;
    let bytes = weights.format().bytes();
    if header.weight_count as usize != weights.len() || header.weight_bytes as usize != bytes {
        return Ok(LoadOutcome::SizeMismatch { expected: weights.len() as u32, found: header.weight_count });
    }
    // The payload was checked by `inspect`; copy it.
    let mut buf = [0u8; CHUNK];
    let mut offset = HEADER_LEN + header.state_len as usize;
    let per_chunk = CHUNK / bytes;
    let mut i = 0;
    while i < weights.len() {
        let count = (weights.len() - i).min(per_chunk);
        let n = count * bytes;
        store.read(found.slot, offset, &mut buf[..n])?;
        for (k, src) in buf[..n].chunks_exact(bytes).enumerate() {
            weights.load_le(i + k, src);
        }
        offset += n;
        i += count;
    }
    Ok(LoadOutcome::Loaded { generation: header.generation, slot: found.slot })
}

/// Loads the newest valid checkpoint into `state` and `weights` if it was
/// saved with `config_hash` and has `weights.len()` weights and a state
/// record this code reads; otherwise leaves both unchanged and says why.
///
/// The state is only decoded here, not checked against a learner: a caller
/// that restores it should use [`find`], check the state
/// ([`crate::agent::Agent::check_state`] and friends), then
/// [`read_weights`], so that a refused state leaves the weights as they
/// were too.
pub fn load<S: CheckpointStore, W: WeightStore + ?Sized>(
    store: &S,
    config_hash: u32,
    state: &mut LearnerState,
    weights: &mut W,
) -> Result<LoadOutcome, S::Error> {
    let found = match find(store, config_hash, weights.len())? {
        Ok(found) => found,
        Err(outcome) => return Ok(outcome),
    };
    let outcome = read_weights(store, &found, weights)?;
    if let LoadOutcome::Loaded { .. } = outcome {
        *state = found.state;
    }
    Ok(outcome)
}

/// FNV-1a (32 bit) of a configuration's byte description: the value stored
/// in a checkpoint's header and compared at load.
pub fn config_hash(bytes: &[u8]) -> u32 {
    let mut h = ConfigHasher::new();
    h.write(bytes);
    h.finish()
}

/// Incremental FNV-1a (32 bit), to describe a configuration field by field
/// without building a byte buffer.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ConfigHasher(u32);

impl Default for ConfigHasher {
    fn default() -> Self {
        Self::new()
    }
}

impl ConfigHasher {
    const OFFSET: u32 = 0x811C_9DC5;
    const PRIME: u32 = 0x0100_0193;

    /// A hasher at FNV-1a's offset basis.
    pub const fn new() -> Self {
        ConfigHasher(Self::OFFSET)
    }
    /// Adds bytes.
    pub fn write(&mut self, bytes: &[u8]) -> &mut Self {
        for &b in bytes {
            self.0 = (self.0 ^ b as u32).wrapping_mul(Self::PRIME);
        }
        self
    }
    /// Adds a `u32`, little endian.
    pub fn write_u32(&mut self, v: u32) -> &mut Self {
        self.write(&v.to_le_bytes())
    }
    /// Adds an `f32` by its bit pattern, little endian.
    pub fn write_f32(&mut self, v: f32) -> &mut Self {
        self.write_u32(v.to_bits())
    }
    /// Adds a string's bytes and its length (so `"ab","c"` ≠ `"a","bc"`).
    pub fn write_str(&mut self, s: &str) -> &mut Self {
        self.write_u32(s.len() as u32).write(s.as_bytes())
    }
    /// The hash.
    pub fn finish(&self) -> u32 {
        self.0
    }
}

/// A [`CheckpointStore`] in RAM: two slots of `SLOT` bytes, erased to
/// `0xFF`. For tests and host-side runs.
#[derive(Debug, Clone)]
pub struct RamStore<const SLOT: usize> {
    slots: [[u8; SLOT]; 2],
}

/// An access outside a [`RamStore`]'s slots.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct OutOfRange;

impl<const SLOT: usize> Default for RamStore<SLOT> {
    fn default() -> Self {
        Self::new()
    }
}

impl<const SLOT: usize> RamStore<SLOT> {
    /// Two erased slots.
    pub const fn new() -> Self {
        RamStore { slots: [[0xFF; SLOT]; 2] }
    }

    /// The raw bytes of a slot (for tests that corrupt them).
    pub fn slot_mut(&mut self, slot: u8) -> Option<&mut [u8; SLOT]> {
        self.slots.get_mut(slot as usize)
    }

    /// The raw bytes of a slot.
    pub fn slot(&self, slot: u8) -> Option<&[u8; SLOT]> {
        self.slots.get(slot as usize)
    }

    fn range(&self, slot: u8, offset: usize, len: usize) -> Result<(usize, core::ops::Range<usize>), OutOfRange> {
        let end = offset.checked_add(len).ok_or(OutOfRange)?;
        if (slot as usize) < self.slots.len() && end <= SLOT {
            Ok((slot as usize, offset..end))
        } else {
            Err(OutOfRange)
        }
    }
}

impl<const SLOT: usize> CheckpointStore for RamStore<SLOT> {
    type Error = OutOfRange;
    fn capacity(&self) -> usize {
        SLOT
    }
    fn read(&self, slot: u8, offset: usize, buf: &mut [u8]) -> Result<(), OutOfRange> {
        let (s, r) = self.range(slot, offset, buf.len())?;
        buf.copy_from_slice(&self.slots[s][r]);
        Ok(())
    }
    fn erase(&mut self, slot: u8) -> Result<(), OutOfRange> {
        let s = self.slots.get_mut(slot as usize).ok_or(OutOfRange)?;
        s.fill(0xFF);
        Ok(())
    }
    fn write(&mut self, slot: u8, offset: usize, data: &[u8]) -> Result<(), OutOfRange> {
        let (s, r) = self.range(slot, offset, data.len())?;
        // As flash: programming can only clear bits of erased bytes.
        for (dst, src) in self.slots[s][r].iter_mut().zip(data) {
            *dst &= *src;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fnv1a_reference_values() {
        assert_eq!(config_hash(b""), 0x811C_9DC5);
        assert_eq!(config_hash(b"a"), 0xE40C_292C);
        assert_eq!(config_hash(b"foobar"), 0xBF9C_F968);
        let mut h = ConfigHasher::new();
        h.write(b"foo").write(b"bar");
        assert_eq!(h.finish(), config_hash(b"foobar"));
        let (mut a, mut b) = (ConfigHasher::new(), ConfigHasher::new());
        a.write_str("ab").write_str("c");
        b.write_str("a").write_str("bc");
        assert_ne!(a.finish(), b.finish());
    }

    #[test]
    fn crc32_check_value() {
        // The catalogue's check value of CRC-32/ISO-HDLC.
        assert_eq!(crc32(b"123456789"), 0xCBF4_3926);
    }

    #[test]
    fn header_round_trip_and_rejections() {
        let h = Header {
            version: FORMAT_VERSION,
            config_hash: 7,
            weight_count: 3,
            generation: 9,
            payload_crc: 1,
            state_len: STATE_LEN as u32,
            weight_bytes: 4,
        };
        let b = h.to_bytes();
        assert_eq!(Header::parse(&b), Ok(h));
        assert_eq!(Header::parse(&[0xFF; HEADER_LEN]), Err(HeaderError::Erased));
        for i in 0..HEADER_LEN {
            let mut c = b;
            c[i] ^= 0x04;
            assert!(Header::parse(&c).is_err(), "bit flip at {i}");
        }
        let h1 = Header { version: 1, state_len: 0, ..h };
        assert_eq!(Header::parse(&h1.to_bytes()), Err(HeaderError::UnsupportedVersion { found: 1 }));
        let h2 = Header { version: 2, ..h };
        assert_eq!(Header::parse(&h2.to_bytes()), Err(HeaderError::UnsupportedVersion { found: 2 }));
        let h4 = Header { version: 4, ..h };
        assert_eq!(Header::parse(&h4.to_bytes()), Err(HeaderError::UnsupportedVersion { found: 4 }));
        // A weight width other than 2 or 4 bytes describes no slot.
        let mut store = RamStore::<{ slot_len(3, 4) }>::new();
        let odd = Header { weight_bytes: 3, ..h };
        let _ = store.write(0, 0, &odd.to_bytes());
        assert_eq!(inspect(&store, 0), Ok(SlotStatus::Invalid(HeaderError::Corrupt)));
    }
}
