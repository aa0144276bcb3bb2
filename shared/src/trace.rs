//! Bounded eligibility traces.
//!
//! As in the paper's reference implementation
//! (`docs/reference/grl.md` §5.3–5.4), a trace is a queue of the
//! feature sets of recent (state, action) pairs, newest last. The k-th most
//! recent entry (k = 0 for the current one) has eligibility `(γλ)^k`; the
//! queue keeps only entries whose eligibility is at least a threshold, which
//! bounds its length: for γλ = 0.99 · 0.92 and threshold 0.01 that is 49
//! entries.
//!
//! The capacity `CAP` is part of the type. When the threshold would keep
//! more entries than fit, the oldest (smallest) entry is dropped to make
//! room, and the drop is counted ([`Trace::drops`]) — never a panic, never
//! silent.
//!
//! Replacing traces (the default) remove each feature of a new entry from
//! all older entries, so a feature's eligibility is reset to 1 rather than
//! summed; accumulating traces keep the duplicates.

use crate::fixed::Frac;
use heapless::Deque;

/// Marks a feature slot that a newer entry replaced.
const REPLACED: u32 = u32::MAX;

/// How a revisited feature's eligibility combines.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum TraceKind {
    /// Eligibility is reset to 1 (Singh & Sutton's replacing traces).
    Replacing,
    /// Eligibilities add up.
    Accumulating,
}

impl TraceKind {
    /// A stable number of the kind, for the configuration hash.
    pub const fn code(self) -> u32 {
        match self {
            TraceKind::Replacing => 1,
            TraceKind::Accumulating => 2,
        }
    }
}

/// A bounded trace of up to `CAP` feature sets of `TILINGS` indices each.
#[derive(Debug, Clone)]
pub struct Trace<const TILINGS: usize, const CAP: usize> {
    entries: Deque<[u32; TILINGS], CAP>,
    kind: TraceKind,
    decay: Frac,
    /// Entries whose eligibility is still at least the threshold.
    keep: usize,
    drops: u32,
}

impl<const TILINGS: usize, const CAP: usize> Trace<TILINGS, CAP> {
    /// An empty trace with per-step decay `γλ` and pruning `threshold`
    /// (both already validated by the agent).
    pub fn new(kind: TraceKind, decay: Frac, threshold: Frac) -> Self {
        // Count the entries with (γλ)^k ≥ threshold, in the same fixed-point
        // arithmetic as the update, up to the capacity plus one (so that a
        // threshold needing more than CAP is known to drop).
        let mut keep = 0usize;
        let mut w = Frac::ONE;
        while w >= threshold && keep <= CAP && threshold > Frac::ZERO {
            keep += 1;
            w = w.times(decay);
            if w == Frac::ZERO {
                break;
            }
        }
        Trace { entries: Deque::new(), kind, decay, keep: keep.max(1), drops: 0 }
    }

    /// Empties the trace (at every episode start).
    pub fn clear(&mut self) {
        self.entries.clear();
    }

    /// Entries held now.
    pub fn len(&self) -> usize {
        self.entries.len()
    }

    /// Whether the trace is empty.
    pub fn is_empty(&self) -> bool {
        self.entries.is_empty()
    }

    /// Entries the threshold keeps (may exceed `CAP`: then entries drop).
    pub fn threshold_length(&self) -> usize {
        self.keep
    }

    /// Entries dropped because the capacity was full while their
    /// eligibility was still above the threshold.
    pub fn drops(&self) -> u32 {
        self.drops
    }

    /// Sets the drop counter (restoring a saved agent).
    pub fn set_drops(&mut self, drops: u32) {
        self.drops = drops;
    }

    /// Adds the features of the current (state, action) as the newest entry,
    /// with eligibility 1; older entries move one step down.
    pub fn push(&mut self, features: &[u32; TILINGS]) {
        if self.kind == TraceKind::Replacing {
            for entry in self.entries.iter_mut() {
                for slot in entry.iter_mut() {
                    if features.contains(slot) {
                        *slot = REPLACED;
                    }
                }
            }
        }
        // Entries beyond the threshold length are pruned silently; entries
        // still eligible are dropped only for lack of room, and counted.
        while self.entries.len() >= self.keep.min(CAP) {
            self.entries.pop_front();
            if self.keep > CAP {
                self.drops = self.drops.saturating_add(1);
            }
        }
        // Cannot fail: the loop above made room (CAP ≥ 1 is asserted by
        // the agent's constructor).
        let _ = self.entries.push_back(*features);
    }

