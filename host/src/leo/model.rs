//! LEO as a rapier3d world, built in one function from the named constants
//! of [`super::constants`] (`docs/reference/grl.md` §1), and its physics step.
//!
//! # How the reference model maps onto rapier
//!
//! - **Planar motion** (§1.4: GRL keeps LEO planar only by symmetry). Here
//!   the robot is one reduced-coordinate multibody whose root is a fixed
//!   anchor and whose first joint is free in x, z and pitch, locked in roll
//!   and yaw, and held at y = 0 by a stiff implicit spring (the lateral tie,
//!   [`LATERAL_TIE`]: with y locked outright rapier's contact friction
//!   fails, see there). Out-of-plane rotation has no coordinate at all.
//! - **The boom** (§1.4) is folded into the torso's mass, CoM and inertia
//!   (see the constants) plus the extra vertical force, applied at its torso
//!   point every physics step. GRL's massless `virtualBoom` body is not
//!   needed: the root joint's angle is the torso pitch.
//! - **Hinges** (§1.5) are revolute multibody joints about −y, so that
//!   rapier's joint coordinate equals ODE's q = θ_parent − θ_child (§1.2).
//! - **Soft joint stops** (§1.5): when a joint is beyond a limit, rapier's
//!   implicit joint spring pulls it back with the stop's K, and (while the
//!   joint moves further in) the damper D is added to the joint's implicit
//!   damping: what ODE's ERP/CFM limit with the same K and D does. Switched
//!   per physics step, so the stop never pulls a joint into the limit.
//! - **RX-28 servos** (§2.1) in their rigid-armature form
//!   ([`pada_core::rx28::ReducedJoint`]): the reflected rotor inertia is the
//!   multibody's per-DoF armature, the back-EMF is its per-DoF (implicit)
//!   damping, and the held voltage becomes a constant joint torque
//!   η·G·k·U/R over the control period, applied as opposite torques on the
//!   two bodies of the joint.
//! - **Dry friction** of 0.2 N m (§1.5, ODE's "motor with target velocity
//!   0 and maximum torque 0.2"): stick and slip per joint
//!   ([`super::stiction`]); a held joint is tied to its angle by a stiff
//!   implicit spring, a sliding one feels the constant friction torque.
//!   Rapier's own per-DoF friction loss is the same constraint as ODE's but
//!   its solver leaves a held joint creeping at a rate set by the step.
//! - **Contacts** (§1.6–1.7): balls on the bodies, the floor a half-space
//!   z ≤ 0; only robot–floor pairs collide (collision groups). Friction uses
//!   the minimum of the two coefficients (floor 100, rubber 100, foam 10).
//!   The contacts are stiff (rigid in effect), not the reference's soft
//!   springs: see [`CONTACT_NATURAL_FREQUENCY`].
//!
//! The step size, solver iterations and contact softness are chosen in
//! `README.md` next to this file.

// Index loops over several parallel fixed-size arrays (joints, DoFs, links)
// read more plainly than zipped iterators here.
#![allow(clippy::needless_range_loop)]

use pada_core::rx28::ReducedJoint;
use rapier3d::prelude::*;

use super::constants::*;
use super::stiction::{FrictionState, Stiction};

/// Index of a revolute joint's free axis (rotation about its local x) in
/// rapier's 6-DoF spatial layout, for the joint springs.
const ANGULAR_X: usize = 3;
/// Index of the lateral (y) translation in rapier's spatial layout.
const LINEAR_Y: usize = 1;

/// The lateral tie of the root: stiffness (N/m) and damping (N s/m) of an
/// implicit spring that holds the robot at y = 0.
///
/// Why y is a DoF at all: with y locked, the contacts' out-of-plane
/// friction direction has no mobility, and rapier's solver divides by a
/// rounding error there (1/(J·M⁻¹·Jᵀ) of a row that should be 0 but is
/// not once the bodies are pitched). The resulting impulses fill the whole
/// friction cone, which rapier caps as one 2-D vector, so nothing was left
/// for the in-plane direction: the standing robot slid under a 1 N push as
/// if the floor had no friction, whatever μ (measured, `README.md`). With y
/// free and tied, that row has the robot's mass behind it. The tie is the
/// boom's lateral stiffness in spirit but not a fact of the reference:
/// 1e7 N/m moves LEO (≈ 2.3 kg) by 0.5 µm under a 5 N side push, and the
/// damper (≈ 2·√(k·m)) keeps it from ringing; rapier integrates both
/// implicitly, so they are stable at any step.
const LATERAL_TIE: [f32; 2] = [1.0e7, 1.0e4];

/// The eight bodies of LEO (§1.3; GRL's `virtualBoom` is not needed).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Body {
    /// Torso with the boom folded in.
    Torso = 0,
    /// Arm (shoulder link).
    Arm,
    /// Left upper leg.
    ThighLeft,
    /// Left lower leg.
    ShankLeft,
    /// Left foot.
    FootLeft,
    /// Right upper leg.
    ThighRight,
    /// Right lower leg.
    ShankRight,
    /// Right foot.
    FootRight,
}

/// Number of bodies.
pub const NUM_BODIES: usize = 8;

/// The seven servo joints (§1.5), in the order of the robot's one
/// definition (`pada_core::robot::leo`), which the firmware's servo table
/// uses too.
pub use pada_core::robot::leo::{Joint, JOINTS, NUM_JOINTS};

/// Contact material (§1.7).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Material {
    Rubber,
    Foam,
}

/// Mass properties and contact spheres of one body (§1.3, §1.6).
struct BodySpec {
    mass: f32,
    iyy: f32,
    com: [f32; 2],
    spheres: &'static [([f32; 2], f32, Material)],
}

const TORSO_SPHERES: [([f32; 2], f32, Material); 3] = [
    (TORSO_ASS_PAMPER.0, TORSO_ASS_PAMPER.1, Material::Foam),
    (
        TORSO_SHOULDER_FRONT.0,
        TORSO_SHOULDER_FRONT.1,
        Material::Foam,
    ),
    (TORSO_SHOULDER_BACK.0, TORSO_SHOULDER_BACK.1, Material::Foam),
];
const ARM_SPHERES: [([f32; 2], f32, Material); 1] = [(ARM_HAND, WHEEL_RADIUS, Material::Rubber)];
const SHANK_SPHERES: [([f32; 2], f32, Material); 1] =
    [(SHANK_KNEE_SPHERE, WHEEL_RADIUS, Material::Rubber)];
/// Toe first, heel second (the contact sensors rely on this order).
const FOOT_SPHERES: [([f32; 2], f32, Material); 2] = [
    (FOOT_TOE, WHEEL_RADIUS, Material::Rubber),
    (FOOT_HEEL, WHEEL_RADIUS, Material::Rubber),
];

const fn thigh() -> BodySpec {
    BodySpec {
        mass: THIGH_MASS,
        iyy: THIGH_IYY,
        com: THIGH_COM,
        spheres: &[],
    }
}
const fn shank() -> BodySpec {
    BodySpec {
        mass: SHANK_MASS,
        iyy: SHANK_IYY,
        com: SHANK_COM,
        spheres: &SHANK_SPHERES,
    }
}
const fn foot() -> BodySpec {
    BodySpec {
        mass: FOOT_MASS,
        iyy: FOOT_IYY,
        com: FOOT_COM,
        spheres: &FOOT_SPHERES,
    }
}

