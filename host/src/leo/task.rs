//! The walking task of `grl-facts.md` §3: rate filters, stance/swing logic,
//! the mirrored observation, the auto-actuated joints, the reward and the
//! termination. Pure functions and small state machines, independent of the
//! physics, so each rule is tested on its own.

use pada_core::rx28::Rx28;

use super::constants::*;
use super::model::{Joint, NUM_JOINTS};

/// Number of observation dimensions (§3.4).
pub const OBS_DIM: usize = 10;
/// Number of learned action dimensions (§3.4).
pub const ACTION_DIM: usize = 3;

/// The 10-D mirrored observation (§3.4): φ, φ̇, q_hip,st, q̇_hip,st,
/// q_hip,sw, q̇_hip,sw, q_knee,st, q̇_knee,st, q_knee,sw, q̇_knee,sw.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Observation(pub [f32; OBS_DIM]);

/// The leg that carries the robot (§3.3).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Leg {
    /// Left leg.
    Left,
    /// Right leg.
    Right,
}

impl Leg {
    /// The other leg.
    pub fn other(self) -> Leg {
        match self {
            Leg::Left => Leg::Right,
            Leg::Right => Leg::Left,
        }
    }
    /// This leg's hip.
    pub fn hip(self) -> Joint {
        match self {
            Leg::Left => Joint::HipLeft,
            Leg::Right => Joint::HipRight,
        }
    }
    /// This leg's knee.
    pub fn knee(self) -> Joint {
        match self {
            Leg::Left => Joint::KneeLeft,
            Leg::Right => Joint::KneeRight,
        }
    }
}

/// First-order Butterworth low-pass discretised with Tustin, no
/// pre-warping (§3.2): T_c = 2π·f_c/f_s, b0 = b1 = T_c/(T_c + 2),
/// a1 = (T_c − 2)/(T_c + 2), `y[n] = b0·(x[n] + x[n−1]) − a1·y[n−1]`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RateFilter {
    b: f32,
    a1: f32,
    x_prev: f32,
    y_prev: f32,
}

impl RateFilter {
    /// A filter for sampling frequency `fs` and cut-off `fc` (Hz), state 0.
    pub fn new(fs: f32, fc: f32) -> Self {
        let tc = 2.0 * core::f32::consts::PI * fc / fs;
        Self {
            b: tc / (tc + 2.0),
            a1: (tc - 2.0) / (tc + 2.0),
            x_prev: 0.0,
            y_prev: 0.0,
        }
    }
    /// The servo-joint filter: 30 Hz sampling, 10 Hz cut-off (§3.2).
    pub fn joint() -> Self {
        Self::new(JOINT_FILTER_HZ[0], JOINT_FILTER_HZ[1])
    }
    /// The torso filter as GRL configures it (§3.2: a step time passed as
    /// the sampling frequency; practically unfiltered).
    pub fn torso() -> Self {
        Self::new(TORSO_FILTER_HZ[0], TORSO_FILTER_HZ[1])
    }
    /// Coefficients (b0 = b1, a1).
    pub fn coefficients(&self) -> (f32, f32) {
        (self.b, self.a1)
    }
    /// Clears the state (every episode start, §3.2).
    pub fn reset(&mut self) {
        self.x_prev = 0.0;
        self.y_prev = 0.0;
    }
    /// Filters one sample.
    pub fn update(&mut self, x: f32) -> f32 {
        let y = self.b * (x + self.x_prev) - self.a1 * self.y_prev;
        self.x_prev = x;
        self.y_prev = y;
        y
    }
    /// The last output.
    pub fn value(&self) -> f32 {
        self.y_prev
    }
}

/// Horizontal ankle position relative to the hip (§3.3):
/// x_a = 0.116·sin(φ + q_hip) + 0.1045·sin(φ + q_hip + q_knee).
pub fn ankle_x(phi: f32, q_hip: f32, q_knee: f32) -> f32 {
    THIGH_LENGTH * (phi + q_hip).sin() + SHANK_LENGTH * (phi + q_hip + q_knee).sin()
}

/// What one stance update found (§3.3).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StanceUpdate {
    /// Footstep length L after the update.
    pub length: f32,
    /// L_prev for the reward (sign kept continuous across stance switches).
    pub previous_length: f32,
    /// Whether the stance leg changed (a footstep).
    pub footstep: bool,
}

/// The stance/swing state machine of §3.3 (BW `updateDerivedStateVars`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StanceTracker {
    stance: Option<Leg>,
    length: f32,
    last_was_footstep: bool,
    footsteps: i32,
    walked: f32,
}

