//! The host's side of the robots pada brings: one entry per robot of the
//! core's registry (`pada_core::robot::registry`) with what the host runs
//! for it — its task for `pada run --task`, its name for `pada sil --task`
//! and the firmware's build, the board it is built for by default, the
//! body that simulates it and its rules — and the command-line parsers of
//! `--task` and `--board`, built from these entries and [`Board::ALL`] as
//! `--algo` is built from the core's policy names.
//!
//! One name means one robot: `pada run --task physical-pendulum` and
//! `pada sil --task pendulum` (or `--task physical-pendulum`) are the same
//! physical pendulum; `pada run --task pendulum` is Section VII's simulated
//! pendulum, a task without a robot (it has no board).

use crate::experiment::task::{Task, TaskSpec};
use crate::leo::model::ModelOptions;
use crate::leo::rl::{leo_params, LeoTask};
use crate::pendulum::{PhysicalPendulumParams, PhysicalPendulumTask};
use crate::rig::{LeoRig, PendulumRig, Rig};
use clap::builder::PossibleValue;
use pada_core::limits::MAX_STATE_DIMS;
use pada_core::profile::{Board, LearnerProfile};
use pada_core::robot::leo::{self, Leo};
use pada_core::robot::pendulum::{self, Pendulum};
use pada_core::robot::{PerServo, RobotRules, RobotSpec, Sensed};
use serde::Serialize;
use std::fmt;

/// The simulated body behind a robot's servos: pada's two hand-built
/// models.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Body {
    /// The physical pendulum's model (`crate::pendulum::physical`).
    Pendulum,
    /// The rapier3d LEO (`crate::leo`).
    Leo,
}

/// What the host runs for one robot.
#[derive(Debug, Clone, Copy)]
pub struct HostRobot {
    /// The robot.
    pub robot: &'static RobotSpec,
    /// Its task for `pada run --task` (named as the robot), if the host
    /// simulates it.
    pub task: Option<TaskName>,
    /// Its name for `pada sil --task` and `cargo xtask --robot`, if the
    /// software-in-the-loop run has a rig for it.
    pub sil: Option<SilTask>,
    /// The board its firmware is built for when `--board` is not given.
    pub default_board: Board,
    /// The body that simulates it.
    pub body: Body,
    /// Its rules, before the first reading.
    pub rules: fn() -> DynRules,
}

/// The host's entries, in the order of the core's registry (a test checks
/// it).
pub static ROBOTS: [HostRobot; 3] = [
    HostRobot {
        robot: &pendulum::SPEC_33HZ,
        task: Some(TaskName::PhysicalPendulum),
        sil: Some(SilTask::Pendulum),
        default_board: Board::F405,
        body: Body::Pendulum,
        rules: || DynRules(Box::new(Pendulum::at_33hz())),
    },
    HostRobot {
        robot: &pendulum::SPEC_20HZ,
        task: None,
        sil: None,
        default_board: Board::F405,
        body: Body::Pendulum,
        rules: || DynRules(Box::new(Pendulum::at_20hz())),
    },
    HostRobot {
        robot: &leo::SPEC,
        task: Some(TaskName::Leo),
        sil: Some(SilTask::Leo),
        default_board: Board::F429Sdram,
        body: Body::Leo,
        rules: || DynRules(Box::new(Leo::new())),
    },
];

/// The entry of `robot`, if the host knows it.
pub fn host_robot(robot: &RobotSpec) -> anyhow::Result<&'static HostRobot> {
    ROBOTS.iter().find(|e| e.robot == robot).ok_or_else(|| {
        anyhow::anyhow!("robot {} (definition {:08x}) is none the host simulates", robot.name, robot.definition_hash())
    })
}

/// A robot's rules behind a pointer, so that one controller type drives
/// any robot on the host (the firmware knows its robot's type at build
/// time).
pub struct DynRules(pub Box<dyn RobotRules + Send>);

