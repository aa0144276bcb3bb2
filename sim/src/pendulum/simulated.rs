//! The simulated inverted pendulum of Section VII.
//!
//! A point mass of 2 kg at 0.2 m from the joint; the moment of inertia is
//! the paper's 0.048 kg·m² **as given** (a point mass would have
//! m·l² = 0.08 kg·m²; the paper's figure is used unchanged). Torque is
//! limited to ±1.5 N·m (three actions {−1.5, 0, +1.5}), so the pendulum
//! cannot be lifted directly (m·g·l = 3.92 N·m) and must be swung up. The
//! state is sampled at 20 Hz.
//!
//! Dynamics, θ from the upright position:
//! `J·θ̈ = m·g·l·sin θ + u − b·θ̇` (b = 0 in the paper, which names no
//! friction), integrated with RK4 over [`SimulatedPendulumParams::substeps`]
//! equal sub-steps per control period with the torque held constant.
//! Reward on the next state: `−5θ² − 0.1θ̇² − a²` with `a` the applied
//! torque. Episodes start hanging down at rest (θ = π).

use crate::task::{Task, TaskSpec, WeightTable};
use pada_core::action_space::{ActionDim, ActionSpace};
use pada_core::agent::{SarsaParams, WeightInit};
use pada_core::tile_coding::StateDim;

/// Physical constants and timing of the simulated pendulum.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SimulatedPendulumParams {
    /// Point mass \[kg\] (Section VII: 2).
    pub mass_kg: f64,
    /// Distance of the mass from the joint \[m\] (Section VII: 0.2).
    pub length_m: f64,
    /// Moment of inertia about the joint \[kg·m²\] (Section VII: 0.048).
    pub inertia_kg_m2: f64,
    /// Gravity \[m/s²\].
    pub gravity: f64,
    /// Viscous friction \[N·m·s/rad\] (0: the paper names none).
    pub damping: f64,
    /// Torque limit \[N·m\] (Section VII: 1.5); commands are clipped to it.
    pub torque_limit: f64,
    /// Control period \[s\] (Section VII: 20 Hz).
    pub period_s: f64,
    /// RK4 sub-steps per control period.
    pub substeps: u32,
    /// Dry friction at the joint \[N·m\] (0 in the model; a plant that
    /// differs from it may have some: [`crate::variation`]).
    pub dry_friction_nm: f64,
    /// Factor on the torque the command asks for (1 in the model: the
    /// motor's constant as the learner assumes it).
    pub motor_factor: f64,
}

impl Default for SimulatedPendulumParams {
    fn default() -> Self {
        SimulatedPendulumParams {
            mass_kg: 2.0,
            length_m: 0.2,
            inertia_kg_m2: 0.048,
            gravity: 9.81,
            damping: 0.0,
            torque_limit: 1.5,
            period_s: 0.05,
            substeps: 30,
            dry_friction_nm: 0.0,
            motor_factor: 1.0,
        }
    }
}

impl SimulatedPendulumParams {
    /// `[θ̇, θ̈]` for state `[θ, θ̇]` under torque `u` (the reference form;
    /// [`advance`](Self::advance) evaluates the same with its constants
    /// folded).
    pub fn derivative(&self, x: &[f64; 2], u: f64) -> [f64; 2] {
        let gravity = self.mass_kg * self.gravity * self.length_m * x[0].sin();
        [
            x[1],
            (gravity + u - self.damping * x[1]) / self.inertia_kg_m2,
        ]
    }

    /// The state after one control period with torque `u` (clipped): RK4
    /// over [`substeps`](Self::substeps) equal steps, torque held.
    pub fn advance(&self, x: [f64; 2], u: f64) -> [f64; 2] {
        let u = u.clamp(-self.torque_limit, self.torque_limit);
        // The constants of the derivative, once per control period.
        let gain = self.mass_kg * self.gravity * self.length_m / self.inertia_kg_m2;
        let (drive, friction) = (u / self.inertia_kg_m2, self.damping / self.inertia_kg_m2);
        if self.dry_friction_nm != 0.0 || self.motor_factor != 1.0 {
            let dry = self.dry_friction_nm / self.inertia_kg_m2;
            return super::swing_dry(x, self.period_s, self.substeps, [gain, drive * self.motor_factor, friction, dry]);
        }
        super::swing(x, self.period_s, self.substeps, gain, drive, friction)
    }

    /// Total mechanical energy `½Jθ̇² + m·g·l·cos θ` \[J\] (conserved
    /// without torque and damping).
    pub fn energy(&self, x: &[f64; 2]) -> f64 {
        0.5 * self.inertia_kg_m2 * x[1] * x[1]
            + self.mass_kg * self.gravity * self.length_m * x[0].cos()
    }
}

