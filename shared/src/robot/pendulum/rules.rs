//! The physical inverted pendulum's rules ([`RobotRules`]): from its
//! encoder to the observation, reward and gearbox torque of the definition
//! in [`super`], and the wait between episodes.
//!
//! One RX-28 in wheel mode turns the pendulum; a quadrature encoder on the
//! axis measures the angle (the servo's potentiometer covers only 300°).
//! The encoder is relative: the firmware takes the pendulum to hang down
//! at rest when it boots. θ̇ is the angle's difference over the control
//! period (the simulation observes the exact rate).
//!
//! Between episodes the motor gets 0 V until the pendulum hangs still
//! (|θ − π| < 0.15 rad and |θ̇| < 0.3 rad/s for 1 s) or 15 s have passed,
//! so every episode starts, as in the simulation, hanging at rest.

use super::{clip_voltage, gearbox_torque, swing_up_reward, wrap_angle};
use crate::limits::{MAX_SERVOS, MAX_STATE_DIMS};
use crate::robot::{PerServo, RobotRules, RobotSpec, Sensed};

/// Hanging within this angle counts as down \[rad\].
const DOWN_ANGLE: f64 = 0.15;
/// And slower than this as still \[rad/s\].
const STILL_RATE: f32 = 0.3;
/// For this long \[µs\].
const STILL_TIME_US: u32 = 1_000_000;
/// Longest wait before an episode starts anyway \[µs\].
const MAX_RESET_US: u32 = 15_000_000;

/// The pendulum's rules at 33 Hz ([`super::SPEC_33HZ`]) or at 20 Hz
/// ([`super::SPEC_20HZ`]): the same hardware.
#[derive(Debug, Clone)]
pub struct Pendulum {
    spec: &'static RobotSpec,
    period_s: f32,
    /// Periods of stillness that end the reset.
    still_needed: u32,
    /// Periods after which the reset ends anyway.
    max_wait: u32,
    /// Unwrapped angle from the encoder, 0 = hanging \[rad\].
    raw: Option<f32>,
    theta: f32,
    omega: f32,
    still_steps: u32,
    waited_steps: u32,
}

impl Pendulum {
    /// The rules of `spec` (one of the pendulum's, [`super::SPEC_33HZ`] or
    /// [`super::SPEC_20HZ`]), hanging at rest.
    pub fn new(spec: &'static RobotSpec) -> Self {
        let period_us = spec.period_us;
        Pendulum {
            spec,
            period_s: period_us as f32 * 1e-6,
            still_needed: STILL_TIME_US.div_ceil(period_us),
            max_wait: MAX_RESET_US.div_ceil(period_us),
            raw: None,
            theta: core::f32::consts::PI,
            omega: 0.0,
            still_steps: 0,
            waited_steps: 0,
        }
    }

    /// The paper's experiment at 33 Hz.
    pub fn at_33hz() -> Self {
        Self::new(&super::SPEC_33HZ)
    }

    /// The same pendulum at 20 Hz.
    pub fn at_20hz() -> Self {
        Self::new(&super::SPEC_20HZ)
    }

    /// Angle, 0 upright \[rad\].
    pub fn theta(&self) -> f32 {
        self.theta
    }

    /// Rate \[rad/s\].
    pub fn omega(&self) -> f32 {
        self.omega
    }
}

impl RobotRules for Pendulum {
    fn spec(&self) -> &'static RobotSpec {
        self.spec
    }

    fn start_episode(&mut self) {}

    /// Takes this period's encoder angle (unwrapped, 0 = the pose at boot,
    /// hanging; `None` if it could not be read: the last angle is kept).
    fn sense(&mut self, sensed: &Sensed) {
        let Some(raw) = sensed.encoder_angle else {
            return;
        };
        self.omega = match self.raw {
            Some(prev) => (raw - prev) / self.period_s,
            None => 0.0,
        };
        self.raw = Some(raw);
        self.theta = wrap_angle(core::f64::consts::PI + raw as f64) as f32;
    }

    /// `[θ, θ̇]`.
    fn observe(&self, obs: &mut [f32; MAX_STATE_DIMS]) -> usize {
        obs[0] = self.theta;
        obs[1] = self.omega;
        2
    }

    fn reward(&self, applied: &PerServo) -> f32 {
        let u = clip_voltage(applied[0] as f64);
        swing_up_reward(self.theta as f64, self.omega as f64, u) as f32
    }

    fn absorbing(&self) -> bool {
        false
    }

    fn commands(&self, output: &[f32], volts: &mut PerServo) {
        *volts = [0.0; MAX_SERVOS];
        volts[0] = clip_voltage(output.first().copied().unwrap_or(0.0) as f64) as f32;
    }

    fn reset_commands(&self, volts: &mut PerServo) {
        *volts = [0.0; MAX_SERVOS];
    }

    fn gear_torques(&self, applied: &PerServo, torques: &mut PerServo) {
        *torques = [0.0; MAX_SERVOS];
        torques[0] = gearbox_torque(applied[0] as f64) as f32;
    }

    fn begin_reset(&mut self) {
        self.still_steps = 0;
        self.waited_steps = 0;
    }

    fn reset_done(&mut self) -> bool {
        self.waited_steps += 1;
        let down = wrap_angle(self.theta as f64 - core::f64::consts::PI).abs() < DOWN_ANGLE;
        if down && self.omega.abs() < STILL_RATE {
            self.still_steps += 1;
        } else {
            self.still_steps = 0;
        }
        self.still_steps >= self.still_needed || self.waited_steps >= self.max_wait
    }

}

