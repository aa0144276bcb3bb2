//! The wear governor on the board (`SetMtbfBudget`): built for the robot's
//! definition and the running policy, and fed each learning period's
//! damage from the controller's fatigue counter.
//!
//! The rule is the learning core's ([`pada_core::governor`]); what the
//! board adds is its input: the damage of the **reported joints** (the
//! gearboxes the learned actions drive: the pendulum's motor, LEO's hips
//! and knees) as the board's own torque estimate counts it, in periods
//! that applied a **learning action** — as `pada run` and the paper's MTBF
//! count them. Test runs and the waits between episodes are not learning
//! and do not move the governor.

use crate::config::MAX_ROBOT_SERVOS;
use core::ops::Range;
use pada_core::error::ConfigError;
use pada_core::fatigue::{FatigueCounter, GearboxParams};
use pada_core::governor::{Governor, GovernorConfig, GOVERNED_JOINTS};
use pada_core::policy::PolicyKind;
use pada_core::robot::RobotSpec;

/// A governor for `spec`'s robot learning with the built `policy`, holding
/// `budget_s`, following the joints `reported` (at most four).
pub fn governor(spec: &RobotSpec, policy: &PolicyKind, budget_s: f32, reported: Range<usize>) -> Result<Governor, ConfigError> {
    let motor = spec.motor()?;
    let config = GovernorConfig {
        budget_s,
        period_s: spec.period_s(),
        gearbox: GearboxParams::TABLE_I,
        worst_torque_nm: spec.worst_commanded_torque(),
        joints: reported.len().min(GOVERNED_JOINTS) as u8,
    };
    Governor::new(policy, &motor, &config)
}

/// Each servo's damage (Q16.48), to diff after the period's update.
pub fn damage_raws(fatigue: &FatigueCounter<MAX_ROBOT_SERVOS>) -> [u64; MAX_ROBOT_SERVOS] {
    core::array::from_fn(|j| fatigue.joints()[j].damage_raw())
}

/// The damage each reported joint took since `before`, in the governor's
/// order.
pub fn increments(
    before: &[u64; MAX_ROBOT_SERVOS],
    fatigue: &FatigueCounter<MAX_ROBOT_SERVOS>,
    reported: Range<usize>,
) -> [u64; GOVERNED_JOINTS] {
    let mut out = [0u64; GOVERNED_JOINTS];
    for (slot, j) in out.iter_mut().zip(reported) {
        *slot = fatigue.joints()[j].damage_raw().saturating_sub(before[j]);
    }
    out
}
