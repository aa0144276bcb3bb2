//! LEO: the Delft biped in rapier3d, its RX-28 servos and the
//! walking task of Section VIII of the paper, behind one small interface:
//!
//! ```text
//! LeoEnv::new(config) -> Result<LeoEnv, LeoError>
//! env.reset(&mut rng) -> Observation            // 10-D, mirrored (§3.4)
//! env.step([U_hip,st, U_hip,sw, U_knee,sw]) -> StepResult
//! ```
//!
//! All facts come from `docs/reference/grl.md` (sections cited in
//! [`constants`]): [`model`] builds the rapier world (§1) with the servo
//! model of [`pada_core::rx28`] (§2); the walking task's rules (§3) are the
//! robot's one definition, [`pada_core::robot::leo`] (here as [`task`]). The step size and solver settings, and the measurements
//! behind them, are in `README.md` next to this file.
//!
//! A simulation that blows up (NaN, a body far away, an absurd joint rate)
//! ends the episode as a fall, is counted ([`LeoEnv::blow_ups`]) and never
//! panics; non-finite action voltages are read as 0 V and flagged.

pub mod compare;
pub mod constants;
pub mod model;
pub mod passive;
pub mod rl;
pub mod stiction;
/// The walking task's rules (§3): the robot's one definition in pada-core,
/// shared with the firmware.
pub use pada_core::robot::leo as task;

use rand_core::RngCore;

use constants::*;
use model::{BlowUp, InitialPose, LeoModel, ModelError, ModelOptions, Snapshot, NUM_JOINTS};
use pada_core::robot::filter::RateFilter;
use task::{joint_rate_filter, torso_rate_filter, Leg, Observation, StanceTracker, ACTION_DIM};

/// Configuration of the LEO walking environment.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LeoConfig {
    /// Physics settings (step, solver, switches for the sanity checks).
    pub model: ModelOptions,
    /// Randomise the starting pose as GRL can (§1.8; off in every LEO
    /// configuration of the reference).
    pub randomize_start: bool,
    /// Episode timeout in simulated seconds after the first observation
    /// (§3.8: 25 s); `None` when whoever drives the environment ends the
    /// episodes (the learning runner ends them after the robot
    /// definition's 750 steps).
    pub timeout: Option<f32>,
}

impl Default for LeoConfig {
    fn default() -> Self {
        Self {
            model: ModelOptions::default(),
            randomize_start: false,
            timeout: Some(EPISODE_TIMEOUT),
        }
    }
}

/// Why an environment could not be made.
#[derive(Debug, Clone, PartialEq)]
pub enum LeoError {
    /// The physics model refused its options.
    Model(ModelError),
    /// The timeout is not finite and positive.
    InvalidTimeout(f32),
    /// The simulation blew up in the first control period of the
    /// reference start: the physics settings are unusable.
    UnstableStart(BlowUp),
}

impl core::fmt::Display for LeoError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            LeoError::Model(e) => e.fmt(f),
            LeoError::InvalidTimeout(t) => write!(
                f,
                "invalid LEO episode timeout {t} s: must be finite and > 0"
            ),
            LeoError::UnstableStart(b) => write!(
                f,
                "the LEO simulation blew up ({b:?}) while settling into the starting pose"
            ),
        }
    }
}

impl std::error::Error for LeoError {}

impl From<ModelError> for LeoError {
    fn from(e: ModelError) -> Self {
        LeoError::Model(e)
    }
}

/// How an episode ended (§3.8).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Terminal {
    /// Not ended.
    None,
    /// Doomed to fall (absorbing, no bootstrap), including blow-ups.
    Fall,
    /// 25 s passed (bootstrapped).
    Timeout,
}

/// What a step reports besides observation and reward.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StepInfo {
    /// Walked distance in this episode: the sum of footstep lengths (m, §3.3).
    pub walked_distance: f32,
    /// Footsteps in this episode (+1 forward, −1 backward, §3.3).
    pub footsteps: i32,
    /// Motor work of this step, E of §3.7 (J).
    pub energy: f32,
    /// Mean gear torque of the three learned joints over the step (N m),
    /// in action order (stance hip, swing hip, swing knee with the stance
    /// leg the action was applied with) — for the fatigue counter.
    pub learned_torques: [f32; ACTION_DIM],
    /// Mean gear torque of every joint (N m, [`model::Joint`] order).
    pub joint_torques: [f32; NUM_JOINTS],
    /// The voltage each servo was commanded over the step (V,
    /// [`model::Joint`] order): learned or held.
    pub voltages: [f32; NUM_JOINTS],
    /// The stance leg after the step.
    pub stance: Leg,
    /// Whether the stance leg changed in this step.
    pub footstep: bool,
    /// Simulated time since the first observation (s).
    pub time: f32,
    /// `Some` if the simulation blew up in this step (then the episode
    /// ended as a fall).
    pub blow_up: Option<BlowUp>,
    /// Whether an action voltage was not finite (it was read as 0 V).
    pub invalid_action: bool,
}

