//! The body of a robot of files against the kinematics its rules use and
//! against its servos' models.

use super::*;
use crate::task::{Plant, Task};
use pada_core::limits::MAX_SERVOS;
use pada_core::robot::RobotRules;
use std::path::Path;

fn reacher() -> pada_robot_file::RobotFile {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../robot-file/tests/data/reacher/robot.toml");
    pada_robot_file::load(&path).unwrap()
}

#[test]
fn rapier_puts_the_tip_where_the_rules_kinematics_do() {
    let robot = reacher();
    let model = UrdfModel::load(&robot).unwrap();
    let mut body = UrdfBody::new(&model).unwrap();
    let tip = robot.vocabulary().points[0];
    for q in [[0.0f32, 0.0], [0.4, -0.9], [-1.1, 1.7], [1.5, 0.3]] {
        body.reset_to(&q).unwrap();
        let angles = body.angles();
        assert!((angles[0] - q[0]).abs() < 1e-5 && (angles[1] - q[1]).abs() < 1e-5, "{angles:?} vs {q:?}");
        let from_rapier = body.link_point(1, tip.offset).unwrap();
        let from_rules = tip.position(&q);
        for a in 0..3 {
            assert!((from_rapier[a] - from_rules[a]).abs() < 1e-5, "at {q:?}: rapier {from_rapier:?}, rules {from_rules:?}");
        }
    }
}

/// The shoulder's rate after two periods of 2 V from the top, stepped
/// `substeps` times a period with `iterations` solver iterations.
fn rate_after_two_periods(model: &UrdfModel) -> f32 {
    let mut body = UrdfBody::new(model).unwrap();
    let mut volts = [0.0; MAX_SERVOS];
    volts[0] = 2.0;
    body.set_voltages(&volts);
    for _ in 0..2 {
        body.step_period().unwrap();
    }
    body.rates()[0]
}

#[test]
fn a_held_voltage_turns_the_joint_as_its_servo_model_says() {
    // No gravity on the shoulder at its start (the arm straight up): a
    // constant 2 V drives it towards the servo's no-load speed at 2 V; in
    // a servo this damped the joint reaches it within a few periods.
    // Stepped finely, so that what is tested is the servo's model.
    let robot = reacher();
    let fine = UrdfModel::load(&robot).unwrap().with_steps(16, 4);
    let motor = robot.spec.joints[0].servo.motor();
    let no_load = motor.no_load_speed(2.0);
    let rate = rate_after_two_periods(&fine);
    assert!(rate > 0.0, "a positive voltage turns the joint positively: {rate}");
    // The arm tipping forward is helped a little by gravity; in two
    // periods it has barely left the top, so it turns at no-load speed to
    // within 1 %.
    assert!((rate - no_load).abs() < 0.01 * no_load, "{rate} rad/s against no-load {no_load}");
    // The gears carry the motor's torque less its back-EMF.
    let mut body = UrdfBody::new(&fine).unwrap();
    let mut volts = [0.0; MAX_SERVOS];
    volts[0] = 2.0;
    body.set_voltages(&volts);
    body.step_period().unwrap();
    let t = body.gear_torques()[0];
    assert!(t.abs() < motor.stall_torque(2.0), "{t}");
}

#[test]
fn the_default_step_keeps_the_servo_speed_within_three_percent() {
    // A robot.toml's default, one step a period with two solver
    // iterations, trades accuracy for speed (docs/your-robot.md): the
    // speed it reaches stays within 3 % of the fine step's (measured 2 %).
    let robot = reacher();
    let model = UrdfModel::load(&robot).unwrap();
    let coarse = rate_after_two_periods(&model);
    let fine = rate_after_two_periods(&model.with_steps(16, 4));
    assert!((coarse - fine).abs() < 0.03 * fine, "default {coarse} rad/s against fine {fine}");
}

