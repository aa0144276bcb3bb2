//! A robot simulated in whole control periods behind its servos, with an
//! operator who holds it between episodes: LEO's rig and a robot of
//! files' rig, one [`Rig`] ([`Periodic`]) over each one's physics
//! ([`PeriodBody`]).
//!
//! The physics advances in whole control periods on the boundaries
//! `k · T`: a reading at any instant of period k is the state at `k · T`,
//! and the voltages in force at `(k + 1) · T` drive the step from `k · T`
//! to `(k + 1) · T` (a zero-order hold of the last command). Torque off is
//! 0 V. The robot is held from boot, and from the end of an episode until
//! the firmware starts the next one.

use super::{joint_volts, servo_reading, JointState, Rig, TEMPERATURE_C};
use pada_core::dynamixel::table::PresentState;
use pada_core::limits::MAX_SERVOS;
use pada_core::robot::RobotSpec;

/// The physics behind a [`Periodic`] rig, joints in the hardware
/// definition's order.
pub trait PeriodBody: Send {
    /// The hardware definition: the servos' IDs, calibration and supply.
    fn hw(&self) -> &'static RobotSpec;

    /// One control period with `volts` on the joints (0 V where torque is
    /// off); `false` where the simulation broke, and the body was put back
    /// as by the operator (the firmware sees the jump).
    fn step_period(&mut self, volts: &[f32]) -> bool;

    /// Joint `k` as its servo senses it now.
    fn sensed(&self, k: usize) -> JointState;

    /// The robot's other sensors now: an encoder's count and the foot
    /// contacts ([`Rig::sensors`]).
    fn sensors(&self) -> (u16, u8) {
        (0, 0)
    }

    /// The operator puts the robot back in its start pose.
    fn put_back(&mut self);

    /// The operator lets go.
    fn let_go(&mut self) {}

    /// The mean torque on joint `k`'s gearbox over the last period \[N·m\].
    fn gear_torque(&self, k: usize) -> f32;

    /// Distance walked since the operator let go \[m\] (a walking robot).
    fn walked_m(&self) -> Option<f64> {
        None
    }

    /// A one-line description for reports.
    fn describe(&self) -> String;
}

/// The rig of a [`PeriodBody`]: its servos' drive, its clock and the
/// operator.
pub struct Periodic<B> {
    pub(crate) body: B,
    /// Servo ID of each joint.
    pub(crate) ids: Vec<u8>,
    period_us: u64,
    /// Voltage and torque enable per joint.
    volts: [f32; MAX_SERVOS],
    torque: [bool; MAX_SERVOS],
    /// The next period boundary \[µs\].
    pub(crate) next_step_us: u64,
    /// Whether the operator holds the robot still.
    held: bool,
    /// Simulated periods, and those that blew up.
    periods: u64,
    blow_ups: u64,
}

impl<B: PeriodBody> Periodic<B> {
    /// `body` at rest at time 0, torque off, held, stepped every
    /// `period_us`.
    pub(crate) fn of_body(body: B, period_us: u64) -> Periodic<B> {
        Periodic {
            ids: body.hw().joints.iter().map(|j| j.id).collect(),
            body,
            period_us,
            volts: [0.0; MAX_SERVOS],
            torque: [false; MAX_SERVOS],
            next_step_us: period_us,
            held: true,
            periods: 0,
            blow_ups: 0,
        }
    }

    /// Control periods simulated, and how many of them blew up.
    pub fn periods(&self) -> (u64, u64) {
        (self.periods, self.blow_ups)
    }

    fn joint_of(&self, id: u8) -> Option<usize> {
        self.ids.iter().position(|&i| i == id)
    }

    /// One control period with the voltages in force.
    fn step(&mut self) {
        let mut u = self.volts;
        for (v, on) in u.iter_mut().zip(self.torque) {
            if !on {
                *v = 0.0;
            }
        }
        self.periods += 1;
        if !self.body.step_period(&u[..self.ids.len()]) {
            self.blow_ups += 1;
        }
    }

    /// Servo `k`'s reading now.
    fn reading(&self, k: usize) -> PresentState {
        let s = self.body.sensed(k);
        servo_reading(&self.body.hw().joints[k], s.angle, s.rate, s.load, self.supply_v())
    }

    /// Whether the state at `t_us` is the state now: no period boundary
    /// to simulate before it (or the operator holds the robot still).
    fn settled_until(&self, t_us: u64) -> bool {
        self.held || t_us < self.next_step_us
    }
}

impl<B: PeriodBody> Rig for Periodic<B> {
    fn servo_ids(&self) -> &[u8] {
        &self.ids
    }

    /// The hardware definition's nominal supply.
    fn supply_v(&self) -> f64 {
        self.body.hw().supply_nominal_v as f64
    }

    fn advance_to(&mut self, t_us: u64) {
        while self.next_step_us <= t_us {
            if !self.held {
                self.step();
            }
            self.next_step_us += self.period_us;
        }
    }

    fn drive(&mut self, t_us: u64, id: u8, torque: bool, volts: f64) {
        self.advance_to(t_us);
        if let Some(k) = self.joint_of(id) {
            self.torque[k] = torque;
            self.volts[k] = joint_volts(&self.body.hw().joints[k], volts) as f32;
        }
    }

    fn present(&mut self, t_us: u64, id: u8) -> PresentState {
        self.advance_to(t_us);
        match self.joint_of(id) {
            Some(k) => self.reading(k),
            None => PresentState { position: 0, speed: 0, load: 0, voltage: 0, temperature: TEMPERATURE_C },
        }
    }

    fn joint_state(&mut self, t_us: u64, id: u8) -> JointState {
        self.advance_to(t_us);
        self.joint_of(id).map_or_else(JointState::default, |k| self.body.sensed(k))
    }

    fn sensors(&mut self, t_us: u64) -> (u16, u8) {
        self.advance_to(t_us);
        self.body.sensors()
    }

    fn peek_present(&self, t_us: u64, id: u8) -> Option<PresentState> {
        let k = self.joint_of(id)?;
        self.settled_until(t_us).then(|| self.reading(k))
    }

    fn peek_sensors(&self, t_us: u64) -> Option<(u16, u8)> {
        self.settled_until(t_us).then(|| self.body.sensors())
    }

    fn walked_m(&self) -> Option<f64> {
        self.body.walked_m()
    }

    fn describe(&self) -> String {
        self.body.describe()
    }

    fn episode_ended(&mut self, _t_us: u64) {
        self.body.put_back();
        self.held = true;
    }

    /// From the next period boundary on, the robot moves.
    fn episode_started(&mut self, _t_us: u64) {
        self.held = false;
        self.body.let_go();
    }

    fn gear_torque(&self, id: u8) -> f32 {
        self.joint_of(id).map_or(0.0, |k| self.body.gear_torque(k))
    }
}