/// Bodies in [`Body`] order (§1.3, §1.6).
const BODY_SPECS: [BodySpec; NUM_BODIES] = [
    BodySpec {
        mass: TORSO_MASS,
        iyy: TORSO_IYY,
        com: TORSO_COM,
        spheres: &TORSO_SPHERES,
    },
    BodySpec {
        mass: ARM_MASS,
        iyy: ARM_IYY,
        com: ARM_COM,
        spheres: &ARM_SPHERES,
    },
    thigh(),
    shank(),
    foot(),
    thigh(),
    shank(),
    foot(),
];

/// One hinge (§1.3 anchors, §1.5 limits and stops).
struct JointSpec {
    parent: Body,
    child: Body,
    parent_anchor: [f32; 2],
    child_anchor: [f32; 2],
    /// Limits and stop [K, D]; `None` for the unlimited shoulder.
    stop: Option<([f32; 2], [f32; 2])>,
}

/// Joints in [`Joint`] order.
const JOINT_SPECS: [JointSpec; NUM_JOINTS] = [
    JointSpec {
        parent: Body::Torso,
        child: Body::Arm,
        parent_anchor: TORSO_SHOULDER_ANCHOR,
        child_anchor: ARM_SHOULDER_ANCHOR,
        stop: None,
    },
    JointSpec {
        parent: Body::Torso,
        child: Body::ThighLeft,
        parent_anchor: TORSO_HIP_ANCHOR,
        child_anchor: THIGH_HIP_ANCHOR,
        stop: Some((HIP_LIMITS, HIP_STOP)),
    },
    JointSpec {
        parent: Body::Torso,
        child: Body::ThighRight,
        parent_anchor: TORSO_HIP_ANCHOR,
        child_anchor: THIGH_HIP_ANCHOR,
        stop: Some((HIP_LIMITS, HIP_STOP)),
    },
    JointSpec {
        parent: Body::ThighLeft,
        child: Body::ShankLeft,
        parent_anchor: THIGH_KNEE_ANCHOR,
        child_anchor: SHANK_KNEE_ANCHOR,
        stop: Some((KNEE_LIMITS, KNEE_STOP)),
    },
    JointSpec {
        parent: Body::ThighRight,
        child: Body::ShankRight,
        parent_anchor: THIGH_KNEE_ANCHOR,
        child_anchor: SHANK_KNEE_ANCHOR,
        stop: Some((KNEE_LIMITS, KNEE_STOP)),
    },
    JointSpec {
        parent: Body::ShankLeft,
        child: Body::FootLeft,
        parent_anchor: SHANK_ANKLE_ANCHOR,
        child_anchor: FOOT_ANKLE_ANCHOR,
        stop: Some((ANKLE_LIMITS, ANKLE_STOP)),
    },
    JointSpec {
        parent: Body::ShankRight,
        child: Body::FootRight,
        parent_anchor: SHANK_ANKLE_ANCHOR,
        child_anchor: FOOT_ANKLE_ANCHOR,
        stop: Some((ANKLE_LIMITS, ANKLE_STOP)),
    },
];

/// The limits of a joint (§1.5), `None` for the shoulder.
pub fn joint_limits(joint: Joint) -> Option<[f32; 2]> {
    JOINT_SPECS[joint as usize].stop.map(|(limits, _)| limits)
}

/// Absolute body pitches of a starting pose (§1.8). All velocities are zero.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct InitialPose {
    /// Torso pitch (rad about +y).
    pub torso: f32,
    /// Arm pitch.
    pub arm: f32,
    /// Left thigh, shank, foot pitches.
    pub left: [f32; 3],
    /// Right thigh, shank, foot pitches.
    pub right: [f32; 3],
}

impl InitialPose {
    /// The reference starting pose (§1.8): left leg straight on the floor,
    /// right leg lifted with the knee bent.
    pub const REFERENCE: InitialPose = InitialPose {
        torso: INIT_TORSO_PITCH,
        arm: INIT_ARM_PITCH,
        left: INIT_LEFT_LEG_PITCH,
        right: INIT_RIGHT_LEG_PITCH,
    };

    /// Absolute pitch of each body, in [`Body`] order.
    pub fn body_pitches(&self) -> [f32; NUM_BODIES] {
        [
            self.torso,
            self.arm,
            self.left[0],
            self.left[1],
            self.left[2],
            self.right[0],
            self.right[1],
            self.right[2],
        ]
    }

    /// Hinge angles q = θ_parent − θ_child (§1.2), in [`Joint`] order.
    pub fn joint_angles(&self) -> [f32; NUM_JOINTS] {
        let p = self.body_pitches();
        JOINT_SPECS.map(|j| p[j.parent as usize] - p[j.child as usize])
    }

    /// Whether every pitch is finite.
    pub fn is_finite(&self) -> bool {
        self.body_pitches().iter().all(|x| x.is_finite())
    }
}

/// Rotates a body point (x, z) by pitch θ about +y (§1.2).
fn rotate(theta: f32, p: [f32; 2]) -> [f32; 2] {
    let (s, c) = theta.sin_cos();
    [p[0] * c + p[1] * s, -p[0] * s + p[1] * c]
}

/// Planar forward kinematics of the assembly rule of §1.8: each child
/// anchor on its parent's anchor, then the whole robot shifted so that the
/// bottom of the left heel wheel is at the origin. Returns the world (x, z)
/// of every body's origin.
pub fn assemble(pose: &InitialPose) -> [[f32; 2]; NUM_BODIES] {
    let pitch = pose.body_pitches();
    let mut origin = [[0.0f32; 2]; NUM_BODIES];
    // Joints are listed parent-before-child.
    for j in &JOINT_SPECS {
        let (p, c) = (j.parent as usize, j.child as usize);
        let a = rotate(pitch[p], j.parent_anchor);
        let b = rotate(pitch[c], j.child_anchor);
        origin[c] = [origin[p][0] + a[0] - b[0], origin[p][1] + a[1] - b[1]];
    }
    let foot = Body::FootLeft as usize;
    let heel = rotate(pitch[foot], INIT_LEFT_FOOT_POINT);
    let shift = [origin[foot][0] + heel[0], origin[foot][1] + heel[1]];
    origin.map(|o| [o[0] - shift[0], o[1] - shift[1]])
}

