//! `pada mtbf`: the fatigue counter (Eqs. 3–7) on a recorded torque log,
//! per joint: backlash re-engagements, damage J and predicted MTBF, over the
//! first N steps (the paper's window) and the whole log. Each joint's
//! gearbox is Table I's (the RX-28's) unless `--gearbox` names another from
//! pada's table or a file; every report names it and says when its geometry
//! is an estimate.

use crate::console::outln;
use crate::error::{usage, CliError};
use crate::torque_log;
use pada_robot_file::gearbox_file::{self, ChosenGearbox};
use pada_core::fatigue::{FatigueReport, JointFatigue};
use serde::Serialize;
use std::path::PathBuf;
use clap::Args;

/// `pada mtbf`.
#[derive(Debug, Clone, Args)]
pub struct MtbfArgs {
    /// CSV torque log [N·m], one column per joint, one row per control
    /// step; an optional header row names the joints.
    #[arg(long, value_name = "FILE.csv")]
    pub torques: PathBuf,
    /// Control rate of the log [Hz].
    #[arg(long, value_name = "HZ", default_value_t = 20.0)]
    pub rate: f64,
    /// MTBF window: the first N steps (the paper's 1200 actions).
    #[arg(long, value_name = "N", default_value_t = 1200, value_parser = clap::value_parser!(u32).range(1..))]
    pub window: u32,
    /// The gearbox of every joint: a name of pada's table (RX-28, MX-28,
    /// XM430-W350, XL430-W250, XL330-M288; case-insensitive) or a TOML file
    /// of the Table I fields (docs/reference/servos.md §4); or one per log
    /// column, separated by commas. Default: Table I (the RX-28).
    #[arg(long, value_name = "NAME|FILE[,...]")]
    pub gearbox: Option<String>,
    /// Print the result as JSON.
    #[arg(long)]
    pub json: bool,
}

/// One joint's figures.
#[derive(Debug, Clone, Serialize)]
pub struct JointMtbf {
    /// Joint name.
    pub joint: String,
    /// Its gearbox: name, source, whether an estimate, note.
    pub gearbox: ChosenGearbox,
    /// The fatigue counter's report (window and whole log).
    pub report: FatigueReport,
}

#[derive(Serialize)]
struct Output<'a> {
    file: String,
    rate_hz: f64,
    steps: usize,
    window_steps: u32,
    joints: &'a [JointMtbf],
    /// Smallest windowed MTBF over joints (the robot fails with its first gearbox).
    robot_window_mtbf_s: f64,
    robot_mtbf_s: f64,
    /// Whether any joint's gearbox geometry is an estimate.
    gearbox_estimate: bool,
}

/// Runs `pada mtbf`.
pub fn run(args: MtbfArgs) -> Result<(), CliError> {
    if !(args.rate.is_finite() && args.rate > 0.0 && args.rate <= 1e6) {
        return Err(usage(format!(
            "--rate {} is out of range: valid is 0 < rate <= 1000000 (Hz)",
            args.rate
        )));
    }
    let log = torque_log::read(&args.torques)?;
    let gearboxes = match &args.gearbox {
        Some(spec) => gearbox_file::resolve_list(spec, log.joints.len()).map_err(usage)?,
        None => vec![ChosenGearbox::table_i(); log.joints.len()],
    };
    let period = 1.0 / args.rate;
    let mut joints = Vec::new();
    for ((j, name), gearbox) in log.joints.iter().enumerate().zip(gearboxes) {
        let mut f = JointFatigue::new(&gearbox.params, Some(args.window))
            .map_err(|e| usage(e.to_string()))?;
        for row in &log.rows {
            f.update(row[j]).map_err(|e| usage(e.to_string()))?;
        }
        joints.push(JointMtbf {
            joint: name.clone(),
            gearbox,
            report: f.report(period),
        });
    }
    let robot_window = joints
        .iter()
        .filter_map(|j| j.report.window.map(|w| w.mtbf_s))
        .fold(f64::INFINITY, f64::min);
    let robot = joints
        .iter()
        .map(|j| j.report.mtbf_s)
        .fold(f64::INFINITY, f64::min);
    if args.json {
        let out = Output {
            file: args.torques.display().to_string(),
            rate_hz: args.rate,
            steps: log.rows.len(),
            window_steps: args.window,
            joints: &joints,
            robot_window_mtbf_s: robot_window,
            robot_mtbf_s: robot,
            gearbox_estimate: joints.iter().any(|j| j.gearbox.estimate),
        };
        outln!(
            "{}",
            serde_json::to_string_pretty(&out).map_err(anyhow::Error::from)?
        )?;
        return Ok(());
    }
    outln!(
        "{}: {} steps at {} Hz ({:.1} s), window of the first {} steps",
        args.torques.display(),
        log.rows.len(),
        args.rate,
        log.rows.len() as f64 * period,
        args.window
    )?;
    // The gearboxes, each once, in the log's order.
    let mut named: Vec<&ChosenGearbox> = Vec::new();
    for j in &joints {
        if !named.iter().any(|g| *g == &j.gearbox) {
            named.push(&j.gearbox);
        }
    }
    for g in &named {
        outln!("gearbox: {}", g.describe())?;
    }
    outln!(
        "{:<12} {:>10} {:>12} {:>14} {:>10} {:>12} {:>14}  {}",
        "joint", "re-eng.", "J", "MTBF [s]", "re-eng.*", "J*", "MTBF* [s]", "gearbox"
    )?;
    for j in &joints {
        let r = &j.report;
        let w = r.window.as_ref();
        outln!(
            "{:<12} {:>10} {:>12.4e} {:>14} {:>10} {:>12.4e} {:>14}  {}{}",
            j.joint,
            r.reengagements,
            r.damage,
            fmt_s(r.mtbf_s),
            w.map_or(0, |w| w.reengagements),
            w.map_or(0.0, |w| w.damage),
            fmt_s(w.map_or(f64::INFINITY, |w| w.mtbf_s)),
            j.gearbox.name,
            if j.gearbox.estimate { " (estimate)" } else { "" }
        )?;
    }
    outln!("(* = first {} steps, the paper's MTBF window)", args.window)?;
    outln!(
        "robot MTBF (weakest joint): {} over the window, {} over the whole log",
        fmt_s(robot_window),
        fmt_s(robot)
    )?;
    if joints.iter().any(|j| j.gearbox.estimate) {
        outln!("(estimate = the gearbox's last-gear geometry is estimated, not measured: so is this MTBF)")?;
    }
    Ok(())
}

fn fmt_s(s: f64) -> String {
    if !s.is_finite() {
        "inf".into()
    } else if s >= 1e6 {
        format!("{s:.4e}")
    } else {
        format!("{s:.1}")
    }
}