#[cfg(test)]
mod tests {
    use super::*;
    use core::f32::consts::PI;

    fn sense(p: &mut Pendulum, angle: Option<f32>) {
        p.sense(&Sensed { angles: [None; MAX_SERVOS], encoder_angle: angle, contacts: 0, applied: [0.0; MAX_SERVOS] });
    }

    fn applied(u: f32) -> PerServo {
        let mut a = [0.0; MAX_SERVOS];
        a[0] = u;
        a
    }

    #[test]
    fn hanging_at_boot_is_theta_pi() {
        let mut p = Pendulum::at_33hz();
        sense(&mut p, Some(0.0));
        let mut obs = [0.0; MAX_STATE_DIMS];
        assert_eq!(p.observe(&mut obs), 2);
        assert!((obs[0].abs() - PI).abs() < 1e-6);
        assert_eq!(obs[1], 0.0);
        // Turned up by half a turn: upright.
        sense(&mut p, Some(PI));
        assert!(p.theta().abs() < 1e-6);
        assert!((p.omega() - PI / 0.03).abs() < 1e-3);
        // A lost reading keeps the last state.
        sense(&mut p, None);
        assert!(p.theta().abs() < 1e-6);
    }

    #[test]
    fn reward_and_torque_are_the_shared_definitions() {
        let mut p = Pendulum::at_33hz();
        sense(&mut p, Some(PI));
        sense(&mut p, Some(PI));
        // Upright at rest (up to the f32 encoder angle's rounding of π).
        assert!(p.reward(&applied(0.0)).abs() < 1e-9);
        assert!((p.reward(&applied(3.0)) + 9.0).abs() < 1e-6);
        assert_eq!(p.reward(&applied(10.0)), p.reward(&applied(3.0)), "voltage clipped as the motor clips it");
        sense(&mut p, Some(0.0));
        let r = p.reward(&applied(0.0));
        let want = -5.0 * PI * PI - 0.1 * (PI / 0.03) * (PI / 0.03);
        assert!((r - want).abs() < 1e-2 * want.abs(), "{r} vs {want}");
        let mut t = [0.0; MAX_SERVOS];
        p.gear_torques(&applied(3.0), &mut t);
        assert!((t[0] - 3.0 * 0.0536 / 9.5).abs() < 1e-7);
    }

    #[test]
    fn reset_waits_until_hanging_still() {
        let mut p = Pendulum::at_33hz();
        sense(&mut p, Some(0.0));
        p.begin_reset();
        // Swinging: not done.
        for k in 0..20 {
            sense(&mut p, Some(if k % 2 == 0 { 0.5 } else { -0.5 }));
            assert!(!p.reset_done());
        }
        // Still for a second: done after 34 periods of 30 ms (the first
        // still sample still carries the last swing's rate).
        let mut n = 0;
        loop {
            sense(&mut p, Some(0.01));
            n += 1;
            if p.reset_done() {
                break;
            }
        }
        assert_eq!(n, 35);
        // Never still: gives up after 15 s.
        p.begin_reset();
        let mut n = 0;
        loop {
            sense(&mut p, Some(if n % 2 == 0 { 1.0 } else { -1.0 }));
            n += 1;
            if p.reset_done() {
                break;
            }
        }
        assert_eq!(n, 500);
        let q = Pendulum::at_20hz();
        assert_eq!(q.max_wait, 300);
    }
}
