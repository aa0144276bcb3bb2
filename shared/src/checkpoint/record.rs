//! The learner-state record: everything a learner saves besides its
//! weights, as a fixed-size little-endian record of [`STATE_LEN`] bytes at
//! slot offset 32 ([`crate::checkpoint`] has the slot around it).
//!
//! # Layout (record version [`STATE_VERSION`], 4)
//!
//! Offsets from the record's start; the third column names the offset's
//! constant in this file, and a test checks every row against it (offset,
//! and offset + size = the next row's offset). Every reserved byte is
//! written 0 and must read 0.
//!
//! | offset | size | `at::` | field |
//! |---|---|---|---|
//! | 0 | 2 | `VERSION` | record version ([`STATE_VERSION`], `u16`) |
//! | 2 | 1 | `MODE` | mode: 0 learning, 1 testing ([`Mode`]) |
//! | 3 | 1 | `KIND` | policy kind built ([`kind_code`]): 0 sarsa, 1 lowpass, 2 markov-lowpass, 3 integrator, 4 markov-integrator, 5 pada, 6 epsilon-pada, 7 ou, 8 pink, 9 action-penalty |
//! | 4 | 4 | `PARAMETER` | its first parameter, `f32`: α of the low-pass filters, Δ of the integrators and the PADAs, θ of ou, σ of pink, the weight of action-penalty, 0 for sarsa |
//! | 8 | 1 | `SWITCHED` | switched back to SARSA: 0 no, 1 yes |
//! | 9 | 1 | `JOINTS` | fatigue joints in use `j`, 0–[`RECORD_JOINTS`] |
//! | 10 | 4 | `PREVIOUS` | previous action: level per action dimension, 4 × `u8` (0 unused) |
//! | 14 | 2 | `RESERVED_A` | reserved |
//! | 16 | 4 × 4 | `OUTPUT` | previous output (filter/integrator memory), 4 × `f32` (0 unused) |
//! | 32 | 4 | `EPSILON` | ε, `f32` |
//! | 36 | 4 | `TD_ERROR` | last TD error, raw [`Q16`] as `i32` |
//! | 40 | 8 | `STEPS` | agent steps (decisions), `u64` |
//! | 48 | 8 | `UPDATES` | SARSA updates, `u64` |
//! | 56 | 8 | `EXPLORATIONS` | exploratory decisions, `u64` |
//! | 64 | 4 | `EPISODES` | episodes started, `u32` |
//! | 68 | 4 | `SATURATIONS` | weight saturations, `u32` |
//! | 72 | 4 | `TRACE_DROPS` | trace drops, `u32` |
//! | 76 | 4 | `PARAMETER_2` | the policy's second parameter, `f32`: σ of ou, 0 for the others |
//! | 80 | 8 | `RNG_STATE` | generator state ([`RngState::state`]), `u64` |
//! | 88 | 8 | `RNG_INCREMENT` | generator increment ([`RngState::increment`], odd), `u64` |
//! | 96 | 4 × 4 | `USER` | user counters, 4 × `u32` ([`USER_COUNTERS`], the caller's) |
//! | 112 | 8 × 48 | `FATIGUE` | fatigue per joint ([`JointFatigueState`]), [`RECORD_JOINTS`] entries of `JOINT_LEN` = 48 bytes, the first `j` in use, the others all 0 |
//! | 496 | 2 × 4 | `ERASES` | erases of slot 0's and slot 1's sector, 2 × `u32` ([`FlashWear`], written by [`super::save`]) |
//! | 504 | 8 | `OPERATING_S` | operating seconds when saved, `u64` ([`FlashWear::operating_s`]) |
//! | 512 | 1 | `GOVERNOR` | wear governor: 0 none (then every byte from here on is 0), 1 one runs |
//! | 513 | 1 | `GOV_RESTRICTS` | what it moves: 0 PADA's Δ, 1 the low-pass α ([`Restricts`]) |
//! | 514 | 1 | `GOV_RUNG` | the rung in force, 0 the floor |
//! | 515 | 1 | `GOV_CURSOR` | the window bucket being filled |
//! | 516 | 1 | `GOV_FILLED` | full buckets before it |
//! | 517 | 1 | `GOV_IN_BUCKET` | actions in the bucket being filled |
//! | 518 | 2 | `GOV_RESERVED_A` | reserved |
//! | 520 | 4 | `GOV_BUDGET` | the budget \[s\], `f32` |
//! | 524 | 4 | `GOV_CALM` | calm actions (since the last move or the headroom last below the reserve), `u32` |
//! | 528 | 4 | `GOV_MOVES` | moves so far, `u32` |
//! | 532 | 4 | `GOV_SINCE_MOVE` | actions since the last move, `u32` |
//! | 536 | 8 | `GOV_STEPS` | learning actions observed, `u64` |
//! | 544 | 8 | `GOV_OVER` | actions after which the window was over budget, `u64` |
//! | 552 | 4 × 12 × 8 | `GOV_BUCKETS` | damage per governed gearbox and bucket, Q16.48, [`GOVERNED_JOINTS`] × [`WINDOW_BUCKETS`] × `u64`, gearbox-major |
//! | 936 | 8 | `GOV_HEADROOM_AT_MOVE` | the headroom right after the last move, Q16.48 as `i64` |
//! | 944 | 8 | `TABLE_SEED` | a claim table's seed of its initial weights, `u64` (0 for plain tables; [`crate::claim_table::InitialWeights`]) |
//! | 952 | 4 | `CLAIMS_REFUSED` | claims the claim table refused, `u32` |
//! | 956 | 68 | `TABLE_END` | reserved, up to [`STATE_LEN`] = 1024 |
//!
//! Each fatigue entry: +0 last sign (`i8`: −1, 0, +1), +1 seven reserved
//! bytes, +8 steps, +16 re-engagements, +24 damage (Q16.48), +32 window
//! re-engagements, +40 window damage (Q16.48), each a `u64`.
//!
//! Records of version 1 (496 bytes, before the flash wear), 2 (512
//! bytes, before the governor) and 3 (before the claim table) are refused;
//! the flash wear sits at the same offsets in versions 2 to 4, so an older
//! record's wear is still read (`WEAR_END`).
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
//! [`Q16`]: crate::fixed::Q16
//! [`Mode`]: crate::agent::Mode
//! [`RngState::check`]: crate::rng::RngState::check
//! [`RngState::increment`]: crate::rng::RngState::increment
//! [`RngState::state`]: crate::rng::RngState::state

