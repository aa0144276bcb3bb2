//! One trial (Section VI): learning for a given simulated time, with a
//! greedy test run before learning and after every
//! [`TaskSpec::test_interval`](crate::experiment::task::TaskSpec) learning episodes.
//!
//! The episodes themselves (the test cadence, the kinds of end, LEO's
//! footstep remap, the return, the telemetry records) are the episode
//! cycle the firmware runs too ([`pada_core::episodes`]); this file drives
//! it with the simulated plant and keeps the trial's books: the learning
//! curve, the MTBF counters, the governor's and the switch's moments.
//!
//! - The learning curve is the test-run return against learning time (the
//!   simulated time of learning episodes only; test runs do not count).
//! - End performance and rise time follow from it ([`super::metrics`]).
//! - The predicted MTBF is the fatigue counter's windowed MTBF over the
//!   first [`PAPER_WINDOW_STEPS`] learning actions (end of Section IV),
//!   counted per physical gearbox (Eqs. 3–7); the robot's MTBF is its
//!   weakest gearbox's. Two of them: **the paper's** (`mtbf_s`), from the
//!   commanded action as Section IV takes it, linear in the voltage
//!   ([`Plant::commanded_torques`]); and **the physical** one
//!   (`physical_mtbf_s`), from the gear torques the simulation computes
//!   ([`Plant::gearbox_torques`]).

use super::agent_setup::{build_agent, HostAgent};
use super::governed::TrialGovernor;
use super::measured::{robot_mtbf_s, TrialCounts};
use super::config::RunConfig;
use crate::board::fault_line::{fault_explained, Faulted};
use crate::experiment::task::{Plant, Task, TaskSpec};
use crate::seed::{trial_rng, trial_seed};
use anyhow::anyhow;
use pada_core::action_space::MAX_ACTION_DIMS;
use pada_core::agent::Mode;
use pada_core::episodes::record::Stamp;
use pada_core::episodes::wear::damage_raws;
use pada_core::episodes::{Episodes, Transition};
use pada_core::fatigue::{FatigueCounter, PAPER_WINDOW_STEPS};
use pada_core::tile_coding::MAX_STATE_DIMS;
use pada_core::wire::{self, RunMode, StepKind, ToHost};
use rand_pcg::Pcg64;

/// The result types, with their one constructor ([`TrialResult::measured`]).
pub use super::measured::{TestPoint, TrialResult};

/// Receives the trial as telemetry: a `Step` for every agent call and an
/// `Episode` for every episode, as the firmware reports them
/// (`pada_core::wire`; [`crate::telemetry`]).
pub type TrialObserver<'o> = &'o mut (dyn FnMut(ToHost) + Send);

/// Runs trial `trial` of `cfg` on `task`. `progress` is told the number of
/// environment steps after every episode.
pub fn run_trial<T: Task>(
    task: &T,
    cfg: &RunConfig,
    trial: u32,
    progress: &(dyn Fn(u64) + Sync),
) -> anyhow::Result<TrialResult> {
    run_trial_from(task, cfg, trial, progress, None, TrialStart::Nothing).map(|(r, ..)| r)
}

/// [`run_trial`], also returning the agent as learned at the end (for
/// saving its weights) and whether it had switched back to SARSA(λ).
pub fn run_trial_keep<T: Task>(
    task: &T,
    cfg: &RunConfig,
    trial: u32,
    progress: &(dyn Fn(u64) + Sync),
) -> anyhow::Result<(TrialResult, HostAgent, bool)> {
    run_trial_from(task, cfg, trial, progress, None, TrialStart::Nothing).map(|(r, a, s, _)| (r, a, s))
}

/// What replaces a trial's initial weights (`pada run --weights`:
/// `crate::start_weights`), after they were drawn from the trial's seed.
pub type StartWith<'s> = &'s (dyn Fn(&mut HostAgent) -> anyhow::Result<()> + Sync);

/// Where a trial's weights start.
pub enum TrialStart<'w> {
    /// The learner's initial weights.
    Nothing,
    /// What an initialiser puts in ([`StartWith`]: saved weights, `pada
    /// run --weights`).
    With(StartWith<'w>),
    /// A learned agent for the task with the run's policy (its weights and
    /// state are kept).
    Agent(HostAgent),
}

