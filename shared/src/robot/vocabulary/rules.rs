//! [`Vocab`]: a [`Vocabulary`] applied, period after period.
//!
//! Everything is measured from the joint angles the servos report (and the
//! voltages applied): rates are differences of angles over the control
//! period, points come from the URDF's forward kinematics, and a point's
//! rate is a difference of positions. The chip and the host's simulation
//! feed the same readings through the same code, so they observe and
//! reward the same. Indices out of range (a malformed definition) read as
//! 0 and are never a panic; `Vocab::check` names them.

use super::{End, RewardTerm, Signal, Vocabulary, MAX_POINTS};
use crate::error::ConfigError;
use crate::limits::{MAX_SERVOS, MAX_STATE_DIMS};
use crate::robot::{PerServo, RobotRules, RobotSpec, Sensed};
use crate::servo::DcMotor;

/// The rules of a robot said in the vocabulary.
#[derive(Debug, Clone)]
pub struct Vocab {
    spec: &'static RobotSpec,
    words: &'static Vocabulary,
    /// Each joint's servo's motor (for the gearbox torque estimate).
    motors: [Option<DcMotor>; MAX_SERVOS],
    period_s: f32,
    /// Joint angles \[rad\] and rates \[rad/s\], this period.
    q: [f32; MAX_SERVOS],
    qd: [f32; MAX_SERVOS],
    q_prev: [Option<f32>; MAX_SERVOS],
    /// Points \[m\] and their rates \[m/s\], this period; the last period's
    /// points.
    points: [[f32; 3]; MAX_POINTS],
    point_rates: [[f32; 3]; MAX_POINTS],
    points_prev: Option<[[f32; 3]; MAX_POINTS]>,
    /// The voltages applied during the last period and the one before.
    applied: PerServo,
    applied_prev: PerServo,
    /// Periods of the reset so far, and of them the last ones settled.
    waited: u32,
    settled: u32,
}

impl Vocab {
    /// The rules of `spec`, whose [`RobotSpec::vocabulary`] says them;
    /// refused, with the field named, if the definition is malformed
    /// ([`Vocab::check`]).
    pub fn new(spec: &'static RobotSpec) -> Result<Vocab, ConfigError> {
        let Some(words) = spec.vocabulary else {
            return Err(ConfigError::new("vocabulary", 0.0, "a robot whose rules are said in the vocabulary"));
        };
        Self::check(spec, words)?;
        let mut motors = [None; MAX_SERVOS];
        for (m, j) in motors.iter_mut().zip(spec.joints) {
            *m = Some(j.servo.motor());
        }
        Ok(Vocab {
            spec,
            words,
            motors,
            period_s: spec.period_us as f32 * 1e-6,
            q: [0.0; MAX_SERVOS],
            qd: [0.0; MAX_SERVOS],
            q_prev: [None; MAX_SERVOS],
            points: [[0.0; 3]; MAX_POINTS],
            point_rates: [[0.0; 3]; MAX_POINTS],
            points_prev: None,
            applied: [0.0; MAX_SERVOS],
            applied_prev: [0.0; MAX_SERVOS],
            waited: 0,
            settled: 0,
        })
    }

