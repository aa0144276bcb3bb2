//! The world build: LEO assembled in one function from the anatomy's tables
//! and the named constants, and the snapshots that reset it.

use rapier3d::prelude::*;
use crate::world_state::WorldState;

use super::super::constants::*;
use super::super::stiction::{FrictionState, Stiction};
use super::anatomy::{
    assemble, body_pose, Body, InitialPose, Material, BODY_SPECS, JOINT_SPECS, NUM_BODIES,
    NUM_JOINTS,
};
use super::options::{options_servo, ModelError, ModelOptions};
use super::{LeoModel, Snapshot, ROOT_DOFS};

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
        // No continuous collision detection: rapier 0.36 sweeps every body
        // it finds moving fast for its size (in 2,314 of 2,404 physics
        // steps of 20 s of learning), and its motion clamping never acted
        // on LEO: with it off, 300 s of SARSA(λ) and of PADA learning end
        // on the same weights bit for bit, and the passive fall and the A/B
        // comparisons are unchanged. It cost 3 % of the instructions
        // (sim/src/leo/README.md, "Speed").
        p.max_ccd_substeps = 0;

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
            let locked = JointAxesMask::LIN_Y | JointAxesMask::ANG_X | JointAxesMask::ANG_Z;
            GenericJointBuilder::new(locked)
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
                .apply_displacement(&[torso[0], torso[1], pitch[Body::Torso as usize]]);
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
        Snapshot {
            world: WorldState::of(&self.world),
            voltages: self.voltages,
            time: self.time,
            stepped: self.stepped,
            friction_states: self.friction_states,
        }
    }

    /// Puts a snapshot of this model back (see [`LeoModel::snapshot`]).
    pub fn restore(&mut self, snapshot: &Snapshot) {
        snapshot.world.restore(&mut self.world);
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
}

/// Every joint held where it stands (the start of an episode: at rest).
pub(super) fn held_at(angles: &[f32; NUM_JOINTS]) -> [FrictionState; NUM_JOINTS] {
    angles.map(|anchor| FrictionState::Stick { anchor })
}
