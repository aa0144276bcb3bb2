//! A LEO that does not move, for instruction counts.

use super::{encoder_count, position_raw, Rig, TEMPERATURE_C};
use pada_core::dynamixel::table::PresentState;

/// A stand-in for LEO until its simulation drives the emulated bus: seven
/// RX-28s (IDs 1–7) that hold the start pose of LEO's definition
/// (`pada_core::robot::leo::START_JOINT_ANGLES`), the boom's encoder at
/// the start angle, the left foot on the ground. Nothing moves: it
/// exercises the LEO image's control loop and agent (for the agent step's
/// instruction count), not learning.
#[derive(Debug, Clone)]
pub struct LeoStandIn {
    /// Present Position by servo ID − 1.
    positions: [u16; 7],
}

impl LeoStandIn {
    /// The boom angle of the start pose (torso angle φ = −0.10 rad) \[rad\].
    pub const BOOM_ANGLE: f64 = -pada_core::robot::leo::START_PHI as f64;

    /// The robot in its start pose.
    pub fn new() -> Self {
        let mut positions = [0; 7];
        let hw = pada_firmware::config::hardware(pada_core::robot::Robot::Leo);
        for (joint, servo) in hw.joints.iter().enumerate() {
            let angle = pada_core::robot::leo::START_JOINT_ANGLES[joint] as f64;
            positions[servo.id as usize - 1] = position_raw(angle);
        }
        LeoStandIn { positions }
    }
}

impl Default for LeoStandIn {
    fn default() -> Self {
        Self::new()
    }
}

impl Rig for LeoStandIn {
    fn servo_ids(&self) -> &[u8] {
        &[1, 2, 3, 4, 5, 6, 7]
    }

    fn advance_to(&mut self, _t_us: u64) {}

    fn drive(&mut self, _t_us: u64, _id: u8, _torque: bool, _volts: f64) {}

    fn present(&mut self, _t_us: u64, id: u8) -> PresentState {
        let i = (id as usize).clamp(1, 7) - 1;
        PresentState {
            position: self.positions[i],
            speed: 0,
            load: 0,
            voltage: 140,
            temperature: TEMPERATURE_C,
        }
    }

    fn sensors(&mut self, _t_us: u64) -> (u16, u8) {
        (
            encoder_count(Self::BOOM_ANGLE),
            pada_firmware::leo::contact::LEFT,
        )
    }

    fn gear_torque(&self, _id: u8) -> f32 {
        0.0
    }

    fn describe(&self) -> String {
        "a LEO stand-in: 7 RX-28s holding the start pose, no dynamics (instruction counts only)"
            .into()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn leo_stand_in_reads_its_start_pose() {
        let mut leo = LeoStandIn::new();
        assert_eq!(leo.present(0, 1).position, 512 - 51);
        assert_eq!(leo.present(0, 4).position, 512 - 248);
        let (count, contacts) = leo.sensors(0);
        assert_eq!(count, 65);
        assert_eq!(contacts, pada_firmware::leo::contact::LEFT);
    }
}
