//! LEO's rules ([`RobotRules`]): from its servos, the boom's encoder and
//! the foot switches to the definition in [`super`] (rate filter, stance,
//! mirrored observation, reward, falls, held joints), as the simulation
//! applies them.
//!
//! - Joints in [`super::Joint`] order (the controller's servo table is in that
//!   order; the servos' IDs are GRL's raw order, see
//!   [`super::JOINT_SPECS`]). Angles from the servos' positions; rates
//!   are position differences over the period through GRL's Butterworth
//!   filter (§3.2).
//! - Torso angle φ = −(boom encoder angle) (§3.1), relative to the pose at
//!   boot: **power LEO up with its torso vertical**.
//! - Between episodes (after a fall, or the time limit) every joint is held
//!   in the start pose of §1.8, and the next episode starts once the torso
//!   has been near its start angle with a foot on the ground for 1 s: on
//!   the boom a person sets LEO upright. (The host's simulation does the
//!   same: it puts the robot back in the start pose and holds it there until
//!   the firmware starts the episode.)

use super::{
    ankle_x, contact, estimated_gear_torque, is_fall, joint_rate_filter, joint_voltages, observe, pose_voltages, reward,
    step_energy, torso_rate_filter, Leg, StanceTracker, StanceUpdate, NUM_JOINTS, OBS_DIM, SPEC,
    START_JOINT_ANGLES, START_PHI,
};
use crate::limits::{MAX_SERVOS, MAX_STATE_DIMS};
use crate::robot::filter::RateFilter;
use crate::robot::{PerServo, RobotRules, RobotSpec, Sensed};

/// The next episode waits for |φ − φ_start| below this \[rad\] …
const READY_PHI: f32 = 0.15;
/// … with a foot on the ground, for this long \[µs\].
const READY_TIME_US: u32 = 1_000_000;

const _: () = assert!(NUM_JOINTS <= MAX_SERVOS && OBS_DIM <= MAX_STATE_DIMS);

/// LEO's rules.
#[derive(Debug, Clone)]
pub struct Leo {
    period_s: f32,
    rate_filters: [RateFilter; NUM_JOINTS],
    torso_filter: RateFilter,
    q: [f32; NUM_JOINTS],
    q_prev: [Option<f32>; NUM_JOINTS],
    qd: [f32; NUM_JOINTS],
    qd_prev: [f32; NUM_JOINTS],
    boom_prev: Option<f32>,
    phi: f32,
    phid: f32,
    contacts: u8,
    stance: StanceTracker,
    update: StanceUpdate,
    energy: f32,
    ready_needed: u32,
    ready_steps: u32,
}

impl Default for Leo {
    fn default() -> Self {
        Self::new()
    }
}

impl Leo {
    /// LEO before its first reading.
    pub fn new() -> Self {
        let period_us = SPEC.period_us;
        Leo {
            period_s: period_us as f32 * 1e-6,
            rate_filters: [joint_rate_filter(); NUM_JOINTS],
            torso_filter: torso_rate_filter(),
            q: [0.0; NUM_JOINTS],
            q_prev: [None; NUM_JOINTS],
            qd: [0.0; NUM_JOINTS],
            qd_prev: [0.0; NUM_JOINTS],
            boom_prev: None,
            phi: 0.0,
            phid: 0.0,
            contacts: 0,
            stance: StanceTracker::new(),
            update: StanceUpdate { length: 0.0, previous_length: 0.0, footstep: false },
            energy: 0.0,
            ready_needed: READY_TIME_US.div_ceil(period_us),
            ready_steps: 0,
        }
    }

    /// The stance leg (left until the feet say otherwise).
    pub fn stance(&self) -> Leg {
        self.stance.stance_or_left()
    }

    /// Torso angle φ \[rad\].
    pub fn phi(&self) -> f32 {
        self.phi
    }

    /// Joint angles \[rad\] in joint order.
    pub fn angles(&self) -> &[f32; NUM_JOINTS] {
        &self.q
    }

    /// Footsteps this episode (forward minus backward).
    pub fn footsteps(&self) -> i32 {
        self.stance.footsteps()
    }
}

