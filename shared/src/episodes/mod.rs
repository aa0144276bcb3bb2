//! The episode cycle, written once for the chip and the host (Section VI).
//!
//! The paper's framework writes an experiment's behaviour once, against an
//! interface, and runs it on the simulator and on the robot. This module is
//! pada's: [`Episodes`] owns everything about an episode that is not I/O,
//!
//! - learning and greedy test episodes, one test episode after every
//!   [`EpisodeRules::test_interval`] learning episodes;
//! - the kinds of end: an absorbing state (a fall, no bootstrap) or the
//!   time limit of [`EpisodeRules::episode_steps`] transitions (bootstrap);
//! - LEO's footstep remap, which moves the policy's memory with the joints
//!   before the next decision;
//! - the undiscounted return and the episode's report;
//! - which agent calls are learning actions ([`Transition::is_learning_action`]),
//!   the ones the fatigue window and the wear governor see ([`wear`]);
//! - the telemetry `Step` of each call ([`record`]).
//!
//! Its two drivers keep only I/O: the firmware's `Controller::period`
//! reads the servos, brings the robot back to its start between episodes
//! and writes the Moving Speeds; the host's `run_trial` steps the simulated
//! plant and writes the files. Each asks [`Episodes::begin`] for an
//! episode's first decision and [`Episodes::advance`] for every later one.
//!
//! | file | its one job |
//! |---|---|
//! | `mod.rs` | the cycle: cadence, ends, the footstep remap, the return |
//! | `record.rs` | the telemetry `Step` of an agent call |
//! | `wear.rs` | the fatigue counter's damage between two calls, for the governor |

pub mod record;
pub mod wear;

use crate::agent::{Agent, Decision, EpisodeEnd, Mode};
use crate::error::StepError;
use crate::limits::MAX_ACTION_DIMS;
use crate::weights::WeightStore;
use crate::wire::{self, RunMode, StepKind};
use rand_core::RngCore;

/// A footstep's remap of the policy's memory: entry `i` names the output
/// whose memory output `i` takes over (`None`: back to rest).
pub type FootstepRemap = [Option<u8>; MAX_ACTION_DIMS];

/// The rules of a robot's episodes (its definition,
/// [`crate::robot::RobotSpec::episode_rules`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EpisodeRules {
    /// Transitions before the time limit ends an episode.
    pub episode_steps: u32,
    /// Learning episodes between two greedy test episodes (at least 1 is
    /// used: 0 would never learn).
    pub test_interval: u32,
    /// The footstep remap, for a walking robot.
    pub footstep_remap: Option<FootstepRemap>,
}

/// The episode in progress.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Current {
    mode: RunMode,
    /// Transitions (rewards) so far.
    steps: u32,
    /// The undiscounted return so far (in `f64`, as the host's learning
    /// curves have always summed it).
    ret: f64,
}

/// What one agent call did.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Transition {
    /// The call: `Start`, `Step`, or the end (`Absorbing`, `Timeout`).
    pub kind: StepKind,
    /// The episode's mode.
    pub mode: RunMode,
    /// The decision, for `Start` and `Step`.
    pub decision: Option<Decision>,
    /// The reward of the transition into this call's observation (0 at
    /// `Start`).
    pub reward: f32,
    /// Whether a footstep remapped the policy's memory before the call.
    pub footstep: bool,
    /// The episode's undiscounted return so far, this reward included.
    pub episode_return: f64,
    /// The finished episode's report, at an end.
    pub ended: Option<wire::Episode>,
}

impl Transition {
    /// Whether this call chose an action that a learning episode applies:
    /// the actions the paper's MTBF window counts and the wear governor
    /// holds to its budget (end of Section IV).
    pub fn is_learning_action(&self) -> bool {
        is_learning_action(self.mode, self.kind)
    }
}

/// Whether a call of `kind` in an episode of `mode` chose a learning action
/// ([`Transition::is_learning_action`]; also for a `Step` record read
/// back from telemetry).
pub fn is_learning_action(mode: RunMode, kind: StepKind) -> bool {
    mode == RunMode::Learning && matches!(kind, StepKind::Start | StepKind::Step)
}

/// Where the episode in progress is ([`Episodes::position`]): what a fault
/// report names, on the board and on the host alike.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct EpisodeAt {
    /// The episode's index (episodes started before it).
    pub index: u32,
    /// Its mode.
    pub mode: RunMode,
    /// Transitions taken so far: the next reading is the one after action
    /// `steps + 1` of the episode.
    pub steps: u32,
}

/// The episode cycle's state: the test cadence, the episode counter and
/// the episode in progress.
#[derive(Debug, Clone, PartialEq)]
pub struct Episodes {
    rules: EpisodeRules,
    /// Episodes started (the index of the next one).
    started: u32,
    /// Learning episodes since the last test episode.
    since_test: u32,
    current: Option<Current>,
    /// The action of the last decision (what an end's record reports).
    last_action: u32,
}

impl Episodes {
    /// No episode yet; the first one learns (unless a test is asked for).
    pub const fn new(rules: EpisodeRules) -> Self {
        Episodes { rules, started: 0, since_test: 0, current: None, last_action: 0 }
    }

    /// Episodes started so far.
    pub fn started(&self) -> u32 {
        self.started
    }

