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

mod anatomy;
mod build;
#[cfg(test)]
mod forward_kinematics_check;
#[cfg(test)]
mod mass_matrix_check;
mod motor_lag;
mod options;
mod state;
mod step;
#[cfg(test)]
mod test_drive;

pub use anatomy::{
    assemble, joint_limits, Body, InitialPose, Joint, JOINTS, NUM_BODIES, NUM_JOINTS,
};
pub use options::{BlowUp, ModelError, ModelOptions};
pub use state::{Energy, RawState};

use pada_core::rx28::ReducedJoint;
use rapier3d::prelude::*;

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