use super::wear::FlashWear;
use crate::action_space::MAX_ACTION_DIMS;
use crate::agent::{AgentState, AgentStats, Mode};
use crate::error::ConfigError;
use crate::fatigue::JointFatigueState;
use crate::fixed::Q16;
use crate::governor::{GovernorState, Restricts, GOVERNED_JOINTS, WINDOW_BUCKETS};
use crate::policy::{kind_code, kind_from_code, kind_parameter, kind_second_parameter, PolicyKind, PolicyState};
use crate::rng::RngState;
use heapless::Vec;

/// Version of the learner-state record this code writes and reads (2 added
/// the flash wear at offset 496; 3 the policy's second parameter at offset
/// 76, the policy codes 6–9 and the wear governor's block from offset 512;
/// 4 the claim table's seed and refusals at offset 944).
pub const STATE_VERSION: u16 = 4;
/// Bytes of the learner-state record (a multiple of 4).
pub const STATE_LEN: usize = 1024;
/// Fatigue counters the state record has room for: one per servo. A layout
/// constant: the compile-time check below fails if it moves the offsets
/// after it.
pub const RECORD_JOINTS: usize = crate::limits::MAX_SERVOS;
/// Counters the state record keeps for the caller ([`LearnerState::user`]).
pub const USER_COUNTERS: usize = 4;

