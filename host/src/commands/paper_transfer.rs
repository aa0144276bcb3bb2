//! `pada paper transfer`: learn in simulation, finish on the robot —
//! the measurement of [`crate::paper::transfer`] on the physical pendulum
//! and robots of files, its report, data and figure in one directory.

use crate::commands::options::{check_seconds, set_threads};
use crate::commands::paper_args::PaperArgs;
use crate::console::outln;
use crate::error::{usage, CliError};
use crate::experiment::algo::{policy_kind_of, Algo, PolicyFlags};
use crate::output::OutDir;
use crate::paper::transfer::{expected_steps, measure, RobotTransfer, Start, TransferOptions, OBJECTIVE_SHARE};
use crate::progress::steps_bar;
use pada_sim::variation::{physical_pendulum_ranges, PlantRanges, Vary};
use std::fmt::Write as _;
use std::path::PathBuf;

/// Learning time on the plant of the physical pendulum \[s\] (its task's).
const PENDULUM_SECONDS: f64 = 1500.0;
/// Learning time on the plant of a robot of files \[s\] (the example
/// arm's measure.sh).
const ROBOT_SECONDS: f64 = 1200.0;
/// Trials of each way.
const TRIALS: u32 = 10;

/// Runs `pada paper transfer`.
pub fn run(args: PaperArgs) -> Result<(), CliError> {
    let robots: Vec<PathBuf> = if args.robots.is_empty() {
        vec!["examples/robots/arm2/robot.toml".into(), "examples/robots/arm3/robot.toml".into()]
    } else {
        args.robots.clone()
    };
    let files = robots
        .iter()
        .map(|p| pada_robot_file::load(p).map_err(|e| usage(e.to_string())))
        .collect::<Result<Vec<_>, _>>()?;
    let out = OutDir::check(&args.out.clone().unwrap_or_else(|| "pada-out/paper-transfer".into()))?;
    set_threads(args.trial.threads)?;
    let policy = policy_kind_of(Algo::Pada, &PolicyFlags::default()).map_err(|e| usage(e.0))?;
    let trials = args.trials.unwrap_or(TRIALS);
    let options = |seconds: f64| -> Result<TransferOptions, CliError> {
        let seconds = check_seconds("--seconds", args.seconds.unwrap_or(seconds))?;
        let pretrain_seconds = check_seconds("--pretrain-seconds", args.pretrain_seconds.unwrap_or(seconds))?;
        Ok(TransferOptions { trials, seconds, pretrain_seconds, seed: args.trial.seed, policy })
    };
    let mut results = Vec::new();
    results.push(one(&crate::pendulum::PhysicalPendulumTask::default(), physical_pendulum_ranges(), &options(PENDULUM_SECONDS)?)?);
    for f in &files {
        let ranges = crate::commands::plant_args::with_ranges_arg(f.plant, args.plant_ranges.as_deref())?;
        if ranges.is_model() {
            return Err(usage(format!("{}: its [plant] states no range: the robot would be its model", f.path.display())));
        }
        let task = pada_sim::urdf::UrdfTask::new(f).map_err(|e| usage(e.to_string()))?;
        results.push(one(&task, ranges, &options(ROBOT_SECONDS)?)?);
    }
    let mut command = format!("pada paper transfer --seed {} --trials {trials}", args.trial.seed);
    for r in &args.robots {
        command += &format!(" --robot {}", r.display());
    }
    if let Some(s) = args.seconds {
        command += &format!(" --seconds {s}");
    }
    if let Some(s) = args.pretrain_seconds {
        command += &format!(" --pretrain-seconds {s}");
    }
    if let Some(r) = &args.plant_ranges {
        command += &format!(" --plant-ranges {r}");
    }
    let report = render(&results, &command);
    let json = serde_json::to_string_pretty(&results).map_err(anyhow::Error::from)? + "\n";
    out.write_all(&[("report.md".to_string(), report.clone().into_bytes()), ("summary.json".to_string(), json.into_bytes())])?;
    crate::plot::save(&crate::plot::transfer::TransferFigure { robots: &results }, out.path(), "transfer")?;
    outln!("{report}")?;
    outln!("wrote {}", out.path().display())?;
    Ok(())
}

/// One robot's measurement, with a progress bar.
fn one<T: Vary + Clone>(task: &T, ranges: PlantRanges, o: &TransferOptions) -> Result<RobotTransfer, CliError> {
    let bar = steps_bar(expected_steps(task, o), &format!("{}: transfer", task.spec().name));
    let r = measure(task, ranges, o, &|n| bar.inc(n)).map_err(|e| usage(format!("{e:#}")))?;
    bar.finish_and_clear();
    Ok(r)
}

/// `x ± ci` in `digits` decimals (or in scientific notation when small).
fn est(e: &crate::stats::Estimate) -> String {
    let ci = if e.ci95.is_finite() { e.ci95 } else { 0.0 };
    let a = e.mean.abs();
    if e.mean == 0.0 && ci == 0.0 {
        "0".into()
    } else if a < 0.01 || a >= 1e5 {
        format!("{:.2e} ± {:.1e}", e.mean, ci)
    } else if a >= 10.0 {
        format!("{:.1} ± {:.1}", e.mean, ci)
    } else {
        format!("{:.3} ± {:.3}", e.mean, ci)
    }
}

/// The report: per robot, its ranges, objective and the three ways.
pub fn render(results: &[RobotTransfer], command: &str) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "# Learn in simulation, finish on the robot\n\n`{command}`\n");
    let _ = writeln!(
        s,
        "Every trial learns with PADA (Δ = 0.5) on a plant drawn within the robot's ranges, one plant per trial; \
         trial i of every way meets the same plant and explores the same way. The objective: a greedy test return \
         covering {:.0} % of the way from the runs from nothing's mean first test return to their mean end performance. \
         Damage is the fatigue counter's cumulative damage of the most damaged gearbox (the paper's torques): the share \
         of the gearbox's MTBF spent. A trial that never reaches the objective counts its whole run. Means ± 95 % intervals.\n",
        OBJECTIVE_SHARE * 100.0
    );
    for r in results {
        let o = &r.options;
        let _ = writeln!(s, "## {}\n", r.robot);
        let _ = writeln!(
            s,
            "Plants within `{}`; {} trials of {} s on the plant, pretraining {} s; objective: test return ≥ {:.2}.\n",
            r.ranges.to_arg(),
            o.trials,
            o.seconds,
            o.pretrain_seconds,
            r.objective
        );
        let _ = writeln!(s, "| start | reached | damage until the objective | × less than from nothing | damage saved (paired) | physical damage | learning time [s] | failures | first test return | end performance | inside the objective | MTBF, 1200 actions [s] |");
        let _ = writeln!(s, "|---|---|---|---|---|---|---|---|---|---|---|---|");
        for w in &r.ways {
            let _ = writeln!(
                s,
                "| {} | {}/{} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} |",
                w.start.label(),
                w.reached,
                w.trials.len(),
                est(&w.damage),
                match (w.start, r.saving(w.start)) {
                    (Start::Nothing, _) => "1".to_string(),
                    (_, x) if x.is_finite() => format!("{x:.1}"),
                    _ => "∞ (none spent)".to_string(),
                },
                if w.start == Start::Nothing { "—".to_string() } else { est(&w.damage_saved) },
                est(&w.physical_damage),
                est(&w.time_s),
                est(&w.failures),
                est(&w.first_return),
                est(&w.end_performance),
                if w.end_inside_objective { "yes" } else { "**no**" },
                est(&w.mtbf_s),
            );
        }
        let _ = writeln!(s);
    }
    s
}
