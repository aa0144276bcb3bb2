//! The command line (clap derive) and its dispatch. Every clap error is
//! turned into one line with exit code 2.

use crate::commands;
use crate::error::{usage, CliError};
use crate::experiment::algo::Algo;
use crate::experiment::tasks::TaskName;
use clap::{Args, Parser, Subcommand, ValueEnum};
use std::ffi::OsString;
use std::path::PathBuf;

/// pada: reinforcement learning that does not break the robot (Meijdam,
/// Plooij and Caarls, "Learning while preventing mechanical failure due to
/// random motions").
#[derive(Debug, Parser)]
#[command(name = "pada", version, allow_negative_numbers = true)]
pub struct Cli {
    /// What to do.
    #[command(subcommand)]
    pub command: Command,
}

/// The subcommands.
#[derive(Debug, Subcommand)]
pub enum Command {
    /// Run trials of one algorithm on one task and summarise them.
    #[command(allow_negative_numbers = true)]
    Run(RunArgs),
    /// SARSA(λ) against PADA Δ = 0.5 on the simulated pendulum, next to the
    /// paper's numbers (about ten seconds on two cores).
    #[command(allow_negative_numbers = true)]
    Demo(DemoArgs),
    /// Reproduce a section of the paper: report.md, tables and figures.
    #[command(allow_negative_numbers = true)]
    Paper(PaperArgs),
    /// Predicted MTBF of a recorded torque log (Eqs. 3–7).
    #[command(allow_negative_numbers = true)]
    Mtbf(MtbfArgs),
    /// Software in the loop: the firmware learns inside QEMU against the
    /// simulated plant (docs/sil.md).
    #[command(allow_negative_numbers = true)]
    Sil(commands::sil::SilArgs),
    /// Decode telemetry from a board's serial port or a recorded stream.
    Capture(commands::capture::CaptureArgs),
    /// A live page in the browser of a board's, a recording's or a live
    /// run's telemetry (decoded and recorded as capture does).
    #[command(allow_negative_numbers = true)]
    Watch(commands::watch::WatchArgs),
    /// Draw a learned LEO gait (saved weights) as a strip of stick figures.
    Render(RenderArgs),
    /// The LEO model on its own: `pada leo passive` (the passive rollout).
    Leo(commands::leo::LeoArgs),
    /// Run one trial of a plan (written with --plan DIR), as a Slurm array
    /// task or a Kubernetes indexed job.
    Trial(commands::trial::TrialArgs),
}

/// Options shared by the commands that run trials.
#[derive(Debug, Clone, Args)]
pub struct TrialOptions {
    /// Master seed; each trial's seed derives from it.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Worker threads (default: all cores).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=1024))]
    pub threads: Option<u32>,
}