/// Offsets in the state record (the table of the module documentation).
pub(super) mod at {
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
    pub const PARAMETER_2: usize = 76;
    pub const RNG_STATE: usize = 80;
    pub const RNG_INCREMENT: usize = 88;
    pub const USER: usize = 96;
    pub const FATIGUE: usize = 112;
    /// Bytes per fatigue entry.
    pub const JOINT_LEN: usize = 48;
    pub const ERASES: usize = 496;
    pub const OPERATING_S: usize = 504;
    /// The governor's block ([`super::super::governor`]).
    pub const GOVERNOR: usize = 512;
    pub const GOV_RESTRICTS: usize = 513;
    pub const GOV_RUNG: usize = 514;
    pub const GOV_CURSOR: usize = 515;
    pub const GOV_FILLED: usize = 516;
    pub const GOV_IN_BUCKET: usize = 517;
    pub const GOV_RESERVED_A: usize = 518;
    pub const GOV_BUDGET: usize = 520;
    pub const GOV_CALM: usize = 524;
    pub const GOV_MOVES: usize = 528;
    pub const GOV_SINCE_MOVE: usize = 532;
    pub const GOV_STEPS: usize = 536;
    pub const GOV_OVER: usize = 544;
    pub const GOV_BUCKETS: usize = 552;
    pub const GOV_HEADROOM_AT_MOVE: usize = GOV_BUCKETS + 8 * super::GOVERNED_JOINTS * super::WINDOW_BUCKETS;
    pub const TABLE_SEED: usize = GOV_HEADROOM_AT_MOVE + 8;
    pub const CLAIMS_REFUSED: usize = 952;
    pub const TABLE_END: usize = 956;
}

