//! The candidates a learner chooses among: per action dimension a
//! contiguous range of levels (all of them, or PADA's neighbourhood of the
//! previous action, Eq. 9), and uniform draws from them.

use crate::action_space::{Levels, MAX_ACTION_DIMS};
use rand_core::RngCore;

/// The set of level combinations the learner may choose from: per dimension
/// a contiguous range of levels `lo..=hi` (all levels, or PADA's
/// neighbourhood, Eq. 9). The joint candidates are the product of the
/// ranges.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Candidates {
    /// Lowest allowed level per dimension.
    pub lo: Levels,
    /// Highest allowed level per dimension.
    pub hi: Levels,
    /// Number of dimensions in use.
    pub dims: u8,
}

impl Candidates {
    /// Number of joint candidates.
    pub fn count(&self) -> u32 {
        (0..self.dims as usize).map(|i| (self.hi[i] - self.lo[i]) as u32 + 1).product()
    }

    /// Whether `levels` is a candidate.
    pub fn contains(&self, levels: &Levels) -> bool {
        (0..self.dims as usize).all(|i| levels[i] >= self.lo[i] && levels[i] <= self.hi[i])
    }

    /// A uniformly random candidate: the product set is uniform when each
    /// dimension is drawn uniformly and independently.
    pub fn random<R: RngCore + ?Sized>(&self, rng: &mut R) -> Levels {
        let mut levels = [0u8; MAX_ACTION_DIMS];
        for i in 0..self.dims as usize {
            let n = (self.hi[i] - self.lo[i]) as u32 + 1;
            levels[i] = self.lo[i] + uniform_below(rng, n) as u8;
        }
        levels
    }

    /// Visits every candidate once, first dimension fastest.
    pub fn for_each(&self, mut visit: impl FnMut(&Levels)) {
        let d = self.dims as usize;
        let mut l = self.lo;
        loop {
            visit(&l);
            // Odometer increment.
            let mut i = 0;
            loop {
                if i == d {
                    return;
                }
                if l[i] < self.hi[i] {
                    l[i] += 1;
                    break;
                }
                l[i] = self.lo[i];
                i += 1;
            }
        }
    }
}

/// A uniform integer in `0..n` (`n ≥ 1`) by Lemire's multiply-shift: one
/// `u32` per draw, no division, bias below 2⁻³² · n.
pub fn uniform_below<R: RngCore + ?Sized>(rng: &mut R, n: u32) -> u32 {
    ((rng.next_u32() as u64 * n as u64) >> 32) as u32
}
