//! What a claim table ([`crate::claim_table`]) answers and reports: a
//! claim's outcome, its occupancy, and the initial weights of the features
//! that hold no slot. A leaf module, so that the weight-store trait
//! ([`crate::weights`]) and the claim table can both name these without
//! importing each other.

use crate::fixed::Q16;

/// The initial weight of a feature that holds no slot: uniform in
/// `[lo, lo + span)` (raw Q16), drawn from the feature's key and the
/// trial's `seed` by a SplitMix64 finaliser, so it is the same on every
/// read, on every machine, and however full the table is.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct InitialWeights {
    /// The trial's seed for the initial weights (saved in checkpoints).
    pub seed: u64,
    /// Lowest initial weight, raw Q16.
    pub lo: i32,
    /// Number of raw values above `lo` that can be drawn (1: a constant).
    pub span: u64,
}

impl InitialWeights {
    /// The initial weight of `key`.
    #[inline]
    pub fn of(&self, key: u32) -> Q16 {
        let mut z = self.seed ^ (key as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15);
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^= z >> 31;
        let r = ((z as u128 * self.span as u128) >> 64) as i64;
        Q16((self.lo as i64 + r) as i32)
    }

    /// The middle of the initial weights' range, raw Q16: where a
    /// [`WhenFull::Replace`] table measures how far learning moved a
    /// weight.
    #[inline]
    pub fn centre(&self) -> i64 {
        self.lo as i64 + (self.span / 2) as i64
    }
}

/// What [`crate::claim_table::ClaimTable::claim`] found.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Claim {
    /// The feature's slot: it held it already (`fresh` false) or took it
    /// now (`fresh` true: tag and initial weight were just written).
    Slot {
        /// The slot.
        slot: u32,
        /// Whether this claim took it.
        fresh: bool,
    },
    /// Neither its tag nor a free slot within [`crate::claim_table::MAX_PROBE`]:
    /// the slot of another feature was given to this one
    /// ([`WhenFull::Replace`]). The slot's tag and weight are this
    /// feature's now (its initial weight); `old_raw` is what the slot's
    /// raw value ([`crate::weights::WeightStore::raw`]) was before, so
    /// that a running checksum can take the old owner out.
    Replaced {
        /// The slot.
        slot: u32,
        /// The slot's raw value before (its old owner's weight and tag).
        old_raw: u32,
    },
    /// Neither its tag nor a free slot within [`crate::claim_table::MAX_PROBE`]: refused.
    Refused,
}

impl Claim {
    /// The slot an update of the feature writes, if it got one.
    #[inline]
    pub fn slot(self) -> Option<u32> {
        match self {
            Claim::Slot { slot, .. } | Claim::Replaced { slot, .. } => Some(slot),
            Claim::Refused => None,
        }
    }
}

/// What a claim table does with a claim whose probe finds neither the
/// feature's tag nor a free slot ([`crate::claim_table::MAX_PROBE`] slots
/// from its home, all held by other features): the table is full there.
///
/// Measured on the F405's tables in docs/board.md ("A full table").
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Hash)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum WhenFull {
    /// Refuse the claim and count it: the update of that feature is
    /// dropped, and it reads its initial weight for ever. A table that
    /// fills stops learning anything new.
    #[default]
    Refuse,
    /// Give the feature the slot, among the probe's, whose weight is
    /// nearest the centre of the initial weights: the feature that
    /// learning has moved least, so the least that is known is forgotten
    /// (the evicted feature reads its initial weight again, which for a
    /// constant initialisation is where an unlearned weight sits). Slots
    /// claimed earlier in the same update are never taken. Counted in
    /// [`Occupancy::replaced`].
    Replace,
}

impl WhenFull {
    /// Every behaviour.
    pub const ALL: [WhenFull; 2] = [WhenFull::Refuse, WhenFull::Replace];

    /// The name the command line and reports use.
    pub const fn name(self) -> &'static str {
        match self {
            WhenFull::Refuse => "refuse",
            WhenFull::Replace => "replace",
        }
    }

    /// The code the configuration hash writes.
    pub const fn code(self) -> u32 {
        match self {
            WhenFull::Refuse => 0,
            WhenFull::Replace => 1,
        }
    }
}

/// Occupancy of a claim table, for reports and telemetry.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Occupancy {
    /// Slots claimed.
    pub claimed: u32,
    /// Slots in the table.
    pub slots: u32,
    /// Claims refused since the table was reset (a full probe run).
    pub refused: u32,
    /// Claims that took another feature's slot since the table was reset
    /// or restored ([`WhenFull::Replace`]; 0 for a table that refuses). A
    /// checkpoint does not keep it.
    #[cfg_attr(feature = "serde", serde(default))]
    pub replaced: u32,
    /// The longest probe a **claim** has needed since the table was reset
    /// or restored: slots looked at past the feature's home before its slot
    /// was found or taken, [`crate::claim_table::MAX_PROBE`] once a claim
    /// was refused. Claimed slots are never freed, so this is also the
    /// farthest any claimed feature sits from its home, and a read of a
    /// claimed feature never probes farther (the framework's "memory
    /// pressure", which it warns of past 7).
    ///
    /// Reads are not counted. A read of a feature that holds no slot stops
    /// at the first free slot or at the bound, as a claim of it would; it
    /// says how full the table is, not where the features are, and
    /// counting it would add a store to every read (`read` takes `&self`;
    /// the agent reads about 5 500 features per decision on LEO). A
    /// checkpoint does not keep it: a restored table starts from 0.
    pub longest_probe: u32,
}

impl Occupancy {
    /// The claimed fraction of the table, 0 ..= 1.
    pub fn fraction(&self) -> f32 {
        if self.slots == 0 {
            0.0
        } else {
            self.claimed as f32 / self.slots as f32
        }
    }
}

