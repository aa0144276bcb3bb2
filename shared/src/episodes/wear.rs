//! The wear governor's feed ([`crate::governor`]): the damage each governed
//! gearbox took between two moments, from the fatigue counter's exact
//! integer damage (Eqs. 3–7), written once for the chip and the host.
//!
//! A driver takes [`damage_raws`] before it feeds the counter a learning
//! action's torques ([`super::Transition::is_learning_action`]) and hands
//! [`increments`] to [`Governor::observe`](crate::governor::Governor::observe).

use crate::fatigue::FatigueCounter;
use crate::governor::GOVERNED_JOINTS;
use core::ops::Range;

/// Every joint's damage, in the counter's integer units.
pub fn damage_raws<const N: usize>(fatigue: &FatigueCounter<N>) -> [u64; N] {
    core::array::from_fn(|j| fatigue.joints()[j].damage_raw())
}

/// The damage the governed `joints` took since `before` (at most
/// [`GOVERNED_JOINTS`]; the rest stay 0). Damage only grows, but a counter
/// restored from a checkpoint between the two moments could be behind:
/// that reads as no damage, never as a wrapped-around huge one.
pub fn increments<const N: usize>(before: &[u64; N], fatigue: &FatigueCounter<N>, joints: Range<usize>) -> [u64; GOVERNED_JOINTS] {
    let mut out = [0u64; GOVERNED_JOINTS];
    for (slot, j) in out.iter_mut().zip(joints.filter(|&j| j < N)) {
        *slot = fatigue.joints()[j].damage_raw().saturating_sub(before[j]);
    }
    out
}
