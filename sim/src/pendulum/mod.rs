//! The two pendulum tasks of Section VII: the simulated inverted pendulum
//! ([`simulated`]) and a model of the physical pendulum of the paper's
//! experiment ([`physical`]), both swung up from hanging down.

pub mod physical;
pub mod simulated;

pub use physical::{PhysicalPendulum, PhysicalPendulumParams, PhysicalPendulumTask};
pub use simulated::{SimulatedPendulum, SimulatedPendulumParams, SimulatedPendulumTask};

/// The angle wrap and the Section VII reward are the physical pendulum's
/// one definition in pada-core (the simulated pendulum's reward is the
/// same, on its torque instead of a voltage).
pub use pada_core::robot::pendulum::{swing_up_reward, wrap_angle};

use crate::task::{Plant, Step};
use crate::integrator::{rk4_step, SinNear};
use pada_core::action_space::{Output, MAX_ACTION_DIMS};
use rand_core::RngCore;
use std::f64::consts::PI;

/// One control period of `θ̈ = gain·sin θ + drive − friction·θ̇`, the
/// equation of motion both pendulums share once their constants are folded
/// (per unit inertia: gravity's moment, the held torque or voltage's, and
/// the viscous plus back-EMF friction): RK4 over `substeps` equal steps,
/// the drive held, `sin` taken near each sub-step's start ([`SinNear`]).
pub(crate) fn swing(mut x: [f64; 2], period_s: f64, substeps: u32, gain: f64, drive: f64, friction: f64) -> [f64; 2] {
    let h = period_s / substeps as f64;
    for _ in 0..substeps {
        let near = SinNear::new(x[0]);
        x = rk4_step(&x, h, |y| [y[1], gain * near.sin(y[0]) + drive - friction * y[1]]);
    }
    x
}

/// [`swing`] with dry friction `k[3]` (per unit inertia) against the
/// motion: `θ̈ = k[0]·sin θ + k[1] − k[2]·θ̇ − k[3]·tanh(θ̇/ω_s)`, the sign
/// smoothed over ω_s, at least 0.05 rad/s and wide enough that RK4 stays
/// stable at the model's step (the friction's slope times the step at most
/// 1) (a plant that differs from its model: [`crate::variation`]).
pub(crate) fn swing_dry(x: [f64; 2], period_s: f64, substeps: u32, k: [f64; 4]) -> [f64; 2] {
    let smooth = (k[3] * period_s / substeps as f64).max(0.05);
    crate::integrator::integrate(x, period_s, substeps, |y| {
        [y[1], k[0] * y[0].sin() + k[1] - k[2] * y[1] - k[3] * (y[1] / smooth).tanh()]
    })
}

/// A pendulum's observation `[θ wrapped to (−π, π], θ̇]` of its state
/// `[θ (unwrapped), θ̇]`.
pub(crate) fn observe(x: &[f64; 2], obs: &mut [f32]) {
    obs[0] = wrap_angle(x[0]) as f32;
    obs[1] = x[1] as f32;
}

/// What a pendulum model gives its plant ([`Pendulum`]).
pub trait PendulumModel: Clone + Send + Sync {
    /// The bound of the drive, torque \[N·m\] or voltage \[V\]: commands
    /// beyond it are clipped.
    fn drive_limit(&self) -> f64;
    /// The state after one control period with the drive `u` held (within
    /// the bound).
    fn advance(&self, x: [f64; 2], u: f64) -> [f64; 2];
    /// The gearbox torque of the motor command `command` \[N·m\].
    fn gearbox_torque(&self, command: f32) -> f32;
    /// The model with `draw`'s mass, motor constant and friction.
    fn varied(&self, draw: &crate::variation::PlantDraw) -> Self;
}

/// A pendulum plant of model `M`: state `[θ, θ̇]` with θ unwrapped
/// internally, swung up from hanging down at rest; the reward is Section
/// VII's ([`swing_up_reward`]) on the clipped drive.
#[derive(Debug, Clone)]
pub struct Pendulum<M> {
    params: M,
    x: [f64; 2],
    /// The angle's reading on a plant that is not its model (`None`: the
    /// model's exact angle).
    sensor: Option<crate::variation::Sensor>,
}

impl<M: PendulumModel> Pendulum<M> {
    /// A pendulum hanging down at rest.
    pub fn new(params: M) -> Self {
        Pendulum { params, x: [PI, 0.0], sensor: None }
    }

    /// A pendulum whose angle is read through `sensor` (play and noise).
    pub fn with_sensor(params: M, sensor: Option<crate::variation::Sensor>) -> Self {
        Pendulum { params, x: [PI, 0.0], sensor }
    }

