//! Whether a board can read a robot's joints where its episodes start.
//!
//! The board reads each joint as its servo's position counts and turns them
//! into an angle with the joint's calibration, in the servo model's units
//! (`JointSpec::angle_of`: 1023 counts over 300° on an RX-28, 4096 a turn
//! on the X series); a simulated servo reports the counts of its angle the
//! same way (`JointSpec::counts_of`), clamped to an absolute sensor's range.
//! A calibration whose zero count lies past that range reads every angle
//! as the range's end: the robot faults on a soft limit at its first
//! reading and never starts an episode, on `pada run --board` as in `pada
//! sil`. This is refused before the run, naming the joint.

use pada_core::robot::RobotSpec;

/// `Ok` if every joint's start angle reads back within one position count;
/// otherwise the first joint that does not, and why. A robot whose rules
/// are code (pada's own) has no start angles here and is not checked.
pub fn check_readable(robot: &RobotSpec) -> Result<(), String> {
    let Some(words) = robot.vocabulary else { return Ok(()) };
    for (joint, &start) in robot.joints.iter().zip(words.start) {
        let read = joint.angle_of(joint.counts_of(start as f64));
        // One count, from the calibration (the unit is the servo's).
        let count = (joint.angle_of(1) - joint.angle_of(0)).abs();
        if (read - start).abs() > count {
            let (low, high) = (joint.counts_of(-1e9), joint.counts_of(1e9));
            let (low, high) = (low.min(high), low.max(high));
            return Err(format!(
                "joint {}: its start angle {start} rad reads back as {read:.3} rad through its {}'s position counts \
                 (zero count {}; the board reads counts {low}..={high}): give a zero count inside that range",
                joint.name, joint.servo.name, joint.zero
            ));
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use pada_core::robot::{leo, pendulum};

    #[test]
    fn a_zero_count_past_the_range_is_refused_and_pada_s_robots_pass() {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples/robots/arm2/robot.toml");
        let arm = pada_robot_file::load(&path).unwrap();
        // As written: X-series servos centred at 2048 of their 4096 counts
        // a turn, which the board reads in the X series' own units.
        assert_eq!(check_readable(arm.spec), Ok(()));
        // The same arm on RX-28s: 2048 is past their 0..=1023.
        let joints: Vec<_> = arm.spec.joints.iter().map(|j| pada_core::robot::JointSpec { servo: &pada_core::servo::RX28, ..*j }).collect();
        let spec = RobotSpec { joints: Box::leak(joints.into_boxed_slice()), ..*arm.spec };
        let e = check_readable(&spec).unwrap_err();
        assert!(e.contains("joint shoulder") && e.contains("RX-28") && e.contains("zero count 2048") && e.contains("0..=1023"), "{e}");
        // Re-centred inside the RX-28's range.
        let joints: Vec<_> = spec.joints.iter().map(|j| pada_core::robot::JointSpec { zero: 512, ..*j }).collect();
        let spec = RobotSpec { joints: Box::leak(joints.into_boxed_slice()), ..spec };
        assert_eq!(check_readable(&spec), Ok(()));
        for robot in [&pendulum::SPEC_33HZ, &pendulum::SPEC_20HZ, &leo::SPEC] {
            assert_eq!(check_readable(robot), Ok(()));
        }
    }
}