impl<'w> TrialStart<'w> {
    /// From the weights `start` puts in, if given.
    pub fn of(start: Option<StartWith<'w>>) -> Self {
        start.map_or(TrialStart::Nothing, TrialStart::With)
    }
}

/// The books of a trial at each of its test runs, in the order of
/// [`TrialResult::curve`]: what learning had cost by then.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct TestBooks {
    /// The fatigue counter's cumulative damage of the most damaged counted
    /// gearbox (the paper's torques, Eqs. 3–7; 1 is its expected failure).
    pub damage: Vec<f64>,
    /// The same from the simulated gear torques.
    pub physical_damage: Vec<f64>,
    /// Learning episodes that had ended in an absorbing state.
    pub learning_falls: Vec<u64>,
}

/// [`run_trial_keep`], telling `observer` every agent call and episode,
/// starting as `start` says, and returning the books at every test run
/// ([`TestBooks`]).
pub fn run_trial_from<T: Task>(
    task: &T,
    cfg: &RunConfig,
    trial: u32,
    progress: &(dyn Fn(u64) + Sync),
    observer: Option<TrialObserver<'_>>,
    start: TrialStart<'_>,
) -> anyhow::Result<(TrialResult, HostAgent, bool, TestBooks)> {
    let spec = task.spec();
    anyhow::ensure!(
        spec.episode_steps >= 1,
        "task {}: episodes must have at least one step",
        spec.name
    );
    let mut rng = trial_rng(cfg.seed, trial);
    // The initial weights are drawn even when the trial starts from
    // others: the trial's random numbers afterwards are those of the trial
    // from nothing (the same seed explores the same way and meets the
    // same plant).
    let mut agent = build_agent(spec, cfg.policy)?;
    agent.reset_weights(&mut rng);
    match start {
        TrialStart::Nothing => {}
        TrialStart::With(put) => put(&mut agent)?,
        TrialStart::Agent(a) => agent = a,
    }
    let fatigue = FatigueCounter::with_gearboxes(
        |c| spec.gearbox(c),
        spec.control_period_s,
        Some(PAPER_WINDOW_STEPS),
    )
    .map_err(|e| anyhow!("{e}"))?;
    let physical = fatigue.clone();
    let governor = match cfg.mtbf_budget_s {
        Some(budget) => {
            let g = TrialGovernor::new(spec, &cfg.policy, budget)?;
            agent.set_policy_parameter(g.parameter()).map_err(|e| anyhow!("{e}"))?;
            Some(g)
        }
        None => None,
    };
    let mut t = Trial {
        spec,
        trial,
        agent,
        plant: task.plant(),
        rng,
        fatigue,
        physical,
        obs: [0.0; MAX_STATE_DIMS],
        switch_step: cfg
            .switch_at_s
            .map(|s| (s / spec.control_period_s).round() as u64),
        learning_steps: 0,
        learning_falls: 0,
        test_steps: 0,
        episodes: 0,
        curve: Vec::new(),
        observer,
        calls: 0,
        cycle: Episodes::new(spec.episode_rules()),
        governor,
        progress,
        books: TestBooks::default(),
    };

    let budget = (cfg.seconds / spec.control_period_s).round() as u64;
    t.report_policy();
    // A test run before learning; then the cycle's own test run after
    // every `test_interval` learning episodes; a final one once the
    // learning time is spent (unless the last episode was one).
    let mut last = t.episode(RunMode::Testing)?;
    while t.learning_steps < budget {
        last = t.episode(RunMode::Learning)?;
    }
    if last == RunMode::Learning {
        t.episode(RunMode::Testing)?;
    }
    // The agent as a finished run leaves it: learning (for saving).
    t.agent.set_mode(Mode::Learning);

    let switched = cfg.switch_at_s.is_some() && t.switch_step.is_none();
    let governor = t.governor.as_ref().map(|g| g.finish(robot_mtbf_s(&t.fatigue), robot_mtbf_s(&t.physical)));
    let counts = TrialCounts {
        trial,
        seed: trial_seed(cfg.seed, trial),
        learning_steps: t.learning_steps,
        test_steps: t.test_steps,
        learning_falls: t.learning_falls,
        learning_episodes: t.episodes,
        stats: t.agent.stats(),
        table: pada_core::weights::WeightStore::occupancy(t.agent.weights()),
        governor,
    };
    let dims = t.spec.motor.dims();
    let result = TrialResult::measured(counts, t.curve, &t.fatigue, &t.physical, dims);
    Ok((result, t.agent, switched, t.books))
}

