//! LEO on the robot: its observation, reward, episode end and the held
//! joints, as GRL's LEO walking task defines them (grl-facts §3), so the
//! learner on the chip sees what the simulation's learner sees.
//!
//! - Joints in GRL's raw order ([`joint`]): shoulder, hip R, hip L, knee R,
//!   knee L, ankle R, ankle L. Angles from the servos' positions (calibrated
//!   in [`crate::config`]); rates are position differences over the period
//!   through GRL's Butterworth filter (§3.2).
//! - Torso pitch φ = −(boom encoder angle) (§3.1), relative to the pose at
//!   boot: **power LEO up with its torso vertical**.
//! - Stance leg from the foot switches, footsteps and the step length L
//!   (§3.3); observation mirrored by stance (§3.4):
//!   `φ, φ̇, q_hip,st, q̇_hip,st, q_hip,sw, q̇_hip,sw, q_knee,st, q̇_knee,st,
//!   q_knee,sw, q̇_knee,sw`.
//! - Reward `−1 − 3·E + 300·(L − L_prev) − 125·[doomed]` (§3.7, the
//!   effective weights), E the electrical energy of hips and knees.
//! - Doomed to fall (absorbing): |φ| > 1 rad or |φ + q_hip,st| > 0.36π (§3.8).
//! - Held joints (§3.5): shoulder to −15°, stance knee to 0, ankles to
//!   3.72°, proportional (GRL has no D term; [`HoldGains`] allows one),
//!   clipped to ±10.6919 V.
//! - Between episodes (after a fall, or the time limit): every joint is held
//!   in the start pose of §1.8 and the next episode starts once the torso
//!   has been near its start pitch with a foot on the ground for 1 s — on
//!   the boom a person sets LEO upright.

use crate::config::{RobotConfig, MAX_OBS, MAX_SERVOS};
use crate::filter::Butterworth1;
use crate::servo::rx28;

/// Joint indices in GRL's raw order (grl-facts §3.1) = the order of
/// [`crate::config::Robot::Leo`]'s servos.
pub mod joint {
    /// Shoulder (arm).
    pub const SHOULDER: usize = 0;
    /// Right hip.
    pub const HIP_R: usize = 1;
    /// Left hip.
    pub const HIP_L: usize = 2;
    /// Right knee.
    pub const KNEE_R: usize = 3;
    /// Left knee.
    pub const KNEE_L: usize = 4;
    /// Right ankle.
    pub const ANKLE_R: usize = 5;
    /// Left ankle.
    pub const ANKLE_L: usize = 6;
}

/// Foot switch bits of [`crate::io::Sensors::contacts`].
pub mod contact {
    /// Right toe.
    pub const TOE_R: u8 = 1 << 0;
    /// Right heel.
    pub const HEEL_R: u8 = 1 << 1;
    /// Left toe.
    pub const TOE_L: u8 = 1 << 2;
    /// Left heel.
    pub const HEEL_L: u8 = 1 << 3;
    /// Right foot.
    pub const RIGHT: u8 = TOE_R | HEEL_R;
    /// Left foot.
    pub const LEFT: u8 = TOE_L | HEEL_L;
}

use joint::*;

/// Which leg stands.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Leg {
    /// Left leg on the ground.
    Left,
    /// Right leg on the ground.
    Right,
}

impl Leg {
    fn hip(self) -> usize {
        match self {
            Leg::Left => HIP_L,
            Leg::Right => HIP_R,
        }
    }
    fn knee(self) -> usize {
        match self {
            Leg::Left => KNEE_L,
            Leg::Right => KNEE_R,
        }
    }
    fn other(self) -> Leg {
        match self {
            Leg::Left => Leg::Right,
            Leg::Right => Leg::Left,
        }
    }
}

/// Upper-leg length \[m\] (grl-facts §1.3).
const UPPER_LEG: f32 = 0.116;
/// Lower-leg length \[m\].
const LOWER_LEG: f32 = 0.1045;
/// Reward weights (§3.7).
const REWARD_TIME: f32 = -1.0;
const REWARD_ENERGY: f32 = -3.0;
const REWARD_PROGRESS: f32 = 300.0;
const REWARD_FALL: f32 = -125.0;
/// Footstep length clip \[m\].
const MAX_STEP: f32 = 10.2;
/// Stance thigh beyond this from vertical is a fall \[rad\] (0.36π).
const THIGH_LIMIT: f32 = 0.36 * core::f32::consts::PI;
/// Torso pitch beyond this is a fall \[rad\].
const TORSO_LIMIT: f32 = 1.0;