impl Default for StanceTracker {
    fn default() -> Self {
        Self::new()
    }
}

impl StanceTracker {
    /// Unknown stance, no footsteps (episode start).
    pub fn new() -> Self {
        Self {
            stance: None,
            length: 0.0,
            last_was_footstep: false,
            footsteps: 0,
            walked: 0.0,
        }
    }

    /// The current stance leg, `None` before the first update.
    pub fn stance(&self) -> Option<Leg> {
        self.stance
    }

    /// Footstep count: +1 per forward step, −1 per backward step.
    pub fn footsteps(&self) -> i32 {
        self.footsteps
    }

    /// Walked distance: the sum of footstep lengths (m).
    pub fn walked(&self) -> f32 {
        self.walked
    }

    /// One update after a control step. `contact_left/right`: toe or heel
    /// of that foot touches; `ankle_left/right`: [`ankle_x`] of each leg.
    ///
    /// - stance: only left touches → left; only right → right; neither →
    ///   unchanged; both → the front foot (larger ankle x);
    /// - L = x_a(swing) − x_a(stance) with the stance from *before* this
    ///   update (unknown before the first update: L = x_L − x_R);
    /// - a footstep is a stance change with a known previous stance:
    ///   count ±1 by the sign of L, walked distance += L;
    /// - L_prev = old L, negated if the previous update was a footstep.
    pub fn update(
        &mut self,
        contact_left: bool,
        contact_right: bool,
        ankle_left: f32,
        ankle_right: f32,
    ) -> StanceUpdate {
        let previous_length = if self.last_was_footstep {
            -self.length
        } else {
            self.length
        };
        let before = self.stance;
        let after = match (contact_left, contact_right) {
            (true, false) => Some(Leg::Left),
            (false, true) => Some(Leg::Right),
            (false, false) => before,
            (true, true) => Some(if ankle_left >= ankle_right {
                Leg::Left
            } else {
                Leg::Right
            }),
        };
        let x = |leg: Leg| match leg {
            Leg::Left => ankle_left,
            Leg::Right => ankle_right,
        };
        self.length = match before {
            Some(st) => x(st.other()) - x(st),
            None => ankle_left - ankle_right,
        };
        let footstep = before.is_some() && after != before;
        if footstep {
            self.footsteps += if self.length > 0.0 { 1 } else { -1 };
            self.walked += self.length;
        }
        self.last_was_footstep = footstep;
        self.stance = after;
        StanceUpdate {
            length: self.length,
            previous_length,
            footstep,
        }
    }
}

/// Voltages of the auto-actuated joints (§3.5), from the current raw joint
/// angles and the stance leg, clipped to ±10.6919 V: shoulder, stance knee
/// and both ankles, proportional only. Returns (joint, voltage) pairs.
pub fn auto_voltages(angles: &[f32; NUM_JOINTS], stance: Leg) -> [(Joint, f32); 4] {
    let clip = |u: f32| u.clamp(-AUTO_VOLTAGE_LIMIT, AUTO_VOLTAGE_LIMIT);
    let p = |[gain, setpoint]: [f32; 2], q: f32| clip(gain * (setpoint - q));
    let knee = stance.knee();
    [
        (
            Joint::Shoulder,
            p(SHOULDER_GAIN_SETPOINT, angles[Joint::Shoulder as usize]),
        ),
        (knee, p(STANCE_KNEE_GAIN_SETPOINT, angles[knee as usize])),
        (
            Joint::AnkleLeft,
            p(ANKLE_GAIN_SETPOINT, angles[Joint::AnkleLeft as usize]),
        ),
        (
            Joint::AnkleRight,
            p(ANKLE_GAIN_SETPOINT, angles[Joint::AnkleRight as usize]),
        ),
    ]
}

/// The joints the three learned actions drive with this stance leg (§3.4):
/// stance hip, swing hip, swing knee.
pub fn learned_joints(stance: Leg) -> [Joint; ACTION_DIM] {
    [stance.hip(), stance.other().hip(), stance.other().knee()]
}

/// All seven voltages for one control step (§3.6 step 1): the learned
/// voltages (clipped to ±10.7 V; non-finite → 0 V) on the stance hip, swing
/// hip and swing knee, the auto-actuation on the rest.
pub fn joint_voltages(
    action: [f32; ACTION_DIM],
    angles: &[f32; NUM_JOINTS],
    stance: Leg,
) -> [f32; NUM_JOINTS] {
    let mut u = [0.0f32; NUM_JOINTS];
    for (joint, v) in auto_voltages(angles, stance) {
        u[joint as usize] = v;
    }
    for (joint, v) in learned_joints(stance).into_iter().zip(action) {
        u[joint as usize] = sanitize_action(v);
    }
    u
}

