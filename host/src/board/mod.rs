//! A board's own learner on the host: `pada run --board NAME`.
//!
//! What runs is the firmware's controller (`pada_firmware::control`, the
//! code the board runs, built for the host) with the board's learner
//! profile (`pada_core::profile`: table layout, size, weight format),
//! against the robot behind the servos ([`crate::rig`]: the physical
//! pendulum's model, or the rapier3d LEO), with the sensors as the board
//! sees them — positions in servo counts, rates differenced from them, the
//! encoder in counts — and the robot's own episode logic: the held joints,
//! the wait until the robot is back at its start. What it learns is what the
//! board will learn; `pada sil` shows that the binary does the same, bit
//! for bit.
//!
//! - [`export`]: weights learned on the host in the board's table;
//! - [`exported`]: a board's checkpoint image of exported weights;
//! - [`demand`]: the slots a trial writes against the board's claim
//!   table, known before flashing;
//! - [`protocol`]: the run protocol and seeds, shared with `pada sil`;
//! - [`trial`]: one trial, the controller and the rig in lock step;
//! - [`fault_line`]: a fault's cause as one line for a person;
//! - [`readable`]: whether the board can read the robot's joints where
//!   its episodes start (a robot of files' calibration);
//! - [`run_board`]: the trials of a run in parallel, with the same
//!   [`TrialResult`]s (and so the same `summary.json`) as `pada run`.

pub mod demand;
pub mod export;
pub mod exported;
pub mod fault_line;
pub mod protocol;
pub mod readable;
pub mod trial;

use crate::experiment::RunConfig;
use crate::experiment::TrialResult;
use pada_core::profile::{LearnerProfile, Memory};
use pada_core::robot::RobotSpec;
use rayon::prelude::*;
use serde::Serialize;

pub use protocol::{EpisodeOutcome, Phase, RunProtocol};
pub use trial::{run_board_trial, run_board_trial_from, run_board_trial_on, run_board_trial_on_from, BoardStart, BoardTrial};

/// A board's learner, as `summary.json` reports it.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ProfileReport {
    /// The board's name.
    pub board: &'static str,
    /// What the board is.
    pub description: &'static str,
    /// The robot.
    pub robot: &'static str,
    /// `exact`, `hashed` or `claim`.
    pub layout: &'static str,
    /// Weights in the table.
    pub weights: usize,
    /// Bits per stored weight.
    pub weight_bits: usize,
    /// Bits per claim tag (0 without claims).
    pub tag_bits: usize,
    /// The table's size \[bytes\].
    pub table_bytes: usize,
    /// Where the table lives.
    pub memory: &'static str,
    /// Bytes of it in CCM and in SRAM, when split over both.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub split_bytes: Option<[usize; 2]>,
}

impl ProfileReport {
    /// The report of `profile` with a table of `weights` weights.
    pub fn new(profile: &LearnerProfile, weights: usize) -> Self {
        let bytes = profile.entry_bytes();
        ProfileReport {
            board: profile.board.name(),
            description: profile.board.description(),
            robot: profile.robot.name,
            layout: profile.layout.name(),
            weights,
            weight_bits: profile.format.bytes() * 8,
            tag_bits: profile.tag_bytes * 8,
            table_bytes: weights * bytes,
            memory: profile.memory.name(),
            split_bytes: match profile.memory {
                Memory::CcmThenSram { ccm_weights } => Some([ccm_weights * bytes, (weights - ccm_weights) * bytes]),
                Memory::CcmWeightsSramTags => Some([weights * profile.format.bytes(), weights * profile.tag_bytes]),
                _ => None,
            },
        }
    }
}

/// The robot of a `--task` that has a board, or why not.
pub fn robot_of_task(task: crate::experiment::tasks::TaskName) -> Result<&'static RobotSpec, String> {
    task.robot().ok_or_else(|| {
        "--board runs a robot that has a board: --task physical-pendulum or --task leo, not pendulum \
         (the simulated pendulum of Section VII is a simulation only)"
            .to_string()
    })
}

/// Runs the trials of `cfg` with `profile`'s learner, in parallel;
/// `progress` is told the environment steps of every finished episode.
pub fn run_board(
    profile: LearnerProfile,
    robot: &crate::robots::SimRobot,
    cfg: &RunConfig,
    progress: &(dyn Fn(u64) + Sync),
) -> anyhow::Result<Vec<BoardTrial>> {
    run_board_from(profile, robot, cfg, BoardStart::Fresh, progress)
}

/// [`run_board`] with every trial's learner starting as `start` says.
pub fn run_board_from(
    profile: LearnerProfile,
    robot: &crate::robots::SimRobot,
    cfg: &RunConfig,
    start: BoardStart<'_>,
    progress: &(dyn Fn(u64) + Sync),
) -> anyhow::Result<Vec<BoardTrial>> {
    (0..cfg.trials).into_par_iter().map(|i| run_board_trial_from(profile, robot, cfg, i, start, progress)).collect()
}

/// The per-trial results of board trials.
pub fn results(trials: &[BoardTrial]) -> Vec<TrialResult> {
    trials.iter().map(|t| t.result.clone()).collect()
}
