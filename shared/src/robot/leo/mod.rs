//! LEO, the Delft biped on its boom, walking (Section VIII), defined once:
//! the facts of `docs/reference/grl.md` §1.3–1.8 the task needs, the
//! walking task of §3, and its hardware (seven RX-28s, the boom's encoder,
//! four foot switches). The rapier3d simulation (`sim/src/leo/`) produces
//! these quantities from physics; the firmware, through [`rules::Leo`],
//! from servo positions, the boom's encoder and the foot switches. Both
//! then apply the same rules, so the chip's learner sees what the
//! simulated learner sees.
//!
//! - Joints in [`Joint`] order (shoulder, hip L/R, knee L/R, ankle L/R);
//!   hinge angles follow ODE, `q = θ_parent − θ_child` (§1.2).
//! - Rates through GRL's Butterworth filter ([`joint_rate_filter`],
//!   [`torso_rate_filter`], §3.2).
//! - Stance leg from the feet, footsteps and the step length L
//!   ([`StanceTracker`], §3.3); the mirrored observation ([`observe`],
//!   §3.4).
//! - The learned voltages drive stance hip, swing hip and swing knee
//!   ([`learned_joints`]); the others are held by P laws ([`held_voltages`],
//!   §3.5).
//! - Reward `−1 − 3·E + 300·(L − L_prev) − 125·[fall]` ([`reward`],
//!   [`step_energy`], §3.7); a fall is absorbing ([`is_fall`], §3.8).

// Numbers are written as the reference prints them: the joint limits are
// the reference's degrees in radians to six places (−0.785398 is −45°, not
// meant as π/4).
#![allow(clippy::approx_constant)]

mod rules;
mod stance;

pub use rules::Leo;
pub use stance::{StanceTracker, StanceUpdate};

use super::filter::RateFilter;
use super::hardware::{EncoderSpec, JointRange, JointSpec};
use super::{MotorLevels, RobotSpec, TableNeed, TorqueLaw};
use crate::agent::{SarsaParams, WeightInit};
use crate::safety::SoftLimit;
use crate::rx28::{Rx28, LEO_MAX_VOLTAGE};
use crate::tile_coding::StateDim;
use crate::trace::TraceKind;
use core::f32::consts::{FRAC_PI_2, PI};

// ---------------------------------------------------------------------------
// The robot (docs/reference/grl.md §1)
// ---------------------------------------------------------------------------

/// The seven servo joints (§1.5), in this order everywhere: the
/// simulation's joint arrays and the firmware's servo table.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Joint {
    /// Torso → arm.
    Shoulder = 0,
    /// Torso → left thigh.
    HipLeft,
    /// Torso → right thigh.
    HipRight,
    /// Left thigh → left shank.
    KneeLeft,
    /// Right thigh → right shank.
    KneeRight,
    /// Left shank → left foot.
    AnkleLeft,
    /// Right shank → right foot.
    AnkleRight,
}

/// Number of servo joints.
pub const NUM_JOINTS: usize = 7;

/// All joints in index order.
pub const JOINTS: [Joint; NUM_JOINTS] = [
    Joint::Shoulder,
    Joint::HipLeft,
    Joint::HipRight,
    Joint::KneeLeft,
    Joint::KneeRight,
    Joint::AnkleLeft,
    Joint::AnkleRight,
];

/// The leg that carries the robot (§3.3).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Leg {
    /// Left leg.
    Left,
    /// Right leg.
    Right,
}

impl Leg {
    /// The other leg.
    pub fn other(self) -> Leg {
        match self {
            Leg::Left => Leg::Right,
            Leg::Right => Leg::Left,
        }
    }
    /// This leg's hip.
    pub fn hip(self) -> Joint {
        match self {
            Leg::Left => Joint::HipLeft,
            Leg::Right => Joint::HipRight,
        }
    }
    /// This leg's knee.
    pub fn knee(self) -> Joint {
        match self {
            Leg::Left => Joint::KneeLeft,
            Leg::Right => Joint::KneeRight,
        }
    }
}

