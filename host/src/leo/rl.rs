//! LEO as a task of the experiment runner ([`crate::experiment::task::Task`]):
//! the walking task of Section VIII learned with SARSA(λ), PADA or the
//! low-pass filter through the same code as the pendulums.
//!
//! Everything the learner is — the 10-D mirrored state with GRL's tile
//! widths, 3 learned joints × 7 voltage levels in [−10.7, 10.7] V, the
//! voltages tile-coded with 6.67 V tiles, GRL's LEO learning parameters,
//! 25 s episodes at 30 Hz — is the robot's one definition,
//! [`pada_core::robot::leo::SPEC`]; the firmware builds its learner from
//! the same. The table is the host's learner profile
//! ([`Board::Host`]: hashed, 2^22 weights, 16 MiB of Q16.16 per agent), or
//! a board's with `pada run --board`.
//!
//! Gearbox torques for the fatigue counter: the mean gear torque of the
//! three learned joints over the step just taken (`learned_torques`).

use super::task::{Observation, ACTION_DIM, OBS_DIM};
use super::{LeoConfig, LeoEnv, Terminal};
use crate::experiment::task::{Plant, Step, Task, TaskSpec};
use pada_core::action_space::{Output, MAX_ACTION_DIMS};
use pada_core::agent::SarsaParams;
use pada_core::profile::{Board, LearnerProfile};
use pada_core::robot::Robot;
use rand_core::RngCore;

/// GRL's LEO learning parameters (`pada_core::robot::leo::PARAMS`, §3.9).
pub fn leo_params() -> SarsaParams {
    pada_core::robot::leo::PARAMS
}

/// The LEO walking task of Section VIII.
#[derive(Debug, Clone)]
pub struct LeoTask {
    config: LeoConfig,
    spec: TaskSpec,
}

impl Default for LeoTask {
    fn default() -> Self {
        Self::new(leo_params())
    }
}

impl LeoTask {
    /// The task with the host's learner and these learning parameters.
    pub fn new(params: SarsaParams) -> Self {
        Self::with_profile(Board::Host.profile(Robot::Leo), params)
    }

    /// The task with a board's learner `profile` (LEO's) and these learning
    /// parameters.
    pub fn with_profile(profile: LearnerProfile, params: SarsaParams) -> Self {
        let mut spec = TaskSpec::of_robot(
            profile,
            "LEO walking (Section VIII; rapier3d model of grl-facts §1-3, 30 Hz, 3 joints x 7 voltages)",
            "mean gear torque of the three learned joints (stance hip, swing hip, swing knee) over the control step, from the rapier3d model",
        );
        spec.params = params;
        spec.default_seconds = 14_666.0;
        spec.default_trials = 2;
        // The runner ends episodes after 750 steps; the environment's own
        // timeout is set beyond that so it never ends one first.
        let config = LeoConfig {
            timeout: 1.0e6,
            ..LeoConfig::default()
        };
        LeoTask { config, spec }
    }

    /// The environment configuration of the plants.
    pub fn config(&self) -> &LeoConfig {
        &self.config
    }
}

impl Task for LeoTask {
    type Plant = LeoPlant;
    fn spec(&self) -> &TaskSpec {
        &self.spec
    }
    fn plant(&self) -> LeoPlant {
        LeoPlant::new(self.config)
    }
}

/// A LEO environment as a [`Plant`].
pub struct LeoPlant {
    env: LeoEnv,
    torques: [f32; ACTION_DIM],
    walked: f32,
}

impl LeoPlant {
    /// A plant with this configuration. Panics if the configuration is
    /// unusable (the default one is checked by the sanity tests).
    pub fn new(config: LeoConfig) -> Self {
        LeoPlant {
            env: LeoEnv::new(config).expect("the LEO configuration builds a stable model"),
            torques: [0.0; ACTION_DIM],
            walked: 0.0,
        }
    }

    /// The environment.
    pub fn env(&self) -> &LeoEnv {
        &self.env
    }
}

fn write_obs(o: &Observation, obs: &mut [f32]) {
    obs[..OBS_DIM].copy_from_slice(&o.0);
}

impl Plant for LeoPlant {
    fn reset(&mut self, rng: &mut dyn RngCore, obs: &mut [f32]) {
        let o = self.env.reset(rng);
        self.torques = [0.0; ACTION_DIM];
        self.walked = 0.0;
        write_obs(&o, obs);
    }

    fn step(&mut self, command: &[f32], obs: &mut [f32]) -> Step {
        let r = self.env.step([command[0], command[1], command[2]]);
        self.torques = r.info.learned_torques;
        self.walked = r.info.walked_distance;
        write_obs(&r.obs, obs);
        Step {
            reward: r.reward,
            terminal: r.terminal == Terminal::Fall,
        }
    }

    fn gearbox_torques(&self, _command: &[f32]) -> Output {
        let mut t = [0.0; MAX_ACTION_DIMS];
        t[..ACTION_DIM].copy_from_slice(&self.torques);
        t
    }

    fn walked_distance_m(&self) -> Option<f64> {
        Some(self.walked as f64)
    }
}
