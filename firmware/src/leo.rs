//! LEO on the robot: an adapter from its servos, the boom's encoder and the
//! foot switches to the one definition in `pada_core::robot::leo`, whose
//! rules (rate filter, stance, mirrored observation, reward, falls, held
//! joints) it applies as the simulation does.
//!
//! - Joints in [`Joint`] order (the controller's servo table is in that
//!   order; the servos' IDs are GRL's raw order, see
//!   [`crate::config::hardware`]). Angles from the servos' positions; rates
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

use crate::config::{RobotConfig, MAX_OBS, MAX_ROBOT_SERVOS};
use crate::robot::{RobotAdapter, Sensed};
use core::ops::Range;
use pada_core::robot::filter::RateFilter;
use pada_core::robot::leo::{
    ankle_x, estimated_gear_torque, is_fall, joint_rate_filter, joint_voltages, observe, pose_voltages, reward,
    step_energy, torso_rate_filter, Joint, Leg, StanceTracker, StanceUpdate, NUM_JOINTS, START_JOINT_ANGLES, START_PHI,
};
use pada_core::robot::Robot;

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

/// The next episode waits for |φ − φ_start| below this \[rad\] …
const READY_PHI: f32 = 0.15;
/// … with a foot on the ground, for this long \[µs\].
const READY_TIME_US: u32 = 1_000_000;

const _: () = assert!(NUM_JOINTS == MAX_ROBOT_SERVOS);

/// LEO's adapter.
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

impl Leo {
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

impl RobotAdapter for Leo {
    const ROBOT: Robot = Robot::Leo;

    fn new(_config: &RobotConfig) -> Self {
        let period_us = Self::spec().period_us;
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
        self.energy = step_energy(&s.applied, &self.qd_prev, &self.qd);
        let ankle = |leg: Leg| ankle_x(self.phi, self.q[leg.hip() as usize], self.q[leg.knee() as usize]);
        self.update = self.stance.update(
            s.contacts & contact::LEFT != 0,
            s.contacts & contact::RIGHT != 0,
            ankle(Leg::Left),
            ankle(Leg::Right),
        );
    }

    /// The mirrored observation (§3.4).
    fn observe(&self, obs: &mut [f32; MAX_OBS]) -> usize {
        obs.copy_from_slice(&observe(self.phi, self.phid, &self.q, &self.qd, self.stance()).0);
        MAX_OBS
    }

    fn reward(&self, _applied: &[f32; MAX_ROBOT_SERVOS]) -> f32 {
        reward(self.energy, &self.update, self.absorbing())
    }

    fn absorbing(&self) -> bool {
        is_fall(self.phi, self.q[self.stance().hip() as usize])
    }

    /// The learner's `[U_hip,st, U_hip,sw, U_knee,sw]` on the joints of the
    /// current stance, the held joints by §3.5.
    fn commands(&self, output: &[f32], volts: &mut [f32; MAX_ROBOT_SERVOS]) {
        let mut action = [0.0; 3];
        for (a, o) in action.iter_mut().zip(output) {
            *a = *o;
        }
        *volts = joint_voltages(action, &self.q, self.stance());
    }

    /// Every joint held in the start pose.
    fn reset_commands(&self, volts: &mut [f32; MAX_ROBOT_SERVOS]) {
        *volts = pose_voltages(&self.q, &START_JOINT_ANGLES);
    }

