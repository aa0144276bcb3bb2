//! The robots' hardware as the firmware drives it, and the learner's fixed
//! sizes.
//!
//! What the learner learns (observation, motor, learning parameters,
//! timing) is each robot's one definition in `pada_core::robot`; how much
//! it remembers is the board's learner profile in `pada_core::profile`.
//! This module holds only what is the firmware's own: which servo is which
//! joint, how its position counts map to the joint angle, the soft limits
//! that fault the robot, the encoder, and the supply assumed until a servo
//! reports it.
//!
//! | robot | servos | encoder |
//! |---|---|---|
//! | physical pendulum (33 or 20 Hz, Section VII) | one RX-28 in wheel mode, ID 1 | on the axis |
//! | LEO (Section VIII) | 7 RX-28s, IDs 1–7 in GRL's raw order | the boom's, for the torso angle |

use crate::servo::Joint;
use pada_core::agent::Agent;
use pada_core::robot::leo::{self, Joint as LeoJoint, NUM_JOINTS};
use pada_core::safety::SoftLimit;

pub use pada_core::profile::{Board, LearnerProfile, TILINGS, TRACE};
pub use pada_core::robot::Robot;

/// The most servos of a robot this firmware drives (LEO's seven): the size
/// of its per-servo arrays and of its fatigue counter. The bus, the wire
/// and the checkpoint allow more ([`pada_core::limits::MAX_SERVOS`]).
pub const MAX_ROBOT_SERVOS: usize = NUM_JOINTS;
const _: () = assert!(MAX_ROBOT_SERVOS <= pada_core::limits::MAX_SERVOS);
/// Most observation dimensions (LEO's 10).
pub const MAX_OBS: usize = 10;

/// The agent the firmware runs.
pub type FirmwareAgent<W> = Agent<W, TILINGS, TRACE>;

/// The seed of the agent's generator when the host sets none.
pub const DEFAULT_SEED: u64 = 0x5041_4441;

/// The quadrature encoder on the pendulum's axis or LEO's boom.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EncoderConfig {
    /// Counts per revolution after the timer's ×4 decoding (a 1024-line
    /// encoder gives 4096).
    pub counts_per_rev: u32,
    /// +1 if counting up turns the measured angle positive.
    pub sign: i8,
}

/// A robot's hardware.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RobotConfig {
    /// Which robot.
    pub robot: Robot,
    /// The servos, in the robot's joint order.
    pub joints: &'static [Joint],
    /// Soft limit per joint (same order), `None` for a joint without one.
    pub soft_limits: &'static [Option<SoftLimit>],
    /// The encoder.
    pub encoder: EncoderConfig,
    /// Supply voltage assumed until a servo reports it \[V\].
    pub supply_nominal_v: f32,
}

impl RobotConfig {
    /// The robot's name.
    pub fn name(&self) -> &'static str {
        self.robot.name()
    }

    /// The control period \[µs\].
    pub fn period_us(&self) -> u32 {
        self.robot.spec().period_us
    }
}

/// The pendulum's motor: Dynamixel ID 1, position counts increasing with
/// the positive (counter-clockwise) voltage.
const PENDULUM_JOINTS: [Joint; 1] = [Joint { id: 1, zero: 512, sign: 1 }];

/// LEO's servos in [`LeoJoint`] order (shoulder, hip L/R, knee L/R, ankle
/// L/R), with the IDs of GRL's raw order (docs/reference/grl.md §3.1: shoulder 1,
/// hip R 2, hip L 3, knee R 4, knee L 5, ankle R 6, ankle L 7). `zero` is
/// the raw position at joint angle 0 and `sign` maps the servo's direction
/// to GRL's joint sign (§1.2, §1.5): **calibrate both on your robot**;
/// these are the mid-range defaults.
const LEO_JOINTS: [Joint; NUM_JOINTS] = [
    Joint { id: 1, zero: 512, sign: 1 },
    Joint { id: 3, zero: 512, sign: 1 },
    Joint { id: 2, zero: 512, sign: 1 },
    Joint { id: 5, zero: 512, sign: 1 },
    Joint { id: 4, zero: 512, sign: 1 },
    Joint { id: 7, zero: 512, sign: 1 },
    Joint { id: 6, zero: 512, sign: 1 },
];

