//! Learn in simulation, finish on the robot: what pretraining on the model
//! saves on a robot that is not its model (`pada paper transfer`).
//!
//! For one robot, three ways of learning on plants drawn within its
//! ranges ([`pada_sim::variation`], one plant per trial):
//!
//! - **from nothing**: the learner's initial weights;
//! - **pretrained on the model**: from the weights of a trial on the model;
//! - **pretrained randomised**: from the weights of a trial on plants drawn
//!   anew every episode (domain randomisation).
//!
//! Trial `i` of every way runs on the same drawn plant with the same
//! exploration (a trial from weights draws the initial weights it does not
//! use, so its generator goes on as the one from nothing).
//!
//! **The objective** of a robot, from the runs from nothing: a greedy test
//! return that covers 90 % of the way from their mean first test return
//! (before learning) to their mean end performance. A trial reaches it at
//! its first test run at or past it; what learning on the plant had cost
//! by then is counted: the fatigue counter's cumulative damage of the most
//! damaged gearbox (the paper's torques; 1 is the gearbox's expected
//! failure, so it is the share of a gearbox's MTBF spent), the learning
//! time, and the task's failures (learning episodes and test runs that
//! ended in an absorbing state). A trial that never reaches it counts its
//! whole run, a lower bound.

use crate::experiment::{run_trial_from, run_trial_keep, HostAgent, RunConfig, TestBooks, TrialResult, TrialStart};
use crate::stats::Estimate;
use pada_core::policy::PolicyKind;
use pada_sim::task::Task;
use pada_sim::variation::{PlantRanges, Redraw, Varied, Vary};
use rayon::prelude::*;
use serde::Serialize;

/// The share of the way from the first test return to the end performance
/// that the objective asks for.
pub const OBJECTIVE_SHARE: f64 = 0.9;

/// Added to the seed of the pretraining trials, so that they differ from
/// the trials on the plant.
pub const PRETRAIN_SEED_OFFSET: u64 = 1_000_003;

/// How a trial on the plant starts.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub enum Start {
    /// From the learner's initial weights.
    Nothing,
    /// From weights pretrained on the model.
    Model,
    /// From weights pretrained on plants randomised every episode.
    Randomised,
}

impl Start {
    /// The three, in the report's order.
    pub const ALL: [Start; 3] = [Start::Nothing, Start::Model, Start::Randomised];

    /// Its label in reports and figures.
    pub fn label(self) -> &'static str {
        match self {
            Start::Nothing => "from nothing",
            Start::Model => "pretrained on the model",
            Start::Randomised => "pretrained randomised",
        }
    }
}

/// What the measurement runs.
#[derive(Debug, Clone, Copy, Serialize)]
pub struct TransferOptions {
    /// Trials of each way.
    pub trials: u32,
    /// Learning time on the plant per trial \[s\].
    pub seconds: f64,
    /// Learning time of a pretraining trial \[s\].
    pub pretrain_seconds: f64,
    /// Master seed.
    pub seed: u64,
    /// The learner, in pretraining and on the plant.
    pub policy: PolicyKind,
}

/// One trial on the plant, up to the objective.
#[derive(Debug, Clone, Copy, Serialize)]
pub struct Outcome {
    /// Whether it reached the objective.
    pub reached: bool,
    /// Cumulative damage of the most damaged gearbox by then (paper's torques).
    pub damage: f64,
    /// The same from the simulated gear torques.
    pub physical_damage: f64,
    /// Learning time by then \[s\].
    pub time_s: f64,
    /// Learning episodes and test runs that ended absorbing before it.
    pub failures: u64,
    /// The trial's end performance.
    pub end_performance: f64,
    /// Its first test return (before learning on the plant).
    pub first_return: f64,
}

/// One way's trials and their means.
#[derive(Debug, Clone, Serialize)]
pub struct Way {
    /// How its trials started.
    pub start: Start,
    /// Each trial.
    pub trials: Vec<Outcome>,
    /// Trials that reached the objective.
    pub reached: usize,
    /// Damage until the objective.
    pub damage: Estimate,
    /// Physical damage until the objective.
    pub physical_damage: Estimate,
    /// Learning time until the objective \[s\].
    pub time_s: Estimate,
    /// Failures until the objective.
    pub failures: Estimate,
    /// End performance.
    pub end_performance: Estimate,
    /// First test return.
    pub first_return: Estimate,
    /// The paper's MTBF over the first 1200 learning actions on the plant \[s\].
    pub mtbf_s: Estimate,
    /// Damage until the objective saved against the same trial from
    /// nothing (trial by trial: the same plant and random numbers).
    pub damage_saved: Estimate,
    /// Whether the mean end performance lies inside the objective.
    pub end_inside_objective: bool,
}

/// One robot's measurement.
#[derive(Debug, Clone, Serialize)]
pub struct RobotTransfer {
    /// The robot's task name.
    pub robot: String,
    /// The ranges its plants were drawn in.
    pub ranges: PlantRanges,
    /// The objective: a test return at least this.
    pub objective: f64,
    /// The three ways, in [`Start::ALL`]'s order.
    pub ways: Vec<Way>,
    /// What it ran.
    pub options: TransferOptions,
}