    /// Learning episodes since the last test episode.
    pub fn since_test(&self) -> u32 {
        self.since_test
    }

    /// Continues the counters of a saved learner (a checkpoint), whose
    /// policy last chose `last_action`; no episode is in progress.
    pub fn restore(&mut self, started: u32, since_test: u32, last_action: u32) {
        self.started = started;
        self.since_test = since_test;
        self.last_action = last_action;
        self.current = None;
    }

    /// Whether an episode is in progress.
    pub fn running(&self) -> bool {
        self.current.is_some()
    }

    /// The episode in progress, if any.
    pub fn position(&self) -> Option<EpisodeAt> {
        self.current.map(|c| EpisodeAt { index: self.started.wrapping_sub(1), mode: c.mode, steps: c.steps })
    }

    /// The mode the next episode will have when `requested` is the run's
    /// mode: a requested test is a test; otherwise every
    /// `test_interval`-th episode after a learning streak is one.
    pub fn next_mode(&self, requested: RunMode) -> RunMode {
        if requested == RunMode::Testing || self.since_test >= self.rules.test_interval.max(1) {
            RunMode::Testing
        } else {
            RunMode::Learning
        }
    }

    /// Whether the next [`advance`](Self::advance) ends the episode in
    /// progress, at an `absorbing` state or the time limit (false with no
    /// episode in progress).
    pub fn ends_next(&self, absorbing: bool) -> bool {
        self.current.is_some_and(|c| absorbing || c.steps + 1 >= self.rules.episode_steps)
    }

    /// Gives up the episode in progress (a broken sensor, torque off):
    /// nothing more is learned from it and no report is made.
    pub fn abandon(&mut self) {
        self.current = None;
    }

    /// Starts an episode in observation `obs` and takes its first decision.
    /// The mode is [`next_mode`](Self::next_mode)`(requested)`; the agent is
    /// put in it. On an error (a non-finite observation) no episode is in
    /// progress and no index is spent.
    pub fn begin<W, R, const T: usize, const TR: usize>(
        &mut self,
        agent: &mut Agent<W, T, TR>,
        requested: RunMode,
        obs: &[f32],
        rng: &mut R,
    ) -> Result<Transition, StepError>
    where
        W: WeightStore,
        R: RngCore + ?Sized,
    {
        let mode = self.next_mode(requested);
        match mode {
            // A cadence's test resets it; a requested one leaves it be.
            RunMode::Testing if requested == RunMode::Learning => self.since_test = 0,
            RunMode::Testing => {}
            RunMode::Learning => self.since_test += 1,
        }
        agent.set_mode(match mode {
            RunMode::Testing => Mode::Testing,
            RunMode::Learning => Mode::Learning,
        });
        self.current = None;
        let decision = agent.start_episode(obs, rng)?;
        self.started = self.started.wrapping_add(1);
        self.current = Some(Current { mode, steps: 0, ret: 0.0 });
        self.last_action = decision.action;
        Ok(Transition {
            kind: StepKind::Start,
            mode,
            decision: Some(decision),
            reward: 0.0,
            footstep: false,
            episode_return: 0.0,
            ended: None,
        })
    }

    /// The next call of the episode in progress: the last action earned
    /// `reward` and led to `obs`, `absorbing` or not; `footstep` says
    /// whether a foot touched down (the remap runs only for a robot that
    /// has one). Ends the episode at an absorbing state or at the time
    /// limit; otherwise takes the next decision. On an error (a
    /// non-finite observation or reward) the episode is given up.
    pub fn advance<W, R, const T: usize, const TR: usize>(
        &mut self,
        agent: &mut Agent<W, T, TR>,
        obs: &[f32],
        reward: f32,
        absorbing: bool,
        footstep: bool,
        rng: &mut R,
    ) -> Result<Transition, StepError>
    where
        W: WeightStore,
        R: RngCore + ?Sized,
    {
        let mut current = self.current.take().ok_or(StepError::NoEpisode)?;
        current.steps += 1;
        let timeout = current.steps >= self.rules.episode_steps;
        let remap = self.rules.footstep_remap.filter(|_| footstep);
        if let Some(map) = &remap {
            agent.remap_memory(map);
        }
        let (kind, decision) = if absorbing {
            agent.end_episode(reward, EpisodeEnd::Absorbing, rng)?;
            (StepKind::Absorbing, None)
        } else if timeout {
            agent.end_episode(reward, EpisodeEnd::Timeout(obs), rng)?;
            (StepKind::Timeout, None)
        } else {
            (StepKind::Step, Some(agent.step(reward, obs, rng)?))
        };
        current.ret += reward as f64;
        let ended = decision.is_none().then(|| wire::Episode {
            index: self.started.wrapping_sub(1),
            mode: current.mode,
            total_reward: current.ret as f32,
            length: current.steps,
            weights_checksum: agent.weights_checksum(),
        });
        match decision {
            Some(d) => {
                self.last_action = d.action;
                self.current = Some(current);
            }
            None => self.current = None,
        }
        Ok(Transition {
            kind,
            mode: current.mode,
            decision,
            reward,
            footstep: remap.is_some(),
            episode_return: current.ret,
            ended,
        })
    }
}

#[cfg(test)]
mod tests;