/// The result of one control step.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StepResult {
    /// Observation after the step (the last valid one after a blow-up).
    pub obs: Observation,
    /// Reward r = −1 − 3E + 300ΔL − 125·\[fall\] (§3.7).
    pub reward: f32,
    /// Whether and how the episode ended.
    pub terminal: Terminal,
    /// Diagnostics.
    pub info: StepInfo,
}

/// The LEO walking environment (§3).
pub struct LeoEnv {
    config: LeoConfig,
    model: LeoModel,
    /// The state after the first control period of the reference start.
    settled: Snapshot,
    joint_filters: [RateFilter; NUM_JOINTS],
    torso_filter: RateFilter,
    filtered: [f32; NUM_JOINTS],
    stance: StanceTracker,
    obs: Observation,
    time: f32,
    terminal: Terminal,
    last_info: StepInfo,
    blow_ups: u64,
    falls: u64,
    episodes: u64,
}

impl LeoEnv {
    /// A new environment; call [`LeoEnv::reset`] before stepping (a step
    /// before the first reset acts on the reference pose as if reset).
    pub fn new(config: LeoConfig) -> Result<Self, LeoError> {
        if let Some(t) = config.timeout.filter(|t| !(t.is_finite() && *t > 0.0)) {
            return Err(LeoError::InvalidTimeout(t));
        }
        let mut model = LeoModel::new(config.model, &InitialPose::REFERENCE)?;
        // The first control period of every reference episode (§1.8).
        model.set_voltages([0.0; NUM_JOINTS]);
        model.control_step().map_err(LeoError::UnstableStart)?;
        let settled = model.snapshot();
        let mut env = Self {
            config,
            model,
            settled,
            joint_filters: [joint_rate_filter(); NUM_JOINTS],
            torso_filter: torso_rate_filter(),
            filtered: [0.0; NUM_JOINTS],
            stance: StanceTracker::new(),
            obs: Observation([0.0; task::OBS_DIM]),
            time: 0.0,
            terminal: Terminal::None,
            last_info: empty_info(),
            blow_ups: 0,
            falls: 0,
            episodes: 0,
        };
        env.model.restore(&env.settled);
        env.begin_episode();
        env.sense();
        env.episodes = 0;
        Ok(env)
    }

    /// The configuration.
    pub fn config(&self) -> &LeoConfig {
        &self.config
    }

    /// The physics model (for inspection, drawing and tests).
    pub fn model(&self) -> &LeoModel {
        &self.model
    }

    /// The physics model, mutable: for tools and tests that inject states
    /// (changing it mid-episode bypasses the task's bookkeeping).
    pub fn model_mut(&mut self) -> &mut LeoModel {
        &mut self.model
    }

    /// Blow-ups since the environment was made (each also counted as a fall).
    pub fn blow_ups(&self) -> u64 {
        self.blow_ups
    }

    /// Falls since the environment was made (blow-ups included).
    pub fn falls(&self) -> u64 {
        self.falls
    }

    /// Episodes started by [`LeoEnv::reset`].
    pub fn episodes(&self) -> u64 {
        self.episodes
    }

    /// The current observation.
    pub fn observation(&self) -> Observation {
        self.obs
    }

    /// Every joint's rate through the task's filter after the last step
    /// (rad/s, [`model::Joint`] order; §3.2).
    pub fn filtered_rates(&self) -> [f32; NUM_JOINTS] {
        self.filtered
    }

    /// The stance leg the next step acts with (§3.3).
    pub fn stance(&self) -> Leg {
        self.current_stance()
    }

    /// How the current episode stands.
    pub fn terminal(&self) -> Terminal {
        self.terminal
    }

