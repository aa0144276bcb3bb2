//! `pada paper wear`: learning on a wear budget, as data and as a report.
//! Every strategy — the paper's six, the four gentle explorations — over a
//! short parameter sweep, and the wear governor (`--mtbf-budget`) on PADA
//! and the low-pass filter at three budgets; end performance against both
//! MTBFs with the Pareto front, and the governor's hold.
//!
//! The sweep is data ([`sweep`]): a list of [`WearEntry`]s per task, made
//! into a plan [`Experiment`] so that `--plan`, `--merge` and `--slurm`
//! run it as they run `pada paper pendulum`.

use crate::experiment::algo::{algo_of, label, Algo, PolicyFlags};
use crate::experiment::task::{Task, TaskSpec};
use crate::experiment::tasks::{visit_task, TaskName, TaskVisitor};
use crate::experiment::{RunConfig, TrialResult};
use crate::paper::curves::{mean_curve, CurvePoint};
use crate::plan::{Experiment, ExperimentKind};
use crate::stats::Estimate;
use crate::summary::RunSummary;
use pada_core::policy::PolicyKind;
use serde::Serialize;
use std::fmt::Write as _;

/// SARSA(λ)'s MTBF on the simulated pendulum \[s\], measured by
/// `pada run --algo sarsa` (29 trials, seed 1: 1297 ± 18 s; README,
/// Section VII results). The governor's budgets are multiples of it.
pub const PENDULUM_SARSA_MTBF_S: f32 = 1297.0;
/// SARSA(λ)'s MTBF on the LEO model \[s\] (the paper's, from the commanded
/// voltage, the weakest gearbox), measured on the host's 2^24-weight
/// table by `pada run --task leo --algo sarsa --trials 15 --seconds 60`
/// (seed 1: 962 ± 70 s; the window is the first 1200 learning actions,
/// 40 s, so a minute of learning measures it; 892 ± 123 s on the 2^22
/// table).
pub const LEO_SARSA_MTBF_S: f32 = 962.0;
/// The budgets as multiples of SARSA(λ)'s MTBF: the target's 2× (the
/// paper's gentle learners double the MTBF), one easier, one harder.
pub const BUDGET_MULTIPLES: [f32; 3] = [1.5, 2.0, 3.0];

/// One configuration of the sweep.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WearEntry {
    /// The policy (for a governed one: its floor, where it starts).
    pub policy: PolicyKind,
    /// The governor's budget \[s\], if one runs.
    pub budget_s: Option<f32>,
}

/// The task's options.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WearOptions {
    /// `pendulum` or `leo`.
    pub task: TaskName,
    /// Trials per configuration.
    pub trials: u32,
    /// Learning time per trial \[s\].
    pub seconds: f64,
    /// Master seed.
    pub seed: u64,
}

fn kind(algo: Algo, flags: PolicyFlags) -> PolicyKind {
    // The sweep's values are in range (checked by a test), so this builds.
    crate::experiment::algo::policy_kind_of(algo, &flags).expect("the sweep's parameters are valid")
}

/// SARSA(λ)'s MTBF on `task`, the unit of the budgets.
pub fn sarsa_mtbf_s(task: TaskName) -> f32 {
    match task {
        TaskName::Leo => LEO_SARSA_MTBF_S,
        _ => PENDULUM_SARSA_MTBF_S,
    }
}

/// The budgets of `task` \[s\].
pub fn budgets(task: TaskName) -> [f32; 3] {
    BUDGET_MULTIPLES.map(|m| (m * sarsa_mtbf_s(task)).round())
}