impl RobotRules for Leo {
    fn spec(&self) -> &'static RobotSpec {
        &SPEC
    }

    /// Filters cleared, stance unknown, L = 0 (§3.2, §3.3).
    fn start_episode(&mut self) {
        for f in &mut self.rate_filters {
            f.reset();
        }
        self.torso_filter.reset();
        self.qd = [0.0; NUM_JOINTS];
        self.stance = StanceTracker::new();
    }

    /// Joint angles (a servo that did not answer keeps its last angle), the
    /// boom's angle, the foot switches and the voltages of the last period
    /// (for the energy term): rates, stance, step length, energy.
    fn sense(&mut self, s: &Sensed) {
        let dt = self.period_s;
        self.qd_prev = self.qd;
        for i in 0..NUM_JOINTS {
            if let Some(a) = s.angles[i] {
                self.q[i] = a;
            }
            let raw = match self.q_prev[i] {
                Some(prev) => (self.q[i] - prev) / dt,
                None => 0.0,
            };
            self.q_prev[i] = Some(self.q[i]);
            self.qd[i] = self.rate_filters[i].update(raw);
        }
        if let Some(boom) = s.encoder_angle {
            let raw = match self.boom_prev {
                Some(prev) => (boom - prev) / dt,
                None => 0.0,
            };
            self.boom_prev = Some(boom);
            self.phi = -boom;
            self.phid = -self.torso_filter.update(raw);
        }
        self.contacts = s.contacts;
        self.energy = step_energy(&joints_of(&s.applied), &self.qd_prev, &self.qd);
        let ankle = |leg: Leg| ankle_x(self.phi, self.q[leg.hip() as usize], self.q[leg.knee() as usize]);
        self.update = self.stance.update(
            s.contacts & contact::LEFT != 0,
            s.contacts & contact::RIGHT != 0,
            ankle(Leg::Left),
            ankle(Leg::Right),
        );
    }

    /// The mirrored observation (§3.4).
    fn observe(&self, obs: &mut [f32; MAX_STATE_DIMS]) -> usize {
        obs[..OBS_DIM].copy_from_slice(&observe(self.phi, self.phid, &self.q, &self.qd, self.stance()).0);
        OBS_DIM
    }

    fn reward(&self, _applied: &PerServo) -> f32 {
        reward(self.energy, &self.update, self.absorbing())
    }

    fn absorbing(&self) -> bool {
        is_fall(self.phi, self.q[self.stance().hip() as usize])
    }

    /// The learner's `[U_hip,st, U_hip,sw, U_knee,sw]` on the joints of the
    /// current stance, the held joints by §3.5.
    fn commands(&self, output: &[f32], volts: &mut PerServo) {
        let mut action = [0.0; 3];
        for (a, o) in action.iter_mut().zip(output) {
            *a = *o;
        }
        *volts = per_servo(joint_voltages(action, &self.q, self.stance()));
    }

    /// Every joint held in the start pose.
    fn reset_commands(&self, volts: &mut PerServo) {
        *volts = per_servo(pose_voltages(&self.q, &START_JOINT_ANGLES));
    }

    /// The RX-28 model's torque at each servo's filtered rate.
    fn gear_torques(&self, applied: &PerServo, torques: &mut PerServo) {
        *torques = [0.0; MAX_SERVOS];
        for j in 0..NUM_JOINTS {
            torques[j] = estimated_gear_torque(applied[j], self.qd[j]);
        }
    }

    fn begin_reset(&mut self) {
        self.ready_steps = 0;
    }

    fn reset_done(&mut self) -> bool {
        if (self.phi - START_PHI).abs() < READY_PHI && self.contacts != 0 {
            self.ready_steps += 1;
        } else {
            self.ready_steps = 0;
        }
        self.ready_steps >= self.ready_needed
    }

    fn footstep(&self) -> bool {
        self.update.footstep
    }

    fn walked_m(&self) -> Option<f32> {
        Some(self.stance.walked())
    }
}

/// LEO's seven joints of a per-servo array.
fn joints_of(values: &PerServo) -> [f32; NUM_JOINTS] {
    let mut out = [0.0; NUM_JOINTS];
    out.copy_from_slice(&values[..NUM_JOINTS]);
    out
}