/// Switches of the physics, for the sanity checks (all on for LEO).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ModelOptions {
    /// Physics steps per control period (h = (1/30)/substeps).
    pub substeps: u32,
    /// Rapier solver iterations per physics step.
    pub solver_iterations: usize,
    /// Contact softness: natural frequency (Hz).
    pub contact_frequency: f32,
    /// Contact softness: damping ratio.
    pub contact_damping_ratio: f32,
    /// Floor contacts on.
    pub contacts: bool,
    /// Dry friction of 0.2 N m in every servo joint (§1.5).
    pub dry_friction: bool,
    /// Back-EMF damping of the servos (§2.1). Off = "torque off"
    /// (free-wheeling windings); the armature inertia stays.
    pub back_emf: bool,
    /// Soft joint stops (§1.5).
    pub joint_stops: bool,
    /// Dampers of the joint stops (§1.5).
    pub stop_damping: bool,
    /// The boom's extra vertical force on the torso (§1.4).
    pub boom_force: bool,
    /// Gravity on.
    pub gravity: bool,
    /// Correct the servos' response lag of a coarse step (see
    /// `LeoModel::correct_motor_lag`); on by default.
    pub motor_lag_correction: bool,
    /// Weld the torso to the world in its starting pose instead of the
    /// root joint (for the energy and joint-limit checks: the legs and
    /// the arm become a tree of pendulums).
    pub fixed_torso: bool,
}

impl Default for ModelOptions {
    fn default() -> Self {
        Self {
            substeps: SUBSTEPS,
            solver_iterations: SOLVER_ITERATIONS,
            contact_frequency: CONTACT_NATURAL_FREQUENCY,
            contact_damping_ratio: CONTACT_DAMPING_RATIO,
            contacts: true,
            dry_friction: true,
            back_emf: true,
            joint_stops: true,
            stop_damping: true,
            boom_force: true,
            gravity: true,
            fixed_torso: false,
            motor_lag_correction: true,
        }
    }
}

/// Why a model could not be built.
#[derive(Debug, Clone, PartialEq)]
pub enum ModelError {
    /// An option is out of range (name and reason).
    InvalidOption(&'static str, &'static str),
    /// The starting pose has a non-finite pitch.
    InvalidPose,
    /// Rapier refused a joint (should not happen with the fixed topology).
    Topology,
}

impl core::fmt::Display for ModelError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            ModelError::InvalidOption(name, why) => {
                write!(f, "invalid LEO model option `{name}`: {why}")
            }
            ModelError::InvalidPose => write!(f, "the starting pose has a non-finite angle"),
            ModelError::Topology => write!(f, "rapier refused LEO's joint tree"),
        }
    }
}

impl std::error::Error for ModelError {}

impl ModelOptions {
    /// Checks the ranges: 1 ≤ substeps ≤ 1000, 1 ≤ iterations ≤ 100,
    /// finite positive contact frequency, finite non-negative damping ratio.
    pub fn validate(&self) -> Result<(), ModelError> {
        if !(1..=1000).contains(&self.substeps) {
            return Err(ModelError::InvalidOption("substeps", "must be in 1..=1000"));
        }
        if !(1..=100).contains(&self.solver_iterations) {
            return Err(ModelError::InvalidOption(
                "solver_iterations",
                "must be in 1..=100",
            ));
        }
        if !(self.contact_frequency.is_finite() && self.contact_frequency > 0.0) {
            return Err(ModelError::InvalidOption(
                "contact_frequency",
                "must be finite and > 0",
            ));
        }
        if !(self.contact_damping_ratio.is_finite() && self.contact_damping_ratio >= 0.0) {
            return Err(ModelError::InvalidOption(
                "contact_damping_ratio",
                "must be finite and >= 0",
            ));
        }
        Ok(())
    }

    /// The physics step h in seconds.
    pub fn dt(&self) -> f32 {
        CONTROL_PERIOD / self.substeps as f32
    }
}

/// What went wrong when the simulation blew up (bad input).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum BlowUp {
    /// A coordinate or velocity is NaN or infinite.
    NonFinite,
    /// A body left the workspace ([`BLOWUP_DISTANCE`]).
    FarAway,
    /// A joint turns faster than [`BLOWUP_JOINT_RATE`].
    JointRate,
}

/// The raw state the task reads after a step (§3.1).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RawState {
    /// Torso pitch θ about +y (≈ GRL's torso_boom angle; φ = −θ).
    pub torso_pitch: f32,
    /// Torso pitch rate.
    pub torso_rate: f32,
    /// World (x, z) of the torso origin.
    pub torso_position: [f32; 2],
    /// Hinge angles, [`Joint`] order.
    pub angles: [f32; NUM_JOINTS],
    /// Hinge rates (exact, unfiltered), [`Joint`] order.
    pub rates: [f32; NUM_JOINTS],
    /// Contact sensors: left toe, left heel, right toe, right heel.
    pub contacts: [bool; 4],
}

/// Energy bookkeeping for the sanity checks (J).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Energy {
    /// Kinetic energy of the bodies plus the armatures' ½·a·q̇².
    pub kinetic: f32,
    /// Gravity, the boom force's potential and the stops' springs.
    pub potential: f32,
}

impl Energy {
    /// Kinetic + potential.
    pub fn total(&self) -> f32 {
        self.kinetic + self.potential
    }
}

/// The simulated robot: a rapier world plus the voltages being held.
pub struct LeoModel {
    world: PhysicsWorld,
    options: ModelOptions,
    servo: ReducedJoint,
    bodies: [RigidBodyHandle; NUM_BODIES],
    /// Toe and heel colliders' centres and radius, per foot (left, right).
    multibody: MultibodyIndex,
    /// Link id of each joint's child in the multibody, [`Joint`] order.
    links: [usize; NUM_JOINTS],
    /// Index of each joint's DoF in the generalized velocity.
    dofs: [usize; NUM_JOINTS],
    /// Link id of the torso and first DoF of the planar root joint
    /// (x, z, pitch); `None` with a fixed torso.
    root_link: usize,
    root_dof: Option<usize>,
    voltages: [f32; NUM_JOINTS],
    time: f64,
    /// The world as built and its pose, for [`LeoModel::reset`].
    built: Option<(Snapshot, InitialPose)>,
    /// Whether rapier has stepped (its mass-matrix factorisation exists).
    stepped: bool,
    /// The servos' dry friction (§1.5) and each joint's stick/slip state.
    friction: Stiction,
    friction_states: [FrictionState; NUM_JOINTS],
    /// A constant external force and torque (world frame) on one body.
    disturbance: Option<(Body, [f32; 3], [f32; 3])>,
}

/// A copy of a [`LeoModel`]'s state (see [`LeoModel::snapshot`]).
#[derive(Clone)]
pub struct Snapshot {
    bodies: RigidBodySet,
    colliders: ColliderSet,
    impulse_joints: ImpulseJointSet,
    multibody_joints: MultibodyJointSet,
    soft_bodies: SoftBodySet,
    islands: IslandManager,
    broad_phase: BroadPhaseBvh,
    narrow_phase: NarrowPhase,
    ccd_solver: CCDSolver,
    voltages: [f32; NUM_JOINTS],
    time: f64,
    stepped: bool,
    friction_states: [FrictionState; NUM_JOINTS],
}

/// The DoF order of the root joint: x, y (the lateral tie), z, pitch.
const ROOT_X: usize = 0;
const ROOT_Y: usize = 1;
const ROOT_Z: usize = 2;
const ROOT_PITCH: usize = 3;
/// The root's free DoFs.
const ROOT_DOFS: usize = 4;

