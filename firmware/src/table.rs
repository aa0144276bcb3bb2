//! The image's learner: the robot chosen at build time (`PADA_ROBOT`,
//! written by build.rs into `$OUT_DIR/robot.rs`), the board's learner
//! profile for it (`pada_core::profile`), and the weight table where that
//! profile puts it (build.rs's `cfg(pada_table)`):
//!
//! | `pada_table` | where | the paper's robots |
//! |---|---|---|
//! | `exact_ccm` | an exact table of Q16 weights in the 64 KiB of CCM | — |
//! | `exact_ccm_sram` | an exact table: all 64 KiB of CCM, then SRAM (`Split`) | the pendulum on F405/F407 and QEMU's netduinoplus2 (`stm32f405`, `stm32f407`, `qemu`) |
//! | `exact_sram` | an exact table in SRAM | the pendulum on the F429I-DISC1 and QEMU's mps2-an386 (`stm32f429`, `mps2`) |
//! | `claimed_ccm` | a claim table of 2^14 slots (16-bit weights and 16-bit tags) in CCM | — |
//! | `hashed_ccm` | a hashed table of 2^15 16-bit weights in all 64 KiB of CCM | LEO and robots of files with a claim table elsewhere, on the F405 |
//! | `claimed_sdram` | a claim table of 2^21 slots, all 8 MiB of the SDRAM (on mps2-an386: its PSRAM, `.sdram` in `memory-mps2.x`) | LEO on the F429 |
//!
//! The statics are NOLOAD (CCM, SDRAM) or `.uninit` (SRAM): the startup
//! code leaves them alone; [`take`] zeroes them once — after the board
//! layer has started their memory, which its [`TableMemory`] proves — and
//! the controller then initialises every weight from its seed.
//!
//! Each static has a symbol name of its own (`PADA_TABLE_CCM`,
//! `PADA_TABLE_SRAM`, `PADA_TABLE_SDRAM`, and a claim table's tags
//! `PADA_TABLE_TAGS_CCM`, `PADA_TABLE_TAGS_SDRAM`), by which `cargo xtask firmware`
//! finds the table's placement in the ELF.

use crate::board::TableMemory;
use core::mem::MaybeUninit;
#[allow(unused_imports)] // the pendulum's tables only
use pada_core::fixed::Q16;
use pada_core::profile::{Board, LearnerProfile, Memory};

// `ThisRobot`, `this_robot()` and `ROBOT`: the robot build.rs chose.
include!(concat!(env!("OUT_DIR"), "/robot.rs"));

/// The board's learner profile: F405-class chips (and their emulation).
#[cfg(not(profile_f429))]
pub const BOARD: Board = Board::F405;
/// The board's learner profile: the F429I-DISC1 with its SDRAM (and its
/// emulation).
#[cfg(profile_f429)]
pub const BOARD: Board = Board::F429Sdram;

/// The learner of this image. (build.rs has checked that the robot's table
/// fits the board, and stops the build with the sizes if not.)
pub const PROFILE: LearnerProfile = match BOARD.profile(ROBOT) {
    Ok(profile) => profile,
    Err(_) => panic!("the robot's exact table fits no memory of this board"),
};

/// Weights in the table.
pub const WEIGHTS: usize = match PROFILE.weights() {
    Some(n) => n,
    None => panic!("a chip's profile has a fixed table size"),
};

/// A zeroed `&'static mut` array from a static `MaybeUninit`. The caller
/// takes each static once.
///
/// # Safety
/// `cell` must not be referenced anywhere else, and all-zero bits must be
/// a valid `T` (they are for `Q16`, `i16` and `u16`, the tables' words).
unsafe fn zeroed<T, const N: usize>(cell: *mut MaybeUninit<[T; N]>) -> &'static mut [T; N] {
    // SAFETY: the caller's guarantee makes the reference unique; the
    // memory is zeroed before it is made.
    unsafe {
        (*cell).as_mut_ptr().cast::<T>().write_bytes(0, N);
        (*cell).assume_init_mut()
    }
}

/// Guards [`take`]: a second call panics, so every `&'static mut` is unique.
static TAKEN: static_cell::StaticCell<()> = static_cell::StaticCell::new();

/// A table in one memory: one static in `$section`, named `$symbol`.
// (Unused by the F405's pendulum, whose table is split over two memories.)
#[allow(unused_macros)]
macro_rules! one_memory {
    ($memory:pat, $section:literal, $symbol:literal) => {
        use super::*;

        const _: () = assert!(matches!(PROFILE.memory, $memory), "the profile puts the table elsewhere");

        #[link_section = $section]
        #[export_name = $symbol]
        static mut TABLE: MaybeUninit<[Q16; WEIGHTS]> = MaybeUninit::uninit();

        /// The table.
        pub type Table = &'static mut [Q16; WEIGHTS];

        pub fn take() -> Table {
            TAKEN.init(());
            // SAFETY: reached once (TAKEN), and nothing else names the static.
            unsafe { zeroed(core::ptr::addr_of_mut!(TABLE)) }
        }
    };
}

// ---------------------------------------------------------------------------
// An exact table over all of CCM, then SRAM (the pendulum on an F405).
// ---------------------------------------------------------------------------

#[cfg(pada_table = "exact_ccm_sram")]
mod layout {
    use super::*;
    use pada_core::weights::Split;

    const CCM: usize = match PROFILE.memory {
        Memory::CcmThenSram { ccm_weights } => ccm_weights,
        _ => panic!("build.rs chose a table split over CCM and SRAM"),
    };
    const REST: usize = WEIGHTS - CCM;

