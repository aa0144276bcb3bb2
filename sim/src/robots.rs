//! The simulator's side of the robots pada brings: one entry per robot of
//! the core's registry (`pada_core::robot::registry`) with the body that
//! simulates it, its rules, and the board its firmware is built for by
//! default; and the rigs and tasks built from them.

use crate::leo::model::ModelOptions;
use crate::leo::rl::{leo_params, LeoTask};
use crate::pendulum::{PhysicalPendulumParams, PhysicalPendulumTask};
use crate::rig::{LeoRig, PendulumRig, Rig};
use crate::task::{Task, TaskSpec};
use crate::urdf::{UrdfModel, UrdfRig, UrdfTask};
use pada_core::limits::MAX_STATE_DIMS;
use pada_core::profile::{Board, LearnerProfile};
use pada_core::robot::leo::{self, Leo};
use pada_core::robot::pendulum::{self, Pendulum};
use pada_core::robot::{PerServo, RobotRules, RobotSpec, Sensed, Vocab};
use pada_robot_file::RobotFile;
use std::sync::Arc;

/// The simulated body behind a robot's servos: pada's two hand-built
/// models, or a robot of files' URDF.
#[derive(Clone)]
pub enum Body {
    /// The physical pendulum's model (`crate::pendulum::physical`).
    Pendulum,
    /// The rapier3d LEO (`crate::leo`).
    Leo,
    /// A robot of files: its URDF in rapier (`crate::urdf`).
    Urdf(Arc<UrdfModel>),
}

impl std::fmt::Debug for Body {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Body::Pendulum => "Pendulum",
            Body::Leo => "Leo",
            Body::Urdf(_) => "Urdf",
        })
    }
}

/// How the simulator runs one robot: one of pada's ([`built_in`]) or a
/// robot of files ([`from_file`]).
#[derive(Debug, Clone)]
pub struct SimRobot {
    /// The robot.
    pub robot: &'static RobotSpec,
    /// The board its firmware is built for when `--board` is not given.
    pub default_board: Board,
    /// The body that simulates it.
    pub body: Body,
}

/// The body and default board of each of pada's robots, in the order of
/// the core's registry (a test checks it).
const BUILT_IN: [(&RobotSpec, Board, fn() -> Body); 3] = [
    (&pendulum::SPEC_33HZ, Board::F405, || Body::Pendulum),
    (&pendulum::SPEC_20HZ, Board::F405, || Body::Pendulum),
    (&leo::SPEC, Board::F429Sdram, || Body::Leo),
];

/// The simulator's entry of one of pada's own robots.
pub fn built_in(robot: &RobotSpec) -> Option<SimRobot> {
    BUILT_IN.iter().find(|(r, ..)| *r == robot).map(|(r, board, body)| SimRobot { robot: r, default_board: *board, body: body() })
}

/// Every one of pada's robots, in the core registry's order.
pub fn built_ins() -> impl Iterator<Item = SimRobot> {
    BUILT_IN.iter().map(|(r, board, body)| SimRobot { robot: r, default_board: *board, body: body() })
}

/// The simulator's entry of `robot` if it is one of pada's, or why not.
pub fn sim_robot(robot: &RobotSpec) -> anyhow::Result<SimRobot> {
    built_in(robot).ok_or_else(|| {
        anyhow::anyhow!("robot {} (definition {:08x}) is none of pada's own: give its robot.toml", robot.name, robot.definition_hash())
    })
}

/// The simulator's entry of a robot of files: its URDF, read and checked.
pub fn from_file(file: &RobotFile) -> anyhow::Result<SimRobot> {
    Ok(SimRobot { robot: file.spec, default_board: Board::F405, body: Body::Urdf(Arc::new(UrdfModel::load(file)?)) })
}

impl SimRobot {
    /// Its rules, before the first reading.
    pub fn rules(&self) -> DynRules {
        DynRules(match &self.body {
            Body::Pendulum => Box::new(Pendulum::new(self.robot)),
            Body::Leo => Box::new(Leo::new()),
            // A robot of files was checked when it was read.
            Body::Urdf(_) => Box::new(Vocab::new(self.robot).unwrap_or_else(|e| unreachable!("checked at load: {e}"))),
        })
    }

    /// The rig a board trial runs against (`pada run --board`): the
    /// physical pendulum's model with an operator who stops it between
    /// episodes, the rapier3d LEO with its operator, or a robot of files
    /// with one.
    pub fn board_rig(&self) -> anyhow::Result<Box<dyn Rig>> {
        Ok(match &self.body {
            Body::Leo => Box::new(LeoRig::new(ModelOptions::default())?),
            Body::Pendulum => Box::new(PendulumRig::with_operator(PhysicalPendulumParams::default())),
            Body::Urdf(model) => Box::new(UrdfRig::of_model(model)?),
        })
    }

    /// The rig behind the emulated bus of `pada sil`: the physical
    /// pendulum's model swinging freely between episodes, as on the real
    /// rig; the others as [`board_rig`](Self::board_rig).
    pub fn sil_rig(&self) -> anyhow::Result<Box<dyn Rig>> {
        Ok(match &self.body {
            Body::Pendulum => Box::new(PendulumRig::new(PhysicalPendulumParams::default())),
            _ => self.board_rig()?,
        })
    }

    /// Its task as the runner describes it with `profile`'s table (`pada
    /// run --board`: the summary's keys and parameters are `pada run`'s).
    pub fn task_spec(&self, profile: LearnerProfile) -> anyhow::Result<TaskSpec> {
        Ok(match &self.body {
            Body::Leo => LeoTask::with_profile(profile, leo_params()).spec().clone(),
            Body::Pendulum => PhysicalPendulumTask::with_profile(PhysicalPendulumParams::default(), profile).spec().clone(),
            Body::Urdf(model) => UrdfTask::of_model(model, profile).spec().clone(),
        })
    }
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_robot_has_one_entry_in_the_order_of_the_core() {
        let ours: Vec<&RobotSpec> = built_ins().map(|e| e.robot).collect();
        let core: Vec<&RobotSpec> = pada_core::robot::registry::specs().collect();
        assert_eq!(ours, core);
        for robot in core {
            assert_eq!(sim_robot(robot).unwrap().robot, robot);
            let rules = sim_robot(robot).unwrap().rules();
            assert_eq!(rules.spec(), robot, "{}'s rules are its own", robot.name);
        }
        assert!(sim_robot(&pada_core::robot::RobotSpec { name: "mine", ..leo::SPEC }).is_err());
    }
}
