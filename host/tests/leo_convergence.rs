//! A converged LEO model. The passive fall does not depend on
//! the step, dry friction holds a joint whose load stays below it at any
//! step, and the stance foot does not slide on the floor.
//!
//! The measured values behind each bound are in `sim/src/leo/README.md`
//! ("Step size").

use pada::leo::constants::*;
use pada::leo::model::*;
use pada::leo::passive::passive_rollout;
use pada_core::rx28::Rx28;

fn model(f: impl FnOnce(&mut ModelOptions)) -> LeoModel {
    let mut o = ModelOptions::default();
    f(&mut o);
    LeoModel::new(o, &InitialPose::REFERENCE).expect("valid options")
}

/// Halving the physics step changes the passive fall (0 V on the learned
/// joints, the held joints on) by less than 5 % in time and by less than
/// 0.02 rad in torso angle at every control step until the fall (the
/// definition of converged). Measured at the default 4 × 1
/// against 8 × 1: both fall at step 24 (0.800 s); |φ| = 1 is reached at
/// 0.7705 s and 0.7727 s (−0.3 %); the torso angles differ by 0.0066 rad
/// at most.
#[test]
fn passive_fall_converges_with_the_step() {
    let coarse = ModelOptions::default();
    let fine = ModelOptions {
        substeps: 2 * coarse.substeps,
        ..coarse
    };
    let a = passive_rollout(coarse, 2.0).unwrap();
    let b = passive_rollout(fine, 2.0).unwrap();
    assert!(a.fell && b.fell, "the passive robot must fall within 2 s");
    assert_eq!((a.blow_ups, b.blow_ups), (0, 0));
    let (ta, tb) = (a.fall_time_s.unwrap(), b.fall_time_s.unwrap());
    assert!(
        ((ta - tb) / tb).abs() < 0.05,
        "fall time {ta} s at {} steps/period, {tb} s at {}",
        coarse.substeps,
        fine.substeps
    );
    let (ca, cb) = (
        a.torso_crossing_time(FALL_TORSO_ANGLE).unwrap(),
        b.torso_crossing_time(FALL_TORSO_ANGLE).unwrap(),
    );
    assert!(
        ((ca - cb) / cb).abs() < 0.05,
        "|φ| = 1 reached at {ca} s and {cb} s"
    );
    let d = a.largest_torso_angle_difference(&b);
    assert!(
        d < 0.02,
        "torso angles differ by up to {d} rad before the fall"
    );
}

/// Dry friction is stiction (§1.5): the shoulder, driven with a torque
/// below its 0.2 N m friction, stays at rest; above it, it slides at the
/// speed where friction and back-EMF balance the drive,
/// (τ − 0.2)/d with d the servo's damping. Torso welded, no gravity, no
/// floor; at 1, 4 and 40 physics steps per control period. Bound at rest:
/// 1 mrad in 3 s (the friction tie deflects 0.19 mrad under 0.19 N m);
/// sliding: within 2 % of the balance speed.
#[test]
fn dry_friction_holds_below_its_torque_and_slides_above_at_any_step() {
    let servo = Rx28::LEO.reduced();
    let friction = servo.dry_friction;
    let volts = |torque: f32| torque / servo.voltage_torque(1.0);
    for substeps in [1, 4, 40] {
        for (torque, holds) in [(0.19f32, true), (-0.19, true), (0.3, false), (-0.3, false)] {
            let mut m = model(|o| {
                o.substeps = substeps;
                o.fixed_torso = true;
                o.gravity = false;
                o.contacts = false;
            });
            let q0 = m.joint_state().0[Joint::Shoulder as usize];
            let mut u = [0.0; NUM_JOINTS];
            u[Joint::Shoulder as usize] = volts(torque);
            m.set_voltages(u);
            for _ in 0..90 {
                m.control_step().unwrap();
            }
            let (q, qd) = m.joint_state();
            let (dq, rate) = (
                q[Joint::Shoulder as usize] - q0,
                qd[Joint::Shoulder as usize],
            );
            if holds {
                assert!(
                    dq.abs() < 1e-3 && rate.abs() < 1e-3,
                    "{torque} N m at {substeps} steps/period moved the shoulder by {dq} rad ({rate} rad/s)"
                );
            } else {
                let expect = (torque - friction * torque.signum()) / servo.damping;
                assert!(
                    (rate / expect - 1.0).abs() < 0.02,
                    "{torque} N m at {substeps} steps/period: {rate} rad/s, expected {expect}"
                );
            }
        }
    }
}

/// Stiction on the whole robot: in the reference start the swing hip
/// carries the swing leg's 0.158 N m (its weight about the hip), less than
/// its 0.2 N m friction, so it holds while the robot falls; the stance hip
/// carries everything above it, 0.27 N m, more than its friction, so it
/// slides (both moments from the start pose's centres of mass, a hand
/// calculation in `README.md`). Bound: the swing hip within 1 mrad of its
/// start until the fall; the stance hip more than 0.1 rad.
#[test]
fn the_passive_robot_holds_its_swing_hip_and_slides_its_stance_hip() {
    let r = passive_rollout(ModelOptions::default(), 2.0).unwrap();
    assert!(r.fell);
    let start = InitialPose::REFERENCE.joint_angles();
    let swing0 = start[Joint::HipRight as usize];
    let stance0 = start[Joint::HipLeft as usize];
    let worst = r
        .steps
        .iter()
        .map(|s| (s.joint_angles_rad.hip_right - swing0).abs())
        .fold(0.0f32, f32::max);
    assert!(worst < 1e-3, "the swing hip moved by {worst} rad");
    let last = r.steps.last().unwrap().joint_angles_rad.hip_left;
    assert!(
        (last - stance0).abs() > 0.1,
        "the stance hip moved only {} rad",
        last - stance0
    );
}

/// The stance foot stands on the floor (§1.7, rubber μ = 100): with 0 V
/// on every joint and a 1 N forward push on the torso, the left foot's
/// heel and toe do not slide while both touch. Bound: 0.2 mm in 0.3 s
/// (measured: 0.015 mm). The root has no lateral DoF, so the floor's
/// lateral friction row has no mobility; upstream rapier divided by its
/// rounding error and lost the in-plane friction, and this test then
/// fails (the foot slid 6.2 mm; `vendor/rapier3d/PATCH.md`).
#[test]
fn the_stance_foot_does_not_slide_on_the_floor() {
    let mut m = model(|_| {});
    let toe0 = m.body_point(Body::FootLeft, FOOT_TOE)[0];
    m.set_disturbance(Some((Body::Torso, [1.0, 0.0, 0.0], [0.0; 3])));
    let mut worst = 0.0f32;
    for _ in 0..9 {
        m.control_step().unwrap();
        let s = m.state();
        if s.contacts[0] && s.contacts[1] {
            let toe = m.body_point(Body::FootLeft, FOOT_TOE)[0];
            worst = worst.max((toe - toe0).abs());
        }
    }
    assert!(worst < 2e-4, "the stance foot slid {worst} m");
}

/// The motion is planar by construction: the root has no lateral DoF, so
/// a 5 N side push on the torso of the standing robot does not move it
/// sideways at all.
#[test]
fn a_side_push_leaves_the_robot_in_its_plane() {
    let mut m = model(|_| {});
    m.set_disturbance(Some((Body::Torso, [0.0, 5.0, 0.0], [0.0; 3])));
    for _ in 0..30 {
        m.control_step().unwrap();
        let y = m.body_pose(Body::Torso).translation.y;
        assert!(y.abs() < 1e-9, "torso at y = {y} m");
    }
}
