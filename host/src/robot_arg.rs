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

use crate::robots::{sim_robot, Body, DynRules, SimRobot, ROBOTS};
use crate::rig::Rig;
use pada_core::robot::pendulum::Pendulum;
use pada_core::robot::{registry, JointSpec, RobotSpec};
use pada_core::servo::{PositionScale, ServoModel};

/// A robot as the command line names it.
#[derive(Debug, Clone, Copy)]
pub struct RobotArg {
    /// Its definition.
    pub spec: &'static RobotSpec,
    /// What was written.
    pub given: &'static str,
    /// The servo model every joint was re-equipped with, if any.
    pub servo: Option<&'static ServoModel>,
}

impl RobotArg {
    /// Parses `--robot`'s value: a built-in robot's name. A path to a
    /// robot file is refused with what to do for now.
    pub fn parse(s: &str) -> Result<RobotArg, String> {
        if let Some(b) = registry::find(s) {
            let given: &'static str = Box::leak(s.to_string().into_boxed_str());
            return Ok(RobotArg { spec: b.spec, given, servo: None });
        }
        let valid: Vec<&str> = registry::names().collect();
        if s.ends_with(".toml") || s.contains('/') {
            return Err(format!(
                "--robot {s}: robots from files (robot.toml) are not read by this version yet; valid are the built-in robots {}",
                valid.join(", ")
            ));
        }
        Err(format!("--robot {s}: unknown robot; valid are {}", valid.join(", ")))
    }

    /// The clap parser of `--robot`.
    pub fn parser() -> impl clap::builder::TypedValueParser<Value = RobotArg> {
        |s: &str| RobotArg::parse(s)
    }

    /// The same robot with every joint's servo of `model` (`--servo`).
    pub fn with_servo(self, model: &'static ServoModel) -> Result<RobotArg, String> {
        if self.sim()?.body == Body::Leo {
            return Err(format!(
                "--servo {}: LEO's rules are written for its RX-28s; --servo re-equips the pendulum (valid robots: pendulum, pendulum-20hz)",
                model.name
            ));
        }
        let joints: Vec<JointSpec> = self.spec.joints.iter().map(|j| reequip(j, model)).collect();
        let joints: &'static [JointSpec] = Box::leak(joints.into_boxed_slice());
        let spec: &'static RobotSpec = Box::leak(Box::new(RobotSpec { joints, ..*self.spec }));
        Ok(RobotArg { spec, given: self.given, servo: Some(model) })
    }

    /// The simulator's entry of the robot (by name: a re-equipped robot is
    /// the same body).
    fn sim(&self) -> Result<&'static SimRobot, String> {
        sim_robot(self.spec)
            .ok()
            .or_else(|| ROBOTS.iter().find(|e| e.robot.name == self.spec.name))
            .ok_or_else(|| format!("--robot {}: the simulator has no body for it", self.given))
    }

    /// Its rules, for its own definition.
    pub fn rules(&self) -> Result<DynRules, String> {
        let sim = self.sim()?;
        if sim.robot == self.spec {
            return Ok((sim.rules)());
        }
        match sim.body {
            // The pendulum's rules take any definition of it.
            Body::Pendulum => Ok(DynRules(Box::new(Pendulum::new(self.spec)))),
            Body::Leo => Err(format!("--robot {}: LEO's rules are for its own definition", self.given)),
        }
    }

    /// The robot behind virtual servos: the body `pada run --board` runs
    /// (the pendulum with an operator who stops it when called, LEO with
    /// its own).
    pub fn rig(&self) -> Result<Box<dyn Rig>, String> {
        crate::robots::board_rig(self.sim()?.robot).map_err(|e| e.to_string())
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
        assert!(RobotArg::parse("examples/robots/arm2/robot.toml").unwrap_err().contains("robot.toml"));
        let x = p.with_servo(&pada_core::servo::XM430_W350).unwrap();
        assert_eq!((x.spec.joints[0].zero, x.spec.joints[0].servo.name), (2048, "XM430-W350"));
        assert_ne!(x.spec.definition_hash(), p.spec.definition_hash());
        assert_eq!(x.rules().unwrap().0.spec(), x.spec);
        assert!(RobotArg::parse("leo").unwrap().with_servo(&pada_core::servo::XM430_W350).is_err());
    }
}
