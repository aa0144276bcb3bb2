//! One control period, from readings to servo commands and telemetry.
//!
//! [`Controller::period`] is everything the control-loop task does between
//! reading the sensors and writing the servos:
//!
//! 1. the safety machine sees every servo answer, timeout, checksum error,
//!    error bit, joint position and the last period's overrun — a fault
//!    found here switches torque off in **this** period's output;
//! 2. the robot's rules ([`RobotRules`]: `pada_core::robot::pendulum`,
//!    `pada_core::robot::leo`, or a robot of the user's own) turn the
//!    readings into the observation and reward of the robot's one
//!    definition;
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
//! ([`pada_core::governor`], [`pada_core::episodes::wear`]) moves PADA's Δ or the
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
//!
//! | file | its one job |
//! |---|---|
//! | `mod.rs` | the controller: its state, construction and accessors |
//! | `period.rs` | one period, steps 1–6: readings → safety, voltages → Moving Speeds, torques → fatigue; the period's types |
//! | `episodes.rs` | the chip's side of the shared episode cycle: resets, observations, the step records |
//! | `persist.rs` | the learner's state, checkpoints and the flash's erase budget |
//! | `host_kept.rs` | a checkpoint the host keeps (no flash holds the table): the image of a save, the sink of a restore |
//! | `governor.rs` | the wear governor's budget command and its feed |
//! | `commands.rs` | the host commands the controller owns |
//! | `telemetry.rs` | `Hello`, `Policy` and `Health` |

mod commands;
mod episodes;
mod governor;
mod host_kept;
mod import;
mod period;
mod persist;
mod telemetry;
#[cfg(test)]
mod test_support;
#[cfg(test)]
mod tests;

pub use commands::CommandResult;
pub use crate::bus::ServoRead;
pub use period::{safety_config, PeriodOutput, Readings};
pub use host_kept::{HostSave, Misaligned, RestoreSink};
pub use persist::CheckpointError;

use crate::config::{soft_limits, FirmwareAgent, LearnerProfile, MAX_ROBOT_SERVOS};
use crate::encoder::Unwrapper;
use pada_core::robot::RobotRules;
use pada_core::checkpoint::FlashWear;
use pada_core::episodes::Episodes;
use pada_core::error::ConfigError;
use pada_core::fatigue::{FatigueCounter, PAPER_WINDOW_STEPS};
use pada_core::governor::Governor;
use pada_core::policy::PolicyKind;
use pada_core::profile::config_hash;
use pada_core::rng::Pcg32;
use pada_core::robot::RobotSpec;
use pada_core::safety::{Event, Safety, State, Transition};
use pada_core::weights::WeightStore;
use rand_core::SeedableRng;

/// Where the episode cycle is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Phase {
    /// Torque off.
    Stopped,
    /// Bringing the robot back to its start.
    Resetting,
    /// In an episode (its progress is the cycle's, [`Episodes`]).
    Running,
}

/// The control loop's state for a robot with rules `R` on weights `W`:
/// agent, safety machine, the robot's rules, fatigue.
pub struct Controller<W, R> {
    profile: LearnerProfile,
    spec: &'static RobotSpec,
    agent: Option<FirmwareAgent<W>>,
    policy: PolicyKind,
    config_hash: u32,
    seed: u64,
    rng: Pcg32,
    safety: Safety,
    fatigue: FatigueCounter<MAX_ROBOT_SERVOS>,
    robot: R,
    encoder: Unwrapper,
    phase: Phase,
    /// The safety state at the end of the last period.
    last_state: State,
    /// The episode cycle: test cadence, episode counters, the episode in
    /// progress.
    episodes: Episodes,
    /// The last decision's output, applied while an episode runs.
    last_output: [f32; pada_core::action_space::MAX_ACTION_DIMS],
    /// Voltage each servo applied during the last period.
    applied: [f32; MAX_ROBOT_SERVOS],
    /// Last supply each servo reported \[V\].
    supply: [Option<f32>; MAX_ROBOT_SERVOS],
    temps: [u8; MAX_ROBOT_SERVOS],
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
    /// The generation of the last checkpoint saved to or restored from the
    /// host (a table that fits no flash, [`host_kept`]); 0: none.
    host_generation: u32,
}

