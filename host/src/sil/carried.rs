//! Which servos the emulated board's bus carries: Dynamixel servos on
//! Protocol 1.0 (the RX-28, `super::bus`) and 2.0 (the X series,
//! `super::bus_v2`), not Feetech's. A robot with a Feetech joint is
//! refused before the run, naming the joint, rather than meeting servos
//! that answer as another model.

use pada_core::robot::RobotSpec;
use pada_core::servo::ServoProtocol;

/// `Ok` if every joint's servo is emulated; otherwise the first that is
/// not, and where the robot runs instead.
pub fn check_servos(robot: &RobotSpec) -> Result<(), String> {
    match robot.joints.iter().find(|j| j.servo.protocol == ServoProtocol::Feetech) {
        Some(j) => Err(format!(
            "joint {}: its {} speaks Feetech's protocol, which the emulated board's bus does not emulate (valid in `pada sil`: Dynamixel servos); `pada run --board` and `pada drive` run it",
            j.name, j.servo.name
        )),
        None => Ok(()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::pendulum::PhysicalPendulumParams;
    use crate::rig::PendulumRig;
    use crate::sil::bus::BusEmulator;

    #[test]
    fn a_feetech_joint_is_refused_naming_it_and_dynamixel_robots_pass() {
        let arm2 = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples/robots/arm2");
        assert_eq!(check_servos(pada_robot_file::load(&arm2.join("robot.toml")).unwrap().spec), Ok(()));
        assert_eq!(check_servos(&pada_core::robot::leo::SPEC), Ok(()));
        // The arm with its elbow on an STS3215, as a robot.toml says it.
        let dir = tempfile::tempdir().unwrap();
        let toml = std::fs::read_to_string(arm2.join("robot.toml")).unwrap().replace("\"XL430-W250\"", "\"STS3215\"");
        std::fs::write(dir.path().join("robot.toml"), toml).unwrap();
        std::fs::copy(arm2.join("arm2.urdf"), dir.path().join("arm2.urdf")).unwrap();
        let spec = pada_robot_file::load(&dir.path().join("robot.toml")).unwrap().spec;
        let e = check_servos(spec).unwrap_err();
        assert!(e.contains("joint elbow") && e.contains("STS3215") && e.contains("Feetech") && e.contains("pada drive"), "{e}");
        let rig = PendulumRig::new(PhysicalPendulumParams::default());
        assert_eq!(BusEmulator::new(&rig, spec, vec![]).unwrap_err(), e);
    }
}
