//! `pada demo`: the README's main job — SARSA(λ) against PADA Δ = 0.5 on
//! the simulated pendulum of Section VII, next to the paper's numbers.

use crate::console::outln;
use crate::commands::options::{check_seconds, set_threads};
use crate::display::{fmt_estimate, fmt_mtbf};
use crate::error::CliError;
use crate::experiment::task::Task;
use crate::experiment::{run_configs, RunConfig};
use crate::output::OutDir;
use crate::paper::numbers::*;
use crate::stats::Estimate;
use crate::pendulum::SimulatedPendulumTask;
use crate::progress::steps_bar;
use crate::summary::{run_files, RunSummary};
use pada_core::policy::PolicyKind;
use std::time::Instant;
use crate::commands::options::TrialOptions;
use std::path::PathBuf;
use clap::Args;

/// `pada demo`.
#[derive(Debug, Clone, Args)]
pub struct DemoArgs {
    /// Trials per algorithm.
    #[arg(long, value_name = "N", default_value_t = 29, value_parser = clap::value_parser!(u32).range(1..=10000))]
    pub trials: u32,
    /// Learning time per trial [s].
    #[arg(long, value_name = "S", default_value_t = 3000.0)]
    pub seconds: f64,
    /// Also write both runs' summaries and curves under this directory.
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,
    /// Print both summaries as JSON on stdout.
    #[arg(long)]
    pub json: bool,
    /// Seed and threads.
    #[command(flatten)]
    pub trial: TrialOptions,
}

/// Runs `pada demo`.
pub fn run(args: DemoArgs) -> Result<(), CliError> {
    let seconds = check_seconds("--seconds", args.seconds)?;
    let out = args.out.as_deref().map(OutDir::check).transpose()?;
    set_threads(args.trial.threads)?;
    let task = SimulatedPendulumTask::default();
    let spec = task.spec();
    let cfgs: Vec<RunConfig> = [PolicyKind::Sarsa, PolicyKind::Pada { delta: 0.5 }]
        .into_iter()
        .map(|policy| RunConfig {
            policy,
            switch_at_s: None,
            mtbf_budget_s: None,
            seconds,
            trials: args.trials,
            seed: args.trial.seed,
        })
        .collect();
    let total: u64 = cfgs
        .iter()
        .map(|c| {
            c.trials as u64
                * c.expected_steps(
                    spec.control_period_s,
                    spec.episode_steps,
                    spec.test_interval,
                )
        })
        .sum();
    let bar = steps_bar(total, "SARSA vs PADA");
    let start = Instant::now();
    let results = run_configs(&task, &cfgs, &|n| bar.inc(n))?;
    let wall = start.elapsed().as_secs_f64();
    bar.finish_and_clear();
    let summaries: Vec<RunSummary> = cfgs
        .iter()
        .zip(&results)
        .map(|(c, r)| RunSummary::new(spec, c, r, wall))
        .collect();
    let env_steps: u64 = summaries.iter().map(|s| s.env_steps).sum();

    if let Some(out) = &out {
        let mut files = Vec::new();
        for s in &summaries {
            for (name, bytes) in run_files(s)? {
                files.push((format!("{}/{name}", s.algo), bytes));
            }
        }
        for s in &summaries {
            std::fs::create_dir_all(out.path().join(s.algo.name()))
                .map_err(|e| anyhow::anyhow!("cannot create {}: {e}", out.path().display()))?;
        }
        out.write_all(&files)?;
    }
    if args.json {
        let json =
            serde_json::json!({ "sarsa": summaries[0], "pada": summaries[1], "wall_s": wall });
        outln!(
            "{}",
            serde_json::to_string_pretty(&json).map_err(anyhow::Error::from)?
        )?;
        return Ok(());
    }
    let (s, p) = (&summaries[0], &summaries[1]);
    outln!(
        "Simulated pendulum of Section VII, {} trials × {} s of learning each (seed {}):\n",
        args.trials, seconds, args.trial.seed
    )?;
    let row = |label: &str, sarsa: String, pada: String, paper: String| {
        outln!("{label:<22} {sarsa:>18} {pada:>18} {paper:>18}")
    };
    let paper = |v: &Published, unit: &str| format!("{:.0} ± {:.0}{unit}", v.mean, v.ci95.unwrap_or(f64::NAN));
    row("", "SARSA(λ)".into(), "PADA Δ=0.5".into(), "paper SARSA(λ)".into())?;
    // Each measure as the paper writes it: returns, seconds, an MTBF.
    let e = |x: &Estimate| fmt_estimate(x.mean, x.ci95, 0, "");
    let r = |x: &Estimate| fmt_estimate(x.mean, x.ci95, 0, " s");
    let m = |x: &Estimate| fmt_mtbf(x.mean, x.ci95);
    row("end performance", e(&s.end_performance), e(&p.end_performance), paper(&SIM_SARSA_END, ""))?;
    row("rise time", r(&s.rise_time_s), r(&p.rise_time_s), paper(&SIM_SARSA_RISE_S, " s"))?;
    row("MTBF (1200 actions)", m(&s.mtbf_s), m(&p.mtbf_s), paper(&SIM_SARSA_MTBF_S, " s"))?;
    outln!(
        "{:<22} {:>18.0} {:>18.0} {:>18}",
        "re-engagements", s.window_reengagements.mean, p.window_reengagements.mean, "–"
    )?;
    outln!(
        "\nPADA's MTBF is {:.2}× SARSA(λ)'s (paper: about 2×). {:.1} s wall, {:.0} env steps/s on {} threads.",
        p.mtbf_s.mean / s.mtbf_s.mean,
        wall,
        env_steps as f64 / wall,
        s.threads
    )?;
    if let Some(out) = &out {
        outln!("wrote {}", out.path().display())?;
    }
    Ok(())
}