const _: () = assert!(at::FATIGUE + RECORD_JOINTS * at::JOINT_LEN == at::ERASES);
const _: () = assert!(at::OPERATING_S + 8 == at::GOVERNOR);
const _: () = assert!(at::TABLE_SEED == 944);
const _: () = assert!(at::TABLE_END == 956 && at::TABLE_END <= STATE_LEN);
// The record has four action dimensions: previous levels and outputs.
const _: () = assert!(MAX_ACTION_DIMS == 4 && at::PREVIOUS + MAX_ACTION_DIMS <= at::RESERVED_A);
const _: () = assert!(at::OUTPUT + 4 * MAX_ACTION_DIMS == at::EPSILON);
const _: () = assert!(STATE_LEN % 4 == 0);
const _: () = assert!(at::USER + 4 * USER_COUNTERS == at::FATIGUE);

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
    /// [`RECORD_JOINTS`]; [`crate::fatigue::FatigueCounter::state`]).
    pub joints: Vec<JointFatigueState, RECORD_JOINTS>,
    /// The caller's counters (the firmware: episodes since the first boot,
    /// learning episodes since the last test episode).
    pub user: [u32; USER_COUNTERS],
    /// The checkpoint sectors' erase counts and the operating time they
    /// were reached in. [`super::save`] writes the counts it knows (the
    /// store's, this field's, whichever is higher, plus its own erase);
    /// the caller supplies the operating time.
    pub wear: FlashWear,
    /// The wear governor's state, when one runs
    /// ([`crate::governor::Governor::state`]).
    pub governor: Option<GovernorState>,
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
                table_seed: 0,
            },
            rng: RngState::default(),
            joints: Vec::new(),
            user: [0; USER_COUNTERS],
            wear: FlashWear::default(),
            governor: None,
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
        put(&mut b, at::TABLE_SEED, &a.table_seed.to_le_bytes());
        put(&mut b, at::CLAIMS_REFUSED, &a.stats.claims_refused.to_le_bytes());
        put(&mut b, at::PARAMETER_2, &kind_second_parameter(&p.kind).to_le_bytes());
        put(&mut b, at::RNG_STATE, &self.rng.state.to_le_bytes());
        put(&mut b, at::RNG_INCREMENT, &self.rng.increment.to_le_bytes());
        for (i, u) in self.user.iter().enumerate() {
            put(&mut b, at::USER + 4 * i, &u.to_le_bytes());
        }
        put_wear(&mut b, &self.wear);
        for (j, f) in self.joints.iter().enumerate() {
            let o = at::FATIGUE + j * at::JOINT_LEN;
            b[o] = f.last_sign as u8;
            put(&mut b, o + 8, &f.steps.to_le_bytes());
            put(&mut b, o + 16, &f.reengagements.to_le_bytes());
            put(&mut b, o + 24, &f.damage_raw.to_le_bytes());
            put(&mut b, o + 32, &f.window_reengagements.to_le_bytes());
            put(&mut b, o + 40, &f.window_damage_raw.to_le_bytes());
        }
        if let Some(g) = &self.governor {
            b[at::GOVERNOR] = 1;
            b[at::GOV_RESTRICTS] = g.restricts.code();
            b[at::GOV_RUNG] = g.rung;
            b[at::GOV_CURSOR] = g.cursor;
            b[at::GOV_FILLED] = g.filled;
            b[at::GOV_IN_BUCKET] = g.in_bucket;
            put(&mut b, at::GOV_BUDGET, &g.budget_bits.to_le_bytes());
            put(&mut b, at::GOV_CALM, &g.calm_steps.to_le_bytes());
            put(&mut b, at::GOV_MOVES, &g.moves.to_le_bytes());
            put(&mut b, at::GOV_SINCE_MOVE, &g.since_move.to_le_bytes());
            put(&mut b, at::GOV_HEADROOM_AT_MOVE, &g.headroom_at_move.to_le_bytes());
            put(&mut b, at::GOV_STEPS, &g.steps.to_le_bytes());
            put(&mut b, at::GOV_OVER, &g.over_budget_steps.to_le_bytes());
            for (j, row) in g.buckets.iter().enumerate() {
                for (k, v) in row.iter().enumerate() {
                    put(&mut b, at::GOV_BUCKETS + 8 * (j * WINDOW_BUCKETS + k), &v.to_le_bytes());
                }
            }
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
            return Err(ConfigError::new("state.version", version as f32, "4"));
        }
        let mode = match r.u8(at::MODE) {
            0 => Mode::Learning,
            1 => Mode::Testing,
            m => return Err(ConfigError::new("mode", m as f32, "0 (learning) or 1 (testing)")),
        };
        let code = r.u8(at::KIND);
        let kind = kind_from_code(code, [r.f32(at::PARAMETER), r.f32(at::PARAMETER_2)]).ok_or(ConfigError::new(
            "policy.kind",
            code as f32,
            "0 sarsa, 1 lowpass, 2 markov-lowpass, 3 integrator, 4 markov-integrator, 5 pada, 6 epsilon-pada, 7 ou, 8 pink, 9 action-penalty",
        ))?;
        if kind == PolicyKind::Sarsa && r.u32(at::PARAMETER) != 0 {
            return Err(ConfigError::new("policy.parameter", r.f32(at::PARAMETER), "0 for sarsa"));
        }
        if !matches!(kind, PolicyKind::OrnsteinUhlenbeck { .. }) && r.u32(at::PARAMETER_2) != 0 {
            return Err(ConfigError::new("policy.parameter2", r.f32(at::PARAMETER_2), "0 unless the policy is ou"));
        }
        let switched = match r.u8(at::SWITCHED) {
            0 => false,
            1 => true,
            s => return Err(ConfigError::new("policy.switched", s as f32, "0 or 1")),
        };
        let joints = r.u8(at::JOINTS) as usize;
        if joints > RECORD_JOINTS {
            return Err(ConfigError::new("joints", joints as f32, "0 ..= 8 fatigue joints"));
        }
        if !r.zero(at::RESERVED_A, 2) || !r.zero(at::TABLE_END, STATE_LEN - at::TABLE_END) {
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
            claims_refused: r.u32(at::CLAIMS_REFUSED),
            last_td_error: Q16(r.u32(at::TD_ERROR) as i32),
        };
        let mut fatigue = Vec::new();
        for j in 0..RECORD_JOINTS {
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
            // Cannot fail: j < joints <= RECORD_JOINTS.
            let _ = fatigue.push(state);
        }
        Ok(LearnerState {
            agent: AgentState {
                stats,
                epsilon: r.f32(at::EPSILON),
                mode,
                policy: PolicyState { kind, switched, previous, output },
                table_seed: r.u64(at::TABLE_SEED),
            },
            rng: RngState { state: r.u64(at::RNG_STATE), increment: r.u64(at::RNG_INCREMENT) },
            joints: fatigue,
            user: core::array::from_fn(|i| r.u32(at::USER + 4 * i)),
            wear: wear_of(&bytes[..WEAR_END]),
            governor: governor_of(&r)?,
        })
    }
}