/// The state of a running trial.
struct Trial<'a, 'o, 'p, P: Plant> {
    spec: &'a TaskSpec,
    /// The trial's index within the run.
    trial: u32,
    agent: HostAgent,
    plant: P,
    rng: Pcg64,
    /// Per gearbox, from the commanded action (the paper's MTBF).
    fatigue: FatigueCounter<MAX_ACTION_DIMS>,
    /// Per gearbox, from the simulated gear torques (the physical MTBF).
    physical: FatigueCounter<MAX_ACTION_DIMS>,
    obs: [f32; MAX_STATE_DIMS],
    /// Learning step at which the policy switches back to SARSA(λ).
    switch_step: Option<u64>,
    learning_steps: u64,
    learning_falls: u64,
    test_steps: u64,
    episodes: u32,
    curve: Vec<TestPoint>,
    observer: Option<TrialObserver<'o>>,
    /// Agent calls so far (the `step` of telemetry).
    calls: u32,
    /// The episode cycle, shared with the firmware.
    cycle: Episodes,
    /// The wear governor, with `--mtbf-budget`.
    governor: Option<TrialGovernor>,
    /// Told the environment steps after every episode.
    progress: &'p (dyn Fn(u64) + Sync),
    /// The books at every test run.
    books: TestBooks,
}

