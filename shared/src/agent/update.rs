//! The agent's SARSA(λ) update: the claims of the pair's features, the TD
//! error, and the trace's writes into the weights. The choice of the next
//! action (`choice.rs`) only reads them.

use super::{Agent, Current};
use crate::claim_table::Claim;
use crate::fixed::Q16;
use crate::weights::{entry_factor, WeightStore};
use rand_core::RngCore;

impl<W, const TILINGS: usize, const TRACE: usize> Agent<W, TILINGS, TRACE>
where
    W: WeightStore,
{
    /// The slots a learning update of `features` writes. A plain table's
    /// features are its slots. A claim table claims each feature's slot now
    /// (a fresh claim enters the running checksum); a refused claim gets
    /// `u32::MAX`, outside the table, so its update is dropped (and the
    /// table counts it).
    #[inline]
    fn claim_slots(&mut self, features: &[u32; TILINGS]) -> [u32; TILINGS] {
        if !self.weights.claims() {
            return *features;
        }
        let mut slots = [u32::MAX; TILINGS];
        for (slot, &f) in slots.iter_mut().zip(features) {
            if let Claim::Slot { slot: s, fresh } = self.weights.claim(f) {
                *slot = s;
                if fresh {
                    if let Some(c) = self.checksum.as_mut() {
                        let i = s as usize;
                        *c = c.wrapping_add(self.weights.raw(i).wrapping_mul(entry_factor(i)));
                    }
                }
            }
        }
        slots
    }

    /// The SARSA(λ) update for the pair `current` that earned `reward`;
    /// `q_next` is `Q(s', a')`, or `None` at an absorbing end. A table that
    /// rounds stochastically gets one dither from `rng` per weight write.
    ///
    /// The reward learned from is the plant's less the policy's penalty for
    /// the action that earned it ([`Policy::penalty`]: the action-change
    /// penalty, 0 for the other kinds); the caller's returns stay the
    /// plant's.
    pub(super) fn update<R: RngCore + ?Sized>(&mut self, current: &Current<TILINGS>, reward: f32, q_next: Option<Q16>, rng: &mut R) {
        let reward = reward - self.policy.penalty();
        let q = self.q_of(&current.features);
        let mut delta = Q16::from_f32(reward).0 as i64 - q.0 as i64;
        if let Some(qn) = q_next {
            delta += qn.mul_frac(self.gamma).0 as i64;
        }
        let delta = Q16::from_wide(delta);
        self.stats.last_td_error = delta;
        let step = delta.mul_frac(self.alpha);
        let slots = self.claim_slots(&current.features);
        self.trace.push(&slots);
        let dithered = self.weights.dithered();
        let weights = &mut self.weights;
        let checksum = &mut self.checksum;
        let mut saturations = 0u32;
        self.trace.for_each_entry(|entry, eligibility| {
            let inc = step.mul_frac(eligibility);
            if inc == Q16::ZERO {
                return;
            }
            for &f in entry {
                // Replaced slots hold u32::MAX: outside the table, so the
                // store writes nothing (and no dither is drawn for them).
                let i = f as usize;
                if i < weights.len() {
                    let dither = if dithered { rng.next_u32() } else { 0 };
                    let old = weights.raw(i);
                    saturations += weights.add(i, inc, dither) as u32;
                    if let Some(c) = checksum.as_mut() {
                        let change = weights.raw(i).wrapping_sub(old);
                        *c = c.wrapping_add(change.wrapping_mul(entry_factor(i)));
                    }
                }
            }
        });
        self.stats.saturations = self.stats.saturations.saturating_add(saturations);
        self.stats.updates += 1;
    }
}