/// The governor's block of a record: `None` when its flag is 0 (then every
/// byte of it is 0).
fn governor_of(r: &Record<'_>) -> Result<Option<GovernorState>, ConfigError> {
    match r.u8(at::GOVERNOR) {
        0 => {
            return if r.zero(at::GOVERNOR, at::TABLE_SEED - at::GOVERNOR) {
                Ok(None)
            } else {
                Err(ConfigError::new("governor", 0.0, "all bytes 0 without a governor"))
            }
        }
        1 => {}
        g => return Err(ConfigError::new("governor", g as f32, "0 (none) or 1")),
    }
    let code = r.u8(at::GOV_RESTRICTS);
    let restricts = Restricts::from_code(code)
        .ok_or(ConfigError::new("governor.restricts", code as f32, "0 (pada delta) or 1 (lowpass alpha)"))?;
    if !r.zero(at::GOV_RESERVED_A, 2) {
        return Err(ConfigError::new("governor.reserved", 0.0, "reserved bytes 0"));
    }
    let mut buckets = [[0u64; WINDOW_BUCKETS]; GOVERNED_JOINTS];
    for (j, row) in buckets.iter_mut().enumerate() {
        for (k, v) in row.iter_mut().enumerate() {
            *v = r.u64(at::GOV_BUCKETS + 8 * (j * WINDOW_BUCKETS + k));
        }
    }
    Ok(Some(GovernorState {
        budget_bits: r.u32(at::GOV_BUDGET),
        restricts,
        rung: r.u8(at::GOV_RUNG),
        cursor: r.u8(at::GOV_CURSOR),
        filled: r.u8(at::GOV_FILLED),
        in_bucket: r.u8(at::GOV_IN_BUCKET),
        calm_steps: r.u32(at::GOV_CALM),
        since_move: r.u32(at::GOV_SINCE_MOVE),
        moves: r.u32(at::GOV_MOVES),
        steps: r.u64(at::GOV_STEPS),
        over_budget_steps: r.u64(at::GOV_OVER),
        headroom_at_move: r.u64(at::GOV_HEADROOM_AT_MOVE) as i64,
        buckets,
    }))
}

/// Writes `wear` into its place in a record.
pub(super) fn put_wear(b: &mut [u8; STATE_LEN], wear: &FlashWear) {
    for (i, e) in wear.erases.iter().enumerate() {
        put(b, at::ERASES + 4 * i, &e.to_le_bytes());
    }
    put(b, at::OPERATING_S, &wear.operating_s.to_le_bytes());
}

/// Where the flash wear ends in a record of version 2 or later: the bytes
/// a reader needs to find the wear of any such record.
pub(super) const WEAR_END: usize = at::OPERATING_S + 8;

/// The wear the first [`WEAR_END`] bytes of a record hold (every value is
/// meaningful: counts and seconds).
pub(super) fn wear_of(bytes: &[u8]) -> FlashWear {
    let u32_at = |i: usize| u32::from_le_bytes([bytes[i], bytes[i + 1], bytes[i + 2], bytes[i + 3]]);
    let u64_at = |i: usize| (u32_at(i) as u64) | ((u32_at(i + 4) as u64) << 32);
    FlashWear { erases: [u32_at(at::ERASES), u32_at(at::ERASES + 4)], operating_s: u64_at(at::OPERATING_S) }
}

#[cfg(test)]
mod layout_doc {
    use super::at;