/// Set points of the held joints \[rad\] (§3.5).
const SHOULDER_SET: f32 = -0.261_799;
const STANCE_KNEE_SET: f32 = 0.0;
const ANKLE_SET: f32 = 0.064_926_2;

/// The start pose (§1.8) in joint order: the hold between episodes.
const START_POSE: [f32; MAX_SERVOS] = [-0.261_799, 0.82, 0.10, -1.27, 0.0, 0.0, 0.0];
/// Start torso pitch φ (§1.8: torso 0.10 ⇒ φ = −0.10).
const START_PHI: f32 = -0.10;
/// The next episode waits for |φ − φ_start| below this \[rad\] …
const READY_PHI: f32 = 0.15;
/// … with a foot on the ground, for this long \[µs\].
const READY_TIME_US: u32 = 1_000_000;

/// Gains of the held joints \[V/rad\], \[V·s/rad\].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HoldGains {
    /// Shoulder and stance knee: 5 · 14/3.3 (§3.5).
    pub kp_shoulder_knee: f32,
    /// Ankles: 10 · 14/3.3.
    pub kp_ankle: f32,
    /// Damping on every held joint (0 in GRL).
    pub kd: f32,
}

impl Default for HoldGains {
    fn default() -> Self {
        HoldGains { kp_shoulder_knee: 5.0 * 14.0 / 3.3, kp_ankle: 10.0 * 14.0 / 3.3, kd: 0.0 }
    }
}

/// The x position of an ankle relative to the hip \[m\] (§3.3).
fn ankle_x(phi: f32, hip: f32, knee: f32) -> f32 {
    UPPER_LEG * libm::sinf(phi + hip) + LOWER_LEG * libm::sinf(phi + hip + knee)
}

/// LEO's observer and its held joints.
#[derive(Debug, Clone)]
pub struct Leo {
    period_s: f32,
    gains: HoldGains,
    rate_filters: [Butterworth1; MAX_SERVOS],
    torso_filter: Butterworth1,
    q: [f32; MAX_SERVOS],
    q_prev: [Option<f32>; MAX_SERVOS],
    qd: [f32; MAX_SERVOS],
    qd_prev: [f32; MAX_SERVOS],
    boom_prev: Option<f32>,
    phi: f32,
    phid: f32,
    contacts: u8,
    stance: Option<Leg>,
    step_len: f32,
    step_len_prev: f32,
    footstep: bool,
    footsteps: i32,
    energy: f32,
    ready_needed: u32,
    ready_steps: u32,
}

impl Leo {
    /// An observer for LEO's `config`.
    pub fn new(config: &RobotConfig, gains: HoldGains) -> Self {
        Leo {
            period_s: config.period_s(),
            gains,
            rate_filters: [Butterworth1::leo_joint(); MAX_SERVOS],
            torso_filter: Butterworth1::leo_torso(),
            q: [0.0; MAX_SERVOS],
            q_prev: [None; MAX_SERVOS],
            qd: [0.0; MAX_SERVOS],
            qd_prev: [0.0; MAX_SERVOS],
            boom_prev: None,
            phi: 0.0,
            phid: 0.0,
            contacts: 0,
            stance: None,
            step_len: 0.0,
            step_len_prev: 0.0,
            footstep: false,
            footsteps: 0,
            energy: 0.0,
            ready_needed: READY_TIME_US.div_ceil(config.period_us),
            ready_steps: 0,
        }
    }

    /// Episode start: filters cleared, stance unknown, L = 0 (§3.2, §3.3).
    pub fn start_episode(&mut self) {
        for f in &mut self.rate_filters {
            f.reset();
        }
        self.torso_filter.reset();
        self.stance = None;
        self.step_len = 0.0;
        self.step_len_prev = 0.0;
        self.footstep = false;
        self.footsteps = 0;
    }

