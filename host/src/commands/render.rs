//! `pada render`: a learned LEO gait as a strip of stick figures (SVG and
//! PNG) and the trajectory as CSV, from weights saved by
//! `pada run --task leo --save-weights FILE`; or the learned motion of a
//! robot of files (`--robot`, [`crate::motion`]), with how well it holds
//! each target of its reward.

use crate::console::outln;
use crate::error::{usage, CliError};
use crate::experiment::task::Task;
use crate::experiment::tasks::TaskName;
use crate::gait::{gait_files, gait_title, record_agent, Frame};
use crate::leo::rl::LeoTask;
use crate::output::OutDir;
use std::path::PathBuf;
use clap::Args;

/// `pada render`.
#[derive(Debug, Clone, Args)]
pub struct RenderArgs {
    /// The task (only leo can be drawn; a robot of files with --robot).
    #[arg(long, value_enum, default_value_t = TaskName::Leo)]
    pub task: TaskName,
    /// A robot of your own: its robot.toml. Draws its poses and each
    /// distance reward's point against its target (motion.svg, motion.png,
    /// motion.csv) and says whether the point held within --hold-cm over
    /// the episode's last half.
    #[arg(long, value_name = "robot.toml", conflicts_with = "task")]
    pub robot: Option<PathBuf>,
    /// Weights saved by `pada run --save-weights`.
    #[arg(long, value_name = "FILE")]
    pub policy: PathBuf,
    /// Output directory (default: pada-out/render-leo, or
    /// pada-out/render-<robot>).
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,
    /// Seconds of the greedy episode to draw (default: 6, or a robot's
    /// episode).
    #[arg(long, value_name = "S")]
    pub seconds: Option<f64>,
    /// With --robot: the distance within which a point counts as held
    /// at its target [cm], 0 < cm <= 100.
    #[arg(long, value_name = "CM", default_value_t = 2.0)]
    pub hold_cm: f64,
    /// Frames in the strip.
    #[arg(long, value_name = "N", default_value_t = 12, value_parser = clap::value_parser!(u32).range(1..=200))]
    pub frames: u32,
}

/// Runs the greedy policy of the weights file for up to `seconds` and
/// records every control step.
pub fn record(args: &RenderArgs) -> anyhow::Result<(Vec<Frame>, bool)> {
    let task = LeoTask::default();
    let (_, mut agent) = crate::weights::load(&args.policy, task.spec())?;
    record_agent(&mut agent, args.seconds.unwrap_or(6.0))
}

fn check_seconds(seconds: f64) -> Result<(), CliError> {
    if !(seconds.is_finite() && seconds > 0.0 && seconds <= 3600.0) {
        return Err(usage(format!("--seconds {seconds} is out of range: valid is 0 < seconds <= 3600")));
    }
    Ok(())
}

/// `pada render --robot`: the learned motion of a robot of files.
fn render_robot(args: &RenderArgs, path: &std::path::Path) -> Result<(), CliError> {
    if !(args.hold_cm.is_finite() && args.hold_cm > 0.0 && args.hold_cm <= 100.0) {
        return Err(usage(format!("--hold-cm {} is out of range: valid is 0 < cm <= 100", args.hold_cm)));
    }
    let file = pada_robot_file::load(path).map_err(|e| usage(e.to_string()))?;
    let task = pada_sim::urdf::UrdfTask::new(&file).map_err(|e| usage(e.to_string()))?;
    let spec = task.spec();
    let seconds = args.seconds.unwrap_or(spec.episode_steps as f64 * spec.control_period_s);
    check_seconds(seconds)?;
    let out = OutDir::check(
        &args.out.clone().unwrap_or_else(|| PathBuf::from(format!("pada-out/render-{}", file.spec.name))),
    )?;
    let (_, mut agent) = crate::weights::load(&args.policy, spec).map_err(|e| usage(e.to_string()))?;
    let motion = crate::motion::record(&file, &task, &mut agent, seconds)?;
    let tolerance = (args.hold_cm / 100.0) as f32;
    let lines = motion.hold_lines(tolerance);
    let source = args.policy.file_name().map(|f| f.to_string_lossy().into_owned()).unwrap_or_default();
    let title = format!(
        "{}: greedy policy of {source}, {:.2} s{}",
        motion.robot,
        motion.frames.last().map_or(0.0, |f| f.time),
        if motion.fault.is_some() {
            ", stopped at a soft limit"
        } else if motion.ended {
            ", ended by its rules"
        } else {
            ""
        }
    );
    out.write_all(&motion.files(&file, tolerance, &title)?)?;
    outln!("{title}")?;
    if let Some(line) = &motion.fault {
        outln!("the robot faulted: {line} (on the board torque goes off there)")?;
    }
    if lines.is_empty() {
        outln!("(its reward has no term with a target on a point: nothing to hold)")?;
    }
    for l in lines {
        outln!("{l}")?;
    }
    outln!("wrote {}/motion.svg, motion.png, motion.csv", out.path().display())?;
    Ok(())
}

/// Runs `pada render`.
pub fn run(args: RenderArgs) -> Result<(), CliError> {
    if let Some(path) = &args.robot {
        return render_robot(&args, path);
    }
    if args.task != TaskName::Leo {
        return Err(usage(format!(
            "pada render draws only --task leo, not {}",
            args.task
        )));
    }
    check_seconds(args.seconds.unwrap_or(6.0))?;
    let out = OutDir::check(&args.out.clone().unwrap_or_else(|| PathBuf::from("pada-out/render-leo")))?;
    let (frames, fell) = record(&args)?;
    let source = args
        .policy
        .file_name()
        .map(|f| f.to_string_lossy().into_owned())
        .unwrap_or_default();
    let title = gait_title(&source, &frames, fell);
    out.write_all(&gait_files(&frames, args.frames as usize, &title)?)?;
    outln!("{title}")?;
    outln!(
        "wrote {}/gait.svg, gait.png, gait-animation.svg, gait.csv",
        out.path().display()
    )?;
    Ok(())
}