/// `pada run`.
#[derive(Debug, Clone, Args)]
pub struct RunArgs {
    /// The task.
    #[arg(long, value_enum, default_value_t = TaskName::Pendulum)]
    pub task: TaskName,
    /// The algorithm (Section V, and the gentle explorations epsilon-pada,
    /// ou, pink, action-penalty).
    #[arg(long, value_parser = crate::experiment::algo::algo_parser())]
    pub algo: Algo,
    /// Low-pass α of Eq. 8, 0 < α ≤ 1 (lowpass, markov-lowpass; default 0.834).
    #[arg(long)]
    pub alpha: Option<f32>,
    /// Δ relative to the action range, 0 < Δ ≤ 1 (integrator,
    /// markov-integrator, pada, epsilon-pada; default 0.5).
    #[arg(long)]
    pub delta: Option<f32>,
    /// OU's mean reversion per step, 0 < θ ≤ 1 (ou; default 0.15).
    #[arg(long)]
    pub theta: Option<f32>,
    /// Noise scale, 0 < σ ≤ 4, in units of the largest distance from 0 to a
    /// bound of the action range (ou, default 0.2; pink, default 0.38).
    #[arg(long)]
    pub sigma: Option<f32>,
    /// The action-change penalty per squared full-range change,
    /// 0 < w ≤ 10000 (action-penalty; default 1).
    #[arg(long)]
    pub weight: Option<f32>,
    /// Learn on a wear budget: a governor moves PADA's Δ or the low-pass
    /// filter's α while learning so that the predicted MTBF over the last
    /// 1200 learning actions stays at or above this [s] (pada, lowpass;
    /// 0 < budget <= 1e10; instead of --delta or --alpha).
    #[arg(long, value_name = "SECONDS")]
    pub mtbf_budget: Option<f32>,
    /// Switch back to SARSA(λ) after this much learning time [s]
    /// (lowpass, pada and the gentle explorations; Section VIII).
    #[arg(long, value_name = "SECONDS")]
    pub switch_at: Option<f64>,
    /// Trials (default: the paper's count for the task, 29 or 28).
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u32).range(1..=10000))]
    pub trials: Option<u32>,
    /// Learning time per trial [s of simulated time] (default: the task's).
    #[arg(long, value_name = "S")]
    pub seconds: Option<f64>,
    /// Output directory for summary.json, trials.csv and the learning
    /// curves (default: pada-out/run-<task>-<algo>).
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,
    /// Print the summary as JSON on stdout.
    #[arg(long)]
    pub json: bool,
    /// Stream trial 0 as the firmware's telemetry frames to FILE or to
    /// tcp:HOST:PORT (loopback only); `pada capture --file` reads them.
    #[arg(long, value_name = "FILE|tcp:HOST:PORT")]
    pub telemetry: Option<String>,
    /// Save the first trial's learned weights to this file (versioned, with
    /// a checksum; read by `pada render`).
    #[arg(long, value_name = "FILE")]
    pub save_weights: Option<PathBuf>,
    /// Run a board's own learner instead of the host's: the firmware's
    /// controller built for the host, with the board's learner profile
    /// (table layout, size, weight format), its sensors (servo counts,
    /// differenced rates, the encoder) and its episode logic, against the
    /// task's plant (physical-pendulum or leo). What it learns is what the
    /// board will learn.
    #[arg(long, value_enum, value_name = "NAME")]
    pub board: Option<crate::board::BoardName>,
    /// With --board: a hashed table of 2^N weights instead of the board's
    /// (placed in CCM, then SRAM on an F405), to see what a board would
    /// learn with more or less memory. The firmware builds only the boards'
    /// own profiles.
    #[arg(long, value_name = "N", requires = "board", value_parser = clap::value_parser!(u32).range(8..=26))]
    pub table_log2: Option<u32>,
    /// With --board: store weights in 16 or 32 bits (16: stochastic
    /// rounding, the robot's range; see pada_core::weights).
    #[arg(long, value_name = "BITS", requires = "board", value_parser = ["16", "32"])]
    pub weight_bits: Option<String>,
    /// Seed and threads.
    #[command(flatten)]
    pub trial: TrialOptions,
    /// Plans, merges and Slurm.
    #[command(flatten)]
    pub cluster: crate::plan::mode::ClusterOptions,
}

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

/// Which experiment `pada paper` reproduces.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum PaperExperiment {
    /// Section VII: the simulated pendulum sweeps and the physical pendulum.
    Pendulum,
    /// Section VIII: SARSA(λ), PADA and low-pass on LEO, with and without
    /// the switch back to SARSA(λ) at half the run.
    Leo,
    /// Learning on a wear budget: every strategy (the six and the gentle
    /// explorations) over a sweep and the wear governor at three budgets;
    /// end performance against both MTBFs with the Pareto front.
    Wear,
}

/// The task of `pada paper wear`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum WearTask {
    /// The simulated pendulum (29 trials of 3000 s).
    Pendulum,
    /// The LEO model (3 trials of 3600 s by default).
    Leo,
}

/// `pada paper`.
#[derive(Debug, Clone, Args)]
pub struct PaperArgs {
    /// The experiment.
    #[arg(value_enum)]
    pub experiment: PaperExperiment,
    /// Output directory for report.md, the figures and the data (default:
    /// pada-out/paper-<experiment>).
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,
    /// Trials per configuration (default: the paper's 29 simulated, 28
    /// physical; LEO: 3, scaled down from the paper's 15).
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u32).range(1..=10000))]
    pub trials: Option<u32>,
    /// Learning time per trial on the simulated pendulum [s] (default
    /// 3000; LEO: 14666, the paper's).
    #[arg(long, value_name = "S")]
    pub seconds: Option<f64>,
    /// The task of `pada paper wear` (default pendulum).
    #[arg(long, value_enum)]
    pub task: Option<WearTask>,
    /// Learning time per trial on the physical pendulum [s].
    #[arg(long, value_name = "S", default_value_t = 1500.0)]
    pub physical_seconds: f64,
    /// Seed and threads.
    #[command(flatten)]
    pub trial: TrialOptions,
    /// Plans, merges and Slurm.
    #[command(flatten)]
    pub cluster: crate::plan::mode::ClusterOptions,
}

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