/// Hip limits, −45°…146° (§1.5) \[rad\].
pub const HIP_LIMITS: [f32; 2] = [-0.785398, 2.548181];
/// Knee limits, −150°…+2° (§1.5) \[rad\].
pub const KNEE_LIMITS: [f32; 2] = [-2.617994, 0.034907];
/// Ankle limits, −90°…83° (§1.5) \[rad\].
pub const ANKLE_LIMITS: [f32; 2] = [-1.570796, 1.448623];

/// The joint's stops (§1.5); the shoulder has none.
pub const fn joint_limits(joint: Joint) -> Option<[f32; 2]> {
    match joint {
        Joint::Shoulder => None,
        Joint::HipLeft | Joint::HipRight => Some(HIP_LIMITS),
        Joint::KneeLeft | Joint::KneeRight => Some(KNEE_LIMITS),
        Joint::AnkleLeft | Joint::AnkleRight => Some(ANKLE_LIMITS),
    }
}

/// Absolute torso pitch at the start (§1.8) \[rad\].
pub const INIT_TORSO_PITCH: f32 = 0.10;
/// Absolute arm pitch at the start: torso + 15° (§1.8) \[rad\].
pub const INIT_ARM_PITCH: f32 = 0.361799;
/// Absolute pitches of the left thigh, shank and foot at the start (§1.8).
pub const INIT_LEFT_LEG_PITCH: [f32; 3] = [0.0, 0.0, 0.0];
/// Absolute pitches of the right thigh, shank and foot at the start (§1.8).
pub const INIT_RIGHT_LEG_PITCH: [f32; 3] = [-0.72, 0.55, 0.55];

/// The joint angles of the start pose (§1.8), `q = θ_parent − θ_child`:
/// shoulder −0.2618, hips 0.10 (L) and 0.82 (R), knees 0 (L) and −1.27
/// (R), ankles 0.
pub const START_JOINT_ANGLES: [f32; NUM_JOINTS] = [
    INIT_TORSO_PITCH - INIT_ARM_PITCH,
    INIT_TORSO_PITCH - INIT_LEFT_LEG_PITCH[0],
    INIT_TORSO_PITCH - INIT_RIGHT_LEG_PITCH[0],
    INIT_LEFT_LEG_PITCH[0] - INIT_LEFT_LEG_PITCH[1],
    INIT_RIGHT_LEG_PITCH[0] - INIT_RIGHT_LEG_PITCH[1],
    INIT_LEFT_LEG_PITCH[1] - INIT_LEFT_LEG_PITCH[2],
    INIT_RIGHT_LEG_PITCH[1] - INIT_RIGHT_LEG_PITCH[2],
];

/// The torso angle φ of the start pose: φ is minus the torso's pitch
/// (§3.1), so −0.10 rad.
pub const START_PHI: f32 = -INIT_TORSO_PITCH;

/// Thigh length used for the ankle position (§3.3) \[m\].
pub const THIGH_LENGTH: f32 = 0.116;
/// Shank length used for the ankle position (§3.3) \[m\].
pub const SHANK_LENGTH: f32 = 0.1045;

// ---------------------------------------------------------------------------
// The walking task (docs/reference/grl.md §2.2, §3)
// ---------------------------------------------------------------------------

/// Control period: 30 Hz (§1.1, §3.6) \[µs\].
pub const CONTROL_PERIOD_US: u32 = 33_333;
/// Episode timeout after the first observation (§3.8) \[s\].
pub const EPISODE_TIMEOUT_S: f32 = 25.0;
/// Control steps of an episode: the timeout's 25 s at 30 Hz, 750 (§3.8).
pub const EPISODE_STEPS: u32 =
    (EPISODE_TIMEOUT_S as u64 * 1_000_000 / CONTROL_PERIOD_US as u64) as u32;