impl LeoModel {
    /// Builds LEO in `pose` at rest, voltages 0 (§1.8).
    pub fn new(options: ModelOptions, pose: &InitialPose) -> Result<Self, ModelError> {
        options.validate()?;
        if !pose.is_finite() {
            return Err(ModelError::InvalidPose);
        }
        let mut world = PhysicsWorld::new();
        world.gravity = if options.gravity {
            Vector::new(0.0, 0.0, -GRAVITY)
        } else {
            Vector::ZERO
        };
        let p = &mut world.integration_parameters;
        p.dt = options.dt();
        p.num_solver_iterations = options.solver_iterations;
        let softness =
            SpringCoefficients::new(options.contact_frequency, options.contact_damping_ratio);
        p.contact_softness = softness;
        p.static_contact_softness = softness;
        // The default recycles contacts until a pair moved 5 cm, far more
        // than LEO's 3.5 mm wheels allow.
        p.contact_recycling = false;
        // Contact friction in both solver passes, not only the relaxing one:
        // the positions are integrated after the biased pass, and without
        // friction there the stance foot crept backwards under the falling
        // robot (0.4 mm in 0.3 s at 4 steps per period, 9 mm at 1; with it
        // < 0.02 mm at every step, test `the_stance_foot_does_not_slide_on_
        // the_floor`). Rapier leaves it off by default for tall stacks of
        // loose boxes, which LEO is not.
        p.friction_in_bias_pass = true;

        let robot_groups =
            InteractionGroups::new(Group::GROUP_1, Group::GROUP_2, InteractionTestMode::And);
        let floor_groups =
            InteractionGroups::new(Group::GROUP_2, Group::GROUP_1, InteractionTestMode::And);
        if options.contacts {
            world.colliders.insert(
                ColliderBuilder::new(SharedShape::halfspace(Vector::Z))
                    .friction(RUBBER_FRICTION.max(FOAM_FRICTION))
                    .friction_combine_rule(CoefficientCombineRule::Min)
                    .collision_groups(floor_groups),
            );
        }

        let pitch = pose.body_pitches();
        let origin = assemble(pose);
        let mut bodies = [RigidBodyHandle::invalid(); NUM_BODIES];
        for (i, spec) in BODY_SPECS.iter().enumerate() {
            let rb = RigidBodyBuilder::dynamic()
                .pose(body_pose(origin[i], pitch[i]))
                .additional_mass_properties(MassProperties::new(
                    Vector::new(spec.com[0], 0.0, spec.com[1]),
                    spec.mass,
                    Vector::new(INERTIA_DONT_CARE, spec.iyy, INERTIA_DONT_CARE),
                ))
                .can_sleep(false);
            let handle = world.bodies.insert(rb);
            for &(centre, radius, material) in spec.spheres {
                let friction = match material {
                    Material::Rubber => RUBBER_FRICTION,
                    Material::Foam => FOAM_FRICTION,
                };
                let collider = ColliderBuilder::ball(radius)
                    .translation(Vector::new(centre[0], 0.0, centre[1]))
                    .density(0.0)
                    .friction(friction)
                    .friction_combine_rule(CoefficientCombineRule::Min)
                    .collision_groups(robot_groups);
                world
                    .colliders
                    .insert_with_parent(collider, handle, &mut world.bodies);
            }
            bodies[i] = handle;
        }

        // The planar root joint: a fixed anchor at the world origin, the
        // torso free in x, z and pitch (planar motion locked
        // explicitly).
        let anchor = world.bodies.insert(RigidBodyBuilder::fixed());
        let planar = if options.fixed_torso {
            GenericJointBuilder::new(JointAxesMask::all())
                .local_frame1(body_pose(
                    origin[Body::Torso as usize],
                    pitch[Body::Torso as usize],
                ))
                .contacts_enabled(false)
                .build()
        } else {
            // y stays a DoF, held by the lateral tie (see `LATERAL_TIE`).
            GenericJointBuilder::new(JointAxesMask::ANG_X | JointAxesMask::ANG_Z)
                .contacts_enabled(false)
                .build()
        };
        world
            .multibody_joints
            .insert(anchor, bodies[Body::Torso as usize], planar, true)
            .ok_or(ModelError::Topology)?;
        for j in &JOINT_SPECS {
            let hinge = RevoluteJointBuilder::new(-Vector::Y)
                .local_anchor1(Vector::new(j.parent_anchor[0], 0.0, j.parent_anchor[1]))
                .local_anchor2(Vector::new(j.child_anchor[0], 0.0, j.child_anchor[1]))
                .contacts_enabled(false);
            world
                .multibody_joints
                .insert(
                    bodies[j.parent as usize],
                    bodies[j.child as usize],
                    hinge,
                    true,
                )
                .ok_or(ModelError::Topology)?;
        }

        let torso_link = *world
            .multibody_joints
            .rigid_body_link(bodies[Body::Torso as usize])
            .ok_or(ModelError::Topology)?;
        let multibody = torso_link.multibody;
        let mut links = [0usize; NUM_JOINTS];
        for (k, j) in JOINT_SPECS.iter().enumerate() {
            let link = world
                .multibody_joints
                .rigid_body_link(bodies[j.child as usize])
                .ok_or(ModelError::Topology)?;
            if link.multibody != multibody {
                return Err(ModelError::Topology);
            }
            links[k] = link.id;
        }

        let servo = options_servo(&options);
        // Rapier computes mass properties lazily at the first step; the
        // multibody's Jacobians (used below and by `energy`) need them now.
        for &h in &bodies {
            let rb = &mut world.bodies[h];
            rb.recompute_mass_properties_from_colliders(&world.colliders);
        }
        let mb = world
            .multibody_joints
            .get_multibody_mut(multibody)
            .ok_or(ModelError::Topology)?;
        // The root (the fixed anchor) counts as a free 6-DoF joint until
        // the multibody has looked at its body type.
        mb.forward_kinematics(&world.bodies, true);
        let root_link = torso_link.id;
        let root_dofs = if options.fixed_torso { 0 } else { ROOT_DOFS };
        let root_dof = mb
            .link(root_link)
            .ok_or(ModelError::Topology)?
            .assembly_id();
        let mut dofs = [0usize; NUM_JOINTS];
        for k in 0..NUM_JOINTS {
            dofs[k] = mb.link(links[k]).ok_or(ModelError::Topology)?.assembly_id();
        }
        if mb.ndofs() != root_dofs + NUM_JOINTS {
            return Err(ModelError::Topology);
        }
        // Per-DoF servo model; the root DoFs get none (rapier's default
        // damping of 0.1 on angular DoFs is removed as well).
        mb.damping_mut().fill(0.0);
        mb.armature_mut().fill(0.0);
        // The dry friction is not rapier's friction loss (see `stiction`).
        mb.frictions_mut().fill(0.0);
        for &d in &dofs {
            mb.damping_mut()[d] = servo.damping;
            mb.armature_mut()[d] = servo.armature;
        }
        // Joint coordinates of the pose: the multibody starts at zero
        // coordinates, so the pose is a displacement.
        let torso = origin[Body::Torso as usize];
        if !options.fixed_torso {
            mb.link_mut(root_link)
                .ok_or(ModelError::Topology)?
                .joint
                .apply_displacement(&[torso[0], 0.0, torso[1], pitch[Body::Torso as usize]]);
            // The lateral tie: a stiff implicit spring and damper at y = 0.
            mb.link_mut(root_link)
                .ok_or(ModelError::Topology)?
                .joint
                .set_spring(LINEAR_Y, LATERAL_TIE[0], 0.0);
            mb.damping_mut()[root_dof + ROOT_Y] = LATERAL_TIE[1];
        }
        let angles = pose.joint_angles();
        for k in 0..NUM_JOINTS {
            mb.link_mut(links[k])
                .ok_or(ModelError::Topology)?
                .joint
                .apply_displacement(&[angles[k]]);
        }
        mb.generalized_velocity_mut().fill(0.0);
        mb.forward_kinematics(&world.bodies, false);
        mb.update_rigid_bodies(&mut world.bodies, true);

        let mut model = Self {
            world,
            options,
            servo,
            bodies,
            multibody,
            links,
            dofs,
            root_link,
            root_dof: (!options.fixed_torso).then_some(root_dof),
            voltages: [0.0; NUM_JOINTS],
            time: 0.0,
            built: None,
            stepped: false,
            friction: Stiction::new(servo.dry_friction),
            friction_states: held_at(&pose.joint_angles()),
            disturbance: None,
        };
        model.built = Some((model.snapshot(), *pose));
        Ok(model)
    }