    /// Takes this period's readings: joint angles (`None` for a servo that
    /// did not answer: its last angle is kept), the boom encoder's angle,
    /// the foot switches, and the voltages applied during the last period
    /// (for the energy term). Updates rates, stance, step length.
    pub fn sense(
        &mut self,
        angles: &[Option<f32>; MAX_SERVOS],
        boom_angle: Option<f32>,
        contacts: u8,
        applied: &[f32; MAX_SERVOS],
    ) {
        let dt = self.period_s;
        self.qd_prev = self.qd;
        for i in 0..MAX_SERVOS {
            if let Some(a) = angles[i] {
                self.q[i] = a;
            }
            let raw = match self.q_prev[i] {
                Some(prev) => (self.q[i] - prev) / dt,
                None => 0.0,
            };
            self.q_prev[i] = Some(self.q[i]);
            self.qd[i] = self.rate_filters[i].step(raw);
        }
        if let Some(boom) = boom_angle {
            let raw = match self.boom_prev {
                Some(prev) => (boom - prev) / dt,
                None => 0.0,
            };
            self.boom_prev = Some(boom);
            self.phi = -boom;
            self.phid = -self.torso_filter.step(raw);
        }
        self.contacts = contacts;

        // Electrical energy of hips and knees during the last period (§3.7).
        let gk = rx28::GEAR_RATIO * rx28::TORQUE_CONSTANT;
        self.energy = [HIP_L, HIP_R, KNEE_L, KNEE_R]
            .iter()
            .map(|&j| {
                let u = applied[j];
                let w = 0.5 * (self.qd_prev[j] + self.qd[j]);
                let current = (u - gk * w) / rx28::RESISTANCE;
                (u * current).max(0.0) * dt
            })
            .sum();

        // Step length with the stance from before this update (§3.3).
        let old = self.step_len;
        self.step_len_prev = if self.footstep { -old } else { old };
        let xl = ankle_x(self.phi, self.q[HIP_L], self.q[KNEE_L]);
        let xr = ankle_x(self.phi, self.q[HIP_R], self.q[KNEE_R]);
        self.step_len = match self.stance {
            Some(Leg::Left) => xr - xl,
            Some(Leg::Right) | None => xl - xr,
        };
        let left = contacts & contact::LEFT != 0;
        let right = contacts & contact::RIGHT != 0;
        let new = match (left, right) {
            (true, false) => Some(Leg::Left),
            (false, true) => Some(Leg::Right),
            (false, false) => self.stance,
            // Both down: the front foot stands.
            (true, true) => Some(if xl >= xr { Leg::Left } else { Leg::Right }),
        };
        self.footstep = matches!((self.stance, new), (Some(a), Some(b)) if a != b);
        if self.footstep {
            self.footsteps += if self.step_len > 0.0 { 1 } else { -1 };
        }
        self.stance = new;
    }

    /// The stance leg (left until the feet say otherwise).
    pub fn stance(&self) -> Leg {
        self.stance.unwrap_or(Leg::Left)
    }

    /// Torso pitch φ \[rad\].
    pub fn phi(&self) -> f32 {
        self.phi
    }

    /// Joint angles \[rad\] in joint order.
    pub fn angles(&self) -> &[f32; MAX_SERVOS] {
        &self.q
    }

    /// Footsteps this episode (forward minus backward).
    pub fn footsteps(&self) -> i32 {
        self.footsteps
    }

    /// The mirrored observation (§3.4); returns its length (10).
    pub fn observe(&self, obs: &mut [f32; MAX_OBS]) -> usize {
        let st = self.stance();
        let sw = st.other();
        let values = [
            self.phi,
            self.phid,
            self.q[st.hip()],
            self.qd[st.hip()],
            self.q[sw.hip()],
            self.qd[sw.hip()],
            self.q[st.knee()],
            self.qd[st.knee()],
            self.q[sw.knee()],
            self.qd[sw.knee()],
        ];
        obs.copy_from_slice(&values);
        MAX_OBS
    }

    /// Whether LEO is falling (absorbing, §3.8).
    pub fn doomed(&self) -> bool {
        let hip = self.q[self.stance().hip()];
        self.phi.abs() > TORSO_LIMIT || (self.phi + hip).abs() > THIGH_LIMIT
    }

    /// Reward of the transition into the current state (§3.7).
    pub fn reward(&self) -> f32 {
        let clip = |l: f32| l.clamp(-MAX_STEP, MAX_STEP);
        let mut r = REWARD_TIME
            + REWARD_ENERGY * self.energy
            + REWARD_PROGRESS * (clip(self.step_len) - clip(self.step_len_prev));
        if self.doomed() {
            r += REWARD_FALL;
        }
        r
    }

