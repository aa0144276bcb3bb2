//! Sanity checks of the LEO model, against `docs/reference/grl.md` §1–3.
//!
//! Each test states its bound; the measured values at the default settings
//! are recorded in `sim/src/leo/README.md`.

use pada::leo::constants::*;
use pada::leo::model::*;
use pada::leo::task::Leg;
use pada::leo::*;
use pada_core::rx28::{Rx28, LEO_MAX_VOLTAGE};
use rand_core::{RngCore, SeedableRng};

const LEVELS: [f32; 7] = [-10.7, -7.1333, -3.5667, 0.0, 3.5667, 7.1333, 10.7];

fn rng(seed: u64) -> rand_pcg::Pcg32 {
    rand_pcg::Pcg32::seed_from_u64(seed)
}

fn random_action(r: &mut rand_pcg::Pcg32) -> [f32; 3] {
    [0, 1, 2].map(|_| LEVELS[(r.next_u32() % 7) as usize])
}

fn model(f: impl FnOnce(&mut ModelOptions)) -> LeoModel {
    let mut o = ModelOptions::default();
    f(&mut o);
    LeoModel::new(o, &InitialPose::REFERENCE).expect("valid options")
}

fn close(a: [f32; 2], b: [f32; 2], tol: f32) -> bool {
    (a[0] - b[0]).abs() <= tol && (a[1] - b[1]).abs() <= tol
}

/// §1.3/§1.4: the boom folded into the torso gives the reference's numbers.
#[test]
fn folded_boom_matches_the_reference() {
    assert!((TORSO_MASS - 1.230991).abs() < 1e-5, "{TORSO_MASS}");
    assert!((TORSO_IYY - 0.00870763).abs() < 1e-7, "{TORSO_IYY}");
    assert!(
        close(TORSO_COM, [-0.0000521, -0.0237952], 1e-6),
        "{TORSO_COM:?}"
    );
    assert!(
        (BOOM_EXTRA_FORCE_Z + 1.026915).abs() < 1e-4,
        "{BOOM_EXTRA_FORCE_Z}"
    );
}

/// §1.8: the starting pose stands on the left foot (toe and heel on the
/// floor), the right foot lifted, and the assembled points match the
/// reference's forward kinematics within 1 mm.
#[test]
fn initial_pose_has_the_left_foot_on_the_floor() {
    let m = model(|_| {});
    let c = m.foot_clearances();
    assert!(
        c[0].abs() < 1e-5 && c[1].abs() < 1e-5,
        "left toe/heel clearance {c:?}"
    );
    assert!(
        (c[2] - 0.0229).abs() < 1e-3 && (c[3] - 0.0652).abs() < 1e-3,
        "right toe/heel {c:?}"
    );
    // Anchors and the torso's centre of mass where the framework's
    // assembly puts them (§1.8) [m].
    for (body, point, want) in [
        (Body::Torso, TORSO_HIP_ANCHOR, [0.0274, 0.2691]),
        (Body::ThighLeft, THIGH_KNEE_ANCHOR, [0.0274, 0.1531]),
        (Body::ShankLeft, SHANK_ANKLE_ANCHOR, [0.0315, 0.0486]),
        (Body::ThighRight, THIGH_KNEE_ANCHOR, [0.1039, 0.1819]),
        (Body::ShankRight, SHANK_ANKLE_ANCHOR, [0.0528, 0.0907]),
        (Body::Torso, TORSO_SHOULDER_ANCHOR, [0.0405, 0.4809]),
        (Body::Torso, TORSO_COM, [0.0344, 0.3659]),
    ] {
        let got = m.body_point(body, point);
        assert!(close(got, want, 1e-3), "{body:?} at {point:?}: {got:?}, want {want:?}");
    }
    let s = m.state();
    assert_eq!(s.contacts, [true, true, false, false]);
    let q = InitialPose::REFERENCE.joint_angles();
    let expect = [-0.261799, 0.10, 0.82, 0.0, -1.27, 0.0, 0.0];
    for k in 0..NUM_JOINTS {
        assert!((s.angles[k] - expect[k]).abs() < 1e-5 && (q[k] - expect[k]).abs() < 1e-5);
    }
    assert!((s.torso_pitch - 0.10).abs() < 1e-6);
    // The environment's first observation (after one control period at
    // 0 V, §1.8) still stands on the left leg, φ ≈ −0.1.
    let env = LeoEnv::new(LeoConfig::default()).unwrap();
    assert_eq!(env.model().state().contacts[..2], [true, true]);
    let o = env.observation().0;
    assert!((o[0] + 0.10).abs() < 0.02, "phi {}", o[0]);
}

