//! The agent's choice of the next action: the state's code, the greedy
//! choice over the policy's candidates (with or without action tiles), and
//! the exploration around it. It reads the weights and changes none of
//! them; the update (`update.rs`) writes them.

use super::{Agent, Decision, Mode};
use crate::action_space::{ActionSpace, Levels, MAX_ACTION_DIMS};
use crate::action_tiles::{ActionTiles, MAX_ACTION_COMBOS};
use crate::fixed::Q16;
use crate::policy::{uniform_below, Candidates, Exploration};
use crate::tile_coding::{StateCode, MAX_STATE_DIMS};
use crate::weights::WeightStore;
use rand_core::RngCore;

impl<W, const TILINGS: usize, const TRACE: usize> Agent<W, TILINGS, TRACE>
where
    W: WeightStore,
{
    /// The state code of `obs` plus the policy's extension.
    pub(super) fn code(&self, obs: &[f32]) -> StateCode<TILINGS> {
        let mut x = [0.0f32; MAX_STATE_DIMS];
        x[..obs.len()].copy_from_slice(obs);
        let ext = self.policy.extension();
        x[obs.len()..obs.len() + ext.len()].copy_from_slice(ext);
        self.coder.encode(&x[..obs.len() + ext.len()])
    }

    /// Sum of the active weights of (state, action): `TILINGS · Q`.
    #[inline]
    fn q_sum(&self, code: &StateCode<TILINGS>, action: u32) -> i64 {
        let w = &self.weights;
        let mut sum = 0i64;
        // The action-tile test once, not per tiling (the greedy loop's
        // inner body on the chip).
        match self.coder.action_tiles() {
            None => {
                for j in 0..TILINGS {
                    sum += w.read(self.coder.action_feature(code, j, action)).0 as i64;
                }
            }
            Some(at) => {
                for j in 0..TILINGS {
                    sum += w.read(self.coder.combo_feature(code, j, at.combo_of_action(j, action))).0 as i64;
                }
            }
        }
        sum
    }

    /// `Q` of a feature set: the mean of its weights.
    pub(super) fn q_of(&self, features: &[u32; TILINGS]) -> Q16 {
        let sum: i64 = features.iter().map(|&f| self.weights.read(f).0 as i64).sum();
        Q16::from_wide(sum / TILINGS as i64)
    }

    /// The next action by the policy's way of exploring
    /// ([`Policy::exploration`]): ε-greedy among its candidates (ε-PADA:
    /// the greedy choice among all actions, the exploratory draw within Δ
    /// of the previous one), or, for the noise explorations, the greedy
    /// action moved by the policy's noise while learning. Testing is always
    /// greedy. Changes nothing but the noise process;
    /// [`commit`](Self::commit) applies the choice.
    pub(super) fn decide<R: RngCore + ?Sized>(
        &mut self,
        obs: &[f32],
        rng: &mut R,
    ) -> (Decision, [u32; TILINGS]) {
        let code = self.code(obs);
        let learning = self.mode == Mode::Learning;
        let (levels, explore) = match self.policy.exploration() {
            Exploration::EpsilonGreedy | Exploration::EpsilonLocal => {
                let explore = learning && (rng.next_u32() as u64) < self.epsilon;
                let levels = if explore {
                    self.policy.explore_candidates().random(rng)
                } else {
                    self.greedy(&code, &self.policy.candidates(), self.policy.learner_space(), rng)
                };
                (levels, explore)
            }
            Exploration::Noise => {
                let greedy = self.greedy(&code, &self.policy.candidates(), self.policy.learner_space(), rng);
                if learning {
                    let moved = self.policy.perturb(&greedy, rng);
                    (moved, moved != greedy)
                } else {
                    (greedy, false)
                }
            }
        };
        let action = self.policy.learner_space().encode(&levels);
        let features = self.coder.features(&code, action);
        let q = self.q_of(&features);
        (Decision { action, levels, output: [0.0; MAX_ACTION_DIMS], explored: explore, q }, features)
    }

    /// The best candidate; ties broken uniformly at random (reservoir
    /// sampling: the k-th tie replaces the choice with probability 1/k).
    fn greedy<R: RngCore + ?Sized>(
        &self,
        code: &StateCode<TILINGS>,
        candidates: &Candidates,
        space: &ActionSpace,
        rng: &mut R,
    ) -> Levels {
        if let Some(at) = self.coder.action_tiles() {
            // Fewer combinations than candidates: load each combination's
            // weight once per tiling. Same sums, same order, same ties.
            if at.combos() < candidates.count() {
                return self.greedy_tiled(code, candidates, at, rng);
            }
        }
        let mut best = candidates.lo;
        let mut best_sum = i64::MIN;
        let mut ties = 0u32;
        candidates.for_each(|levels| {
            let sum = self.q_sum(code, space.encode(levels));
            if sum > best_sum {
                best_sum = sum;
                best = *levels;
                ties = 1;
            } else if sum == best_sum {
                ties += 1;
                if uniform_below(rng, ties) == 0 {
                    best = *levels;
                }
            }
        });
        best
    }

    /// [`greedy`](Self::greedy) with action tiles: a table of the
    /// `TILINGS × combos` active weights, then per candidate one table read
    /// per tiling. The candidates are visited in `Candidates::for_each`'s
    /// order (first dimension fastest), so ties break exactly as there;
    /// the other dimensions' share of each tiling's combination index is
    /// summed once per run of the first dimension.
    fn greedy_tiled<R: RngCore + ?Sized>(
        &self,
        code: &StateCode<TILINGS>,
        candidates: &Candidates,
        at: &ActionTiles<TILINGS>,
        rng: &mut R,
    ) -> Levels {
        const MASK: usize = MAX_ACTION_COMBOS - 1;
        let combos = at.combos() as usize;
        // The features first (their bits), then, where the table is larger
        // than a cache, one load of each (independent loads, whose misses
        // overlap), then the reads, whose probes now hit the cache. (Three
        // passes: the touch folded into the hashing loop measured 25·10³
        // more instructions per choice.)
        let mut table = [[0i32; MAX_ACTION_COMBOS]; TILINGS];
        for (j, row) in table.iter_mut().enumerate() {
            for (c, slot) in row.iter_mut().enumerate().take(combos) {
                *slot = self.coder.combo_feature(code, j, c as u32) as i32;
            }
        }
        if self.weights.touches_before_reading() {
            let mut touched = 0u32;
            for row in &table {
                for &feature in row.iter().take(combos) {
                    touched ^= self.weights.touch(feature as u32);
                }
            }
            core::hint::black_box(touched);
        }
        for row in table.iter_mut() {
            for slot in row.iter_mut().take(combos) {
                *slot = self.weights.read(*slot as u32).0;
            }
        }
        // Unused dimensions have lo = hi = 0 and contribute 0.
        let (lo, hi) = (candidates.lo, candidates.hi);
        let mut best = lo;
        let mut best_sum = i64::MIN;
        let mut ties = 0u32;
        let mut base = [0u32; TILINGS];
        for l3 in lo[3]..=hi[3] {
            for l2 in lo[2]..=hi[2] {
                for l1 in lo[1]..=hi[1] {
                    for (j, b) in base.iter_mut().enumerate() {
                        *b = at.part(j, 1, l1) + at.part(j, 2, l2) + at.part(j, 3, l3);
                    }
                    for l0 in lo[0]..=hi[0] {
                        let mut sum = 0i64;
                        for (j, row) in table.iter().enumerate() {
                            // base + part < combos ≤ MAX_ACTION_COMBOS (a
                            // power of two): the mask only drops the check.
                            sum += row[(base[j] + at.part(j, 0, l0)) as usize & MASK] as i64;
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
        best
    }

}