const _: () = assert!(EPISODE_STEPS == 750);
/// Number of observation dimensions (§3.4).
pub const OBS_DIM: usize = 10;
/// Number of learned action dimensions (§3.4).
pub const ACTION_DIM: usize = 3;
/// Voltage levels per learned joint (§3.9).
pub const ACTION_LEVELS: u8 = 7;
/// Bound of the learned voltages, ±10.7 V (LW `maxvoltage`, §2.2, §3.4).
pub const ACTION_VOLTAGE_LIMIT: f32 = 10.7;
/// Tile width of each learned voltage \[V\]: GRL generalises over actions
/// (`generalizeActions`, voltage scale 0.15 ↔ 6.67 V, §3.9), so
/// neighbouring levels (3.57 V apart) share about half their tiles.
pub const ACTION_TILE_WIDTH: f32 = 6.67;
/// Clip of the held joints, ≈ ±10.6919 V (§2.2, §3.5).
pub const HELD_VOLTAGE_LIMIT: f32 = LEO_MAX_VOLTAGE;
/// Rate filter of the servo joints: sampling 30 Hz, cut-off 10 Hz (§3.2).
pub const JOINT_FILTER_HZ: [f32; 2] = [30.0, 10.0];
/// Rate filter of the torso: GRL passes the step time 1/30 where a sampling
/// frequency belongs, cut-off 25 Hz (§3.2), which makes it practically a
/// pass-through; kept so every learner sees what GRL's saw.
pub const TORSO_FILTER_HZ: [f32; 2] = [1.0 / 30.0, 25.0];
/// Shoulder P gain 5·14/3.3 V/rad and set point −15° (§3.5).
pub const SHOULDER_GAIN_SETPOINT: [f32; 2] = [5.0 * 14.0 / 3.3, -0.261799];
/// Stance knee P gain 5·14/3.3 V/rad and set point 0 (§3.5).
pub const STANCE_KNEE_GAIN_SETPOINT: [f32; 2] = [5.0 * 14.0 / 3.3, 0.0];
/// Ankle P gain 10·14/3.3 V/rad and set point 3.72° (§3.5).
pub const ANKLE_GAIN_SETPOINT: [f32; 2] = [10.0 * 14.0 / 3.3, 0.0649262];
/// Reward per step (w_t, §3.7).
pub const REWARD_TIME: f32 = -1.0;
/// Reward per joule of motor work (w_E, §3.7).
pub const REWARD_ENERGY: f32 = -3.0;
/// Reward per metre of footstep-length change (w_c, §3.7).
pub const REWARD_FOOTSTEP_DIST: f32 = 300.0;
/// Footstep lengths are clipped to ±10.20 m (L_max, §3.7).
pub const FOOTSTEP_MAX_LENGTH: f32 = 10.20;
/// Reward of a fall (w_fall, §3.7).
pub const REWARD_FALL: f32 = -125.0;
/// Fall when the torso angle φ leaves ±1 rad (§3.8).
pub const FALL_TORSO_ANGLE: f32 = 1.0;
/// Fall when the stance thigh is more than 0.36π from vertical (§3.8).
pub const FALL_STANCE_THIGH_ANGLE: f32 = 0.36 * PI;

/// The 10 observation dimensions (§3.4 order) with GRL's tile widths
/// (`cfg/leosim/sarsa.yaml`, §3.9): torso 0.14 rad and 5 rad/s, joints
/// 0.28 rad and 10 rad/s. The ranges only clamp: the torso ±π/2 (a fall
/// at |φ| > 1 ends the episode first), its rate ±20 rad/s, joint angles ±π
/// (the stops are inside), joint rates ±40 rad/s (about 7× the RX-28's
/// no-load speed; a swing leg hit by the floor moves faster).
pub const STATE: [StateDim; OBS_DIM] = {
    const ANGLE: StateDim = StateDim { min: -PI, max: PI, tile_width: 0.28, wrap: false };
    const RATE: StateDim = StateDim { min: -40.0, max: 40.0, tile_width: 10.0, wrap: false };
    [
        StateDim { min: -FRAC_PI_2, max: FRAC_PI_2, tile_width: 0.14, wrap: false },
        StateDim { min: -20.0, max: 20.0, tile_width: 5.0, wrap: false },
        ANGLE,
        RATE,
        ANGLE,
        RATE,
        ANGLE,
        RATE,
        ANGLE,
        RATE,
    ]
};

