//! Section VIII on LEO: SARSA(λ), PADA and the low-pass filter at a few Δ
//! and α, with and without switching back to SARSA(λ) at half the run, in
//! one call.
//!
//! Configurations (the paper names neither its Δ nor its α for LEO):
//! PADA Δ ∈ {1/6, 1/3} — with 7 levels 1/6 of the range apart, Δ = 1/6
//! allows the current level ±1, Δ = 1/3 ±2 —, low-pass α ∈ {0.2, 0.5};
//! each without and with the switch at half the learning time (the paper's
//! 7,333 s of 14,666 s).

use crate::console::errln;
use crate::experiment::task::Task;
use crate::experiment::tasks::TaskName;
use crate::experiment::{
    run_configs_keeping, run_trial_keep, FinishedTrial, HostAgent, RunConfig, TrialResult,
};
use crate::leo::rl::LeoTask;
use crate::paper::curves::binned_curve;
use crate::paper::pendulum::ConfigResult;
use crate::plan::{Experiment, ExperimentKind};
use crate::summary::RunSummary;
use pada_core::policy::PolicyKind;
use serde::Serialize;

/// PADA Δ values.
pub const LEO_PADA_DELTAS: [f32; 2] = [1.0 / 6.0, 1.0 / 3.0];
/// Low-pass α values.
pub const LEO_LOWPASS_ALPHAS: [f32; 2] = [0.2, 0.5];
/// The paper's learning time per trial \[s\].
pub const PAPER_SECONDS: f64 = 14_666.0;
/// The paper's trials per configuration.
pub const PAPER_TRIALS: u32 = 15;
/// Paper: SARSA(λ) end performance 1760 ± 262.
pub const PAPER_SARSA_END: (f64, f64) = (1760.0, 262.0);
/// Paper: SARSA(λ) MTBF 362 s.
pub const PAPER_SARSA_MTBF_S: f64 = 362.0;
/// Paper: PADA and low-pass with the switch reach ≈ 39,000 s (×108).
pub const PAPER_FILTERED_MTBF_S: f64 = 39_000.0;

/// How to run Section VIII.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct LeoOptions {
    /// Trials per configuration.
    pub trials: u32,
    /// Learning time per trial \[s\].
    pub seconds: f64,
    /// Master seed.
    pub seed: u64,
}

/// One configuration: policy and switch.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LeoConfigSpec {
    /// The policy.
    pub policy: PolicyKind,
    /// Whether it switches back to SARSA(λ) at half the learning time.
    pub switch: bool,
}

/// The configurations, SARSA(λ) first.
pub fn leo_configs() -> Vec<LeoConfigSpec> {
    let mut v = vec![LeoConfigSpec {
        policy: PolicyKind::Sarsa,
        switch: false,
    }];
    for switch in [false, true] {
        for &delta in &LEO_PADA_DELTAS {
            v.push(LeoConfigSpec {
                policy: PolicyKind::Pada { delta },
                switch,
            });
        }
        for &alpha in &LEO_LOWPASS_ALPHAS {
            v.push(LeoConfigSpec {
                policy: PolicyKind::LowPass { alpha },
                switch,
            });
        }
    }
    v
}

/// The results of Section VIII: a function of the options and the trials'
/// results only (wall time and threads: [`crate::timing::RunTiming`]).
#[derive(Debug, Clone, Serialize)]
pub struct LeoResults {
    /// Options used.
    pub options: LeoOptions,
    /// One per configuration, in [`leo_configs`] order.
    pub configs: Vec<ConfigResult>,
    /// Whether each configuration switched, parallel to `configs`.
    pub switched: Vec<bool>,
    /// Environment steps.
    pub env_steps: u64,
}

fn run_configs_of(o: &LeoOptions) -> Vec<RunConfig> {
    leo_configs()
        .iter()
        .map(|c| RunConfig {
            policy: c.policy,
            switch_at_s: c.switch.then_some(o.seconds / 2.0),
            mtbf_budget_s: None,
            seconds: o.seconds,
            trials: o.trials,
            seed: o.seed,
        })
        .collect()
}

/// Environment steps the whole experiment takes (for a progress bar).
pub fn expected_steps(o: &LeoOptions) -> u64 {
    let task = LeoTask::default();
    let s = task.spec();
    run_configs_of(o)
        .iter()
        .map(|c| {
            c.trials as u64 * c.expected_steps(s.control_period_s, s.episode_steps, s.test_interval)
        })
        .sum()
}

/// The learner of the trial with the best end performance of the whole
/// experiment, kept to draw its gait.
pub struct BestTrial {
    /// Index into [`LeoResults::configs`].
    pub config: usize,
    /// Trial index within the configuration.
    pub trial: u32,
    /// Its end performance.
    pub end_performance: f64,
    /// Whether it had switched back to SARSA(λ).
    pub switched: bool,
    /// The learned agent.
    pub agent: HostAgent,
}

/// Section VIII as an experiment, in [`leo_configs`] order.
pub fn experiment(o: &LeoOptions, command: String) -> Experiment {
    let configs: Vec<(TaskName, RunConfig)> = run_configs_of(o)
        .into_iter()
        .map(|c| (TaskName::Leo, c))
        .collect();
    Experiment::new(ExperimentKind::PaperLeo, command, &configs)
}

/// Whether trial `(config, trial)` with end performance `e` beats the best
/// so far: a higher finite end performance, ties going to the earlier
/// configuration and trial, so the choice does not depend on which trial
/// finished first.
fn beats(e: f64, at: (usize, u32), best: Option<(f64, (usize, u32))>) -> bool {
    e.is_finite() && best.is_none_or(|(b, b_at)| e > b || (e == b && at < b_at))
}

