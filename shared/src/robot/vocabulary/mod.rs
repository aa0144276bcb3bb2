//! The rules of a robot said in a small fixed vocabulary, so that a robot
//! of the user's own needs a `robot.toml` and a URDF and no code: the
//! signals it observes (joint angles and rates, the coordinates of named
//! points and their rates), the reward as a sum of terms (a quadratic cost
//! about a target, a point's distance or squared distance to a target
//! point, a point's
//! progress along an axis, an action and an action-change cost, a constant
//! per step), the limits that end an episode, the P laws of the joints the
//! learner does not drive, and the start pose a robot is brought back to
//! between episodes. [`Vocab`] applies them ([`crate::robot::RobotRules`]),
//! on the chip and on the host alike.
//!
//! | piece | `robot.toml` | here |
//! |---|---|---|
//! | a quantity | `"shoulder.angle"`, `"elbow.rate"`, `"tip.z"`, `"tip.z_rate"` | [`Signal`] |
//! | a point of a link | `[point.tip]` | [`Point`] (its kinematic chain from the URDF) |
//! | the reward | `[[reward]]` | [`RewardTerm`] |
//! | an end | `[[end]]` | [`End`] |
//! | a held joint | `[joint.X] hold_gain_v_per_rad` | [`Hold`] |
//!
//! A task the vocabulary cannot say implements [`crate::robot::RobotRules`]
//! in its own crate, as the pendulum and LEO do.

pub mod kinematics;
mod rules;

pub use kinematics::{ChainJoint, Point, Pose, MAX_CHAIN};
pub use rules::Vocab;

/// Points a robot's rules name, at most.
pub const MAX_POINTS: usize = 4;

/// A quantity of the robot, as the chip and the simulation both measure
/// it: from the joint angles alone (rates are differences over the control
/// period; points come from the URDF's kinematics).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Signal {
    /// Joint `.0`'s angle \[rad\].
    Angle(u8),
    /// Joint `.0`'s rate \[rad/s\].
    Rate(u8),
    /// Coordinate `axis` (0 x, 1 y, 2 z) of point `point` in the base frame
    /// \[m\].
    Position {
        /// The point ([`Vocabulary::points`]).
        point: u8,
        /// 0 x, 1 y, 2 z.
        axis: u8,
    },
    /// The rate of that coordinate \[m/s\].
    Velocity {
        /// The point ([`Vocabulary::points`]).
        point: u8,
        /// 0 x, 1 y, 2 z.
        axis: u8,
    },
}

/// One term of the reward; the reward of a step is their sum, evaluated on
/// the state the step reached and the voltages applied during it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum RewardTerm {
    /// `weight · (signal − target)²` (with `wrap`, the difference of two
    /// angles taken in (−π, π]). A cost has a negative weight: the
    /// pendulum's `−5θ²` is `weight −5` about `target 0`.
    Quadratic {
        /// What is measured.
        signal: Signal,
        /// Its target.
        target: f32,
        /// The weight.
        weight: f32,
        /// Whether the difference is an angle's.
        wrap: bool,
    },
    /// `weight · ‖point − target‖` \[m\].
    Distance {
        /// The point ([`Vocabulary::points`]).
        point: u8,
        /// Where it should be, in the base frame \[m\].
        target: [f32; 3],
        /// The weight (negative: a cost).
        weight: f32,
    },
    /// `weight · ‖point − target‖²` \[m²\]: the squared distance, a cost
    /// that grows gently near the target and steeply far from it (a
    /// [`RewardTerm::Distance`] pulls as hard at 1 mm as at 1 m).
    DistanceSquared {
        /// The point ([`Vocabulary::points`]).
        point: u8,
        /// Where it should be, in the base frame \[m\].
        target: [f32; 3],
        /// The weight per m² (negative: a cost).
        weight: f32,
    },
    /// `weight · Δ` of the point's coordinate `axis` over the step \[m\]:
    /// forward progress.
    Progress {
        /// The point ([`Vocabulary::points`]).
        point: u8,
        /// 0 x, 1 y, 2 z.
        axis: u8,
        /// The weight per metre.
        weight: f32,
    },
    /// `weight · Σ u²` over the learned joints, `u` the voltage applied
    /// \[V\].
    Action {
        /// The weight per V².
        weight: f32,
    },
    /// `weight · Σ (u − u_prev)²` over the learned joints: the change of
    /// the applied voltage since the step before.
    ActionChange {
        /// The weight per V².
        weight: f32,
    },
    /// `value` every step (a time penalty or a survival bonus).
    Constant {
        /// The value.
        value: f32,
    },
}

/// An episode ends, absorbing, when `signal` leaves `[min, max]`; the step
/// that leaves earns `reward` besides the reward's terms.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct End {
    /// What is watched.
    pub signal: Signal,
    /// The lowest allowed value.
    pub min: f32,
    /// The highest allowed value.
    pub max: f32,
    /// The reward of leaving (negative: a penalty).
    pub reward: f32,
}

/// A joint the learner does not drive, held by a P law in an episode.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Hold {
    /// The joint.
    pub joint: u8,
    /// Its set point \[rad\].
    pub target: f32,
    /// The gain \[V/rad\].
    pub gain_v_per_rad: f32,
}

