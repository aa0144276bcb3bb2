//! A robot of files behind a board's servos (`pada run --board`,
//! `pada sil`): the body simulated in whole control periods, as LEO's rig
//! is, read through each servo's calibration, and an operator who puts the
//! robot back in its start pose when an episode ends and holds it there
//! until the next one starts.

use super::body::{UrdfBody, UrdfModel};
use crate::rig::periodic::{PeriodBody, Periodic};
use crate::rig::JointState;
use pada_core::limits::MAX_SERVOS;
use pada_core::robot::RobotSpec;
use pada_robot_file::RobotFile;

/// The rig of a robot of files.
pub type UrdfRig = Periodic<UrdfOnRig>;

/// A robot of files' physics behind its servos ([`UrdfRig`]'s body): its
/// body as simulated and as read, to put back.
pub struct UrdfOnRig {
    body: UrdfBody,
    model: UrdfModel,
    hw: &'static RobotSpec,
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
        Ok(Periodic::of_body(UrdfOnRig { body, model: model.clone(), hw: spec }, spec.period_us as u64))
    }
}

impl PeriodBody for UrdfOnRig {
    fn hw(&self) -> &'static RobotSpec {
        self.hw
    }

    fn step_period(&mut self, volts: &[f32]) -> bool {
        let mut u = [0.0; MAX_SERVOS];
        u[..volts.len()].copy_from_slice(volts);
        self.body.set_voltages(&u);
        if self.body.step_period().is_err() {
            // The simulation broke: the robot is put back as by the
            // operator; the firmware sees the jump.
            self.put_back();
            return false;
        }
        true
    }

    fn put_back(&mut self) {
        self.body = UrdfBody::new(&self.model).unwrap_or_else(|e| unreachable!("the body built at load: {e}"));
    }

    fn sensed(&self, k: usize) -> JointState {
        let (q, qd, t) = (self.body.angles(), self.body.rates(), self.body.gear_torques());
        let supply_v = self.hw.supply_nominal_v as f64;
        let stall = self.hw.joints[k].servo.motor().stall_torque(supply_v as f32).abs().max(1e-6);
        JointState { angle: q[k] as f64, rate: qd[k] as f64, load: (t[k] / stall).clamp(-1.0, 1.0) }
    }

    fn gear_torque(&self, k: usize) -> f32 {
        self.body.gear_torques()[k]
    }

    fn describe(&self) -> String {
        let servos: Vec<String> = self.hw.joints.iter().map(|j| format!("{} ({}, ID {})", j.name, j.servo.name, j.id)).collect();
        format!("{} in rapier3d from its URDF: {}; put back in its start pose between episodes", self.hw.name, servos.join(", "))
    }
}