/// GRL's LEO learning parameters (§3.9, the per-step values of
/// `leo_sim_sarsa_walk.yaml` and the Schuitema constants): α 0.2,
/// γ 0.9962 (≈ 4 s horizon), λ 0.8582 (≈ 0.1 s), ε 0.05, replacing traces
/// pruned at 0.01, weights U[0, 0.01].
pub const PARAMS: SarsaParams = SarsaParams {
    alpha: 0.2,
    gamma: 0.9962,
    lambda: 0.8582,
    epsilon: 0.05,
    trace_threshold: 0.01,
    trace_kind: TraceKind::Replacing,
    init: WeightInit::Uniform { min: 0.0, max: 0.01 },
};

/// LEO's learning task: 3 learned joints × 7 levels over ±10.7 V, the
/// 10-D mirrored state, 25 s episodes at 30 Hz, a test run every 10
/// learning episodes (Section VI); its seven RX-28s, the boom's encoder,
/// the wear of both hips and both knees counted.
pub static SPEC: RobotSpec = RobotSpec {
    name: "leo",
    period_us: CONTROL_PERIOD_US,
    episode_steps: EPISODE_STEPS,
    test_interval: 10,
    state: &STATE,
    motor_dims: ACTION_DIM as u8,
    levels: MotorLevels::Uniform { min: -ACTION_VOLTAGE_LIMIT, max: ACTION_VOLTAGE_LIMIT, count: ACTION_LEVELS },
    action_tiles: Some(&[ACTION_TILE_WIDTH; ACTION_DIM]),
    params: PARAMS,
    joints: &JOINT_SPECS,
    counted: COUNTED,
    // The boom's encoder; the torso angle is minus its angle (§3.1).
    encoder: Some(EncoderSpec { counts_per_rev: 4096, sign: 1 }),
    // LEO_SUPPLY_VOLTAGE (docs/reference/grl.md §2.2).
    supply_nominal_v: crate::rx28::LEO_SUPPLY_VOLTAGE,
    paper_torque: TorqueLaw::Rule(commanded_gear_torque),
    footstep_remap: Some(FOOTSTEP_REMAP),
    half_shift: HALF_SHIFT,
    table: TableNeed::Claimed,
    vocabulary: None,
};

/// LEO's servos in [`Joint`] order (shoulder, hip L/R, knee L/R, ankle
/// L/R), with the IDs of GRL's raw order (docs/reference/grl.md §3.1:
/// shoulder 1, hip R 2, hip L 3, knee R 4, knee L 5, ankle R 6, ankle L
/// 7). `zero` is the raw position at joint angle 0 and `sign` maps the
/// servo's direction to GRL's joint sign (§1.2, §1.5): **calibrate both on
/// your robot**; these are the mid-range defaults. Each soft limit is the
/// joint's stop ([`joint_limits`]; the shoulder's ±90° where it has none)
/// widened by [`STOP_MARGIN`].
pub const JOINT_SPECS: [JointSpec; NUM_JOINTS] = [
    servo("shoulder", Joint::Shoulder, 1),
    servo("hip_left", Joint::HipLeft, 3),
    servo("hip_right", Joint::HipRight, 2),
    servo("knee_left", Joint::KneeLeft, 5),
    servo("knee_right", Joint::KneeRight, 4),
    servo("ankle_left", Joint::AnkleLeft, 7),
    servo("ankle_right", Joint::AnkleRight, 6),
];

/// Margin outside LEO's joint stops (docs/reference/grl.md §1.5) before a
/// soft-limit fault \[rad\]: the stops are soft springs, a joint that
/// passes them by this much is being driven into them.
pub const STOP_MARGIN: f32 = 0.15;

/// The shoulder has no stop (§1.5, [`joint_limits`] is `None`): its soft
/// limit, a fault and not a physical stop, is ±90°.
pub const SHOULDER_SOFT_LIMITS: [f32; 2] = [-FRAC_PI_2, FRAC_PI_2];

/// One of LEO's RX-28s: its ID, mid-range calibration and soft limit.
const fn servo(name: &'static str, joint: Joint, id: u8) -> JointSpec {
    let [min, max] = match joint_limits(joint) {
        Some(stop) => stop,
        None => SHOULDER_SOFT_LIMITS,
    };
    JointSpec {
        name,
        servo: &crate::servo::RX28,
        id,
        zero: 512,
        sign: 1,
        soft_limit: Some(SoftLimit { min: min - STOP_MARGIN, max: max + STOP_MARGIN }),
    }
}