/// Largest learning time accepted per trial [s].
pub const MAX_SECONDS: f64 = 1.0e6;

/// Checks a learning time given with `flag`.
pub fn check_seconds(flag: &str, s: f64) -> Result<f64, CliError> {
    if s.is_finite() && s > 0.0 && s <= MAX_SECONDS {
        Ok(s)
    } else {
        Err(usage(format!(
            "{flag} {s} is out of range: valid is 0 < seconds <= {MAX_SECONDS}"
        )))
    }
}

/// Sets the size of rayon's pool, once.
pub fn set_threads(threads: Option<u32>) -> Result<(), CliError> {
    if let Some(n) = threads {
        rayon::ThreadPoolBuilder::new()
            .num_threads(n as usize)
            .build_global()
            .map_err(|e| CliError::Runtime(anyhow::anyhow!("cannot start {n} threads: {e}")))?;
    }
    Ok(())
}

/// One line from a clap error: its message and the valid values, without
/// the usage block.
fn clap_one_line(e: &clap::Error) -> String {
    let text = e.render().to_string();
    let line = text
        .lines()
        .map(str::trim)
        .filter(|l| {
            !l.is_empty() && !l.starts_with("Usage:") && !l.starts_with("For more information")
        })
        .collect::<Vec<_>>()
        .join(" ");
    line.strip_prefix("error: ").unwrap_or(&line).to_string()
}

/// The subcommands of `pada <parent>`, comma-separated (without `help`).
fn subcommands_of(parent: &str) -> String {
    use clap::CommandFactory;
    Cli::command()
        .find_subcommand(parent)
        .map(|c| {
            c.get_subcommands()
                .map(|s| s.get_name().to_string())
                .filter(|n| n != "help")
                .collect::<Vec<_>>()
                .join(", ")
        })
        .unwrap_or_default()
}

/// Parses `args` and runs the command. Help and version requests print and
/// return `Ok`.
pub fn run<I, T>(args: I) -> Result<(), CliError>
where
    I: IntoIterator<Item = T>,
    T: Into<OsString> + Clone,
{
    let args: Vec<OsString> = args.into_iter().map(Into::into).collect();
    let cli = match Cli::try_parse_from(&args) {
        Ok(cli) => cli,
        Err(e) => {
            use clap::error::ErrorKind;
            let nested = args.get(1).and_then(|a| a.to_str()).filter(|&a| a == "leo");
            return match e.kind() {
                ErrorKind::DisplayHelp | ErrorKind::DisplayVersion => {
                    let _ = e.print();
                    Ok(())
                }
                ErrorKind::DisplayHelpOnMissingArgumentOrSubcommand | ErrorKind::MissingSubcommand
                    if nested.is_some() =>
                {
                    let parent = nested.unwrap_or_default();
                    Err(usage(format!(
                        "pada {parent} needs a subcommand: valid is {} (see pada {parent} --help)",
                        subcommands_of(parent)
                    )))
                }
                ErrorKind::InvalidSubcommand if nested.is_some() => {
                    let parent = nested.unwrap_or_default();
                    Err(usage(format!(
                        "{} of pada {parent}: valid is {}",
                        clap_one_line(&e),
                        subcommands_of(parent)
                    )))
                }
                ErrorKind::DisplayHelpOnMissingArgumentOrSubcommand => Err(usage(
                    "no command given: valid commands are run, demo, paper, mtbf, render, sil, capture, watch, leo, trial (see pada --help)",
                )),
                _ => Err(usage(clap_one_line(&e))),
            };
        }
    };
    match cli.command {
        Command::Run(a) => commands::run::run(a),
        Command::Demo(a) => commands::demo::run(a),
        Command::Paper(a) => commands::paper::run(a),
        Command::Mtbf(a) => commands::mtbf::run(a),
        Command::Sil(a) => commands::sil::run(a),
        Command::Capture(a) => commands::capture::run(a),
        Command::Watch(a) => commands::watch::run(a),
        Command::Render(a) => commands::render::run(a),
        Command::Leo(a) => commands::leo::run(a),
        Command::Trial(a) => commands::trial::run(a),
    }
}