    /// A copy of the world's state (bodies, colliders, joints, contact
    /// and broad-phase caches) plus the held voltages and the time, to be
    /// put back with [`LeoModel::restore`]. Restoring a snapshot continues
    /// exactly (bit for bit) as the original did from that point.
    pub fn snapshot(&self) -> Snapshot {
        let w = &self.world;
        Snapshot {
            bodies: w.bodies.clone(),
            colliders: w.colliders.clone(),
            impulse_joints: w.impulse_joints.clone(),
            multibody_joints: w.multibody_joints.clone(),
            soft_bodies: w.soft_bodies.clone(),
            islands: w.islands.clone(),
            broad_phase: w.broad_phase.clone(),
            narrow_phase: w.narrow_phase.clone(),
            ccd_solver: w.ccd_solver.clone(),
            voltages: self.voltages,
            time: self.time,
            stepped: self.stepped,
            friction_states: self.friction_states,
        }
    }

    /// Puts a snapshot of this model back (see [`LeoModel::snapshot`]).
    pub fn restore(&mut self, snapshot: &Snapshot) {
        let w = &mut self.world;
        w.bodies.clone_from(&snapshot.bodies);
        w.colliders.clone_from(&snapshot.colliders);
        w.impulse_joints.clone_from(&snapshot.impulse_joints);
        w.multibody_joints.clone_from(&snapshot.multibody_joints);
        w.soft_bodies.clone_from(&snapshot.soft_bodies);
        w.islands.clone_from(&snapshot.islands);
        w.broad_phase.clone_from(&snapshot.broad_phase);
        w.narrow_phase.clone_from(&snapshot.narrow_phase);
        w.ccd_solver.clone_from(&snapshot.ccd_solver);
        self.voltages = snapshot.voltages;
        self.time = snapshot.time;
        self.stepped = snapshot.stepped;
        self.friction_states = snapshot.friction_states;
    }

    /// Puts the robot into `pose` at rest with 0 V and time 0, as if just
    /// built: the world as built (no contacts yet) is restored, then the
    /// joint coordinates are moved to the pose. Cheaper than a rebuild,
    /// which costs about as much as a control step (and early-learning
    /// episodes last only a dozen steps).
    pub fn reset(&mut self, pose: &InitialPose) -> Result<(), ModelError> {
        if !pose.is_finite() {
            return Err(ModelError::InvalidPose);
        }
        let built = self.built.take();
        if let Some((snapshot, built_pose)) = &built {
            self.restore(snapshot);
            if pose != built_pose {
                self.set_pose(pose)?;
            }
        } else {
            *self = Self::new(self.options, pose)?;
            return Ok(());
        }
        self.built = built;
        Ok(())
    }

    /// Moves the joint coordinates of a model at rest to `pose`.
    fn set_pose(&mut self, pose: &InitialPose) -> Result<(), ModelError> {
        let origin = assemble(pose);
        let torso = origin[Body::Torso as usize];
        let root_target = [torso[0], torso[1], pose.torso];
        let angles = pose.joint_angles();
        let mb = self
            .world
            .multibody_joints
            .get_multibody_mut(self.multibody)
            .ok_or(ModelError::Topology)?;
        // Joint coordinates only move by displacements.
        let root = mb.link_mut(self.root_link).ok_or(ModelError::Topology)?;
        if self.root_dof.is_some() {
            let c = root.joint.coords();
            root.joint.apply_displacement(&[
                root_target[0] - c[0],
                -c[1],
                root_target[1] - c[2],
                root_target[2] - c[4],
            ]);
        } else {
            root.joint.data.local_frame1 = body_pose(torso, pose.torso);
        }
        for k in 0..NUM_JOINTS {
            let link = mb.link_mut(self.links[k]).ok_or(ModelError::Topology)?;
            let q = link.joint.coords()[3];
            link.joint.apply_displacement(&[angles[k] - q]);
        }
        mb.generalized_velocity_mut().fill(0.0);
        mb.forward_kinematics(&self.world.bodies, false);
        mb.update_rigid_bodies(&mut self.world.bodies, true);
        self.friction_states = held_at(&angles);
        Ok(())
    }

    /// Each joint's dry-friction state ([`Joint`] order).
    pub fn friction_states(&self) -> [FrictionState; NUM_JOINTS] {
        self.friction_states
    }

    /// The options the model was built with.
    pub fn options(&self) -> &ModelOptions {
        &self.options
    }

    /// The servo model in use (rigid-armature form, with the options'
    /// switches applied).
    pub fn servo(&self) -> &ReducedJoint {
        &self.servo
    }

    /// Simulated time since the model was built (s).
    pub fn time(&self) -> f64 {
        self.time
    }

    /// Holds these voltages (V, [`Joint`] order) until the next call
    /// (zero-order hold, §1.1). Each passes the supply clip of §2.1;
    /// non-finite values become 0 V.
    pub fn set_voltages(&mut self, voltages: [f32; NUM_JOINTS]) {
        self.voltages = voltages.map(|u| {
            if u.is_finite() {
                u.clamp(-SERVO.supply_clip, SERVO.supply_clip)
            } else {
                0.0
            }
        });
    }

    /// A constant external force (N) at the body's centre of mass and a
    /// torque (N m), world frame, applied every physics step until cleared
    /// with `None` — pushes for tests and robustness experiments.
    /// Non-finite components are ignored (read as 0).
    pub fn set_disturbance(&mut self, disturbance: Option<(Body, [f32; 3], [f32; 3])>) {
        let clean = |v: [f32; 3]| v.map(|x| if x.is_finite() { x } else { 0.0 });
        self.disturbance = disturbance.map(|(b, f, t)| (b, clean(f), clean(t)));
    }

