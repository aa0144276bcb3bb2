//! Board learner profiles: a board's memory decides its learner.
//!
//! The learning task is the robot's ([`crate::robot`]); how much it can
//! remember is the board's. A [`LearnerProfile`] fixes, for one board and
//! one robot, the weight table's layout and size, the weight format and the
//! memory the table lives in. The firmware sizes its tables from it at
//! compile time, and the host runs the same profile (`pada run --board`),
//! so a user sees what a board will learn before flashing it.
//!
//! | board | memory for the table | pendulum | LEO |
//! |---|---|---|---|
//! | `f405` | 64 KB CCM + 128 KB SRAM (STM32F405) | exact, 24 960 Q16 weights (CCM, then SRAM) | claim table, 2^14 slots of 16-bit weight + 16-bit tag (64 KiB of CCM) |
//! | `f429-sdram` | 8 MB SDRAM on the FMC (STM32F429I-DISC1) | exact, in SRAM | claim table, 2^21 slots of 16-bit weight + 16-bit tag (8 MiB) |
//! | `host` | the heap | exact, as large as the policy needs | claim table, 2^22 slots of Q16 weight + 32-bit tag (32 MiB) |
//!
//! [`config_hash`] covers the profile: a checkpoint saved under one
//! profile is refused by another.

use crate::agent::Agent;
use crate::checkpoint::ConfigHasher;
use crate::robot::Robot;
use crate::tile_coding::Layout;
use crate::weights::{WeightFormat, WeightStore};

/// Tilings of every board's tile coder: the paper's reference
/// configuration (GRL, docs/reference/grl.md §4 and §5).
pub const TILINGS: usize = 16;
/// Capacity of every board's eligibility trace, in (state, action) entries:
/// LEO's γλ = 0.9962 · 0.8582 keeps 30 entries above 0.01, the paper's
/// pendulum γλ = 0.99 · 0.92 keeps 49.
pub const TRACE: usize = 64;

/// A board the learner runs on.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Board {
    /// An STM32F405 (or F407): 128 KB SRAM and 64 KB CCM on the chip.
    F405,
    /// An STM32F429I-DISC1-class board: the F429's 192 KB SRAM and 64 KB
    /// CCM plus 8 MB of SDRAM on the FMC, for LEO's table.
    F429Sdram,
    /// The host: the table on the heap, as large as the task wants.
    Host,
}

impl Board {
    /// Every board.
    pub const ALL: [Board; 3] = [Board::F405, Board::F429Sdram, Board::Host];