    /// Marks every entry's `slot` replaced (`u32::MAX`): the slot now
    /// belongs to another feature (a full claim table gave it away), so no
    /// older eligibility may be written into it.
    pub fn forget(&mut self, slot: u32) {
        for entry in self.entries.iter_mut() {
            for s in entry.iter_mut() {
                if *s == slot {
                    *s = REPLACED;
                }
            }
        }
    }

    /// Visits every live feature with its eligibility, newest entry first:
    /// `(feature, (γλ)^k)`.
    pub fn for_each(&self, mut visit: impl FnMut(u32, Frac)) {
        let mut w = Frac::ONE;
        for entry in self.entries.iter().rev() {
            for &f in entry.iter() {
                if f != REPLACED {
                    visit(f, w);
                }
            }
            w = w.times(self.decay);
        }
    }

    /// Visits every entry with its eligibility, newest first; replaced slots
    /// hold `u32::MAX`.
    pub fn for_each_entry(&self, mut visit: impl FnMut(&[u32; TILINGS], Frac)) {
        let mut w = Frac::ONE;
        for entry in self.entries.iter().rev() {
            visit(entry, w);
            w = w.times(self.decay);
        }
    }
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::*;
    use std::vec::Vec;

    fn trace<const CAP: usize>(kind: TraceKind) -> Trace<2, CAP> {
        Trace::new(kind, Frac::from_f32(0.99 * 0.92), Frac::from_f32(0.01))
    }

    #[test]
    fn paper_parameters_keep_about_fifty_steps() {
        let t = trace::<64>(TraceKind::Replacing);
        // 0.9108^49 ≈ 0.0103 ≥ 0.01 > 0.9108^50 ≈ 0.0093: k = 0 ..= 49.
        assert_eq!(t.threshold_length(), 50);
    }

    #[test]
    fn eligibilities_decay_geometrically_and_prune() {
        let mut t = trace::<64>(TraceKind::Accumulating);
        for i in 0..100u32 {
            t.push(&[2 * i, 2 * i + 1]);
        }
        assert_eq!(t.len(), 50);
        assert_eq!(t.drops(), 0);
        let mut ws = Vec::new();
        t.for_each_entry(|e, w| ws.push((e[0], w.to_f32())));
        assert_eq!(ws[0], (198, 1.0));
        assert!((ws[1].1 - 0.9108).abs() < 1e-6);
        assert!((ws[49].1 - 0.9108f32.powi(49)).abs() < 1e-6);
    }

    #[test]
    fn full_capacity_drops_the_oldest_and_counts() {
        let mut t = trace::<8>(TraceKind::Replacing);
        for i in 0..20u32 {
            t.push(&[2 * i, 2 * i + 1]);
        }
        assert_eq!(t.len(), 8);
        assert_eq!(t.drops(), 12);
        let mut oldest = 0;
        t.for_each_entry(|e, _| oldest = e[0]);
        assert_eq!(oldest, 24);
    }

    #[test]
    fn replacing_resets_revisited_features() {
        let mut r = trace::<64>(TraceKind::Replacing);
        r.push(&[1, 2]);
        r.push(&[2, 3]);
        let mut seen = Vec::new();
        r.for_each(|f, w| seen.push((f, w.to_f32())));
        // Feature 2 appears once, with eligibility 1.
        assert_eq!(seen.iter().filter(|(f, _)| *f == 2).count(), 1);
        assert_eq!(seen[0], (2, 1.0));
        let mut a = trace::<64>(TraceKind::Accumulating);
        a.push(&[1, 2]);
        a.push(&[2, 3]);
        let mut n = 0;
        a.for_each(|f, _| n += (f == 2) as usize);
        assert_eq!(n, 2);
    }
}
