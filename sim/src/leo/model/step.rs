//! The physics step and the control step: the held voltages, the joints'
//! springs and dampers (stops, friction ties), the external forces, and
//! the friction states following the motion.

use rapier3d::prelude::*;

use super::super::constants::*;
use super::anatomy::{limits_and_stop, Body, JOINT_SPECS, NUM_JOINTS};
use super::options::BlowUp;
use super::{LeoModel, ANGULAR_X};

impl LeoModel {
    /// Holds these voltages (V, [`Joint`] order) until the next call
    /// (zero-order hold, §1.1). Each passes the supply clip of §2.1;
    /// non-finite values become 0 V.
    ///
    /// A joint held by dry friction whose tie cannot carry the change of
    /// its voltage torque breaks away now ([`Stiction::at_load_change`]).
    ///
    /// [`Stiction::at_load_change`]: super::super::stiction::Stiction::at_load_change
    pub fn set_voltages(&mut self, voltages: [f32; NUM_JOINTS]) {
        let before = self.voltages;
        self.voltages = voltages.map(|u| {
            if u.is_finite() {
                u.clamp(-SERVO.supply_clip, SERVO.supply_clip)
            } else {
                0.0
            }
        });
        let (q, qd) = self.joint_state();
        for k in 0..NUM_JOINTS {
            let change =
                self.servo.voltage_torque(self.voltages[k]) - self.servo.voltage_torque(before[k]);
            self.friction_states[k] =
                (self.friction).at_load_change(self.friction_states[k], q[k], qd[k], change);
        }
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
                (limits_and_stop(k), self.options.joint_stops)
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

    /// The robot's multibody (every joint's DoFs), mutable.
    pub(super) fn multibody_mut(&mut self) -> Option<&mut Multibody> {
        self.world.multibody_joints.get_multibody_mut(self.multibody)
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
        let Some(mb) = self.multibody_mut() else {
            return;
        };
        let set: Vec<usize> = (0..NUM_JOINTS).filter(|&k| stopped[k]).collect();
        // Columns of A⁻¹ for the stopped DoFs.
        let mut columns = Vec::with_capacity(set.len());
        for &k in &set {
            let mut e = DVector::<f32>::zeros(mb.ndofs());
            if !solve_inverse_column(mb, dofs[k], &mut e) {
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

/// Puts column `dof` of A⁻¹ into `e` (of the multibody's DoFs; the caller
/// keeps it, so a loop of solves allocates once), with A the matrix rapier
/// factorised in its last step (mass, armature, h·damping, h²·springs);
/// `false` where the factorisation cannot solve.
pub(super) fn solve_inverse_column(mb: &Multibody, dof: usize, e: &mut rapier3d::na::DVector<f32>) -> bool {
    e.fill(0.0);
    e[dof] = 1.0;
    mb.inv_augmented_mass().solve_mut(e)
}