/// The simulated pendulum ([`super::Pendulum`] of these constants).
pub type SimulatedPendulum = super::Pendulum<SimulatedPendulumParams>;

impl super::PendulumModel for SimulatedPendulumParams {
    fn drive_limit(&self) -> f64 {
        self.torque_limit
    }

    fn advance(&self, x: [f64; 2], u: f64) -> [f64; 2] {
        SimulatedPendulumParams::advance(self, x, u)
    }

    fn varied(&self, draw: &crate::variation::PlantDraw) -> Self {
        SimulatedPendulumParams {
            mass_kg: self.mass_kg * draw.mass,
            inertia_kg_m2: self.inertia_kg_m2 * draw.mass,
            motor_factor: self.motor_factor * draw.motor_constant,
            dry_friction_nm: self.dry_friction_nm + draw.friction_nm,
            ..*self
        }
    }

    fn gearbox_torque(&self, command: f32) -> f32 {
        // Section VII: the torque is generated by the same hardware as in
        // LEO, so the applied torque is the gearbox torque.
        command.clamp(-self.torque_limit as f32, self.torque_limit as f32)
    }
}

/// Tile width of the angle: 20 tiles per turn (0.314 rad), the resolution of
/// the paper's reference pendulum configuration (GRL, docs/reference/grl.md §4).
pub const ANGLE_TILES: u32 = 20;
/// Tile width of the angular velocity \[rad/s\]: π, as in GRL (docs/reference/grl.md §4).
pub const VELOCITY_TILE_RAD_S: f32 = std::f32::consts::PI;
/// Velocity range ±8π rad/s: above the fastest speed of a swing-up with
/// ±1.5 N·m (about 19 rad/s through the bottom); faster states are clamped.
pub const VELOCITY_LIMIT_RAD_S: f32 = 8.0 * std::f32::consts::PI;

/// The Section VII task on [`SimulatedPendulum`].
#[derive(Debug, Clone)]
pub struct SimulatedPendulumTask {
    params: SimulatedPendulumParams,
    spec: TaskSpec,
}

impl Default for SimulatedPendulumTask {
    fn default() -> Self {
        Self::new(SimulatedPendulumParams::default())
    }
}

impl SimulatedPendulumTask {
    /// The task with these pendulum constants.
    pub fn new(params: SimulatedPendulumParams) -> Self {
        let limit = params.torque_limit as f32;
        let spec = TaskSpec {
            name: "pendulum",
            title: "simulated inverted pendulum of Section VII (2 kg at 0.2 m, 0.048 kg m^2, +-1.5 N m, 20 Hz)",
            control_period_s: params.period_s,
            episode_steps: (3.0 / params.period_s).round() as u32,
            state: vec![
                StateDim::wrapping(-std::f32::consts::PI, std::f32::consts::PI, ANGLE_TILES)
                    .expect("valid angle dimension"),
                StateDim::new(-VELOCITY_LIMIT_RAD_S, VELOCITY_LIMIT_RAD_S, VELOCITY_TILE_RAD_S)
                    .expect("valid velocity dimension"),
            ],
            motor: ActionSpace::new(&[ActionDim::from_levels(&[-limit, 0.0, limit]).expect("valid levels")])
                .expect("valid action space"),
            table: WeightTable::Exact,
            action_tiles: None,
            gearboxes: 1,
            footstep_remap: None,
            profile: None,
            // The action is the gearbox torque.
            worst_torque_nm: limit,
            params: SarsaParams { init: WeightInit::Uniform { min: 0.0, max: 1.0 }, ..SarsaParams::default() },
            test_interval: 10,
            default_seconds: 3000.0,
            default_trials: 29,
            torque_note: "the applied torque in N m (Section VII: generated by the same hardware as in LEO)",
        };
        SimulatedPendulumTask { params, spec }
    }

    /// The pendulum constants.
    pub fn params(&self) -> &SimulatedPendulumParams {
        &self.params
    }
}

impl crate::variation::Vary for SimulatedPendulumTask {
    fn plant_with(&self, draw: &crate::variation::PlantDraw, seed: u64) -> SimulatedPendulum {
        use super::PendulumModel;
        SimulatedPendulum::with_sensor(self.params.varied(draw), crate::variation::Sensor::of(draw, seed))
    }
}

impl Task for SimulatedPendulumTask {
    type Plant = SimulatedPendulum;

    fn spec(&self) -> &TaskSpec {
        &self.spec
    }