#[test]
fn the_task_learns_on_the_rules_and_reports_the_servos_torques() {
    let robot = reacher();
    let task = UrdfTask::new(&robot).unwrap();
    let mut plant = task.plant();
    let mut rng = rand_pcg::Pcg32::new(1, 1);
    let mut obs = vec![0.0; task.spec().state.len()];
    plant.reset(&mut rng, &mut obs);
    assert_eq!(obs, [0.0, 0.0]);
    let step = plant.step(&[2.0, -2.0], &mut obs);
    assert!(obs[0] > 0.0 && obs[1] < 0.0, "{obs:?}");
    assert!(step.reward < 0.0 && step.reward.is_finite() && !step.terminal);
    let commanded = plant.commanded_torques(&[2.0, -2.0]);
    assert_eq!(commanded[0], robot.spec.joints[0].servo.motor().stall_torque(2.0));
    assert!(commanded[1] < 0.0);
    assert!(plant.gearbox_torques(&[2.0, -2.0])[..2].iter().all(|t| *t != 0.0));
    assert_eq!(plant.rules().spec().name, "reacher");
}

#[test]
fn a_joint_in_position_mode_follows_its_goal_through_the_servos_loop() {
    use pada_core::servo::{ControlMode, LoopGains, STS3215};
    // The reacher's shoulder under the STS3215's loop (LeRobot's gains):
    // the loop's voltage drives the shoulder's own motor model at the
    // robot's 12 V supply; the elbow stays in voltage mode at 0 V.
    let robot = reacher();
    let model = UrdfModel::load(&robot).unwrap().with_steps(16, 4);
    let mut body = UrdfBody::new(&model).unwrap();
    let spec = STS3215.position_loop(LoopGains::LEROBOT).expect("the STS3215 runs its own loop");
    assert!(body.set_control_mode(0, ControlMode::Position(spec)));
    assert!(!body.set_control_mode(MAX_SERVOS, ControlMode::Voltage));
    // Switched on, it holds where it is.
    body.step_period().unwrap();
    assert!(body.angles()[0].abs() * spec.counts_per_rad <= 1.5, "{}", body.angles()[0]);
    let mut goals = [0.0; MAX_SERVOS];
    goals[0] = 0.3;
    body.set_goals(&goals);
    body.step_period().unwrap();
    assert!(body.gear_torques()[0] > 0.0 && body.applied_voltages()[0] > 0.0);
    assert_eq!(body.applied_voltages()[1], 0.0, "the elbow is in voltage mode");
    for _ in 0..40 {
        body.step_period().unwrap();
    }
    let e = (body.angles()[0] - 0.3).abs();
    assert!(e < 0.02, "{} rad off the goal", e);
    assert!(body.rates()[0].abs() < 0.05, "{}", body.rates()[0]);
    // The goal flips: the first period's gear torque flips with it.
    goals[0] = -0.3;
    body.set_goals(&goals);
    body.step_period().unwrap();
    assert!(body.gear_torques()[0] < 0.0 && body.applied_voltages()[0] < 0.0);
    // A reset puts the loop back at rest, holding the start pose.
    body.reset().unwrap();
    body.step_period().unwrap();
    assert!(body.angles()[0].abs() < 0.01, "{}", body.angles()[0]);
}

#[test]
fn voltage_mode_is_what_it_was() {
    // The same voltages give the same angles and torques, bit for bit,
    // whether or not the body could run a position loop.
    use pada_core::servo::ControlMode;
    let robot = reacher();
    let model = UrdfModel::load(&robot).unwrap();
    let mut a = UrdfBody::new(&model).unwrap();
    let mut b = UrdfBody::new(&model).unwrap();
    assert!(b.set_control_mode(0, ControlMode::Voltage));
    let mut volts = [0.0; MAX_SERVOS];
    volts[0] = 3.0;
    volts[1] = -1.5;
    for body in [&mut a, &mut b] {
        body.set_voltages(&volts);
        for _ in 0..5 {
            body.step_period().unwrap();
        }
    }
    assert_eq!(a.angles().map(f32::to_bits), b.angles().map(f32::to_bits));
    assert_eq!(a.gear_torques().map(f32::to_bits), b.gear_torques().map(f32::to_bits));
    assert_eq!(a.applied_voltages(), volts);
}