/// Between episodes every joint is held at the start pose by a P law with
/// `gain_v_per_rad`; the next episode starts once every joint has been
/// within `tolerance_rad` of it and slower than `still_rad_s` for
/// `settle_us`, or after `timeout_us` whatever the pose.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Reset {
    /// The P gain towards the start pose \[V/rad\].
    pub gain_v_per_rad: f32,
    /// Close enough to the start pose \[rad\].
    pub tolerance_rad: f32,
    /// Still enough \[rad/s\].
    pub still_rad_s: f32,
    /// For this long \[µs\].
    pub settle_us: u32,
    /// The longest wait \[µs\].
    pub timeout_us: u32,
}

/// A robot's rules in the vocabulary: the data [`Vocab`] applies.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Vocabulary {
    /// The observation, one signal per dimension of
    /// [`crate::robot::RobotSpec::state`] (which gives each one's range and
    /// tile width).
    pub observation: &'static [Signal],
    /// The joint each motor dimension drives, in motor order.
    pub learned: &'static [u8],
    /// The joints held by a P law during an episode.
    pub held: &'static [Hold],
    /// The learned voltages are clipped to ±this \[V\]; the held ones too.
    pub voltage_limit_v: f32,
    /// The start pose, one angle per joint \[rad\].
    pub start: &'static [f32],
    /// How the robot is brought back to it between episodes.
    pub reset: Reset,
    /// The points the signals name (at most [`MAX_POINTS`]).
    pub points: &'static [Point],
    /// The reward's terms.
    pub rewards: &'static [RewardTerm],
    /// The limits that end an episode.
    pub ends: &'static [End],
}

impl Vocabulary {
    /// Writes every number of the rules into `h`, for the robot's
    /// definition hash (a change of a reward's weight is another robot).
    pub fn hash_into(&self, h: &mut crate::crc::ConfigHasher) {
        fn signal(h: &mut crate::crc::ConfigHasher, s: &Signal) {
            let (kind, a, b) = match *s {
                Signal::Angle(j) => (1, j, 0),
                Signal::Rate(j) => (2, j, 0),
                Signal::Position { point, axis } => (3, point, axis),
                Signal::Velocity { point, axis } => (4, point, axis),
            };
            h.write_u32(kind).write_u32(a as u32).write_u32(b as u32);
        }
        h.write_u32(self.observation.len() as u32);
        for s in self.observation {
            signal(h, s);
        }
        h.write_u32(self.learned.len() as u32);
        for j in self.learned {
            h.write_u32(*j as u32);
        }
        h.write_u32(self.held.len() as u32);
        for hold in self.held {
            h.write_u32(hold.joint as u32).write_f32(hold.target).write_f32(hold.gain_v_per_rad);
        }
        h.write_f32(self.voltage_limit_v).write_u32(self.start.len() as u32);
        for q in self.start {
            h.write_f32(*q);
        }
        let r = &self.reset;
        h.write_f32(r.gain_v_per_rad).write_f32(r.tolerance_rad).write_f32(r.still_rad_s);
        h.write_u32(r.settle_us).write_u32(r.timeout_us);
        h.write_u32(self.points.len() as u32);
        for p in self.points {
            h.write_str(p.name).write_u32(p.chain.len() as u32);
            for c in p.chain {
                for x in c.xyz.iter().chain(&c.rpy).chain(&c.axis) {
                    h.write_f32(*x);
                }
                h.write_u32(c.joint.map_or(u32::MAX, |j| j as u32));
            }
            for x in p.offset {
                h.write_f32(x);
            }
        }
        h.write_u32(self.rewards.len() as u32);
        for term in self.rewards {
            match *term {
                RewardTerm::Quadratic { signal: s, target, weight, wrap } => {
                    h.write_u32(1);
                    signal(h, &s);
                    h.write_f32(target).write_f32(weight).write_u32(wrap as u32);
                }
                RewardTerm::Distance { point, target, weight } => {
                    h.write_u32(2).write_u32(point as u32);
                    for x in target {
                        h.write_f32(x);
                    }
                    h.write_f32(weight);
                }
                RewardTerm::Progress { point, axis, weight } => {
                    h.write_u32(3).write_u32(point as u32).write_u32(axis as u32).write_f32(weight);
                }
                RewardTerm::Action { weight } => {
                    h.write_u32(4).write_f32(weight);
                }
                RewardTerm::ActionChange { weight } => {
                    h.write_u32(5).write_f32(weight);
                }
                RewardTerm::Constant { value } => {
                    h.write_u32(6).write_f32(value);
                }
                RewardTerm::DistanceSquared { point, target, weight } => {
                    h.write_u32(7).write_u32(point as u32);
                    for x in target {
                        h.write_f32(x);
                    }
                    h.write_f32(weight);
                }
            }
        }
        h.write_u32(self.ends.len() as u32);
        for e in self.ends {
            signal(h, &e.signal);
            h.write_f32(e.min).write_f32(e.max).write_f32(e.reward);
        }
    }
}

#[cfg(test)]
mod tests;