    fn plant(&self) -> SimulatedPendulum {
        SimulatedPendulum::new(self.params)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::task::Plant;
    use std::f64::consts::PI;
    use crate::pendulum::{swing_up_reward, wrap_angle};
    use rand_core::SeedableRng;
    use rand_pcg::Pcg64;

    #[test]
    fn energy_is_conserved_without_torque_and_damping() {
        let p = SimulatedPendulumParams::default();
        // Released at 2 rad from upright with a push: a large swing.
        let mut x = [2.0, 3.0];
        let e0 = p.energy(&x);
        for _ in 0..(10.0 / p.period_s) as usize {
            x = p.advance(x, 0.0);
        }
        let drift = (p.energy(&x) - e0).abs() / e0.abs();
        assert!(drift < 1e-8, "relative energy drift {drift:e} over 10 s");
    }

    #[test]
    fn damping_and_torque_change_the_energy_as_they_should() {
        let damped = SimulatedPendulumParams {
            damping: 0.01,
            ..Default::default()
        };
        let mut x = [2.0, 3.0];
        let e0 = damped.energy(&x);
        for _ in 0..100 {
            x = damped.advance(x, 0.0);
        }
        assert!(damped.energy(&x) < e0 - 1e-3);
        // Positive torque while moving in the positive direction adds energy.
        let p = SimulatedPendulumParams::default();
        let x0 = [PI, 1.0];
        assert!(p.energy(&p.advance(x0, 1.5)) > p.energy(&p.advance(x0, 0.0)));
    }

    #[test]
    fn plant_observes_wrapped_angle_and_pays_the_papers_reward() {
        let mut plant = SimulatedPendulum::new(SimulatedPendulumParams::default());
        let mut rng = Pcg64::seed_from_u64(0);
        let mut obs = [0.0f32; 2];
        plant.reset(&mut rng, &mut obs);
        assert_eq!(obs, [PI as f32, 0.0]);
        // Torques beyond the limit are clipped, in the dynamics, the reward
        // and the gearbox torque alike.
        let step = plant.step(&[5.0], &mut obs);
        let x = plant.state();
        let expected = swing_up_reward(wrap_angle(x[0]), x[1], 1.5);
        assert!(
            (step.reward as f64 - expected).abs() < 1e-3,
            "{} vs {expected}",
            step.reward
        );
        assert!(!step.terminal);
        assert!(obs[0] > -std::f32::consts::PI && obs[0] <= std::f32::consts::PI);
        assert_eq!(plant.gearbox_torques(&[-7.0])[0], -1.5);
        // Hanging still: −5π² per step with no torque.
        plant.reset(&mut rng, &mut obs);
        let r = plant.step(&[0.0], &mut obs).reward as f64;
        assert!((r + 5.0 * PI * PI).abs() < 1e-3, "{r}");
    }

    /// A hand-written swing-up controller on the three torques: pump
    /// energy with ±1.5 N·m in the direction of motion until the pendulum
    /// would reach the top, then a PD law near upright, rounded to the
    /// nearest level. Its return over one 3 s episode is about −860, the
    /// scale of the paper's SARSA(λ) end performance (−851): evidence that
    /// the paper's episodes were about 3 s long.
    #[test]
    fn a_hand_written_swing_up_scores_near_the_papers_end_performance() {
        let p = SimulatedPendulumParams::default();
        let mgl = p.mass_kg * p.gravity * p.length_m;
        let mut plant = SimulatedPendulum::new(p);
        let mut rng = Pcg64::seed_from_u64(0);
        let mut obs = [0.0f32; 2];
        plant.reset(&mut rng, &mut obs);
        let mut ret = 0.0f64;
        for _ in 0..60 {
            let [theta, omega] = plant.state();
            let theta = wrap_angle(theta);
            let energy = 0.5 * p.inertia_kg_m2 * omega * omega + mgl * (theta.cos() - 1.0);
            let u: f64 = if theta.abs() < 0.8 {
                -(5.0 * theta + omega)
            } else if energy < 0.0 {
                1.5f64.copysign(omega + 1e-9)
            } else {
                0.0
            };
            let level = if u > 0.75 {
                1.5
            } else if u < -0.75 {
                -1.5
            } else {
                0.0
            };
            ret += plant.step(&[level], &mut obs).reward as f64;
        }
        eprintln!("hand-written swing-up: return {ret:.1}");
        assert!((-900.0..-820.0).contains(&ret), "return {ret}");
        // It does balance: upright and slow at the end.
        let [theta, omega] = plant.state();
        assert!(
            wrap_angle(theta).abs() < 0.1 && omega.abs() < 1.0,
            "{theta} {omega}"
        );
    }

    #[test]
    fn task_spec_is_section_vii() {
        let t = SimulatedPendulumTask::default();
        let s = t.spec();
        assert_eq!(s.control_period_s, 0.05);
        assert_eq!(s.episode_steps, 60);
        assert_eq!(s.motor.dim(0).values(), &[-1.5, 0.0, 1.5]);
        assert_eq!(
            (
                s.params.alpha,
                s.params.gamma,
                s.params.epsilon,
                s.params.lambda
            ),
            (0.2, 0.99, 0.05, 0.92)
        );
    }
}