    /// The name the command line and the configuration hash use.
    pub const fn name(self) -> &'static str {
        match self {
            Board::F405 => "f405",
            Board::F429Sdram => "f429-sdram",
            Board::Host => "host",
        }
    }

    /// The board with this [`name`](Self::name).
    pub fn from_name(name: &str) -> Option<Board> {
        Board::ALL.into_iter().find(|b| b.name() == name)
    }

    /// What the board is, for reports.
    pub const fn description(self) -> &'static str {
        match self {
            Board::F405 => "STM32F405: 128 KB SRAM + 64 KB CCM on the chip",
            Board::F429Sdram => "STM32F429I-DISC1: 192 KB SRAM + 64 KB CCM, 8 MB SDRAM on the FMC",
            Board::Host => "the host: tables on the heap",
        }
    }

    /// This board's learner for `robot`.
    pub const fn profile(self, robot: Robot) -> LearnerProfile {
        let pendulum = matches!(robot, Robot::Pendulum33 | Robot::Pendulum20);
        let (layout, size, format, memory, tag_bytes) = match (self, pendulum) {
            // The pendulum's exact table (20 × 26 tiles × 16 tilings × 3
            // actions) is 97.5 KB: all 64 KB of CCM and 33.5 KB of SRAM.
            (Board::F405, true) => (
                Layout::Exact,
                TableSize::Weights(PENDULUM_EXACT_WEIGHTS),
                WeightFormat::Q16,
                Memory::CcmThenSram { ccm_weights: CCM_BYTES / 4 },
                0,
            ),
            // LEO in the 64 KB of CCM: a claim table of 2^14 slots, each
            // a 16-bit weight and a 16-bit tag.
            (Board::F405, false) => (Layout::Claimed, TableSize::Weights(1 << 14), LEO_CHIP_FORMAT, Memory::Ccm, 2),
            (Board::F429Sdram, true) => {
                (Layout::Exact, TableSize::Weights(PENDULUM_EXACT_WEIGHTS), WeightFormat::Q16, Memory::Sram, 0)
            }
            // All 8 MiB of the SDRAM: a claim table of 2^21 slots, each a
            // 16-bit weight and a 16-bit tag (docs/board.md measures what a
            // trial claims and what the 16 bits cost).
            (Board::F429Sdram, false) => {
                (Layout::Claimed, TableSize::Weights(1 << 21), LEO_CHIP_FORMAT, Memory::Sdram, 2)
            }
            (Board::Host, true) => (Layout::Exact, TableSize::FitExact, WeightFormat::Q16, Memory::Heap, 0),
            // A claim table as the framework keeps its LEO table
            // (docs/reference/grl.md §3.9 and §5.1, `safe: 1`): Q16 weights
            // and 32-bit tags, so two features share a slot only if their
            // 32-bit hashes are equal. A hashed table of 2^22 slots held
            // SARSA(λ) below one footstep (its greedy choice over 343
            // actions read other features' learned weights), and 2^24 let
            // it walk; a claim table needs only the slots a trial writes.
            (Board::Host, false) => {
                (Layout::Claimed, TableSize::Weights(1 << HOST_LEO_LOG2), WeightFormat::Q16, Memory::Heap, 4)
            }
        };
        LearnerProfile { board: self, robot, layout, size, format, memory, tag_bytes }
    }
}

/// The chips' LEO weights: 16 bits, Q16 shifted right by LEO's
/// [`crate::robot::leo::HALF_SHIFT`] (±2048 in steps of 1/16, rounded
/// stochastically).
pub const LEO_CHIP_FORMAT: WeightFormat = WeightFormat::Half { shift: crate::robot::leo::HALF_SHIFT };

/// log2 of the host's LEO claim table: Q16 weights with 32-bit tags, the
/// framework's semantics. 2^22 slots (32 MiB): the most a measured LEO
/// trial claimed in 14 666 s is 2.39 M (SARSA(λ), 15 trials, `pada
/// claims`, docs/board.md), 57 % of it. While no claim is refused a claim
/// table learns the same whatever its size (a feature's tag and initial
/// weight depend on its key alone), so this size changes no result.
pub const HOST_LEO_LOG2: u32 = 22;

/// Bytes of the F405's core-coupled RAM.
pub const CCM_BYTES: usize = 64 * 1024;
/// Weights of the physical pendulum's exact table with SARSA, the low-pass
/// filter, the integrator or PADA: 20 angle tiles × 26 velocity tiles ×
/// 16 tilings × 3 actions (the Markov variants add a state dimension and
/// need 4× more).
pub const PENDULUM_EXACT_WEIGHTS: usize = 24_960;

/// How many weights a table has.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum TableSize {
    /// A fixed number (the chip's tables are sized at compile time).
    Weights(usize),
    /// Exactly what the exact layout needs for the policy (host only).
    FitExact,
}

/// The memory a board keeps its table in.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Memory {
    /// Core-coupled RAM: zero wait states, no DMA.
    Ccm,
    /// The main SRAM.
    Sram,
    /// The first `ccm_weights` in CCM, the rest in SRAM
    /// ([`crate::weights::Split`]).
    CcmThenSram {
        /// Weights in CCM.
        ccm_weights: usize,
    },
    /// External SDRAM on the FMC.
    Sdram,
    /// The host's heap.
    Heap,
}

impl Memory {
    /// The name for reports.
    pub const fn name(self) -> &'static str {
        match self {
            Memory::Ccm => "CCM",
            Memory::Sram => "SRAM",
            Memory::CcmThenSram { .. } => "CCM + SRAM",
            Memory::Sdram => "SDRAM",
            Memory::Heap => "heap",
        }
    }
}

