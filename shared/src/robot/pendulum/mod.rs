//! The physical inverted pendulum of Section VII, defined once (constants,
//! timing, observation, reward as GRL's, docs/reference/grl.md §4, and its
//! hardware: one RX-28 in wheel mode, an encoder on the axis). The host's
//! model (`sim/src/pendulum/physical.rs`) integrates its dynamics; the
//! firmware reads it through the encoder and drives its motor. Both apply
//! the rules of [`rules::Pendulum`].
//!
//! - θ = 0 upright, the observation `[θ wrapped to (−π, π], θ̇]`;
//! - actions {−3, 0, +3} V, at 33 Hz (the paper's experiment) or 20 Hz
//!   (the simulated pendulum's rate on the same hardware);
//! - reward on the new state and the applied voltage `−5θ² − 0.1θ̇² − u²`;
//! - episodes of 3 s that end by time only, starting hanging at rest;
//! - the gearbox torque for the fatigue counter: the voltage times the
//!   motor's stall torque per volt `K/R` (the paper's "linear relationship
//!   between voltage and torque"; see [`gearbox_torque`]).

mod rules;

pub use rules::Pendulum;

use super::hardware::{EncoderSpec, JointRange, JointSpec};
use super::{MotorLevels, RobotSpec, TableNeed, TorqueLaw};
use crate::agent::{SarsaParams, WeightInit};
use crate::tile_coding::StateDim;
use core::f32::consts::PI;

/// Motor torque constant K \[N·m/A\] (docs/reference/grl.md §4).
pub const TORQUE_CONSTANT: f64 = 0.0536;
/// Motor resistance R \[Ω\] (docs/reference/grl.md §4).
pub const RESISTANCE: f64 = 9.5;
/// The motor's voltage limit \[V\] (docs/reference/grl.md §4).
pub const VOLTAGE_LIMIT: f64 = 3.0;
/// Episode length \[µs\]: 3 s (docs/reference/grl.md §4).
pub const EPISODE_US: u32 = 3_000_000;

/// The tile coder's view (GRL's resolution \[0.31415 rad, 3.1415 rad/s\]
/// and velocity bounds ±12π, docs/reference/grl.md §4): 20 angle tiles per turn,
/// velocity tiles π rad/s wide.
pub const STATE: [StateDim; 2] = [
    StateDim { min: -PI, max: PI, tile_width: 2.0 * PI / 20.0, wrap: true },
    StateDim { min: -12.0 * PI, max: 12.0 * PI, tile_width: PI, wrap: false },
];

/// The voltage levels \[V\].
pub const LEVELS: [f32; 3] = [-VOLTAGE_LIMIT as f32, 0.0, VOLTAGE_LIMIT as f32];

/// The paper's learning parameters ([`SarsaParams::SECTION_VII`]: α 0.2,
/// γ 0.99, ε 0.05, λ 0.92, replacing traces pruned at 0.01), weights
/// U[0, 1] (GRL's pendulum configuration; optimistic, since every reward
/// ≤ 0).
pub const PARAMS: SarsaParams = SarsaParams { init: WeightInit::Uniform { min: 0.0, max: 1.0 }, ..SarsaParams::SECTION_VII };

/// 16-bit weights hold ±16384 in steps of 1/2. Typical Q-values are
/// −100 … −2000; the bound of a return over the 100-step horizon of
/// γ = 0.99, −(5π² + 0.1·(12π)² + 9)·100 ≈ −20 000, needs a pendulum
/// spinning at its 12π limit for the whole horizon (a weight there would
/// saturate, and be counted).
pub const HALF_SHIFT: u8 = 15;

/// The pendulum's motor: one RX-28 in wheel mode, Dynamixel ID 1,
/// position counts increasing with the positive (counter-clockwise)
/// voltage. It turns freely: no soft limit.
pub const JOINTS: [JointSpec; 1] =
    [JointSpec { name: "axis", servo: &crate::servo::RX28, id: 1, zero: 512, sign: 1, soft_limit: None }];

/// The quadrature encoder on the axis (the servo's potentiometer covers
/// only 300°): a 1024-line encoder, 4096 counts per turn.
pub const ENCODER: EncoderSpec = EncoderSpec { counts_per_rev: 4096, sign: 1 };

/// The supply assumed until the servo reports it \[V\].
pub const SUPPLY_NOMINAL_V: f32 = 12.0;

/// Weights of the pendulum's exact table with SARSA, the low-pass filter,
/// the integrator or PADA: 20 angle tiles × 26 velocity tiles × 16
/// tilings × 3 actions (the Markov variants add a state dimension and need
/// 4× more).
pub const EXACT_WEIGHTS: usize = 24_960;