/// Planar motion is locked explicitly, not by symmetry. With
/// random actions and a sideways push on the torso (5 N along y plus a
/// 0.5 N m torque about x and z), every body stays in y = 0 and rotates
/// only about y.
#[test]
fn motion_stays_planar() {
    let mut env = LeoEnv::new(LeoConfig::default()).unwrap();
    let mut r = rng(3);
    env.reset(&mut r);
    for _ in 0..60 {
        env.model_mut()
            .set_disturbance(Some((Body::Torso, [0.0, 5.0, 0.0], [0.5, 0.0, 0.5])));
        if env.step(random_action(&mut r)).terminal != Terminal::None {
            env.reset(&mut r);
        }
        for b in [
            Body::Torso,
            Body::Arm,
            Body::FootLeft,
            Body::FootRight,
            Body::ShankRight,
        ] {
            let p = env.model().body_pose(b);
            assert!(
                p.translation.y.abs() < 1e-6,
                "{b:?} left the plane: {:?}",
                p.translation
            );
            let axis = p.rotation * rapier3d::math::Vector::Y;
            assert!(
                (axis.y - 1.0).abs() < 1e-5,
                "{b:?} tilted out of the plane: {axis:?}"
            );
        }
    }
}

/// §2.1: the simulated servo reproduces the no-load speed (5.5845 rad/s at
/// 10.6919 V) and the stall torque after η (1.7852 N m) within 1%.
///
/// No-load: the arm (the shoulder has no limits) spins freely, torso
/// welded, no gravity, no dry friction: its speed settles at U/(G·k).
/// Stall: the left knee pressed into its +2° stop at 10.6919 V, no gravity,
/// no dry friction: at rest the stop's spring carries the whole gear
/// torque, K·δ = η·τ_stall.
#[test]
fn servo_reproduces_stall_torque_and_no_load_speed() {
    let u = LEO_MAX_VOLTAGE;
    let mut m = model(pada::model_presets::servo_bench);
    let mut v = [0.0; NUM_JOINTS];
    v[Joint::Shoulder as usize] = u;
    v[Joint::KneeLeft as usize] = u;
    m.set_voltages(v);
    for _ in 0..60 {
        m.control_step().unwrap();
    }
    let (q, qd) = m.joint_state();
    let speed = qd[Joint::Shoulder as usize];
    assert!((speed / 5.5845 - 1.0).abs() < 0.01, "no-load speed {speed}");
    let over = q[Joint::KneeLeft as usize] - KNEE_LIMITS[1];
    let torque = KNEE_STOP[0] * over;
    assert!(
        (torque / 1.7852 - 1.0).abs() < 0.01,
        "stall torque {torque} (δ = {over})"
    );
    assert!(qd[Joint::KneeLeft as usize].abs() < 1e-3);
    // The same numbers from the motor model itself.
    let servo = Rx28::LEO;
    assert!((servo.stall_torque(u) / 2.3803 - 1.0).abs() < 0.01);
    assert!((servo.no_load_speed(u) / 5.5845 - 1.0).abs() < 0.01);
}

