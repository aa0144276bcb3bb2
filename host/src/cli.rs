//! The command line (clap derive) and its dispatch. Every clap error is
//! turned into one line with exit code 2. Each command owns its argument
//! struct (`crate::commands::*`); the options several commands share are
//! in [`crate::commands::options`].

use crate::commands;
use crate::error::{usage, CliError};
use clap::{Parser, Subcommand};
use std::ffi::OsString;

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
    Run(commands::run::RunArgs),
    /// SARSA(λ) against PADA Δ = 0.5 on the simulated pendulum, next to the
    /// paper's numbers (about ten seconds on two cores).
    #[command(allow_negative_numbers = true)]
    Demo(commands::demo::DemoArgs),
    /// Reproduce a section of the paper: report.md, tables and figures.
    #[command(allow_negative_numbers = true)]
    Paper(commands::paper_args::PaperArgs),
    /// Predicted MTBF of a recorded torque log (Eqs. 3–7).
    #[command(allow_negative_numbers = true)]
    Mtbf(commands::mtbf::MtbfArgs),
    /// What LEO's trials write into the claim table: slots claimed over
    /// learning time from `pada run` outputs, and when each board's table
    /// would be full (claims.png).
    Claims(commands::claims::ClaimsArgs),
    /// Software in the loop: the firmware learns inside QEMU against the
    /// simulated plant (docs/sil.md).
    #[command(allow_negative_numbers = true)]
    Sil(commands::sil::SilArgs),
    /// Learn on a real robot from this PC: the firmware's controller over a
    /// serial port (a USB adapter to the servos, or `pada servos`).
    #[command(allow_negative_numbers = true)]
    Drive(commands::drive::DriveArgs),
    /// Virtual servos of a robot on a pseudo-terminal, answering with its
    /// simulated physics; or --scan a real port for what answers.
    Servos(commands::servos::ServosArgs),
    /// Decode telemetry from a board's serial port or a recorded stream.
    Capture(commands::capture::CaptureArgs),
    /// A live page in the browser of a board's, a recording's or a live
    /// run's telemetry (decoded and recorded as capture does).
    #[command(allow_negative_numbers = true)]
    Watch(commands::watch::WatchArgs),
    /// Draw a learned LEO gait (saved weights) as a strip of stick figures,
    /// or a robot of files' learned motion (--robot).
    Render(commands::render::RenderArgs),
    /// Write a new robot's robot.toml and URDF, commented field by field,
    /// which run as they are (docs/your-robot.md).
    NewRobot(commands::new_robot::NewRobotArgs),
    /// The LEO model on its own: `pada leo passive` (the passive rollout).
    Leo(commands::leo::LeoArgs),
    /// Run one trial of a plan (written with --plan DIR), as a Slurm array
    /// task or a Kubernetes indexed job.
    Trial(commands::trial::TrialArgs),
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
                    "no command given: valid commands are run, demo, paper, mtbf, claims, render, sil, drive, servos, capture, watch, leo, trial (see pada --help)",
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
        // Before flashing (a robot and a board) or after runs (their directories).
        Command::Claims(a) if a.robot.is_some() || a.task.is_some() => commands::claims_demand::run(a),
        Command::Claims(a) => commands::claims::run(a),
        Command::Sil(a) => commands::sil::run(a),
        Command::Drive(a) => commands::drive::run(a),
        Command::Servos(a) => commands::servos::run(a),
        Command::Capture(a) => commands::capture::run(a),
        Command::Watch(a) => commands::watch::run(a),
        Command::Render(a) => commands::render::run(a),
        Command::NewRobot(a) => commands::new_robot::run(a),
        Command::Leo(a) => commands::leo::run(a),
        Command::Trial(a) => commands::trial::run(a),
    }
}