    /// The RX-28 model's torque at each servo's filtered rate.
    fn gear_torques(&self, applied: &[f32; MAX_ROBOT_SERVOS], torques: &mut [f32; MAX_ROBOT_SERVOS]) {
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

    /// Both hips and both knees, which take turns as stance and swing
    /// joints.
    fn reported_joints() -> Range<usize> {
        Joint::HipLeft as usize..Joint::KneeRight as usize + 1
    }

    fn footstep(&self) -> bool {
        self.update.footstep
    }

    fn walked_m(&self) -> Option<f32> {
        Some(self.stance.walked())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::config::hardware;
    use pada_core::robot::leo::{ACTION_VOLTAGE_LIMIT, HELD_VOLTAGE_LIMIT};

    fn leo() -> Leo {
        let mut l = Leo::new(&hardware(Robot::Leo));
        l.start_episode();
        l
    }

    fn sense(l: &mut Leo, angles: [f32; NUM_JOINTS], boom: f32, contacts: u8, applied: [f32; MAX_ROBOT_SERVOS]) {
        l.sense(&Sensed { angles: angles.map(Some), encoder_angle: Some(boom), contacts, applied });
    }

    /// LEO in the start pose of §1.8 (left leg stance).
    fn start_pose(l: &mut Leo, contacts: u8) {
        sense(l, START_JOINT_ANGLES, -START_PHI, contacts, [0.0; MAX_ROBOT_SERVOS]);
    }

    #[test]
    fn start_pose_observation_and_first_reward_artefact() {
        let mut l = leo();
        start_pose(&mut l, contact::LEFT);
        assert_eq!(l.stance(), Leg::Left);
        let mut obs = [0.0; MAX_OBS];
        assert_eq!(l.observe(&mut obs), 10);
        assert!((obs[0] + 0.10).abs() < 1e-6, "φ = −boom");
        assert!((obs[2] - 0.10).abs() < 1e-6, "stance hip = left hip");
        assert!((obs[4] - 0.82).abs() < 1e-6, "swing hip = right hip");
        assert!((obs[8] + 1.27).abs() < 1e-6, "swing knee = right knee");
        assert!(!l.absorbing());
        // The second update: L flips from x_L − x_R to x_R − x_L, the
        // +11.9 artefact of the first transition (§3.7).
        start_pose(&mut l, contact::LEFT);
        let r = l.reward(&[0.0; MAX_ROBOT_SERVOS]);
        assert!((r - 11.9).abs() < 0.5, "{r}");
        // Standing still afterwards: the time penalty only.
        start_pose(&mut l, contact::LEFT);
        assert!((l.reward(&[0.0; MAX_ROBOT_SERVOS]) + 1.0).abs() < 1e-4);
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
        let mut obs = [0.0; MAX_OBS];
        l.observe(&mut obs);
        assert!((obs[2] - 0.82).abs() < 1e-6, "stance hip is now the right hip");
        // L is continuous across the switch: the next reward is the time
        // penalty only.
        start_pose(&mut l, contact::RIGHT);
        assert!((l.reward(&[0.0; MAX_ROBOT_SERVOS]) + 1.0).abs() < 1e-4);
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
        sense(&mut l, START_JOINT_ANGLES, 1.2, contact::LEFT, [0.0; MAX_ROBOT_SERVOS]);
        assert!(l.absorbing());
        assert!(l.reward(&[0.0; MAX_ROBOT_SERVOS]) < -100.0);
    }

    #[test]
    fn learned_and_held_joints_by_stance() {
        let mut l = leo();
        start_pose(&mut l, contact::LEFT);
        let mut v = [0.0; MAX_ROBOT_SERVOS];
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
        sense(&mut l, [3.0; NUM_JOINTS], 0.10, contact::LEFT, [0.0; MAX_ROBOT_SERVOS]);
        l.commands(&[0.0; 3], &mut v);
        assert!((v[Joint::Shoulder as usize] + HELD_VOLTAGE_LIMIT).abs() < 1e-5);
        // Between episodes everything is held at the start pose.
        start_pose(&mut l, contact::LEFT);
        l.reset_commands(&mut v);
        assert!(v.iter().all(|u| u.abs() < 1e-5), "{v:?}");
    }

    #[test]
    fn energy_counts_motor_work_only() {
        let mut l = leo();
        start_pose(&mut l, contact::LEFT);
        start_pose(&mut l, contact::LEFT);
        let mut applied = [0.0; MAX_ROBOT_SERVOS];
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
