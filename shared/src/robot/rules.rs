//! The one interface between a controller and a robot: what a robot's
//! rules turn its readings into (observation, reward, absorbing states) and
//! its learner's output into (voltages on every servo, held joints, the
//! commands between episodes, the gearbox torques of the fatigue counter).
//!
//! The paper's own framework writes its behaviours against an actuation
//! interface that both the simulator and the robot provide; so does pada.
//! The firmware's controller is generic over [`RobotRules`], and so are
//! the host's drivers of it (`pada run --board`, `pada sil`, a robot of
//! the user's own simulated from its URDF). The pendulum's and LEO's rules
//! are two implementations ([`super::pendulum::Pendulum`],
//! [`super::leo::Leo`]); a robot of the user's own implements the trait in
//! its own crate, or takes the ready-made vocabulary of rewards and ends
//! that a `robot.toml` describes.

use super::RobotSpec;
use crate::limits::{MAX_SERVOS, MAX_STATE_DIMS};

/// One value per servo, in the robot's joint order (voltages \[V\] or
/// torques \[N·m\]); entries past the robot's joints are 0.
pub type PerServo = [f32; MAX_SERVOS];

/// What the controller read in one period, in joint order.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sensed {
    /// Each servo's joint angle \[rad\], `None` if it did not answer.
    pub angles: [Option<f32>; MAX_SERVOS],
    /// The encoder's unwrapped angle since boot \[rad\], `None` if unread.
    pub encoder_angle: Option<f32>,
    /// Foot switches (the robot's own bits, e.g. [`super::leo::contact`]).
    pub contacts: u8,
    /// The voltage each servo applied during the last period \[V\].
    pub applied: PerServo,
}

/// A robot's rules, as a controller drives it each period: [`sense`],
/// then [`observe`], [`reward`] and [`absorbing`] in an episode, and
/// [`commands`] (or [`reset_commands`] between episodes) for the servos.
///
/// [`sense`]: Self::sense
/// [`observe`]: Self::observe
/// [`reward`]: Self::reward
/// [`absorbing`]: Self::absorbing
/// [`commands`]: Self::commands
/// [`reset_commands`]: Self::reset_commands
pub trait RobotRules {
    /// The robot's definition: its learning task and its hardware.
    fn spec(&self) -> &'static RobotSpec;

    /// Clears what an episode accumulates (filters, stance, step length).
    fn start_episode(&mut self);

    /// Takes this period's readings.
    fn sense(&mut self, sensed: &Sensed);

    /// Writes the observation ([`RobotSpec::state`]'s dimensions); returns
    /// its length.
    fn observe(&self, obs: &mut [f32; MAX_STATE_DIMS]) -> usize;

    /// The reward of the transition into the current state, under the
    /// voltages applied during the last period.
    fn reward(&self, applied: &PerServo) -> f32;

    /// Whether the current state is absorbing (a fall): the episode ends
    /// without bootstrapping.
    fn absorbing(&self) -> bool;

    /// Per-servo voltages for the learner's output (one value per motor
    /// dimension) in an episode: the learned joints and the held ones.
    fn commands(&self, output: &[f32], volts: &mut PerServo);

    /// Per-servo voltages between episodes (e.g. holding the start pose).
    fn reset_commands(&self, volts: &mut PerServo);

    /// The gearbox torque of each servo \[N·m\] for the fatigue counter,
    /// as the robot can estimate it from the voltages applied during the
    /// last period and what it sensed.
    fn gear_torques(&self, applied: &PerServo, torques: &mut PerServo);

    /// Starts waiting for the robot to be back at its start.
    fn begin_reset(&mut self);

    /// One period of waiting; true once the next episode may start.
    fn reset_done(&mut self) -> bool;

    /// Whether the last [`sense`](Self::sense) saw a footstep (the stance
    /// leg changed), when the policy's memory moves with the joints
    /// ([`RobotSpec::footstep_remap`]).
    fn footstep(&self) -> bool {
        false
    }

    /// Distance walked in the current episode \[m\], for a walking robot.
    fn walked_m(&self) -> Option<f32> {
        None
    }
}
