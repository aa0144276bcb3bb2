//! LEO as a task of the experiment runner ([`crate::task::Task`]):
//! the walking task of Section VIII learned with SARSA(λ), PADA or the
//! low-pass filter through the same code as the pendulums.
//!
//! Everything the learner is — the 10-D mirrored state with GRL's tile
//! widths, 3 learned joints × 7 voltage levels in [−10.7, 10.7] V, the
//! voltages tile-coded with 6.67 V tiles, GRL's LEO learning parameters,
//! 25 s episodes at 30 Hz — is the robot's one definition,
//! [`pada_core::robot::leo::SPEC`]; the firmware builds its learner from
//! the same. The table is the host's learner profile
//! ([`Board::Host`]: hashed, 2^24 weights, 64 MiB of Q16.16 per agent), or
//! a board's with `pada run --board`.
//!
//! Gearbox torques for the fatigue counter, per physical gearbox (both hips,
//! both knees, [`pada_core::robot::leo::GEARBOXES`]): the simulation's mean
//! gear torque over the step (the physical MTBF), and the stall torque of
//! the commanded voltage (the paper's, [`pada_core::robot::leo::commanded_gear_torque`]).

use super::task::{commanded_gear_torque, Observation, GEARBOXES, OBS_DIM};
use super::{LeoConfig, LeoEnv, Terminal};
use crate::task::{Plant, Step, Task, TaskSpec};
use pada_core::action_space::{Output, MAX_ACTION_DIMS};
use pada_core::agent::SarsaParams;
use pada_core::profile::{Board, LearnerProfile};
use rand_core::RngCore;

/// Gearboxes counted: both hips, both knees.
const GEARBOX_COUNT: usize = GEARBOXES.len();
const _: () = assert!(GEARBOX_COUNT <= MAX_ACTION_DIMS);

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
        Self::with_profile(Board::Host.profile(&pada_core::robot::leo::SPEC).expect("the host holds a claim table"), params)
    }

    /// The task with a board's learner `profile` (LEO's) and these learning
    /// parameters.
    pub fn with_profile(profile: LearnerProfile, params: SarsaParams) -> Self {
        let mut spec = TaskSpec::of_robot(
            profile,
            "LEO walking (Section VIII; rapier3d model of docs/reference/grl.md §1-3, 30 Hz, 3 joints x 7 voltages)",
            "per gearbox (hips, knees): mtbf_s from the commanded voltage's RX-28 stall torque (0.167 N m/V, the paper's linear law); physical_mtbf_s from the rapier3d model's mean gear torque over the control step",
        );
        spec.params = params;
        spec.default_seconds = 14_666.0;
        spec.default_trials = 2;
        // The runner ends episodes after the definition's 750 steps, so
        // the environment has no timeout of its own.
        let config = LeoConfig {
            timeout: None,
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
    /// Per gearbox: the simulation's mean torque, and the commanded
    /// voltage's stall torque, over the last step.
    torques: [f32; GEARBOX_COUNT],
    commanded: [f32; GEARBOX_COUNT],
    walked: f32,
    footstep: bool,
}

impl LeoPlant {
    /// A plant with this configuration. Panics if the configuration is
    /// unusable (the default one is checked by the sanity tests).
    pub fn new(config: LeoConfig) -> Self {
        LeoPlant {
            env: LeoEnv::new(config).expect("the LEO configuration builds a stable model"),
            torques: [0.0; GEARBOX_COUNT],
            commanded: [0.0; GEARBOX_COUNT],
            walked: 0.0,
            footstep: false,
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
        self.torques = [0.0; GEARBOX_COUNT];
        self.commanded = [0.0; GEARBOX_COUNT];
        self.walked = 0.0;
        self.footstep = false;
        write_obs(&o, obs);
    }

    fn step(&mut self, command: &[f32], obs: &mut [f32]) -> Step {
        let r = self.env.step([command[0], command[1], command[2]]);
        for (g, j) in GEARBOXES.iter().enumerate() {
            self.torques[g] = r.info.joint_torques[*j as usize];
            self.commanded[g] = commanded_gear_torque(r.info.voltages[*j as usize]);
        }
        self.walked = r.info.walked_distance;
        self.footstep = r.info.footstep;
        write_obs(&r.obs, obs);
        Step {
            reward: r.reward,
            terminal: r.terminal == Terminal::Fall,
        }
    }

    fn gearbox_torques(&self, _command: &[f32]) -> Output {
        let mut t = [0.0; MAX_ACTION_DIMS];
        t[..GEARBOX_COUNT].copy_from_slice(&self.torques);
        t
    }

    fn commanded_torques(&self, _command: &[f32]) -> Output {
        let mut t = [0.0; MAX_ACTION_DIMS];
        t[..GEARBOX_COUNT].copy_from_slice(&self.commanded);
        t
    }

    fn walked_distance_m(&self) -> Option<f64> {
        Some(self.walked as f64)
    }

    fn footstep(&self) -> bool {
        self.footstep
    }
}
