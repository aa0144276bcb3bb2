//! The agent's choice of the next action: the state's code, the greedy
//! choice over the policy's candidates (with or without action tiles), and
//! the exploration around it. It reads the weights and changes none of
//! them; the update (`update.rs`) writes them.

use super::tiled::TileBoxes;
use super::{Agent, Decision, Mode};
use crate::action_space::{ActionSpace, Levels, MAX_ACTION_DIMS};
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
    pub(super) fn q_sum(&self, code: &StateCode<TILINGS>, action: u32) -> i64 {
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
    /// ([`Policy::exploration`](crate::policy::Policy::exploration)):
    /// ε-greedy among its candidates (ε-PADA: the greedy choice among all
    /// actions, the exploratory draw within Δ of the previous one), or, for
    /// the noise explorations, the greedy action moved by the policy's
    /// noise while learning. Testing is always greedy. Changes nothing but
    /// the noise process; [`commit`](Self::commit) applies the choice.
    pub(super) fn decide<R: RngCore + ?Sized>(
        &mut self,
        obs: &[f32],
        rng: &mut R,
    ) -> (Decision, [u32; TILINGS]) {
        let code = self.code(obs);
        let learning = self.mode == Mode::Learning;
        // The greedy choice's sum of the chosen action's weights, when the
        // choice is the greedy action: its `Q` without reading them again.
        let (levels, explore, greedy_sum) = match self.policy.exploration() {
            Exploration::EpsilonGreedy | Exploration::EpsilonLocal => {
                let explore = learning && (rng.next_u32() as u64) < self.epsilon;
                if explore {
                    (self.policy.explore_candidates().random(rng), true, None)
                } else {
                    let candidates = self.policy.candidates();
                    self.prepare_boxes(&candidates);
                    let (levels, sum) = self.greedy(&code, &candidates, self.policy.learner_space(), rng);
                    (levels, false, Some(sum))
                }
            }
            Exploration::Noise => {
                let candidates = self.policy.candidates();
                self.prepare_boxes(&candidates);
                let (greedy, sum) = self.greedy(&code, &candidates, self.policy.learner_space(), rng);
                if learning {
                    let moved = self.policy.perturb(&greedy, rng);
                    (moved, moved != greedy, (moved == greedy).then_some(sum))
                } else {
                    (greedy, false, Some(sum))
                }
            }
        };
        let action = self.policy.learner_space().encode(&levels);
        let features = self.coder.features(&code, action);
        let q = match greedy_sum {
            Some(sum) => Q16::from_wide(sum / TILINGS as i64),
            None => self.q_of(&features),
        };
        (Decision { action, levels, output: [0.0; MAX_ACTION_DIMS], explored: explore, q }, features)
    }

    /// The best candidate and its sum of weights (`TILINGS · Q`); ties
    /// broken uniformly at random (reservoir sampling: the k-th tie
    /// replaces the choice with probability 1/k), the candidates visited in
    /// [`Candidates::for_each`]'s order.
    pub(super) fn greedy<R: RngCore + ?Sized>(
        &self,
        code: &StateCode<TILINGS>,
        candidates: &Candidates,
        space: &ActionSpace,
        rng: &mut R,
    ) -> (Levels, i64) {
        if let Some(at) = self.coder.action_tiles() {
            // Fewer weights to read as each tiling's tile combinations than
            // as each candidate's features: read each once. Same sums, same
            // order, same ties.
            let local;
            let boxes = match &self.boxes {
                Some((made_for, boxes)) if made_for == candidates => boxes,
                _ => {
                    local = TileBoxes::new(at, candidates);
                    &local
                }
            };
            if boxes.total() < candidates.count().saturating_mul(TILINGS as u32) {
                return self.greedy_tiled(code, candidates, at, boxes, rng);
            }
        }
        self.greedy_walk(code, candidates, space, rng)
    }

    /// Makes the tiled greedy choice's boxes for `candidates` unless they
    /// are made already (with action tiles only).
    fn prepare_boxes(&mut self, candidates: &Candidates) {
        if let Some(at) = self.coder.action_tiles() {
            if !matches!(&self.boxes, Some((made_for, _)) if made_for == candidates) {
                self.boxes = Some((*candidates, TileBoxes::new(at, candidates)));
            }
        }
    }

    /// [`greedy`](Self::greedy) by every candidate's own features: the
    /// plain walk (and the reference the tiled choice is tested against).
    pub(super) fn greedy_walk<R: RngCore + ?Sized>(
        &self,
        code: &StateCode<TILINGS>,
        candidates: &Candidates,
        space: &ActionSpace,
        rng: &mut R,
    ) -> (Levels, i64) {
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
        (best, best_sum)
    }
}
