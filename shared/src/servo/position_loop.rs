//! A servo's own position loop, as the STS3215's firmware runs it in
//! Operating_Mode 0 (every LeRobot arm): a PID on the goal-position error
//! in encoder counts whose output is the H-bridge's duty cycle, i.e. a
//! fraction of the supply applied to the motor. The voltage it produces
//! drives the same DC-motor model as a learned voltage ([`super::DcMotor`]),
//! so the gear torque the fatigue counter sees is the one the loop causes.
//!
//! What is published and what is a guess (`docs/reference/feetech.md`,
//! "Which mode pada uses and why"):
//!
//! - **P, D, I** are bytes at addresses 21, 22, 23 of the control table;
//!   factory 32, 32, 0 (Feetech's memory table); LeRobot writes 16, 32, 0
//!   ([`LoopGains::LEROBOT`]).
//! - **The output scaling of P** is measured: Rhoban's BAM found with an
//!   oscilloscope that a position error of 1 rad times P gives a duty cycle
//!   of 0.166, saturating at 0.97. In counts (4096 per turn) that is
//!   0.166·2π/4096 = 2.546·10⁻⁴ of full duty per count per unit of P,
//!   about P·e/4 in Feetech's 0.1 % units.
//! - **D and I's scaling** is not published: D is given P's scale on the
//!   change of the error over one loop period, I P's scale on the error
//!   summed over the loop periods of one second (guesses; LeRobot and the
//!   factory set I = 0, and BAM's P-only model fits the servo at D = 32).
//! - **The loop period** is taken as 1 ms ("position update rate 1 ms" in
//!   Feetech's STS3250 datasheet as Robonine quotes it); a guess for the
//!   STS3215.
//! - **The dead zones** (CW_Dead_Zone 26, CCW_Dead_Zone 27, factory 1
//!   count each) and the **minimum starting force** (address 24, factory
//!   16 in 0.1 % of full output) are the memory table's; how the firmware
//!   applies them (no output within the dead zone; at least the minimum
//!   outside it) is read from their descriptions, not measured.
//!
//! All arithmetic is total: a non-finite angle, goal or supply reads as 0.

/// The loop's three coefficients as the control table holds them.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct LoopGains {
    /// P_Coefficient (address 21).
    pub p: u8,
    /// D_Coefficient (address 22).
    pub d: u8,
    /// I_Coefficient (address 23).
    pub i: u8,
}

impl LoopGains {
    /// As the STS3215 ships (Feetech's memory table): P 32, D 32, I 0.
    pub const FACTORY: LoopGains = LoopGains { p: 32, d: 32, i: 0 };
    /// What LeRobot's SO follower writes at every connect: P 16, D 32, I 0.
    pub const LEROBOT: LoopGains = LoopGains { p: 16, d: 32, i: 0 };
}

/// A position loop's constants: the gains and how the firmware scales them.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct PositionLoopSpec {
    /// The coefficients.
    pub gains: LoopGains,
    /// Encoder counts per radian at the output (4096 per turn).
    pub counts_per_rad: f32,
    /// Duty cycle per count of error per unit of a coefficient.
    pub duty_per_count: f32,
    /// The largest duty cycle the bridge applies.
    pub max_duty: f32,
    /// No output while the goal is this many counts or fewer below the
    /// present position (CW_Dead_Zone).
    pub cw_dead_zone: u8,
    /// No output while the goal is this many counts or fewer above it
    /// (CCW_Dead_Zone).
    pub ccw_dead_zone: u8,
    /// The smallest duty cycle applied outside the dead zone (Minimum
    /// Startup Force).
    pub min_duty: f32,
    /// The loop's period \[s\].
    pub period_s: f32,
}

impl PositionLoopSpec {
    /// The STS3215's loop with `gains` (module documentation for each
    /// constant and its source).
    pub const fn sts3215(gains: LoopGains) -> PositionLoopSpec {
        PositionLoopSpec {
            gains,
            counts_per_rad: (4096.0 / core::f64::consts::TAU) as f32,
            // BAM: 0.166 duty per rad per unit of P, 4096 counts per turn.
            duty_per_count: (0.166 * core::f64::consts::TAU / 4096.0) as f32,
            max_duty: 0.97,
            cw_dead_zone: 1,
            ccw_dead_zone: 1,
            // Minimum Startup Force 16 × 0.1 %.
            min_duty: 0.016,
            period_s: 0.001,
        }
    }

