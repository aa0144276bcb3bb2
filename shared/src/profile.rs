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
//! | `f405` | 64 KB CCM + 48 KB of the 128 KB SRAM (STM32F405) | exact, 24 960 Q16 weights (CCM, then SRAM) | hashed table, 2^15 16-bit weights (all 64 KiB of CCM) |
//! | `f429-sdram` | 8 MB SDRAM on the FMC (STM32F429I-DISC1) | exact, in SRAM | claim table, 2^21 slots of 16-bit weight + 16-bit tag (8 MiB) |
//! | `host` | the heap | exact, as large as the policy needs | claim table, 2^22 slots of Q16 weight + 32-bit tag (32 MiB) |
//!
//! [`config_hash`] covers the profile: a checkpoint saved under one
//! profile is refused by another.

use crate::agent::Agent;
use crate::checkpoint::ConfigHasher;
use crate::claims::WhenFull;
use crate::robot::{RobotSpec, TableNeed};
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

    /// This board's learner for `robot`: an exact table where the robot
    /// needs one ([`TableNeed::Exact`]), Q16 weights in the board's fastest
    /// memory that holds them; a claim table otherwise, as large as the
    /// board's table memory ([`TableNeed::Claimed`]). An exact table that
    /// fits no memory of the board is an error that names the sizes (the
    /// firmware's build turns it into a compile-time error).
    pub const fn profile(self, robot: &'static RobotSpec) -> Result<LearnerProfile, ProfileError> {
        let (layout, size, format, memory, tag_bytes) = match (self, robot.table) {
            // The pendulum's exact table (20 × 26 tiles × 16 tilings × 3
            // actions) is 97.5 KB: all 64 KB of CCM and 33.5 KB of SRAM.
            (Board::F405, TableNeed::Exact { weights }) => {
                let bytes = weights * 4;
                let memory = if bytes <= CCM_BYTES {
                    Memory::Ccm
                } else if bytes <= CCM_BYTES + F405_SRAM_TABLE_BYTES {
                    Memory::CcmThenSram { ccm_weights: CCM_BYTES / 4 }
                } else {
                    return Err(ProfileError { board: self, weights, bytes, room: CCM_BYTES + F405_SRAM_TABLE_BYTES });
                };
                (Layout::Exact, TableSize::Weights(weights), WeightFormat::Q16, memory, 0)
            }
            // A hashed table of 2^15 16-bit weights in all 64 KB of CCM.
            // Features whose hashes collide share a weight. Of the three
            // things a full table can do in these bytes (a claim table of
            // 2^14 slots that refuses, one that replaces, or twice the
            // entries without tags that collide), this learned best on a
            // three-joint arm and on LEO (docs/board.md, "A full table").
            // (2^16 over CCM and 64 KB of SRAM learned better still, but
            // left the emulated image's stack 21 KB, and it overflowed at
            // boot: docs/board.md.)
            (Board::F405, TableNeed::Claimed) => (
                Layout::Hashed,
                TableSize::Weights(F405_HASHED_WEIGHTS),
                WeightFormat::Half { shift: robot.half_shift },
                Memory::Ccm,
                0,
            ),
            (Board::F429Sdram, TableNeed::Exact { weights }) => {
                let bytes = weights * 4;
                if bytes > F429_SRAM_TABLE_BYTES {
                    return Err(ProfileError { board: self, weights, bytes, room: F429_SRAM_TABLE_BYTES });
                }
                (Layout::Exact, TableSize::Weights(weights), WeightFormat::Q16, Memory::Sram, 0)
            }
            // All 8 MiB of the SDRAM: a claim table of 2^21 slots, each a
            // 16-bit weight and a 16-bit tag (docs/board.md measures what a
            // trial claims and what the 16 bits cost).
            (Board::F429Sdram, TableNeed::Claimed) => (
                Layout::Claimed,
                TableSize::Weights(1 << 21),
                WeightFormat::Half { shift: robot.half_shift },
                Memory::Sdram,
                2,
            ),
            (Board::Host, TableNeed::Exact { .. }) => {
                (Layout::Exact, TableSize::FitExact, WeightFormat::Q16, Memory::Heap, 0)
            }
            // A claim table as the framework keeps its LEO table
            // (docs/reference/grl.md §3.9 and §5.1, `safe: 1`): Q16 weights
            // and 32-bit tags, so two features share a slot only if their
            // 32-bit hashes are equal. A hashed table of 2^22 slots held
            // SARSA(λ) below one footstep (its greedy choice over 343
            // actions read other features' learned weights), and 2^24 let
            // it walk; a claim table needs only the slots a trial writes.
            (Board::Host, TableNeed::Claimed) => {
                (Layout::Claimed, TableSize::Weights(1 << HOST_CLAIM_LOG2), WeightFormat::Q16, Memory::Heap, 4)
            }
        };
        // The F429's and the host's claim tables do not fill with the
        // paper's robots: they refuse, as before, so their runs are bit
        // for bit as they were (`pada run --board --table-full` tries the
        // others).
        Ok(LearnerProfile { board: self, robot, layout, size, format, memory, tag_bytes, when_full: WhenFull::Refuse })
    }
}

