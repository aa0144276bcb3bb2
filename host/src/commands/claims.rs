//! `pada claims`: what a trial writes. With `--robot FILE` or `--task
//! leo` and `--board B`, before flashing: the slots one host trial of the
//! robot writes against the board's claim table (`claims_demand`, which
//! the command line dispatches to).
//! Otherwise it reads the output directories of
//! `pada run --task leo` (their `summary.json` and the `claimed_slots`
//! column of each `trial-NNN.csv`, written for claim tables), prints the
//! slots claimed at chosen learning times and when each board's claim
//! table would pass nine tenths full, and draws `claims.svg` and
//! `claims.png`: claimed slots against learning time, one line per trial.

use crate::console::outln;
use crate::error::{usage, CliError};
use crate::experiment::algo::{label, policy_kind, Algo};
use crate::output::OutDir;
use crate::plot::claims::{Capacity, ClaimSeries, ClaimsFigure};
use clap::Args;
use pada_core::profile::Board;
use serde::Serialize;
use std::path::{Path, PathBuf};

/// `pada claims`.
#[derive(Debug, Clone, Args)]
pub struct ClaimsArgs {
    /// Output directories of `pada run` on a claim table, one per
    /// configuration (or none, with --robot or --task and --board).
    #[arg(value_name = "RUN_DIR", required_unless_present_any = ["robot", "task"])]
    pub runs: Vec<PathBuf>,
    /// Before flashing: a robot of your own (its robot.toml), whose demand
    /// a host trial measures (cached), against --board's claim table.
    #[arg(long, value_name = "robot.toml", conflicts_with_all = ["task", "runs"], requires = "board")]
    pub robot: Option<PathBuf>,
    /// Before flashing: one of pada's robots (leo) instead of --robot.
    #[arg(long, value_enum, conflicts_with = "runs", requires = "board")]
    pub task: Option<crate::experiment::tasks::TaskName>,
    /// With --robot or --task: the board whose claim table to check.
    #[arg(long, value_name = "NAME", value_parser = crate::robots::board_parser())]
    pub board: Option<Board>,
    /// With --robot or --task: the learner (default pada).
    #[arg(long, value_parser = crate::experiment::algo::algo_parser())]
    pub algo: Option<Algo>,
    /// With --algo pada (or another that takes Δ): its Δ (the default otherwise).
    #[arg(long)]
    pub delta: Option<f32>,
    /// With --robot or --task: the learning time [s] (the robot's default
    /// otherwise).
    #[arg(long, value_name = "S")]
    pub seconds: Option<f64>,
    /// With --robot or --task: the run's master seed.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Learning times to report the claimed slots at [s].
    #[arg(long, value_name = "S", value_delimiter = ',', default_values_t = [3600.0, 7333.0, 14666.0])]
    pub at: Vec<f64>,
    /// Where to write claims.svg, claims.png and claims.json.
    #[arg(long, value_name = "DIR", default_value = "pada-out/claims")]
    pub out: PathBuf,
    /// Print the result as JSON.
    #[arg(long)]
    pub json: bool,
}

/// One configuration's claims.
#[derive(Debug, Clone, Serialize)]
pub struct ConfigClaims {
    /// The run directory.
    pub run: String,
    /// The configuration, as `pada run` labels it.
    pub label: String,
    /// Trials read.
    pub trials: usize,
    /// Per time of `--at`: the time, the mean and the largest claimed
    /// slots over the trials (each trial's last test run at or before it;
    /// `None` past a trial's end).
    pub at: Vec<AtTime>,
    /// Per board with a fixed LEO table: the earliest learning time at
    /// which a trial had claimed nine tenths of it [s] (`None`: never).
    pub nine_tenths_full_s: Vec<(String, Option<f64>)>,
}

/// Claimed slots at one learning time.
#[derive(Debug, Clone, Serialize)]
pub struct AtTime {
    /// Learning time [s].
    pub learning_time_s: f64,
    /// Mean over the trials that reached it.
    pub mean: Option<f64>,
    /// Largest.
    pub max: Option<u32>,
}

/// A trial's (learning time, claimed slots) at each test run.
fn trial_curve(path: &Path) -> Result<Vec<(f64, u32)>, CliError> {
    let bad = |e: String| usage(format!("{}: {e}", path.display()));
    let mut r = csv::Reader::from_path(path).map_err(|e| bad(e.to_string()))?;
    let headers = r.headers().map_err(|e| bad(e.to_string()))?.clone();
    let col = |name: &str| headers.iter().position(|h| h == name);
    let (Some(t), Some(c)) = (col("learning_time_s"), col("claimed_slots")) else {
        return Err(bad("no learning_time_s and claimed_slots columns (a run on a claim table writes them)".into()));
    };
    let mut out = Vec::new();
    for (i, row) in r.records().enumerate() {
        let row = row.map_err(|e| bad(e.to_string()))?;
        let parse_err = |what: &str| bad(format!("row {}: {what} is not a number", i + 2));
        let time: f64 = row.get(t).and_then(|v| v.parse().ok()).ok_or_else(|| parse_err("learning_time_s"))?;
        let claimed: u32 = row.get(c).and_then(|v| v.parse().ok()).ok_or_else(|| parse_err("claimed_slots"))?;
        out.push((time, claimed));
    }
    Ok(out)
}