/// §2.1: the servo's first-order response. The arm (torso welded, no
/// gravity, no dry friction) driven from rest at 10.6919 V is a single DoF
/// J·q̈ = τ_U − d·q̇ with J = the arm's inertia about the shoulder plus the
/// armature η·J_a·G² and d = η·G²k²/R, so after one control period its
/// speed is v∞·(1 − exp(−T·d/J)) ≈ 4.784 rad/s. Bound: 1.5% (without the
/// armature it would be 5.43, with rapier's plain backward Euler at the
/// default step 4.34).
#[test]
fn servo_response_over_one_control_period() {
    let servo = Rx28::LEO.reduced();
    let r2 = ARM_COM[0] * ARM_COM[0] + ARM_COM[1] * ARM_COM[1];
    let j = ARM_IYY + ARM_MASS * r2 + servo.armature;
    let v_inf = servo.voltage_torque(LEO_MAX_VOLTAGE) / servo.damping;
    let expect = v_inf * (1.0 - (-CONTROL_PERIOD * servo.damping / j).exp());
    let mut m = model(pada::model_presets::servo_bench);
    let mut v = [0.0; NUM_JOINTS];
    v[Joint::Shoulder as usize] = LEO_MAX_VOLTAGE;
    m.set_voltages(v);
    m.control_step().unwrap();
    let got = m.joint_state().1[Joint::Shoulder as usize];
    assert!(
        (got / expect - 1.0).abs() < 0.015,
        "speed after 1/30 s: {got}, expected {expect}"
    );
}

/// A passive robot (0 V: back-EMF braking, dry friction) falls
/// and comes to rest without gaining energy.
///
/// Bounds: the mechanical energy never exceeds its starting value by more
/// than 1 mJ; after 5 s the kinetic energy is below 1e-5 J; the robot lost
/// more than 1 J of potential energy (it fell; standing it has ≈ 6.08 J).
#[test]
fn passive_robot_falls_and_comes_to_rest() {
    let mut m = model(|_| {});
    let e0 = m.energy().total();
    let mut peak = f32::MIN;
    for _ in 0..150 {
        m.control_step().unwrap();
        peak = peak.max(m.energy().total() - e0);
    }
    let e = m.energy();
    assert!(peak < 1e-3, "energy gain {peak} J");
    assert!(e.kinetic < 1e-5, "still moving: {} J", e.kinetic);
    assert!(e.total() < e0 - 1.0, "did not fall: {} → {}", e0, e.total());
    let s = m.state();
    assert!(s.torso_pitch.abs() > 1.0, "torso pitch {}", s.torso_pitch);
}

/// With contacts and friction off, total energy drifts less than
/// a stated bound over 10 s.
///
/// Setting: torso welded in the starting pose, gravity on, no floor, no
/// dry friction, no back-EMF, no joint stops (the stops' dampers and
/// implicit springs are dissipative by design); the limbs start with joint
/// rates of 2–4 rad/s and swing as a tree of pendulums. Bound: |E − E0| <
/// 0.015 J over 10 s (the swing's kinetic energy peaks near 0.2 J).
/// Also free-floating without gravity: kinetic energy within 2%.
#[test]
fn energy_is_conserved_without_contacts_and_friction() {
    let mut m = model(pada::model_presets::lossless_fixed_torso);
    m.set_velocities([3.0, 2.0, -2.0, -3.0, 3.0, 4.0, -4.0], [0.0; 3]);
    let e0 = m.energy().total();
    let mut worst = 0.0f32;
    for _ in 0..300 {
        m.control_step().unwrap();
        worst = worst.max((m.energy().total() - e0).abs());
    }
    assert!(worst < 0.015, "energy drift {worst} J");

    let mut m = model(|o| {
        o.contacts = false;
        o.gravity = false;
        o.boom_force = false;
        o.dry_friction = false;
        o.back_emf = false;
        o.joint_stops = false;
    });
    m.set_velocities([1.0, 0.5, -0.5, -1.0, 1.0, 1.0, -1.0], [0.1, 0.05, 0.5]);
    let k0 = m.energy().kinetic;
    for _ in 0..300 {
        m.control_step().unwrap();
        let k = m.energy().kinetic;
        assert!(
            (k / k0 - 1.0).abs() < 0.02,
            "free-floating kinetic energy {k0} → {k}"
        );
    }
}