    /// The voltages being held.
    pub fn voltages(&self) -> [f32; NUM_JOINTS] {
        self.voltages
    }

    /// The multibody link of a body ([`Body`] index).
    fn body_link(&self, body: usize) -> usize {
        if body == Body::Torso as usize {
            return self.root_link;
        }
        JOINT_SPECS
            .iter()
            .position(|j| j.child as usize == body)
            .map_or(self.root_link, |k| self.links[k])
    }

    fn multibody(&self) -> &Multibody {
        // The index was checked when the model was built and the topology
        // never changes.
        &self.world.multibody_joints[self.multibody]
    }

    /// Hinge angles and rates, [`Joint`] order.
    pub fn joint_state(&self) -> ([f32; NUM_JOINTS], [f32; NUM_JOINTS]) {
        let mb = self.multibody();
        let v = mb.generalized_velocity();
        let mut q = [0.0; NUM_JOINTS];
        let mut qd = [0.0; NUM_JOINTS];
        for k in 0..NUM_JOINTS {
            // A revolute joint's coordinate is its angle about the joint
            // frame's x axis (−y in the world here).
            q[k] = mb
                .link(self.links[k])
                .map_or(f32::NAN, |l| l.joint.coords()[3]);
            qd[k] = v[self.dofs[k]];
        }
        (q, qd)
    }

    /// World pose of a body.
    pub fn body_pose(&self, body: Body) -> Pose {
        *self.world.bodies[self.bodies[body as usize]].position()
    }

    /// World (x, z) of a point given in a body's frame.
    pub fn body_point(&self, body: Body, point: [f32; 2]) -> [f32; 2] {
        let p = self
            .body_pose(body)
            .transform_point(Vector::new(point[0], 0.0, point[1]));
        [p.x, p.z]
    }

    /// Height of the lowest point of the toe and heel spheres: left toe,
    /// left heel, right toe, right heel (m).
    pub fn foot_clearances(&self) -> [f32; 4] {
        let l = Body::FootLeft;
        let r = Body::FootRight;
        [
            self.body_point(l, FOOT_TOE)[1] - WHEEL_RADIUS,
            self.body_point(l, FOOT_HEEL)[1] - WHEEL_RADIUS,
            self.body_point(r, FOOT_TOE)[1] - WHEEL_RADIUS,
            self.body_point(r, FOOT_HEEL)[1] - WHEEL_RADIUS,
        ]
    }

    /// The state the task reads (§3.1).
    pub fn state(&self) -> RawState {
        let mb = self.multibody();
        let (angles, rates) = self.joint_state();
        let root = mb.link(self.root_link).map(|l| l.joint.coords());
        let (x, z, pitch) = match (root, self.root_dof) {
            // Coordinates of the root joint: coords[0] = x, coords[1] = y
            // (the lateral tie's), coords[2] = z, coords[4] = rotation
            // about y (not wrapped).
            (Some(c), Some(_)) => (c[0], c[2], c[4]),
            _ => {
                let pose = self.body_pose(Body::Torso);
                let ex = pose.rotation * Vector::X;
                (pose.translation.x, pose.translation.z, (-ex.z).atan2(ex.x))
            }
        };
        let clear = self.foot_clearances();
        RawState {
            torso_pitch: pitch,
            torso_rate: self.root_velocity()[2],
            torso_position: [x, z],
            angles,
            rates,
            contacts: clear.map(|c| c <= CONTACT_SENSOR_TOLERANCE),
        }
    }

    /// The generalized velocity of the root joint (ẋ, ż, θ̇).
    pub fn root_velocity(&self) -> [f32; 3] {
        let v = self.multibody().generalized_velocity();
        match self.root_dof {
            Some(r) => [v[r + ROOT_X], v[r + ROOT_Z], v[r + ROOT_PITCH]],
            None => [0.0; 3],
        }
    }

    /// Sets joint rates (rad/s, [`Joint`] order) and the root velocity
    /// (ẋ, ż, θ̇), for the sanity checks.
    pub fn set_velocities(&mut self, joint_rates: [f32; NUM_JOINTS], root: [f32; 3]) {
        let dofs = self.dofs;
        let root_dof = self.root_dof;
        if let Some(mb) = self
            .world
            .multibody_joints
            .get_multibody_mut(self.multibody)
        {
            let mut v = mb.generalized_velocity_mut();
            for k in 0..NUM_JOINTS {
                v[dofs[k]] = joint_rates[k];
            }
            if let Some(r) = root_dof {
                v[r + ROOT_X] = root[0];
                v[r + ROOT_Y] = 0.0;
                v[r + ROOT_Z] = root[1];
                v[r + ROOT_PITCH] = root[2];
            }
        }
    }

    /// Mechanical energy (J): bodies' kinetic energy, the armatures'
    /// ½·a·q̇², gravity, the boom force's potential (it is a constant
    /// vertical force at a torso point) and the stop springs' ½·K·δ².
    pub fn energy(&self) -> Energy {
        let g = if self.options.gravity { GRAVITY } else { 0.0 };
        let mut kinetic = 0.0f64;
        let mut potential = 0.0f64;
        let mb = self.multibody();
        let gv = mb.generalized_velocity();
        for (i, spec) in BODY_SPECS.iter().enumerate() {
            let rb = &self.world.bodies[self.bodies[i]];
            // Body velocity from the generalized velocity (the rigid bodies'
            // own velocities lag behind a `set_velocities` until the next
            // step): rows 0..3 the CoM's linear, 3..6 the angular velocity.
            let link = self.body_link(i);
            let jv = mb.body_jacobian(link) * gv;
            let v = Vector::new(jv[0], jv[1], jv[2]);
            let w = rb.position().rotation.inverse() * Vector::new(jv[3], jv[4], jv[5]);
            let inertia = [INERTIA_DONT_CARE, spec.iyy, INERTIA_DONT_CARE];
            kinetic += 0.5 * spec.mass as f64 * v.length_squared() as f64;
            kinetic += 0.5
                * (inertia[0] * w.x * w.x + inertia[1] * w.y * w.y + inertia[2] * w.z * w.z) as f64;
            let com = rb
                .position()
                .transform_point(Vector::new(spec.com[0], 0.0, spec.com[1]));
            potential += (spec.mass * g * com.z) as f64;
        }
        let (q, qd) = self.joint_state();
        for k in 0..NUM_JOINTS {
            // The armature the simulation uses (see `correct_motor_lag`).
            let armature = mb.armature()[self.dofs[k]];
            kinetic += 0.5 * (armature * qd[k] * qd[k]) as f64;
            if let (Some((limits, stop)), true) = (JOINT_SPECS[k].stop, self.options.joint_stops) {
                let over = (q[k] - limits[1]).max(0.0) + (limits[0] - q[k]).max(0.0);
                potential += 0.5 * (stop[0] * over * over) as f64;
            }
        }
        if self.options.boom_force {
            let p = self.body_point(Body::Torso, BOOM_FORCE_POINT);
            potential += (-BOOM_EXTRA_FORCE_Z * p[1]) as f64;
        }
        // The lateral tie's spring and the friction ties' springs.
        if self.root_dof.is_some() {
            let y = mb
                .link(self.root_link)
                .map_or(0.0, |l| l.joint.coords()[LINEAR_Y]);
            potential += 0.5 * (LATERAL_TIE[0] * y * y) as f64;
        }
        for k in 0..NUM_JOINTS {
            if let (FrictionState::Stick { anchor }, true) =
                (self.friction_states[k], self.friction.is_active())
            {
                let d = q[k] - anchor;
                potential += 0.5 * (self.friction.stiffness * d * d) as f64;
            }
        }
        Energy {
            kinetic: kinetic as f32,
            potential: potential as f32,
        }
    }

