//! Trials in parallel: every (configuration, trial) pair is one job for
//! rayon's pool (all cores by default), each with its own seed, so the
//! results do not depend on scheduling.

use super::agent_setup::HostAgent;
/// The run configuration, where the runner's users have found it.
pub use super::config::RunConfig;
use super::trial::{run_trial_from, run_trial_keep, StartWith, TrialObserver, TrialResult, TrialStart};
use crate::experiment::task::Task;
use rayon::prelude::*;

/// Runs the trials of `cfg` in parallel; results in trial order.
pub fn run_trials<T: Task>(
    task: &T,
    cfg: &RunConfig,
    progress: &(dyn Fn(u64) + Sync),
) -> anyhow::Result<Vec<TrialResult>> {
    Ok(run_configs(task, std::slice::from_ref(cfg), progress)?.remove(0))
}

/// [`run_trials`], with trial 0 told to `observer` (telemetry) if given,
/// and trial 0's learned agent returned with whether it had switched back
/// to SARSA(λ) (for saving its weights). The other trials run in parallel
/// with it. Every trial starts from the weights `start` puts in, if given.
pub fn run_trials_observed<T: Task>(
    task: &T,
    cfg: &RunConfig,
    progress: &(dyn Fn(u64) + Sync),
    observer: Option<TrialObserver<'_>>,
    start: Option<StartWith<'_>>,
) -> anyhow::Result<(Vec<TrialResult>, HostAgent, bool)> {
    let (first, rest) = rayon::join(
        || run_trial_from(task, cfg, 0, progress, observer, TrialStart::of(start)).map(|(r, a, s, _)| (r, a, s)),
        || {
            (1..cfg.trials)
                .into_par_iter()
                .map(|t| run_trial_from(task, cfg, t, progress, None, TrialStart::of(start)).map(|(r, ..)| r))
                .collect::<anyhow::Result<Vec<_>>>()
        },
    );
    let (first, agent, switched) = first?;
    let mut results = vec![first];
    results.extend(rest?);
    Ok((results, agent, switched))
}

/// Runs every configuration's trials as one pool of jobs (good load
/// balance across configurations); results per configuration, in trial
/// order. The first error stops the run.
pub fn run_configs<T: Task>(
    task: &T,
    cfgs: &[RunConfig],
    progress: &(dyn Fn(u64) + Sync),
) -> anyhow::Result<Vec<Vec<TrialResult>>> {
    run_configs_keeping(task, cfgs, progress, &|_| {})
}

/// A finished trial's learner, handed to [`run_configs_keeping`]'s `keep`.
pub struct FinishedTrial<'a> {
    /// Index of its configuration in `cfgs`.
    pub config: usize,
    /// Trial index within the configuration.
    pub trial: u32,
    /// Its result.
    pub result: &'a TrialResult,
    /// The learned agent.
    pub agent: HostAgent,
    /// Whether it had switched back to SARSA(λ).
    pub switched: bool,
}

/// [`run_configs`], offering each trial's learner to `keep` as it finishes
/// (from the worker thread); a learner `keep` does not take is dropped.
pub fn run_configs_keeping<T: Task>(
    task: &T,
    cfgs: &[RunConfig],
    progress: &(dyn Fn(u64) + Sync),
    keep: &(dyn Fn(FinishedTrial) + Sync),
) -> anyhow::Result<Vec<Vec<TrialResult>>> {
    let jobs: Vec<(usize, u32)> = cfgs
        .iter()
        .enumerate()
        .flat_map(|(c, cfg)| (0..cfg.trials).map(move |t| (c, t)))
        .collect();
    let results: Vec<TrialResult> = jobs
        .par_iter()
        .map(|&(c, t)| {
            let (result, agent, switched) = run_trial_keep(task, &cfgs[c], t, progress)?;
            keep(FinishedTrial { config: c, trial: t, result: &result, agent, switched });
            Ok(result)
        })
        .collect::<anyhow::Result<_>>()?;
    let mut out: Vec<Vec<TrialResult>> = cfgs
        .iter()
        .map(|c| Vec::with_capacity(c.trials as usize))
        .collect();
    for (&(c, _), r) in jobs.iter().zip(results) {
        out[c].push(r);
    }
    Ok(out)
}
