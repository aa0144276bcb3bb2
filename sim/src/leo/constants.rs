//! Every number of the LEO model in one place; the walking task's numbers,
//! shared with the firmware, come from `pada_core::robot::leo` (re-exported
//! below).
//!
//! Each constant names the section of `docs/reference/grl.md` it
//! comes from (a clean-room restatement of GRL's `leoconfig.xml`,
//! `leolearnwalking-sarsa-tc.xml` and `LeoBhWalkSym.cpp`). The few numbers
//! that are choices of this simulator, not facts of the reference (rapier's
//! step, solver iterations and contact softness), are grouped at the end and
//! justified in `sim/src/leo/README.md`.
//!
//! Frames (§1.1–1.2): z is up, the robot walks in +x, every hinge axis is y.
//! A point "(x, z)" on a body is relative to that body's reference origin;
//! body pitch θ is a rotation about +y (positive θ tips the body's +z toward
//! +x). Hinge angles follow ODE: q = θ_parent − θ_child, so a positive torque
//! increases q.

// Numbers are written as the reference prints them (more digits than f32
// holds; limits such as −0.785398 are the reference's degrees, not π/4).
#![allow(clippy::excessive_precision, clippy::approx_constant)]

use pada_core::rx28;

// The facts the walking task shares with the firmware live once, in
// `pada_core::robot::leo` (joint limits, start pose, the task's constants);
// they are re-exported here so the model reads them by the same names.
pub use pada_core::robot::leo::{
    ACTION_VOLTAGE_LIMIT, ANKLE_GAIN_SETPOINT, ANKLE_LIMITS, EPISODE_TIMEOUT_S as EPISODE_TIMEOUT,
    FALL_STANCE_THIGH_ANGLE, FALL_TORSO_ANGLE, FOOTSTEP_MAX_LENGTH,
    HELD_VOLTAGE_LIMIT as AUTO_VOLTAGE_LIMIT, HIP_LIMITS, INIT_ARM_PITCH, INIT_LEFT_LEG_PITCH,
    INIT_RIGHT_LEG_PITCH, INIT_TORSO_PITCH, JOINT_FILTER_HZ, KNEE_LIMITS, REWARD_ENERGY,
    REWARD_FALL, REWARD_FOOTSTEP_DIST, REWARD_TIME, SHANK_LENGTH, SHOULDER_GAIN_SETPOINT,
    STANCE_KNEE_GAIN_SETPOINT, THIGH_LENGTH, TORSO_FILTER_HZ,
};

/// Control period: 30 Hz, voltages held over it (§1.1, §3.6): the robot
/// definition's 33 333 µs, the learner's period on the chip too.
pub const CONTROL_PERIOD: f32 = pada_core::robot::leo::CONTROL_PERIOD_US as f32 * 1e-6;

// ---------------------------------------------------------------------------
// §1.1 World, integration, timing
// ---------------------------------------------------------------------------

/// Gravity in m/s², acting along −z (§1.1).
pub const GRAVITY: f32 = 9.81;
/// GRL's physics sub-steps per control period (1/5010 s, §1.1), for reference.
pub const REFERENCE_SUBSTEPS: u32 = 167;

// ---------------------------------------------------------------------------
// §1.3 Bodies: mass [kg], IYY about the CoM [kg m²], CoM (x, z) from origin [m]
// ---------------------------------------------------------------------------

/// IXX = IZZ of every body ("inertiadontcare", §1.2). Irrelevant in the plane.
pub const INERTIA_DONT_CARE: f32 = 0.001;

/// Raw torso (without the boom) mass (§1.3).
pub const TORSO_RAW_MASS: f32 = 0.91326;
/// Raw torso CoM (§1.3).
pub const TORSO_RAW_COM: [f32; 2] = [-0.00102, 0.009945];
/// Raw torso IYY (§1.3).
pub const TORSO_RAW_IYY: f32 = 0.004676374;

/// Arm mass (§1.3).
pub const ARM_MASS: f32 = 0.095;
/// Arm IYY (§1.3).
pub const ARM_IYY: f32 = 0.00087318718;
/// Arm CoM (§1.3).
pub const ARM_COM: [f32; 2] = [0.05308, -0.14260];

