//! One control period, from readings to servo commands and telemetry.
//!
//! [`Controller::period`] is everything the control-loop task does between
//! reading the sensors and writing the servos:
//!
//! 1. the safety machine sees every servo answer, timeout, checksum error,
//!    error bit, joint position and the last period's overrun — a fault
//!    found here switches torque off in **this** period's output;
//! 2. the robot's adapter ([`RobotAdapter`]: [`crate::pendulum`],
//!    [`crate::leo`]) turns the readings into the observation and reward of
//!    the robot's one definition in `pada_core::robot`;
//! 3. while torque is on: between episodes the robot is brought back to
//!    its start (pendulum hanging still, LEO set upright); in an episode the
//!    agent takes one step (`start_episode`, `step` or `end_episode` at an
//!    absorbing state or the time limit); every `test_interval` learning
//!    episodes one greedy test episode is run (Section VI);
//! 4. the learner's output and the held joints become voltages, the
//!    voltages become Moving Speeds of each servo's measured supply;
//! 5. the fatigue counter sees each servo's gearbox torque as the robot's
//!    definition estimates it from the applied voltage (and, for LEO, the
//!    joint's rate through the RX-28 model);
//! 6. telemetry records: the step (everything a host replay needs: kind,
//!    observation, reward, action, TD error), the finished episode, state
//!    changes and faults.
//!
//! Randomness: the agent's generator ([`pada_core::rng::Pcg32`] from a
//! seed, output-identical to the host's `rand_pcg::Pcg32`) is used by the
//! agent only — weight initialisation and action choice — so a host build of
//! the same agent, fed the reported observations and rewards, draws the same
//! numbers and takes the same actions.
//!
//! Learning on a wear budget: after `SetMtbfBudget` a wear governor
//! ([`pada_core::governor`], [`crate::wear_budget`]) moves PADA's Δ or the
//! low-pass filter's α after every learning period from the fatigue
//! counter's damage of the learned joints, and the period's output carries
//! a `Policy` report at every move and after every episode.
//!
//! Saved learning: [`Controller::save_checkpoint`] writes the weights and
//! the learner's state — the agent's counters, ε, mode and policy, the
//! fatigue counter of every servo, the generator, the episode counters, the
//! wear governor — and
//! [`Controller::load_checkpoint`] (at boot and on the host's command)
//! restores them when the configuration matches and every field is in range
//! for the running learner, so that a board that resets continues where it
//! was. Anything else is refused and counted
//! ([`Controller::checkpoints_refused`]), and the learner stays as it was.

use crate::bus::BusConfig;
use crate::config::{hardware, FirmwareAgent, LearnerProfile, RobotConfig, MAX_OBS, MAX_SERVOS, TILINGS};
use crate::encoder::Unwrapper;
use crate::io::CycleCounter;
use crate::robot::{RobotAdapter, Sensed};
use crate::wear_budget;
use heapless::Vec;
use pada_core::agent::{Decision, EpisodeEnd, Mode};
use pada_core::checkpoint::{self, CheckpointStore, FlashWear, LearnerState, LoadOutcome, SaveError, Saved, WearBudget};
use pada_core::dynamixel::{table::PresentState, ErrorFlags};
use pada_core::error::ConfigError;
use pada_core::fatigue::{FatigueCounter, FatigueError, GearboxParams, PAPER_WINDOW_STEPS};
use pada_core::governor::Governor;
use pada_core::policy::PolicyKind;
use pada_core::profile::config_hash;
use pada_core::rng::Pcg32;
use pada_core::robot::RobotSpec;
use pada_core::weights::WeightStore;
use pada_core::safety::{Command, Event, RunMode, Safety, SafetyConfig, State, Transition};
use pada_core::wire::{self, NackReason, StepKind};
use rand_core::SeedableRng;

/// One servo's part of a period's readings.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct ServoRead {
    /// Present Position … Temperature, if the servo answered.
    pub state: Option<PresentState>,
    /// Error bits of its answer.
    pub error: ErrorFlags,
    /// Attempts that got no answer.
    pub timeouts: u8,
    /// Answers with a bad checksum.
    pub checksum_errors: u8,
}

/// Everything the control loop read in one period.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Readings {
    /// Per servo, in the robot's joint order.
    pub servos: [ServoRead; MAX_SERVOS],
    /// The encoder's counter, if it could be read.
    pub encoder: Option<u16>,
    /// Foot switches ([`crate::leo::contact`]).
    pub contacts: u8,
    /// Time since boot \[ms\].
    pub time_ms: u32,
    /// Whether the previous period's work overran its period.
    pub last_period_overran: bool,
}

/// What the control loop applies and reports after one period.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct PeriodOutput {
    /// Torque Enable for every servo.
    pub torque: bool,
    /// Moving Speed per servo (ID, value); all zero while torque is off.
    pub speeds: Vec<(u8, u16), MAX_SERVOS>,
    /// The agent's step, if one was taken (`loop_us` is the caller's to
    /// fill in).
    pub step: Option<wire::Step>,
    /// The episode that ended.
    pub episode: Option<wire::Episode>,
    /// Safety state changes of this period, in order.
    pub transitions: Vec<Transition, 8>,
    /// Cycles of the agent call, if there was one.
    pub agent_cycles: Option<u32>,
    /// The gearbox torque of each servo the fatigue counter saw this
    /// period \[N·m\] (the robot's estimate; 0 with torque off).
    pub torques: [f32; MAX_SERVOS],
    /// A `Policy` report to send: the wear governor moved Δ or α this
    /// period, or an episode ended while it runs.
    pub policy: Option<wire::PolicyReport>,
}

/// A host command's result, for the `Ack`/`Nack`.
pub type CommandResult = Result<(), NackReason>;

/// Where the episode cycle is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Phase {
    /// Torque off.
    Stopped,
    /// Bringing the robot back to its start.
    Resetting,
    /// In an episode of `steps` transitions so far.
    Running {
        /// Transitions (rewards) so far.
        steps: u32,
    },
}

/// The fault thresholds: a request that fails every attempt of its period
/// is a fault in that period, so torque goes off within one control period
/// of a servo falling silent or its answers arriving damaged:
/// [`BusConfig::attempts`] timeouts in a row (the retry budget is one less)
/// or as many checksum errors within a second. The cause tells which
/// (servo-timeout or checksum-errors); a damaged answer counts as both, and
/// checksum errors are seen first.
pub fn safety_config(soft_limits: Vec<pada_core::safety::SoftLimit, { pada_core::safety::MAX_SOFT_LIMITS }>) -> SafetyConfig {
    let attempts = BusConfig::default().attempts.max(1);
    SafetyConfig {
        soft_limits,
        servo_retry_budget: attempts - 1,
        checksum_threshold: attempts,
        checksum_window_ms: 1000,
        ..SafetyConfig::default()
    }
}

/// A fatigue error as a configuration error (same name and range).
fn fatigue_error(e: FatigueError) -> ConfigError {
    match e {
        FatigueError::InvalidParameter { param, value, valid } => ConfigError::new(param, value as f32, valid),
        _ => ConfigError::new("fatigue", 0.0, "finite torques"),
    }
}

/// The control loop's state for robot `R` on weights `W`: agent, safety
/// machine, the robot's adapter, fatigue.
pub struct Controller<W, R> {
    profile: LearnerProfile,
    spec: &'static RobotSpec,
    config: RobotConfig,
    agent: Option<FirmwareAgent<W>>,
    policy: PolicyKind,
    config_hash: u32,
    seed: u64,
    rng: Pcg32,
    safety: Safety,
    fatigue: FatigueCounter<MAX_SERVOS>,
    robot: R,
    encoder: Unwrapper,
    phase: Phase,
    /// The safety state at the end of the last period.
    last_state: State,
    episode_mode: RunMode,
    /// Episodes started since boot (the index of the next one).
    episodes: u32,
    /// Learning episodes since the last test episode.
    since_test: u32,
    episode_return: f32,
    last_action: u32,
    last_output: [f32; pada_core::action_space::MAX_ACTION_DIMS],
    /// Voltage each servo applied during the last period.
    applied: [f32; MAX_SERVOS],
    /// Last supply each servo reported \[V\].
    supply: [Option<f32>; MAX_SERVOS],
    temps: [u8; MAX_SERVOS],
    steps: u32,
    /// Checkpoints found but not loaded since boot.
    checkpoints_refused: u32,
    /// Saves that failed since boot (torque on not counted).
    saves_failed: u32,
    /// Why the last learner state was refused.
    last_refusal: Option<ConfigError>,
    /// Control periods since boot (the operating time of this boot).
    periods: u64,
    /// The checkpoint sectors' erases as far as known (the store's newest
    /// record at load, then every save of this boot).
    flash_wear: FlashWear,
    /// Operating seconds before this boot, as the checkpoints carried it.
    operating_before_s: u64,
    /// Saves refused since boot to keep the flash within its budget.
    saves_refused: u32,
    /// The wear governor, after `SetMtbfBudget`.
    governor: Option<Governor>,
}

/// The record has room for every servo's fatigue counter.
const _: () = assert!(MAX_SERVOS <= checkpoint::MAX_JOINTS);

/// Why a checkpoint operation of the controller failed.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CheckpointError<E> {
    /// Torque is on: checkpoints are saved and loaded only with torque off
    /// (an erase stalls the CPU; a load replaces the learner).
    Busy,
    /// The save failed; the previous checkpoint is intact.
    Save(SaveError<E>),
    /// Reading the store failed.
    Store(E),
}

/// The user counters of the firmware's learner-state record.
mod user {
    /// Episodes started since the first boot (the next episode's index).
    pub const EPISODES: usize = 0;
    /// Learning episodes since the last test episode.
    pub const SINCE_TEST: usize = 1;
}