/// The sweep of `task`: SARSA(λ) first, then each strategy over a few
/// parameters around the paper's choice, then the governor.
///
/// Why these values: the low-pass α around the paper's 0.834 (0.5–0.9, the
/// range where Section VII's end performance holds); Δ one and two levels
/// on LEO (7 levels: 1/6, 2/6, 3/6) and the one level there is on the
/// pendulum (3 levels: 0.5); OU at DDPG's θ = 0.15 with σ 0.2 and 0.4
/// (stationary deviation 0.38 and 0.77 of the range's half); pink noise at
/// the same two deviations; the action-change penalty from a tenth of the
/// task's torque cost to three times it.
pub fn sweep(task: TaskName) -> Vec<WearEntry> {
    let d = |delta| PolicyFlags { delta: Some(delta), ..PolicyFlags::default() };
    let a = |alpha| PolicyFlags { alpha: Some(alpha), ..PolicyFlags::default() };
    let fixed = |p| WearEntry { policy: p, budget_s: None };
    let deltas: &[f32] = match task {
        TaskName::Leo => &[1.0 / 6.0, 2.0 / 6.0, 0.5],
        _ => &[0.5],
    };
    let mut v = vec![fixed(PolicyKind::Sarsa)];
    for &alpha in &[0.5, 0.7, 0.834, 0.9] {
        v.push(fixed(kind(Algo::LowPass, a(alpha))));
    }
    v.push(fixed(kind(Algo::MarkovLowPass, a(0.834))));
    v.push(fixed(kind(Algo::Integrator, d(0.5))));
    v.push(fixed(kind(Algo::MarkovIntegrator, d(0.5))));
    for &delta in deltas {
        v.push(fixed(kind(Algo::Pada, d(delta))));
    }
    for &delta in deltas {
        v.push(fixed(kind(Algo::EpsilonPada, d(delta))));
    }
    for sigma in [0.2, 0.4] {
        v.push(fixed(kind(
            Algo::OrnsteinUhlenbeck,
            PolicyFlags { theta: Some(0.15), sigma: Some(sigma), ..PolicyFlags::default() },
        )));
    }
    for sigma in [0.38, 0.77] {
        v.push(fixed(kind(Algo::PinkNoise, PolicyFlags { sigma: Some(sigma), ..PolicyFlags::default() })));
    }
    for weight in [0.1, 1.0, 3.0] {
        v.push(fixed(kind(Algo::ActionPenalty, PolicyFlags { weight: Some(weight), ..PolicyFlags::default() })));
    }
    for algo in [Algo::Pada, Algo::LowPass] {
        for b in budgets(task) {
            // The floor's parameter; the governor sets the rung in force.
            let policy = kind(algo, PolicyFlags::default());
            v.push(WearEntry { policy, budget_s: Some(b) });
        }
    }
    v
}

/// The sweep as a plan experiment.
pub fn experiment(o: &WearOptions, command: String) -> Experiment {
    let configs: Vec<(TaskName, RunConfig)> = sweep(o.task)
        .into_iter()
        .map(|e| {
            (
                o.task,
                RunConfig {
                    policy: e.policy,
                    switch_at_s: None,
                    mtbf_budget_s: e.budget_s,
                    seconds: o.seconds,
                    trials: o.trials,
                    seed: o.seed,
                },
            )
        })
        .collect();
    Experiment::new(ExperimentKind::PaperWear, command, &configs)
}

struct SpecOf;

impl TaskVisitor for SpecOf {
    type Output = TaskSpec;
    fn visit<T: Task>(self, task: &T) -> TaskSpec {
        task.spec().clone()
    }
}

/// The task's description (for expected steps and summaries).
pub fn spec_of(task: TaskName) -> TaskSpec {
    visit_task(task, SpecOf)
}

/// Learning and test steps the sweep takes (for the progress bar).
pub fn expected_steps(o: &WearOptions, experiment: &Experiment) -> u64 {
    let spec = spec_of(o.task);
    experiment
        .configurations
        .iter()
        .filter_map(|c| c.run_config().ok())
        .map(|cfg| {
            cfg.trials as u64 * cfg.expected_steps(spec.control_period_s, spec.episode_steps, spec.test_interval)
        })
        .sum()
}

/// One configuration's results.
#[derive(Debug, Clone, Serialize)]
pub struct WearResult {
    /// A label: the strategy and its parameters, or the governor and its
    /// budget.
    pub label: String,
    /// The strategy (for a governed one: `pada` or `lowpass`).
    #[serde(skip)]
    pub algo: Algo,
    /// The policy.
    #[serde(skip)]
    pub policy: PolicyKind,
    /// The governor's budget \[s\], if one ran.
    pub budget_s: Option<f32>,
    /// The summary over trials.
    pub summary: RunSummary,
    /// Mean learning curve.
    #[serde(skip)]
    pub curve: Vec<CurvePoint>,
    /// On the Pareto front of end performance against the paper's MTBF.
    pub pareto: bool,
    /// On the Pareto front of end performance against the physical MTBF.
    pub pareto_physical: bool,
}