/// Upper leg (thigh) mass (§1.3).
pub const THIGH_MASS: f32 = 0.17978;
/// Upper leg IYY (§1.3).
pub const THIGH_IYY: f32 = 0.000273133;
/// Upper leg CoM (§1.3).
pub const THIGH_COM: [f32; 2] = [0.00285, -0.00481];

/// Lower leg (shank) mass (§1.3).
pub const SHANK_MASS: f32 = 0.12691;
/// Lower leg IYY (§1.3).
pub const SHANK_IYY: f32 = 0.000153379;
/// Lower leg CoM (§1.3).
pub const SHANK_COM: [f32; 2] = [0.00804, -0.00867];

/// Foot mass (§1.3).
pub const FOOT_MASS: f32 = 0.07319;
/// Foot IYY (§1.3).
pub const FOOT_IYY: f32 = 0.000048812;
/// Foot CoM (§1.3).
pub const FOOT_COM: [f32; 2] = [0.00048, 0.00461];

// ---------------------------------------------------------------------------
// §1.3 Anchors (x, z) on each body [m]
// ---------------------------------------------------------------------------

/// Hip anchor on the torso (both hips share it, §1.3, §1.5).
pub const TORSO_HIP_ANCHOR: [f32; 2] = [0.00273, -0.120775];
/// Shoulder anchor on the torso (§1.3).
pub const TORSO_SHOULDER_ANCHOR: [f32; 2] = [-0.00543, 0.091275];
/// Shoulder anchor on the arm (§1.3).
pub const ARM_SHOULDER_ANCHOR: [f32; 2] = [0.0, 0.0];
/// Hip anchor on the thigh (§1.3).
pub const THIGH_HIP_ANCHOR: [f32; 2] = [0.0, 0.058];
/// Knee anchor on the thigh (§1.3).
pub const THIGH_KNEE_ANCHOR: [f32; 2] = [0.0, -0.058];
/// Knee anchor on the shank (4.05 mm behind the shank axis, §1.3, §1.5).
pub const SHANK_KNEE_ANCHOR: [f32; 2] = [-0.00405, 0.05225];
/// Ankle anchor on the shank (§1.3).
pub const SHANK_ANKLE_ANCHOR: [f32; 2] = [0.0, -0.05225];
/// Ankle anchor on the foot (§1.3).
pub const FOOT_ANKLE_ANCHOR: [f32; 2] = [-0.009, 0.03559];

// ---------------------------------------------------------------------------
// §1.4 The boom, folded into the torso
// ---------------------------------------------------------------------------

/// Boom mass (§1.4).
pub const BOOM_MASS: f32 = 0.860;
/// Distance of the boom's CoM from its pivot (§1.4).
pub const BOOM_COM_DISTANCE: f32 = 0.835;
/// Boom length, pivot → robot middle (§1.4).
pub const BOOM_LENGTH: f32 = 1.70;
/// Boom inertia about the pivot's vertical axis (§1.4).
pub const BOOM_PIVOT_INERTIA: f32 = 0.31863;
/// Horizontal (inertial) equivalent mass of the boom at the robot,
/// (d²·m + I)/L² ≈ 0.317731 kg, added to the torso at the hip anchor (§1.4).
pub const BOOM_HORIZONTAL_MASS: f32 = (BOOM_COM_DISTANCE * BOOM_COM_DISTANCE * BOOM_MASS
    + BOOM_PIVOT_INERTIA)
    / (BOOM_LENGTH * BOOM_LENGTH);
/// Vertical (weight) equivalent mass of the boom, m·d/L ≈ 0.422412 kg (§1.4).
pub const BOOM_VERTICAL_MASS: f32 = BOOM_MASS * BOOM_COM_DISTANCE / BOOM_LENGTH;
/// The constant extra world-frame vertical force on the torso,
/// (m_bz − m_bx)·(−g) ≈ −1.026915 N, applied every sub-step (§1.4).
pub const BOOM_EXTRA_FORCE_Z: f32 = (BOOM_VERTICAL_MASS - BOOM_HORIZONTAL_MASS) * -GRAVITY;
/// Body point of the torso where the extra force acts (§1.4; GRL's comment
/// wonders whether x should have been 0.00273, kept as in the reference).
pub const BOOM_FORCE_POINT: [f32; 2] = [0.02, -0.120775];