/// A robot's exact table fits no memory of a board.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct ProfileError {
    /// The board.
    pub board: Board,
    /// Weights of the robot's exact table.
    pub weights: usize,
    /// Their bytes as Q16 weights.
    pub bytes: usize,
    /// The bytes the board has for a table.
    pub room: usize,
}

impl core::fmt::Display for ProfileError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        write!(
            f,
            "the robot's exact table of {} weights ({} bytes) does not fit board {}: it has room for {} bytes \
             (fewer observation tiles or actions, or a larger board)",
            self.weights,
            self.bytes,
            self.board.name(),
            self.room
        )
    }
}

/// log2 of the host's claim table (LEO's): Q16 weights with 32-bit tags, the
/// framework's semantics. 2^22 slots (32 MiB): the most a measured LEO
/// trial claimed in 14 666 s is 2.39 M (SARSA(λ), 15 trials, `pada
/// claims`, docs/board.md), 57 % of it. While no claim is refused a claim
/// table learns the same whatever its size (a feature's tag and initial
/// weight depend on its key alone), so this size changes no result.
pub const HOST_CLAIM_LOG2: u32 = 22;

/// Bytes of the F405's core-coupled RAM.
pub const CCM_BYTES: usize = 64 * 1024;
/// Bytes of the F405's 128 KB SRAM an exact table may take after all of
/// CCM: the rest is the firmware's statics (about 32 KB on the chip, 43 KB
/// in the emulated image) and its stack, which at 21 KB overflowed at boot.
pub const F405_SRAM_TABLE_BYTES: usize = 48 * 1024;
/// Weights of the F405's hashed table: 16-bit weights in all of CCM.
pub const F405_HASHED_WEIGHTS: usize = CCM_BYTES / 2;
/// Bytes of the F429's 192 KB SRAM an exact table may take.
pub const F429_SRAM_TABLE_BYTES: usize = 128 * 1024;

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
    /// A claim table's weights in CCM, its tags in SRAM (the F405: the
    /// weights, read by every choice, in the faster memory).
    CcmWeightsSramTags,
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
            Memory::CcmWeightsSramTags => "CCM (weights) + SRAM (tags)",
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
    pub robot: &'static RobotSpec,
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
    /// What a claim table does when a claim finds it full (a plain
    /// table's is [`WhenFull::Refuse`] and means nothing).
    pub when_full: WhenFull,
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
            Board::F405 if tag_bytes > 0 && weights * format.bytes() <= CCM_BYTES => Memory::CcmWeightsSramTags,
            Board::F405 => Memory::CcmThenSram { ccm_weights: CCM_BYTES / format.bytes() },
        };
        LearnerProfile { layout, size: TableSize::Weights(weights), format, memory, tag_bytes, ..self }
    }

    /// The same profile with a full claim table doing `when_full`.
    pub const fn when_full(self, when_full: WhenFull) -> LearnerProfile {
        LearnerProfile { when_full, ..self }
    }
}

/// Version of what [`config_hash`] covers; bump when its meaning changes.
pub const CONFIG_HASH_VERSION: u32 = 4;

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
        .write_str(profile.robot.name)
        .write_u32(profile.robot.definition_hash())
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
    if w.claims() && w.when_full() != WhenFull::Refuse {
        // The table's own behaviour, as the table's size and format are
        // its own. Written only for a table that does not refuse, so every
        // other hash stays as it was.
        h.write_str("when full").write_u32(w.when_full().code());
    }
    agent.write_config(&mut h);
    h.finish()
}