    /// Starts an episode (§1.8): the starting pose (randomised if
    /// configured), voltages 0, one control period simulated, then the first
    /// observation.
    pub fn reset<R: RngCore + ?Sized>(&mut self, rng: &mut R) -> Observation {
        if !self.config.randomize_start {
            // The reference start is deterministic: restore the state after
            // its first control period instead of simulating it again.
            self.model.restore(&self.settled);
            self.begin_episode();
            self.sense();
            return self.obs;
        }
        let pose = randomized_pose(rng);
        match self.model.reset(&pose) {
            Ok(()) => self.start_episode(),
            Err(_) => {
                // Cannot happen (the options were validated and the pose is
                // finite); if it did, the episode ends at once as a fall.
                self.episodes += 1;
                self.terminal = Terminal::Fall;
                self.falls += 1;
            }
        }
        self.obs
    }

    /// Clears the task's state for a new episode.
    fn begin_episode(&mut self) {
        self.episodes += 1;
        self.joint_filters = [joint_rate_filter(); NUM_JOINTS];
        self.torso_filter = torso_rate_filter();
        self.filtered = [0.0; NUM_JOINTS];
        self.stance = StanceTracker::new();
        self.time = 0.0;
        self.terminal = Terminal::None;
        self.last_info = empty_info();
    }

    /// Starts an episode from a model in its starting pose: voltages 0,
    /// one control period, the first observation (§1.8).
    fn start_episode(&mut self) {
        self.begin_episode();
        self.model.set_voltages([0.0; NUM_JOINTS]);
        match self.model.control_step() {
            Ok(_) => {
                self.sense();
            }
            Err(b) => {
                self.blow_ups += 1;
                self.falls += 1;
                self.terminal = Terminal::Fall;
                self.last_info.blow_up = Some(b);
            }
        }
    }

    /// Reads the state after a control step: filters the rates, updates
    /// the stance logic and the observation. Returns the filtered rates
    /// before this update, the stance update and φ.
    fn sense(&mut self) -> ([f32; NUM_JOINTS], task::StanceUpdate, f32) {
        let s = self.model.state();
        let before = self.filtered;
        for k in 0..NUM_JOINTS {
            self.filtered[k] = self.joint_filters[k].update(s.rates[k]);
        }
        let phi = -s.torso_pitch;
        let phi_rate = -self.torso_filter.update(s.torso_rate);
        let q = &s.angles;
        let ankle = |leg: Leg| task::ankle_x(phi, q[leg.hip() as usize], q[leg.knee() as usize]);
        let update = self.stance.update(
            s.contacts[0] || s.contacts[1],
            s.contacts[2] || s.contacts[3],
            ankle(Leg::Left),
            ankle(Leg::Right),
        );
        let stance = self.current_stance();
        self.obs = task::observe(phi, phi_rate, q, &self.filtered, stance);
        (before, update, phi)
    }

    /// The stance leg; the starting pose stands on the left leg (§1.8), so
    /// that is the answer before any foot ever touched.
    fn current_stance(&self) -> Leg {
        self.stance.stance().unwrap_or(Leg::Left)
    }

    /// One control step (§3.6) with the three learned voltages (stance hip,
    /// swing hip, swing knee; clipped to ±10.7 V, non-finite → 0 V).
    ///
    /// After the episode ended, returns the final observation again with
    /// reward 0 and the same terminal, without simulating.
    pub fn step(&mut self, action_voltages: [f32; ACTION_DIM]) -> StepResult {
        if let Some(ended) = self.ended() {
            return ended;
        }
        let stance = self.current_stance();
        let (angles, _) = self.model.joint_state();
        let voltages = task::joint_voltages(action_voltages, &angles, stance);
        let invalid_action = action_voltages.iter().any(|v| !v.is_finite());
        self.step_voltages(voltages, invalid_action)
    }

    /// One control step (§3.6) with every servo's voltage given (V,
    /// [`model::Joint`] order) instead of the three learned ones and the
    /// held joints' P laws: for driving the model open loop with another
    /// simulator's applied voltages (`pada leo compare`). The task's
    /// bookkeeping (filters, stance, reward, falls) is the same as
    /// [`LeoEnv::step`]'s; non-finite voltages are read as 0 V and flagged.
    pub fn step_joint_voltages(&mut self, voltages: [f32; NUM_JOINTS]) -> StepResult {
        if let Some(ended) = self.ended() {
            return ended;
        }
        let invalid_action = voltages.iter().any(|v| !v.is_finite());
        let voltages = voltages.map(|u| if u.is_finite() { u } else { 0.0 });
        self.step_voltages(voltages, invalid_action)
    }