/// The best trial of the results: `(configuration, trial)`.
pub fn best_of(per_config: &[Vec<TrialResult>]) -> Option<(usize, u32)> {
    let mut best: Option<(f64, (usize, u32))> = None;
    for (c, results) in per_config.iter().enumerate() {
        for r in results {
            if beats(r.end_performance, (c, r.trial), best) {
                best = Some((r.end_performance, (c, r.trial)));
            }
        }
    }
    best.map(|(_, at)| at)
}

/// Runs Section VIII in this process: every trial of every configuration in
/// parallel. Returns the results per configuration and the best trial's
/// learner (`None` only when no trial has a finite end performance).
pub fn run_local(
    experiment: &Experiment,
    progress: &(dyn Fn(u64) + Sync),
) -> anyhow::Result<(Vec<Vec<TrialResult>>, Option<BestTrial>)> {
    let task = LeoTask::default();
    let cfgs = experiment
        .configurations
        .iter()
        .map(|c| c.run_config())
        .collect::<anyhow::Result<Vec<_>>>()?;
    // Only the best learner so far is kept (64 MiB each), not all of them.
    let best: std::sync::Mutex<Option<BestTrial>> = std::sync::Mutex::new(None);
    let results = run_configs_keeping(&task, &cfgs, progress, &|f: FinishedTrial| {
        let e = f.result.end_performance;
        let mut b = best.lock().unwrap_or_else(|p| p.into_inner());
        let so_far = b.as_ref().map(|b| (b.end_performance, (b.config, b.trial)));
        if beats(e, (f.config, f.trial), so_far) {
            *b = Some(BestTrial {
                config: f.config,
                trial: f.trial,
                end_performance: e,
                switched: f.switched,
                agent: f.agent,
            });
        }
    })?;
    Ok((
        results,
        best.into_inner().unwrap_or_else(|p| p.into_inner()),
    ))
}

/// Runs the best trial again to get its learner, for a run whose trials ran
/// elsewhere (a merged plan): a trial is reproducible bit for bit from its
/// seed, so this is the learner the local run kept.
pub fn rerun_best(
    experiment: &Experiment,
    per_config: &[Vec<TrialResult>],
) -> anyhow::Result<Option<BestTrial>> {
    let Some((config, trial)) = best_of(per_config) else {
        return Ok(None);
    };
    let cfg = experiment.configurations[config].run_config()?;
    let (result, agent, switched) = run_trial_keep(&LeoTask::default(), &cfg, trial, &|_| {})?;
    anyhow::ensure!(
        result == per_config[config][trial as usize],
        "the best trial ({}, trial {trial}) ran again differently from its stored result",
        experiment.configurations[config].label
    );
    Ok(Some(BestTrial {
        config,
        trial,
        end_performance: result.end_performance,
        switched,
        agent,
    }))
}

/// The best trial's learner for a run of the plan in `dir`: the weights
/// its trial kept there ([`crate::plan::best`]), or, if they are missing,
/// the trial run again ([`rerun_best`]).
pub fn best_of_plan(
    dir: &std::path::Path,
    experiment: &Experiment,
    per_config: &[Vec<TrialResult>],
) -> anyhow::Result<Option<BestTrial>> {
    let Some((config, trial)) = best_of(per_config) else {
        return Ok(None);
    };
    let index = experiment
        .trials()
        .iter()
        .position(|t| t.config == config && t.trial == trial)
        .ok_or_else(|| anyhow::anyhow!("the best trial is not in the plan"))? as u32;
    let path = crate::plan::best::weights_path(dir, index);
    if !path.exists() {
        errln!(
            "{} is missing: running the best trial again for its weights and gait",
            path.display()
        );
        return rerun_best(experiment, per_config);
    }
    let (header, agent) = crate::weights::load(&path, LeoTask::default().spec())?;
    let cfg = experiment.configurations[config].run_config()?;
    anyhow::ensure!(
        header.policy == cfg.policy,
        "{} holds the weights of another configuration",
        path.display()
    );
    Ok(Some(BestTrial {
        config,
        trial,
        end_performance: per_config[config][trial as usize].end_performance,
        switched: header.switched,
        agent,
    }))
}

/// The width of a learning curve's bin: one test interval of full-length
/// learning episodes (10 × 25 s = 250 s), the longest gap between two test
/// runs, so a trial's held value spans at most one bin
/// ([`binned_curve`]).
fn curve_bin_s(spec: &crate::experiment::task::TaskSpec) -> f64 {
    f64::from(spec.test_interval) * f64::from(spec.episode_steps) * spec.control_period_s
}

/// The results of Section VIII from every configuration's trials.
pub fn assemble(
    o: &LeoOptions,
    experiment: &Experiment,
    per_config: Vec<Vec<TrialResult>>,
) -> anyhow::Result<LeoResults> {
    anyhow::ensure!(
        per_config.len() == experiment.configurations.len(),
        "Section VIII has {} configurations, not {}",
        experiment.configurations.len(),
        per_config.len()
    );
    let task = LeoTask::default();
    let mut configs = Vec::with_capacity(per_config.len());
    let mut switched = Vec::with_capacity(per_config.len());
    for (c, r) in experiment.configurations.iter().zip(per_config) {
        let cfg = c.run_config()?;
        switched.push(cfg.switch_at_s.is_some());
        configs.push(ConfigResult {
            policy: cfg.policy,
            summary: RunSummary::new(task.spec(), &cfg, &r, f64::NAN),
            curve: binned_curve(&r, o.seconds, curve_bin_s(task.spec())),
        });
    }
    let env_steps = configs.iter().map(|c| c.summary.env_steps).sum();
    Ok(LeoResults {
        options: *o,
        configs,
        switched,
        env_steps,
    })
}
