//! The command line's names of the robots pada brings: `pada run --task`'s
//! tasks, `pada sil --task`'s robots, and the parser of `--board`, built
//! from [`Board::ALL`] as `--algo` is built from the core's policy names.
//! What the simulator runs for each robot is `pada_sim::robots`; a robot
//! of the user's own comes by `--robot FILE` and has no name here.
//!
//! One name means one robot: `pada run --task physical-pendulum` and
//! `pada sil --task pendulum` (or `--task physical-pendulum`) are the same
//! physical pendulum; `pada run --task pendulum` is Section VII's simulated
//! pendulum, a task without a robot (it has no board).

use crate::rig::Rig;
use clap::builder::PossibleValue;
use pada_core::profile::Board;
use pada_core::robot::{leo, pendulum, RobotSpec};
pub use pada_sim::robots::*;
use serde::Serialize;
use std::fmt;

/// The clap parser of `--board`: the core's board names ([`Board::ALL`]),
/// listed with their descriptions in the help and in the error for an
/// unknown one.
pub fn board_parser() -> impl clap::builder::TypedValueParser<Value = Board> {
    use clap::builder::TypedValueParser;
    clap::builder::PossibleValuesParser::new(Board::ALL.map(|b| PossibleValue::new(b.name()).help(b.description())))
        .try_map(|name| Board::from_name(&name).ok_or("unknown board"))
}

/// A task name on the command line (`pada run --task`): Section VII's
/// simulated pendulum, and every robot the host simulates, named as the
/// robot.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TaskName {
    /// The simulated inverted pendulum of Section VII.
    Pendulum,
    /// The model of the physical pendulum of the paper's experiment (robot
    /// `physical-pendulum`).
    PhysicalPendulum,
    /// The LEO biped walking (Section VIII; robot `leo`).
    Leo,
}

impl TaskName {
    /// Every task: the simulated pendulum, then the robots' tasks in the
    /// order of the core's registry.
    pub const ALL: [TaskName; 3] = [TaskName::Pendulum, TaskName::PhysicalPendulum, TaskName::Leo];

    /// The robot this task simulates; `None` for the simulated pendulum.
    pub fn robot(self) -> Option<&'static RobotSpec> {
        match self {
            TaskName::Pendulum => None,
            TaskName::PhysicalPendulum => Some(&pendulum::SPEC_33HZ),
            TaskName::Leo => Some(&leo::SPEC),
        }
    }

    /// The name on the command line: the robot's, or `pendulum`.
    pub fn name(self) -> &'static str {
        self.robot().map_or("pendulum", |r| r.name)
    }

    fn help(self) -> &'static str {
        match self {
            TaskName::Pendulum => "the simulated inverted pendulum of Section VII",
            TaskName::PhysicalPendulum => "the model of the physical pendulum of the paper's experiment",
            TaskName::Leo => "the LEO biped walking (Section VIII)",
        }
    }
}

impl fmt::Display for TaskName {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl clap::ValueEnum for TaskName {
    fn value_variants<'a>() -> &'a [Self] {
        &TaskName::ALL
    }

    fn to_possible_value(&self) -> Option<PossibleValue> {
        Some(PossibleValue::new(self.name()).help(self.help()))
    }
}

/// The robots `pada sil` runs: pada's, by the names `pada sil --task` and
/// `cargo xtask --robot` give them, and a robot of files (`pada sil
/// --robot FILE`). `pendulum` here is the physical pendulum (robot
/// `physical-pendulum`, also accepted by that name), not `pada run --task
/// pendulum`'s simulated one.
#[derive(Debug, Clone, Copy)]
pub enum SilTask {
    /// The physical pendulum at 33 Hz (robot `physical-pendulum`) against
    /// the host's model of it.
    Pendulum,
    /// LEO (robot `leo`) against the rapier3d LEO.
    Leo,
    /// A robot of files against its URDF in rapier3d ([`SilTask::of_file`]).
    File(&'static FileRobot),
}

/// A robot of files as `pada sil` runs it: where its `robot.toml` is (the
/// firmware's build reads the same file) and the simulator's entry.
#[derive(Debug)]
pub struct FileRobot {
    /// Its `robot.toml`, as an absolute path.
    pub path: std::path::PathBuf,
    /// What the simulator runs.
    pub sim: SimRobot,
}

impl PartialEq for SilTask {
    fn eq(&self, other: &Self) -> bool {
        match (self, other) {
            (SilTask::File(a), SilTask::File(b)) => a.path == b.path && a.sim.robot == b.sim.robot,
            (SilTask::Pendulum, SilTask::Pendulum) | (SilTask::Leo, SilTask::Leo) => true,
            _ => false,
        }
    }
}

impl Eq for SilTask {}

/// As the summary's `task`: the name ([`SilTask::name`]).
impl Serialize for SilTask {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str(self.name())
    }
}

impl SilTask {
    /// Every one of pada's robots `pada sil` runs.
    pub const ALL: [SilTask; 2] = [SilTask::Pendulum, SilTask::Leo];

    /// The robot of the `robot.toml` at `path` (relative to the current
    /// directory), read and checked, with its URDF body. It lives for the
    /// rest of the process, as the definitions of pada's robots do.
    pub fn of_file(path: &std::path::Path) -> anyhow::Result<SilTask> {
        // Absolute, because `cargo xtask` builds the image elsewhere.
        let path = std::path::absolute(path).unwrap_or_else(|_| path.to_path_buf());
        let file = pada_robot_file::load(&path).map_err(|e| anyhow::anyhow!("{e}"))?;
        let sim = from_file(&file)?;
        Ok(SilTask::File(Box::leak(Box::new(FileRobot { path, sim }))))
    }

