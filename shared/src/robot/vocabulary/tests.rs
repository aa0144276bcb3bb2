//! The vocabulary's rules on a two-joint arm in a vertical plane, and the
//! pendulum's reward said in it.

use super::*;
use crate::agent::SarsaParams;
use crate::limits::{MAX_SERVOS, MAX_STATE_DIMS};
use crate::robot::hardware::{JointRange, JointSpec};
use crate::robot::{MotorLevels, PerServo, RobotRules, RobotSpec, Sensed, TableNeed, TorqueLaw};
use crate::tile_coding::StateDim;

const CHAIN: [ChainJoint; 2] = [
    ChainJoint { xyz: [0.0, 0.0, 0.1], rpy: [0.0; 3], joint: Some(0), axis: [0.0, 1.0, 0.0] },
    ChainJoint { xyz: [0.0, 0.0, 0.2], rpy: [0.0; 3], joint: Some(1), axis: [0.0, 1.0, 0.0] },
];
const POINTS: [Point; 1] = [Point { name: "tip", chain: &CHAIN, offset: [0.0, 0.0, 0.15] }];
const OBS: [Signal; 4] = [Signal::Angle(0), Signal::Rate(0), Signal::Angle(1), Signal::Position { point: 0, axis: 2 }];
const REWARDS: [RewardTerm; 4] = [
    RewardTerm::Distance { point: 0, target: [0.2, 0.0, 0.3], weight: -1.0 },
    RewardTerm::Action { weight: -0.01 },
    RewardTerm::ActionChange { weight: -0.1 },
    RewardTerm::Constant { value: 0.5 },
];
const ENDS: [End; 1] = [End { signal: Signal::Angle(1), min: -2.5, max: 2.5, reward: -50.0 }];
const HELD: [Hold; 1] = [Hold { joint: 2, target: 0.3, gain_v_per_rad: 10.0 }];
static WORDS: Vocabulary = Vocabulary {
    observation: &OBS,
    learned: &[0, 1],
    held: &HELD,
    voltage_limit_v: 6.0,
    start: &[0.0, 0.0, 0.3],
    reset: Reset { gain_v_per_rad: 8.0, tolerance_rad: 0.05, still_rad_s: 0.1, settle_us: 300_000, timeout_us: 3_000_000 },
    points: &POINTS,
    rewards: &REWARDS,
    ends: &ENDS,
};
const JOINTS: [JointSpec; 3] = [
    JointSpec { name: "shoulder", servo: &crate::servo::XM430_W350, id: 1, zero: 2048, sign: 1, soft_limit: None },
    JointSpec { name: "elbow", servo: &crate::servo::XL430_W250, id: 2, zero: 2048, sign: 1, soft_limit: None },
    JointSpec { name: "wrist", servo: &crate::servo::XL330_M288, id: 3, zero: 2048, sign: 1, soft_limit: None },
];
const DIM: StateDim = StateDim { min: -3.2, max: 3.2, tile_width: 0.4, wrap: false };
static ARM: RobotSpec = RobotSpec {
    name: "test-arm",
    period_us: 30_000,
    episode_steps: 100,
    test_interval: 10,
    state: &[DIM; 4],
    motor_dims: 2,
    levels: MotorLevels::Uniform { min: -6.0, max: 6.0, count: 3 },
    action_tiles: None,
    params: SarsaParams::SECTION_VII,
    joints: &JOINTS,
    counted: JointRange { start: 0, end: 2 },
    encoder: None,
    supply_nominal_v: 12.0,
    paper_torque: TorqueLaw::ServoStall,
    footstep_remap: None,
    half_shift: 12,
    table: TableNeed::Claimed,
    vocabulary: Some(&WORDS),
};

fn sense(v: &mut Vocab, q: [f32; 3], applied: [f32; 3]) {
    let mut angles = [None; MAX_SERVOS];
    let mut u: PerServo = [0.0; MAX_SERVOS];
    for j in 0..3 {
        angles[j] = Some(q[j]);
        u[j] = applied[j];
    }
    v.sense(&Sensed { angles, encoder_angle: None, contacts: 0, applied: u });
}

fn per_servo(u: [f32; 3]) -> PerServo {
    let mut out = [0.0; MAX_SERVOS];
    out[..3].copy_from_slice(&u);
    out
}

#[test]
fn it_observes_rates_and_points_from_the_angles() {
    let mut v = Vocab::new(&ARM).unwrap();
    v.start_episode();
    sense(&mut v, [0.0, 0.0, 0.3], [0.0; 3]);
    let mut obs = [0.0; MAX_STATE_DIMS];
    assert_eq!(v.observe(&mut obs), 4);
    assert_eq!(obs[..3], [0.0, 0.0, 0.0]);
    assert!((obs[3] - 0.45).abs() < 1e-6, "the tip straight up: {}", obs[3]);
    sense(&mut v, [0.03, -0.2, 0.3], [0.0; 3]);
    v.observe(&mut obs);
    assert!((obs[1] - 1.0).abs() < 1e-4, "0.03 rad in 30 ms: {}", obs[1]);
    let z = 0.1 + 0.2 * libm::cosf(0.03) + 0.15 * libm::cosf(0.03 - 0.2);
    assert!((obs[3] - z).abs() < 1e-5);
    assert!((v.signal(Signal::Velocity { point: 0, axis: 2 }) - (z - 0.45) / 0.03).abs() < 1e-3);
}