/// §1.5: the joint limits hold. Torso welded, no floor, every joint driven
/// at ±10.7 V into its limits for 1 s each way. The stops are soft springs
/// (K = 100 N m/rad for hips and ankles, 50 for knees): under the stall
/// torque they give 0.018 and 0.036 rad. Bound: no joint more than 0.07 rad
/// past its limit. Also: the stops never add energy (passive stops).
#[test]
fn joint_limits_hold() {
    let mut m = model(|o| {
        o.fixed_torso = true;
        o.contacts = false;
    });
    let mut worst = 0.0f32;
    for u in [10.7f32, -10.7, 10.7] {
        m.set_voltages([u; NUM_JOINTS]);
        for _ in 0..30 {
            m.control_step().unwrap();
            let (q, _) = m.joint_state();
            for j in JOINTS {
                if let Some([lo, hi]) = joint_limits(j) {
                    worst = worst.max(q[j as usize] - hi).max(lo - q[j as usize]);
                }
            }
        }
    }
    assert!(worst < 0.07, "a joint went {worst} rad past its limit");
    assert!(worst > 0.0, "the test never reached a limit");

    // Passive swinging into the stops, dampers on: energy only decreases.
    let mut m = model(|o| {
        o.fixed_torso = true;
        o.contacts = false;
        o.dry_friction = false;
        o.back_emf = false;
    });
    m.set_velocities([6.0, 6.0, -6.0, 6.0, -6.0, 6.0, -6.0], [0.0; 3]);
    let e0 = m.energy().total();
    for _ in 0..90 {
        m.control_step().unwrap();
        let e = m.energy().total();
        assert!(e < e0 + 0.01, "energy rose from {e0} to {e}");
    }
}

/// §3.3/§3.8: random actions make LEO fall; every episode ends in a fall
/// or a timeout, rewards are finite, and the walked distance is the sum of
/// footstep lengths that the footstep count agrees with in sign.
#[test]
fn random_actions_end_in_falls_with_finite_rewards() {
    let mut env = LeoEnv::new(LeoConfig::default()).unwrap();
    let mut r = rng(11);
    let mut falls = 0;
    for _ in 0..5 {
        env.reset(&mut r);
        let mut steps = 0;
        loop {
            let res = env.step(random_action(&mut r));
            steps += 1;
            assert!(res.reward.is_finite() && res.obs.0.iter().all(|x| x.is_finite()));
            assert!(
                res.info.energy >= 0.0 && res.info.learned_torques.iter().all(|t| t.abs() < 5.0)
            );
            match res.terminal {
                Terminal::None => assert!(steps <= 751),
                Terminal::Fall => {
                    falls += 1;
                    assert!(res.reward < -100.0);
                    break;
                }
                Terminal::Timeout => break,
            }
        }
    }
    assert!(falls >= 4, "only {falls} of 5 random episodes fell");
    assert_eq!(env.falls(), falls as u64);
    assert_eq!(env.blow_ups(), 0);
}

/// §3.8: the 25 s timeout (here shortened to 0.2 s), and stepping after the
/// end repeats the last result without simulating.
#[test]
fn timeout_ends_the_episode() {
    let cfg = LeoConfig {
        timeout: Some(0.2),
        ..LeoConfig::default()
    };
    let mut env = LeoEnv::new(cfg).unwrap();
    env.reset(&mut rng(1));
    let mut n = 0;
    let last = loop {
        let res = env.step([0.0; 3]);
        n += 1;
        if res.terminal != Terminal::None {
            break res;
        }
    };
    assert_eq!(last.terminal, Terminal::Timeout);
    assert_eq!(n, 7); // 7/30 s > 0.2 s
    let t = env.model().time();
    let again = env.step([10.0; 3]);
    assert_eq!(again.terminal, Terminal::Timeout);
    assert_eq!(again.reward, 0.0);
    assert_eq!(env.model().time(), t);
}

/// The first step after a reset carries GRL's artefact of §3.7: the first
/// stance update ran with an unknown previous stance (L = x_L − x_R), so
/// ΔL ≈ 2·(x_R − x_L) ≈ 0.043 m and r ≈ −1 + 12.8 − 3E.
#[test]
fn first_step_reward_carries_the_reference_artefact() {
    let mut env = LeoEnv::new(LeoConfig::default()).unwrap();
    env.reset(&mut rng(1));
    let res = env.step([0.0; 3]);
    assert!(
        res.reward > 8.0 && res.reward < 13.0,
        "first reward {}",
        res.reward
    );
    assert_eq!(res.info.stance, Leg::Left);
}