    /// The observation, the angle through the sensor if there is one.
    fn sense(&mut self, obs: &mut [f32]) {
        observe(&self.x, obs);
        if let Some(s) = self.sensor.as_mut() {
            obs[0] = wrap_angle(s.read(0, self.x[0])) as f32;
        }
    }

    /// The internal state `[θ (unwrapped), θ̇]`.
    pub fn state(&self) -> [f64; 2] {
        self.x
    }
}

impl<M: PendulumModel> Plant for Pendulum<M> {
    fn reset(&mut self, _rng: &mut dyn RngCore, obs: &mut [f32]) {
        self.x = [PI, 0.0];
        if let Some(s) = self.sensor.as_mut() {
            s.settle(0, PI);
        }
        self.sense(obs);
    }

    fn step(&mut self, command: &[f32], obs: &mut [f32]) -> Step {
        let limit = self.params.drive_limit();
        let u = (command[0] as f64).clamp(-limit, limit);
        self.x = self.params.advance(self.x, u);
        self.sense(obs);
        let reward = swing_up_reward(wrap_angle(self.x[0]), self.x[1], u);
        Step { reward: reward as f32, terminal: false }
    }

    fn gearbox_torques(&self, command: &[f32]) -> Output {
        let mut t = [0.0; MAX_ACTION_DIMS];
        t[0] = self.params.gearbox_torque(command[0]);
        t
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// One pendulum's 3 s bang-bang swing-up: ±`bound` switching every 7
    /// control periods pumps it over the top (the most demanding motion
    /// of the task).
    struct SwingUp {
        substeps: u32,
        bound: f64,
        period_s: f64,
        periods: usize,
        /// `advance` of the model at `n` sub-steps.
        advance: Box<dyn Fn(u32, [f64; 2], f64) -> [f64; 2]>,
        /// The model's reference derivative.
        derivative: Box<dyn Fn(&[f64; 2], f64) -> [f64; 2]>,
    }

    impl SwingUp {
        fn drive(&self, k: usize) -> f64 {
            if (k / 7) % 2 == 0 {
                self.bound
            } else {
                -self.bound
            }
        }

        /// The state after the swing-up at `n` sub-steps per period.
        fn rollout(&self, n: u32) -> [f64; 2] {
            (0..self.periods).fold([PI, 0.0], |x, k| (self.advance)(n, x, self.drive(k)))
        }
    }

    fn both() -> [SwingUp; 2] {
        let (sim, phys) = (SimulatedPendulumParams::default(), PhysicalPendulumParams::default());
        [
            SwingUp {
                substeps: sim.substeps,
                bound: sim.torque_limit,
                period_s: sim.period_s,
                periods: (3.0 / sim.period_s).round() as usize,
                advance: Box::new(|n, x, u| SimulatedPendulumParams { substeps: n, ..Default::default() }.advance(x, u)),
                derivative: Box::new(move |x, u| sim.derivative(x, u)),
            },
            SwingUp {
                substeps: phys.substeps,
                bound: phys.voltage_limit,
                period_s: phys.period_s,
                periods: (3.0 / phys.period_s).round() as usize,
                advance: Box::new(|n, x, u| PhysicalPendulumParams { substeps: n, ..Default::default() }.advance(x, u)),
                derivative: Box::new(move |x, u| phys.derivative(x, u)),
            },
        ]
    }

    #[test]
    fn halving_the_step_changes_a_3s_rollout_by_less_than_1e_6_rad() {
        for s in both() {
            let n = s.substeps;
            let (a, b) = (s.rollout(n), s.rollout(2 * n));
            let d = (a[0] - b[0]).abs();
            assert!(d < 1e-6, "Δθ = {d:e} rad with {n} vs {} sub-steps", 2 * n);
            // The pendulum did swing: the check is not on a resting state.
            assert!(a[1].abs() > 1.0, "{a:?}");
            // And the criterion is not met trivially: 2 sub-steps miss it.
            assert!((s.rollout(2)[0] - s.rollout(4)[0]).abs() > 1e-6, "{n} sub-steps");
        }
    }

    #[test]
    fn swing_agrees_with_plain_rk4_on_the_library_sin() {
        // The shortcut for sin inside a sub-step changes nothing beyond
        // rounding: compare with the generic integrator on f64::sin.
        for s in both() {
            let (mut a, mut b) = ([PI, 0.0], [PI, 0.0]);
            for k in 0..s.periods {
                let u = s.drive(k);
                a = (s.advance)(s.substeps, a, u);
                b = crate::integrator::integrate(b, s.period_s, s.substeps, |x| (s.derivative)(x, u));
            }
            assert!((a[0] - b[0]).abs() < 1e-12 && (a[1] - b[1]).abs() < 1e-11, "{a:?} vs {b:?}");
        }
    }
}