/// LEO's foot switches, as [`crate::robot::Sensed::contacts`] carries them.
pub mod contact {
    /// Right toe.
    pub const TOE_R: u8 = 1 << 0;
    /// Right heel.
    pub const HEEL_R: u8 = 1 << 1;
    /// Left toe.
    pub const TOE_L: u8 = 1 << 2;
    /// Left heel.
    pub const HEEL_L: u8 = 1 << 3;
    /// Right foot.
    pub const RIGHT: u8 = TOE_R | HEEL_R;
    /// Left foot.
    pub const LEFT: u8 = TOE_L | HEEL_L;
}

/// At a footstep the learned dimensions trade joints: the new stance hip
/// was the swing hip, the new swing hip was the stance hip, and the new
/// swing knee was the stance knee, held by its P law rather than learned.
/// So the policy's memory moves with the joints — stance hip ← swing hip,
/// swing hip ← stance hip, swing knee at rest (0 V) — as GRL's LEO
/// action sampler mirrors PADA's previous action at touchdown and sets the
/// auto-actuated knee's entry to 0 (docs/reference/grl.md §6.2). Without it a physical
/// hip's voltage could jump by the whole range at every footstep.
pub const FOOTSTEP_REMAP: [Option<u8>; crate::action_space::MAX_ACTION_DIMS] = [Some(1), Some(0), None, None];

/// 16-bit weights hold ±2048 in steps of 1/16: LEO's Q-values stay far
/// inside. Walking at 0.5 m/s earns about 300 · 0.5/30 − 1 = 4 per step,
/// and with γ = 0.9962 (a horizon of 1/(1 − γ) ≈ 263 steps) Q ≈ 1000; a
/// fall costs 125 once.
pub const HALF_SHIFT: u8 = 12;

/// The 10-D mirrored observation (§3.4): φ, φ̇, q_hip,st, q̇_hip,st,
/// q_hip,sw, q̇_hip,sw, q_knee,st, q̇_knee,st, q_knee,sw, q̇_knee,sw.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Observation(pub [f32; OBS_DIM]);

/// The servo joints' rate filter: 30 Hz sampling, 10 Hz cut-off (§3.2).
pub fn joint_rate_filter() -> RateFilter {
    RateFilter::new(JOINT_FILTER_HZ[0], JOINT_FILTER_HZ[1])
}

/// The torso's rate filter as GRL configures it (§3.2).
pub fn torso_rate_filter() -> RateFilter {
    RateFilter::new(TORSO_FILTER_HZ[0], TORSO_FILTER_HZ[1])
}

/// Horizontal ankle position relative to the hip (§3.3):
/// x_a = 0.116·sin(φ + q_hip) + 0.1045·sin(φ + q_hip + q_knee).
pub fn ankle_x(phi: f32, q_hip: f32, q_knee: f32) -> f32 {
    THIGH_LENGTH * libm::sinf(phi + q_hip) + SHANK_LENGTH * libm::sinf(phi + q_hip + q_knee)
}

/// Voltages of the held joints (§3.5), from the current joint angles and
/// the stance leg, clipped to ±10.6919 V: shoulder, stance knee and both
/// ankles, proportional only (GRL has no D term). Returns (joint, voltage)
/// pairs.
pub fn held_voltages(angles: &[f32; NUM_JOINTS], stance: Leg) -> [(Joint, f32); 4] {
    let knee = stance.knee();
    [
        (Joint::Shoulder, hold(SHOULDER_GAIN_SETPOINT, angles[Joint::Shoulder as usize])),
        (knee, hold(STANCE_KNEE_GAIN_SETPOINT, angles[knee as usize])),
        (Joint::AnkleLeft, hold(ANKLE_GAIN_SETPOINT, angles[Joint::AnkleLeft as usize])),
        (Joint::AnkleRight, hold(ANKLE_GAIN_SETPOINT, angles[Joint::AnkleRight as usize])),
    ]
}

