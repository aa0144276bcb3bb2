//! `pada paper wear [--task pendulum|leo]`: every strategy over a sweep and
//! the wear governor at three budgets ([`crate::paper::wear`]); report.md,
//! the Pareto figure against both MTBFs, learning curves and the data.

use crate::commands::options::{check_seconds, set_threads};
use crate::commands::paper_args::{PaperArgs, WearTask};
use crate::console::outln;
use crate::error::CliError;
use crate::experiment::algo::Algo;
use crate::experiment::tasks::TaskName;
use crate::output::OutDir;
use crate::paper::wear::{self, WearOptions, WearResult, WearResults};
use crate::plan::mode::obtain_with_bar;
use crate::plot::figures::{Curve, LearningCurves};
use crate::plot::save;
use crate::plot::wear::{WearPareto, WearPoint};

/// Default trials per configuration: the paper's 29 on the pendulum; 3 on
/// LEO (as `pada paper leo`: a LEO trial of an hour costs minutes).
pub const fn default_trials(task: TaskName) -> u32 {
    match task {
        TaskName::Leo => 3,
        _ => crate::paper::numbers::SIM_TRIALS,
    }
}

/// Default learning time per trial \[s\]: the pendulum's 3000 (Section
/// VII), LEO's 3600 (where PADA's walking first shows on the converged
/// model, README).
pub const fn default_seconds(task: TaskName) -> f64 {
    match task {
        TaskName::Leo => 3600.0,
        _ => 3000.0,
    }
}

/// Runs `pada paper wear`.
pub fn run(args: PaperArgs) -> Result<(), CliError> {
    let task = match args.task.unwrap_or(WearTask::Pendulum) {
        WearTask::Pendulum => TaskName::Pendulum,
        WearTask::Leo => TaskName::Leo,
    };
    let o = WearOptions {
        task,
        trials: args.trials.unwrap_or(default_trials(task)),
        seconds: check_seconds("--seconds", args.seconds.unwrap_or(default_seconds(task)))?,
        seed: args.trial.seed,
    };
    let out = OutDir::check(&args.out.clone().unwrap_or_else(|| format!("pada-out/paper-wear-{task}").into()))?;
    let mode = args.cluster.mode(out.path())?;
    set_threads(args.trial.threads)?;
    let command =
        format!("pada paper wear --task {task} --trials {} --seconds {} --seed {}", o.trials, o.seconds, o.seed);
    let experiment = wear::experiment(&o, command.clone());
    let steps = wear::expected_steps(&o, &experiment);
    let Some((per_config, timing)) = obtain_with_bar(&mode, &experiment, steps, "wear sweep", |p| {
        crate::plan::local::run_experiment(&experiment, p)
    })?
    else {
        return Ok(());
    };
    let r = wear::assemble(&o, &experiment, per_config)?;
    let report = wear::render(&r, &command);
    out.write_all(&[
        ("report.md".to_string(), report.into_bytes()),
        (
            "summary.json".to_string(),
            (serde_json::to_string_pretty(&r).map_err(anyhow::Error::from)? + "\n").into_bytes(),
        ),
        ("configurations.csv".to_string(), configs_csv(&r)?),
        ("timing.json".to_string(), timing.to_json()),
    ])?;
    draw(&r, &out)?;
    let governed: Vec<String> = r
        .configs
        .iter()
        .filter_map(|c| {
            let g = c.summary.governor.as_ref()?;
            Some(format!("{} {:.1} %", c.label, 100.0 * g.held_fraction))
        })
        .collect();
    outln!(
        "{} configurations × {} trials in {:.1} s wall ({}); budget held: {}",
        r.configs.len(),
        o.trials,
        timing.wall_s,
        timing.workers(),
        governed.join(", ")
    )?;
    outln!("wrote {}/report.md and the figures", out.path().display())?;
    Ok(())
}

fn draw(r: &WearResults, out: &OutDir) -> anyhow::Result<()> {
    let sarsa = &r.configs[0].summary;
    let points = r
        .configs
        .iter()
        .map(|c| WearPoint {
            algo: c.algo,
            governed: c.budget_s.is_some(),
            mtbf_s: c.summary.mtbf_s,
            physical_mtbf_s: c.summary.physical_mtbf_s,
            end: c.summary.end_performance,
            pareto: c.pareto,
            pareto_physical: c.pareto_physical,
        })
        .collect();
    save(
        &WearPareto {
            title: format!("End performance against MTBF ({}): every strategy and the wear governor", r.task),
            points,
            sarsa_mtbf_s: [sarsa.mtbf_s.mean, sarsa.physical_mtbf_s.mean],
        },
        out.path(),
        "wear-pareto",
    )?;
    // Curves: SARSA(λ), each strategy's best fixed configuration, and the
    // governor at 2× SARSA(λ)'s MTBF.
    let two = (2.0 * r.budget_unit_s).round();
    let mut picked: Vec<&WearResult> = vec![&r.configs[0]];
    for algo in Algo::ALL.iter().copied().filter(|a| *a != Algo::Sarsa) {
        let best = r
            .configs
            .iter()
            .filter(|c| c.algo == algo && c.budget_s.is_none())
            .max_by(|a, b| a.summary.end_performance.mean.total_cmp(&b.summary.end_performance.mean));
        picked.extend(best);
    }
    picked.extend(r.configs.iter().filter(|c| c.budget_s == Some(two)));
    save(
        &LearningCurves {
            title: format!("Learning curves ({}): best of each strategy, governor at {two:.0} s", r.task),
            curves: picked
                .iter()
                .map(|c| Curve { label: c.label.clone(), algo: c.algo, points: c.curve.clone() })
                .collect(),
            sarsa_end: sarsa.end_performance.mean,
            sarsa_rise_s: sarsa.rise_time_s.mean,
            switch_at_s: None,
        },
        out.path(),
        "wear-curves",
    )?;
    Ok(())
}

/// One row per configuration.
fn configs_csv(r: &WearResults) -> anyhow::Result<Vec<u8>> {
    let mut w = csv::Writer::from_writer(Vec::new());
    w.write_record([
        "label",
        "algo",
        "parameter",
        "parameter2",
        "mtbf_budget_s",
        "trials",
        "mtbf_s",
        "mtbf_ci95",
        "physical_mtbf_s",
        "physical_mtbf_ci95",
        "end_performance",
        "end_performance_ci95",
        "rise_time_s",
        "rise_time_ci95",
        "held_fraction",
        "mean_governed_parameter",
        "pareto",
        "pareto_physical",
    ])?;
    for c in &r.configs {
        let m = &c.summary;
        let names = c.algo.parameter_names().len();
        let p = c.policy.parameters();
        let row = crate::paper::csv_row::CsvRow::new()
            .cell(&c.label)
            .cell(c.algo.name())
            .opt((names > 0).then_some(p[0] as f64))
            .opt((names > 1).then_some(p[1] as f64))
            .opt(c.budget_s.map(f64::from))
            .cell(m.trials)
            .estimate(&m.mtbf_s)
            .estimate(&m.physical_mtbf_s)
            .estimate(&m.end_performance)
            .estimate(&m.rise_time_s)
            .opt(m.governor.as_ref().map(|g| g.held_fraction))
            .opt(m.governor.as_ref().map(|g| g.mean_parameter.mean))
            .cell(c.pareto)
            .cell(c.pareto_physical);
        w.write_record(row.cells())?;
    }
    w.into_inner().map_err(|e| anyhow::anyhow!("{e}"))
}
