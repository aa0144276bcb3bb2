//! A model of the physical inverted pendulum of the paper's experiment
//! (Section VII, "Inverted pendulum experiment"), standing in for the real
//! setup. Constants, timing, observation and reward are those of the
//! paper's reference framework (GRL, `docs/reference/grl.md` §4):
//!
//! `J·θ̈ = m·g·l·sin θ − b·θ̇ − (K²/R)·θ̇ + (K/R)·u`, θ = 0 upright, with
//! J = 1.91·10⁻⁴ kg·m², m = 0.055 kg, l = 0.042 m, b = 3·10⁻⁶ N·m·s/rad,
//! K = 0.0536 N·m/A, R = 9.5 Ω and the motor voltage u clipped to ±3 V.
//! Control period 0.03 s (the paper's 33 Hz), actions {−3, 0, +3} V,
//! reward on the next state `−5θ² − 0.1θ̇² − u²`, episodes of 3 s
//! (100 steps) starting hanging down at rest.
//!
//! The task (timing, state, actions, learning parameters, reward and the
//! gearbox torque for the fatigue counter) is the robot's one definition,
//! [`pada_core::robot::pendulum`], which the firmware drives too; this
//! module integrates the dynamics. **Torque for the fatigue counter:** the
//! paper's "linear relationship between voltage and torque", the motor's
//! own stall torque per volt `K/R` = 5.642·10⁻³ N·m/V
//! ([`pada_core::robot::pendulum::gearbox_torque`]).

use crate::task::{Task, TaskSpec};
use pada_core::profile::{Board, LearnerProfile};
use pada_core::robot::pendulum::{self as robot, gearbox_torque};

/// Constants of the physical pendulum's model (docs/reference/grl.md §4).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PhysicalPendulumParams {
    /// Moment of inertia \[kg·m²\].
    pub inertia_kg_m2: f64,
    /// Mass \[kg\].
    pub mass_kg: f64,
    /// Distance of the centre of mass from the axis \[m\].
    pub length_m: f64,
    /// Gravity \[m/s²\].
    pub gravity: f64,
    /// Viscous friction \[N·m·s/rad\].
    pub damping: f64,
    /// Motor torque constant K \[N·m/A\].
    pub torque_constant: f64,
    /// Motor resistance R \[Ω\].
    pub resistance_ohm: f64,
    /// Voltage limit \[V\].
    pub voltage_limit: f64,
    /// Control period \[s\].
    pub period_s: f64,
    /// RK4 sub-steps per control period.
    pub substeps: u32,
    /// Dry friction at the axis \[N·m\] (0 in the model; a plant that
    /// differs from it may have some: [`crate::variation`]).
    pub dry_friction_nm: f64,
}

impl Default for PhysicalPendulumParams {
    fn default() -> Self {
        PhysicalPendulumParams {
            inertia_kg_m2: 1.91e-4,
            mass_kg: 0.055,
            length_m: 0.042,
            gravity: 9.81,
            damping: 3e-6,
            torque_constant: robot::TORQUE_CONSTANT,
            resistance_ohm: robot::RESISTANCE,
            voltage_limit: robot::VOLTAGE_LIMIT,
            period_s: robot::SPEC_33HZ.period_s(),
            substeps: 10,
            dry_friction_nm: 0.0,
        }
    }
}

impl PhysicalPendulumParams {
    /// `[θ̇, θ̈]` for state `[θ, θ̇]` under voltage `u`.
    #[inline]
    pub fn derivative(&self, x: &[f64; 2], u: f64) -> [f64; 2] {
        let sin_theta = x[0].sin();
        let k_over_r = self.torque_constant / self.resistance_ohm;
        let torque = self.mass_kg * self.gravity * self.length_m * sin_theta
            - self.damping * x[1]
            - self.torque_constant * k_over_r * x[1]
            + k_over_r * u;
        [x[1], torque / self.inertia_kg_m2]
    }

    /// The state after one control period with voltage `u` (clipped): RK4
    /// over [`substeps`](Self::substeps) equal steps, voltage held.
    pub fn advance(&self, x: [f64; 2], u: f64) -> [f64; 2] {
        let u = u.clamp(-self.voltage_limit, self.voltage_limit);
        // The constants of the derivative, once per control period.
        let k_over_r = self.torque_constant / self.resistance_ohm;
        let gain = self.mass_kg * self.gravity * self.length_m / self.inertia_kg_m2;
        let drive = k_over_r * u / self.inertia_kg_m2;
        let friction = (self.damping + self.torque_constant * k_over_r) / self.inertia_kg_m2;
        if self.dry_friction_nm != 0.0 {
            let dry = self.dry_friction_nm / self.inertia_kg_m2;
            return super::swing_dry(x, self.period_s, self.substeps, [gain, drive, friction, dry]);
        }
        super::swing(x, self.period_s, self.substeps, gain, drive, friction)
    }

    /// Gearbox torque per volt \[N·m/V\]: the motor's stall torque `K/R`
    /// (see the module documentation).
    pub fn torque_per_volt(&self) -> f64 {
        self.torque_constant / self.resistance_ohm
    }
}

/// The physical pendulum's model ([`super::Pendulum`] of these constants).
pub type PhysicalPendulum = super::Pendulum<PhysicalPendulumParams>;