impl RobotTransfer {
    /// The way that started as `start`.
    pub fn way(&self, start: Start) -> &Way {
        &self.ways[Start::ALL.iter().position(|s| *s == start).unwrap_or(0)]
    }

    /// Mean damage until the objective from nothing over that of `start`.
    pub fn saving(&self, start: Start) -> f64 {
        self.way(Start::Nothing).damage.mean / self.way(start).damage.mean
    }
}

/// Environment steps the measurement takes (for a progress bar).
pub fn expected_steps<T: Task>(task: &T, o: &TransferOptions) -> u64 {
    let s = task.spec();
    let cfg = |seconds| RunConfig { policy: o.policy, switch_at_s: None, mtbf_budget_s: None, seconds, trials: o.trials, seed: o.seed };
    let per = |seconds| cfg(seconds).expected_steps(s.control_period_s, s.episode_steps, s.test_interval);
    o.trials as u64 * (2 * per(o.pretrain_seconds) + 3 * per(o.seconds))
}

/// Runs the measurement on `task` with plants drawn within `ranges`.
pub fn measure<T: Vary + Clone>(
    task: &T,
    ranges: PlantRanges,
    o: &TransferOptions,
    progress: &(dyn Fn(u64) + Sync),
) -> anyhow::Result<RobotTransfer> {
    let pre = RunConfig {
        policy: o.policy,
        switch_at_s: None,
        mtbf_budget_s: None,
        seconds: o.pretrain_seconds,
        trials: o.trials,
        seed: o.seed.wrapping_add(PRETRAIN_SEED_OFFSET),
    };
    let on_plant = RunConfig { seconds: o.seconds, seed: o.seed, ..pre };
    let randomised = Varied::new(task.clone(), ranges, Redraw::PerEpisode);
    let plant = Varied::new(task.clone(), ranges, Redraw::PerTrial);
    // Pretraining: on the model and randomised, every trial in parallel.
    let jobs: Vec<(bool, u32)> = (0..o.trials).flat_map(|t| [(false, t), (true, t)]).collect();
    let agents: Vec<HostAgent> = jobs
        .par_iter()
        .map(|&(rand, t)| {
            let (_, agent, _) = if rand { run_trial_keep(&randomised, &pre, t, progress)? } else { run_trial_keep(task, &pre, t, progress)? };
            Ok(agent)
        })
        .collect::<anyhow::Result<_>>()?;
    // On the plant: from nothing and from each pretrained agent.
    let mut starts: Vec<(Start, u32, Option<HostAgent>)> = Vec::new();
    for (&(rand, t), agent) in jobs.iter().zip(agents) {
        starts.push((if rand { Start::Randomised } else { Start::Model }, t, Some(agent)));
    }
    starts.extend((0..o.trials).map(|t| (Start::Nothing, t, None)));
    let runs: Vec<(Start, u32, TrialResult, TestBooks)> = starts
        .into_par_iter()
        .map(|(start, t, agent)| {
            let from = agent.map_or(TrialStart::Nothing, TrialStart::Agent);
            let (r, _, _, books) = run_trial_from(&plant, &on_plant, t, progress, None, from)?;
            Ok((start, t, r, books))
        })
        .collect::<anyhow::Result<_>>()?;
    let of = |s: Start| {
        let mut v: Vec<_> = runs.iter().filter(|r| r.0 == s).collect();
        v.sort_by_key(|r| r.1);
        v
    };
    let nothing = of(Start::Nothing);
    let mean = |f: &dyn Fn(&TrialResult) -> f64| nothing.iter().map(|r| f(&r.2)).sum::<f64>() / nothing.len().max(1) as f64;
    let first = mean(&|r| r.curve.first().map_or(f64::NAN, |p| p.test_return));
    let end = mean(&|r| r.end_performance);
    let objective = first + OBJECTIVE_SHARE * (end - first);
    let rising = end >= first;
    let base: Vec<Outcome> = nothing.iter().map(|(_, _, r, b)| outcome(r, b, objective, rising)).collect();
    let ways = Start::ALL
        .iter()
        .map(|&s| {
            let trials: Vec<Outcome> = of(s).iter().map(|(_, _, r, b)| outcome(r, b, objective, rising)).collect();
            let saved: Vec<f64> = base.iter().zip(&trials).map(|(n, t)| n.damage - t.damage).collect();
            let end_mean = trials.iter().map(|t| t.end_performance).sum::<f64>() / trials.len().max(1) as f64;
            let est = |f: fn(&Outcome) -> f64| Estimate::of(&trials.iter().map(f).collect::<Vec<_>>());
            Way {
                start: s,
                reached: trials.iter().filter(|t| t.reached).count(),
                damage: est(|t| t.damage),
                physical_damage: est(|t| t.physical_damage),
                time_s: est(|t| t.time_s),
                failures: est(|t| t.failures as f64),
                end_performance: est(|t| t.end_performance),
                first_return: est(|t| t.first_return),
                mtbf_s: Estimate::of(&of(s).iter().map(|r| r.2.mtbf_s).collect::<Vec<_>>()),
                damage_saved: Estimate::of(&saved),
                end_inside_objective: if rising { end_mean >= objective } else { end_mean <= objective },
                trials,
            }
        })
        .collect();
    Ok(RobotTransfer { robot: task.spec().name.to_string(), ranges, objective, ways, options: *o })
}