    fn hold(&self, j: usize, set: f32, kp: f32) -> f32 {
        let u = kp * (set - self.q[j]) - self.gains.kd * self.qd[j];
        u.clamp(-rx28::MAX_HOLD_VOLTAGE, rx28::MAX_HOLD_VOLTAGE)
    }

    /// Per-servo voltages: the learner's `[U_hip,st, U_hip,sw, U_knee,sw]`
    /// on the joints of the current stance, the held joints by §3.5.
    pub fn commands(&self, output: &[f32], volts: &mut [f32; MAX_SERVOS]) {
        let st = self.stance();
        let sw = st.other();
        let g = self.gains;
        volts[SHOULDER] = self.hold(SHOULDER, SHOULDER_SET, g.kp_shoulder_knee);
        volts[st.knee()] = self.hold(st.knee(), STANCE_KNEE_SET, g.kp_shoulder_knee);
        volts[ANKLE_R] = self.hold(ANKLE_R, ANKLE_SET, g.kp_ankle);
        volts[ANKLE_L] = self.hold(ANKLE_L, ANKLE_SET, g.kp_ankle);
        volts[st.hip()] = output[0];
        volts[sw.hip()] = output[1];
        volts[sw.knee()] = output[2];
    }

    /// Per-servo voltages between episodes: every joint held in the start
    /// pose.
    pub fn reset_commands(&self, volts: &mut [f32; MAX_SERVOS]) {
        let g = self.gains;
        for j in 0..MAX_SERVOS {
            let kp = if j == ANKLE_L || j == ANKLE_R { g.kp_ankle } else { g.kp_shoulder_knee };
            volts[j] = self.hold(j, START_POSE[j], kp);
        }
    }

    /// Joint speeds \[rad/s\] for the torque estimate (filtered rates).
    pub fn servo_speeds(&self, speeds: &mut [f32; MAX_SERVOS]) {
        *speeds = self.qd;
    }

    /// Starts waiting for LEO to be set upright.
    pub fn begin_reset(&mut self) {
        self.ready_steps = 0;
    }

