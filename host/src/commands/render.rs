//! `pada render`: a learned LEO gait as a strip of stick figures (SVG and
//! PNG) and the trajectory as CSV, from weights saved by
//! `pada run --task leo --save-weights FILE`.

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
    /// The task (only leo can be drawn).
    #[arg(long, value_enum, default_value_t = TaskName::Leo)]
    pub task: TaskName,
    /// Weights saved by `pada run --save-weights`.
    #[arg(long, value_name = "FILE")]
    pub policy: PathBuf,
    /// Output directory for gait.svg, gait.png and gait.csv.
    #[arg(long, value_name = "DIR", default_value = "pada-out/render-leo")]
    pub out: PathBuf,
    /// Seconds of the greedy episode to draw.
    #[arg(long, value_name = "S", default_value_t = 6.0)]
    pub seconds: f64,
    /// Frames in the strip.
    #[arg(long, value_name = "N", default_value_t = 12, value_parser = clap::value_parser!(u32).range(1..=200))]
    pub frames: u32,
}

/// Runs the greedy policy of the weights file for up to `seconds` and
/// records every control step.
pub fn record(args: &RenderArgs) -> anyhow::Result<(Vec<Frame>, bool)> {
    let task = LeoTask::default();
    let (_, mut agent) = crate::weights::load(&args.policy, task.spec())?;
    record_agent(&mut agent, args.seconds)
}

/// Runs `pada render`.
pub fn run(args: RenderArgs) -> Result<(), CliError> {
    if args.task != TaskName::Leo {
        return Err(usage(format!(
            "pada render draws only --task leo, not {}",
            args.task
        )));
    }
    if !(args.seconds.is_finite() && args.seconds > 0.0 && args.seconds <= 3600.0) {
        return Err(usage(format!(
            "--seconds {} is out of range: valid is 0 < seconds <= 3600",
            args.seconds
        )));
    }
    let out = OutDir::check(&args.out)?;
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