#[test]
fn the_reward_is_the_sum_of_its_terms_and_an_end_adds_its_own() {
    let mut v = Vocab::new(&ARM).unwrap();
    v.start_episode();
    sense(&mut v, [0.0, 0.0, 0.3], [2.0, -1.0, 0.0]);
    sense(&mut v, [0.0, 0.0, 0.3], [3.0, -1.0, 5.0]);
    let applied = per_servo([3.0, -1.0, 5.0]);
    // Tip at (0, 0, 0.45): 0.25 m from (0.2, 0, 0.3); the held wrist's 5 V
    // is no action of the learner's.
    let distance = libm::sqrtf(0.2 * 0.2 + 0.15 * 0.15);
    let want = -distance - 0.01 * (9.0 + 1.0) - 0.1 * 1.0 + 0.5;
    assert!((v.reward(&applied) - want).abs() < 1e-5, "{} vs {want}", v.reward(&applied));
    assert!(!v.absorbing());
    sense(&mut v, [0.0, 2.6, 0.3], [3.0, -1.0, 5.0]);
    assert!(v.absorbing());
    assert!(v.reward(&applied) < -49.0);
    // A NaN reading ends the episode too.
    sense(&mut v, [0.0, f32::NAN, 0.3], [0.0; 3]);
    assert!(v.absorbing());
}

#[test]
fn learned_joints_take_the_output_and_held_ones_their_p_law() {
    let mut v = Vocab::new(&ARM).unwrap();
    sense(&mut v, [0.0, 0.0, 0.1], [0.0; 3]);
    let mut volts = [0.0; MAX_SERVOS];
    v.commands(&[4.0, 60.0], &mut volts);
    assert_eq!(volts[0], 4.0);
    assert_eq!(volts[1], 6.0, "clipped to the voltage limit");
    assert!((volts[2] - 10.0 * 0.2).abs() < 1e-6, "the wrist held at 0.3 rad");
    v.commands(&[f32::NAN, 0.0], &mut volts);
    assert_eq!(volts[0], 0.0);
    // Between episodes: every joint towards the start pose.
    sense(&mut v, [0.5, -0.1, 0.3], [0.0; 3]);
    v.reset_commands(&mut volts);
    assert!((volts[0] + 4.0).abs() < 1e-6 && (volts[1] - 0.8).abs() < 1e-6 && volts[2].abs() < 1e-6, "{volts:?}");
}

#[test]
fn a_reset_ends_when_the_robot_settles_at_its_start_or_the_wait_runs_out() {
    let mut v = Vocab::new(&ARM).unwrap();
    v.begin_reset();
    let mut n = 0;
    loop {
        sense(&mut v, [0.0, 0.0, 0.3], [0.0; 3]);
        n += 1;
        if v.reset_done() {
            break;
        }
    }
    assert_eq!(n, 10, "300 ms settled at 30 ms a period");
    v.begin_reset();
    let mut n = 0;
    loop {
        sense(&mut v, [1.0, 0.0, 0.3], [0.0; 3]);
        n += 1;
        if v.reset_done() {
            break;
        }
    }
    assert_eq!(n, 100, "3 s at most");
}

#[test]
fn the_paper_torque_is_each_servos_stall_torque_and_the_estimate_its_motor() {
    let v = Vocab::new(&ARM).unwrap();
    let xm = crate::servo::XM430_W350.motor();
    let xl = crate::servo::XL430_W250.motor();
    assert_eq!(ARM.paper_gear_torque(0, 6.0), xm.stall_torque(6.0));
    assert_eq!(ARM.paper_gear_torque(1, 6.0), xl.stall_torque(6.0));
    let mut t = [0.0; MAX_SERVOS];
    v.gear_torques(&per_servo([6.0, 6.0, 0.0]), &mut t);
    assert_eq!((t[0], t[1]), (xm.joint_torque(6.0, 0.0), xl.joint_torque(6.0, 0.0)));
}

#[test]
fn a_malformed_vocabulary_is_refused_by_name() {
    static BAD_LEARNED: Vocabulary = Vocabulary { learned: &[0, 7], ..WORDS };
    static BAD_END: Vocabulary =
        Vocabulary { ends: &[End { signal: Signal::Angle(0), min: 1.0, max: 1.0, reward: 0.0 }], ..WORDS };
    static BAD_OBS: Vocabulary = Vocabulary { observation: &[Signal::Angle(0)], ..WORDS };
    static BAD_POINT: Vocabulary = Vocabulary {
        rewards: &[RewardTerm::Progress { point: 3, axis: 0, weight: 1.0 }],
        ..WORDS
    };
    for (words, field) in [(&BAD_LEARNED, "learned"), (&BAD_END, "ends"), (&BAD_OBS, "observation"), (&BAD_POINT, "rewards")] {
        let e = Vocab::check(&ARM, words).unwrap_err();
        assert_eq!(e.param, field, "{e:?}");
    }
    assert!(Vocab::new(&crate::robot::pendulum::SPEC_33HZ).is_err(), "the pendulum's rules are code");
}