/// The run's label from its `summary.json`.
fn run_label(dir: &Path) -> Result<(Algo, String), CliError> {
    let path = dir.join("summary.json");
    let bad = |e: String| usage(format!("{}: {e}", path.display()));
    let text = std::fs::read_to_string(&path).map_err(|e| bad(format!("cannot read it ({e}); is {} a `pada run` output?", dir.display())))?;
    let v: serde_json::Value = serde_json::from_str(&text).map_err(|e| bad(e.to_string()))?;
    let name = v["algo"].as_str().ok_or_else(|| bad("no \"algo\"".into()))?;
    let algo = Algo::from_name(name).ok_or_else(|| bad(format!("unknown algo {name:?}")))?;
    let param = |k: &str| v["parameters"][k].as_f64().map(|x| x as f32);
    let kind = policy_kind(algo, param("alpha"), param("delta")).map_err(|e| bad(e.to_string()))?;
    Ok((algo, label(&kind)))
}

/// The claimed slots of the last point at or before `t` (`None` if the
/// curve ends before `t` minus one test interval's slack).
fn at_time(curve: &[(f64, u32)], t: f64) -> Option<u32> {
    let end = curve.last()?.0;
    if end + 200.0 < t {
        return None;
    }
    curve.iter().take_while(|p| p.0 <= t).last().map(|p| p.1)
}

/// Runs `pada claims`.
pub fn run(args: ClaimsArgs) -> Result<(), CliError> {
    if let Some(t) = args.at.iter().find(|t| !(t.is_finite() && **t >= 0.0)) {
        return Err(usage(format!("--at {t} is out of range: valid is a learning time >= 0 s")));
    }
    let boards: Vec<(String, f64)> = [Board::F405, Board::F429Sdram]
        .into_iter()
        .filter_map(|b| b.profile(&pada_core::robot::leo::SPEC).ok()?.weights().map(|n| (b.name().to_string(), n as f64)))
        .collect();
    let mut series = Vec::new();
    let mut results = Vec::new();
    for dir in &args.runs {
        let (algo, label) = run_label(dir)?;
        let mut files: Vec<PathBuf> = std::fs::read_dir(dir)
            .map_err(|e| usage(format!("{}: {e}", dir.display())))?
            .filter_map(|e| e.ok().map(|e| e.path()))
            .filter(|p| p.file_name().and_then(|n| n.to_str()).is_some_and(|n| n.starts_with("trial-") && n.ends_with(".csv")))
            .collect();
        files.sort();
        if files.is_empty() {
            return Err(usage(format!("{}: no trial-NNN.csv", dir.display())));
        }
        let curves = files.iter().map(|f| trial_curve(f)).collect::<Result<Vec<_>, _>>()?;
        let at = args
            .at
            .iter()
            .map(|&t| {
                let vals: Vec<u32> = curves.iter().filter_map(|c| at_time(c, t)).collect();
                AtTime {
                    learning_time_s: t,
                    mean: (!vals.is_empty()).then(|| vals.iter().map(|&v| v as f64).sum::<f64>() / vals.len() as f64),
                    max: vals.iter().copied().max(),
                }
            })
            .collect();
        let nine_tenths_full_s = boards
            .iter()
            .map(|(name, slots)| {
                let t = curves
                    .iter()
                    .filter_map(|c| c.iter().find(|p| p.1 as f64 >= 0.9 * slots).map(|p| p.0))
                    .fold(None, |m: Option<f64>, t| Some(m.map_or(t, |m| m.min(t))));
                (name.clone(), t)
            })
            .collect();
        series.push(ClaimSeries {
            label: label.clone(),
            algo,
            trials: curves.iter().map(|c| c.iter().map(|&(t, n)| (t, n as f64)).collect()).collect(),
        });
        results.push(ConfigClaims { run: dir.display().to_string(), label, trials: curves.len(), at, nine_tenths_full_s });
    }
    let out = OutDir::check(&args.out)?;
    let figure = ClaimsFigure {
        title: "LEO: claim-table slots a trial writes".into(),
        series,
        capacities: boards
            .iter()
            .filter(|(_, slots)| *slots >= 1e5)
            .map(|(name, slots)| Capacity { label: format!("{name}'s table: {} slots", *slots as u64), slots: *slots })
            .collect(),
    };
    let json = serde_json::to_string_pretty(&results).map_err(|e| usage(e.to_string()))?;
    let svg = crate::plot::to_svg(&figure).map_err(|e| usage(format!("drawing the figure: {e}")))?;
    let png = crate::plot::svg_to_png(&svg).map_err(|e| usage(format!("drawing the figure: {e}")))?;
    out.write_all(&[
        ("claims.json".to_string(), json.clone().into_bytes()),
        ("claims.svg".to_string(), svg.into_bytes()),
        ("claims.png".to_string(), png),
    ])?;
    if args.json {
        outln!("{json}")?;
        return Ok(());
    }
    let mut head = format!("{:<24} {:>6}", "configuration", "trials");
    for t in &args.at {
        head += &format!(" {:>20}", format!("claimed at {t:.0} s"));
    }
    for (name, _) in &boards {
        head += &format!(" {:>18}", format!("{name} 90 % at"));
    }
    outln!("{head}")?;
    for r in &results {
        let mut line = format!("{:<24} {:>6}", r.label, r.trials);
        for a in &r.at {
            let cell = match (a.mean, a.max) {
                (Some(m), Some(x)) => format!("{:.2} M (max {:.2})", m / 1e6, x as f64 / 1e6),
                _ => "—".into(),
            };
            line += &format!(" {cell:>20}");
        }
        for (_, t) in &r.nine_tenths_full_s {
            line += &format!(" {:>18}", t.map_or("never".into(), |t| format!("{t:.0} s")));
        }
        outln!("{line}")?;
    }
    outln!("wrote {}", out.path().display())?;
    Ok(())
}