impl WearResult {
    /// The label of a configuration.
    pub fn label_of(policy: &PolicyKind, budget_s: Option<f32>) -> String {
        match budget_s {
            Some(b) => format!("{} governed, budget {b:.0} s", policy.name()),
            None => label(policy),
        }
    }
}

/// The whole experiment's results.
#[derive(Debug, Clone, Serialize)]
pub struct WearResults {
    /// The task.
    pub task: String,
    /// SARSA(λ)'s MTBF the budgets are multiples of \[s\].
    pub budget_unit_s: f32,
    /// Every configuration, in the sweep's order (SARSA(λ) first).
    pub configs: Vec<WearResult>,
}

/// Indices of the configurations on the Pareto front of (mean MTBF, mean
/// end performance), both larger better: those no other configuration
/// beats in one while at least matching it in the other.
pub fn pareto_front(points: &[(f64, f64)]) -> Vec<bool> {
    let finite = |x: f64| if x.is_nan() { f64::NEG_INFINITY } else { x };
    points
        .iter()
        .map(|&(m, e)| {
            let (m, e) = (finite(m), finite(e));
            !points.iter().any(|&(m2, e2)| {
                let (m2, e2) = (finite(m2), finite(e2));
                (m2 >= m && e2 >= e) && (m2 > m || e2 > e)
            })
        })
        .collect()
}

/// The results from every configuration's trials, in [`experiment`]'s
/// order, however they were run.
pub fn assemble(o: &WearOptions, experiment: &Experiment, per_config: Vec<Vec<TrialResult>>) -> anyhow::Result<WearResults> {
    anyhow::ensure!(
        per_config.len() == experiment.configurations.len(),
        "the wear sweep has {} configurations, not {}",
        experiment.configurations.len(),
        per_config.len()
    );
    let spec = spec_of(o.task);
    let mut configs = Vec::with_capacity(per_config.len());
    for (c, results) in experiment.configurations.iter().zip(per_config) {
        let cfg = c.run_config()?;
        configs.push(WearResult {
            label: WearResult::label_of(&cfg.policy, cfg.mtbf_budget_s),
            algo: algo_of(&cfg.policy),
            policy: cfg.policy,
            budget_s: cfg.mtbf_budget_s,
            summary: RunSummary::new(&spec, &cfg, &results, f64::NAN),
            curve: mean_curve(&results),
            pareto: false,
            pareto_physical: false,
        });
    }
    let paper: Vec<(f64, f64)> =
        configs.iter().map(|c| (c.summary.mtbf_s.mean, c.summary.end_performance.mean)).collect();
    let physical: Vec<(f64, f64)> =
        configs.iter().map(|c| (c.summary.physical_mtbf_s.mean, c.summary.end_performance.mean)).collect();
    for (c, (p, q)) in configs.iter_mut().zip(pareto_front(&paper).into_iter().zip(pareto_front(&physical))) {
        c.pareto = p;
        c.pareto_physical = q;
    }
    Ok(WearResults { task: o.task.to_string(), budget_unit_s: sarsa_mtbf_s(o.task), configs })
}

fn est(e: &Estimate, digits: usize) -> String {
    crate::display::fmt_estimate(e.mean, e.ci95, digits, "")
}

/// Whether two 95 % intervals overlap (a NaN interval, from one trial,
/// counts as the point).
fn overlap(a: &Estimate, b: &Estimate) -> bool {
    let h = |e: &Estimate| if e.ci95.is_finite() { e.ci95 } else { 0.0 };
    (a.mean - b.mean).abs() <= h(a) + h(b)
}

/// The parameters of a configuration, as the table shows them.
fn parameters(c: &WearResult) -> String {
    if let Some(b) = c.budget_s {
        let g = c.summary.governor.as_ref();
        let sym = if c.algo.takes_alpha() { "α" } else { "Δ" };
        return match g {
            Some(g) => format!("budget {b:.0} s; mean {sym} {}", est(&g.mean_parameter, 3)),
            None => format!("budget {b:.0} s"),
        };
    }
    let names = c.algo.parameter_names();
    let values = c.policy.parameters();
    if names.is_empty() {
        return "–".into();
    }
    names.iter().zip(values).map(|(n, v)| format!("{n} {v:.3}")).collect::<Vec<_>>().join(", ")
}

