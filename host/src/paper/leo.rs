//! Section VIII on LEO: SARSA(λ), PADA and the low-pass filter at a few Δ
//! and α, with and without switching back to SARSA(λ) at half the run, in
//! one call.
//!
//! Configurations (the paper names neither its Δ nor its α for LEO):
//! PADA Δ ∈ {1/6, 1/3} — with 7 levels 1/6 of the range apart, Δ = 1/6
//! allows the current level ±1, Δ = 1/3 ±2 —, low-pass α ∈ {0.2, 0.5};
//! each without and with the switch at half the learning time (the paper's
//! 7,333 s of 14,666 s).

use crate::experiment::{run_configs_keeping, FinishedTrial, HostAgent, RunConfig};
use crate::leo::rl::LeoTask;
use crate::paper::pendulum::{mean_curve, ConfigResult};
use crate::summary::RunSummary;
use crate::experiment::task::Task;
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

/// The results of Section VIII.
#[derive(Debug, Clone, Serialize)]
pub struct LeoResults {
    /// Options used.
    pub options: LeoOptions,
    /// One per configuration, in [`leo_configs`] order.
    pub configs: Vec<ConfigResult>,
    /// Whether each configuration switched, parallel to `configs`.
    pub switched: Vec<bool>,
    /// Wall time \[s\].
    pub wall_s: f64,
    /// Environment steps.
    pub env_steps: u64,
    /// Worker threads.
    pub threads: usize,
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

/// Runs Section VIII: every trial of every configuration in parallel.
/// Returns the results and the best trial's learner (`None` only when no
/// trial has a finite end performance).
pub fn run(o: &LeoOptions, progress: &(dyn Fn(u64) + Sync)) -> anyhow::Result<(LeoResults, Option<BestTrial>)> {
    let start = std::time::Instant::now();
    let task = LeoTask::default();
    let cfgs = run_configs_of(o);
    // Only the best learner so far is kept (16 MiB each), not all of them.
    let best: std::sync::Mutex<Option<BestTrial>> = std::sync::Mutex::new(None);
    let results = run_configs_keeping(&task, &cfgs, progress, &|f: FinishedTrial| {
        let e = f.result.end_performance;
        let mut b = best.lock().unwrap_or_else(|p| p.into_inner());
        if e.is_finite() && b.as_ref().is_none_or(|b| e > b.end_performance) {
            *b = Some(BestTrial { config: f.config, trial: f.trial, end_performance: e, switched: f.switched, agent: f.agent });
        }
    })?;
    let wall_s = start.elapsed().as_secs_f64();
    let configs: Vec<ConfigResult> = cfgs
        .iter()
        .zip(results)
        .map(|(cfg, r)| ConfigResult {
            policy: cfg.policy,
            summary: RunSummary::new(task.spec(), cfg, &r, f64::NAN),
            curve: mean_curve(&r),
        })
        .collect();
    let env_steps = configs.iter().map(|c| c.summary.env_steps).sum();
    let results = LeoResults {
        options: *o,
        switched: cfgs.iter().map(|c| c.switch_at_s.is_some()).collect(),
        configs,
        wall_s,
        env_steps,
        threads: rayon::current_num_threads(),
    };
    Ok((results, best.into_inner().unwrap_or_else(|p| p.into_inner())))
}