impl super::PendulumModel for PhysicalPendulumParams {
    fn drive_limit(&self) -> f64 {
        self.voltage_limit
    }

    fn advance(&self, x: [f64; 2], u: f64) -> [f64; 2] {
        PhysicalPendulumParams::advance(self, x, u)
    }

    fn varied(&self, draw: &crate::variation::PlantDraw) -> Self {
        PhysicalPendulumParams {
            mass_kg: self.mass_kg * draw.mass,
            inertia_kg_m2: self.inertia_kg_m2 * draw.mass,
            torque_constant: self.torque_constant * draw.motor_constant,
            dry_friction_nm: self.dry_friction_nm + draw.friction_nm,
            ..*self
        }
    }

    fn gearbox_torque(&self, command: f32) -> f32 {
        let u = (command as f64).clamp(-self.voltage_limit, self.voltage_limit);
        // The robot's definition (the model's K/R with its defaults).
        gearbox_torque(u) as f32
    }
}

/// The physical-pendulum task on [`PhysicalPendulum`].
#[derive(Debug, Clone)]
pub struct PhysicalPendulumTask {
    params: PhysicalPendulumParams,
    spec: TaskSpec,
}

impl Default for PhysicalPendulumTask {
    fn default() -> Self {
        Self::new(PhysicalPendulumParams::default())
    }
}

impl PhysicalPendulumTask {
    /// The task with these constants on the host's learner.
    pub fn new(params: PhysicalPendulumParams) -> Self {
        Self::with_profile(params, Board::Host.profile(&pada_core::robot::pendulum::SPEC_33HZ).expect("the host holds any exact table"))
    }

    /// The task on a board's learner `profile` (the 33 Hz pendulum's).
    pub fn with_profile(params: PhysicalPendulumParams, profile: LearnerProfile) -> Self {
        let mut spec = TaskSpec::of_robot(
            profile,
            "model of the physical pendulum of the paper's experiment (GRL constants, +-3 V, 33 Hz)",
            "voltage x K/R = 5.642e-3 N m/V (linear voltage-to-torque, the pendulum motor's stall torque per volt)",
        );
        spec.default_seconds = 1500.0;
        spec.default_trials = 28;
        PhysicalPendulumTask { params, spec }
    }

    /// The constants.
    pub fn params(&self) -> &PhysicalPendulumParams {
        &self.params
    }
}

impl crate::variation::Vary for PhysicalPendulumTask {
    fn plant_with(&self, draw: &crate::variation::PlantDraw, seed: u64) -> PhysicalPendulum {
        use super::PendulumModel;
        PhysicalPendulum::with_sensor(self.params.varied(draw), crate::variation::Sensor::of(draw, seed))
    }
}

impl Task for PhysicalPendulumTask {
    type Plant = PhysicalPendulum;

    fn spec(&self) -> &TaskSpec {
        &self.spec
    }

    fn plant(&self) -> PhysicalPendulum {
        PhysicalPendulum::new(self.params)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::task::Plant;
    use std::f64::consts::PI;

    #[test]
    fn energy_is_conserved_without_voltage_and_friction() {
        // No friction and no back-EMF (K = 0 also removes the motor).
        let p = PhysicalPendulumParams {
            damping: 0.0,
            torque_constant: 0.0,
            ..Default::default()
        };
        let energy = |x: &[f64; 2]| {
            0.5 * p.inertia_kg_m2 * x[1] * x[1] + p.mass_kg * p.gravity * p.length_m * x[0].cos()
        };
        let mut x = [2.0, 5.0];
        let e0 = energy(&x);
        for _ in 0..300 {
            x = p.advance(x, 0.0);
        }
        let drift = (energy(&x) - e0).abs() / e0.abs();
        // RK4 at 10 sub-steps per 0.03 s: about 7e-8 here.
        assert!(drift < 1e-6, "relative energy drift {drift:e} over 9 s");
    }

    #[test]
    fn back_emf_brakes_and_voltage_maps_to_torque_linearly() {
        let p = PhysicalPendulumParams::default();
        // Upright-free fall is symmetric; a spinning pendulum with the
        // motor shorted (u = 0) slows down faster than without the motor.
        let free = PhysicalPendulumParams {
            torque_constant: 0.0,
            damping: 0.0,
            ..p
        };
        let spin = [PI, 20.0];
        assert!(p.advance(spin, 0.0)[1].abs() < free.advance(spin, 0.0)[1].abs());
        let plant = PhysicalPendulum::new(p);
        let t = plant.gearbox_torques(&[3.0])[0] as f64;
        assert!((t - 3.0 * 0.0536 / 9.5).abs() < 1e-7, "{t}");
        assert!((plant.gearbox_torques(&[-9.0])[0] as f64 + 3.0 * 0.0536 / 9.5).abs() < 1e-7);
    }

    #[test]
    fn task_spec_is_grl_facts_4() {
        let t = PhysicalPendulumTask::default();
        let s = t.spec();
        assert_eq!(s.control_period_s, 0.03);
        assert_eq!(s.episode_steps, 100);
        assert_eq!(s.motor.dim(0).values(), &[-3.0, 0.0, 3.0]);
        assert!((s.state[0].tile_width - 0.314_159).abs() < 1e-4);
        assert!((s.state[1].tile_width - std::f32::consts::PI).abs() < 1e-6);
    }
}