#[cfg(test)]
mod tests {
    use super::*;
    use crate::robot::{leo, pendulum, registry};

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
                .write_str(p.robot.name)
                .write_u32(p.robot.definition_hash())
                .write_str(p.board.name())
                .write_u32(p.layout.code())
                .write_u32(a.weights().len() as u32)
                .write_u32(a.weights().format().code())
                .write_u32(a.weights().tag_bytes() as u32);
            a.write_config(&mut h);
            h.finish()
        }
        let p = Board::F405.profile(&leo::SPEC).unwrap();
        let small16 = agent(Tags16(vec![0u16; 1 << 14]));
        let large16 = agent(Tags16(vec![0u16; 1 << 17]));
        let small32 = agent(Tags32(vec![0u32; 1 << 14]));
        assert_ne!(config_hash(&p, &small16), whole_key_hash(&p, &small16), "2^14 slots keep 29 bits of a key");
        assert_eq!(config_hash(&p, &large16), whole_key_hash(&p, &large16));
        assert_eq!(config_hash(&p, &small32), whole_key_hash(&p, &small32));
    }

    #[test]
    fn chip_tables_fit_their_memory() {
        for robot in registry::specs() {
            let p = Board::F405.profile(robot).unwrap();
            let bytes = p.table_bytes().unwrap();
            match p.memory {
                Memory::Ccm => assert!(bytes <= CCM_BYTES, "{}", robot.name),
                Memory::CcmThenSram { ccm_weights } => {
                    assert!(ccm_weights * p.format.bytes() <= CCM_BYTES, "{}", robot.name);
                    // The rest must leave most of the 128 KB SRAM to the
                    // firmware's stack, buffers and executor.
                    assert!(bytes - ccm_weights * p.format.bytes() <= F405_SRAM_TABLE_BYTES, "{}", robot.name);
                }
                Memory::CcmWeightsSramTags => {
                    assert_eq!(p.weights().unwrap() * p.format.bytes(), CCM_BYTES, "{}: the weights fill CCM", robot.name);
                    assert!(p.weights().unwrap() * p.tag_bytes <= F405_SRAM_TABLE_BYTES, "{}", robot.name);
                }
                m => panic!("{}: {m:?} on an F405", robot.name),
            }
            let p = Board::F429Sdram.profile(robot).unwrap();
            assert!(p.table_bytes().unwrap() <= 8 * 1024 * 1024);
        }
        assert_eq!(Board::F429Sdram.profile(&leo::SPEC).unwrap().table_bytes(), Some(8 * 1024 * 1024));
        for b in Board::ALL {
            assert_eq!(Board::from_name(b.name()), Some(b));
        }
    }

    #[test]
    fn the_profiles_of_the_paper_robots_are_the_measured_ones() {
        // The tables docs/board.md measures: the pendulum's exact 24 960
        // weights over CCM and SRAM; LEO's claim tables of 2^14 and 2^21
        // slots with 16-bit weights shifted by 12 and 16-bit tags; the
        // host's 2^22 slots of Q16 weights with 32-bit tags.
        let p = Board::F405.profile(&pendulum::SPEC_33HZ).unwrap();
        assert_eq!((p.layout, p.weights(), p.format), (Layout::Exact, Some(24_960), WeightFormat::Q16));
        assert_eq!(p.memory, Memory::CcmThenSram { ccm_weights: 16_384 });
        let l = Board::F405.profile(&leo::SPEC).unwrap();
        assert_eq!((l.layout, l.weights(), l.format, l.tag_bytes), (Layout::Hashed, Some(1 << 15), WeightFormat::Half { shift: 12 }, 0));
        assert_eq!(l.memory, Memory::Ccm);
        let l = Board::F429Sdram.profile(&leo::SPEC).unwrap();
        assert_eq!((l.weights(), l.memory, l.tag_bytes), (Some(1 << 21), Memory::Sdram, 2));
        let h = Board::Host.profile(&leo::SPEC).unwrap();
        assert_eq!((h.weights(), h.format, h.tag_bytes), (Some(1 << 22), WeightFormat::Q16, 4));
        assert_eq!(Board::Host.profile(&pendulum::SPEC_20HZ).unwrap().size, TableSize::FitExact);
    }

    #[test]
    fn an_exact_table_too_large_for_a_board_is_refused_with_its_sizes() {
        static HUGE: RobotSpec = RobotSpec { table: TableNeed::Exact { weights: 40_000 }, ..pendulum::SPEC_33HZ };
        let e = Board::F405.profile(&HUGE).unwrap_err();
        assert_eq!((e.weights, e.bytes, e.room), (40_000, 160_000, 112 * 1024));
        let text = alloc_free_text(&e);
        assert!(text.contains("40000 weights") && text.contains("f405"), "{text}");
        assert!(Board::F429Sdram.profile(&HUGE).is_err());
        assert!(Board::Host.profile(&HUGE).is_ok());
    }

    /// `e`'s message in a fixed buffer.
    fn alloc_free_text(e: &ProfileError) -> heapless::String<256> {
        use core::fmt::Write;
        let mut s = heapless::String::new();
        write!(s, "{e}").unwrap();
        s
    }
}