/// A per-servo array of LEO's seven joints (the rest 0).
fn per_servo(values: [f32; NUM_JOINTS]) -> PerServo {
    let mut out = [0.0; MAX_SERVOS];
    out[..NUM_JOINTS].copy_from_slice(&values);
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::robot::leo::{Joint, ACTION_VOLTAGE_LIMIT, HELD_VOLTAGE_LIMIT};

    fn leo() -> Leo {
        let mut l = Leo::new();
        l.start_episode();
        l
    }

    fn sense(l: &mut Leo, angles: [f32; NUM_JOINTS], boom: f32, contacts: u8, applied: [f32; MAX_SERVOS]) {
        let mut sensed = [None; MAX_SERVOS];
        for (s, a) in sensed.iter_mut().zip(angles) {
            *s = Some(a);
        }
        l.sense(&Sensed { angles: sensed, encoder_angle: Some(boom), contacts, applied });
    }

    /// LEO in the start pose of §1.8 (left leg stance).
    fn start_pose(l: &mut Leo, contacts: u8) {
        sense(l, START_JOINT_ANGLES, -START_PHI, contacts, [0.0; MAX_SERVOS]);
    }

    #[test]
    fn start_pose_observation_and_first_reward_artefact() {
        let mut l = leo();
        start_pose(&mut l, contact::LEFT);
        assert_eq!(l.stance(), Leg::Left);
        let mut obs = [0.0; MAX_STATE_DIMS];
        assert_eq!(l.observe(&mut obs), OBS_DIM);
        assert!((obs[0] + 0.10).abs() < 1e-6, "φ = −boom");
        assert!((obs[2] - 0.10).abs() < 1e-6, "stance hip = left hip");
        assert!((obs[4] - 0.82).abs() < 1e-6, "swing hip = right hip");
        assert!((obs[8] + 1.27).abs() < 1e-6, "swing knee = right knee");
        assert!(!l.absorbing());
        // The second update: L flips from x_L − x_R to x_R − x_L, the
        // +11.9 artefact of the first transition (§3.7).
        start_pose(&mut l, contact::LEFT);
        let r = l.reward(&[0.0; MAX_SERVOS]);
        assert!((r - 11.9).abs() < 0.5, "{r}");
        // Standing still afterwards: the time penalty only.
        start_pose(&mut l, contact::LEFT);
        assert!((l.reward(&[0.0; MAX_SERVOS]) + 1.0).abs() < 1e-4);
    }

    #[test]
    fn stance_switch_mirrors_the_observation_and_counts_a_footstep() {
        let mut l = leo();
        start_pose(&mut l, contact::LEFT);
        start_pose(&mut l, contact::LEFT);
        // Right foot (ahead) lands, left lifts.
        start_pose(&mut l, contact::RIGHT);
        assert_eq!(l.stance(), Leg::Right);
        assert_eq!(l.footsteps(), 1);
        assert!(l.walked_m().unwrap() > 0.0);
        let mut obs = [0.0; MAX_STATE_DIMS];
        l.observe(&mut obs);
        assert!((obs[2] - 0.82).abs() < 1e-6, "stance hip is now the right hip");
        // L is continuous across the switch: the next reward is the time
        // penalty only.
        start_pose(&mut l, contact::RIGHT);
        assert!((l.reward(&[0.0; MAX_SERVOS]) + 1.0).abs() < 1e-4);
        // Both feet down: the front foot stands (the right ankle is ahead).
        start_pose(&mut l, contact::LEFT | contact::RIGHT);
        assert_eq!(l.stance(), Leg::Right);
    }

    #[test]
    fn falling_is_absorbing_with_the_penalty() {
        let mut l = leo();
        start_pose(&mut l, contact::LEFT);
        start_pose(&mut l, contact::LEFT);
        assert!(!l.absorbing());
        sense(&mut l, START_JOINT_ANGLES, 1.2, contact::LEFT, [0.0; MAX_SERVOS]);
        assert!(l.absorbing());
        assert!(l.reward(&[0.0; MAX_SERVOS]) < -100.0);
    }

    #[test]
    fn learned_and_held_joints_by_stance() {
        let mut l = leo();
        start_pose(&mut l, contact::LEFT);
        let mut v = [0.0; MAX_SERVOS];
        l.commands(&[1.0, 2.0, 3.0], &mut v);
        let (hl, hr, kr, kl) =
            (Joint::HipLeft as usize, Joint::HipRight as usize, Joint::KneeRight as usize, Joint::KneeLeft as usize);
        assert_eq!((v[hl], v[hr], v[kr]), (1.0, 2.0, 3.0));
        // Stance knee (left) at its set point 0: no voltage; ankles at 0 →
        // 42.42 · 0.0649 V; shoulder at its set point.
        assert!(v[kl].abs() < 1e-6);
        assert!((v[Joint::AnkleLeft as usize] - 42.4242 * 0.064_926_2).abs() < 1e-3);
        assert!(v[Joint::Shoulder as usize].abs() < 1e-5);
        // Learned voltages are clipped to ±10.7 V, held ones to 10.69 V.
        l.commands(&[50.0, 0.0, 0.0], &mut v);
        assert_eq!(v[hl], ACTION_VOLTAGE_LIMIT);
        sense(&mut l, [3.0; NUM_JOINTS], 0.10, contact::LEFT, [0.0; MAX_SERVOS]);
        l.commands(&[0.0; 3], &mut v);
        assert!((v[Joint::Shoulder as usize] + HELD_VOLTAGE_LIMIT).abs() < 1e-5);
        // Between episodes everything is held at the start pose.
        start_pose(&mut l, contact::LEFT);
        l.reset_commands(&mut v);
        assert!(v.iter().all(|u| u.abs() < 1e-5), "{v:?}");
        assert_eq!(v[NUM_JOINTS..], [0.0; MAX_SERVOS - NUM_JOINTS], "no servo past LEO's seven");
    }

    #[test]
    fn energy_counts_motor_work_only() {
        let mut l = leo();
        start_pose(&mut l, contact::LEFT);
        start_pose(&mut l, contact::LEFT);
        let mut applied = [0.0; MAX_SERVOS];
        applied[Joint::HipLeft as usize] = 10.0;
        sense(&mut l, START_JOINT_ANGLES, -START_PHI, contact::LEFT, applied);
        // At stall: U²/R · T; reward −1 − 3E.
        let e = 100.0 / 8.6 * 0.033_333;
        let r = l.reward(&applied);
        assert!((r - (-1.0 - 3.0 * e)).abs() < 1e-3, "{r}");
    }

    #[test]
    fn reset_waits_for_an_upright_torso_on_a_foot() {
        let mut l = leo();
        l.begin_reset();
        for _ in 0..40 {
            start_pose(&mut l, 0);
            assert!(!l.reset_done(), "no foot down");
        }
        let mut n = 0;
        loop {
            start_pose(&mut l, contact::LEFT);
            n += 1;
            if l.reset_done() {
                break;
            }
        }
        assert_eq!(n, 31);
    }
}
