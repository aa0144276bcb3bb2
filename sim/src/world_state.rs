//! A copy of a rapier world's state, to put back later: what LEO's
//! snapshots and every URDF body's reset restore.
//!
//! rapier's `PhysicsWorld` is not `Clone` (its pipelines are workspaces),
//! so this is every set and cache that a step changes. Restoring continues
//! exactly, bit for bit, as the world did from the copy; `clone_from`
//! reuses the world's allocations, so a reset allocates nothing once the
//! sets have their size.

use rapier3d::prelude::*;

/// Every set and cache of a [`PhysicsWorld`] that a step changes: bodies,
/// colliders, both kinds of joints, soft bodies, islands, the broad and
/// narrow phases' caches and the CCD solver's state.
#[derive(Clone)]
pub struct WorldState {
    bodies: RigidBodySet,
    colliders: ColliderSet,
    impulse_joints: ImpulseJointSet,
    multibody_joints: MultibodyJointSet,
    soft_bodies: SoftBodySet,
    islands: IslandManager,
    broad_phase: BroadPhaseBvh,
    narrow_phase: NarrowPhase,
    ccd_solver: CCDSolver,
}

impl WorldState {
    /// A copy of `w`'s state now.
    pub fn of(w: &PhysicsWorld) -> WorldState {
        WorldState {
            bodies: w.bodies.clone(),
            colliders: w.colliders.clone(),
            impulse_joints: w.impulse_joints.clone(),
            multibody_joints: w.multibody_joints.clone(),
            soft_bodies: w.soft_bodies.clone(),
            islands: w.islands.clone(),
            broad_phase: w.broad_phase.clone(),
            narrow_phase: w.narrow_phase.clone(),
            ccd_solver: w.ccd_solver.clone(),
        }
    }

    /// Puts this state back into `w` (the world it was taken from).
    pub fn restore(&self, w: &mut PhysicsWorld) {
        w.bodies.clone_from(&self.bodies);
        w.colliders.clone_from(&self.colliders);
        w.impulse_joints.clone_from(&self.impulse_joints);
        w.multibody_joints.clone_from(&self.multibody_joints);
        w.soft_bodies.clone_from(&self.soft_bodies);
        w.islands.clone_from(&self.islands);
        w.broad_phase.clone_from(&self.broad_phase);
        w.narrow_phase.clone_from(&self.narrow_phase);
        w.ccd_solver.clone_from(&self.ccd_solver);
    }
}
