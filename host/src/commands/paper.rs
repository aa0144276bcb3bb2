//! `pada paper pendulum`: the whole of Section VII — data, report.md and
//! the figures — in one directory.

use crate::console::outln;
use crate::commands::options::{check_seconds, set_threads};
pub use crate::commands::paper_args::{PaperArgs, PaperExperiment, WearTask};
use crate::error::CliError;
use crate::experiment::algo::{algo_of, parameter_of};
use crate::output::OutDir;
use crate::paper::figure_data::{curves, point};
use crate::paper::numbers::{PHYS_TRIALS, SIM_TRIALS};
use crate::paper::pendulum::{self, ConfigResult, PendulumOptions, PendulumResults};
use crate::paper::report;
use crate::plan::mode::obtain_with_bar;
use crate::plot::figures::{LearningCurves, Measure, MtbfSweep, PerformanceVsMtbf, SweepPoint};
use crate::plot::save;
use crate::timing::RunTiming;


/// Runs `pada paper`.
pub fn run(args: PaperArgs) -> Result<(), CliError> {
    if args.task.is_some() && args.experiment != PaperExperiment::Wear {
        return Err(crate::error::usage(
            "--task applies only to `pada paper wear` (pendulum or leo)",
        ));
    }
    match args.experiment {
        PaperExperiment::Pendulum => pendulum_cmd(args),
        PaperExperiment::Leo => super::paper_leo::run(args),
        PaperExperiment::Wear => super::paper_wear::run(args),
        PaperExperiment::Transfer => super::paper_transfer::run(args),
    }
}

fn pendulum_cmd(args: PaperArgs) -> Result<(), CliError> {
    let options = PendulumOptions {
        sim_trials: args.trials.unwrap_or(SIM_TRIALS),
        phys_trials: args.trials.unwrap_or(PHYS_TRIALS),
        sim_seconds: check_seconds("--seconds", args.seconds.unwrap_or(3000.0))?,
        phys_seconds: check_seconds("--physical-seconds", args.physical_seconds)?,
        seed: args.trial.seed,
    };
    let out = OutDir::check(
        &args
            .out
            .clone()
            .unwrap_or_else(|| "pada-out/paper-pendulum".into()),
    )?;
    let mode = args.cluster.mode(out.path())?;
    set_threads(args.trial.threads)?;

    let mut command = format!("pada paper pendulum --seed {}", options.seed);
    if let Some(t) = args.trials {
        command += &format!(" --trials {t}");
    }
    if options.sim_seconds != 3000.0 {
        command += &format!(" --seconds {}", options.sim_seconds);
    }
    if options.phys_seconds != 1500.0 {
        command += &format!(" --physical-seconds {}", options.phys_seconds);
    }
    let experiment = pendulum::experiment(&options, command.clone());
    let steps = pendulum::expected_steps(&options);
    let Some((per_config, timing)) =
        obtain_with_bar(&mode, &experiment, steps, "Section VII", |p| pendulum::run_local(&experiment, p))?
    else {
        return Ok(());
    };
    let results = pendulum::assemble(&options, &experiment, per_config)?;

    let report = report::render(&results, &command);
    let files = vec![
        ("report.md".to_string(), report.clone().into_bytes()),
        (
            "summary.json".to_string(),
            (serde_json::to_string_pretty(&results).map_err(anyhow::Error::from)? + "\n")
                .into_bytes(),
        ),
        (
            "simulated.csv".to_string(),
            configs_csv(&results.simulated)?,
        ),
        ("physical.csv".to_string(), configs_csv(&results.physical)?),
        ("timing.json".to_string(), timing.to_json()),
        (
            "physical-curves.csv".to_string(),
            curves_csv(&results.physical)?,
        ),
        (
            "simulated-curves.csv".to_string(),
            curves_csv(&results.simulated)?,
        ),
    ];
    out.write_all(&files)?;
    draw_figures(&results, &out)?;
    outln!("{}", headline(&results, &timing))?;
    outln!("wrote {}/report.md and the figures", out.path().display())?;
    Ok(())
}

/// A few lines for the terminal.
fn headline(r: &PendulumResults, t: &RunTiming) -> String {
    let s = &r.simulated[0].summary;
    format!(
        "SARSA(λ): end {:.0} ± {:.0} (paper −851 ± 39), rise {:.0} ± {:.0} s (paper 681 ± 67), MTBF {:.0} ± {:.0} s (paper 1596 ± 34); {:.1} s wall, {}",
        s.end_performance.mean,
        s.end_performance.ci95,
        s.rise_time_s.mean,
        s.rise_time_s.ci95,
        s.mtbf_s.mean,
        s.mtbf_s.ci95,
        t.wall_s,
        t.workers()
    )
}