/// A learned voltage clipped to ±10.7 V; non-finite → 0 V.
pub fn sanitize_action(v: f32) -> f32 {
    if v.is_finite() {
        v.clamp(-ACTION_VOLTAGE_LIMIT, ACTION_VOLTAGE_LIMIT)
    } else {
        0.0
    }
}

/// Motor work of one control step (§3.7): Σ over both hips and both knees
/// of max(0, U·I)/30 with I = (U − k·G·ω̄)/R, ω̄ the mean of the previous
/// and current filtered rate.
pub fn step_energy(
    voltages: &[f32; NUM_JOINTS],
    filtered_prev: &[f32; NUM_JOINTS],
    filtered_now: &[f32; NUM_JOINTS],
) -> f32 {
    let servo = Rx28::LEO;
    [
        Joint::HipLeft,
        Joint::HipRight,
        Joint::KneeLeft,
        Joint::KneeRight,
    ]
    .iter()
    .map(|&j| {
        let k = j as usize;
        let w = 0.5 * (filtered_prev[k] + filtered_now[k]);
        let u = voltages[k];
        (u * servo.current(u, w)).max(0.0) * CONTROL_PERIOD
    })
    .sum()
}

/// Reward of one step (§3.7): r = −1 − 3·E + 300·(clip(L) − clip(L_prev))
/// − 125·\[fall\], lengths clipped to ±10.2 m.
pub fn reward(energy: f32, update: &StanceUpdate, fall: bool) -> f32 {
    let clip = |l: f32| l.clamp(-FOOTSTEP_MAX_LENGTH, FOOTSTEP_MAX_LENGTH);
    REWARD_TIME
        + REWARD_ENERGY * energy
        + REWARD_FOOTSTEP_DIST * (clip(update.length) - clip(update.previous_length))
        + if fall { REWARD_FALL } else { 0.0 }
}

/// "Doomed to fall" (§3.8): φ outside ±1 rad, or the stance thigh more than
/// 0.36π from vertical (|φ + q_hip,st|).
pub fn is_fall(phi: f32, q_hip_stance: f32) -> bool {
    !(phi.abs() <= FALL_TORSO_ANGLE && (phi + q_hip_stance).abs() <= FALL_STANCE_THIGH_ANGLE)
}