    /// One period of waiting; true once the next episode may start.
    pub fn reset_done(&mut self) -> bool {
        if (self.phi - START_PHI).abs() < READY_PHI && self.contacts != 0 {
            self.ready_steps += 1;
        } else {
            self.ready_steps = 0;
        }
        self.ready_steps >= self.ready_needed
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::config::Robot;

    /// LEO in the start pose of §1.8 (left leg stance).
    fn start_pose(leo: &mut Leo, contacts: u8) {
        let angles = START_POSE.map(Some);
        leo.sense(&angles, Some(0.10), contacts, &[0.0; MAX_SERVOS]);
    }

    #[test]
    fn start_pose_observation_and_first_reward_artefact() {
        let mut leo = Leo::new(&Robot::Leo.config(), HoldGains::default());
        leo.start_episode();
        start_pose(&mut leo, contact::LEFT);
        assert_eq!(leo.stance(), Leg::Left);
        let mut obs = [0.0; MAX_OBS];
        assert_eq!(leo.observe(&mut obs), 10);
        assert!((obs[0] + 0.10).abs() < 1e-6, "φ = −boom");
        assert!((obs[2] - 0.10).abs() < 1e-6, "stance hip = left hip");
        assert!((obs[4] - 0.82).abs() < 1e-6, "swing hip = right hip");
        assert!((obs[8] + 1.27).abs() < 1e-6, "swing knee = right knee");
        assert!(!leo.doomed());
        // The second update: L flips from x_L − x_R to x_R − x_L, the
        // +11.9 artefact of the first transition (§3.7).
        start_pose(&mut leo, contact::LEFT);
        let r = leo.reward();
        assert!((r - 11.9).abs() < 0.5, "{r}");
        // Standing still afterwards: the time penalty only.
        start_pose(&mut leo, contact::LEFT);
        assert!((leo.reward() + 1.0).abs() < 1e-4, "{}", leo.reward());
    }

    #[test]
    fn stance_switch_mirrors_the_observation_and_counts_a_footstep() {
        let mut leo = Leo::new(&Robot::Leo.config(), HoldGains::default());
        leo.start_episode();
        start_pose(&mut leo, contact::LEFT);
        start_pose(&mut leo, contact::LEFT);
        // Right foot (ahead) lands, left lifts.
        start_pose(&mut leo, contact::RIGHT);
        assert_eq!(leo.stance(), Leg::Right);
        assert_eq!(leo.footsteps(), 1);
        let mut obs = [0.0; MAX_OBS];
        leo.observe(&mut obs);
        assert!((obs[2] - 0.82).abs() < 1e-6, "stance hip is now the right hip");
        // L is continuous across the switch: the next reward is the time
        // penalty only.
        start_pose(&mut leo, contact::RIGHT);
        assert!((leo.reward() + 1.0).abs() < 1e-4, "{}", leo.reward());
        // Both feet down: the front foot stands (the right ankle is ahead).
        start_pose(&mut leo, contact::LEFT | contact::RIGHT);
        assert_eq!(leo.stance(), Leg::Right);
    }

    #[test]
    fn falling_is_absorbing_with_the_penalty() {
        let mut leo = Leo::new(&Robot::Leo.config(), HoldGains::default());
        leo.start_episode();
        let angles = START_POSE.map(Some);
        leo.sense(&angles, Some(0.10), contact::LEFT, &[0.0; MAX_SERVOS]);
        leo.sense(&angles, Some(0.10), contact::LEFT, &[0.0; MAX_SERVOS]);
        assert!(!leo.doomed());
        leo.sense(&angles, Some(1.2), contact::LEFT, &[0.0; MAX_SERVOS]);
        assert!(leo.doomed());
        assert!(leo.reward() < -100.0);
    }

    #[test]
    fn learned_and_held_joints_by_stance() {
        let mut leo = Leo::new(&Robot::Leo.config(), HoldGains::default());
        leo.start_episode();
        start_pose(&mut leo, contact::LEFT);
        let mut v = [0.0; MAX_SERVOS];
        leo.commands(&[1.0, 2.0, 3.0], &mut v);
        assert_eq!((v[HIP_L], v[HIP_R], v[KNEE_R]), (1.0, 2.0, 3.0));
        // Stance knee (left) at its set point 0: no voltage; ankles at 0 →
        // 42.42 · 0.0649 V; shoulder at its set point.
        assert!(v[KNEE_L].abs() < 1e-6);
        assert!((v[ANKLE_L] - 42.4242 * 0.064_926_2).abs() < 1e-3);
        assert!(v[SHOULDER].abs() < 1e-5);
        // Clipped at 10.69 V.
        let far = [Some(3.0); MAX_SERVOS];
        leo.sense(&far, Some(0.10), contact::LEFT, &[0.0; MAX_SERVOS]);
        leo.commands(&[0.0; 3], &mut v);
        assert!((v[SHOULDER] + rx28::MAX_HOLD_VOLTAGE).abs() < 1e-5);
    }

    #[test]
    fn energy_counts_motor_work_only() {
        let mut leo = Leo::new(&Robot::Leo.config(), HoldGains::default());
        leo.start_episode();
        start_pose(&mut leo, contact::LEFT);
        start_pose(&mut leo, contact::LEFT);
        let mut applied = [0.0; MAX_SERVOS];
        applied[HIP_L] = 10.0;
        let angles = START_POSE.map(Some);
        leo.sense(&angles, Some(0.10), contact::LEFT, &applied);
        // At stall: U²/R · dt = 100/8.6/30 J; reward −1 − 3E.
        let e = 100.0 / 8.6 / 30.0;
        assert!((leo.reward() - (-1.0 - 3.0 * e)).abs() < 1e-3, "{}", leo.reward());
    }

    #[test]
    fn reset_waits_for_an_upright_torso_on_a_foot() {
        let mut leo = Leo::new(&Robot::Leo.config(), HoldGains::default());
        leo.begin_reset();
        for _ in 0..40 {
            start_pose(&mut leo, 0);
            assert!(!leo.reset_done(), "no foot down");
        }
        let mut n = 0;
        loop {
            start_pose(&mut leo, contact::LEFT);
            n += 1;
            if leo.reset_done() {
                break;
            }
        }
        assert_eq!(n, 31);
    }
}