/// A trial's costs up to the objective (`rising`: higher returns are better).
pub fn outcome(r: &TrialResult, b: &TestBooks, objective: f64, rising: bool) -> Outcome {
    let met = |x: f64| if rising { x >= objective } else { x <= objective };
    let k = r.curve.iter().position(|p| met(p.test_return));
    let last = r.curve.len().saturating_sub(1);
    let at = k.unwrap_or(last);
    let test_falls = r.curve[..at.min(r.curve.len())].iter().filter(|p| p.fell).count() as u64;
    let (damage, physical_damage, learning_falls) = match k {
        Some(k) => (b.damage[k], b.physical_damage[k], b.learning_falls[k]),
        // Never reached: the whole run (a lower bound).
        None => (
            b.damage.last().copied().unwrap_or(0.0),
            b.physical_damage.last().copied().unwrap_or(0.0),
            r.learning_falls,
        ),
    };
    Outcome {
        reached: k.is_some(),
        damage,
        physical_damage,
        time_s: r.curve.get(at).map_or(0.0, |p| p.learning_time_s),
        failures: learning_falls + test_falls,
        end_performance: r.end_performance,
        first_return: r.curve.first().map_or(f64::NAN, |p| p.test_return),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::experiment::run_trial;
    use crate::pendulum::PhysicalPendulumTask;

    fn cfg(seconds: f64, seed: u64) -> RunConfig {
        RunConfig { policy: PolicyKind::Sarsa, switch_at_s: None, mtbf_budget_s: None, seconds, trials: 1, seed }
    }

    #[test]
    fn the_objective_is_met_at_the_first_test_run_past_it_with_the_books_of_then() {
        let task = PhysicalPendulumTask::default();
        let (r, _, _, b) = run_trial_from(&task, &cfg(60.0, 2), 0, &|_| {}, None, TrialStart::Nothing).unwrap();
        assert_eq!((b.damage.len(), b.physical_damage.len(), b.learning_falls.len()), (r.curve.len(), r.curve.len(), r.curve.len()));
        assert!(b.damage.windows(2).all(|w| w[0] <= w[1]) && *b.damage.last().unwrap() > 0.0, "{:?}", b.damage);
        let best = r.curve.iter().map(|p| p.test_return).fold(f64::MIN, f64::max);
        let k = r.curve.iter().position(|p| p.test_return >= best).unwrap();
        let o = outcome(&r, &b, best, true);
        assert!(o.reached);
        assert_eq!((o.damage, o.time_s), (b.damage[k], r.curve[k].learning_time_s));
        let never = outcome(&r, &b, best + 1.0, true);
        assert!(!never.reached);
        assert_eq!(never.damage, *b.damage.last().unwrap());
    }

    #[test]
    fn a_trial_from_no_weights_is_the_trial_as_before_and_from_weights_starts_where_they_left_off() {
        let task = PhysicalPendulumTask::default();
        let before = run_trial(&task, &cfg(600.0, 5), 0, &|_| {}).unwrap();
        let (now, agent, _, _) = run_trial_from(&task, &cfg(600.0, 5), 0, &|_| {}, None, TrialStart::Nothing).unwrap();
        assert_eq!(now, before);
        // The model is deterministic and the test run greedy: learning on
        // from the weights, the first test run repeats the last one.
        let (on, _, _, _) = run_trial_from(&task, &cfg(30.0, 6), 0, &|_| {}, None, TrialStart::Agent(agent)).unwrap();
        assert_eq!(on.curve[0].test_return, before.curve.last().unwrap().test_return);
        assert_ne!(on.curve[0].test_return, before.curve[0].test_return);
    }

    #[test]
    fn the_measurement_runs_three_ways_on_the_same_plants() {
        let task = PhysicalPendulumTask::default();
        let ranges = PlantRanges::MODEL.with_arg("motor_constant=0.8..0.9").unwrap();
        let o = TransferOptions { trials: 2, seconds: 300.0, pretrain_seconds: 600.0, seed: 1, policy: PolicyKind::Sarsa };
        let r = measure(&task, ranges, &o, &|_| {}).unwrap();
        assert_eq!(r.ways.iter().map(|w| (w.start, w.trials.len())).collect::<Vec<_>>(), Start::ALL.map(|s| (s, 2)).to_vec());
        let n = r.way(Start::Nothing);
        assert!(r.objective > n.first_return.mean && r.objective < n.end_performance.mean, "{} {:?}", r.objective, n);
        // Pretrained, the first test run on the plant is better than from nothing's.
        assert!(r.way(Start::Model).first_return.mean > n.first_return.mean);
    }
}
