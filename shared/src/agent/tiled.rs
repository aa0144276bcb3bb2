//! The greedy choice with action tiles ([`crate::action_tiles`]): each
//! tiling's weights read once per tile combination, then every candidate
//! summed from them.
//!
//! A candidate's feature in tiling `j` is the combination of the tiles its
//! levels fall into there, so the candidates' box of levels (`lo..=hi` per
//! dimension) reaches, in each tiling, only the box of tiles between the
//! tiles of `lo` and of `hi` (tiles are non-decreasing in the level). For
//! LEO's 343 actions that is 1,172 of the 16 × 125 combinations: in most
//! tilings the seven levels of a dimension span four tiles of the five
//! that some tiling needs. Each tiling's box is laid out compactly (its
//! first dimension fastest), so the features are read in one run per
//! tiling and no weight is read that no candidate sums.

use super::Agent;
use crate::action_space::{Levels, MAX_ACTION_DIMS, MAX_LEVELS};
use crate::action_tiles::{ActionTiles, MAX_ACTION_COMBOS};
use crate::policy::{uniform_below, Candidates};
use crate::tile_coding::{StateCode, TileCoder};
use crate::weights::WeightStore;
use rand_core::RngCore;

/// Each tiling's box of tiles for a box of candidates, laid out compactly:
/// the box's combination of tiles `(t_0, …, t_3)` sits at
/// `Σ_d (t_d − first_d) · Π_{e<d} count_e` of the tiling's row.
pub(super) struct TileBoxes<const TILINGS: usize> {
    /// `offset[d][l][j]`: what level `l` of dimension `d` adds to the
    /// compact index in tiling `j` (transposed so that one level's offsets
    /// in every tiling are adjacent, for the candidates' sums).
    offset: [[[u8; TILINGS]; MAX_LEVELS]; MAX_ACTION_DIMS],
    /// The first tile of each dimension's range, per tiling.
    first: [[u32; MAX_ACTION_DIMS]; TILINGS],
    /// The number of tiles in each dimension's range, per tiling.
    count: [[u32; MAX_ACTION_DIMS]; TILINGS],
    /// Combinations in each tiling's box (at most the action tiling's
    /// combinations, so at most [`MAX_ACTION_COMBOS`]).
    size: [u32; TILINGS],
}

impl<const TILINGS: usize> TileBoxes<TILINGS> {
    /// The boxes of `candidates` (a box of levels of `at`'s space).
    pub(super) fn new(at: &ActionTiles<TILINGS>, candidates: &Candidates) -> Self {
        let mut boxes = TileBoxes {
            offset: [[[0u8; TILINGS]; MAX_LEVELS]; MAX_ACTION_DIMS],
            first: [[0u32; MAX_ACTION_DIMS]; TILINGS],
            count: [[1u32; MAX_ACTION_DIMS]; TILINGS],
            size: [1u32; TILINGS],
        };
        for j in 0..TILINGS {
            let mut stride = 1u32;
            for d in 0..MAX_ACTION_DIMS {
                // An unused dimension has lo = hi = 0 and tile 0: one tile.
                let (lo, hi) = (candidates.lo[d], candidates.hi[d]);
                let first = at.tile(j, d, lo);
                for l in lo..=hi {
                    // < the box's size ≤ MAX_ACTION_COMBOS = 128: fits a u8.
                    boxes.offset[d][l as usize & (MAX_LEVELS - 1)][j] = ((at.tile(j, d, l) - first) * stride) as u8;
                }
                let count = at.tile(j, d, hi) - first + 1;
                boxes.first[j][d] = first;
                boxes.count[j][d] = count;
                stride *= count;
            }
            boxes.size[j] = stride;
        }
        boxes
    }

    /// Combinations in all the boxes: the weights the tiled choice reads.
    pub(super) fn total(&self) -> u32 {
        self.size.iter().sum()
    }
}

