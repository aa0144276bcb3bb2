//! Section VII from one call: the SARSA(λ) baseline and the sweeps of α
//! (low-pass, Markov low-pass) and Δ (integrator, Markov integrator, PADA)
//! on the simulated pendulum, the objective check, and SARSA(λ), low-pass
//! α = 0.834 and PADA Δ = 0.5 on the physical pendulum's model.
//!
//! Sweep values (the paper plots its sweeps without listing the values):
//! α ∈ {0.1, 0.25, 0.5, 0.7, 0.834, 0.9}; integrator Δ ∈ {0.05, 0.1, 0.2,
//! 0.3, 0.5}; PADA Δ = 0.5. With three torque levels 1.5 N·m apart
//! (range 3 N·m), PADA's Δ < 0.5 would leave only the current torque
//! (the motor would never leave rest) and Δ = 1 allows every level, which
//! is SARSA(λ) itself, bit for bit (a test checks it): Δ = 0.5 is the only
//! value that restricts.

use crate::experiment::algo::{algo_of, Algo};
use crate::experiment::task::Task;
use crate::experiment::tasks::TaskName;
use crate::experiment::{RunConfig, TrialResult};
use crate::paper::curves::{mean_curve, CurvePoint};
use crate::paper::objective::{Objective, Verdict};
use crate::pendulum::{PhysicalPendulumTask, SimulatedPendulumTask};
use crate::plan::{Experiment, ExperimentKind};
use crate::summary::RunSummary;
use pada_core::policy::PolicyKind;
use serde::Serialize;

/// Low-pass α values of the sweep.
pub const LOWPASS_ALPHAS: [f32; 6] = [0.1, 0.25, 0.5, 0.7, 0.834, 0.9];
/// Integrator Δ values of the sweep.
pub const INTEGRATOR_DELTAS: [f32; 5] = [0.05, 0.1, 0.2, 0.3, 0.5];
/// PADA Δ values of the sweep.
pub const PADA_DELTAS: [f32; 1] = [0.5];

/// How to run the experiments.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PendulumOptions {
    /// Trials per configuration on the simulated pendulum (paper: 29).
    pub sim_trials: u32,
    /// Trials per configuration on the physical pendulum (paper: 28).
    pub phys_trials: u32,
    /// Learning time per simulated-pendulum trial \[s\].
    pub sim_seconds: f64,
    /// Learning time per physical-pendulum trial \[s\].
    pub phys_seconds: f64,
    /// Master seed.
    pub seed: u64,
}

/// The result of one configuration.
#[derive(Debug, Clone, Serialize)]
pub struct ConfigResult {
    /// The policy and its parameter.
    #[serde(skip)]
    pub policy: PolicyKind,
    /// Its summary (per-configuration wall time is not measured: trials of
    /// all configurations share the pool).
    pub summary: RunSummary,
    /// The mean learning curve.
    #[serde(skip)]
    pub curve: Vec<CurvePoint>,
}

impl ConfigResult {
    /// The algorithm.
    pub fn algo(&self) -> Algo {
        algo_of(&self.policy)
    }
}

/// Everything `pada paper pendulum` measured: a function of the options
/// and the trials' results only (the run's wall time and threads are in
/// [`crate::timing::RunTiming`], so a merged run reports the same bytes).
#[derive(Debug, Clone, Serialize)]
pub struct PendulumResults {
    /// The options used.
    #[serde(skip)]
    pub options: PendulumOptions,
    /// Simulated pendulum, SARSA(λ) first, then the sweeps.
    pub simulated: Vec<ConfigResult>,
    /// The objective derived from the simulated SARSA(λ).
    pub objective: Objective,
    /// Verdicts, parallel to `simulated`.
    pub verdicts: Vec<Verdict>,
    /// Physical pendulum: SARSA(λ), low-pass α = 0.834, PADA Δ = 0.5.
    pub physical: Vec<ConfigResult>,
    /// Environment steps of everything.
    pub env_steps: u64,
}

/// The simulated-pendulum configurations, SARSA(λ) first.
pub fn simulated_policies() -> Vec<PolicyKind> {
    let mut p = vec![PolicyKind::Sarsa];
    p.extend(
        LOWPASS_ALPHAS
            .iter()
            .map(|&alpha| PolicyKind::LowPass { alpha }),
    );
    p.extend(
        LOWPASS_ALPHAS
            .iter()
            .map(|&alpha| PolicyKind::MarkovLowPass { alpha }),
    );
    p.extend(
        INTEGRATOR_DELTAS
            .iter()
            .map(|&delta| PolicyKind::Integrator { delta }),
    );
    p.extend(
        INTEGRATOR_DELTAS
            .iter()
            .map(|&delta| PolicyKind::MarkovIntegrator { delta }),
    );
    p.extend(PADA_DELTAS.iter().map(|&delta| PolicyKind::Pada { delta }));
    p
}

