//! A robot of files behind a board's servos (`pada run --board`,
//! `pada sil`): the body simulated in whole control periods, as LEO's rig
//! is, read through each servo's calibration, and an operator who puts the
//! robot back in its start pose when an episode ends and holds it there
//! until the next one starts.

use super::body::{UrdfBody, UrdfModel};
use crate::rig::{joint_volts, servo_reading, JointState, Rig};
use pada_core::dynamixel::table::PresentState;
use pada_core::limits::MAX_SERVOS;
use pada_core::robot::RobotSpec;
use pada_robot_file::RobotFile;

/// The rig of a robot of files.
pub struct UrdfRig {
    body: UrdfBody,
    model: UrdfModel,
    hw: &'static RobotSpec,
    ids: Vec<u8>,
    period_us: u64,
    volts: [f32; MAX_SERVOS],
    torque: [bool; MAX_SERVOS],
    next_step_us: u64,
    /// Held by the operator (between episodes, and at the start).
    held: bool,
    /// Control periods simulated, and how many of them blew up.
    periods: u64,
    blow_ups: u64,
}

impl UrdfRig {
    /// The robot at rest in its start pose at time 0, torque off, held.
    pub fn new(robot: &RobotFile) -> anyhow::Result<UrdfRig> {
        Self::of_model(&UrdfModel::load(robot)?)
    }

    /// The same from its body as read.
    pub fn of_model(model: &UrdfModel) -> anyhow::Result<UrdfRig> {
        let body = UrdfBody::new(model)?;
        let spec = model.spec();
        let period_us = spec.period_us as u64;
        Ok(UrdfRig {
            body,
            model: model.clone(),
            hw: spec,
            ids: spec.joints.iter().map(|j| j.id).collect(),
            period_us,
            volts: [0.0; MAX_SERVOS],
            torque: [false; MAX_SERVOS],
            next_step_us: period_us,
            held: true,
            periods: 0,
            blow_ups: 0,
        })
    }

    /// Control periods simulated, and how many of them blew up.
    pub fn periods(&self) -> (u64, u64) {
        (self.periods, self.blow_ups)
    }

    fn joint_of(&self, id: u8) -> Option<usize> {
        self.ids.iter().position(|&i| i == id)
    }

    fn step(&mut self) {
        let mut u = self.volts;
        for (v, on) in u.iter_mut().zip(self.torque) {
            if !on {
                *v = 0.0;
            }
        }
        self.body.set_voltages(&u);
        self.periods += 1;
        if self.body.step_period().is_err() {
            // The simulation broke: the robot is put back as by the
            // operator; the firmware sees the jump.
            self.blow_ups += 1;
            self.put_back();
        }
    }

    fn put_back(&mut self) {
        self.body = UrdfBody::new(&self.model).unwrap_or_else(|e| unreachable!("the body built at load: {e}"));
    }

    /// Joint `k` as its servo senses it now.
    fn sensed(&self, k: usize) -> JointState {
        let (q, qd, t) = (self.body.angles(), self.body.rates(), self.body.gear_torques());
        let stall = self.hw.joints[k].servo.motor().stall_torque(self.supply_v() as f32).abs().max(1e-6);
        JointState { angle: q[k] as f64, rate: qd[k] as f64, load: (t[k] / stall).clamp(-1.0, 1.0) }
    }

    fn reading(&self, k: usize) -> PresentState {
        let s = self.sensed(k);
        servo_reading(&self.hw.joints[k], s.angle, s.rate, s.load, self.supply_v())
    }

    fn settled_until(&self, t_us: u64) -> bool {
        self.held || t_us < self.next_step_us
    }
}

impl Rig for UrdfRig {
    fn servo_ids(&self) -> &[u8] {
        &self.ids
    }

    fn supply_v(&self) -> f64 {
        self.hw.supply_nominal_v as f64
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
            self.volts[k] = joint_volts(&self.hw.joints[k], volts) as f32;
        }
    }

    fn present(&mut self, t_us: u64, id: u8) -> PresentState {
        self.advance_to(t_us);
        match self.joint_of(id) {
            Some(k) => self.reading(k),
            None => PresentState { position: 0, speed: 0, load: 0, voltage: 0, temperature: crate::rig::TEMPERATURE_C },
        }
    }

    fn joint_state(&mut self, t_us: u64, id: u8) -> JointState {
        self.advance_to(t_us);
        self.joint_of(id).map_or_else(JointState::default, |k| self.sensed(k))
    }

    /// A robot of files has no encoder and no foot switches.
    fn sensors(&mut self, t_us: u64) -> (u16, u8) {
        self.advance_to(t_us);
        (0, 0)
    }

    fn peek_present(&self, t_us: u64, id: u8) -> Option<PresentState> {
        let k = self.joint_of(id)?;
        self.settled_until(t_us).then(|| self.reading(k))
    }

    fn peek_sensors(&self, t_us: u64) -> Option<(u16, u8)> {
        self.settled_until(t_us).then_some((0, 0))
    }

    fn describe(&self) -> String {
        let servos: Vec<String> = self.hw.joints.iter().map(|j| format!("{} ({}, ID {})", j.name, j.servo.name, j.id)).collect();
        format!("{} in rapier3d from its URDF: {}; put back in its start pose between episodes", self.hw.name, servos.join(", "))
    }

    fn episode_ended(&mut self, _t_us: u64) {
        self.put_back();
        self.held = true;
    }

    fn episode_started(&mut self, _t_us: u64) {
        self.held = false;
    }

    fn gear_torque(&self, id: u8) -> f32 {
        self.joint_of(id).map_or(0.0, |k| self.body.gear_torques()[k])
    }
}
