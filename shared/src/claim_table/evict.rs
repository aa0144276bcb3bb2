//! Which slot a full claim table gives to a new feature
//! ([`WhenFull::Replace`](crate::claims::WhenFull::Replace)).
//!
//! The candidates are the [`MAX_PROBE`] slots of the new feature's probe
//! (all held by other features, or it would have found a free one), so
//! that the new feature is found again by the same bounded probe, and no
//! slot is ever freed: every other feature's probe still ends where it did.
//!
//! The rule: the slot whose weight is nearest the centre of the initial
//! weights. Learning moves a weight by the sum of its TD updates, so this
//! is the feature that has been learned least, and it costs no memory
//! beyond the weight itself (the F405 has none to spare for an age or a
//! visit count per slot). Where the initialisation is a constant (every
//! robot of files by default) an unlearned weight sits exactly at the
//! centre, and forgetting it loses nothing: the evicted feature reads its
//! initial weight again. Where the initialisation is uniform (LEO: [0, 1])
//! a fresh weight sits up to half the range from the centre, and the rule
//! cannot tell it from a learned weight that came back there; LEO's
//! Q-values span hundreds, so that half a unit is small against them.
//!
//! Ties go to the slot nearest the home, so the rule is the same on every
//! machine. Slots the current update holds are spared (the caller's
//! `batch`), so no feature of an update loses its slot to another of the
//! same update.

use crate::claims::Claim;
use crate::weights::WeightStore;

use super::MAX_PROBE;

/// The slot to give away among the [`MAX_PROBE`] from `home` (in a table
/// of `mask + 1` slots): the weight nearest `centre` (raw Q16) that no
/// claim of `batch` holds; `None` if every one of them does.
pub(super) fn victim<W: WeightStore>(weights: &W, home: u32, mask: u32, centre: i64, batch: &[Claim]) -> Option<u32> {
    let mut best: Option<(u64, u32)> = None;
    for n in 0..MAX_PROBE {
        let i = (home + n) & mask;
        let distance = (weights.get(i as usize).0 as i64 - centre).unsigned_abs();
        if best.is_some_and(|(d, _)| d <= distance) {
            continue;
        }
        // Checked only for a slot that would win: most do not.
        if batch.iter().any(|c| c.slot() == Some(i)) {
            continue;
        }
        best = Some((distance, i));
    }
    best.map(|(_, slot)| slot)
}