/// report.md: it depends only on the command (the wall time and threads
/// are in timing.json), as `pada paper pendulum`'s.
pub fn render(r: &WearResults, command: &str) -> String {
    let mut s = String::new();
    let sarsa = &r.configs[0].summary;
    let _ = writeln!(s, "# Learning on a wear budget ({})\n", r.task);
    let _ = writeln!(s, "Command: `{command}`\n");
    let _ = writeln!(
        s,
        "Every strategy over a short sweep and the wear governor (`--mtbf-budget`) on PADA and the \
         low-pass filter at {} s ({}× the SARSA(λ) MTBF of {:.0} s the budgets are set from; this \
         run's SARSA(λ): {}). MTBF is the predicted MTBF over the first 1200 learning actions: the \
         paper's from the commanded torque (what the governor sees), the physical one from the \
         simulated gear torque. ± is the 95 % interval over {} trials.\n",
        budgets_text(r),
        BUDGET_MULTIPLES.map(|m| m.to_string()).join("×, "),
        r.budget_unit_s,
        crate::display::fmt_mtbf(sarsa.mtbf_s.mean, sarsa.mtbf_s.ci95),
        sarsa.trials
    );
    let _ = writeln!(
        s,
        "| strategy | parameters | MTBF [s] | physical MTBF [s] | end performance | rise time [s] | Pareto (paper / physical) | budget held |"
    );
    let _ = writeln!(s, "|---|---|---|---|---|---|---|---|");
    for c in &r.configs {
        let m = &c.summary;
        let held = match &m.governor {
            Some(g) => format!("{:.1} % ({:.1} % physical)", 100.0 * g.held_fraction, 100.0 * g.physical_held_fraction),
            None => "–".into(),
        };
        let strategy = match c.budget_s {
            Some(_) => format!("{} + governor", c.algo),
            None => c.algo.to_string(),
        };
        let _ = writeln!(
            s,
            "| {strategy} | {} | {} | {} | {} | {} | {} / {} | {held} |",
            parameters(c),
            est(&m.mtbf_s, 0),
            est(&m.physical_mtbf_s, 0),
            est(&m.end_performance, 0),
            est(&m.rise_time_s, 0),
            if c.pareto { "**yes**" } else { "no" },
            if c.pareto_physical { "**yes**" } else { "no" },
        );
    }
    let _ = writeln!(s);
    dominance(&mut s, r, false);
    dominance(&mut s, r, true);
    targets(&mut s, r);
    s
}

fn budgets_text(r: &WearResults) -> String {
    let mut b: Vec<f32> = r.configs.iter().filter_map(|c| c.budget_s).collect();
    b.sort_by(f32::total_cmp);
    b.dedup();
    b.iter().map(|x| format!("{x:.0}")).collect::<Vec<_>>().join(", ")
}

/// Which strategy dominates where: the Pareto front from the highest end
/// performance to the highest MTBF, each with the MTBF range where it is
/// the best and whether its end performance is distinguishable from the
/// next point's.
fn dominance(s: &mut String, r: &WearResults, physical: bool) {
    let mtbf = |c: &WearResult| if physical { c.summary.physical_mtbf_s } else { c.summary.mtbf_s };
    let mut front: Vec<&WearResult> =
        r.configs.iter().filter(|c| if physical { c.pareto_physical } else { c.pareto }).collect();
    front.sort_by(|a, b| mtbf(a).mean.total_cmp(&mtbf(b).mean));
    let _ = writeln!(
        s,
        "## Pareto front, end performance against the {} MTBF\n",
        if physical { "physical" } else { "paper's" }
    );
    let _ = writeln!(s, "From the highest end performance to the highest MTBF; a point is the best end performance for any MTBF requirement up to its own.\n");
    for (i, c) in front.iter().enumerate() {
        let lo = if i == 0 { 0.0 } else { mtbf(front[i - 1]).mean };
        let next = front.get(i + 1);
        let distinct = match next {
            Some(n) if overlap(&c.summary.end_performance, &n.summary.end_performance) => {
                format!("; its end performance is **not distinguishable** within the 95 % intervals from the next point's ({})", n.label)
            }
            Some(n) => format!("; above the next point's ({}, {}) beyond the intervals", n.label, est(&n.summary.end_performance, 0)),
            None => String::new(),
        };
        let _ = writeln!(
            s,
            "- MTBF {lo:.0}–{:.0} s: **{}**, end performance {}, MTBF {}{distinct}.",
            mtbf(c).mean,
            c.label,
            est(&c.summary.end_performance, 0),
            est(&mtbf(c), 0),
        );
    }
    let _ = writeln!(s);
}