    /// The count an angle reads as (rounded, as the encoder does).
    pub fn counts(&self, angle_rad: f32) -> i32 {
        let c = libm::roundf(finite_or_zero(angle_rad) * self.counts_per_rad);
        c.clamp(-1.0e9, 1.0e9) as i32
    }

    /// The loop's stiffness outside the dead zone and below saturation: the
    /// voltage per radian of error at `supply_v` \[V/rad\].
    pub fn volts_per_rad(&self, supply_v: f32) -> f32 {
        self.gains.p as f32 * self.duty_per_count * self.counts_per_rad * finite_or_zero(supply_v)
    }
}

use crate::rx28::finite_or_zero;

/// One servo's position loop in motion: the error of the last tick, the
/// integral, the time to the next tick and the duty cycle held until then.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct PositionLoop {
    spec: PositionLoopSpec,
    last_error: Option<i32>,
    integral: f32,
    until_tick: f32,
    duty: f32,
}

impl PositionLoop {
    /// A loop at rest: no error seen, no output.
    pub const fn new(spec: PositionLoopSpec) -> PositionLoop {
        PositionLoop { spec, last_error: None, integral: 0.0, until_tick: 0.0, duty: 0.0 }
    }

    /// Its constants.
    pub fn spec(&self) -> &PositionLoopSpec {
        &self.spec
    }

    /// Back at rest (torque re-enabled, a new episode).
    pub fn reset(&mut self) {
        *self = PositionLoop::new(self.spec);
    }

    /// The duty cycle applied now, −max_duty..max_duty.
    pub fn duty(&self) -> f32 {
        self.duty
    }

    /// One tick of the firmware's loop on the goal and present counts:
    /// returns the new duty cycle, held until the next tick.
    pub fn tick(&mut self, goal: i32, present: i32) -> f32 {
        let s = &self.spec;
        let e = goal.saturating_sub(present);
        let inside = (e < 0 && -e <= s.cw_dead_zone as i32) || (e >= 0 && e <= s.ccw_dead_zone as i32);
        let de = self.last_error.map_or(0, |l| e.saturating_sub(l));
        self.last_error = Some(e);
        if inside {
            self.duty = 0.0;
            return 0.0;
        }
        let ticks_per_s = 1.0 / s.period_s.max(1e-6);
        let g = s.duty_per_count;
        if s.gains.i > 0 {
            // Anti-windup: the integral alone never asks for more than full duty.
            let limit = s.max_duty / (g * s.gains.i as f32) * ticks_per_s;
            self.integral = (self.integral + e as f32).clamp(-limit, limit);
        }
        let u = g
            * (s.gains.p as f32 * e as f32
                + s.gains.d as f32 * de as f32
                + s.gains.i as f32 * self.integral / ticks_per_s);
        let u = if u != 0.0 && libm::fabsf(u) < s.min_duty { libm::copysignf(s.min_duty, u) } else { u };
        self.duty = u.clamp(-s.max_duty, s.max_duty);
        self.duty
    }

    /// Advances the loop by `dt` seconds of a simulation with the joint at
    /// `angle_rad` and the goal at `goal_rad`; returns the voltage applied
    /// over that step, the duty cycle times `supply_v`. The loop ticks when
    /// a period has passed (at its own rate when `dt` is shorter than a
    /// period; once a step when it is longer).
    pub fn step(&mut self, goal_rad: f32, angle_rad: f32, supply_v: f32, dt: f32) -> f32 {
        self.until_tick -= finite_or_zero(dt);
        if self.until_tick <= 0.0 {
            let (goal, present) = (self.spec.counts(goal_rad), self.spec.counts(angle_rad));
            self.tick(goal, present);
            self.until_tick = (self.until_tick + self.spec.period_s).max(0.0);
        }
        self.duty * finite_or_zero(supply_v)
    }
}

/// How a joint's servo turns a command into its motor's voltage.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum ControlMode {
    /// The command is the voltage (the paper's actions: Dynamixel wheel
    /// mode or PWM Control Mode, Feetech Operating_Mode 2).
    Voltage,
    /// The command is a goal angle that the servo's own loop follows
    /// (Feetech Operating_Mode 0, Dynamixel Position Control Mode).
    Position(PositionLoopSpec),
}

#[cfg(test)]
#[path = "position_loop_tests.rs"]
mod tests;