/// Resetting reproduces a fresh environment exactly (the reference start is
/// restored from a snapshot), whatever happened before.
#[test]
fn reset_is_exact() {
    let cfg = LeoConfig::default();
    let mut used = LeoEnv::new(cfg).unwrap();
    let mut r = rng(5);
    for _ in 0..3 {
        used.reset(&mut r);
        while used.step(random_action(&mut r)).terminal == Terminal::None {}
    }
    let mut fresh = LeoEnv::new(cfg).unwrap();
    assert_eq!(fresh.reset(&mut r), used.reset(&mut r));
    let mut a = rng(6);
    for _ in 0..20 {
        let act = random_action(&mut a);
        assert_eq!(fresh.step(act), used.step(act));
    }
}

/// Bad input: a blown-up simulation ends the episode as a fall,
/// is counted, keeps the observation finite and never panics; the next
/// reset starts cleanly. Non-finite actions are read as 0 V and flagged.
#[test]
fn blow_ups_are_falls_not_panics() {
    let mut env = LeoEnv::new(LeoConfig::default()).unwrap();
    let mut r = rng(2);
    env.reset(&mut r);
    let res = env.step([f32::NAN, f32::INFINITY, 1.0]);
    assert!(res.info.invalid_action && res.obs.0.iter().all(|x| x.is_finite()));

    for (rates, kind) in [
        ([1.0e6f32; NUM_JOINTS], BlowUp::JointRate),
        ([f32::NAN; NUM_JOINTS], BlowUp::NonFinite),
    ] {
        env.reset(&mut r);
        env.model_mut().set_velocities(rates, [0.0; 3]);
        let res = env.step([0.0; 3]);
        assert_eq!(res.terminal, Terminal::Fall);
        assert!(res.reward <= -125.0);
        assert_eq!(
            res.info.blow_up.map(|b| core::mem::discriminant(&b)),
            Some(core::mem::discriminant(&kind))
        );
        assert!(res.obs.0.iter().all(|x| x.is_finite()));
    }
    // A body far away: launched straight up (sideways the foot's floor
    // friction would hold it back and the joints would spin first).
    env.reset(&mut r);
    env.model_mut()
        .set_velocities([0.0; NUM_JOINTS], [0.0, 1.0e4, 0.0]);
    let res = env.step([0.0; 3]);
    assert_eq!(res.info.blow_up, Some(BlowUp::FarAway));
    assert_eq!(env.blow_ups(), 3);
    assert_eq!(env.falls(), 3);
    // Clean again after a reset.
    let o = env.reset(&mut r);
    assert_eq!(o, LeoEnv::new(LeoConfig::default()).unwrap().observation());
    assert_eq!(env.step([0.0; 3]).terminal, Terminal::None);
}

/// Invalid settings are refused with a message, not a panic.
#[test]
fn invalid_config_is_refused() {
    for bad in [
        LeoConfig {
            model: ModelOptions {
                substeps: 0,
                ..Default::default()
            },
            ..Default::default()
        },
        LeoConfig {
            model: ModelOptions {
                solver_iterations: 0,
                ..Default::default()
            },
            ..Default::default()
        },
        LeoConfig {
            model: ModelOptions {
                contact_frequency: f32::NAN,
                ..Default::default()
            },
            ..Default::default()
        },
        LeoConfig {
            timeout: Some(-1.0),
            ..Default::default()
        },
    ] {
        let e = LeoEnv::new(bad).err().expect("refused");
        assert!(!e.to_string().is_empty());
    }
    let pose = InitialPose {
        torso: f32::NAN,
        ..InitialPose::REFERENCE
    };
    assert!(LeoModel::new(ModelOptions::default(), &pose).is_err());
}

/// §1.8 randomisation (off by default) still starts on the left foot.
#[test]
fn randomized_start_stands_on_the_left_foot() {
    let cfg = LeoConfig {
        randomize_start: true,
        ..LeoConfig::default()
    };
    let mut env = LeoEnv::new(cfg).unwrap();
    let mut r = rng(8);
    for _ in 0..5 {
        let o = env.reset(&mut r);
        assert!(o.0.iter().all(|x| x.is_finite()));
        assert_eq!(env.terminal(), Terminal::None);
    }
}