    /// Checks the state for a blow-up (NaN, far away, absurd joint rate).
    pub fn check(&self) -> Result<(), BlowUp> {
        let mb = self.multibody();
        if !mb.generalized_velocity().iter().all(|x| x.is_finite()) {
            return Err(BlowUp::NonFinite);
        }
        for &h in &self.bodies {
            let rb = &self.world.bodies[h];
            if !(rb.position().translation.is_finite()
                && rb.linvel().is_finite()
                && rb.angvel().is_finite())
            {
                return Err(BlowUp::NonFinite);
            }
        }
        let v = mb.generalized_velocity();
        if self.dofs.iter().any(|&d| v[d].abs() > BLOWUP_JOINT_RATE) {
            return Err(BlowUp::JointRate);
        }
        if self
            .bodies
            .iter()
            .any(|&h| self.world.bodies[h].position().translation.length() > BLOWUP_DISTANCE)
        {
            return Err(BlowUp::FarAway);
        }
        Ok(())
    }

    /// One physics step of length h with the held voltages: the joints'
    /// springs and dampers (stops, friction ties) and the external forces
    /// set, then rapier steps, then the friction states follow the motion.
    pub fn physics_step(&mut self) -> Result<(), BlowUp> {
        let friction_torques = self.set_joint_springs();
        // External forces: the boom (§1.4) and the servos' voltage torques (§2.1).
        for &h in &self.bodies {
            let rb = &mut self.world.bodies[h];
            rb.reset_forces(false);
            rb.reset_torques(false);
        }
        if self.options.boom_force {
            let p = self.body_pose(Body::Torso).transform_point(Vector::new(
                BOOM_FORCE_POINT[0],
                0.0,
                BOOM_FORCE_POINT[1],
            ));
            self.world.bodies[self.bodies[Body::Torso as usize]].add_force_at_point(
                Vector::new(0.0, 0.0, BOOM_EXTRA_FORCE_Z),
                p,
                false,
            );
        }
        if let Some((body, f, t)) = self.disturbance {
            let rb = &mut self.world.bodies[self.bodies[body as usize]];
            rb.add_force(Vector::new(f[0], f[1], f[2]), false);
            rb.add_torque(Vector::new(t[0], t[1], t[2]), false);
        }
        for k in 0..NUM_JOINTS {
            let tau = self.servo.voltage_torque(self.voltages[k]) + friction_torques[k];
            if tau == 0.0 {
                continue;
            }
            // The joint axis is −y: +τ about −y on the child, the reaction
            // on the parent (§1.2: a positive torque increases q).
            let axis = -Vector::Y;
            let j = &JOINT_SPECS[k];
            self.world.bodies[self.bodies[j.child as usize]].add_torque(axis * tau, false);
            self.world.bodies[self.bodies[j.parent as usize]].add_torque(-axis * tau, false);
        }
        self.world.step();
        self.stepped = true;
        self.time += self.options.dt() as f64;
        self.check()?;
        self.follow_friction();
        Ok(())
    }

    /// Sets every servo joint's implicit spring and damping for the next
    /// physics step and returns the sliding joints' friction torques.
    ///
    /// - Soft stops (§1.5): beyond a limit, a spring K toward the limit and
    ///   (while the joint moves further in) a damper D. Rapier integrates
    ///   both implicitly, as ODE's ERP/CFM limit with the same K and D does;
    ///   they are switched per physics step, so a stop never pulls a joint
    ///   into the limit.
    /// - Dry friction (§1.5, [`super::stiction`]): a held joint's tie, or a
    ///   sliding joint's constant friction torque.
    /// - The back-EMF damping of the servo (§2.1) underneath.
    ///
    /// Two springs on one joint add up to one: stiffness k₁ + k₂ toward
    /// (k₁·r₁ + k₂·r₂)/(k₁ + k₂).
    fn set_joint_springs(&mut self) -> [f32; NUM_JOINTS] {
        let (q, qd) = self.joint_state();
        let mut torques = [0.0f32; NUM_JOINTS];
        let Some(mb) = self
            .world
            .multibody_joints
            .get_multibody_mut(self.multibody)
        else {
            return torques;
        };
        for k in 0..NUM_JOINTS {
            let load = self.friction.load(self.friction_states[k]);
            let mut stiffness = load.stiffness;
            let mut moment = load.stiffness * load.rest;
            let mut damping = self.servo.damping + load.damping;
            torques[k] = load.torque;
            if let (Some((limits, [stop_k, stop_d])), true) =
                (JOINT_SPECS[k].stop, self.options.joint_stops)
            {
                let beyond = if q[k] > limits[1] {
                    Some((limits[1], qd[k] > 0.0))
                } else if q[k] < limits[0] {
                    Some((limits[0], qd[k] < 0.0))
                } else {
                    None
                };
                if let Some((limit, inward)) = beyond {
                    stiffness += stop_k;
                    moment += stop_k * limit;
                    if inward && self.options.stop_damping {
                        damping += stop_d;
                    }
                }
            }
            let rest = if stiffness > 0.0 {
                moment / stiffness
            } else {
                0.0
            };
            if let Some(link) = mb.link_mut(self.links[k]) {
                link.joint.set_spring(ANGULAR_X, stiffness, rest);
            }
            mb.damping_mut()[self.dofs[k]] = damping;
        }
        torques
    }

    /// After a physics step: every joint's friction state follows its
    /// motion (break-away, or a stop inside the step); the joints that
    /// stopped inside the step get their rate set to 0 together, by one
    /// generalized impulse on their DoFs (`stop_joints`).
    fn follow_friction(&mut self) {
        let (q, qd) = self.joint_state();
        let mut stopped = [false; NUM_JOINTS];
        for k in 0..NUM_JOINTS {
            let u = self.friction.update(self.friction_states[k], q[k], qd[k]);
            self.friction_states[k] = u.state;
            stopped[k] = u.stop;
        }
        if stopped.iter().any(|&s| s) {
            self.stop_joints(&stopped);
        }
    }