/// The physical-pendulum configurations of the paper's experiment.
pub fn physical_policies() -> Vec<PolicyKind> {
    vec![
        PolicyKind::Sarsa,
        PolicyKind::LowPass { alpha: 0.834 },
        PolicyKind::Pada { delta: 0.5 },
    ]
}

/// Environment steps the whole experiment takes (for a progress bar).
pub fn expected_steps(o: &PendulumOptions) -> u64 {
    fn steps<T: Task>(task: &T, configs: usize, trials: u32, seconds: f64) -> u64 {
        let s = task.spec();
        let cfg = RunConfig {
            policy: PolicyKind::Sarsa,
            switch_at_s: None,
            mtbf_budget_s: None,
            seconds,
            trials,
            seed: 0,
        };
        configs as u64
            * trials as u64
            * cfg.expected_steps(s.control_period_s, s.episode_steps, s.test_interval)
    }
    steps(
        &SimulatedPendulumTask::default(),
        simulated_policies().len(),
        o.sim_trials,
        o.sim_seconds,
    ) + steps(
        &PhysicalPendulumTask::default(),
        physical_policies().len(),
        o.phys_trials,
        o.phys_seconds,
    )
}

/// Section VII as an experiment: the simulated pendulum's configurations
/// (SARSA(λ) first), then the physical pendulum's. `command` is the command
/// line the report names.
pub fn experiment(o: &PendulumOptions, command: String) -> Experiment {
    let cfg = |policy, trials, seconds| RunConfig {
        policy,
        switch_at_s: None,
        mtbf_budget_s: None,
        seconds,
        trials,
        seed: o.seed,
    };
    let mut configs: Vec<(TaskName, RunConfig)> = simulated_policies()
        .into_iter()
        .map(|p| (TaskName::Pendulum, cfg(p, o.sim_trials, o.sim_seconds)))
        .collect();
    configs.extend(physical_policies().into_iter().map(|p| {
        (
            TaskName::PhysicalPendulum,
            cfg(p, o.phys_trials, o.phys_seconds),
        )
    }));
    Experiment::new(ExperimentKind::PaperPendulum, command, &configs)
}

/// Runs the whole of Section VII in this process: the trials of every
/// configuration of [`experiment`], per configuration.
pub fn run_local(
    experiment: &Experiment,
    progress: &(dyn Fn(u64) + Sync),
) -> anyhow::Result<Vec<Vec<TrialResult>>> {
    crate::plan::local::run_experiment(experiment, progress)
}

/// The results of Section VII from every configuration's trials (in
/// [`experiment`]'s order), however they were run.
pub fn assemble(
    o: &PendulumOptions,
    experiment: &Experiment,
    per_config: Vec<Vec<TrialResult>>,
) -> anyhow::Result<PendulumResults> {
    let n_sim = simulated_policies().len();
    anyhow::ensure!(
        per_config.len() == n_sim + physical_policies().len()
            && per_config.len() == experiment.configurations.len(),
        "Section VII has {} configurations, not {}",
        experiment.configurations.len(),
        per_config.len()
    );
    let sim_task = SimulatedPendulumTask::default();
    let phys_task = PhysicalPendulumTask::default();
    let mut simulated = Vec::with_capacity(n_sim);
    let mut physical = Vec::new();
    for (c, results) in experiment.configurations.iter().zip(per_config) {
        let cfg = c.run_config()?;
        let spec = if (c.index as usize) < n_sim {
            sim_task.spec()
        } else {
            phys_task.spec()
        };
        let r = ConfigResult {
            policy: cfg.policy,
            summary: RunSummary::new(spec, &cfg, &results, f64::NAN),
            curve: mean_curve(&results),
        };
        if (c.index as usize) < n_sim {
            simulated.push(r);
        } else {
            physical.push(r);
        }
    }
    let sarsa = &simulated[0].summary;
    let objective =
        Objective::from_sarsa(&sarsa.end_performance, &sarsa.rise_time_s, &sarsa.mtbf_s);
    let verdicts = simulated
        .iter()
        .map(|c| {
            objective.judge(
                &c.summary.end_performance,
                &c.summary.rise_time_s,
                &c.summary.mtbf_s,
            )
        })
        .collect();
    let env_steps = simulated
        .iter()
        .chain(&physical)
        .map(|c| c.summary.env_steps)
        .sum();
    Ok(PendulumResults {
        options: *o,
        simulated,
        objective,
        verdicts,
        physical,
        env_steps,
    })
}
