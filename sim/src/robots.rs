//! The simulator's side of the robots pada brings: one entry per robot of
//! the core's registry (`pada_core::robot::registry`) with the body that
//! simulates it, its rules, and the board its firmware is built for by
//! default; and the rigs and tasks built from them.

use crate::leo::model::ModelOptions;
use crate::leo::rl::{leo_params, LeoTask};
use crate::pendulum::{PhysicalPendulumParams, PhysicalPendulumTask};
use crate::rig::{LeoRig, PendulumRig, Rig};
use crate::task::{Task, TaskSpec};
use pada_core::limits::MAX_STATE_DIMS;
use pada_core::profile::{Board, LearnerProfile};
use pada_core::robot::leo::{self, Leo};
use pada_core::robot::pendulum::{self, Pendulum};
use pada_core::robot::{PerServo, RobotRules, RobotSpec, Sensed};

/// The simulated body behind a robot's servos: pada's two hand-built
/// models.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Body {
    /// The physical pendulum's model (`crate::pendulum::physical`).
    Pendulum,
    /// The rapier3d LEO (`crate::leo`).
    Leo,
}

/// How the simulator runs one robot.
#[derive(Debug, Clone, Copy)]
pub struct SimRobot {
    /// The robot.
    pub robot: &'static RobotSpec,
    /// The board its firmware is built for when `--board` is not given.
    pub default_board: Board,
    /// The body that simulates it.
    pub body: Body,
    /// Its rules, before the first reading.
    pub rules: fn() -> DynRules,
}

/// The simulator's entries, in the order of the core's registry (a test
/// checks it).
pub static ROBOTS: [SimRobot; 3] = [
    SimRobot {
        robot: &pendulum::SPEC_33HZ,
        default_board: Board::F405,
        body: Body::Pendulum,
        rules: || DynRules(Box::new(Pendulum::at_33hz())),
    },
    SimRobot {
        robot: &pendulum::SPEC_20HZ,
        default_board: Board::F405,
        body: Body::Pendulum,
        rules: || DynRules(Box::new(Pendulum::at_20hz())),
    },
    SimRobot {
        robot: &leo::SPEC,
        default_board: Board::F429Sdram,
        body: Body::Leo,
        rules: || DynRules(Box::new(Leo::new())),
    },
];

/// The entry of `robot`, if the simulator knows it.
pub fn sim_robot(robot: &RobotSpec) -> anyhow::Result<&'static SimRobot> {
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
    Ok(match sim_robot(robot)?.body {
        Body::Leo => Box::new(LeoRig::new(ModelOptions::default())?),
        Body::Pendulum => Box::new(PendulumRig::with_operator(PhysicalPendulumParams::default())),
    })
}

/// The rig behind the emulated bus of `pada sil`: the physical pendulum's
/// model, swinging freely between episodes as on the real rig; or the
/// rapier3d LEO with its operator.
pub fn sil_rig(robot: &RobotSpec) -> anyhow::Result<Box<dyn Rig>> {
    Ok(match sim_robot(robot)?.body {
        Body::Leo => Box::new(LeoRig::new(ModelOptions::default())?),
        Body::Pendulum => Box::new(PendulumRig::new(PhysicalPendulumParams::default())),
    })
}

/// The task of `profile`'s robot as the runner describes it, with
/// `profile`'s table (`pada run --board`: the summary's keys and
/// parameters are `pada run`'s).
pub fn board_task_spec(profile: LearnerProfile) -> anyhow::Result<TaskSpec> {
    Ok(match sim_robot(profile.robot)?.body {
        Body::Leo => LeoTask::with_profile(profile, leo_params()).spec().clone(),
        Body::Pendulum => PhysicalPendulumTask::with_profile(PhysicalPendulumParams::default(), profile).spec().clone(),
    })
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
            assert_eq!(sim_robot(robot).unwrap().robot, robot);
            let rules = (sim_robot(robot).unwrap().rules)();
            assert_eq!(rules.spec(), robot, "{}'s rules are its own", robot.name);
        }
        assert!(sim_robot(&pada_core::robot::RobotSpec { name: "mine", ..leo::SPEC }).is_err());
    }
}