impl<W, R> Controller<W, R>
where
    W: WeightStore,
    R: RobotAdapter,
{
    /// A controller for `R` with the board's learner `profile` (whose robot
    /// must be `R`'s), learning with `policy` on `weights`, initialised from
    /// `seed` (also the generator of every action).
    pub fn new(profile: LearnerProfile, policy: PolicyKind, weights: W, seed: u64) -> Result<Self, ConfigError> {
        if profile.robot != R::ROBOT {
            return Err(ConfigError::new("profile.robot", profile.robot.code() as f32, "the controller's robot"));
        }
        if profile.weights().is_some_and(|n| n != weights.len()) {
            return Err(ConfigError::new("weights", weights.len() as f32, "the profile's table size"));
        }
        let config = hardware(R::ROBOT);
        let mut soft_limits = Vec::new();
        for limit in config.soft_limits.iter().map_while(|l| *l) {
            let _ = soft_limits.push(limit);
        }
        let safety = Safety::new(safety_config(soft_limits))?;
        let spec = R::spec();
        let fatigue = FatigueCounter::new(GearboxParams::TABLE_I, spec.period_s(), Some(PAPER_WINDOW_STEPS))
            .map_err(|_| ConfigError::new("fatigue", 0.0, "Table I parameters"))?;
        let mut controller = Controller {
            profile,
            spec,
            robot: R::new(&config),
            config,
            agent: None,
            policy,
            config_hash: 0,
            seed,
            rng: Pcg32::seed_from_u64(seed),
            safety,
            fatigue,
            encoder: Unwrapper::new(),
            phase: Phase::Stopped,
            last_state: State::Idle,
            episode_mode: RunMode::Learning,
            episodes: 0,
            since_test: 0,
            episode_return: 0.0,
            last_action: 0,
            last_output: [0.0; pada_core::action_space::MAX_ACTION_DIMS],
            applied: [0.0; MAX_SERVOS],
            supply: [None; MAX_SERVOS],
            temps: [0; MAX_SERVOS],
            steps: 0,
            checkpoints_refused: 0,
            saves_failed: 0,
            last_refusal: None,
            periods: 0,
            flash_wear: FlashWear::default(),
            operating_before_s: 0,
            saves_refused: 0,
            governor: None,
        };
        controller.build(policy, weights)?;
        Ok(controller)
    }

    /// A fresh agent with `policy` on `weights`: the generator is reseeded
    /// and the weights initialised, as a host build would do.
    fn build(&mut self, policy: PolicyKind, weights: W) -> Result<(), ConfigError> {
        let mut agent = self.spec.agent(policy, self.profile.layout, weights)?;
        let hash = config_hash(&self.profile, &agent);
        self.rng = Pcg32::seed_from_u64(self.seed);
        agent.reset_weights(&mut self.rng);
        self.agent = Some(agent);
        self.policy = policy;
        self.config_hash = hash;
        Ok(())
    }

    fn agent(&self) -> &FirmwareAgent<W> {
        // Always Some outside `set_policy`.
        self.agent.as_ref().unwrap_or_else(|| unreachable!())
    }

    fn agent_mut(&mut self) -> &mut FirmwareAgent<W> {
        self.agent.as_mut().unwrap_or_else(|| unreachable!())
    }

    /// The robot's hardware.
    pub fn config(&self) -> &RobotConfig {
        &self.config
    }

    /// The robot's learning task.
    pub fn spec(&self) -> &'static RobotSpec {
        self.spec
    }

    /// The board's learner profile.
    pub fn profile(&self) -> &LearnerProfile {
        &self.profile
    }

    /// The robot's adapter (for inspection).
    pub fn robot(&self) -> &R {
        &self.robot
    }

    /// The configuration hash of the running learner.
    pub fn config_hash(&self) -> u32 {
        self.config_hash
    }

    /// The policy.
    pub fn policy(&self) -> PolicyKind {
        self.policy
    }

    /// The safety state.
    pub fn state(&self) -> State {
        self.safety.state()
    }

    /// Whether torque may be on now.
    pub fn torque_enabled(&self) -> bool {
        self.safety.torque_enabled()
    }

    /// The weights.
    pub fn weights(&self) -> &W {
        self.agent().weights()
    }

    /// The weights, to load a checkpoint into (only while torque is off).
    pub fn weights_mut(&mut self) -> Option<&mut W> {
        if self.torque_enabled() {
            return None;
        }
        Some(self.agent_mut().weights_mut())
    }

    /// The learner's state besides its weights, as a checkpoint saves it:
    /// the agent's ([`pada_core::agent::AgentState`]), the generator, every
    /// servo's fatigue counter, and the episode counters (user counters 0:
    /// episodes started, 1: learning episodes since the last test).
    pub fn learner_state(&self) -> LearnerState {
        let mut user = [0u32; checkpoint::USER_COUNTERS];
        user[user::EPISODES] = self.episodes;
        user[user::SINCE_TEST] = self.since_test;
        LearnerState {
            agent: self.agent().state(),
            rng: self.rng.state(),
            // Fits: MAX_SERVOS <= MAX_JOINTS (checked at compile time).
            joints: Vec::from_slice(&self.fatigue.state()).unwrap_or_default(),
            user,
            wear: FlashWear { erases: self.flash_wear.erases, operating_s: self.operating_s() },
            governor: self.governor.as_ref().map(Governor::state),
        }
    }

    /// Seconds this board has operated: before this boot (as the
    /// checkpoints carried it) and the control periods since, each the
    /// robot's period in whole µs (no float on the way).
    pub fn operating_s(&self) -> u64 {
        let period_us = u64::from(self.spec.period_us);
        self.operating_before_s.saturating_add(self.periods.saturating_mul(period_us) / 1_000_000)
    }

    /// The checkpoint sectors' erase counts as far as known.
    pub fn flash_wear(&self) -> FlashWear {
        self.flash_wear
    }

    /// Saves refused since boot to keep the flash within its erase budget.
    pub fn saves_refused(&self) -> u32 {
        self.saves_refused
    }

    /// Takes in the wear the store's newest checkpoint recorded (whatever
    /// its configuration): erase counts and the operating time before this
    /// boot.
    fn note_stored_wear(&mut self, stored: FlashWear) {
        self.flash_wear = self.flash_wear.max(&stored);
        let since_boot = self.operating_s() - self.operating_before_s;
        self.operating_before_s = self.operating_before_s.max(stored.operating_s.saturating_sub(since_boot));
    }

    /// Checks that `state` can be restored into this controller; the error
    /// names the first field out of range and its valid range: the agent's
    /// ([`pada_core::agent::Agent::check_state`]), the fatigue counters (one
    /// per servo, [`FatigueCounter::check_state`]), the generator's
    /// increment, learning episodes since the last test within the robot's
    /// test interval, unused user counters 0, and the wear governor's
    /// state for the saved policy and budget
    /// ([`Governor::check_state`]).
    pub fn check_learner_state(&self, state: &LearnerState) -> Result<(), ConfigError> {
        self.agent().check_state(&state.agent)?;
        if let Some(g) = &state.governor {
            self.governor_for(&state.agent.policy.kind, g.budget_s())?.check_state(g)?;
        }
        self.fatigue.check_state(&state.joints).map_err(fatigue_error)?;
        state.rng.check()?;
        let since_test = state.user[user::SINCE_TEST];
        if since_test > self.spec.test_interval {
            return Err(ConfigError::new(
                "since_test",
                since_test as f32,
                "learning episodes since the last test <= the robot's test interval",
            ));
        }
        if let Some(i) = (user::SINCE_TEST + 1..checkpoint::USER_COUNTERS).find(|&i| state.user[i] != 0) {
            return Err(ConfigError::new("user", state.user[i] as f32, "0 (unused)").at(i));
        }
        Ok(())
    }

    /// Restores a state that passed [`check_learner_state`](Self::check_learner_state)
    /// (the caller's to call first: each part below checks itself again, but
    /// only the whole check makes the restore all or nothing). The agent's
    /// episode ends (traces are not saved); the next Start brings the robot
    /// to its start and begins a new one.
    fn restore_learner_state(&mut self, state: &LearnerState) -> Result<(), ConfigError> {
        let rng = Pcg32::from_state(state.rng)?;
        let governor = match &state.governor {
            Some(g) => {
                let mut governor = self.governor_for(&state.agent.policy.kind, g.budget_s())?;
                governor.restore(g)?;
                Some(governor)
            }
            None => None,
        };
        self.fatigue.restore(&state.joints).map_err(fatigue_error)?;
        let agent = self.agent_mut();
        agent.restore_state(&state.agent)?;
        // The governor's rung decides the parameter in force.
        if let Some(g) = &governor {
            agent.set_policy_parameter(g.parameter())?;
        }
        let policy = agent.policy().built_kind();
        let previous = agent.policy().learner_space().encode(&agent.policy().previous());
        self.policy = policy;
        self.rng = rng;
        self.episodes = state.user[user::EPISODES];
        self.since_test = state.user[user::SINCE_TEST];
        self.last_action = previous;
        self.last_output = [0.0; pada_core::action_space::MAX_ACTION_DIMS];
        self.episode_return = 0.0;
        self.governor = governor;
        // Torque is off (the callers check): no episode runs.
        self.phase = Phase::Stopped;
        Ok(())
    }

    /// A fresh governor for the built `policy` holding `budget_s`.
    fn governor_for(&self, policy: &PolicyKind, budget_s: f32) -> Result<Governor, ConfigError> {
        wear_budget::governor(self.spec, policy, budget_s, self.reported_joints())
    }

    /// Starts the wear governor with `budget_s` (the smallest predicted
    /// MTBF over the last 1200 learning actions it accepts \[s\]), at its
    /// floor, or stops it (`None`: Δ or α stays where it is). Only with
    /// torque off and for a `pada` or `lowpass` learner; an invalid budget
    /// (`0 < budget <= 1e10 s`) changes nothing.
    pub fn set_mtbf_budget(&mut self, budget_s: Option<f32>) -> CommandResult {
        if self.torque_enabled() {
            return Err(NackReason::Busy);
        }
        let Some(budget) = budget_s else {
            self.governor = None;
            return Ok(());
        };
        let policy = self.agent().policy().built_kind();
        let governor = self.governor_for(&policy, budget).map_err(|_| NackReason::InvalidParameter)?;
        self.agent_mut().set_policy_parameter(governor.parameter()).map_err(|_| NackReason::InvalidParameter)?;
        self.policy = self.agent().policy().built_kind();
        self.governor = Some(governor);
        Ok(())
    }

    /// The wear governor, if one runs.
    pub fn governor(&self) -> Option<&Governor> {
        self.governor.as_ref()
    }

    /// Saves the weights and the learner's state ([`learner_state`](Self::learner_state))
    /// into `store` (the slot not holding the newest checkpoint); only while
    /// torque is off, and only within the flash's erase budget
    /// ([`WearBudget::STM32F4`]: a refused save is
    /// `CheckpointError::Save(SaveError::Wear(..))`, counted in
    /// [`saves_refused`](Self::saves_refused), and erases nothing). A
    /// checkpoint larger than a slot
    /// ([`checkpoint_bytes`](Self::checkpoint_bytes) > `store.capacity()`:
    /// the F429's 8 MiB LEO table against a 128 KiB flash sector) is refused
    /// as `SaveError::TooLarge` before the store is touched; every other
    /// failed save counts in [`saves_failed`](Self::saves_failed).
    pub fn save_checkpoint<S: CheckpointStore>(&mut self, store: &mut S) -> Result<Saved, CheckpointError<S::Error>> {
        if self.torque_enabled() {
            return Err(CheckpointError::Busy);
        }
        let state = self.learner_state();
        let result = checkpoint::save_within(store, self.config_hash, &state, self.weights(), &WearBudget::STM32F4);
        match result {
            Ok(saved) => {
                let slot = saved.slot as usize & 1;
                self.flash_wear.erases[slot] = self.flash_wear.erases[slot].max(saved.erases);
            }
            Err(SaveError::Wear(_)) => self.saves_refused = self.saves_refused.saturating_add(1),
            Err(_) => self.saves_failed = self.saves_failed.saturating_add(1),
        }
        result.map_err(CheckpointError::Save)
    }

    /// Bytes a checkpoint of this learner takes in a slot: header, learner
    /// state and the whole table.
    pub fn checkpoint_bytes(&self) -> usize {
        checkpoint::slot_len(self.weights().len(), self.weights().format().bytes())
    }

    /// Saves that failed since boot (too large for a slot, the store
    /// failing, or a read-back that did not verify); a save refused because
    /// torque was on, or to spare the flash ([`saves_refused`](Self::saves_refused)),
    /// is not counted here.
    pub fn saves_failed(&self) -> u32 {
        self.saves_failed
    }

    /// Loads the newest checkpoint of `store` — weights and learner state —
    /// if it was saved with this configuration and its state passes
    /// [`check_learner_state`](Self::check_learner_state); only while torque
    /// is off. Otherwise nothing changes and the outcome says why
    /// ([`LoadOutcome::InvalidState`] for a refused state:
    /// [`last_refusal`](Self::last_refusal) names the field); every
    /// checkpoint found but not loaded counts in
    /// [`checkpoints_refused`](Self::checkpoints_refused).
    ///
    /// If the store fails while the weights are copied, the learner is
    /// rebuilt fresh from the seed (as after `SetPolicy`), never left half
    /// loaded.
    pub fn load_checkpoint<S: CheckpointStore>(&mut self, store: &S) -> Result<LoadOutcome, CheckpointError<S::Error>> {
        if self.torque_enabled() {
            return Err(CheckpointError::Busy);
        }
        self.last_refusal = None;
        let stored = checkpoint::stored_wear(store).map_err(CheckpointError::Store)?;
        self.note_stored_wear(stored);
        let weight_count = self.weights().len();
        let found = match checkpoint::find(store, self.config_hash, weight_count).map_err(CheckpointError::Store)? {
            Ok(found) => found,
            Err(outcome) => {
                if outcome != LoadOutcome::NoCheckpoint {
                    self.checkpoints_refused = self.checkpoints_refused.saturating_add(1);
                }
                return Ok(outcome);
            }
        };
        if let Err(e) = self.check_learner_state(&found.state) {
            self.checkpoints_refused = self.checkpoints_refused.saturating_add(1);
            self.last_refusal = Some(e);
            return Ok(LoadOutcome::InvalidState);
        }
        let read = checkpoint::read_weights(store, &found, self.agent_mut().weights_mut());
        self.agent_mut().rehash();
        let outcome = match read {
            Ok(outcome) => outcome,
            Err(e) => {
                self.rebuild();
                return Err(CheckpointError::Store(e));
            }
        };
        if let LoadOutcome::Loaded { .. } = outcome {
            // Checked above, so this restores.
            if let Err(e) = self.restore_learner_state(&found.state) {
                self.last_refusal = Some(e);
            }
        } else {
            self.checkpoints_refused = self.checkpoints_refused.saturating_add(1);
        }
        Ok(outcome)
    }

    /// A fresh learner with the running policy (generator reseeded, weights
    /// initialised).
    fn rebuild(&mut self) {
        if let Some(agent) = self.agent.take() {
            // The running policy built before, so it builds again.
            let _ = self.build(self.policy, agent.into_weights());
        }
    }

    /// Checkpoints found but not loaded since boot (another configuration
    /// or size, another format version, corrupt slots, or a learner state
    /// out of range); an empty store is not counted.
    pub fn checkpoints_refused(&self) -> u32 {
        self.checkpoints_refused
    }

    /// Why the last load's learner state was refused by
    /// [`check_learner_state`](Self::check_learner_state) (the field and its
    /// valid range); `None` when the last load refused nothing for that
    /// reason (an undecodable record is [`LoadOutcome::InvalidState`] with
    /// `None` here).
    pub fn last_refusal(&self) -> Option<ConfigError> {
        self.last_refusal
    }

    /// The agent's counters.
    pub fn agent_stats(&self) -> pada_core::agent::AgentStats {
        self.agent().stats()
    }

    /// The fatigue counter (every servo, joint order).
    pub fn fatigue(&self) -> &FatigueCounter<MAX_SERVOS> {
        &self.fatigue
    }

    /// Joints whose fatigue goes into each `Step`: the learned ones (the
    /// pendulum's motor; LEO's hips and knees, which take turns as stance
    /// and swing joints).
    pub fn reported_joints(&self) -> core::ops::Range<usize> {
        R::reported_joints()
    }

    /// Distance walked in the current (or last) episode \[m\], for a
    /// walking robot.
    pub fn walked_m(&self) -> Option<f32> {
        self.robot.walked_m()
    }

    /// The `Hello` of this configuration.
    pub fn hello(&self) -> wire::Hello {
        wire::Hello {
            protocol: wire::PROTOCOL_VERSION,
            config_hash: self.config_hash,
            weight_count: self.weights().len() as u32,
            period_us: self.spec.period_us,
            state_dims: self.spec.state.len() as u8,
            joints: self.reported_joints().len() as u8,
        }
    }

    /// The `Policy` report of the learner now: the built policy with its
    /// α/Δ and whether it switched back to SARSA(λ).
    pub fn policy_report(&self) -> wire::PolicyReport {
        let policy = self.agent().policy();
        wire::PolicyReport {
            step: self.agent_stats().steps as u32,
            built: policy.built_kind(),
            switched_to_sarsa: policy.switched(),
            governor: self.governor.as_ref().map(Governor::status),
        }
    }

    /// At boot, after a reset by the independent watchdog: a fault.
    pub fn watchdog_reset(&mut self) -> Transition {
        self.safety.on(Event::WatchdogReset)
    }

    /// Carries out a host command that the controller owns (start, stop,
    /// pause, clear fault, policy, ε, switch to SARSA); the others
    /// (checkpoints, weights, ping) are the caller's.
    pub fn command(&mut self, cmd: &wire::ToChip) -> (CommandResult, Option<Transition>) {
        let safety = |c| Some(Event::Command(c));
        let event = match *cmd {
            wire::ToChip::Start(mode) => safety(Command::Start(mode)),
            wire::ToChip::Stop => safety(Command::Stop),
            wire::ToChip::Pause => safety(Command::Pause),
            wire::ToChip::ClearFault => safety(Command::ClearFault),
            _ => None,
        };
        if let Some(event) = event {
            let t = self.safety.on(event);
            let result = match t.outcome {
                pada_core::safety::Outcome::Rejected(r) => Err(NackReason::State(r)),
                _ => Ok(()),
            };
            return (result, Some(t));
        }
        let result = match *cmd {
            wire::ToChip::SetPolicy(spec) => self.set_policy(spec),
            wire::ToChip::SetEpsilon(e) => self.agent_mut().set_epsilon(e).map_err(|_| NackReason::InvalidParameter),
            wire::ToChip::SwitchToSarsa => {
                self.agent_mut().switch_to_sarsa().map_err(|_| NackReason::InvalidParameter)
            }
            wire::ToChip::SetMtbfBudget(budget) => self.set_mtbf_budget(budget),
            _ => Err(NackReason::Unsupported),
        };
        (result, None)
    }

    /// A fresh learner with `policy` (generator reseeded, weights
    /// initialised, no wear governor: `SetMtbfBudget` starts one for the
    /// new learner); only while torque is off. An invalid parameter leaves
    /// the running learner as it was.
    pub fn set_policy(&mut self, policy: PolicyKind) -> CommandResult {
        if self.torque_enabled() {
            return Err(NackReason::Busy);
        }
        if self.spec.check::<TILINGS>(policy, self.profile.layout, self.weights().len()).is_err() {
            return Err(NackReason::InvalidParameter);
        }
        let Some(agent) = self.agent.take() else {
            return Err(NackReason::Busy);
        };
        let weights = agent.into_weights();
        self.governor = None;
        // Validated above, so this builds.
        self.build(policy, weights).map_err(|_| NackReason::InvalidParameter)
    }

    /// One control period (see the module documentation). `cycles` times
    /// the agent call.
    pub fn period(&mut self, readings: &Readings, cycles: &impl CycleCounter, out: &mut PeriodOutput) {
        out.step = None;
        out.episode = None;
        out.transitions.clear();
        out.speeds.clear();
        out.agent_cycles = None;
        out.torques = [0.0; MAX_SERVOS];
        out.policy = None;
        self.steps = self.steps.wrapping_add(1);
        self.periods = self.periods.saturating_add(1);
        let now = readings.time_ms;
        let joints = self.config.joints;
        let n = joints.len();

        // 1. Safety sees everything that was read.
        fn feed(safety: &mut Safety, out: &mut Vec<Transition, 8>, event: Event) {
            let t = safety.on(event);
            if t.changed() {
                let _ = out.push(t);
            }
        }
        let overrun = Event::LoopTiming { overrun: readings.last_period_overran };
        feed(&mut self.safety, &mut out.transitions, overrun);
        let mut angles = [None; MAX_SERVOS];
        for (i, (joint, read)) in joints.iter().zip(&readings.servos).enumerate() {
            for _ in 0..read.checksum_errors {
                feed(&mut self.safety, &mut out.transitions, Event::ChecksumError { at_ms: now });
            }
            for _ in 0..read.timeouts {
                feed(&mut self.safety, &mut out.transitions, Event::ServoTimeout { servo: joint.id });
            }
            if let Some(state) = read.state {
                let status = Event::ServoStatus { servo: joint.id, error: read.error, at_ms: now };
                feed(&mut self.safety, &mut out.transitions, status);
                self.supply[i] = Some(state.voltage_v());
                self.temps[i] = state.temperature;
                let angle = joint.angle(state.position);
                angles[i] = Some(angle);
                if self.config.soft_limits.get(i).is_some_and(|l| l.is_some()) {
                    let position = Event::JointPosition { joint: i as u8, position: angle };
                    feed(&mut self.safety, &mut out.transitions, position);
                }
            }
        }

        // 2. Where the episode cycle goes this period. The reset's end is
        // judged on the last period's observation, so that an episode's
        // first observation is taken after the observer was restarted.
        let torque = self.safety.torque_enabled();
        let state = self.safety.state();
        let mut starting = false;
        if !torque {
            self.phase = Phase::Stopped;
        } else {
            if state != self.last_state {
                // Just started, resumed or switched mode: the robot is
                // wherever it is; bring it to its start first.
                self.begin_reset();
            } else if self.phase == Phase::Resetting && self.robot.reset_done() {
                starting = true;
                self.robot.start_episode();
            }
        }
        self.last_state = state;

        // 3. Observe.
        let encoder_angle = readings.encoder.map(|c| self.config.encoder.angle(self.encoder.update(c)));
        self.robot.sense(&Sensed { angles, encoder_angle, contacts: readings.contacts, applied: self.applied });

        // 4. The agent's step, and the voltages.
        let mut volts = [0.0f32; MAX_SERVOS];
        if torque {
            let mode = state.run_mode().unwrap_or(RunMode::Learning);
            if starting {
                self.start_episode(mode, readings, cycles, out);
            } else if let Phase::Running { steps } = self.phase {
                self.continue_episode(steps + 1, readings, cycles, out);
            }
            match self.phase {
                Phase::Running { .. } => {
                    let dims = self.spec.motor_dims as usize;
                    self.robot.commands(&self.last_output[..dims], &mut volts)
                }
                _ => self.robot.reset_commands(&mut volts),
            }
        }

        // 5. Voltages → Moving Speeds of the measured supply.
        let nominal = self.config.supply_nominal_v;
        for (i, joint) in joints.iter().enumerate() {
            let v = if torque { volts[i] } else { 0.0 };
            let supply = self.supply[i].filter(|s| *s >= 5.0).unwrap_or(nominal);
            let speed = joint.moving_speed(v, self.supply[i], nominal);
            self.applied[i] = joint.voltage_of(speed, supply);
            let _ = out.speeds.push((joint.id, speed));
        }

        // 6. Fatigue from the estimated gearbox torque (servos past the
        // robot's count stay at 0); the governor sees a learning action's.
        if torque {
            let mut torques = [0.0f32; MAX_SERVOS];
            self.robot.gear_torques(&self.applied, &mut torques);
            torques[n..].fill(0.0);
            let before = wear_budget::damage_raws(&self.fatigue);
            let _ = self.fatigue.update(&torques);
            out.torques = torques;
            let learning_action = out.step.as_ref().is_some_and(|s| {
                s.mode == RunMode::Learning && matches!(s.kind, StepKind::Start | StepKind::Step)
            });
            if learning_action {
                self.govern(&before, out);
            }
        }
        if out.episode.is_some() && self.governor.is_some() {
            out.policy = Some(self.policy_report());
        }
        out.torque = torque;
    }

    /// Feeds the governor this period's damage of the learned joints; a
    /// move sets the policy's parameter for the next decision and is
    /// reported.
    fn govern(&mut self, before: &[u64; MAX_SERVOS], out: &mut PeriodOutput) {
        let increments = wear_budget::increments(before, &self.fatigue, self.reported_joints());
        let Some(moved) = self.governor.as_mut().and_then(|g| g.observe(&increments)) else { return };
        // The governor's ladder is the policy's own range, so this is
        // accepted; a refusal would leave the previous parameter in force.
        let _ = self.agent_mut().set_policy_parameter(moved);
        self.policy = self.agent().policy().built_kind();
        out.policy = Some(self.policy_report());
    }

    fn begin_reset(&mut self) {
        self.phase = Phase::Resetting;
        self.robot.begin_reset();
    }

    fn start_episode(&mut self, mode: RunMode, readings: &Readings, cycles: &impl CycleCounter, out: &mut PeriodOutput) {
        // Every `test_interval` learning episodes, one greedy test episode.
        let test = mode == RunMode::Testing || self.since_test >= self.spec.test_interval;
        self.episode_mode = if test { RunMode::Testing } else { RunMode::Learning };
        if test {
            if mode == RunMode::Learning {
                self.since_test = 0;
            }
        } else {
            self.since_test += 1;
        }
        self.agent_mut().set_mode(if test { Mode::Testing } else { Mode::Learning });
        self.episode_return = 0.0;
        let mut obs = [0.0; MAX_OBS];
        let dims = self.robot.observe(&mut obs);
        let t0 = cycles.cycles();
        let result = {
            let (agent, rng) = (self.agent.as_mut(), &mut self.rng);
            agent.map(|a| a.start_episode(&obs[..dims], rng))
        };
        out.agent_cycles = Some(cycles.cycles().wrapping_sub(t0));
        match result {
            Some(Ok(decision)) => {
                self.phase = Phase::Running { steps: 0 };
                self.record(StepKind::Start, &obs[..dims], 0.0, Some(decision), false, readings.time_ms, out);
            }
            // A non-finite observation (a broken sensor): try again next
            // period.
            _ => self.begin_reset(),
        }
    }

    fn continue_episode(&mut self, steps: u32, readings: &Readings, cycles: &impl CycleCounter, out: &mut PeriodOutput) {
        let mut obs = [0.0; MAX_OBS];
        let dims = self.robot.observe(&mut obs);
        let (reward, absorbing) = (self.robot.reward(&self.applied), self.robot.absorbing());
        let timeout = steps >= self.spec.episode_steps;
        // A footstep: the policy's memory moves with the joints before the
        // next decision.
        let footstep = self.robot.footstep() && self.spec.footstep_remap.is_some();
        if let (true, Some(map)) = (footstep, self.spec.footstep_remap) {
            self.agent_mut().remap_memory(&map);
        }
        let t0 = cycles.cycles();
        let (kind, result) = {
            let Some(agent) = self.agent.as_mut() else { return };
            let rng = &mut self.rng;
            if absorbing {
                (StepKind::Absorbing, agent.end_episode(reward, EpisodeEnd::Absorbing, rng).map(|_| None))
            } else if timeout {
                (StepKind::Timeout, agent.end_episode(reward, EpisodeEnd::Timeout(&obs[..dims]), rng).map(|_| None))
            } else {
                (StepKind::Step, agent.step(reward, &obs[..dims], rng).map(Some))
            }
        };
        out.agent_cycles = Some(cycles.cycles().wrapping_sub(t0));
        match result {
            Ok(decision) => {
                self.episode_return += reward;
                self.record(kind, &obs[..dims], reward, decision, footstep, readings.time_ms, out);
                if decision.is_some() {
                    self.phase = Phase::Running { steps };
                } else {
                    out.episode = Some(wire::Episode {
                        index: self.episodes.wrapping_sub(1),
                        mode: self.episode_mode,
                        total_reward: self.episode_return,
                        length: steps,
                        weights_checksum: self.agent().weights_checksum(),
                    });
                    self.begin_reset();
                }
            }
            // A non-finite observation or reward: the episode is given up
            // (nothing learned from it) and the robot reset.
            Err(_) => self.begin_reset(),
        }
    }

    /// Fills the step record.
    #[allow(clippy::too_many_arguments)]
    fn record(
        &mut self,
        kind: StepKind,
        obs: &[f32],
        reward: f32,
        decision: Option<Decision>,
        footstep: bool,
        time_ms: u32,
        out: &mut PeriodOutput,
    ) {
        if kind == StepKind::Start {
            self.episodes = self.episodes.wrapping_add(1);
        }
        let outputs = self.agent().policy().motor_space().dims();
        match decision {
            Some(d) => {
                self.last_action = d.action;
                self.last_output = d.output;
            }
            None => self.last_output = [0.0; pada_core::action_space::MAX_ACTION_DIMS],
        }
        let td_error = match (kind, self.episode_mode) {
            (StepKind::Start, _) | (_, RunMode::Testing) => 0,
            _ => self.agent().stats().last_td_error.0,
        };
        let mut joints = Vec::new();
        for j in self.reported_joints() {
            if let Some(f) = self.fatigue.joint(j) {
                let _ = joints.push(wire::JointFatigue {
                    damage: f.damage(),
                    reengagements: f.reengagements().min(u32::MAX as u64) as u32,
                });
            }
        }
        out.step = Some(wire::Step {
            step: self.steps,
            time_ms,
            episode: self.episodes.wrapping_sub(1),
            mode: self.episode_mode,
            kind,
            state: Vec::from_slice(obs).unwrap_or_default(),
            action: self.last_action,
            output: Vec::from_slice(&self.last_output[..outputs]).unwrap_or_default(),
            reward,
            td_error,
            explored: decision.is_some_and(|d| d.explored),
            footstep,
            joints,
            loop_us: 0,
            agent_cycles: out.agent_cycles.unwrap_or(0),
        });
    }

    /// Health fields the controller knows; the caller adds bus, loop and
    /// link counters.
    pub fn health(&self, health: &mut wire::Health) {
        health.servo_temps_c.clear();
        let n = self.config.joints.len();
        for &t in &self.temps[..n] {
            let _ = health.servo_temps_c.push(t);
        }
        health.min_voltage_dv =
            self.supply[..n].iter().flatten().map(|v| (v * 10.0 + 0.5) as u8).min().unwrap_or(0);
        let stats = self.agent().stats();
        health.trace_drops = stats.trace_drops;
        health.weight_saturations = stats.saturations;
        health.checkpoint_erases = self.flash_wear.most_erases();
        health.saves_refused = self.saves_refused;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use pada_core::fixed::Q16;
    use crate::config::{Board, Robot, TRACE};
    use crate::leo::Leo;
    use crate::pendulum::Pendulum33;
    use pada_core::profile::PENDULUM_EXACT_WEIGHTS as WEIGHTS;
    use core::cell::Cell;
    use core::f32::consts::PI;
    use pada_core::safety::FaultCause;

    struct Clock(Cell<u32>);
    impl CycleCounter for Clock {
        fn cycles(&self) -> u32 {
            let c = self.0.get();
            self.0.set(c + 1000);
            c
        }
    }

    /// The F405's learner for `robot`.
    fn profile(robot: Robot) -> LearnerProfile {
        Board::F405.profile(robot)
    }

    /// The F405's pendulum table (exact).
    fn table() -> Box<[Q16]> {
        vec![Q16::ZERO; WEIGHTS].into_boxed_slice()
    }

    /// The F405's LEO table.
    fn leo_table() -> Box<[Q16]> {
        vec![Q16::ZERO; profile(Robot::Leo).weights().unwrap()].into_boxed_slice()
    }

    /// A healthy pendulum reading: the servo answers, the encoder at `counts`.
    fn pendulum_readings(counts: u16, time_ms: u32) -> Readings {
        let mut r = Readings { encoder: Some(counts), time_ms, ..Readings::default() };
        r.servos[0].state = Some(PresentState { position: 512, speed: 0, load: 0, voltage: 120, temperature: 35 });
        r
    }

    fn start<R: RobotAdapter>(c: &mut Controller<Box<[Q16]>, R>, mode: RunMode) {
        let (result, t) = c.command(&wire::ToChip::Start(mode));
        assert_eq!(result, Ok(()));
        assert!(t.unwrap().torque_enable);
    }

    #[test]
    fn idle_means_torque_off_and_zero_speed() {
        let mut c = Controller::<_, Pendulum33>::new(profile(Robot::Pendulum33), PolicyKind::Sarsa, table(), 1).unwrap();
        let mut out = PeriodOutput::default();
        c.period(&pendulum_readings(0, 0), &Clock(Cell::new(0)), &mut out);
        assert!(!out.torque);
        assert_eq!(out.speeds.as_slice(), &[(1, 0)]);
        assert!(out.step.is_none());
    }

    #[test]
    fn pendulum_episodes_start_after_hanging_still_and_end_by_time() {
        let mut c = Controller::<_, Pendulum33>::new(profile(Robot::Pendulum33), PolicyKind::Pada { delta: 0.5 }, table(), 7).unwrap();
        start(&mut c, RunMode::Learning);
        let clock = Clock(Cell::new(0));
        let mut out = PeriodOutput::default();
        let mut kinds = std::vec::Vec::new();
        let mut episodes = std::vec::Vec::new();
        for k in 0..400u32 {
            c.period(&pendulum_readings(0, k * 30), &clock, &mut out);
            assert!(out.torque);
            if let Some(s) = &out.step {
                kinds.push(s.kind);
                assert_eq!(s.state.len(), 2);
                assert_eq!(s.output.len(), 1);
                assert_eq!(s.joints.len(), 1);
                assert!(out.agent_cycles.is_some());
            }
            if let Some(e) = out.episode {
                episodes.push(e);
            }
        }
        // 34 periods of waiting (1 s still), then Start, 99 Steps, Timeout.
        assert_eq!(kinds[0], StepKind::Start);
        assert!(kinds.iter().filter(|k| **k == StepKind::Step).count() >= 99);
        assert_eq!(kinds[100], StepKind::Timeout);
        assert_eq!(episodes[0].length, 100);
        assert_eq!(episodes[0].index, 0);
        assert_eq!(episodes[0].mode, RunMode::Learning);
        // Reward at the bottom, at rest, with the actions taken.
        assert!(episodes[0].total_reward < 0.0);
    }

    #[test]
    fn every_tenth_episode_is_a_test() {
        let mut c = Controller::<_, Pendulum33>::new(profile(Robot::Pendulum33), PolicyKind::Sarsa, table(), 3).unwrap();
        start(&mut c, RunMode::Learning);
        let clock = Clock(Cell::new(0));
        let mut out = PeriodOutput::default();
        let mut modes = std::vec::Vec::new();
        for k in 0..(11 * 140) {
            c.period(&pendulum_readings(0, k * 30), &clock, &mut out);
            if let Some(e) = out.episode {
                modes.push(e.mode);
            }
        }
        assert!(modes.len() >= 11, "{}", modes.len());
        assert!(modes[..10].iter().all(|m| *m == RunMode::Learning));
        assert_eq!(modes[10], RunMode::Testing);
    }

    #[test]
    fn a_silent_servo_faults_and_torque_goes_off_in_the_same_period() {
        let mut c = Controller::<_, Pendulum33>::new(profile(Robot::Pendulum33), PolicyKind::Sarsa, table(), 1).unwrap();
        start(&mut c, RunMode::Learning);
        let clock = Clock(Cell::new(0));
        let mut out = PeriodOutput::default();
        c.period(&pendulum_readings(0, 0), &clock, &mut out);
        assert!(out.torque);
        // One attempt of two lost: the retry answered, no fault.
        let mut r = pendulum_readings(0, 30);
        r.servos[0].timeouts = 1;
        c.period(&r, &clock, &mut out);
        assert!(out.torque);
        // Both attempts of a period time out: a fault in that period.
        r.servos[0] = ServoRead { state: None, timeouts: 2, ..ServoRead::default() };
        c.period(&r, &clock, &mut out);
        assert!(!out.torque, "torque off in the period the fault is found");
        assert_eq!(out.speeds.as_slice(), &[(1, 0)]);
        let t = out.transitions.iter().find_map(|t| t.entered_fault()).unwrap();
        assert_eq!(t, FaultCause::ServoTimeout { servo: 1, attempts: 2 });
        // Start is refused until the host clears the fault.
        let (result, _) = c.command(&wire::ToChip::Start(RunMode::Learning));
        assert_eq!(result, Err(NackReason::State(pada_core::safety::Rejection::InFault)));
        assert_eq!(c.command(&wire::ToChip::ClearFault).0, Ok(()));
        start(&mut c, RunMode::Learning);
    }

    #[test]
    fn damaged_answers_fault_as_checksum_errors_in_the_period() {
        let mut c = Controller::<_, Pendulum33>::new(profile(Robot::Pendulum33), PolicyKind::Sarsa, table(), 1).unwrap();
        start(&mut c, RunMode::Learning);
        let clock = Clock(Cell::new(0));
        let mut out = PeriodOutput::default();
        // Both answers of the period damaged (each also counts as a timeout).
        let mut r = pendulum_readings(0, 30);
        r.servos[0] = ServoRead { state: None, timeouts: 2, checksum_errors: 2, ..ServoRead::default() };
        c.period(&r, &clock, &mut out);
        assert!(!out.torque);
        let t = out.transitions.iter().find_map(|t| t.entered_fault()).unwrap();
        assert_eq!(t, FaultCause::ChecksumErrors { count: 2, window_ms: 1000 });
    }

    #[test]
    fn servo_error_bits_and_overrun_streaks_fault() {
        let mut c = Controller::<_, Pendulum33>::new(profile(Robot::Pendulum33), PolicyKind::Sarsa, table(), 1).unwrap();
        start(&mut c, RunMode::Learning);
        let clock = Clock(Cell::new(0));
        let mut out = PeriodOutput::default();
        let mut r = pendulum_readings(0, 0);
        r.servos[0].error = ErrorFlags::OVERHEATING;
        c.period(&r, &clock, &mut out);
        assert!(!out.torque);
        assert!(matches!(c.state(), State::Fault(FaultCause::ServoError { servo: 1, .. })));

        let mut c = Controller::<_, Pendulum33>::new(profile(Robot::Pendulum33), PolicyKind::Sarsa, table(), 1).unwrap();
        start(&mut c, RunMode::Learning);
        let mut r = pendulum_readings(0, 0);
        r.last_period_overran = true;
        for _ in 0..2 {
            c.period(&r, &clock, &mut out);
            assert!(out.torque);
        }
        c.period(&r, &clock, &mut out);
        assert!(!out.torque);
        assert!(matches!(c.state(), State::Fault(FaultCause::OverrunStreak { count: 3 })));
    }

    #[test]
    fn leo_soft_limit_faults() {
        let mut c = Controller::<_, Leo>::new(profile(Robot::Leo), PolicyKind::Sarsa, leo_table(), 1).unwrap();
        start(&mut c, RunMode::Learning);
        let clock = Clock(Cell::new(0));
        let mut out = PeriodOutput::default();
        let mut r = Readings { encoder: Some(0), contacts: crate::leo::contact::LEFT, ..Readings::default() };
        for s in r.servos.iter_mut() {
            s.state = Some(PresentState { position: 512, speed: 0, load: 0, voltage: 140, temperature: 30 });
        }
        c.period(&r, &clock, &mut out);
        assert!(out.torque);
        assert_eq!(out.speeds.len(), 7);
        // Right knee bent forward by 40 counts ≈ +0.2 rad: beyond +2° + margin.
        let knee_r = pada_core::robot::leo::Joint::KneeRight as usize;
        r.servos[knee_r].state.as_mut().unwrap().position = 512 + 40;
        c.period(&r, &clock, &mut out);
        assert!(!out.torque);
        assert!(matches!(c.state(), State::Fault(FaultCause::SoftLimit { joint: 4, .. })));
    }

    #[test]
    fn policy_changes_only_with_torque_off_and_reseed() {
        let mut c = Controller::<_, Pendulum33>::new(profile(Robot::Pendulum33), PolicyKind::Sarsa, table(), 5).unwrap();
        let fresh = c.agent().weights_checksum();
        c.agent_mut().weights_mut()[0] = Q16(12345);
        assert_eq!(c.command(&wire::ToChip::SetPolicy(PolicyKind::Pada { delta: 0.5 })).0, Ok(()));
        assert_eq!(c.policy(), PolicyKind::Pada { delta: 0.5 });
        assert_eq!(c.agent().weights_checksum(), fresh, "fresh learner, same seed, same weights");
        assert_eq!(
            c.command(&wire::ToChip::SetPolicy(PolicyKind::Pada { delta: -1.0 })).0,
            Err(NackReason::InvalidParameter)
        );
        assert_eq!(c.policy(), PolicyKind::Pada { delta: 0.5 });
        start(&mut c, RunMode::Learning);
        assert_eq!(c.command(&wire::ToChip::SetPolicy(PolicyKind::Sarsa)).0, Err(NackReason::Busy));
        assert!(c.weights_mut().is_none());
        assert_eq!(c.command(&wire::ToChip::SetEpsilon(2.0)).0, Err(NackReason::InvalidParameter));
        assert_eq!(c.command(&wire::ToChip::SetEpsilon(0.0)).0, Ok(()));
        assert_eq!(c.command(&wire::ToChip::SwitchToSarsa).0, Ok(()));
    }

    #[test]
    fn replaying_the_reported_steps_on_a_host_agent_gives_the_same_actions() {
        // What `pada sil` does with the firmware's telemetry, in miniature: a
        // pendulum that moves with the commands, the Step records replayed
        // through a plain agent with the same seed.
        let seed = 11;
        let mut c = Controller::<_, Pendulum33>::new(profile(Robot::Pendulum33), PolicyKind::Pada { delta: 0.5 }, table(), seed).unwrap();
        start(&mut c, RunMode::Learning);
        let clock = Clock(Cell::new(0));
        let mut out = PeriodOutput::default();
        let mut steps = std::vec::Vec::new();
        let mut angle: f32 = 0.0;
        for k in 0..1500u32 {
            let counts = (angle / (2.0 * PI) * 4096.0).round() as i64;
            c.period(&pendulum_readings(counts.rem_euclid(65536) as u16, k * 30), &clock, &mut out);
            if let Some(s) = out.step.take() {
                steps.push(s);
            }
            // A crude plant: the voltage turns the pendulum.
            let u = c.applied[0];
            angle += 0.02 * u - 0.05 * libm::sinf(angle);
        }
        assert!(steps.len() > 300);

        let robot = Robot::Pendulum33;
        // The host's generator: the firmware's own must draw the same.
        let mut rng = rand_pcg::Pcg32::seed_from_u64(seed);
        let mut agent = robot.spec().agent::<_, TILINGS, TRACE>(PolicyKind::Pada { delta: 0.5 }, profile(robot).layout, table()).unwrap();
        agent.reset_weights(&mut rng);
        for s in &steps {
            agent.set_mode(if s.mode == RunMode::Testing { Mode::Testing } else { Mode::Learning });
            match s.kind {
                StepKind::Start => {
                    let d = agent.start_episode(&s.state, &mut rng).unwrap();
                    assert_eq!(d.action, s.action);
                }
                StepKind::Step => {
                    let d = agent.step(s.reward, &s.state, &mut rng).unwrap();
                    assert_eq!(d.action, s.action, "step {}", s.step);
                }
                StepKind::Absorbing => agent.end_episode(s.reward, EpisodeEnd::Absorbing, &mut rng).unwrap(),
                StepKind::Timeout => {
                    agent.end_episode(s.reward, EpisodeEnd::Timeout(&s.state), &mut rng).unwrap()
                }
            }
        }
        assert_eq!(agent.weights_checksum(), c.agent().weights_checksum());
    }

    // -----------------------------------------------------------------------
    // Saved learning
    // -----------------------------------------------------------------------

    type Store = pada_core::checkpoint::RamStore<{ checkpoint::slot_len(WEIGHTS, 4) }>;

    /// `periods` periods of the crude pendulum of the replay test, from
    /// period `k0`; the Step records.
    fn run_pendulum(c: &mut Controller<Box<[Q16]>, Pendulum33>, angle: &mut f32, k0: u32, periods: u32) -> std::vec::Vec<wire::Step> {
        let clock = Clock(Cell::new(0));
        let mut out = PeriodOutput::default();
        let mut steps = std::vec::Vec::new();
        for k in k0..k0 + periods {
            let counts = (*angle / (2.0 * PI) * 4096.0).round() as i64;
            c.period(&pendulum_readings(counts.rem_euclid(65536) as u16, k * 30), &clock, &mut out);
            if let Some(s) = out.step.take() {
                steps.push(s);
            }
            let u = c.applied[0];
            *angle += 0.02 * u - 0.05 * libm::sinf(*angle);
        }
        steps
    }

    fn stop(c: &mut Controller<Box<[Q16]>, Pendulum33>) {
        assert_eq!(c.command(&wire::ToChip::Stop).0, Ok(()));
        let mut out = PeriodOutput::default();
        c.period(&pendulum_readings(0, 0), &Clock(Cell::new(0)), &mut out);
        assert!(!out.torque);
    }

    #[test]
    fn the_generator_draws_as_the_hosts_rand_pcg() {
        use rand_core::RngCore;
        for seed in [0, 1, 11, crate::config::DEFAULT_SEED, u64::MAX] {
            let mut mine = Pcg32::seed_from_u64(seed);
            let mut host = rand_pcg::Pcg32::seed_from_u64(seed);
            for _ in 0..10_000 {
                assert_eq!(mine.next_u32(), host.next_u32());
            }
            assert_eq!(mine.next_u64(), host.next_u64());
        }
    }

    // -----------------------------------------------------------------------
    // Learning on a wear budget
    // -----------------------------------------------------------------------

    /// The budget the governed tests hold: on the crude pendulum of
    /// `run_pendulum`, tight enough that the governor moves Δ both ways.
    const TEST_BUDGET_S: f32 = 2.0e8;

    #[test]
    fn the_wear_budget_command_starts_a_governor_for_pada_and_lowpass_only() {
        let mut c = Controller::<_, Pendulum33>::new(profile(Robot::Pendulum33), PolicyKind::Pada { delta: 1.0 }, table(), 3).unwrap();
        assert_eq!(c.command(&wire::ToChip::SetMtbfBudget(Some(1.0e3))).0, Ok(()));
        assert_eq!(c.governor().map(|g| g.budget_s()), Some(1.0e3));
        assert_eq!(c.policy(), PolicyKind::Pada { delta: 0.5 }, "starts at the floor, one level");
        assert!(c.policy_report().governor.is_some(), "telemetry carries its status");
        for bad in [0.0, -1.0, f32::NAN, f32::INFINITY, 2.0e10] {
            assert_eq!(c.command(&wire::ToChip::SetMtbfBudget(Some(bad))).0, Err(NackReason::InvalidParameter), "{bad}");
            assert_eq!(c.governor().map(|g| g.budget_s()), Some(1.0e3), "a refused budget changes nothing");
        }
        start(&mut c, RunMode::Learning);
        assert_eq!(c.command(&wire::ToChip::SetMtbfBudget(None)).0, Err(NackReason::Busy));
        stop(&mut c);
        assert_eq!(c.command(&wire::ToChip::SetMtbfBudget(None)).0, Ok(()));
        assert!(c.governor().is_none());
        assert_eq!(c.policy(), PolicyKind::Pada { delta: 0.5 }, "stopping keeps the Δ in force");
        assert_eq!(c.command(&wire::ToChip::SetMtbfBudget(Some(1.0e3))).0, Ok(()));
        assert_eq!(c.command(&wire::ToChip::SetPolicy(PolicyKind::LowPass { alpha: 0.5 })).0, Ok(()));
        assert!(c.governor().is_none(), "a new learner starts without one");
        assert_eq!(c.command(&wire::ToChip::SetMtbfBudget(Some(1.0e3))).0, Ok(()));
        assert_eq!(c.policy(), PolicyKind::LowPass { alpha: 0.1 });
        for k in [PolicyKind::Sarsa, PolicyKind::Integrator { delta: 0.5 }, PolicyKind::OrnsteinUhlenbeck { theta: 0.15, sigma: 0.2 }] {
            assert_eq!(c.command(&wire::ToChip::SetPolicy(k)).0, Ok(()));
            assert_eq!(c.command(&wire::ToChip::SetMtbfBudget(Some(1.0e3))).0, Err(NackReason::InvalidParameter), "{k:?}");
            assert!(c.governor().is_none());
        }
    }

    /// A governed run's records in the order the board sends them.
    enum Sent {
        Step(wire::Step),
        Policy(wire::PolicyReport),
    }

    fn run_governed(c: &mut Controller<Box<[Q16]>, Pendulum33>, angle: &mut f32, periods: u32) -> std::vec::Vec<Sent> {
        let clock = Clock(Cell::new(0));
        let mut out = PeriodOutput::default();
        let mut sent = std::vec::Vec::new();
        for k in 0..periods {
            let counts = (*angle / (2.0 * PI) * 4096.0).round() as i64;
            c.period(&pendulum_readings(counts.rem_euclid(65536) as u16, k * 30), &clock, &mut out);
            if let Some(s) = out.step.take() {
                sent.push(Sent::Step(s));
            }
            if let Some(p) = out.policy.take() {
                sent.push(Sent::Policy(p));
            }
            let u = c.applied[0];
            *angle += 0.02 * u - 0.05 * libm::sinf(*angle);
        }
        sent
    }

    #[test]
    fn a_governed_run_replays_bit_for_bit_from_its_telemetry() {
        // The board's Step records and the Policy reports of the
        // governor's moves, replayed through a host agent that takes each
        // reported Δ when it arrives, give the same actions and weights.
        let seed = 11;
        let mut c = Controller::<_, Pendulum33>::new(profile(Robot::Pendulum33), PolicyKind::Pada { delta: 0.5 }, table(), seed).unwrap();
        assert_eq!(c.command(&wire::ToChip::SetMtbfBudget(Some(TEST_BUDGET_S))).0, Ok(()));
        start(&mut c, RunMode::Learning);
        let mut angle = 0.0;
        let sent = run_governed(&mut c, &mut angle, 3000);
        let moves = c.governor().unwrap().status().moves;
        assert!(moves >= 2, "the governor moved {moves} times: the test needs it to move");

        let robot = Robot::Pendulum33;
        let mut rng = rand_pcg::Pcg32::seed_from_u64(seed);
        let mut agent = robot.spec().agent::<_, TILINGS, TRACE>(PolicyKind::Pada { delta: 0.5 }, profile(robot).layout, table()).unwrap();
        agent.reset_weights(&mut rng);
        let (mut compared, mut reports) = (0, 0);
        for r in &sent {
            let s = match r {
                Sent::Policy(p) => {
                    let g = p.governor.expect("a governed board reports its governor");
                    agent.set_policy_parameter(g.parameter).unwrap();
                    assert_eq!(p.built, PolicyKind::Pada { delta: g.parameter });
                    reports += 1;
                    continue;
                }
                Sent::Step(s) => s,
            };
            agent.set_mode(if s.mode == RunMode::Testing { Mode::Testing } else { Mode::Learning });
            match s.kind {
                StepKind::Start => assert_eq!(agent.start_episode(&s.state, &mut rng).unwrap().action, s.action),
                StepKind::Step => assert_eq!(agent.step(s.reward, &s.state, &mut rng).unwrap().action, s.action, "step {}", s.step),
                StepKind::Absorbing => agent.end_episode(s.reward, EpisodeEnd::Absorbing, &mut rng).unwrap(),
                StepKind::Timeout => agent.end_episode(s.reward, EpisodeEnd::Timeout(&s.state), &mut rng).unwrap(),
            }
            compared += 1;
        }
        assert!(compared > 1000 && reports >= moves, "{compared} steps, {reports} reports");
        assert_eq!(agent.weights_checksum(), c.agent().weights_checksum());
    }

    #[test]
    fn a_checkpoint_carries_the_governor() {
        let mut store = Store::new();
        let mut a = Controller::<_, Pendulum33>::new(profile(Robot::Pendulum33), PolicyKind::Pada { delta: 0.5 }, table(), 5).unwrap();
        assert_eq!(a.command(&wire::ToChip::SetMtbfBudget(Some(TEST_BUDGET_S))).0, Ok(()));
        start(&mut a, RunMode::Learning);
        let mut angle = 0.0;
        run_governed(&mut a, &mut angle, 2000);
        stop(&mut a);
        let governor = a.governor().unwrap().clone();
        assert!(governor.state().steps > 1000);
        a.save_checkpoint(&mut store).unwrap();

        let mut b = Controller::<_, Pendulum33>::new(profile(Robot::Pendulum33), PolicyKind::Pada { delta: 0.5 }, table(), 99).unwrap();
        assert_eq!(b.load_checkpoint(&store), Ok(LoadOutcome::Loaded { generation: 1, slot: 0 }));
        assert_eq!(b.governor(), Some(&governor));
        assert_eq!(b.policy(), a.policy(), "the governor's rung is the Δ in force");
        assert_eq!(b.learner_state(), a.learner_state());
        // Both go on the same way (from the pendulum hanging still, as
        // after a reset).
        start(&mut a, RunMode::Learning);
        start(&mut b, RunMode::Learning);
        let (mut x, mut y) = (0.0, 0.0);
        let sa = run_governed(&mut a, &mut x, 1500);
        let sb = run_governed(&mut b, &mut y, 1500);
        assert!(sa.len() > 300);
        assert_eq!(sa.len(), sb.len());
        assert!(b.governor().unwrap().state().steps > governor.state().steps + 300);
        assert_eq!(a.governor(), b.governor());
        assert_eq!(a.agent().weights_checksum(), b.agent().weights_checksum());
    }

    #[test]
    fn a_checkpoint_carries_the_learner_across_a_reset() {
        let mut store = Store::new();
        let mut a = Controller::<_, Pendulum33>::new(profile(Robot::Pendulum33), PolicyKind::Pada { delta: 0.5 }, table(), 11).unwrap();
        start(&mut a, RunMode::Learning);
        // Only with torque off.
        assert_eq!(a.save_checkpoint(&mut store), Err(CheckpointError::Busy));
        assert_eq!(a.load_checkpoint(&store), Err(CheckpointError::Busy));
        let mut angle = 0.0;
        let before = run_pendulum(&mut a, &mut angle, 0, 1500);
        assert!(before.len() > 300);
        stop(&mut a);
        assert!(a.fatigue().joint(0).unwrap().reengagements() > 0);
        assert_eq!(a.save_checkpoint(&mut store), Ok(Saved { generation: 1, slot: 0, erases: 1 }));
        let saved = a.learner_state();
        assert_eq!(saved.user[user::EPISODES], a.episodes);
        assert!(a.episodes >= 3);

        // The board resets: it boots with SARSA and another seed, and loads.
        let mut b = Controller::<_, Pendulum33>::new(profile(Robot::Pendulum33), PolicyKind::Sarsa, table(), 99).unwrap();
        assert_ne!(b.agent().weights_checksum(), a.agent().weights_checksum());
        assert_eq!(b.load_checkpoint(&store), Ok(LoadOutcome::Loaded { generation: 1, slot: 0 }));
        assert_eq!(b.checkpoints_refused(), 0);
        assert_eq!(b.learner_state(), saved);
        assert_eq!(b.weights(), a.weights());
        assert_eq!(b.policy(), PolicyKind::Pada { delta: 0.5 });
        assert_eq!(b.fatigue().state(), a.fatigue().state());

        // It continues: episode numbers go on, and what it does replays on a
        // host agent restored from the same checkpoint.
        start(&mut b, RunMode::Learning);
        let mut angle = 0.0;
        let after = run_pendulum(&mut b, &mut angle, 0, 1500);
        assert!(after.len() > 300);
        assert_eq!(after[0].kind, StepKind::Start);
        assert_eq!(after[0].episode, saved.user[user::EPISODES]);
        assert!(b.agent_stats().steps > saved.agent.stats.steps);

        let mut state = LearnerState::default();
        let mut weights = table();
        assert!(matches!(checkpoint::load(&store, b.config_hash(), &mut state, &mut weights), Ok(LoadOutcome::Loaded { .. })));
        let robot = Robot::Pendulum33;
        let mut agent = robot.spec().agent::<_, TILINGS, TRACE>(PolicyKind::Sarsa, profile(robot).layout, weights).unwrap();
        agent.restore_state(&state.agent).unwrap();
        let mut rng = Pcg32::from_state(state.rng).unwrap();
        for s in &after {
            agent.set_mode(if s.mode == RunMode::Testing { Mode::Testing } else { Mode::Learning });
            match s.kind {
                StepKind::Start => assert_eq!(agent.start_episode(&s.state, &mut rng).unwrap().action, s.action),
                StepKind::Step => assert_eq!(agent.step(s.reward, &s.state, &mut rng).unwrap().action, s.action),
                StepKind::Absorbing => agent.end_episode(s.reward, EpisodeEnd::Absorbing, &mut rng).unwrap(),
                StepKind::Timeout => agent.end_episode(s.reward, EpisodeEnd::Timeout(&s.state), &mut rng).unwrap(),
            }
        }
        assert_eq!(agent.weights_checksum(), b.agent().weights_checksum());

        // The next save goes to the other slot and carries on the counters.
        stop(&mut b);
        assert_eq!(b.save_checkpoint(&mut store), Ok(Saved { generation: 2, slot: 1, erases: 1 }));
        let mut c = Controller::<_, Pendulum33>::new(profile(Robot::Pendulum33), PolicyKind::Sarsa, table(), 5).unwrap();
        assert_eq!(c.load_checkpoint(&store), Ok(LoadOutcome::Loaded { generation: 2, slot: 1 }));
        assert_eq!(c.learner_state(), b.learner_state());
    }

    #[test]
    fn saves_beyond_the_flash_budget_are_refused_counted_and_reported() {
        let mut c = Controller::<_, Pendulum33>::new(profile(Robot::Pendulum33), PolicyKind::Sarsa, table(), 3).unwrap();
        let mut store = Store::new();
        assert_eq!(c.save_checkpoint(&mut store).map(|s| s.erases), Ok(1));
        // A store whose sectors were erased 5000 times in under a minute of
        // operation: far ahead of the ten-year budget.
        let mut worn = c.learner_state();
        worn.wear = FlashWear { erases: [5000, 5000], operating_s: 40 };
        checkpoint::save(&mut store, c.config_hash(), &worn, c.weights()).unwrap();
        let mut d = Controller::<_, Pendulum33>::new(profile(Robot::Pendulum33), PolicyKind::Sarsa, table(), 3).unwrap();
        assert!(matches!(d.load_checkpoint(&store), Ok(LoadOutcome::Loaded { .. })));
        assert_eq!(d.flash_wear().erases, [5000, 5001]);
        assert_eq!(d.operating_s(), 40, "the operating time carried by the checkpoint");
        let before = store.clone();
        let r = d.save_checkpoint(&mut store);
        assert!(matches!(r, Err(CheckpointError::Save(SaveError::Wear(_)))), "{r:?}");
        assert_eq!(store.slot(0), before.slot(0), "nothing erased");
        assert_eq!(d.saves_refused(), 1);
        let mut health = wire::Health::default();
        d.health(&mut health);
        assert_eq!((health.checkpoint_erases, health.saves_refused), (5001, 1));
    }

    #[test]
    fn refused_checkpoints_are_counted_and_change_nothing() {
        let mut c = Controller::<_, Pendulum33>::new(profile(Robot::Pendulum33), PolicyKind::Sarsa, table(), 3).unwrap();
        start(&mut c, RunMode::Learning);
        let mut angle = 0.0;
        run_pendulum(&mut c, &mut angle, 0, 600);
        stop(&mut c);
        let (state, checksum) = (c.learner_state(), c.agent().weights_checksum());
        // The learner is unchanged; the flash wear is the store's to report.
        let unchanged = |c: &Controller<Box<[Q16]>, Pendulum33>| {
            assert_eq!(LearnerState { wear: state.wear, ..c.learner_state() }, state);
            assert_eq!(c.agent().weights_checksum(), checksum);
        };

        // Nothing there: not a refusal.
        let mut store = Store::new();
        assert_eq!(c.load_checkpoint(&store), Ok(LoadOutcome::NoCheckpoint));
        assert_eq!(c.checkpoints_refused(), 0);

        // Another robot's checkpoint.
        let mut leo = Controller::<_, Leo>::new(profile(Robot::Leo), PolicyKind::Sarsa, leo_table(), 1).unwrap();
        leo.save_checkpoint(&mut store).unwrap();
        let expected = LoadOutcome::ConfigMismatch { expected: c.config_hash(), found: leo.config_hash() };
        assert_eq!(c.load_checkpoint(&store), Ok(expected));
        assert_eq!(c.checkpoints_refused(), 1);
        unchanged(&c);

        // The right configuration, a state out of range: refused by name.
        // (An integrator with Δ = 0.5 has the pendulum's −3/0/+3 V levels,
        // so the configuration hash matches; the state record tells them
        // apart.)
        let integrator = Robot::Pendulum33
            .spec()
            .agent::<_, TILINGS, TRACE>(PolicyKind::Integrator { delta: 0.5 }, profile(Robot::Pendulum33).layout, table())
            .unwrap();
        assert_eq!(config_hash(&profile(Robot::Pendulum33), &integrator), c.config_hash());
        type Change = fn(&mut LearnerState);
        let cases: [(&str, Change); 6] = [
            ("epsilon", |s| s.agent.epsilon = 2.0),
            ("policy.kind", |s| s.agent.policy.kind = PolicyKind::Integrator { delta: 0.5 }),
            ("joints", |s| {
                s.joints.truncate(1);
            }),
            ("rng.increment", |s| s.rng.increment = 2),
            ("since_test", |s| s.user[user::SINCE_TEST] = 11),
            ("user", |s| s.user[3] = 1),
        ];
        for (i, (field, change)) in cases.iter().enumerate() {
            let mut bad = state.clone();
            change(&mut bad);
            let mut store = Store::new();
            checkpoint::save(&mut store, c.config_hash(), &bad, &vec![Q16(1); WEIGHTS]).unwrap();
            assert_eq!(c.load_checkpoint(&store), Ok(LoadOutcome::InvalidState), "{field}");
            assert_eq!(c.last_refusal().map(|e| e.param), Some(*field));
            assert_eq!(c.checkpoints_refused(), 2 + i as u32);
            unchanged(&c);
        }

        // A format-1 checkpoint (weights without the learner's state).
        let mut store = Store::new();
        let v1 = checkpoint::Header {
            version: 1,
            config_hash: c.config_hash(),
            weight_count: WEIGHTS as u32,
            generation: 4,
            payload_crc: checkpoint::crc32(&[0u8; WEIGHTS * 4]),
            state_len: 0,
            weight_bytes: 4,
        };
        let slot = store.slot_mut(0).unwrap();
        slot[..checkpoint::HEADER_LEN].copy_from_slice(&v1.to_bytes());
        slot[checkpoint::HEADER_LEN..checkpoint::HEADER_LEN + WEIGHTS * 4].fill(0);
        assert_eq!(c.load_checkpoint(&store), Ok(LoadOutcome::UnsupportedVersion { found: 1 }));
        assert_eq!(c.last_refusal(), None);
        assert_eq!(c.checkpoints_refused(), 8);
        unchanged(&c);

        // Garbage.
        store.slot_mut(0).unwrap().fill(0);
        assert_eq!(c.load_checkpoint(&store), Ok(LoadOutcome::Corrupt));
        assert_eq!(c.checkpoints_refused(), 9);
        unchanged(&c);

        // And a good one still loads.
        let mut store = Store::new();
        c.save_checkpoint(&mut store).unwrap();
        assert!(matches!(c.load_checkpoint(&store), Ok(LoadOutcome::Loaded { .. })));
        assert_eq!(c.checkpoints_refused(), 9);
        unchanged(&c);
    }
    /// Bytes of one checkpoint slot on every real board: one 128 KiB flash
    /// sector (`memory.x`: sectors 10–11 of the F405/F407; `memory-f429.x`:
    /// sectors 22–23 of the F429).
    const FLASH_SLOT: usize = 128 * 1024;

    #[test]
    fn the_f429s_leo_table_is_refused_as_too_large_and_counted_and_its_pendulum_saves() {
        // LEO on the F429: 2^21 Q16 weights, 8 MiB, all of the SDRAM.
        let f429_leo = Board::F429Sdram.profile(Robot::Leo);
        let weights = f429_leo.weights().unwrap();
        assert_eq!(weights, 1 << 21);
        let mut leo = Controller::<_, Leo>::new(f429_leo, PolicyKind::Sarsa, vec![Q16::ZERO; weights].into_boxed_slice(), 1).unwrap();
        let needed = checkpoint::HEADER_LEN + checkpoint::STATE_LEN + 8 * 1024 * 1024;
        assert_eq!(leo.checkpoint_bytes(), needed);
        let mut store = Box::new(pada_core::checkpoint::RamStore::<FLASH_SLOT>::new());
        let too_large = Err(CheckpointError::Save(SaveError::TooLarge { needed, capacity: FLASH_SLOT }));
        assert_eq!(leo.save_checkpoint(&mut *store), too_large);
        assert_eq!(leo.saves_failed(), 1);
        assert_eq!(leo.save_checkpoint(&mut *store), too_large);
        assert_eq!(leo.saves_failed(), 2);
        // Refused before the store was touched: both slots still erased.
        for slot in 0..2 {
            assert!(store.slot_mut(slot).unwrap().iter().all(|&b| b == 0xFF), "slot {slot} written");
        }
        assert_eq!(leo.load_checkpoint(&*store), Ok(LoadOutcome::NoCheckpoint));

        // The F429's pendulum (exact table in SRAM) fits a sector and saves.
        let f429_pendulum = Board::F429Sdram.profile(Robot::Pendulum33);
        let mut pendulum = Controller::<_, Pendulum33>::new(f429_pendulum, PolicyKind::Sarsa, table(), 1).unwrap();
        assert!(pendulum.checkpoint_bytes() <= FLASH_SLOT, "{}", pendulum.checkpoint_bytes());
        assert_eq!(pendulum.save_checkpoint(&mut *store), Ok(Saved { generation: 1, slot: 0, erases: 1 }));
        assert_eq!(pendulum.saves_failed(), 0);
        // A saved F429 pendulum is not the F405's: the profile is in the hash.
        let mut f405 = Controller::<_, Pendulum33>::new(profile(Robot::Pendulum33), PolicyKind::Sarsa, table(), 1).unwrap();
        assert!(matches!(f405.load_checkpoint(&*store), Ok(LoadOutcome::ConfigMismatch { .. })));
    }

    /// A checkpoint's operating time after 10^6 periods of robot `R` on
    /// `weights` weights is the controlled time to the period (10^6
    /// periods are whole seconds), and after 17 more the whole seconds of
    /// it, rounded down.
    fn operating_time_is_the_controlled_time<R: RobotAdapter>(weights: usize) {
        let table = vec![Q16::ZERO; weights].into_boxed_slice();
        let mut c = Controller::<_, R>::new(profile(R::ROBOT), PolicyKind::Sarsa, table, 1).unwrap();
        let mut store = Box::new(pada_core::checkpoint::RamStore::<FLASH_SLOT>::new());
        let (clock, mut out) = (Clock(Cell::new(0)), PeriodOutput::default());
        let period_us = R::spec().period_us as u64;
        let mut periods = 0;
        for more in [1_000_000, 17] {
            for _ in 0..more {
                c.period(&Readings::default(), &clock, &mut out);
            }
            periods += more;
            c.save_checkpoint(&mut *store).unwrap();
            let operating_s = checkpoint::stored_wear(&*store).unwrap().operating_s;
            let controlled_us = periods * period_us;
            assert_eq!(operating_s, controlled_us / 1_000_000, "{:?} after {periods} periods of {period_us} µs", R::ROBOT);
        }
    }

    #[test]
    fn a_checkpoints_operating_time_is_the_controlled_time() {
        // 30 000 s of the 33 Hz pendulum, 50 000 s of the 20 Hz one,
        // 33 333 s of LEO (33 333 µs a period).
        operating_time_is_the_controlled_time::<Pendulum33>(WEIGHTS);
        operating_time_is_the_controlled_time::<crate::pendulum::Pendulum20>(profile(Robot::Pendulum20).weights().unwrap());
        operating_time_is_the_controlled_time::<Leo>(profile(Robot::Leo).weights().unwrap());
    }

    #[test]
    fn every_f405_checkpoint_fits_a_flash_sector() {
        for robot in Robot::ALL {
            let p = profile(robot);
            let bytes = checkpoint::slot_len(p.weights().unwrap(), p.format.bytes());
            assert!(bytes <= FLASH_SLOT, "{robot:?}: {bytes}");
        }
    }
}