impl RobotRules for DynRules {
    fn spec(&self) -> &'static RobotSpec {
        self.0.spec()
    }
    fn start_episode(&mut self) {
        self.0.start_episode()
    }
    fn sense(&mut self, sensed: &Sensed) {
        self.0.sense(sensed)
    }
    fn observe(&self, obs: &mut [f32; MAX_STATE_DIMS]) -> usize {
        self.0.observe(obs)
    }
    fn reward(&self, applied: &PerServo) -> f32 {
        self.0.reward(applied)
    }
    fn absorbing(&self) -> bool {
        self.0.absorbing()
    }
    fn commands(&self, output: &[f32], volts: &mut PerServo) {
        self.0.commands(output, volts)
    }
    fn reset_commands(&self, volts: &mut PerServo) {
        self.0.reset_commands(volts)
    }
    fn gear_torques(&self, applied: &PerServo, torques: &mut PerServo) {
        self.0.gear_torques(applied, torques)
    }
    fn begin_reset(&mut self) {
        self.0.begin_reset()
    }
    fn reset_done(&mut self) -> bool {
        self.0.reset_done()
    }
    fn footstep(&self) -> bool {
        self.0.footstep()
    }
    fn walked_m(&self) -> Option<f32> {
        self.0.walked_m()
    }
}

/// The rig a board trial of `robot` runs against (`pada run --board`): the
/// physical pendulum's model with an operator who stops it between
/// episodes, or the rapier3d LEO with its operator.
pub fn board_rig(robot: &RobotSpec) -> anyhow::Result<Box<dyn Rig>> {
    Ok(match host_robot(robot)?.body {
        Body::Leo => Box::new(LeoRig::new(ModelOptions::default())?),
        Body::Pendulum => Box::new(PendulumRig::with_operator(PhysicalPendulumParams::default())),
    })
}

/// The rig behind the emulated bus of `pada sil`: the physical pendulum's
/// model, swinging freely between episodes as on the real rig; or the
/// rapier3d LEO with its operator.
pub fn sil_rig(robot: &RobotSpec) -> anyhow::Result<Box<dyn Rig>> {
    Ok(match host_robot(robot)?.body {
        Body::Leo => Box::new(LeoRig::new(ModelOptions::default())?),
        Body::Pendulum => Box::new(PendulumRig::new(PhysicalPendulumParams::default())),
    })
}

/// The task of `profile`'s robot as the runner describes it, with
/// `profile`'s table (`pada run --board`: the summary's keys and
/// parameters are `pada run`'s).
pub fn board_task_spec(profile: LearnerProfile) -> anyhow::Result<TaskSpec> {
    Ok(match host_robot(profile.robot)?.body {
        Body::Leo => LeoTask::with_profile(profile, leo_params()).spec().clone(),
        Body::Pendulum => PhysicalPendulumTask::with_profile(PhysicalPendulumParams::default(), profile).spec().clone(),
    })
}

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
/// robot ([`ROBOTS`]).
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
    /// order of [`ROBOTS`] (a test checks it).
    pub const ALL: [TaskName; 3] = [TaskName::Pendulum, TaskName::PhysicalPendulum, TaskName::Leo];

    /// The robot this task simulates; `None` for the simulated pendulum.
    pub fn robot(self) -> Option<&'static RobotSpec> {
        ROBOTS.iter().find(|e| e.task == Some(self)).map(|e| e.robot)
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

/// The robots `pada sil` runs, by the names `pada sil --task` and
/// `cargo xtask --robot` give them. `pendulum` here is the physical
/// pendulum (robot `physical-pendulum`, also accepted by that name), not
/// `pada run --task pendulum`'s simulated one.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum SilTask {
    /// The physical pendulum at 33 Hz (robot `physical-pendulum`) against
    /// the host's model of it.
    Pendulum,
    /// LEO (robot `leo`) against the rapier3d LEO.
    Leo,
}

impl SilTask {
    /// Every robot `pada sil` runs.
    pub const ALL: [SilTask; 2] = [SilTask::Pendulum, SilTask::Leo];