    /// Whether `words` fits `spec`: every index names a joint, a point or
    /// an axis that exists, one signal per observed dimension, one learned
    /// joint per motor dimension, a start angle per joint, at most
    /// [`MAX_POINTS`] points.
    pub fn check(spec: &RobotSpec, words: &Vocabulary) -> Result<(), ConfigError> {
        let joints = spec.joints.len();
        let fail = |field: &'static str, value: usize, valid: &'static str| {
            Err(ConfigError::new(field, value as f32, valid))
        };
        if words.points.len() > MAX_POINTS {
            return fail("points", words.points.len(), "at most 4 points");
        }
        let signal_ok = |s: &Signal| match *s {
            Signal::Angle(j) | Signal::Rate(j) => (j as usize) < joints,
            Signal::Position { point, axis } | Signal::Velocity { point, axis } => {
                (point as usize) < words.points.len() && axis < 3
            }
        };
        if words.observation.len() != spec.state.len() {
            return fail("observation", words.observation.len(), "one signal per state dimension");
        }
        if words.observation.iter().any(|s| !signal_ok(s)) {
            return fail("observation", 0, "signals of the robot's joints and points");
        }
        if words.learned.len() != spec.motor_dims as usize {
            return fail("learned", words.learned.len(), "one joint per motor dimension");
        }
        if words.learned.iter().chain(words.held.iter().map(|h| &h.joint)).any(|j| *j as usize >= joints) {
            return fail("learned", 0, "joints of the robot");
        }
        if words.start.len() != joints {
            return fail("start", words.start.len(), "one angle per joint");
        }
        for p in words.points {
            if p.chain.len() > super::MAX_CHAIN || p.chain.iter().any(|c| c.joint.is_some_and(|j| j as usize >= joints)) {
                return fail("points", p.chain.len(), "chains of at most 8 joints of the robot");
            }
        }
        for term in words.rewards {
            let ok = match *term {
                RewardTerm::Quadratic { signal, .. } => signal_ok(&signal),
                RewardTerm::Distance { point, .. } | RewardTerm::DistanceSquared { point, .. } => {
                    (point as usize) < words.points.len()
                }
                RewardTerm::Progress { point, axis, .. } => (point as usize) < words.points.len() && axis < 3,
                RewardTerm::Action { .. } | RewardTerm::ActionChange { .. } | RewardTerm::Constant { .. } => true,
            };
            if !ok {
                return fail("rewards", 0, "terms of the robot's joints and points");
            }
        }
        if words.ends.iter().any(|e| !signal_ok(&e.signal) || e.min.partial_cmp(&e.max) != Some(core::cmp::Ordering::Less)) {
            return fail("ends", 0, "limits of the robot's signals with min < max");
        }
        if !(words.voltage_limit_v.is_finite() && words.voltage_limit_v > 0.0) {
            return Err(ConfigError::new("voltage_limit_v", words.voltage_limit_v, "a positive voltage"));
        }
        Ok(())
    }

    /// The value of `signal` now.
    pub fn signal(&self, signal: Signal) -> f32 {
        let at = |v: &[f32], i: u8| v.get(i as usize).copied().unwrap_or(0.0);
        match signal {
            Signal::Angle(j) => at(&self.q, j),
            Signal::Rate(j) => at(&self.qd, j),
            Signal::Position { point, axis } => self.points.get(point as usize).map_or(0.0, |p| at(p, axis)),
            Signal::Velocity { point, axis } => self.point_rates.get(point as usize).map_or(0.0, |p| at(p, axis)),
        }
    }

    /// The position of point `point` now \[m\].
    pub fn point(&self, point: usize) -> Option<[f32; 3]> {
        (point < self.words.points.len()).then(|| self.points[point])
    }

    /// The squared distance of point `point` to `target` now \[m²\].
    fn squared_distance(&self, point: u8, target: [f32; 3]) -> f32 {
        let p = self.points.get(point as usize).copied().unwrap_or([0.0; 3]);
        let (dx, dy, dz) = (p[0] - target[0], p[1] - target[1], p[2] - target[2]);
        dx * dx + dy * dy + dz * dz
    }

    /// The end that is violated now, if any.
    fn end(&self) -> Option<&End> {
        self.words.ends.iter().find(|e| {
            let v = self.signal(e.signal);
            // NaN (a broken reading) ends the episode too.
            !(v >= e.min && v <= e.max)
        })
    }

    /// `gain · (target − q)` clipped to the voltage limit.
    fn hold(&self, joint: u8, target: f32, gain: f32) -> f32 {
        let q = self.q.get(joint as usize).copied().unwrap_or(0.0);
        let limit = self.words.voltage_limit_v;
        (gain * (target - q)).clamp(-limit, limit)
    }
}

/// `x` wrapped into (−π, π].
fn wrap(x: f32) -> f32 {
    use core::f32::consts::{PI, TAU};
    let w = x - TAU * libm::floorf(x / TAU);
    if w > PI {
        w - TAU
    } else {
        w
    }
}