/// The pendulum's learning task at a control period of `period_us`.
const fn spec(name: &'static str, period_us: u32) -> RobotSpec {
    RobotSpec {
        name,
        period_us,
        episode_steps: EPISODE_US / period_us,
        test_interval: 10,
        state: &STATE,
        motor_dims: 1,
        levels: MotorLevels::Listed(&LEVELS),
        action_tiles: None,
        params: PARAMS,
        joints: &JOINTS,
        counted: JointRange { start: 0, end: 1 },
        encoder: Some(ENCODER),
        supply_nominal_v: SUPPLY_NOMINAL_V,
        paper_torque: TorqueLaw::Rule(paper_gear_torque),
        footstep_remap: None,
        half_shift: HALF_SHIFT,
        table: TableNeed::Exact { weights: EXACT_WEIGHTS },
        vocabulary: None,
    }
}

/// At the paper's 33 Hz (30 ms, 100 steps per episode).
pub static SPEC_33HZ: RobotSpec = spec("physical-pendulum", 30_000);
/// At 20 Hz (50 ms, 60 steps per episode).
pub static SPEC_20HZ: RobotSpec = spec("physical-pendulum-20hz", 50_000);

/// An angle wrapped to (−π, π].
pub fn wrap_angle(theta: f64) -> f64 {
    use core::f64::consts::{PI, TAU};
    // `f64::rem_euclid` as std defines it (std only): [0, 2π).
    let r = theta % TAU;
    let w = if r < 0.0 { r + TAU } else { r };
    if w > PI {
        w - TAU
    } else {
        w
    }
}

/// The Section VII reward on a state and the applied voltage:
/// `−5θ² − 0.1θ̇² − u²` (θ wrapped, 0 upright). In `f64`, as the host's
/// model integrates; the chip's few calls per period cost nothing.
pub fn swing_up_reward(theta: f64, omega: f64, voltage: f64) -> f64 {
    -5.0 * theta * theta - 0.1 * omega * omega - voltage * voltage
}

/// The voltage the motor applies for a command: clipped to ±3 V.
pub fn clip_voltage(voltage: f64) -> f64 {
    voltage.clamp(-VOLTAGE_LIMIT, VOLTAGE_LIMIT)
}

/// Gearbox torque \[N·m\] for the fatigue counter under `voltage`: the
/// paper assumes "a linear relationship between voltage and torque, and
/// that it is generated by the same hardware as in LEO"; the factor is the
/// motor's own stall torque per volt K/R = 5.642·10⁻³ N·m/V (3 V ↦
/// 0.0169 N·m), fed to LEO's gearbox of Table I. With it the MTBF comes out
/// near the paper's 10⁸ s; RX-28's 3.3/14 N·m/V would give ~10⁴ s.
pub fn gearbox_torque(voltage: f64) -> f64 {
    clip_voltage(voltage) * TORQUE_CONSTANT / RESISTANCE
}

/// [`gearbox_torque`] in the form of the definition's [`TorqueLaw`]
/// (`f32` in and out, as the fatigue counter takes torques).
pub fn paper_gear_torque(voltage: f32) -> f32 {
    gearbox_torque(voltage as f64) as f32
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn wrap_angle_range() {
        use core::f64::consts::PI;
        assert_eq!(wrap_angle(PI), PI);
        assert!((wrap_angle(-PI) - PI).abs() < 1e-15);
        assert!((wrap_angle(3.0 * PI / 2.0) + PI / 2.0).abs() < 1e-12);
        assert!((wrap_angle(-0.1) + 0.1).abs() < 1e-15);
        assert!((wrap_angle(4.0 * PI + 0.25) - 0.25).abs() < 1e-12);
        for k in -100..100 {
            let w = wrap_angle(k as f64 * 0.37);
            assert!(w > -PI && w <= PI, "{w}");
        }
    }

    #[test]
    fn reward_and_torque_are_the_papers() {
        use core::f64::consts::PI;
        assert_eq!(swing_up_reward(0.0, 0.0, 0.0), 0.0);
        assert!((swing_up_reward(PI, 0.0, 0.0) + 5.0 * PI * PI).abs() < 1e-12);
        assert!((swing_up_reward(0.1, 2.0, 1.5) - (-0.05 - 0.4 - 2.25)).abs() < 1e-12);
        assert!((gearbox_torque(3.0) - 3.0 * 0.0536 / 9.5).abs() < 1e-12);
        assert_eq!(gearbox_torque(-9.0), gearbox_torque(-3.0));
    }

    #[test]
    fn timing() {
        assert_eq!(SPEC_33HZ.episode_steps, 100);
        assert_eq!(SPEC_20HZ.episode_steps, 60);
    }
}