/// A P law `gain·(set point − q)` clipped to the held joints' limit.
fn hold([gain, setpoint]: [f32; 2], q: f32) -> f32 {
    (gain * (setpoint - q)).clamp(-HELD_VOLTAGE_LIMIT, HELD_VOLTAGE_LIMIT)
}

/// The P gain of `joint` when it is held [V/rad]: the ankles' (§3.5) for
/// the ankles, the shoulder's and knees' for every other joint. The
/// firmware holds every joint at the start pose with these between
/// episodes, while a person sets LEO upright.
pub fn hold_gain(joint: Joint) -> f32 {
    match joint {
        Joint::AnkleLeft | Joint::AnkleRight => ANKLE_GAIN_SETPOINT[0],
        _ => SHOULDER_GAIN_SETPOINT[0],
    }
}

/// Voltages that hold every joint at `targets` with [`hold_gain`], clipped
/// to the held joints' limit.
pub fn pose_voltages(angles: &[f32; NUM_JOINTS], targets: &[f32; NUM_JOINTS]) -> [f32; NUM_JOINTS] {
    let mut u = [0.0; NUM_JOINTS];
    for j in JOINTS {
        let k = j as usize;
        u[k] = hold([hold_gain(j), targets[k]], angles[k]);
    }
    u
}

/// The joints the three learned actions drive with this stance leg (§3.4):
/// stance hip, swing hip, swing knee.
pub fn learned_joints(stance: Leg) -> [Joint; ACTION_DIM] {
    [stance.hip(), stance.other().hip(), stance.other().knee()]
}

/// All seven voltages for one control step (§3.6 step 1): the learned
/// voltages (clipped to ±10.7 V; non-finite → 0 V) on the stance hip, swing
/// hip and swing knee, the held joints' P laws on the rest.
pub fn joint_voltages(action: [f32; ACTION_DIM], angles: &[f32; NUM_JOINTS], stance: Leg) -> [f32; NUM_JOINTS] {
    let mut u = [0.0f32; NUM_JOINTS];
    for (joint, v) in held_voltages(angles, stance) {
        u[joint as usize] = v;
    }
    for (joint, v) in learned_joints(stance).into_iter().zip(action) {
        u[joint as usize] = sanitize_action(v);
    }
    u
}

/// A learned voltage clipped to ±10.7 V; non-finite → 0 V.
pub fn sanitize_action(v: f32) -> f32 {
    if v.is_finite() {
        v.clamp(-ACTION_VOLTAGE_LIMIT, ACTION_VOLTAGE_LIMIT)
    } else {
        0.0
    }
}

/// Motor work of one control step (§3.7): Σ over both hips and both knees
/// of max(0, U·I)·T with I = (U − k·G·ω̄)/R, ω̄ the mean of the previous
/// and current filtered rate and T the control period.
pub fn step_energy(
    voltages: &[f32; NUM_JOINTS],
    filtered_prev: &[f32; NUM_JOINTS],
    filtered_now: &[f32; NUM_JOINTS],
) -> f32 {
    let servo = Rx28::LEO;
    let period = CONTROL_PERIOD_US as f32 * 1e-6;
    [Joint::HipLeft, Joint::HipRight, Joint::KneeLeft, Joint::KneeRight]
        .iter()
        .map(|&j| {
            let k = j as usize;
            let w = 0.5 * (filtered_prev[k] + filtered_now[k]);
            let u = voltages[k];
            (u * servo.current(u, w)).max(0.0) * period
        })
        .sum()
}

/// Reward of one step (§3.7): r = −1 − 3·E + 300·(clip(L) − clip(L_prev))
/// − 125·\[fall\], lengths clipped to ±10.2 m.
pub fn reward(energy: f32, update: &StanceUpdate, fall: bool) -> f32 {
    let clip = |l: f32| l.clamp(-FOOTSTEP_MAX_LENGTH, FOOTSTEP_MAX_LENGTH);
    REWARD_TIME
        + REWARD_ENERGY * energy
        + REWARD_FOOTSTEP_DIST * (clip(update.length) - clip(update.previous_length))
        + if fall { REWARD_FALL } else { 0.0 }
}