/// The targets: the governor at 2× SARSA's MTBF against the best
/// fixed Δ (and α), and the hold.
fn targets(s: &mut String, r: &WearResults) {
    let _ = writeln!(s, "## The governor's targets\n");
    let two = (2.0 * r.budget_unit_s).round();
    for (algo, sym) in [(Algo::Pada, "Δ"), (Algo::LowPass, "α")] {
        let fixed = r
            .configs
            .iter()
            .filter(|c| c.algo == algo && c.budget_s.is_none())
            .max_by(|a, b| a.summary.end_performance.mean.total_cmp(&b.summary.end_performance.mean));
        let governed = r.configs.iter().find(|c| c.algo == algo && c.budget_s == Some(two));
        if let (Some(f), Some(g)) = (fixed, governed) {
            let verdict = if overlap(&f.summary.end_performance, &g.summary.end_performance) {
                "matches it within the 95 % intervals"
            } else if g.summary.end_performance.mean > f.summary.end_performance.mean {
                "is above it beyond the intervals"
            } else {
                "is **below** it beyond the intervals"
            };
            let _ = writeln!(
                s,
                "- {algo} at a budget of {two:.0} s (2× SARSA(λ)): end performance {} against the best fixed {sym}'s ({}, {}): it {verdict}.",
                est(&g.summary.end_performance, 0),
                f.label,
                est(&f.summary.end_performance, 0),
            );
        }
    }
    for c in r.configs.iter().filter(|c| c.budget_s.is_some()) {
        if let Some(g) = &c.summary.governor {
            let n = c.summary.trials;
            let held = (g.held_fraction * n as f64).round() as u32;
            let _ = writeln!(
                s,
                "- {}: held in {held}/{n} trials ({:.1} %, target ≥ 90 %: {}), MTBF {}, {:.0} % of learning actions at the floor, {:.0} moves per trial.",
                c.label,
                100.0 * g.held_fraction,
                if g.held_fraction >= 0.9 { "met" } else { "**missed**" },
                est(&c.summary.mtbf_s, 0),
                100.0 * g.floor_fraction.mean,
                g.moves.mean
            );
        }
    }
    let floor_note = if r.task == TaskName::Leo.to_string() {
        "PADA's floor on LEO is Δ = 1/6 (one of 7 levels) and the filter's α = 0.1."
    } else {
        "On the pendulum PADA has three levels, so its only restriction is Δ = 0.5 (one level), \
         whose own MTBF varies from trial to trial about its mean (2796 ± 68 s, below 2594 s in \
         3 of 29 trials)."
    };
    let _ = writeln!(
        s,
        "\nA budget above what the governor's floor itself holds cannot be held: the governor then \
         stays at the floor and counts the actions over budget. {floor_note}\n"
    );
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_sweep_builds_and_comes_back_from_its_plan_form() {
        for task in [TaskName::Pendulum, TaskName::Leo] {
            let o = WearOptions { task, trials: 2, seconds: 60.0, seed: 3 };
            let e = experiment(&o, "x".into());
            assert_eq!(e.configurations.len(), sweep(task).len());
            for (c, entry) in e.configurations.iter().zip(sweep(task)) {
                let cfg = c.run_config().unwrap();
                assert_eq!((cfg.policy, cfg.mtbf_budget_s), (entry.policy, entry.budget_s), "{}", c.label);
            }
            assert_eq!(e.configurations.iter().filter(|c| c.mtbf_budget_s.is_some()).count(), 6);
        }
        assert_eq!(budgets(TaskName::Pendulum), [1946.0, 2594.0, 3891.0]);
    }

    #[test]
    fn the_pareto_front_keeps_what_nothing_beats_in_both() {
        let p = [(1.0, 5.0), (2.0, 4.0), (2.0, 3.0), (3.0, 1.0), (0.5, 5.0), (f64::INFINITY, f64::NAN)];
        assert_eq!(pareto_front(&p), [true, true, false, true, false, true]);
    }
}
