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
    /// `TILINGS · Q` of `features` and the slots a learning update of them
    /// writes. A plain table's features are its slots. A claim table reads
    /// every feature's weight, then claims each feature's slot (a fresh
    /// claim enters the running checksum), one probe for both where it can
    /// ([`WeightStore::read_then_claim`]); a refused claim gets `u32::MAX`,
    /// outside the table, so its update is dropped (and the table counts
    /// it).
    #[inline]
    fn read_and_claim(&mut self, features: &[u32; TILINGS]) -> (i64, [u32; TILINGS]) {
        let mut claims = [Claim::Refused; TILINGS];
        let sum = self.weights.read_then_claim(features, &mut claims);
        let mut slots = [u32::MAX; TILINGS];
        for (slot, claim) in slots.iter_mut().zip(claims) {
            match claim {
                Claim::Slot { slot: s, fresh } => {
                    *slot = s;
                    if fresh {
                        if let Some(c) = self.checksum.as_mut() {
                            let i = s as usize;
                            *c = c.wrapping_add(self.weights.raw(i).wrapping_mul(entry_factor(i)));
                        }
                    }
                }
                Claim::Replaced { slot: s, old_raw } => {
                    *slot = s;
                    let i = s as usize;
                    if let Some(c) = self.checksum.as_mut() {
                        let change = self.weights.raw(i).wrapping_sub(old_raw);
                        *c = c.wrapping_add(change.wrapping_mul(entry_factor(i)));
                    }
                    // The slot's old feature is gone: the trace's older
                    // entries must not credit the new one with its
                    // eligibility.
                    self.trace.forget(s);
                }
                Claim::Refused => {}
            }
        }
        (sum, slots)
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
        let (sum, slots) = self.read_and_claim(&current.features);
        let q = Q16::from_wide(sum / TILINGS as i64);
        let mut delta = Q16::from_f32(reward).0 as i64 - q.0 as i64;
        if let Some(qn) = q_next {
            delta += qn.mul_frac(self.gamma).0 as i64;
        }
        let delta = Q16::from_wide(delta);
        self.stats.last_td_error = delta;
        let step = delta.mul_frac(self.alpha);
        self.trace.push(&slots);
        let weights = &mut self.weights;
        let mut saturations = 0u32;
        let mut change = 0u32;
        self.trace.for_each_entry(|entry, eligibility| {
            let inc = step.mul_frac(eligibility);
            if inc == Q16::ZERO {
                return;
            }
            // Replaced slots hold u32::MAX: outside the table, so the store
            // writes nothing (and draws no dither for them).
            let added = weights.add_each(entry, inc, || rng.next_u32());
            saturations += added.saturations;
            change = change.wrapping_add(added.checksum_change);
        });
        if let Some(c) = self.checksum.as_mut() {
            *c = c.wrapping_add(change);
        }
        self.stats.saturations = self.stats.saturations.saturating_add(saturations);
        self.stats.updates += 1;
    }
}