    /// After the episode ended: the final observation again with reward 0
    /// and the same terminal, without simulating.
    fn ended(&self) -> Option<StepResult> {
        (self.terminal != Terminal::None).then_some(StepResult {
            obs: self.obs,
            reward: 0.0,
            terminal: self.terminal,
            info: self.last_info,
        })
    }

    /// The body of a control step once the servos' voltages are known.
    fn step_voltages(&mut self, voltages: [f32; NUM_JOINTS], invalid_action: bool) -> StepResult {
        let stance = self.current_stance();
        self.model.set_voltages(voltages);
        let learned = task::learned_joints(stance);
        let torques = match self.model.control_step() {
            Ok(t) => t,
            Err(b) => {
                self.blow_ups += 1;
                self.falls += 1;
                self.terminal = Terminal::Fall;
                self.time += CONTROL_PERIOD;
                let info = StepInfo {
                    blow_up: Some(b),
                    invalid_action,
                    time: self.time,
                    stance,
                    walked_distance: self.stance.walked(),
                    footsteps: self.stance.footsteps(),
                    ..empty_info()
                };
                self.last_info = info;
                return StepResult {
                    obs: self.obs,
                    reward: REWARD_TIME + REWARD_FALL,
                    terminal: Terminal::Fall,
                    info,
                };
            }
        };
        self.time += CONTROL_PERIOD;
        let (filtered_before, update, phi) = self.sense();
        let energy = task::step_energy(&voltages, &filtered_before, &self.filtered);
        let stance_after = self.current_stance();
        let (q, _) = self.model.joint_state();
        let fall = task::is_fall(phi, q[stance_after.hip() as usize]);
        let reward = task::reward(energy, &update, fall);
        self.terminal = if fall {
            self.falls += 1;
            Terminal::Fall
        } else if self.config.timeout.is_some_and(|t| self.time > t) {
            Terminal::Timeout
        } else {
            Terminal::None
        };
        let info = StepInfo {
            walked_distance: self.stance.walked(),
            footsteps: self.stance.footsteps(),
            energy,
            learned_torques: learned.map(|j| torques[j as usize]),
            joint_torques: torques,
            voltages,
            stance: stance_after,
            footstep: update.footstep,
            time: self.time,
            blow_up: None,
            invalid_action,
        };
        self.last_info = info;
        StepResult {
            obs: self.obs,
            reward,
            terminal: self.terminal,
            info,
        }
    }
}

fn empty_info() -> StepInfo {
    StepInfo {
        walked_distance: 0.0,
        footsteps: 0,
        energy: 0.0,
        learned_torques: [0.0; ACTION_DIM],
        joint_torques: [0.0; NUM_JOINTS],
        voltages: [0.0; NUM_JOINTS],
        stance: Leg::Left,
        footstep: false,
        time: 0.0,
        blow_up: None,
        invalid_action: false,
    }
}

/// Uniform in [lo, hi) from 24 random bits.
fn uniform<R: RngCore + ?Sized>(rng: &mut R, lo: f32, hi: f32) -> f32 {
    lo + (hi - lo) * ((rng.next_u32() >> 8) as f32 / (1u32 << 24) as f32)
}

/// GRL's optional start randomisation (§1.8), as offsets on the reference
/// pose: torso d_t ~ U(−C, C); thighs d_t + U(−C, C); shanks their thigh's
/// offset + U(0, 2C); right foot the right shank's offset + U(−C, C); left
/// foot 0; arm U(−C, C). The left foot is placed on the floor as usual.
pub fn randomized_pose<R: RngCore + ?Sized>(rng: &mut R) -> InitialPose {
    let c = INIT_RANDOMIZATION;
    let mut p = InitialPose::REFERENCE;
    let dt = uniform(rng, -c, c);
    p.torso += dt;
    let thigh_l = dt + uniform(rng, -c, c);
    let thigh_r = dt + uniform(rng, -c, c);
    let shank_l = thigh_l + uniform(rng, 0.0, 2.0 * c);
    let shank_r = thigh_r + uniform(rng, 0.0, 2.0 * c);
    p.left[0] += thigh_l;
    p.left[1] += shank_l;
    p.right[0] += thigh_r;
    p.right[1] += shank_r;
    p.right[2] += shank_r + uniform(rng, -c, c);
    p.arm += uniform(rng, -c, c);
    p
}