impl<W, const TILINGS: usize, const TRACE: usize> Agent<W, TILINGS, TRACE>
where
    W: WeightStore,
{
    /// [`greedy`](Self::greedy) with action tiles, on the candidates'
    /// `boxes`: a table of each tiling's box of weights, then per candidate
    /// one table read per tiling. The candidates are visited in
    /// `Candidates::for_each`'s order (first dimension fastest), so ties
    /// break exactly as there; the other dimensions' share of each tiling's
    /// index is summed once per run of the first dimension.
    pub(super) fn greedy_tiled<R: RngCore + ?Sized>(
        &self,
        code: &StateCode<TILINGS>,
        candidates: &Candidates,
        at: &ActionTiles<TILINGS>,
        boxes: &TileBoxes<TILINGS>,
        rng: &mut R,
    ) -> (Levels, i64) {
        const MASK: usize = MAX_ACTION_COMBOS - 1;
        const ROW: usize = MAX_ACTION_COMBOS + MAX_LEVELS;
        // Each combination's share of its feature's hash, once per choice
        // rather than once per tiling.
        // (MAX_LEVELS more entries than combinations, here and in the rows,
        // so that a run of the first dimension is copied as a whole block
        // of MAX_LEVELS, the tail overwritten by the next run.)
        let mut word = [0u32; ROW];
        for (c, w) in word.iter_mut().enumerate().take(at.combos() as usize) {
            *w = TileCoder::<TILINGS>::word_part(c as u32);
        }
        // Each tiling's row: its features, then their weights' bits, read
        // in one tight loop so that the processor overlaps their cache
        // misses itself. (A pass that loaded each feature's home slot
        // before the reads paid for itself when a read was a call through
        // the host table's dispatch; with this loop it measured no faster
        // in CPU time on LEO with the home's tag alone, and 15 % slower
        // with its tag and weight.) Row by row (`from_fn`), so that each
        // row is cleared on its own rather than the whole table at once,
        // which glibc does with `rep stosb` and valgrind counts as a
        // thousands of instructions.
        let table: [[u32; ROW]; TILINGS] = core::array::from_fn(|j| {
            let mut row = [0u32; ROW];
            // The word parts of the box's combinations in the row's order
            // (runs of the first dimension, whose stride is 1, of at most
            // MAX_LEVELS tiles), then the features, in a loop the compiler
            // vectorises.
            let (first, count) = (boxes.first[j], boxes.count[j]);
            let mut k = 0usize;
            for t3 in first[3]..first[3] + count[3] {
                for t2 in first[2]..first[2] + count[2] {
                    for t1 in first[1]..first[1] + count[1] {
                        let base = (t1 * at.stride(1) + t2 * at.stride(2) + t3 * at.stride(3) + first[0]) as usize;
                        // k and base are below MAX_ACTION_COMBOS: both
                        // blocks are in their arrays.
                        if let (Some(to), Some(from)) = (row.get_mut(k..k + MAX_LEVELS), word.get(base..base + MAX_LEVELS)) {
                            to.copy_from_slice(from);
                        }
                        k += count[0] as usize;
                    }
                }
            }
            let features = &mut row[..boxes.size[j] as usize];
            let state = self.coder.state_part(code, j);
            for x in features.iter_mut() {
                *x = self.coder.feature_of_parts(state, *x);
            }
            self.weights.read_each(features);
            row
        });
        // Unused dimensions have lo = hi = 0 and offset 0.
        let (lo, hi) = (candidates.lo, candidates.hi);
        let offset = |d: usize, l: u8| &boxes.offset[d][l as usize & (MAX_LEVELS - 1)];
        let mut best = lo;
        let mut best_sum = i64::MIN;
        let mut ties = 0u32;
        for l3 in lo[3]..=hi[3] {
            for l2 in lo[2]..=hi[2] {
                for l1 in lo[1]..=hi[1] {
                    // Every candidate of this run's index in every tiling
                    // at once, in fixed-size loops the compiler does in
                    // vector registers (the offsets of levels beyond `hi`
                    // are 0, their indices unused), then the sums.
                    let (o1, o2, o3) = (offset(1, l1), offset(2, l2), offset(3, l3));
                    let mut index = [[0u8; TILINGS]; MAX_LEVELS];
                    for (l, row) in index.iter_mut().enumerate() {
                        let o0 = &boxes.offset[0][l];
                        for j in 0..TILINGS {
                            // Below the box's size ≤ MAX_ACTION_COMBOS =
                            // 128: no u8 overflow.
                            row[j] = o0[j] + o1[j] + o2[j] + o3[j];
                        }
                    }
                    for l0 in lo[0]..=hi[0] {
                        let mut sum = 0i64;
                        for (row, &i) in table.iter().zip(&index[l0 as usize & (MAX_LEVELS - 1)]) {
                            // The mask only drops the check.
                            sum += row[i as usize & MASK] as i32 as i64;
                        }
                        if sum > best_sum {
                            best_sum = sum;
                            best = [l0, l1, l2, l3];
                            ties = 1;
                        } else if sum == best_sum {
                            ties += 1;
                            if uniform_below(rng, ties) == 0 {
                                best = [l0, l1, l2, l3];
                            }
                        }
                    }
                }
            }
        }
        (best, best_sum)
    }
}

#[cfg(test)]
mod tests {
    //! The tiled choice against the plain walk over every candidate's own
    //! features ([`Agent::greedy_walk`]): the same action, the same sum and
    //! the same draws for its ties, on every kind of table.
    extern crate std;
    use super::*;
    use crate::action_space::{ActionDim, ActionSpace};
    use crate::agent::{EpisodeEnd, SarsaParams, WeightInit};
    use crate::claim_table::{ClaimTable, Tags16, Tags32};
    use crate::fixed::Q16;
    use crate::policy::PolicyKind;
    use crate::tile_coding::{Layout, StateDim};
    use crate::weights::Half;
    use proptest::prelude::*;
    use rand_core::{RngCore, SeedableRng};
    use rand_pcg::Pcg32;
    use std::vec;
    use std::vec::Vec;