impl RobotRules for Vocab {
    fn spec(&self) -> &'static RobotSpec {
        self.spec
    }

    /// Rates and point rates start again from the next reading.
    fn start_episode(&mut self) {
        self.q_prev = [None; MAX_SERVOS];
        self.points_prev = None;
        self.qd = [0.0; MAX_SERVOS];
        self.point_rates = [[0.0; 3]; MAX_POINTS];
        self.applied_prev = [0.0; MAX_SERVOS];
    }

    /// Joint angles (a servo that did not answer keeps its last angle),
    /// their rates, the points and their rates, the voltages applied.
    fn sense(&mut self, s: &Sensed) {
        let n = self.spec.joints.len().min(MAX_SERVOS);
        for i in 0..n {
            if let Some(a) = s.angles[i] {
                self.q[i] = a;
            }
            self.qd[i] = match self.q_prev[i] {
                Some(prev) => (self.q[i] - prev) / self.period_s,
                None => 0.0,
            };
            self.q_prev[i] = Some(self.q[i]);
        }
        for (k, p) in self.words.points.iter().enumerate().take(MAX_POINTS) {
            self.points[k] = p.position(&self.q[..n]);
        }
        if let Some(prev) = self.points_prev {
            for k in 0..MAX_POINTS {
                for a in 0..3 {
                    self.point_rates[k][a] = (self.points[k][a] - prev[k][a]) / self.period_s;
                }
            }
        }
        self.points_prev = Some(self.points);
        self.applied_prev = self.applied;
        self.applied = s.applied;
    }

    fn observe(&self, obs: &mut [f32; MAX_STATE_DIMS]) -> usize {
        let n = self.words.observation.len().min(MAX_STATE_DIMS);
        for (o, s) in obs.iter_mut().zip(&self.words.observation[..n]) {
            *o = self.signal(*s);
        }
        n
    }

    fn reward(&self, applied: &PerServo) -> f32 {
        let mut r = 0.0f32;
        let learned = self.words.learned.iter().map(|j| *j as usize);
        for term in self.words.rewards {
            r += match *term {
                RewardTerm::Quadratic { signal, target, weight, wrap: w } => {
                    let d = self.signal(signal) - target;
                    let d = if w { wrap(d) } else { d };
                    weight * d * d
                }
                RewardTerm::Distance { point, target, weight } => weight * libm::sqrtf(self.squared_distance(point, target)),
                RewardTerm::DistanceSquared { point, target, weight } => weight * self.squared_distance(point, target),
                RewardTerm::Progress { point, axis, weight } => {
                    let v = self.signal(super::Signal::Velocity { point, axis });
                    weight * v * self.period_s
                }
                RewardTerm::Action { weight } => {
                    weight * learned.clone().map(|j| applied.get(j).map_or(0.0, |u| u * u)).sum::<f32>()
                }
                RewardTerm::ActionChange { weight } => {
                    let change = |j: usize| {
                        applied.get(j).copied().unwrap_or(0.0) - self.applied_prev.get(j).copied().unwrap_or(0.0)
                    };
                    weight * learned.clone().map(|j| change(j) * change(j)).sum::<f32>()
                }
                RewardTerm::Constant { value } => value,
            };
        }
        if let Some(end) = self.end() {
            r += end.reward;
        }
        r
    }

    fn absorbing(&self) -> bool {
        self.end().is_some()
    }

    /// The learned voltages (clipped; non-finite → 0) on their joints, the
    /// held joints' P laws, 0 V on the rest.
    fn commands(&self, output: &[f32], volts: &mut PerServo) {
        *volts = [0.0; MAX_SERVOS];
        for h in self.words.held {
            if let Some(v) = volts.get_mut(h.joint as usize) {
                *v = self.hold(h.joint, h.target, h.gain_v_per_rad);
            }
        }
        let limit = self.words.voltage_limit_v;
        for (j, u) in self.words.learned.iter().zip(output) {
            if let Some(v) = volts.get_mut(*j as usize) {
                *v = if u.is_finite() { u.clamp(-limit, limit) } else { 0.0 };
            }
        }
    }

    /// Every joint towards the start pose.
    fn reset_commands(&self, volts: &mut PerServo) {
        *volts = [0.0; MAX_SERVOS];
        let gain = self.words.reset.gain_v_per_rad;
        for (j, target) in self.words.start.iter().enumerate().take(MAX_SERVOS) {
            volts[j] = self.hold(j as u8, *target, gain);
        }
    }

    /// Each servo's motor model at the joint's measured rate.
    fn gear_torques(&self, applied: &PerServo, torques: &mut PerServo) {
        *torques = [0.0; MAX_SERVOS];
        for j in 0..MAX_SERVOS {
            if let Some(m) = &self.motors[j] {
                torques[j] = m.joint_torque(applied[j], self.qd[j]);
            }
        }
    }

    fn begin_reset(&mut self) {
        self.waited = 0;
        self.settled = 0;
    }

    fn reset_done(&mut self) -> bool {
        let r = &self.words.reset;
        self.waited = self.waited.saturating_add(1);
        let close = self.words.start.iter().enumerate().all(|(j, target)| {
            let (q, qd) = (self.q.get(j).copied().unwrap_or(0.0), self.qd.get(j).copied().unwrap_or(0.0));
            (q - target).abs() <= r.tolerance_rad && qd.abs() <= r.still_rad_s
        });
        self.settled = if close { self.settled.saturating_add(1) } else { 0 };
        let period_us = self.spec.period_us.max(1);
        self.settled >= r.settle_us.div_ceil(period_us) || self.waited >= r.timeout_us.div_ceil(period_us)
    }
}