/// Torso mass with the boom's horizontal mass folded in, ≈ 1.230991 kg (§1.4).
pub const TORSO_MASS: f32 = TORSO_RAW_MASS + BOOM_HORIZONTAL_MASS;
/// Torso CoM with the boom mass at the hip anchor, ≈ (−0.0000521, −0.0237952) (§1.4).
pub const TORSO_COM: [f32; 2] = [
    (TORSO_RAW_MASS * TORSO_RAW_COM[0] + BOOM_HORIZONTAL_MASS * TORSO_HIP_ANCHOR[0]) / TORSO_MASS,
    (TORSO_RAW_MASS * TORSO_RAW_COM[1] + BOOM_HORIZONTAL_MASS * TORSO_HIP_ANCHOR[1]) / TORSO_MASS,
];
/// Squared distance in the plane.
const fn dist2(a: [f32; 2], b: [f32; 2]) -> f32 {
    (a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1])
}
/// Torso IYY about the new CoM by the parallel-axis rule, ≈ 0.00870763 kg m² (§1.4).
pub const TORSO_IYY: f32 = TORSO_RAW_IYY
    + TORSO_RAW_MASS * dist2(TORSO_RAW_COM, TORSO_COM)
    + BOOM_HORIZONTAL_MASS * dist2(TORSO_HIP_ANCHOR, TORSO_COM);

// ---------------------------------------------------------------------------
// §1.5 Joints: limits [rad] and soft stops (K [N m/rad], D [N m s/rad])
// ---------------------------------------------------------------------------

/// Hip stop spring and damper (§1.5).
pub const HIP_STOP: [f32; 2] = [100.0, 10.0];
/// Knee stop spring and damper (§1.5).
pub const KNEE_STOP: [f32; 2] = [50.0, 5.0];
/// Ankle stop spring and damper (§1.5).
pub const ANKLE_STOP: [f32; 2] = [100.0, 10.0];

/// Every servo joint: the RX-28 of §2.1 (dry friction 0.2 N m, §1.5).
pub const SERVO: rx28::Rx28 = rx28::Rx28::LEO;

// ---------------------------------------------------------------------------
// §1.6 Contact spheres (centre (x, z) on the body, radius) and §1.7 materials
// ---------------------------------------------------------------------------

/// Radius of the toe, heel, knee and hand wheels' "ring" (§1.6).
pub const WHEEL_RADIUS: f32 = 0.0035;
/// Toe sphere on the foot (§1.6).
pub const FOOT_TOE: [f32; 2] = [0.0405, -0.0095];
/// Heel sphere on the foot (§1.6).
pub const FOOT_HEEL: [f32; 2] = [-0.0405, -0.0095];
/// Knee sphere on the shank (§1.6).
pub const SHANK_KNEE_SPHERE: [f32; 2] = [0.0405, 0.06875];
/// Hand sphere on the arm (§1.6).
pub const ARM_HAND: [f32; 2] = [0.122050, -0.277697];
/// Torso's rear bumper ("asspamper"), centre and radius (§1.6).
pub const TORSO_ASS_PAMPER: ([f32; 2], f32) = ([-0.01116, -0.122005], 0.068);
/// Torso's front shoulder bumper (§1.6).
pub const TORSO_SHOULDER_FRONT: ([f32; 2], f32) = ([0.02184, 0.090775], 0.050);
/// Torso's rear shoulder bumper (§1.6).
pub const TORSO_SHOULDER_BACK: ([f32; 2], f32) = ([-0.02316, 0.120775], 0.035);