    /// Sets the rates of the `stopped` joints to 0 with the generalized
    /// impulse λ on those DoFs alone that does it: v + A⁻¹·E·λ has zero
    /// entries there, (A⁻¹)_SS·λ = −v_S, with A the matrix rapier just
    /// factorised (mass, armature, h·damping, h²·springs). The friction
    /// torque over-acted within the step (the joint stopped part-way); this
    /// hands the excess back consistently with the rest of the tree.
    fn stop_joints(&mut self, stopped: &[bool; NUM_JOINTS]) {
        use rapier3d::na::{DMatrix, DVector};
        let dofs = self.dofs;
        let Some(mb) = self
            .world
            .multibody_joints
            .get_multibody_mut(self.multibody)
        else {
            return;
        };
        let n = mb.ndofs();
        let set: Vec<usize> = (0..NUM_JOINTS).filter(|&k| stopped[k]).collect();
        // Columns of A⁻¹ for the stopped DoFs.
        let mut columns = Vec::with_capacity(set.len());
        for &k in &set {
            let mut e = DVector::<f32>::zeros(n);
            e[dofs[k]] = 1.0;
            if !mb.inv_augmented_mass().solve_mut(&mut e) {
                return;
            }
            columns.push(e);
        }
        let m = set.len();
        let block = DMatrix::from_fn(m, m, |i, j| columns[j][dofs[set[i]]]);
        let v = mb.generalized_velocity();
        let rhs = DVector::from_fn(m, |i, _| -v[dofs[set[i]]]);
        let Some(lambda) = block.lu().solve(&rhs) else {
            return;
        };
        let mut v = mb.generalized_velocity_mut();
        for (j, column) in columns.iter().enumerate() {
            v.axpy(lambda[j], column, 1.0);
        }
        // Exactly 0, not a rounding error away from it.
        for &k in &set {
            v[dofs[k]] = 0.0;
        }
    }

    /// Simulates one control period (1/30 s) with the held voltages and
    /// returns the mean gear torque of every servo over it (N m, [`Joint`]
    /// order): η·G·k·(U − G·k·q̇)/R averaged over the physics steps, minus
    /// the armature's reaction a·Δq̇/T. Stops at the first blow-up.
    pub fn control_step(&mut self) -> Result<[f32; NUM_JOINTS], BlowUp> {
        if self.options.motor_lag_correction {
            self.correct_motor_lag();
        }
        let (_, start) = self.joint_state();
        let mut sum = [0.0f32; NUM_JOINTS];
        for _ in 0..self.options.substeps {
            self.physics_step()?;
            let (_, qd) = self.joint_state();
            for k in 0..NUM_JOINTS {
                sum[k] += self.servo.voltage_torque(self.voltages[k]) - self.servo.damping * qd[k];
            }
        }
        let (_, end) = self.joint_state();
        let n = self.options.substeps as f32;
        let mut torque = [0.0; NUM_JOINTS];
        for k in 0..NUM_JOINTS {
            torque[k] = sum[k] / n - self.servo.armature * (end[k] - start[k]) / CONTROL_PERIOD;
        }
        Ok(torque)
    }
}

impl LeoModel {
    /// The step-size correction of the servos' first-order response.
    ///
    /// A servo joint is dominated by its electrical damping d = η·G²k²/R:
    /// J·q̈ = τ_U − d·q̇ with J the joint's inertia (link tree plus the
    /// armature a), time constant J/d ≈ 8–20 ms. Rapier integrates the
    /// damping implicitly (backward Euler), which over a step h makes the
    /// velocity decay by J/(J + h·d) instead of exp(−h·d/J): at h = 11 ms
    /// a voltage step reaches ≈ 9% less speed after one control period
    /// (≈ 7% at the 8.3 ms default).
    /// Backward Euler gives the exact decay if the inertia it sees is
    /// J' = h·d/(exp(h·d/J) − 1) < J, which changes neither the stall
    /// torque nor the no-load speed (inertia has no static effect). So once
    /// per control period the armature of every servo DoF is lowered by
    /// J − J' (never below 0), with J = 1/(M⁻¹)_dd the DoF's inertia with
    /// the other DoFs free (rapier's `dof_inverse_inertia`). As h → 0 the
    /// correction vanishes.
    fn correct_motor_lag(&mut self) {
        let h = self.options.dt() / self.options.solver_iterations as f32;
        let d = self.servo.damping;
        let a = self.servo.armature;
        if d <= 0.0 {
            return;
        }
        let dofs = self.dofs;
        let links = self.links;
        let stepped = self.stepped;
        let Some(mb) = self
            .world
            .multibody_joints
            .get_multibody_mut(self.multibody)
        else {
            return;
        };
        // (M⁻¹)_dd: after a step, from the factorisation rapier already has
        // of M + armature + h·damping + h²·springs (cheap: one solve per
        // DoF); before the first step, from a fresh assembly of M +
        // armature. Adding δ to a diagonal entry adds exactly δ to
        // 1/(M⁻¹)_dd (a Schur complement), so the DoF's own damping and
        // spring terms are taken off again below; the other DoFs' stay in,
        // so a neighbour held by its friction tie moves with this DoF.
        let n = mb.ndofs();
        let mut inv = [0.0f32; NUM_JOINTS];
        let mut own = [0.0f32; NUM_JOINTS];
        if stepped {
            let mut e = rapier3d::na::DVector::<f32>::zeros(n);
            for (i, &k) in dofs.iter().enumerate() {
                e.fill(0.0);
                e[k] = 1.0;
                inv[i] = if mb.inv_augmented_mass().solve_mut(&mut e) {
                    e[k]
                } else {
                    f32::NAN
                };
            }
            for (i, &k) in dofs.iter().enumerate() {
                let spring = mb
                    .link(links[i])
                    .map_or(0.0, |l| l.joint.spring(ANGULAR_X).0);
                own[i] = h * mb.damping()[k] + h * h * spring;
            }
        } else {
            let all = mb.dof_inverse_inertia(&self.world.bodies);
            for (i, &k) in dofs.iter().enumerate() {
                inv[i] = all[k];
            }
        }
        for (i, &k) in dofs.iter().enumerate() {
            let current = mb.armature()[k];
            // The DoF's inertia with the true armature.
            let j = 1.0 / inv[i] - own[i] - current + a;
            let x = h * d / j;
            if !(j.is_finite() && j > 0.0 && x.is_finite() && x > 1e-6) {
                mb.armature_mut()[k] = a;
                continue;
            }
            let fitted = h * d / x.exp_m1();
            mb.armature_mut()[k] = (a - (j - fitted)).max(0.0);
        }
    }
}

/// Every joint held where it stands (the start of an episode: at rest).
fn held_at(angles: &[f32; NUM_JOINTS]) -> [FrictionState; NUM_JOINTS] {
    angles.map(|anchor| FrictionState::Stick { anchor })
}

/// The servo of §2.1 in rigid-armature form, with the options' switches.
fn options_servo(options: &ModelOptions) -> ReducedJoint {
    let mut servo = SERVO.reduced();
    if !options.back_emf {
        servo.damping = 0.0;
    }
    if !options.dry_friction {
        servo.dry_friction = 0.0;
    }
    servo
}

/// A body's world pose from its origin (x, z) and pitch.
fn body_pose(origin: [f32; 2], pitch: f32) -> Pose {
    Pose::from_parts(
        Vector::new(origin[0], 0.0, origin[1]),
        Rotation::from_rotation_y(pitch),
    )
}