#[test]
fn the_pendulums_reward_is_said_in_the_vocabulary() {
    // −5θ² − 0.1θ̇² − u², θ wrapped about upright.
    const TERMS: [RewardTerm; 3] = [
        RewardTerm::Quadratic { signal: Signal::Angle(0), target: 0.0, weight: -5.0, wrap: true },
        RewardTerm::Quadratic { signal: Signal::Rate(0), target: 0.0, weight: -0.1, wrap: false },
        RewardTerm::Action { weight: -1.0 },
    ];
    static WORDS1: Vocabulary = Vocabulary {
        observation: &[Signal::Angle(0), Signal::Rate(0)],
        learned: &[0],
        held: &[],
        start: &[core::f32::consts::PI],
        points: &[],
        rewards: &TERMS,
        ends: &[],
        ..WORDS
    };
    static ONE: [JointSpec; 1] = [JOINTS[0]];
    static P: RobotSpec = RobotSpec {
        state: &[DIM; 2],
        motor_dims: 1,
        joints: &ONE,
        counted: JointRange { start: 0, end: 1 },
        vocabulary: Some(&WORDS1),
        ..ARM
    };
    let mut v = Vocab::new(&P).unwrap();
    v.start_episode();
    let mut angles = [None; MAX_SERVOS];
    angles[0] = Some(3.0);
    v.sense(&Sensed { angles, encoder_angle: None, contacts: 0, applied: [0.0; MAX_SERVOS] });
    angles[0] = Some(3.3);
    let u = per_servo([2.0, 0.0, 0.0]);
    v.sense(&Sensed { angles, encoder_angle: None, contacts: 0, applied: u });
    let want = crate::robot::pendulum::swing_up_reward(
        crate::robot::pendulum::wrap_angle(3.3f32 as f64),
        ((3.3f32 - 3.0f32) / 0.03) as f64,
        2.0,
    );
    assert!((v.reward(&u) as f64 - want).abs() < 1e-3 * want.abs(), "{} vs {want}", v.reward(&u));
}

#[test]
fn a_squared_distance_term_is_the_distance_squared_and_hashes_apart() {
    const SQUARED: [RewardTerm; 1] = [RewardTerm::DistanceSquared { point: 0, target: [0.2, 0.0, 0.3], weight: -4.0 }];
    static WORDS_SQ: Vocabulary = Vocabulary { rewards: &SQUARED, ..WORDS };
    static ARM_SQ: RobotSpec = RobotSpec { vocabulary: Some(&WORDS_SQ), ..ARM };
    const PLAIN: [RewardTerm; 1] = [RewardTerm::Distance { point: 0, target: [0.2, 0.0, 0.3], weight: -4.0 }];
    static WORDS_D: Vocabulary = Vocabulary { rewards: &PLAIN, ..WORDS };
    static ARM_D: RobotSpec = RobotSpec { vocabulary: Some(&WORDS_D), ..ARM };
    let (mut sq, mut d) = (Vocab::new(&ARM_SQ).unwrap(), Vocab::new(&ARM_D).unwrap());
    let applied = per_servo([0.0; 3]);
    for q in [[0.0, 0.0, 0.3], [0.4, -0.7, 0.3], [-1.2, 2.0, 0.3]] {
        sense(&mut sq, q, [0.0; 3]);
        sense(&mut d, q, [0.0; 3]);
        let metres = d.reward(&applied) / -4.0;
        let want = -4.0 * metres * metres;
        assert!((sq.reward(&applied) - want).abs() <= 1e-6 * want.abs().max(1.0), "{q:?}: {} vs {want}", sq.reward(&applied));
    }
    // At the tip straight up: 0.25 m from the target, 0.0625 m².
    sense(&mut sq, [0.0, 0.0, 0.3], [0.0; 3]);
    assert!((sq.reward(&applied) + 4.0 * 0.0625).abs() < 1e-6);
    assert_ne!(ARM_SQ.definition_hash(), ARM_D.definition_hash());
    // A point the robot lacks is refused.
    const NOWHERE: [RewardTerm; 1] = [RewardTerm::DistanceSquared { point: 3, target: [0.0; 3], weight: -1.0 }];
    static WORDS_BAD: Vocabulary = Vocabulary { rewards: &NOWHERE, ..WORDS };
    static ARM_BAD: RobotSpec = RobotSpec { vocabulary: Some(&WORDS_BAD), ..ARM };
    assert!(Vocab::new(&ARM_BAD).is_err());
}