/// "Doomed to fall" (§3.8): φ outside ±1 rad, or the stance thigh more than
/// 0.36π from vertical (|φ + q_hip,st|); a NaN is a fall.
pub fn is_fall(phi: f32, q_hip_stance: f32) -> bool {
    !(phi.abs() <= FALL_TORSO_ANGLE && (phi + q_hip_stance).abs() <= FALL_STANCE_THIGH_ANGLE)
}

/// The mirrored observation (§3.4) from the torso angle φ and its filtered
/// rate, the joint angles and filtered rates, and the stance leg.
pub fn observe(
    phi: f32,
    phi_rate: f32,
    angles: &[f32; NUM_JOINTS],
    rates: &[f32; NUM_JOINTS],
    stance: Leg,
) -> Observation {
    let sw = stance.other();
    let (hs, hw, ks, kw) = (stance.hip() as usize, sw.hip() as usize, stance.knee() as usize, sw.knee() as usize);
    Observation([
        phi, phi_rate, angles[hs], rates[hs], angles[hw], rates[hw], angles[ks], rates[ks], angles[kw], rates[kw],
    ])
}

/// The gearboxes whose fatigue is counted, in this order: both hips and
/// both knees (the shoulder and ankles are held and never learned), the
/// joints the learned actions drive as stance and swing roles trade legs.
pub const GEARBOXES: [Joint; 4] = [Joint::HipLeft, Joint::HipRight, Joint::KneeLeft, Joint::KneeRight];

/// [`GEARBOXES`] as the definition's run of joints.
pub const COUNTED: JointRange = JointRange { start: Joint::HipLeft as u8, end: Joint::KneeRight as u8 + 1 };
const _: () = {
    let mut i = 0;
    while i < GEARBOXES.len() {
        assert!(GEARBOXES[i] as u8 == COUNTED.start + i as u8);
        i += 1;
    }
    assert!(COUNTED.len() == GEARBOXES.len());
};

/// The gearbox torque as the paper takes it (Section IV): linear in the
/// commanded voltage, the RX-28's stall torque at that voltage,
/// η·G·k·U/R ≈ 0.167 N·m/V (1.79 N·m at 10.7 V; §2.1), back-EMF left out.
pub fn commanded_gear_torque(voltage: f32) -> f32 {
    Rx28::LEO.estimate_joint_torque(voltage, 0.0)
}