fn draw_figures(r: &PendulumResults, out: &OutDir) -> anyhow::Result<()> {
    let dir = out.path();
    let sarsa = &r.simulated[0].summary;
    let points: Vec<SweepPoint> = r.simulated.iter().map(point).collect();
    save(
        &MtbfSweep {
            title: "Fig. 3 — MTBF against α or Δ (simulated pendulum)".into(),
            points: points[1..].to_vec(),
            sarsa_mtbf_s: sarsa.mtbf_s,
        },
        dir,
        "fig3-mtbf",
    )?;
    for (measure, stem, title, threshold) in [
        (
            Measure::EndPerformance,
            "fig4-end-performance",
            "Fig. 4 — end performance against MTBF",
            r.objective.end_threshold,
        ),
        (
            Measure::RiseTime,
            "fig5-rise-time",
            "Fig. 5 — rise time against MTBF",
            r.objective.rise_threshold_s,
        ),
    ] {
        save(
            &PerformanceVsMtbf {
                title: format!("{title} (simulated pendulum)"),
                measure,
                points: points.clone(),
                threshold,
                sarsa_mtbf_s: sarsa.mtbf_s.mean,
            },
            dir,
            stem,
        )?;
    }
    let phys = &r.physical[0].summary;
    save(
        &LearningCurves {
            title: "Fig. 6 — learning curves, physical pendulum (model)".into(),
            curves: curves(&r.physical, |_| true),
            sarsa_end: phys.end_performance.mean,
            sarsa_rise_s: phys.rise_time_s.mean,
            switch_at_s: None,
        },
        dir,
        "fig6-physical-curves",
    )?;
    save(
        &LearningCurves {
            title: "Learning curves, simulated pendulum".into(),
            curves: curves(&r.simulated, |c| {
                let p = parameter_of(&c.policy);
                matches!(algo_of(&c.policy), crate::experiment::algo::Algo::Sarsa)
                    || (algo_of(&c.policy) == crate::experiment::algo::Algo::LowPass && p == Some(0.834))
                    || (algo_of(&c.policy) == crate::experiment::algo::Algo::Pada && p == Some(0.5))
            }),
            sarsa_end: sarsa.end_performance.mean,
            sarsa_rise_s: sarsa.rise_time_s.mean,
            switch_at_s: None,
        },
        dir,
        "fig6-simulated-curves",
    )?;
    Ok(())
}

/// One row per configuration.
fn configs_csv(cs: &[ConfigResult]) -> anyhow::Result<Vec<u8>> {
    let mut w = csv::Writer::from_writer(Vec::new());
    w.write_record([
        "algo",
        "parameter",
        "trials",
        "mtbf_s",
        "mtbf_ci95",
        "end_performance",
        "end_performance_ci95",
        "rise_time_s",
        "rise_time_ci95",
        "window_reengagements",
    ])?;
    for c in cs {
        let m = &c.summary;
        let row = crate::paper::csv_row::CsvRow::new()
            .cell(c.algo().name())
            .opt(parameter_of(&c.policy))
            .cell(m.trials)
            .estimate(&m.mtbf_s)
            .estimate(&m.end_performance)
            .estimate(&m.rise_time_s)
            .cell(m.window_reengagements.mean);
        w.write_record(row.cells())?;
    }
    w.into_inner().map_err(|e| anyhow::anyhow!("{e}"))
}

/// Mean learning curves, one row per (configuration, test run).
fn curves_csv(cs: &[ConfigResult]) -> anyhow::Result<Vec<u8>> {
    let mut w = csv::Writer::from_writer(Vec::new());
    w.write_record([
        "algo",
        "parameter",
        "test_run",
        "learning_time_s",
        "mean_return",
        "ci95",
    ])?;
    for c in cs {
        for (i, p) in c.curve.iter().enumerate() {
            w.write_record([
                c.algo().name().to_string(),
                parameter_of(&c.policy)
                    .map(|p| p.to_string())
                    .unwrap_or_default(),
                i.to_string(),
                p.learning_time_s.to_string(),
                p.mean.to_string(),
                p.ci95.to_string(),
            ])?;
        }
    }
    w.into_inner().map_err(|e| anyhow::anyhow!("{e}"))
}
