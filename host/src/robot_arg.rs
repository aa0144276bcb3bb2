//! `--robot R`: a robot on the command line of `pada drive` and `pada
//! servos`, parsed in one place. Today `R` is a built-in robot's name
//! (`pada_core::robot::registry`: `pendulum`, `pendulum-20hz`, `leo`, or
//! their definitions' names); a `robot.toml` path is the obvious next
//! case of [`RobotArg::parse`] (a path names a file, a name a built-in
//! robot), and everything after parsing takes a [`RobotArg`].
//!
//! `--servo MODEL` re-equips every joint with another servo model (the
//! built-in pendulum on an XM430-W350 instead of its discontinued RX-28):
//! the same robot, physics and rules, another definition (its hash
//! differs, so its learner and checkpoints are its own). Each joint keeps
//! its angle for a count: its zero moves to the same angle in the new
//! model's counts.

use crate::rig::Rig;
use crate::robots::{built_in, from_file, Body, DynRules, SimRobot};
use pada_core::robot::pendulum::Pendulum;
use pada_core::robot::{registry, JointSpec, RobotSpec};
use pada_core::servo::{PositionScale, ServoModel};
use std::path::Path;

/// A robot as the command line names it.
#[derive(Debug, Clone)]
pub struct RobotArg {
    /// Its definition (a re-equipped one with `--servo`).
    pub spec: &'static RobotSpec,
    /// What was written.
    pub given: String,
    /// The servo model every joint was re-equipped with, if any.
    pub servo: Option<&'static ServoModel>,
    /// The simulator's entry of the robot as named (before `--servo`).
    sim: SimRobot,
}

impl RobotArg {
    /// Parses `--robot`'s value: a built-in robot's name, or the path of a
    /// robot's `robot.toml` (anything with a `/` or ending in `.toml`),
    /// read and checked with its URDF by `pada_robot_file`.
    pub fn parse(s: &str) -> Result<RobotArg, String> {
        if let Some(b) = registry::find(s) {
            let sim = built_in(b.spec).ok_or_else(|| format!("--robot {s}: the simulator has no body for it"))?;
            return Ok(RobotArg { spec: b.spec, given: s.to_string(), servo: None, sim });
        }
        if s.ends_with(".toml") || s.contains('/') {
            let file = pada_robot_file::load(Path::new(s)).map_err(|e| format!("--robot: {e}"))?;
            let sim = from_file(&file).map_err(|e| format!("--robot {s}: {e}"))?;
            return Ok(RobotArg { spec: file.spec, given: s.to_string(), servo: None, sim });
        }
        let valid: Vec<&str> = registry::names().collect();
        Err(format!("--robot {s}: unknown robot; valid are {}, or the path of a robot.toml", valid.join(", ")))
    }

    /// The clap parser of `--robot`.
    pub fn parser() -> impl clap::builder::TypedValueParser<Value = RobotArg> {
        |s: &str| RobotArg::parse(s)
    }

    /// The same robot with every joint's servo of `model` (`--servo`).
    pub fn with_servo(self, model: &'static ServoModel) -> Result<RobotArg, String> {
        if !matches!(self.sim.body, Body::Pendulum) {
            return Err(format!(
                "--servo {}: only the pendulum's rules take another servo (a robot of files names its servos in its robot.toml, LEO's rules are written for its RX-28s); valid robots: pendulum, pendulum-20hz",
                model.name
            ));
        }
        let joints: Vec<JointSpec> = self.spec.joints.iter().map(|j| reequip(j, model)).collect();
        let joints: &'static [JointSpec] = Box::leak(joints.into_boxed_slice());
        let spec: &'static RobotSpec = Box::leak(Box::new(RobotSpec { joints, ..*self.spec }));
        Ok(RobotArg { spec, servo: Some(model), ..self })
    }

    /// The simulator's entry of the robot's body.
    pub fn sim(&self) -> &SimRobot {
        &self.sim
    }

    /// Its rules, for its own definition.
    pub fn rules(&self) -> Result<DynRules, String> {
        if self.sim.robot == self.spec {
            return Ok(self.sim.rules());
        }
        match self.sim.body {
            // The pendulum's rules take any definition of it.
            Body::Pendulum => Ok(DynRules(Box::new(Pendulum::new(self.spec)))),
            _ => Err(format!("--robot {}: its rules are for its own definition", self.given)),
        }
    }

    /// The robot behind virtual servos: the body `pada run --board` runs
    /// (the pendulum with an operator who stops it when called, LEO and a
    /// robot of files with theirs).
    pub fn rig(&self) -> Result<Box<dyn Rig>, String> {
        self.sim.board_rig().map_err(|e| e.to_string())
    }
}

/// `j` with a servo of `model`, its zero at the same angle in the new
/// model's counts.
fn reequip(j: &JointSpec, model: &'static ServoModel) -> JointSpec {
    let centre = |scale: PositionScale| match scale {
        PositionScale::Span { max, .. } => (max as f64 / 2.0).ceil(),
        PositionScale::Turns { per_turn } => per_turn as f64 / 2.0,
    };
    let (old, new) = (j.servo.encoding.position, model.encoding.position);
    let offset_rad = (j.zero as f64 - centre(old)) * old.unit_rad() as f64;
    let zero = (centre(new) + offset_rad / new.unit_rad() as f64).round().clamp(0.0, u16::MAX as f64) as u16;
    JointSpec { servo: model, zero, ..*j }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_paths_and_servos() {
        let p = RobotArg::parse("pendulum").unwrap();
        assert_eq!(p.spec.name, "physical-pendulum");
        assert_eq!(RobotArg::parse("physical-pendulum").unwrap().spec, p.spec);
        let e = RobotArg::parse("arm2").unwrap_err();
        assert!(e.contains("unknown robot") && e.contains("pendulum") && e.contains("leo"), "{e}");
        let missing = RobotArg::parse("no/such/robot.toml").unwrap_err();
        assert!(missing.contains("no/such/robot.toml") && !missing.contains('\n'), "{missing}");
        let x = p.clone().with_servo(&pada_core::servo::XM430_W350).unwrap();
        assert_eq!((x.spec.joints[0].zero, x.spec.joints[0].servo.name), (2048, "XM430-W350"));
        assert_ne!(x.spec.definition_hash(), p.spec.definition_hash());
        assert_eq!(x.rules().unwrap().0.spec(), x.spec);
        assert!(RobotArg::parse("leo").unwrap().with_servo(&pada_core::servo::XM430_W350).is_err());
        // A robot of files: its own servos (Protocol 2.0 on the arm).
        let arm = concat!(env!("CARGO_MANIFEST_DIR"), "/../examples/robots/arm2/robot.toml");
        let arm = RobotArg::parse(arm).unwrap();
        assert_eq!(arm.spec.name, "arm2");
        let models: Vec<&str> = arm.spec.joints.iter().map(|j| j.servo.name).collect();
        assert_eq!(models, ["XM430-W350", "XL430-W250"]);
        assert!(arm.rig().is_ok());
        assert_eq!(arm.rules().unwrap().0.spec(), arm.spec);
    }
}
