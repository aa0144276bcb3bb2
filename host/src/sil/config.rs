//! What a software-in-the-loop run runs: the robot, the board and its QEMU
//! machine, the learner, the faults, power cuts and hangs to inject, and
//! where the results go. A leaf: the run ([`super::run`]), its lock-step
//! session ([`super::session`]) and its report ([`super::report`]) all read
//! it, and it reads none of them.

use super::fault::FaultSpec;
use super::power_cut::CutSpec;
use pada_core::policy::PolicyKind;
use pada_core::profile::{Board, LearnerProfile};
use std::path::PathBuf;
use std::time::Duration;

/// The robots `pada sil` runs (the registry's and robots of files,
/// [`crate::robots`]).
pub use crate::robots::SilTask;

/// The QEMU machine that emulates `board`: netduinoplus2 (an STM32F405)
/// for `f405`, mps2-an386 (a Cortex-M4F with 16 MB of PSRAM standing in
/// for the DISC1's SDRAM) for `f429-sdram`; `None` for the host.
pub fn machine(board: Board) -> Option<&'static str> {
    match board {
        Board::F405 => Some("netduinoplus2"),
        Board::F429Sdram => Some("mps2-an386"),
        Board::Host => None,
    }
}

/// What to run.
#[derive(Debug, Clone)]
pub struct SilConfig {
    /// `qemu-system-arm`.
    pub qemu: PathBuf,
    /// The firmware image (built for `board`'s emulation and `task`'s
    /// robot).
    pub elf: PathBuf,
    /// The robot.
    pub task: SilTask,
    /// The board learner profile the image was built for.
    pub board: Board,
    /// The policy the run sets (`SetPolicy`) before starting.
    pub policy: PolicyKind,
    /// The wear governor's budget \[s\] (`SetMtbfBudget`, after the policy
    /// and before the first run), or none.
    pub mtbf_budget_s: Option<f32>,
    /// Learning time to reach \[s\].
    pub seconds: f64,
    /// The master seed (`pada run`'s: the board learns with
    /// `crate::seed::trial_seed(seed, 0)`).
    pub seed: u64,
    /// Faults to inject.
    pub faults: Vec<FaultSpec>,
    /// Power cuts (`--power-cut`).
    pub power_cuts: Vec<CutSpec>,
    /// Hangs of the control loop (`--fault hang:at=S`) \[s\].
    pub hangs_s: Vec<f64>,
    /// Learning time between checkpoint saves \[s\] (none: no saves).
    pub save_every_s: Option<f64>,
    /// Forecast the bus's answers (fewer exchanges, the same run).
    pub forecast: bool,
    /// Also run the firmware's controller on the host to compare with (the
    /// same trial of `pada run --board` for LEO; eight seeds for the
    /// pendulum).
    pub compare: bool,
    /// Where the telemetry, logs and summary go (created).
    pub out_dir: PathBuf,
    /// Longest wall-clock wait for the board before calling it hung.
    pub hang_timeout: Duration,
    /// Show a progress bar on stderr.
    pub progress: bool,
    /// Also stream the firmware's telemetry, as it comes, to a file or a
    /// loopback TCP listener.
    pub telemetry: Option<crate::telemetry::TelemetryTarget>,
    /// Weights exported from the host to start from (`--weights`): the
    /// board boots from their checkpoint image, which the host keeps for
    /// it; `None`: a fresh learner.
    pub weights: Option<SilWeights>,
}

/// Exported weights a SIL run starts from.
#[derive(Debug, Clone)]
pub struct SilWeights {
    /// The board table's entries (`crate::board::export`), for the host
    /// comparison's trial.
    pub entries: Vec<u8>,
    /// The checkpoint image of the learner holding them
    /// (`crate::board::exported::image_of`), restored by the board at its
    /// first boot.
    pub image: Vec<u8>,
}

impl SilConfig {
    /// The learner the image runs.
    pub fn profile(&self) -> LearnerProfile {
        // pada's own robots' tables fit every board (pada-core's profile
        // tests check it); a robot of files' table was checked against the
        // board before the run (`pada sil`), and its image would not have
        // built otherwise.
        self.board.profile(self.task.robot()).expect("the robot's table fits the board (checked before the run)")
    }

    /// The seed of the board's learner.
    pub fn learner_seed(&self) -> u64 {
        crate::seed::trial_seed(self.seed, 0)
    }
}

