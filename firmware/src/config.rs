//! The learner's fixed sizes on the chip.
//!
//! What a robot is — its learning task, its joints with their servos,
//! calibration and soft limits, its encoder — is its one definition in
//! `pada_core::robot` ([`RobotSpec`]); how much it remembers is the board's
//! learner profile in `pada_core::profile`. This module holds only what is
//! the firmware's own: the sizes of its per-servo arrays and its agent.

use pada_core::agent::Agent;
use pada_core::robot::RobotSpec;
use pada_core::safety::SoftLimit;

pub use pada_core::profile::{Board, LearnerProfile, TILINGS, TRACE};

/// The most servos of a robot this firmware drives: the size of its
/// per-servo arrays and of its fatigue counter, as the bus, the wire and
/// the checkpoint allow ([`pada_core::limits::MAX_SERVOS`]).
pub const MAX_ROBOT_SERVOS: usize = pada_core::limits::MAX_SERVOS;
/// Most observation dimensions.
pub const MAX_OBS: usize = pada_core::limits::MAX_STATE_DIMS;

/// The agent the firmware runs.
pub type FirmwareAgent<W> = Agent<W, TILINGS, TRACE>;

/// The seed of the agent's generator when the host sets none.
pub const DEFAULT_SEED: u64 = 0x5041_4441;

/// The soft limits of `spec`'s joints that have one, in joint order, for
/// the safety machine (which takes them up to the first joint without
/// one).
pub fn soft_limits(spec: &RobotSpec) -> heapless::Vec<SoftLimit, { pada_core::safety::MAX_SOFT_LIMITS }> {
    let mut limits = heapless::Vec::new();
    for limit in spec.joints.iter().map_while(|j| j.soft_limit) {
        // At most MAX_SERVOS joints, the capacity (the definition's tests
        // check the count).
        let _ = limits.push(limit);
    }
    limits
}

#[cfg(test)]
mod tests {
    use super::*;
    use pada_core::robot::leo;

    #[test]
    fn leo_servos_are_in_joint_order_with_grl_ids() {
        let spec = &leo::SPEC;
        let id = |j: leo::Joint| spec.joints[j as usize].id;
        assert_eq!(
            [leo::Joint::Shoulder, leo::Joint::HipRight, leo::Joint::HipLeft, leo::Joint::KneeRight, leo::Joint::KneeLeft]
                .map(id),
            [1, 2, 3, 4, 5]
        );
        assert_eq!([id(leo::Joint::AnkleRight), id(leo::Joint::AnkleLeft)], [6, 7]);
        // Each soft limit is the definition's stop (the shoulder's ±90°
        // where it has none) widened by the margin.
        let limits = soft_limits(spec);
        assert_eq!(limits.len(), leo::NUM_JOINTS);
        for (i, l) in limits.iter().enumerate() {
            let [min, max] = leo::joint_limits(leo::JOINTS[i]).unwrap_or(leo::SHOULDER_SOFT_LIMITS);
            assert_eq!(*l, SoftLimit { min: min - leo::STOP_MARGIN, max: max + leo::STOP_MARGIN }, "joint {i}");
            // The start pose is inside every soft limit.
            let q = leo::START_JOINT_ANGLES[i];
            assert!(l.min < q && q < l.max, "joint {i}: {q} outside {l:?}");
        }
        assert!(soft_limits(&pada_core::robot::pendulum::SPEC_33HZ).is_empty());
    }
}
