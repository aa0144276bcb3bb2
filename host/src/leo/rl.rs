//! LEO as a task of the experiment runner ([`crate::experiment::task::Task`]): the
//! walking task of Section VIII learned with SARSA(λ), PADA or the low-pass
//! filter through the same code as the pendulums.
//!
//! - Motor: 3 learned joints (stance hip, swing hip, swing knee) × 7
//!   voltage levels in [−10.7, 10.7] V (grl-facts §3.4, §3.9).
//! - State: the 10-D mirrored observation of §3.4 with GRL's tile widths
//!   (`cfg/leosim/sarsa.yaml`, §3.9): angles 0.28 rad (torso 0.14 rad),
//!   rates 10 rad/s (torso 5 rad/s); 16 tilings.
//! - Actions tile-coded too (6.67 V tiles, [`LEO_ACTION_TILE_WIDTH`]), as
//!   GRL's LEO learner generalises over actions.
//! - Weight table: hashed, 2^22 weights (16 MiB of Q16.16 per agent); see
//!   [`LEO_TABLE_LOG2`].
//! - Learning parameters: GRL's LEO values per 30 Hz step, γ 0.9962
//!   (≈ 4 s horizon), λ 0.8582 (≈ 0.1 s), α 0.2, ε 0.05, weights U[0, 0.01]
//!   (§3.9); see [`leo_params`].
//! - Gearbox torques for the fatigue counter: the mean gear torque of the
//!   three learned joints over the step just taken (`learned_torques`).

use super::task::{Observation, ACTION_DIM, OBS_DIM};
use super::{LeoConfig, LeoEnv, Terminal};
use crate::experiment::task::{Plant, Step, Task, TaskSpec, WeightTable};
use pada_core::action_space::{ActionDim, ActionSpace, Output, MAX_ACTION_DIMS};
use pada_core::agent::{SarsaParams, WeightInit};
use pada_core::tile_coding::StateDim;
use rand_core::RngCore;

/// Base-2 logarithm of the hashed weight table (2^22 = 4 194 304 weights,
/// 16 MiB). GRL used 2^24 (`cfg/leosim/sarsa.yaml`); 2^22 keeps two trials
/// in parallel within a few tens of MiB and the random reads of the 343
/// actions × 16 tilings per greedy choice closer to the caches, while a
/// 3600 s run (108 000 steps × 16 tilings) touches far fewer distinct tiles
/// than the table has slots per action.
pub const LEO_TABLE_LOG2: u32 = 22;
/// Tile width of each learned voltage \[V\]: GRL generalises over actions
/// (`generalizeActions` true, voltage scale 0.15 ↔ tile width 6.67 V,
/// grl-facts §3.9), so neighbouring voltage levels (3.57 V apart) share
/// about half their tiles and 343 joint actions learn like far fewer.
pub const LEO_ACTION_TILE_WIDTH: f32 = 6.67;
/// Voltage limit of the learned actions \[V\] (grl-facts §2.2: 10.69 V).
pub const LEO_VOLTAGE: f32 = 10.7;
/// Voltage levels per learned joint (§3.9).
pub const LEO_LEVELS: usize = 7;
/// Control steps of an episode: 25 s at 30 Hz (§3.8).
pub const LEO_EPISODE_STEPS: u32 = 750;

/// GRL's LEO learning parameters (§3.9, the per-step values of
/// `leo_sim_sarsa_walk.yaml` and the Schuitema constants): α 0.2,
/// γ 0.9962, λ 0.8582, ε 0.05, replacing traces, weights U[0, 0.01].
pub fn leo_params() -> SarsaParams {
    SarsaParams {
        alpha: 0.2,
        gamma: 0.9962,
        lambda: 0.8582,
        epsilon: 0.05,
        init: WeightInit::Uniform {
            min: 0.0,
            max: 0.01,
        },
        ..SarsaParams::default()
    }
}

/// The 10 observation dimensions (§3.4 order) with GRL's tile widths.
/// Ranges only clamp: angles ±π (the joints' stops are inside), torso ±π/2
/// (a fall ends the episode before), rates ±40 rad/s (torso ±20).
pub fn leo_state_dims() -> Vec<StateDim> {
    use std::f32::consts::{FRAC_PI_2, PI};
    let d = |lo: f32, hi: f32, w: f32| StateDim::new(lo, hi, w).expect("valid LEO dimension");
    let mut v = vec![d(-FRAC_PI_2, FRAC_PI_2, 0.14), d(-20.0, 20.0, 5.0)];
    for _ in 0..4 {
        v.push(d(-PI, PI, 0.28));
        v.push(d(-40.0, 40.0, 10.0));
    }
    debug_assert_eq!(v.len(), OBS_DIM);
    v
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
    /// The task with these learning parameters.
    pub fn new(params: SarsaParams) -> Self {
        let level =
            ActionDim::uniform(-LEO_VOLTAGE, LEO_VOLTAGE, LEO_LEVELS).expect("valid levels");
        let spec = TaskSpec {
            name: "leo",
            title: "LEO walking (Section VIII; rapier3d model of grl-facts §1-3, 30 Hz, 3 joints x 7 voltages)",
            control_period_s: super::constants::CONTROL_PERIOD as f64,
            episode_steps: LEO_EPISODE_STEPS,
            state: leo_state_dims(),
            motor: ActionSpace::new(&[level.clone(), level.clone(), level]).expect("valid action space"),
            table: WeightTable::Hashed { log2_size: LEO_TABLE_LOG2 },
            action_tiles: Some(vec![LEO_ACTION_TILE_WIDTH; ACTION_DIM]),
            params,
            test_interval: 10,
            default_seconds: 14_666.0,
            default_trials: 2,
            torque_note: "mean gear torque of the three learned joints (stance hip, swing hip, swing knee) over the control step, from the rapier3d model",
        };
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