/// Friction coefficient rubber–linoleum (toe, heel, knee, hand; §1.7).
pub const RUBBER_FRICTION: f32 = 100.0;
/// Friction coefficient foam–linoleum (torso bumpers; §1.7).
pub const FOAM_FRICTION: f32 = 10.0;
/// Contact spring/damper rubber–linoleum (K [N/m], D [N s/m]; §1.7), for
/// reference: the simulated contacts are stiff instead (see
/// [`CONTACT_NATURAL_FREQUENCY`]); the foam pair (1200 N/m, 40 N s/m) only
/// matters once the torso is on the floor, i.e. after a fall.
pub const RUBBER_CONTACT: [f32; 2] = [2.5e4, 250.0];
/// Contact spring/damper foam–linoleum (§1.7), for reference.
pub const FOAM_CONTACT: [f32; 2] = [1200.0, 40.0];

// ---------------------------------------------------------------------------
// §1.8 Initial condition
// ---------------------------------------------------------------------------

/// The point of the left foot placed at the world origin: the bottom of the
/// left heel wheel (§1.8).
pub const INIT_LEFT_FOOT_POINT: [f32; 2] = [-0.0405, -0.013];
/// Half-width C of the optional initial-pose randomisation (§1.8; off by
/// default in every LEO configuration).
pub const INIT_RANDOMIZATION: f32 = 0.0872639;

// ---------------------------------------------------------------------------
// Blow-up guards (bad input): not from the reference.
// ---------------------------------------------------------------------------

/// A body further than this from the start (m) means the simulation blew up.
pub const BLOWUP_DISTANCE: f32 = 100.0;
/// A joint faster than this (rad/s) means the simulation blew up: 20× the
/// RX-28's no-load speed (≈ 5.6 rad/s at 10.7 V, §2.1).
pub const BLOWUP_JOINT_RATE: f32 = 100.0;

// ---------------------------------------------------------------------------
// Choices of this simulator (see README.md for the measurements)
// ---------------------------------------------------------------------------

/// Physics steps per control period: h = (1/30)/N = 8.3 ms. The coarsest
/// step at which halving it moves the passive fall by less than 5 % and
/// the torso angle by less than 0.02 rad (0.3 %, 0.007 rad) and every
/// sanity check holds; at 3 the 0-V robot gains 1.6 mJ while it falls (the
/// stops switch on at step boundaries), at 2 the stops overshoot by
/// 0.08 rad (`README.md`).
pub const SUBSTEPS: u32 = 4;
/// Rapier solver iterations per physics step: 1. More are sub-steps inside
/// rapier that the stops, friction ties and contacts do not follow (they
/// are set once per physics step), and they converge worse (3 × 2 against
/// 6 × 2: 1.1 %, 0.026 rad).
pub const SOLVER_ITERATIONS: usize = 1;
/// Natural frequency (Hz) of rapier's contact softness: stiff, so that the
/// contacts are rigid in effect.
///
/// The reference's rubber pair is a soft spring (K = 2.5e4 N/m, D = 250
/// N s/m, §1.7: ≈ 0.4 mm under LEO's weight; ≈ 25 Hz and ζ ≈ 0.8 for the
/// ≈ 1 kg LEO puts on one foot), and in the earlier, unconverged model this setting matched
/// it. But rapier's softness is not a spring: it acts in a biased solver
/// pass, a second pass then removes all approach velocity, and so the
/// penetration builds up at a rate set by the step (after 0.2 s of
/// standing: 0.6 mm at 11 ms steps, 0.14 mm at 0.05 ms steps). With a soft
/// contact the passive fall therefore kept moving as the step shrank (3–5 %
/// between 48 and 192 steps per control period). At 100 Hz, ζ = 1 the
/// penetration stays near g/ω² (tens of µm) at every step and the fall
/// converges at first order (`README.md`); the reference's fraction of a
/// millimetre of rubber compression is what this leaves out.
pub const CONTACT_NATURAL_FREQUENCY: f32 = 100.0;
/// Damping ratio of rapier's contact softness (see
/// [`CONTACT_NATURAL_FREQUENCY`]).
pub const CONTACT_DAMPING_RATIO: f32 = 1.0;
/// A toe or heel counts as touching the floor when its sphere's lowest point
/// is at most this high (m). ODE's sensor fires on touch (§1.7); rapier's
/// solver may leave a resting sphere a hair above the plane.
pub const CONTACT_SENSOR_TOLERANCE: f32 = 5.0e-4;