    #[link_section = ".ccmram"]
    #[export_name = "PADA_TABLE_CCM"]
    static mut IN_CCM: MaybeUninit<[Q16; CCM]> = MaybeUninit::uninit();
    #[link_section = ".uninit.pada_table"]
    #[export_name = "PADA_TABLE_SRAM"]
    static mut IN_SRAM: MaybeUninit<[Q16; REST]> = MaybeUninit::uninit();

    /// The table.
    pub type Table = Split<&'static mut [Q16; CCM], &'static mut [Q16; REST]>;

    pub fn take() -> Table {
        TAKEN.init(());
        // SAFETY: reached once (TAKEN), and nothing else names the statics.
        unsafe {
            Split {
                first: zeroed(core::ptr::addr_of_mut!(IN_CCM)),
                second: zeroed(core::ptr::addr_of_mut!(IN_SRAM)),
            }
        }
    }
}

/// A claim table: 16-bit weights in one static in `$section`, 16-bit tags
/// in another in `$tag_section` (`pada_core::claim_table`), doing what the
/// profile says when it is full.
#[allow(unused_macros)]
macro_rules! claim_table {
    ($memory:pat, $section:literal, $weights:literal, $tag_section:literal, $tags:literal) => {
        use super::*;
        use pada_core::claim_table::{ClaimTable, Tags16};
        use pada_core::weights::Half;

        const _: () = assert!(matches!(PROFILE.memory, $memory), "the profile puts the table elsewhere");
        const _: () = assert!(PROFILE.tag_bytes == 2 && PROFILE.format.bytes() == 2, "16-bit weights and tags");
        const _: () = assert!(WEIGHTS >= 2 && WEIGHTS.is_power_of_two(), "a claim table has 2^n slots");
        const SHIFT: u32 = match PROFILE.format {
            pada_core::weights::WeightFormat::Half { shift } => shift as u32,
            pada_core::weights::WeightFormat::Q16 => panic!("the chips' claim tables have 16-bit weights"),
        };

        #[link_section = $section]
        #[export_name = $weights]
        static mut WEIGHTS_16: MaybeUninit<[i16; WEIGHTS]> = MaybeUninit::uninit();
        #[link_section = $tag_section]
        #[export_name = $tags]
        static mut TAGS_16: MaybeUninit<[u16; WEIGHTS]> = MaybeUninit::uninit();

        /// The table.
        pub type Table = ClaimTable<Half<&'static mut [i16; WEIGHTS], SHIFT>, Tags16<&'static mut [u16; WEIGHTS]>>;

        pub fn take() -> Table {
            TAKEN.init(());
            // SAFETY: reached once (TAKEN), and nothing else names the
            // statics; all-zero bits are valid i16 and u16.
            let (weights, tags) = unsafe { (zeroed(core::ptr::addr_of_mut!(WEIGHTS_16)), zeroed(core::ptr::addr_of_mut!(TAGS_16))) };
            match ClaimTable::new(Half::new(weights), Tags16(tags)) {
                Ok(t) => t.on_full(PROFILE.when_full),
                // Unreachable: both statics have WEIGHTS entries, a power
                // of two (asserted at compile time above).
                Err(_) => panic!("the claim table's statics disagree"),
            }
        }
    };
}

// A claim table in the 64 KiB of CCM, weights and tags.
#[cfg(pada_table = "claimed_ccm")]
mod layout {
    claim_table!(Memory::Ccm, ".ccmram", "PADA_TABLE_CCM", ".ccmram", "PADA_TABLE_TAGS_CCM");
}

// A hashed table of 16-bit weights in all of CCM (LEO and robots of files
// whose features outgrow an exact table, on an F405).
#[cfg(pada_table = "hashed_ccm")]
mod layout {
    use super::*;
    use pada_core::weights::Half;

    const _: () = assert!(matches!(PROFILE.memory, Memory::Ccm), "the profile puts the table elsewhere");
    const SHIFT: u32 = match PROFILE.format {
        pada_core::weights::WeightFormat::Half { shift } => shift as u32,
        pada_core::weights::WeightFormat::Q16 => panic!("the F405's hashed table has 16-bit weights"),
    };

    #[link_section = ".ccmram"]
    #[export_name = "PADA_TABLE_CCM"]
    static mut IN_CCM: MaybeUninit<[i16; WEIGHTS]> = MaybeUninit::uninit();

    /// The table.
    pub type Table = Half<&'static mut [i16; WEIGHTS], SHIFT>;

    pub fn take() -> Table {
        TAKEN.init(());
        // SAFETY: reached once (TAKEN), and nothing else names the static;
        // all-zero bits are valid i16.
        Half::new(unsafe { zeroed(core::ptr::addr_of_mut!(IN_CCM)) })
    }
}

// An exact table in CCM (a small robot's).
#[cfg(pada_table = "exact_ccm")]
mod layout {
    one_memory!(Memory::Ccm, ".ccmram", "PADA_TABLE_CCM");
}

// An exact table in SRAM (the pendulum on the F429: 97.5 KiB of its 192
// KiB).
#[cfg(pada_table = "exact_sram")]
mod layout {
    one_memory!(Memory::Sram, ".uninit.pada_table", "PADA_TABLE_SRAM");
}

// A claim table in all 8 MiB of the SDRAM, weights and tags (LEO on the
// F429).
#[cfg(pada_table = "claimed_sdram")]
mod layout {
    claim_table!(Memory::Sdram, ".sdram", "PADA_TABLE_SDRAM", ".sdram", "PADA_TABLE_TAGS_SDRAM");
}

pub use layout::Table;

/// The weight table, zeroed; once (a second call panics). `memory` is the
/// board layer's word that the table's memory works.
pub fn take(memory: TableMemory) -> Table {
    let _: TableMemory = memory;
    layout::take()
}

/// The controller of this image.
pub type Ctl = pada_firmware::control::Controller<Table, ThisRobot>;
