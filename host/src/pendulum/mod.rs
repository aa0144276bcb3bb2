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

use crate::integrator::{rk4_step, SinNear};

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

/// A pendulum's observation `[θ wrapped to (−π, π], θ̇]` of its state
/// `[θ (unwrapped), θ̇]`.
pub(crate) fn observe(x: &[f64; 2], obs: &mut [f32]) {
    obs[0] = wrap_angle(x[0]) as f32;
    obs[1] = x[1] as f32;
}
