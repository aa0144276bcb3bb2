//! The one interface between the controller and a robot: what
//! [`crate::control::Controller`] needs from the pendulum or LEO, as the
//! paper's own framework writes its behaviours against an actuation
//! interface that both the simulator and the robot provide.
//!
//! Each implementation ([`crate::pendulum::Pendulum`],
//! [`crate::leo::Leo`]) is an adapter: it turns servo positions, the
//! encoder and the foot switches into the quantities of the robot's one
//! definition in `pada_core::robot`, and applies that definition's rules
//! (observation, reward, falls, held joints). Only what is the robot's on
//! the bench lives here: turning counts into angles and rates, and waiting
//! between episodes until the robot is back at its start.

use crate::config::{RobotConfig, MAX_OBS, MAX_ROBOT_SERVOS};
use core::ops::Range;
use pada_core::robot::{Robot, RobotSpec};

/// What the controller read in one period, in joint order.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sensed {
    /// Each servo's joint angle \[rad\], `None` if it did not answer.
    pub angles: [Option<f32>; MAX_ROBOT_SERVOS],
    /// The encoder's unwrapped angle since boot \[rad\], `None` if unread.
    pub encoder_angle: Option<f32>,
    /// Foot switches ([`crate::leo::contact`] bits).
    pub contacts: u8,
    /// The voltage each servo applied during the last period \[V\].
    pub applied: [f32; MAX_ROBOT_SERVOS],
}

/// A robot as the controller drives it.
pub trait RobotAdapter {
    /// Which robot.
    const ROBOT: Robot;

    /// Its learning task (`pada_core::robot`).
    fn spec() -> &'static RobotSpec {
        Self::ROBOT.spec()
    }

    /// An adapter for the robot's hardware description.
    fn new(config: &RobotConfig) -> Self;

    /// Clears what an episode accumulates (filters, stance, step length).
    fn start_episode(&mut self);

    /// Takes this period's readings.
    fn sense(&mut self, sensed: &Sensed);

    /// Writes the observation; returns its length.
    fn observe(&self, obs: &mut [f32; MAX_OBS]) -> usize;

    /// The reward of the transition into the current state, under the
    /// voltages applied during the last period.
    fn reward(&self, applied: &[f32; MAX_ROBOT_SERVOS]) -> f32;

    /// Whether the current state is absorbing (a fall).
    fn absorbing(&self) -> bool;

    /// Per-servo voltages for the learner's output (one value per motor
    /// dimension) in an episode.
    fn commands(&self, output: &[f32], volts: &mut [f32; MAX_ROBOT_SERVOS]);

    /// Per-servo voltages between episodes.
    fn reset_commands(&self, volts: &mut [f32; MAX_ROBOT_SERVOS]);

    /// The gearbox torque of each servo \[N·m\] for the fatigue counter,
    /// under the voltages applied during the last period.
    fn gear_torques(&self, applied: &[f32; MAX_ROBOT_SERVOS], torques: &mut [f32; MAX_ROBOT_SERVOS]);

    /// Starts waiting for the robot to be back at its start.
    fn begin_reset(&mut self);

    /// One period of waiting; true once the next episode may start.
    fn reset_done(&mut self) -> bool;

    /// The servos whose fatigue each `Step` record reports: the learned
    /// joints.
    fn reported_joints() -> Range<usize>;

    /// Whether the last [`sense`](Self::sense) saw a footstep (the stance
    /// leg changed), when the policy's memory moves with the joints
    /// (`RobotSpec::footstep_remap`).
    fn footstep(&self) -> bool {
        false
    }

    /// Distance walked in the current episode \[m\], for a walking robot.
    fn walked_m(&self) -> Option<f32> {
        None
    }
}