/// The mirrored observation (§3.4) from the torso angle φ and its filtered
/// rate, the raw angles and filtered rates, and the stance leg.
pub fn observe(
    phi: f32,
    phi_rate: f32,
    angles: &[f32; NUM_JOINTS],
    rates: &[f32; NUM_JOINTS],
    stance: Leg,
) -> Observation {
    let sw = stance.other();
    let (hs, hw, ks, kw) = (
        stance.hip() as usize,
        sw.hip() as usize,
        stance.knee() as usize,
        sw.knee() as usize,
    );
    Observation([
        phi, phi_rate, angles[hs], rates[hs], angles[hw], rates[hw], angles[ks], rates[ks],
        angles[kw], rates[kw],
    ])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn filter_coefficients_match_section_3_2() {
        let (b, a1) = RateFilter::joint().coefficients();
        assert!(
            (b - 0.511527).abs() < 1e-5 && (a1 - 0.023055).abs() < 1e-5,
            "{b} {a1}"
        );
        let (b, a1) = RateFilter::torso().coefficients();
        assert!(
            (b - 0.999576).abs() < 1e-5 && (a1 - 0.999152).abs() < 1e-5,
            "{b} {a1}"
        );
        // DC gain 1: a constant input is passed through.
        let mut f = RateFilter::joint();
        let mut y = 0.0;
        for _ in 0..50 {
            y = f.update(2.0);
        }
        assert!((y - 2.0).abs() < 1e-4);
        f.reset();
        assert_eq!(f.value(), 0.0);
    }

    #[test]
    fn stance_logic_follows_section_3_3() {
        let mut s = StanceTracker::new();
        // First update, left on the floor, right foot ahead by 0.02 m:
        // previous stance unknown → L = x_L − x_R.
        let u = s.update(true, false, 0.01, 0.03);
        assert_eq!(s.stance(), Some(Leg::Left));
        assert!((u.length - (-0.02)).abs() < 1e-6 && !u.footstep);
        // Still left stance: L = x_R − x_L.
        let u = s.update(true, false, 0.0, 0.05);
        assert!((u.length - 0.05).abs() < 1e-6 && (u.previous_length + 0.02).abs() < 1e-6);
        // Right touches down ahead: both feet down, right is in front → footstep.
        let u = s.update(true, true, -0.04, 0.06);
        assert!(u.footstep && s.stance() == Some(Leg::Right));
        assert!((u.length - 0.10).abs() < 1e-6);
        assert_eq!(s.footsteps(), 1);
        assert!((s.walked() - 0.10).abs() < 1e-6);
        // Next update: L is measured for the right stance, L_prev is −L.
        let u = s.update(false, true, -0.05, 0.05);
        assert!((u.previous_length + 0.10).abs() < 1e-6);
        assert!((u.length + 0.10).abs() < 1e-6);
        // Neither foot: keep stance.
        s.update(false, false, 0.0, 0.0);
        assert_eq!(s.stance(), Some(Leg::Right));
        // Backward step: left lands behind → footstep −1.
        let u = s.update(true, false, -0.1, 0.0);
        assert!(u.footstep && u.length < 0.0);
        assert_eq!(s.footsteps(), 0);
    }

    #[test]
    fn auto_actuation_and_clipping() {
        let mut q = [0.0f32; NUM_JOINTS];
        q[Joint::Shoulder as usize] = -0.261799;
        q[Joint::KneeRight as usize] = -0.1;
        q[Joint::AnkleLeft as usize] = 0.0649262;
        q[Joint::AnkleRight as usize] = 2.0;
        let u = joint_voltages([20.0, f32::NAN, -3.0], &q, Leg::Right);
        assert!(u[Joint::Shoulder as usize].abs() < 1e-4);
        assert!((u[Joint::KneeRight as usize] - 21.2121 * 0.1).abs() < 1e-3);
        assert!(u[Joint::AnkleLeft as usize].abs() < 1e-4);
        assert!((u[Joint::AnkleRight as usize] + AUTO_VOLTAGE_LIMIT).abs() < 1e-5);
        // Learned: stance hip (right), swing hip (left), swing knee (left).
        assert_eq!(u[Joint::HipRight as usize], ACTION_VOLTAGE_LIMIT);
        assert_eq!(u[Joint::HipLeft as usize], 0.0);
        assert_eq!(u[Joint::KneeLeft as usize], -3.0);
    }

    #[test]
    fn reward_and_fall() {
        let up = StanceUpdate {
            length: 0.05,
            previous_length: 0.03,
            footstep: false,
        };
        assert!((reward(0.1, &up, false) - (-1.0 - 0.3 + 6.0)).abs() < 1e-4);
        assert!((reward(0.0, &up, true) - (-1.0 + 6.0 - 125.0)).abs() < 1e-4);
        assert!(!is_fall(-0.1, 0.1));
        assert!(is_fall(1.01, 0.0));
        assert!(is_fall(-1.01, 0.0));
        assert!(is_fall(0.5, 0.7));
        assert!(is_fall(f32::NAN, 0.0));
    }

    #[test]
    fn energy_counts_only_positive_work_of_hips_and_knees() {
        let mut u = [0.0f32; NUM_JOINTS];
        u[Joint::HipLeft as usize] = 10.0;
        u[Joint::AnkleLeft as usize] = 10.0; // ankles excluded
        let zero = [0.0; NUM_JOINTS];
        let e = step_energy(&u, &zero, &zero);
        assert!((e - 10.0 * 10.0 / 8.6 / 30.0).abs() < 1e-4, "{e}");
        // Regenerative braking is not counted as negative work.
        let mut w = [0.0; NUM_JOINTS];
        w[Joint::HipLeft as usize] = 10.0; // back-EMF 19 V > 10 V: current < 0
        assert_eq!(step_energy(&u, &w, &w), 0.0);
    }

    #[test]
    fn observation_is_mirrored() {
        let q = [0.0, 1.0, 2.0, 3.0, 4.0, 5.0, 6.0];
        let r = q.map(|x| x * 10.0);
        let l = observe(0.5, 0.6, &q, &r, Leg::Left).0;
        assert_eq!(l, [0.5, 0.6, 1.0, 10.0, 2.0, 20.0, 3.0, 30.0, 4.0, 40.0]);
        let rr = observe(0.5, 0.6, &q, &r, Leg::Right).0;
        assert_eq!(rr, [0.5, 0.6, 2.0, 20.0, 1.0, 10.0, 4.0, 40.0, 3.0, 30.0]);
    }
}
