//! LEO as a rapier3d world, built in one function from the named constants
//! of [`super::constants`] (`docs/reference/grl.md` §1), and its physics step.
//!
//! # How the reference model maps onto rapier
//!
//! - **Planar motion** (§1.4: GRL keeps LEO planar only by symmetry). Here
//!   the robot is one reduced-coordinate multibody whose root is a fixed
//!   anchor and whose first joint is free in x, z and pitch only: the
//!   lateral translation, roll and yaw have no coordinate at all. (Rapier's
//!   contact friction needs a patch for that: the floor's lateral friction
//!   row has no mobility, `vendor/rapier3d/PATCH.md`.)
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
use crate::world_state::WorldState;

use super::stiction::{FrictionState, Stiction};

/// Index of a revolute joint's free axis (rotation about its local x) in
/// rapier's 6-DoF spatial layout, for the joint springs.
const ANGULAR_X: usize = 3;

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
    world: WorldState,
    voltages: [f32; NUM_JOINTS],
    time: f64,
    stepped: bool,
    friction_states: [FrictionState; NUM_JOINTS],
}

/// The DoF order of the root joint: x, z, pitch.
const ROOT_X: usize = 0;
const ROOT_Z: usize = 1;
const ROOT_PITCH: usize = 2;
/// The root's free DoFs.
const ROOT_DOFS: usize = 3;