impl<W, R> Controller<W, R>
where
    W: WeightStore,
    R: RobotRules,
{
    /// A controller for `robot` with the board's learner `profile` (whose
    /// robot must be `robot`'s), learning with `policy` on `weights`,
    /// initialised from `seed` (also the generator of every action).
    pub fn new(robot: R, profile: LearnerProfile, policy: PolicyKind, weights: W, seed: u64) -> Result<Self, ConfigError> {
        let mut controller = Self::without_agent(robot, profile, policy, &weights, seed)?;
        controller.build(policy, weights)?;
        Ok(controller)
    }

    /// The same as [`Controller::new`], written into `slot` (a static's
    /// memory) before its agent is built and its weights initialised there.
    ///
    /// Why: the controller is as large as its agent (tens of KiB), and
    /// `new` returns it by value, so its frame holds a whole controller
    /// while the weights are initialised. On the F405 the stack ends where
    /// the table's SRAM part begins, and that frame reached into the table:
    /// the initialised weights and the controller overwrote each other
    /// (the pendulum's SIL replay found it). Here the agent is built by
    /// [`Controller::build`] on the controller in its final place, and the
    /// weights are initialised after the largest frame has returned.
    pub fn new_in(
        slot: &mut core::mem::MaybeUninit<Self>,
        robot: R,
        profile: LearnerProfile,
        policy: PolicyKind,
        weights: W,
        seed: u64,
    ) -> Result<&mut Self, ConfigError> {
        let controller = slot.write(Self::without_agent(robot, profile, policy, &weights, seed)?);
        controller.build(policy, weights)?;
        Ok(controller)
    }

    /// Everything but the agent (`None`), checked against `weights`.
    fn without_agent(robot: R, profile: LearnerProfile, policy: PolicyKind, weights: &W, seed: u64) -> Result<Self, ConfigError> {
        let spec = robot.spec();
        if profile.robot != spec {
            return Err(ConfigError::new("profile.robot", profile.robot.definition_hash() as f32, "the controller's robot"));
        }
        if spec.joints.len() > MAX_ROBOT_SERVOS {
            return Err(ConfigError::new("joints", spec.joints.len() as f32, "at most MAX_SERVOS (8)"));
        }
        if profile.weights().is_some_and(|n| n != weights.len()) {
            return Err(ConfigError::new("weights", weights.len() as f32, "the profile's table size"));
        }
        let safety = Safety::new(safety_config(soft_limits(spec)))?;
        let fatigue = FatigueCounter::with_gearboxes(|j| spec.joint_gearbox(j), spec.period_s(), Some(PAPER_WINDOW_STEPS))
            .map_err(|_| ConfigError::new("fatigue", 0.0, "valid gearbox parameters (Eqs. 3-7)"))?;
        let controller = Controller {
            profile,
            spec,
            robot,
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
            episodes: Episodes::new(spec.episode_rules()),
            last_output: [0.0; pada_core::action_space::MAX_ACTION_DIMS],
            applied: [0.0; MAX_ROBOT_SERVOS],
            supply: [None; MAX_ROBOT_SERVOS],
            temps: [0; MAX_ROBOT_SERVOS],
            steps: 0,
            checkpoints_refused: 0,
            saves_failed: 0,
            last_refusal: None,
            periods: 0,
            flash_wear: FlashWear::default(),
            operating_before_s: 0,
            saves_refused: 0,
            governor: None,
            host_generation: 0,
        };
        Ok(controller)
    }

    /// A fresh agent with `policy` on `weights`: the generator is reseeded
    /// and the weights initialised, as a host build would do.
    fn build(&mut self, policy: PolicyKind, weights: W) -> Result<(), ConfigError> {
        // Put in its place at once: the agent is several KiB, and every
        // move of it is a copy on the boot's stack, which on the F405 ends
        // where the table's SRAM part begins.
        self.agent = None;
        let agent = self.agent.insert(self.spec.agent(policy, self.profile.layout, weights)?);
        let hash = config_hash(&self.profile, agent);
        self.rng = Pcg32::seed_from_u64(self.seed);
        agent.reset_weights(&mut self.rng);
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

    /// The robot's learning task.
    pub fn spec(&self) -> &'static RobotSpec {
        self.spec
    }

    /// The board's learner profile.
    pub fn profile(&self) -> &LearnerProfile {
        &self.profile
    }

    /// The robot's rules (for inspection).
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

    /// The episode in progress, if any (what a fault report names).
    pub fn episode(&self) -> Option<pada_core::episodes::EpisodeAt> {
        self.episodes.position()
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

    /// The agent's counters.
    pub fn agent_stats(&self) -> pada_core::agent::AgentStats {
        self.agent().stats()
    }

    /// The fatigue counter (every servo, joint order).
    pub fn fatigue(&self) -> &FatigueCounter<MAX_ROBOT_SERVOS> {
        &self.fatigue
    }

    /// Joints whose fatigue goes into each `Step`: the learned ones (the
    /// pendulum's motor; LEO's hips and knees, which take turns as stance
    /// and swing joints).
    pub fn reported_joints(&self) -> core::ops::Range<usize> {
        self.spec.counted.range()
    }

    /// Distance walked in the current (or last) episode \[m\], for a
    /// walking robot.
    pub fn walked_m(&self) -> Option<f32> {
        self.robot.walked_m()
    }

    /// At boot, after a reset by the independent watchdog: a fault.
    pub fn watchdog_reset(&mut self) -> Transition {
        self.safety.on(Event::WatchdogReset)
    }

}
