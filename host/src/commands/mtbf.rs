//! `pada mtbf`: the fatigue counter (Eqs. 3–7, Table I) on a recorded
//! torque log, per joint: backlash re-engagements, damage J and predicted
//! MTBF, over the first N steps (the paper's window) and the whole log.

use crate::console::outln;
use crate::error::{usage, CliError};
use crate::torque_log;
use pada_core::fatigue::{FatigueReport, GearboxParams, JointFatigue};
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
    /// Print the result as JSON.
    #[arg(long)]
    pub json: bool,
}

/// One joint's figures.
#[derive(Debug, Clone, Serialize)]
pub struct JointMtbf {
    /// Joint name.
    pub joint: String,
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
    let period = 1.0 / args.rate;
    let mut joints = Vec::new();
    for (j, name) in log.joints.iter().enumerate() {
        let mut f = JointFatigue::new(&GearboxParams::TABLE_I, Some(args.window))
            .map_err(|e| usage(e.to_string()))?;
        for row in &log.rows {
            f.update(row[j]).map_err(|e| usage(e.to_string()))?;
        }
        joints.push(JointMtbf {
            joint: name.clone(),
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
    outln!(
        "{:<12} {:>10} {:>12} {:>14} {:>10} {:>12} {:>14}",
        "joint", "re-eng.", "J", "MTBF [s]", "re-eng.*", "J*", "MTBF* [s]"
    )?;
    for j in &joints {
        let r = &j.report;
        let w = r.window.as_ref();
        outln!(
            "{:<12} {:>10} {:>12.4e} {:>14} {:>10} {:>12.4e} {:>14}",
            j.joint,
            r.reengagements,
            r.damage,
            fmt_s(r.mtbf_s),
            w.map_or(0, |w| w.reengagements),
            w.map_or(0.0, |w| w.damage),
            fmt_s(w.map_or(f64::INFINITY, |w| w.mtbf_s))
        )?;
    }
    outln!("(* = first {} steps, the paper's MTBF window)", args.window)?;
    outln!(
        "robot MTBF (weakest joint): {} over the window, {} over the whole log",
        fmt_s(robot_window),
        fmt_s(robot)
    )?;
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