/// One board's learner for one robot.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct LearnerProfile {
    /// The board.
    pub board: Board,
    /// The robot.
    pub robot: Robot,
    /// How features map to weights.
    pub layout: Layout,
    /// How many weights.
    pub size: TableSize,
    /// How each weight is stored.
    pub format: WeightFormat,
    /// Where the table lives.
    pub memory: Memory,
    /// Bytes of a claim tag beside each weight ([`Layout::Claimed`]: 2 or
    /// 4; 0 for the other layouts).
    pub tag_bytes: usize,
}

impl LearnerProfile {
    /// The table's length when it is fixed (every chip's), else `None`.
    pub const fn weights(&self) -> Option<usize> {
        match self.size {
            TableSize::Weights(n) => Some(n),
            TableSize::FitExact => None,
        }
    }

    /// Bytes of one table entry: its weight and its claim tag.
    pub const fn entry_bytes(&self) -> usize {
        self.format.bytes() + self.tag_bytes
    }

    /// The table's bytes when its length is fixed.
    pub const fn table_bytes(&self) -> Option<usize> {
        match self.weights() {
            Some(n) => Some(n * self.entry_bytes()),
            None => None,
        }
    }
}

impl LearnerProfile {
    /// The same board with another table of `2^log2_weights` entries in
    /// `layout` (hashed, or claimed with tags of `tag_bytes`), weights in
    /// `format`, placed as a chip would place it: in CCM if it fits, else
    /// CCM first and the rest in SRAM (the F405), the SDRAM (the F429) or
    /// the heap (the host). For exploring what a board could learn with
    /// more or less memory; the firmware builds only the profiles of
    /// [`Board::profile`].
    pub const fn with_hashed_table(
        self,
        layout: Layout,
        log2_weights: u32,
        format: WeightFormat,
        tag_bytes: usize,
    ) -> LearnerProfile {
        let tag_bytes = if matches!(layout, Layout::Claimed) { tag_bytes } else { 0 };
        let weights = 1usize << log2_weights;
        let bytes = weights * (format.bytes() + tag_bytes);
        let memory = match self.board {
            Board::Host => Memory::Heap,
            Board::F429Sdram => Memory::Sdram,
            Board::F405 if bytes <= CCM_BYTES => Memory::Ccm,
            Board::F405 => Memory::CcmThenSram { ccm_weights: CCM_BYTES / format.bytes() },
        };
        LearnerProfile { layout, size: TableSize::Weights(weights), format, memory, tag_bytes, ..self }
    }
}

/// Version of what [`config_hash`] covers; bump when its meaning changes.
pub const CONFIG_HASH_VERSION: u32 = 3;

/// The hash of everything that gives a learner's weights their meaning
/// (FNV-1a, stored in checkpoints and sent in `Hello`): the robot, the
/// board's profile (its name, layout, table size, weight format, a claim
/// table's tag bytes and, if it keeps fewer than 32 bits of a key, how many:
/// [`crate::claim_table::key_bits`]), and what
/// the built agent knows of itself ([`Agent::write_config`]: the tile
/// coder's dimensions as prepared, tilings, trace capacity, the learner's
/// actions and their tiles, α, γ, λ and the trace settings).
///
/// Computed from the agent itself, so two programs that build their
/// learner differently (the host's runner, the firmware) get the same hash
/// only if the learners are the same. Policies that share the learner's
/// layout share the hash (PADA switches to SARSA on the same weights,
/// Section VIII); ε and the initialisation are left out.
pub fn config_hash<W: WeightStore, const TILINGS_: usize, const TRACE_: usize>(
    profile: &LearnerProfile,
    agent: &Agent<W, TILINGS_, TRACE_>,
) -> u32 {
    let mut h = ConfigHasher::new();
    h.write_u32(CONFIG_HASH_VERSION)
        .write_str(profile.robot.name())
        .write_str(profile.board.name())
        .write_u32(profile.layout.code())
        .write_u32(agent.weights().len() as u32)
        .write_u32(agent.weights().format().code())
        .write_u32(agent.weights().tag_bytes() as u32);
    let w = agent.weights();
    let kept = crate::claim_table::key_bits(w.tag_bytes() as u32 * 8, w.len().trailing_zeros());
    if w.claims() && kept < 32 {
        // A claim table that keeps fewer than 32 bits of a key (16-bit tags
        // below 2^17 slots: the F405's LEO table) tags those bits only; its
        // tags once covered the whole key, so a checkpoint saved before
        // holds tags of other features and must be refused. Written only
        // for such a table, so every other hash stays as it was.
        h.write_str("claim key bits").write_u32(kept);
    }
    agent.write_config(&mut h);
    h.finish()
}


