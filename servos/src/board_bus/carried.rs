//! Which servos the emulated board's bus carries: Dynamixel servos on
//! Protocol 1.0 (the RX-28, [`super`]) and 2.0 (the X series,
//! [`super::v2`]), and Feetech's STS3215 ([`super::ft`]). A robot
//! with another Feetech model is refused before the run, naming the joint,
//! rather than meeting servos that answer as another model.

use pada_core::feetech::control_table::sts3215::STS3215_MODEL;
use pada_core::robot::RobotSpec;
use pada_core::servo::ServoProtocol;

/// `Ok` if every joint's servo is emulated; otherwise the first that is
/// not, and where the robot runs instead.
pub fn check_servos(robot: &RobotSpec) -> Result<(), String> {
    match robot.joints.iter().find(|j| j.servo.protocol == ServoProtocol::Feetech && j.servo.model_number != STS3215_MODEL) {
        Some(j) => Err(format!(
            "joint {}: its {} is a Feetech model the emulated board's bus does not emulate (valid in `pada sil`: Dynamixel servos and the STS3215); `pada run --board` runs it",
            j.name, j.servo.name
        )),
        None => Ok(()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use pada_sim::pendulum::PhysicalPendulumParams;
    use pada_sim::rig::PendulumRig;
    use super::super::BusEmulator;

    #[test]
    fn dynamixel_robots_and_sts3215s_pass() {
        let arm2 = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples/robots/arm2");
        assert_eq!(check_servos(pada_robot_file::load(&arm2.join("robot.toml")).unwrap().spec), Ok(()));
        assert_eq!(check_servos(&pada_core::robot::leo::SPEC), Ok(()));
        let so101 = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples/robots/so101/robot.toml");
        let spec = pada_robot_file::load(&so101).unwrap().spec;
        assert_eq!(check_servos(spec), Ok(()));
        let rig = PendulumRig::new(PhysicalPendulumParams::default());
        assert!(BusEmulator::new(&rig, spec, vec![]).is_ok());
    }
}
