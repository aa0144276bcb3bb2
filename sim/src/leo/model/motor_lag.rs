//! The step-size correction of the servos' first-order response.

use super::step::solve_inverse_column;
use super::{LeoModel, ANGULAR_X, NUM_JOINTS};

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
    pub(super) fn correct_motor_lag(&mut self) {
        let h = self.options.dt() / self.options.solver_iterations as f32;
        let d = self.servo.damping;
        let a = self.servo.armature;
        if d <= 0.0 {
            return;
        }
        let dofs = self.dofs;
        let links = self.links;
        let stepped = self.stepped;
        // Not `multibody_mut`: the multibody and the rigid bodies are
        // borrowed together below.
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
        let mut inv = [0.0f32; NUM_JOINTS];
        let mut own = [0.0f32; NUM_JOINTS];
        if stepped {
            // One vector for every DoF's solve: this runs every step.
            let mut e = rapier3d::na::DVector::<f32>::zeros(mb.ndofs());
            for (i, &k) in dofs.iter().enumerate() {
                inv[i] = if solve_inverse_column(mb, k, &mut e) { e[k] } else { f32::NAN };
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