    /// The firmware's robot.
    pub fn robot(self) -> &'static RobotSpec {
        match self {
            SilTask::Pendulum => &pendulum::SPEC_33HZ,
            SilTask::Leo => &leo::SPEC,
            SilTask::File(f) => f.sim.robot,
        }
    }

    /// The name on the command line (and `cargo xtask --robot`'s); a robot
    /// of files' own name.
    pub fn name(self) -> &'static str {
        match self {
            SilTask::Pendulum => "pendulum",
            SilTask::Leo => "leo",
            SilTask::File(f) => f.sim.robot.name,
        }
    }

    /// What `cargo xtask qemu --robot` takes for it: the name, or the path
    /// of a robot of files.
    pub fn xtask_robot(self) -> String {
        match self {
            SilTask::File(f) => f.path.display().to_string(),
            _ => self.name().to_string(),
        }
    }

    /// The simulator's entry.
    pub fn sim(self) -> anyhow::Result<SimRobot> {
        match self {
            SilTask::File(f) => Ok(f.sim.clone()),
            _ => sim_robot(self.robot()),
        }
    }

    /// The board each robot is built for when `--board` is not given: the
    /// F405 for the pendulum and a robot of files, the F429I-DISC1 with its
    /// SDRAM for LEO.
    pub fn default_board(self) -> Board {
        self.sim().map_or(Board::F405, |e| e.default_board)
    }

    /// The robot behind the bus ([`SimRobot::sil_rig`]).
    pub fn rig(self) -> anyhow::Result<Box<dyn Rig>> {
        self.sim()?.sil_rig()
    }

    fn help(self) -> &'static str {
        match self {
            SilTask::Pendulum => "the physical pendulum (robot physical-pendulum; not `pada run --task pendulum`, the simulated one) against its model",
            SilTask::Leo => "LEO against the rapier3d LEO, with an operator who sets it up between episodes",
            SilTask::File(_) => "a robot of files",
        }
    }
}

impl clap::ValueEnum for SilTask {
    fn value_variants<'a>() -> &'a [Self] {
        &SilTask::ALL
    }

    fn to_possible_value(&self) -> Option<PossibleValue> {
        // A robot of files is named by `--robot FILE`, not by `--task`.
        if let SilTask::File(_) = self {
            return None;
        }
        let value = PossibleValue::new(self.name()).help(self.help());
        // The robot's own name is accepted too, so one name means one robot.
        Some(if self.robot().name == self.name() { value } else { value.alias(self.robot().name) })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_task_list_is_the_simulated_pendulum_and_robots_of_the_registry() {
        assert_eq!(TaskName::ALL[0], TaskName::Pendulum);
        assert_eq!(TaskName::Pendulum.robot(), None);
        for task in &TaskName::ALL[1..] {
            assert!(sim_robot(task.robot().unwrap()).is_ok(), "{task}: a robot the simulator runs");
        }
        for task in &TaskName::ALL[1..] {
            let robot = task.robot().expect("a robot");
            assert_eq!(task.name(), robot.name, "a robot's task is named as the robot");
        }
        let names: Vec<&str> = TaskName::ALL.iter().map(|t| t.name()).collect();
        assert_eq!(names, ["pendulum", "physical-pendulum", "leo"]);
    }

    #[test]
    fn the_sil_robots_are_the_registrys() {
        assert_eq!(SilTask::Pendulum.robot(), &pendulum::SPEC_33HZ);
        assert_eq!(SilTask::Leo.robot(), &leo::SPEC);
        assert_eq!((SilTask::Pendulum.default_board(), SilTask::Leo.default_board()), (Board::F405, Board::F429Sdram));
        use clap::ValueEnum;
        assert_eq!(SilTask::from_str("physical-pendulum", false), Ok(SilTask::Pendulum));
        assert_eq!(SilTask::from_str("pendulum", false), Ok(SilTask::Pendulum));
        assert_eq!(TaskName::from_str("physical-pendulum", false), Ok(TaskName::PhysicalPendulum));
    }

    #[test]
    fn pada_sil_takes_a_robot_of_protocol_2_servos() {
        let arm = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples/robots/arm2/robot.toml");
        let task = SilTask::of_file(&arm).expect("the arm of X-series servos runs in pada sil");
        assert_eq!(task.robot().name, "arm2");
        assert!(task.robot().joints.iter().all(|j| j.servo.protocol == pada_core::servo::ServoProtocol::V2));
        // A file that is not there stays one line.
        let e = SilTask::of_file(std::path::Path::new("no/such/robot.toml")).err().expect("refused").to_string();
        assert!(!e.contains('\n'), "{e}");
    }

    #[test]
    fn the_board_parser_knows_every_board() {
        use clap::builder::TypedValueParser;
        let cmd = clap::Command::new("t");
        for board in Board::ALL {
            let parsed = board_parser().parse_ref(&cmd, None, std::ffi::OsStr::new(board.name())).unwrap();
            assert_eq!(parsed, board);
        }
        assert!(board_parser().parse_ref(&cmd, None, std::ffi::OsStr::new("f446")).is_err());
    }
}