/// Margin outside LEO's joint stops (docs/reference/grl.md §1.5) before a soft-limit
/// fault \[rad\]: the stops are soft springs, a joint that passes them by
/// this much is being driven into them.
const STOP_MARGIN: f32 = 0.15;

/// The shoulder has no stop (§1.5, `joint_limits` is `None`): its soft
/// limit, a fault and not a physical stop, is ±90°.
const SHOULDER_SOFT_LIMITS: [f32; 2] = [-core::f32::consts::FRAC_PI_2, core::f32::consts::FRAC_PI_2];

const fn limit([min, max]: [f32; 2]) -> Option<SoftLimit> {
    Some(SoftLimit { min: min - STOP_MARGIN, max: max + STOP_MARGIN })
}

/// LEO's soft limits in joint order: the definition's stops
/// (`leo::joint_limits`; the shoulder's ±90° where it has none) plus the
/// margin.
const LEO_LIMITS: [Option<SoftLimit>; NUM_JOINTS] = {
    let mut out = [None; NUM_JOINTS];
    let mut i = 0;
    while i < NUM_JOINTS {
        out[i] = limit(match leo::joint_limits(leo::JOINTS[i]) {
            Some(stop) => stop,
            None => SHOULDER_SOFT_LIMITS,
        });
        i += 1;
    }
    out
};

/// The pendulum turns freely: no soft limit.
const PENDULUM_LIMITS: [Option<SoftLimit>; 1] = [None];

const _: () = assert!(LeoJoint::AnkleRight as usize == NUM_JOINTS - 1);

/// The robot's hardware.
pub const fn hardware(robot: Robot) -> RobotConfig {
    match robot {
        Robot::Pendulum33 | Robot::Pendulum20 => RobotConfig {
            robot,
            joints: &PENDULUM_JOINTS,
            soft_limits: &PENDULUM_LIMITS,
            encoder: EncoderConfig { counts_per_rev: 4096, sign: 1 },
            supply_nominal_v: 12.0,
        },
        Robot::Leo => RobotConfig {
            robot,
            joints: &LEO_JOINTS,
            soft_limits: &LEO_LIMITS,
            // The boom's encoder; the torso angle is minus its angle (§3.1).
            encoder: EncoderConfig { counts_per_rev: 4096, sign: 1 },
            // LEO_SUPPLY_VOLTAGE (docs/reference/grl.md §2.2).
            supply_nominal_v: pada_core::rx28::LEO_SUPPLY_VOLTAGE,
        },
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn leo_servos_are_in_joint_order_with_grl_ids() {
        let hw = hardware(Robot::Leo);
        assert_eq!(hw.joints.len(), MAX_ROBOT_SERVOS);
        assert_eq!(hw.soft_limits.len(), MAX_ROBOT_SERVOS);
        let id = |j: LeoJoint| hw.joints[j as usize].id;
        assert_eq!(
            [LeoJoint::Shoulder, LeoJoint::HipRight, LeoJoint::HipLeft, LeoJoint::KneeRight, LeoJoint::KneeLeft]
                .map(id),
            [1, 2, 3, 4, 5]
        );
        assert_eq!([id(LeoJoint::AnkleRight), id(LeoJoint::AnkleLeft)], [6, 7]);
        // Each soft limit is the definition's stop (the shoulder's ±90°
        // where it has none) widened by the margin.
        for (i, l) in hw.soft_limits.iter().enumerate() {
            let [min, max] = leo::joint_limits(leo::JOINTS[i]).unwrap_or(SHOULDER_SOFT_LIMITS);
            assert_eq!(*l, Some(SoftLimit { min: min - STOP_MARGIN, max: max + STOP_MARGIN }), "joint {i}");
        }
        // The start pose is inside every soft limit.
        for (i, l) in hw.soft_limits.iter().enumerate() {
            let l = l.unwrap();
            let q = leo::START_JOINT_ANGLES[i];
            assert!(l.min < q && q < l.max, "joint {i}: {q} outside {l:?}");
        }
    }
}