    /// LEO's learner in small: 4 state dimensions, 3 × 7 voltages in
    /// 6.67 V action tiles, 16 tilings.
    fn agent<W: WeightStore>(layout: Layout, weights: W, init: WeightInit) -> Agent<W, 16, 64> {
        let obs: Vec<StateDim> = (0..4).map(|_| StateDim::new(-3.0, 3.0, 0.5).unwrap()).collect();
        let space = ActionSpace::repeated(ActionDim::uniform(-10.7, 10.7, 7).unwrap(), 3).unwrap();
        let params = SarsaParams { init, epsilon: 0.3, ..SarsaParams::default() };
        let mut a = Agent::new(&obs, space, PolicyKind::Sarsa, params, layout, weights).unwrap();
        a.generalise_actions(&[6.67; 3]).unwrap();
        a
    }

    fn observation(rng: &mut Pcg32) -> [f32; 4] {
        core::array::from_fn(|_| (rng.next_u32() as f32 / u32::MAX as f32) * 6.0 - 3.0)
    }

    /// Learns a little with rewards from `{-1, 0, 1}` (claims, moves
    /// weights, leaves many ties), then compares the two choices on random
    /// states and random boxes of candidates.
    fn tiled_is_the_walk<W: WeightStore>(mut a: Agent<W, 16, 64>, seed: u64) -> Result<(), TestCaseError> {
        let mut rng = Pcg32::seed_from_u64(seed);
        a.reset_weights(&mut rng);
        for _ in 0..(seed % 4) {
            a.start_episode(&observation(&mut rng), &mut rng).unwrap();
            for _ in 0..20 {
                let r = (rng.next_u32() % 3) as f32 - 1.0;
                a.step(r, &observation(&mut rng), &mut rng).unwrap();
            }
            a.end_episode(-1.0, EpisodeEnd::Absorbing, &mut rng).unwrap();
        }
        let at = a.coder().action_tiles().unwrap().clone();
        let space = a.policy().learner_space().clone();
        for _ in 0..20 {
            let code = a.code(&observation(&mut rng));
            let (mut lo, mut hi) = ([0u8; 4], [0u8; 4]);
            for d in 0..3 {
                let (x, y) = ((rng.next_u32() % 7) as u8, (rng.next_u32() % 7) as u8);
                (lo[d], hi[d]) = (x.min(y), x.max(y));
            }
            if rng.next_u32() % 2 == 0 {
                (lo, hi) = ([0; 4], [6, 6, 6, 0]);
            }
            let candidates = Candidates { lo, hi, dims: 3 };
            let (mut r1, mut r2) = (rng.clone(), rng.clone());
            let tiled = a.greedy_tiled(&code, &candidates, &at, &TileBoxes::new(&at, &candidates), &mut r1);
            let walk = a.greedy_walk(&code, &candidates, &space, &mut r2);
            prop_assert_eq!(tiled, walk);
            prop_assert_eq!(r1.next_u64(), r2.next_u64(), "the same draws for the ties");
            prop_assert_eq!(tiled.1, a.q_sum(&code, space.encode(&tiled.0)), "the sum is the chosen action's");
            rng.next_u32();
        }
        Ok(())
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(24))]
        #[test]
        fn the_tiled_choice_is_the_plain_walk(seed in any::<u64>()) {
            // A plain hashed table of weights from {0, 16, 32} (ties).
            let mut a = agent(Layout::Hashed, vec![Q16::ZERO; 1 << 12], WeightInit::Constant(0.0));
            let mut rng = Pcg32::seed_from_u64(seed);
            a.reset_weights(&mut rng);
            for w in a.weights_mut().iter_mut() {
                *w = Q16((rng.next_u32() % 3) as i32 * 16);
            }
            a.rehash();
            tiled_is_the_walk(a, seed)?;
            // Claim tables: the host's, and the chips' 16-bit one; constant
            // initial weights (every candidate ties until learning).
            let host = ClaimTable::new(vec![Q16::ZERO; 1 << 12], Tags32(vec![0u32; 1 << 12])).unwrap();
            tiled_is_the_walk(agent(Layout::Claimed, host, WeightInit::Constant(0.0)), seed)?;
            let chip = ClaimTable::new(Half::<_, 12>::new(vec![0i16; 1 << 12]), Tags16(vec![0u16; 1 << 12])).unwrap();
            tiled_is_the_walk(agent(Layout::Claimed, chip, WeightInit::Uniform { min: 0.0, max: 0.01 }), seed)?;
        }
    }
}