    /// The firmware's robot.
    pub fn robot(self) -> &'static RobotSpec {
        ROBOTS.iter().find(|e| e.sil == Some(self)).map_or(&pendulum::SPEC_33HZ, |e| e.robot)
    }

    /// The name on the command line (and `cargo xtask --robot`'s).
    pub fn name(self) -> &'static str {
        match self {
            SilTask::Pendulum => "pendulum",
            SilTask::Leo => "leo",
        }
    }

    /// The board each robot is built for when `--board` is not given: the
    /// F405 for the pendulum, the F429I-DISC1 with its SDRAM for LEO.
    pub fn default_board(self) -> Board {
        host_robot(self.robot()).map_or(Board::F405, |e| e.default_board)
    }

    /// The robot behind the bus ([`sil_rig`]).
    pub fn rig(self) -> anyhow::Result<Box<dyn Rig>> {
        sil_rig(self.robot())
    }

    fn help(self) -> &'static str {
        match self {
            SilTask::Pendulum => "the physical pendulum (robot physical-pendulum; not `pada run --task pendulum`, the simulated one) against its model",
            SilTask::Leo => "LEO against the rapier3d LEO, with an operator who sets it up between episodes",
        }
    }
}

impl clap::ValueEnum for SilTask {
    fn value_variants<'a>() -> &'a [Self] {
        &SilTask::ALL
    }

    fn to_possible_value(&self) -> Option<PossibleValue> {
        let value = PossibleValue::new(self.name()).help(self.help());
        // The robot's own name is accepted too, so one name means one robot.
        Some(if self.robot().name == self.name() { value } else { value.alias(self.robot().name) })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_robot_has_one_entry_in_the_order_of_the_core() {
        let ours: Vec<&RobotSpec> = ROBOTS.iter().map(|e| e.robot).collect();
        let core: Vec<&RobotSpec> = pada_core::robot::registry::specs().collect();
        assert_eq!(ours, core);
        for robot in core {
            assert_eq!(host_robot(robot).unwrap().robot, robot);
            let rules = (host_robot(robot).unwrap().rules)();
            assert_eq!(rules.spec(), robot, "{}'s rules are its own", robot.name);
        }
        assert!(host_robot(&pada_core::robot::RobotSpec { name: "mine", ..leo::SPEC }).is_err());
    }

    #[test]
    fn the_task_list_is_the_simulated_pendulum_and_the_registrys_tasks() {
        let from_registry: Vec<TaskName> = ROBOTS.iter().filter_map(|e| e.task).collect();
        assert_eq!(TaskName::ALL[0], TaskName::Pendulum);
        assert_eq!(TaskName::ALL[1..], from_registry[..]);
        assert_eq!(TaskName::Pendulum.robot(), None);
        for task in &TaskName::ALL[1..] {
            let robot = task.robot().expect("a robot");
            assert_eq!(task.name(), robot.name, "a robot's task is named as the robot");
        }
        let names: Vec<&str> = TaskName::ALL.iter().map(|t| t.name()).collect();
        assert_eq!(names, ["pendulum", "physical-pendulum", "leo"]);
    }

    #[test]
    fn the_sil_list_is_the_registrys() {
        let from_registry: Vec<SilTask> = ROBOTS.iter().filter_map(|e| e.sil).collect();
        assert_eq!(SilTask::ALL[..], from_registry[..]);
        assert_eq!(SilTask::Pendulum.robot(), &pendulum::SPEC_33HZ);
        assert_eq!(SilTask::Leo.robot(), &leo::SPEC);
        assert_eq!((SilTask::Pendulum.default_board(), SilTask::Leo.default_board()), (Board::F405, Board::F429Sdram));
        use clap::ValueEnum;
        assert_eq!(SilTask::from_str("physical-pendulum", false), Ok(SilTask::Pendulum));
        assert_eq!(SilTask::from_str("pendulum", false), Ok(SilTask::Pendulum));
        assert_eq!(TaskName::from_str("physical-pendulum", false), Ok(TaskName::PhysicalPendulum));
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