    /// Every offset constant of [`at`] with its value, in record order.
    const OFFSETS: &[(&str, usize)] = &[
        ("VERSION", at::VERSION),
        ("MODE", at::MODE),
        ("KIND", at::KIND),
        ("PARAMETER", at::PARAMETER),
        ("SWITCHED", at::SWITCHED),
        ("JOINTS", at::JOINTS),
        ("PREVIOUS", at::PREVIOUS),
        ("RESERVED_A", at::RESERVED_A),
        ("OUTPUT", at::OUTPUT),
        ("EPSILON", at::EPSILON),
        ("TD_ERROR", at::TD_ERROR),
        ("STEPS", at::STEPS),
        ("UPDATES", at::UPDATES),
        ("EXPLORATIONS", at::EXPLORATIONS),
        ("EPISODES", at::EPISODES),
        ("SATURATIONS", at::SATURATIONS),
        ("TRACE_DROPS", at::TRACE_DROPS),
        ("PARAMETER_2", at::PARAMETER_2),
        ("RNG_STATE", at::RNG_STATE),
        ("RNG_INCREMENT", at::RNG_INCREMENT),
        ("USER", at::USER),
        ("FATIGUE", at::FATIGUE),
        ("ERASES", at::ERASES),
        ("OPERATING_S", at::OPERATING_S),
        ("GOVERNOR", at::GOVERNOR),
        ("GOV_RESTRICTS", at::GOV_RESTRICTS),
        ("GOV_RUNG", at::GOV_RUNG),
        ("GOV_CURSOR", at::GOV_CURSOR),
        ("GOV_FILLED", at::GOV_FILLED),
        ("GOV_IN_BUCKET", at::GOV_IN_BUCKET),
        ("GOV_RESERVED_A", at::GOV_RESERVED_A),
        ("GOV_BUDGET", at::GOV_BUDGET),
        ("GOV_CALM", at::GOV_CALM),
        ("GOV_MOVES", at::GOV_MOVES),
        ("GOV_SINCE_MOVE", at::GOV_SINCE_MOVE),
        ("GOV_STEPS", at::GOV_STEPS),
        ("GOV_OVER", at::GOV_OVER),
        ("GOV_BUCKETS", at::GOV_BUCKETS),
        ("GOV_HEADROOM_AT_MOVE", at::GOV_HEADROOM_AT_MOVE),
        ("TABLE_SEED", at::TABLE_SEED),
        ("CLAIMS_REFUSED", at::CLAIMS_REFUSED),
        ("TABLE_END", at::TABLE_END),
    ];

    /// A size cell: a number or a product such as `4 × 12 × 8`.
    fn size(cell: &str) -> usize {
        cell.split('×').map(|f| f.trim().parse::<usize>().expect("a size")).product()
    }

    #[test]
    fn the_documented_layout_is_the_codes_layout() {
        let source = include_str!("record.rs");
        // The rows of the module documentation's table: offset, size, name.
        let mut rows = [("", 0usize, 0usize); 64];
        let mut n = 0;
        for line in source.lines() {
            let Some(row) = line.strip_prefix("//! | ") else { continue };
            let mut cells = row.split(" | ");
            let (Some(offset), Some(len), Some(name)) = (cells.next(), cells.next(), cells.next()) else { continue };
            let Ok(offset) = offset.trim().parse::<usize>() else { continue };
            rows[n] = (name.trim().trim_matches('`'), offset, size(len));
            n += 1;
        }
        let rows = &rows[..n];
        assert_eq!(rows.len(), OFFSETS.len(), "one documented row per offset constant");
        for (i, (&(name, offset, len), &(code_name, code_offset))) in rows.iter().zip(OFFSETS).enumerate() {
            assert_eq!(name, code_name, "row {i} names another offset than the code's");
            assert_eq!(offset, code_offset, "{name}: documented at {offset}, the code has {code_offset}");
            let next = rows.get(i + 1).map_or(super::STATE_LEN, |r| r.1);
            assert_eq!(offset + len, next, "{name}: offset + size does not reach the next field");
        }
        // Every offset constant of `at` is in OFFSETS (JOINT_LEN is a length).
        let consts = source
            .lines()
            .skip_while(|l| !l.starts_with("pub(super) mod at {"))
            .take_while(|l| *l != "}")
            .filter(|l| l.trim_start().starts_with("pub const ") && !l.contains("JOINT_LEN"))
            .count();
        assert_eq!(consts, OFFSETS.len(), "an offset of `at` is missing from the test's list");
        assert_eq!(at::FATIGUE + super::RECORD_JOINTS * at::JOINT_LEN, at::ERASES);
    }
}
