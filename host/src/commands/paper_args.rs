//! The arguments of `pada paper` ([`PaperArgs`]), which its three
//! experiments read: the pendulum's ([`super::paper`]), LEO's
//! ([`super::paper_leo`]) and the wear budget's ([`super::paper_wear`]).

use crate::commands::options::TrialOptions;
use clap::{Args, ValueEnum};
use std::path::PathBuf;

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
    /// Learn in simulation, finish on the robot: the gear damage until the
    /// objective on plants that differ from the model, from nothing against
    /// from weights pretrained on the model and randomised (the physical
    /// pendulum and the robots of --robot).
    Transfer,
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
    /// `pada paper transfer`: robots of files to measure besides the
    /// physical pendulum, each with its robot.toml's [plant] ranges
    /// (default: examples/robots/arm2 and arm3).
    #[arg(long = "robot", value_name = "robot.toml")]
    pub robots: Vec<PathBuf>,
    /// `pada paper transfer`: ranges over the robots of files' [plant]
    /// (not the pendulum's), as `pada run --plant-ranges` takes them.
    #[arg(long, value_name = "RANGES")]
    pub plant_ranges: Option<String>,
    /// `pada paper transfer`: learning time of each pretraining trial on
    /// the model [s] (default: the learning time on the plant).
    #[arg(long, value_name = "S")]
    pub pretrain_seconds: Option<f64>,
    /// Seed and threads.
    #[command(flatten)]
    pub trial: TrialOptions,
    /// Plans, merges and Slurm.
    #[command(flatten)]
    pub cluster: crate::plan::mode::ClusterOptions,
}
