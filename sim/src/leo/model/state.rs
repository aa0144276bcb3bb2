//! What can be read off the simulated robot: joint and root state, body
//! poses, contact sensors, energy, and the blow-up check.

use pada_core::rx28::ReducedJoint;
use rapier3d::prelude::*;

use super::super::constants::*;
use super::super::stiction::FrictionState;
use super::anatomy::{limits_and_stop, Body, BODY_SPECS, JOINT_SPECS, NUM_JOINTS};
use super::options::{BlowUp, ModelOptions};
use super::{LeoModel, ROOT_PITCH, ROOT_X, ROOT_Z};

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

impl LeoModel {
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
            // Coordinates of the root joint: coords[0] = x, coords[2] = z,
            // coords[4] = rotation about y (not wrapped).
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
        if let Some(mb) = self.multibody_mut() {
            let mut v = mb.generalized_velocity_mut();
            for k in 0..NUM_JOINTS {
                v[dofs[k]] = joint_rates[k];
            }
            if let Some(r) = root_dof {
                v[r + ROOT_X] = root[0];
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
            if let (Some((limits, stop)), true) = (limits_and_stop(k), self.options.joint_stops) {
                let over = (q[k] - limits[1]).max(0.0) + (limits[0] - q[k]).max(0.0);
                potential += 0.5 * (stop[0] * over * over) as f64;
            }
        }
        if self.options.boom_force {
            let p = self.body_point(Body::Torso, BOOM_FORCE_POINT);
            potential += (-BOOM_EXTRA_FORCE_Z * p[1]) as f64;
        }
        // The friction ties' springs.
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
}
