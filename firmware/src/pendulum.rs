//! The physical inverted pendulum of Section VII on the robot: observation,
//! reward and the reset between episodes.
//!
//! One RX-28 in wheel mode turns the pendulum; a quadrature encoder on the
//! axis measures the angle (the servo's potentiometer covers only 300°).
//! The encoder is relative: the firmware takes the pendulum to hang down
//! at rest when it boots.
//!
//! As the host's model of the same pendulum (grl-facts §4): θ = 0 upright,
//! observation `[θ wrapped to (−π, π], θ̇]`, reward on the new state and the
//! applied voltage `−5θ² − 0.1θ̇² − u²`, episodes of 3 s that end by time
//! only. θ̇ is the angle's difference over the control period (the model
//! observes the exact rate).
//!
//! Between episodes the motor gets 0 V until the pendulum hangs still
//! (|θ − π| < 0.15 rad and |θ̇| < 0.3 rad/s for 1 s) or 15 s have passed,
//! so every episode starts, as in the model, hanging at rest.

use crate::config::{RobotConfig, MAX_OBS, MAX_SERVOS};
use crate::encoder::wrap_pi;
use core::f32::consts::PI;

/// The voltage limit of the pendulum's motor \[V\] (grl-facts §4).
pub const VOLTAGE_LIMIT: f32 = 3.0;
/// Hanging within this angle counts as down \[rad\].
const DOWN_ANGLE: f32 = 0.15;
/// And slower than this as still \[rad/s\].
const STILL_RATE: f32 = 0.3;
/// For this long \[µs\].
const STILL_TIME_US: u32 = 1_000_000;
/// Longest wait before an episode starts anyway \[µs\].
const MAX_RESET_US: u32 = 15_000_000;

/// The section VII reward on a state (θ wrapped, 0 upright) and the applied
/// voltage.
pub fn swing_up_reward(theta: f32, omega: f32, u: f32) -> f32 {
    -5.0 * theta * theta - 0.1 * omega * omega - u * u
}

/// The pendulum's observer.
#[derive(Debug, Clone)]
pub struct Pendulum {
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
    /// An observer for `config`'s period.
    pub fn new(config: &RobotConfig) -> Self {
        Pendulum {
            period_s: config.period_s(),
            still_needed: STILL_TIME_US.div_ceil(config.period_us),
            max_wait: MAX_RESET_US.div_ceil(config.period_us),
            raw: None,
            theta: PI,
            omega: 0.0,
            still_steps: 0,
            waited_steps: 0,
        }
    }

    /// Takes this period's encoder angle (unwrapped, 0 = the pose at boot,
    /// hanging; `None` if it could not be read: the last angle is kept).
    pub fn sense(&mut self, encoder_angle: Option<f32>) {
        let Some(raw) = encoder_angle else {
            return;
        };
        self.omega = match self.raw {
            Some(prev) => (raw - prev) / self.period_s,
            None => 0.0,
        };
        self.raw = Some(raw);
        self.theta = wrap_pi(PI + raw);
    }

    /// The observation `[θ, θ̇]`; returns its length.
    pub fn observe(&self, obs: &mut [f32; MAX_OBS]) -> usize {
        obs[0] = self.theta;
        obs[1] = self.omega;
        2
    }

    /// Reward for the transition into the current state under the voltage
    /// `applied` during the last period (clipped as the motor clips it).
    pub fn reward(&self, applied: f32) -> f32 {
        let u = applied.clamp(-VOLTAGE_LIMIT, VOLTAGE_LIMIT);
        swing_up_reward(self.theta, self.omega, u)
    }

    /// Angle, 0 upright \[rad\].
    pub fn theta(&self) -> f32 {
        self.theta
    }

    /// Rate \[rad/s\].
    pub fn omega(&self) -> f32 {
        self.omega
    }

    /// Per-servo voltages for the learner's output (the one motor).
    pub fn commands(&self, output: f32, volts: &mut [f32; MAX_SERVOS]) {
        *volts = [0.0; MAX_SERVOS];
        volts[0] = output.clamp(-VOLTAGE_LIMIT, VOLTAGE_LIMIT);
    }

    /// Per-servo voltages between episodes: none.
    pub fn reset_commands(&self, volts: &mut [f32; MAX_SERVOS]) {
        *volts = [0.0; MAX_SERVOS];
    }

    /// Gearbox speed of each servo \[rad/s\] (for the torque estimate).
    pub fn servo_speeds(&self, speeds: &mut [f32; MAX_SERVOS]) {
        *speeds = [0.0; MAX_SERVOS];
        speeds[0] = self.omega;
    }

    /// Starts waiting for the pendulum to hang still.
    pub fn begin_reset(&mut self) {
        self.still_steps = 0;
        self.waited_steps = 0;
    }

    /// One period of waiting; true once the next episode may start.
    pub fn reset_done(&mut self) -> bool {
        self.waited_steps += 1;
        let down = wrap_pi(self.theta - PI).abs() < DOWN_ANGLE;
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
    use crate::config::Robot;

    #[test]
    fn hanging_at_boot_is_theta_pi() {
        let mut p = Pendulum::new(&Robot::Pendulum33.config());
        p.sense(Some(0.0));
        let mut obs = [0.0; MAX_OBS];
        assert_eq!(p.observe(&mut obs), 2);
        assert!((obs[0].abs() - PI).abs() < 1e-6);
        assert_eq!(obs[1], 0.0);
        // Turned up by half a turn: upright.
        p.sense(Some(PI));
        assert!(p.theta().abs() < 1e-6);
        assert!((p.omega() - PI / 0.03).abs() < 1e-3);
        // A lost reading keeps the last state.
        p.sense(None);
        assert!(p.theta().abs() < 1e-6);
    }

    #[test]
    fn reward_matches_the_paper() {
        let mut p = Pendulum::new(&Robot::Pendulum33.config());
        p.sense(Some(PI));
        p.sense(Some(PI));
        assert_eq!(p.reward(0.0), 0.0);
        assert_eq!(p.reward(3.0), -9.0);
        assert_eq!(p.reward(10.0), -9.0, "voltage clipped as the motor clips it");
        p.sense(Some(0.0));
        let r = p.reward(0.0);
        let want = -5.0 * PI * PI - 0.1 * (PI / 0.03) * (PI / 0.03);
        assert!((r - want).abs() < 1e-2 * want.abs(), "{r} vs {want}");
    }

    #[test]
    fn reset_waits_until_hanging_still() {
        let cfg = Robot::Pendulum33.config();
        let mut p = Pendulum::new(&cfg);
        p.sense(Some(0.0));
        p.begin_reset();
        // Swinging: not done.
        for k in 0..20 {
            p.sense(Some(if k % 2 == 0 { 0.5 } else { -0.5 }));
            assert!(!p.reset_done());
        }
        // Still for a second: done after 34 periods of 30 ms (the first
        // still sample still carries the last swing's rate).
        let mut n = 0;
        loop {
            p.sense(Some(0.01));
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
            p.sense(Some(if n % 2 == 0 { 1.0 } else { -1.0 }));
            n += 1;
            if p.reset_done() {
                break;
            }
        }
        assert_eq!(n, 500);
    }
}