impl<P: Plant> Trial<'_, '_, '_, P> {
    /// Reports one agent call to the observer, as the firmware does
    /// (the cycle's record).
    fn report_step(&mut self, t: &Transition) {
        let Some(observer) = self.observer.as_mut() else {
            return;
        };
        self.calls = self.calls.wrapping_add(1);
        let env_steps = self.learning_steps + self.test_steps;
        let stamp = Stamp {
            step: self.calls,
            time_ms: (env_steps as f64 * self.spec.control_period_s * 1000.0) as u32,
            agent_cycles: 0,
        };
        let gearboxes = &self.fatigue.joints()[..self.spec.gearboxes.min(MAX_ACTION_DIMS)];
        let obs = &self.obs[..self.spec.state.len()];
        observer(ToHost::Step(self.cycle.record(t, &self.agent, obs, gearboxes, stamp)));
        if let Some(report) = t.ended {
            observer(ToHost::Episode(report));
            // While a governor runs, its damage rate after every episode.
            if self.governor.is_some() {
                self.report_policy();
            }
        }
    }

    /// Switches to SARSA(λ) once the learning steps reach the switch point.
    fn maybe_switch(&mut self) -> anyhow::Result<()> {
        if self.switch_step.is_some_and(|s| self.learning_steps >= s) {
            self.agent.switch_to_sarsa().map_err(|e| anyhow!("{e}"))?;
            self.switch_step = None;
            self.report_policy();
        }
        Ok(())
    }

    /// Reports the policy in force to the observer (at the start and after
    /// the switch back to SARSA(λ)), as the firmware does.
    fn report_policy(&mut self) {
        let Some(observer) = self.observer.as_mut() else {
            return;
        };
        let policy = self.agent.policy();
        observer(ToHost::Policy(wire::PolicyReport {
            step: self.calls,
            built: policy.built_kind(),
            switched_to_sarsa: policy.switched(),
            governor: self.governor.as_ref().map(|g| g.governor().status()),
        }));
    }

    /// Ends the trial at a fault of the plant's last reading (a joint past
    /// its soft limit), as the board's trial ends there: the same reading
    /// faults on both, told in the same words.
    fn stop_at_fault(&self) -> anyhow::Result<()> {
        let Some(cause) = self.plant.fault() else { return Ok(()) };
        let at = self.cycle.position();
        let readings = self.learning_steps + self.test_steps + at.map_or(0, |e| e.steps as u64 + 1);
        let t_us = (readings as f64 * self.spec.control_period_s * 1e6).round() as u64;
        let Some(robot) = self.spec.profile.map(|p| p.robot) else {
            anyhow::bail!("trial {}: {} faulted ({}) {:.2} s into the run", self.trial, self.spec.name, cause.name(), t_us as f64 * 1e-6);
        };
        anyhow::bail!("trial {}: {}", self.trial, fault_explained(robot, cause, t_us, at, Faulted::Simulation))
    }

    /// One episode to the time limit or an absorbing state, in the mode the
    /// cycle gives `requested`; returns that mode. A learning episode
    /// counts its steps, falls and applied torques; a test run goes on the
    /// learning curve.
    fn episode(&mut self, requested: RunMode) -> anyhow::Result<RunMode> {
        let spec = self.spec;
        let (n, motors) = (spec.state.len(), spec.motor.dims());
        let bad = |e: pada_core::error::StepError| anyhow!("{}: {e}", spec.name);
        let mode = self.cycle.next_mode(requested);
        let learning = mode == RunMode::Learning;
        if learning {
            self.maybe_switch()?;
        }
        self.plant.reset(&mut self.rng, &mut self.obs[..n]);
        self.stop_at_fault()?;
        let mut t = self.cycle.begin(&mut self.agent, requested, &self.obs[..n], &mut self.rng).map_err(bad)?;
        self.report_step(&t);
        let report = loop {
            let Some(d) = t.decision else { unreachable!("a decision until the episode ends") };
            let command = &d.output[..motors];
            let step = self.plant.step(command, &mut self.obs[..n]);
            self.stop_at_fault()?;
            if learning {
                let before = damage_raws(&self.fatigue);
                self.fatigue
                    .update(&self.plant.commanded_torques(command))
                    .map_err(|e| anyhow!("{e}"))?;
                // The governor moves Δ or α for the next decision.
                let moved = self.governor.as_mut().and_then(|g| g.observe(&before, &self.fatigue));
                if let Some(parameter) = moved {
                    self.agent.set_policy_parameter(parameter).map_err(|e| anyhow!("{e}"))?;
                    self.report_policy();
                }
                self.physical
                    .update(&self.plant.gearbox_torques(command))
                    .map_err(|e| anyhow!("{e}"))?;
                self.learning_steps += 1;
                self.learning_falls += step.terminal as u64;
                if !self.cycle.ends_next(step.terminal) {
                    self.maybe_switch()?;
                }
            }
            let (obs, footstep) = (&self.obs[..n], self.plant.footstep());
            t = self
                .cycle
                .advance(&mut self.agent, obs, step.reward, step.terminal, footstep, &mut self.rng)
                .map_err(bad)?;
            self.report_step(&t);
            if let Some(report) = t.ended {
                break report;
            }
        };
        (self.progress)(report.length as u64);
        if learning {
            self.episodes += 1;
        } else {
            self.curve.push(TestPoint {
                learning_time_s: self.learning_steps as f64 * spec.control_period_s,
                learning_episodes: self.episodes,
                test_return: t.episode_return,
                walked_m: self.plant.walked_distance_m(),
                fell: t.kind == StepKind::Absorbing,
                duration_s: report.length as f64 * spec.control_period_s,
                claimed_slots: pada_core::weights::WeightStore::occupancy(self.agent.weights()).map(|o| o.claimed),
            });
            self.test_steps += report.length as u64;
            let most = |c: &FatigueCounter<MAX_ACTION_DIMS>| {
                c.joints()[..spec.gearboxes.min(MAX_ACTION_DIMS)].iter().map(|j| j.damage()).fold(0.0, f64::max)
            };
            self.books.damage.push(most(&self.fatigue));
            self.books.physical_damage.push(most(&self.physical));
            self.books.learning_falls.push(self.learning_falls);
        }
        Ok(mode)
    }
}