#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_hash_names_the_key_bits_of_a_table_that_keeps_fewer_than_32() {
        extern crate std;
        use crate::action_space::{ActionDim, ActionSpace};
        use crate::agent::SarsaParams;
        use crate::claim_table::{ClaimTable, TagStore, Tags16, Tags32};
        use crate::policy::PolicyKind;
        use crate::tile_coding::StateDim;
        use std::vec;

        fn agent<T: TagStore>(tags: T) -> Agent<ClaimTable<std::vec::Vec<crate::fixed::Q16>, T>, 4, 8> {
            let n = tags.len();
            let table = ClaimTable::new(vec![crate::fixed::Q16::ZERO; n], tags).unwrap();
            let obs = [StateDim::new(0.0, 1.0, 0.5).unwrap()];
            let space = ActionSpace::repeated(ActionDim::from_levels(&[-1.0, 1.0]).unwrap(), 1).unwrap();
            Agent::new(&obs, space, PolicyKind::Sarsa, SarsaParams::default(), Layout::Claimed, table).unwrap()
        }
        // The hash as it was computed before a table's key bits were part
        // of it: tables that keep whole keys must still hash to it.
        fn whole_key_hash<W: WeightStore>(p: &LearnerProfile, a: &Agent<W, 4, 8>) -> u32 {
            let mut h = ConfigHasher::new();
            h.write_u32(CONFIG_HASH_VERSION)
                .write_str(p.robot.name())
                .write_str(p.board.name())
                .write_u32(p.layout.code())
                .write_u32(a.weights().len() as u32)
                .write_u32(a.weights().format().code())
                .write_u32(a.weights().tag_bytes() as u32);
            a.write_config(&mut h);
            h.finish()
        }
        let p = Board::F405.profile(Robot::Leo);
        let small16 = agent(Tags16(vec![0u16; 1 << 14]));
        let large16 = agent(Tags16(vec![0u16; 1 << 17]));
        let small32 = agent(Tags32(vec![0u32; 1 << 14]));
        assert_ne!(config_hash(&p, &small16), whole_key_hash(&p, &small16), "2^14 slots keep 29 bits of a key");
        assert_eq!(config_hash(&p, &large16), whole_key_hash(&p, &large16));
        assert_eq!(config_hash(&p, &small32), whole_key_hash(&p, &small32));
    }

    #[test]
    fn chip_tables_fit_their_memory() {
        for robot in Robot::ALL {
            let p = Board::F405.profile(robot);
            let bytes = p.table_bytes().unwrap();
            match p.memory {
                Memory::Ccm => assert!(bytes <= CCM_BYTES, "{robot:?}"),
                Memory::CcmThenSram { ccm_weights } => {
                    assert!(ccm_weights * p.format.bytes() <= CCM_BYTES);
                    // The rest must leave most of the 128 KB SRAM to the
                    // firmware's stack, buffers and executor.
                    assert!(bytes - ccm_weights * p.format.bytes() <= 48 * 1024, "{robot:?}");
                }
                m => panic!("{robot:?}: {m:?} on an F405"),
            }
            let p = Board::F429Sdram.profile(robot);
            assert!(p.table_bytes().unwrap() <= 8 * 1024 * 1024);
        }
        assert_eq!(Board::F429Sdram.profile(Robot::Leo).table_bytes(), Some(8 * 1024 * 1024));
        for b in Board::ALL {
            assert_eq!(Board::from_name(b.name()), Some(b));
        }
    }
}