/// The gearbox torque the fatigue counter sees on a servo that applies
/// `voltage` at joint rate `rate`, as the robot can estimate it: the RX-28
/// model in steady motion, η·G·k·(U − G·k·q̇)/R (§2.1,
/// [`Rx28::estimate_joint_torque`]).
pub fn estimated_gear_torque(voltage: f32, rate: f32) -> f32 {
    Rx28::LEO.estimate_joint_torque(voltage, rate)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn filter_coefficients_match_section_3_2() {
        let (b, a1) = joint_rate_filter().coefficients();
        assert!((b - 0.511527).abs() < 1e-5 && (a1 - 0.023055).abs() < 1e-5, "{b} {a1}");
        let (b, a1) = torso_rate_filter().coefficients();
        assert!((b - 0.999576).abs() < 1e-5 && (a1 - 0.999152).abs() < 1e-5, "{b} {a1}");
        // DC gain 1: a constant input is passed through.
        let mut f = joint_rate_filter();
        let mut y = 0.0;
        for _ in 0..50 {
            y = f.update(2.0);
        }
        assert!((y - 2.0).abs() < 1e-4);
        f.reset();
        assert_eq!(f.value(), 0.0);
    }

    #[test]
    fn start_pose_in_joint_angles() {
        let want = [-0.261799, 0.10, 0.82, 0.0, -1.27, 0.0, 0.0];
        for (a, b) in START_JOINT_ANGLES.iter().zip(want) {
            assert!((a - b).abs() < 1e-6, "{START_JOINT_ANGLES:?}");
        }
        assert!(!is_fall(START_PHI, START_JOINT_ANGLES[Joint::HipLeft as usize]));
    }

    #[test]
    fn held_joints_and_clipping() {
        let mut q = [0.0f32; NUM_JOINTS];
        q[Joint::Shoulder as usize] = -0.261799;
        q[Joint::KneeRight as usize] = -0.1;
        q[Joint::AnkleLeft as usize] = 0.0649262;
        q[Joint::AnkleRight as usize] = 2.0;
        let u = joint_voltages([20.0, f32::NAN, -3.0], &q, Leg::Right);
        assert!(u[Joint::Shoulder as usize].abs() < 1e-4);
        assert!((u[Joint::KneeRight as usize] - 21.2121 * 0.1).abs() < 1e-3);
        assert!(u[Joint::AnkleLeft as usize].abs() < 1e-4);
        assert!((u[Joint::AnkleRight as usize] + HELD_VOLTAGE_LIMIT).abs() < 1e-5);
        // Learned: stance hip (right), swing hip (left), swing knee (left).
        assert_eq!(u[Joint::HipRight as usize], ACTION_VOLTAGE_LIMIT);
        assert_eq!(u[Joint::HipLeft as usize], 0.0);
        assert_eq!(u[Joint::KneeLeft as usize], -3.0);
        // Holding a pose: zero at the pose, clipped far from it.
        let at = pose_voltages(&START_JOINT_ANGLES, &START_JOINT_ANGLES);
        assert!(at.iter().all(|v| v.abs() < 1e-6), "{at:?}");
        let far = pose_voltages(&[3.0; NUM_JOINTS], &START_JOINT_ANGLES);
        assert!(far.iter().all(|v| (v + HELD_VOLTAGE_LIMIT).abs() < 1e-5), "{far:?}");
    }

    #[test]
    fn reward_and_fall() {
        let up = StanceUpdate { length: 0.05, previous_length: 0.03, footstep: false };
        assert!((reward(0.1, &up, false) - (-1.0 - 0.3 + 6.0)).abs() < 1e-4);
        assert!((reward(0.0, &up, true) - (-1.0 + 6.0 - 125.0)).abs() < 1e-4);
        assert!(!is_fall(-0.1, 0.1));
        assert!(is_fall(1.01, 0.0));
        assert!(is_fall(-1.01, 0.0));
        assert!(is_fall(0.5, 0.7));
        assert!(is_fall(f32::NAN, 0.0));
    }

    #[test]
    fn energy_counts_only_positive_work_of_hips_and_knees() {
        let mut u = [0.0f32; NUM_JOINTS];
        u[Joint::HipLeft as usize] = 10.0;
        u[Joint::AnkleLeft as usize] = 10.0; // ankles excluded
        let zero = [0.0; NUM_JOINTS];
        let e = step_energy(&u, &zero, &zero);
        assert!((e - 10.0 * 10.0 / 8.6 * 0.033333).abs() < 1e-4, "{e}");
        // Regenerative braking is not counted as negative work.
        let mut w = [0.0; NUM_JOINTS];
        w[Joint::HipLeft as usize] = 10.0; // back-EMF 19 V > 10 V: current < 0
        assert_eq!(step_energy(&u, &w, &w), 0.0);
    }

    #[test]
    fn observation_is_mirrored() {
        let q = [0.0, 1.0, 2.0, 3.0, 4.0, 5.0, 6.0];
        let r = q.map(|x| x * 10.0);
        let l = observe(0.5, 0.6, &q, &r, Leg::Left).0;
        assert_eq!(l, [0.5, 0.6, 1.0, 10.0, 2.0, 20.0, 3.0, 30.0, 4.0, 40.0]);
        let rr = observe(0.5, 0.6, &q, &r, Leg::Right).0;
        assert_eq!(rr, [0.5, 0.6, 2.0, 20.0, 1.0, 10.0, 4.0, 40.0, 3.0, 30.0]);
    }

    #[test]
    fn the_gear_torque_estimate_is_the_rx28_model() {
        // Stall torque at 10.6919 V ≈ 2.3803 N·m before η (docs/reference/grl.md §2.1).
        let stall = estimated_gear_torque(10.6919, 0.0);
        assert!((stall - 0.75 * 2.3803).abs() < 1e-3, "{stall}");
        // Back-EMF can reverse the torque's sign (braking).
        assert!(estimated_gear_torque(1.0, 3.0) < 0.0);
    }
}
