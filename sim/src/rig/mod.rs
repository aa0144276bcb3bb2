//! The robot behind a board's servos and sensors: what the servos move and
//! the sensors read, driven by the firmware's own controller — through the
//! emulated bus of the software-in-the-loop run (`pada sil`), or directly
//! on the host (`pada run --board`). One interface, two drivers.
//!
//! A [`Rig`] is advanced to the instant of every bus transaction (or
//! control period), so a voltage applies from the moment its Moving Speed
//! reaches the servo (the motor's command is a zero-order hold between
//! writes, as on the real robot) and a reading reflects the state at the
//! moment it is taken. Its trajectory depends only on when and what was
//! commanded, never on when or how often it was read, so the SIL run's
//! forecasts ([`Rig::peek_present`]) can read ahead without changing it.
//!
//! | rig | what |
//! |---|---|
//! | [`pendulum::PendulumRig`] | the physical pendulum's model, one RX-28 in wheel mode, the encoder on its axis |
//! | [`leo::LeoRig`] | the rapier3d LEO: seven RX-28s, the boom's encoder, the foot switches, an operator between episodes |

pub mod leo;
pub mod pendulum;

pub use leo::LeoRig;
pub use pendulum::PendulumRig;

use pada_core::dynamixel::table::{self, PresentState};
use pada_core::robot::JointSpec as Joint;

/// Present Temperature every emulated servo reports \[°C\].
pub const TEMPERATURE_C: u8 = 40;

/// The robot behind the bus.
pub trait Rig: Send {
    /// The Dynamixel IDs of its servos.
    fn servo_ids(&self) -> &[u8];

    /// The servos' supply \[V\]: what they report as Present Voltage, and
    /// what a Moving Speed's ratio of it applies.
    fn supply_v(&self) -> f64;

    /// Advances the simulation to `t_us` with the drive in force.
    fn advance_to(&mut self, t_us: u64);

    /// From `t_us` on, servo `id` has torque `torque` and applies `volts`
    /// (its Moving Speed times its supply; ignored without torque).
    fn drive(&mut self, t_us: u64, id: u8, torque: bool, volts: f64);

    /// What servo `id` reads at `t_us` (Present Position … Temperature).
    fn present(&mut self, t_us: u64, id: u8) -> PresentState;

    /// The encoder's 16-bit count and the foot contacts at `t_us`.
    fn sensors(&mut self, t_us: u64) -> (u16, u8);

    /// What [`present`](Self::present) would read at `t_us` (not earlier
    /// than the last event), without changing the rig — if no command
    /// comes first; `None` if the rig cannot tell without simulating ahead.
    fn peek_present(&self, t_us: u64, id: u8) -> Option<PresentState>;

    /// What [`sensors`](Self::sensors) would read at `t_us`, likewise.
    fn peek_sensors(&self, t_us: u64) -> Option<(u16, u8)>;

    /// A one-line description for reports.
    fn describe(&self) -> String;

    /// The firmware reported the end of an episode at `t_us` (and now waits
    /// until the robot is back at its start): a rig with an operator puts
    /// the robot back in its start pose and holds it there. Also called
    /// when the firmware reports a fault, after which a walking robot may
    /// lie on the floor.
    fn episode_ended(&mut self, _t_us: u64) {}

    /// The firmware started an episode at `t_us`: the operator lets go.
    fn episode_started(&mut self, _t_us: u64) {}

    /// Distance walked since the operator let go \[m\], as the plant
    /// measures it (a walking robot; `None` otherwise).
    fn walked_m(&self) -> Option<f64> {
        None
    }

    /// The mean torque on servo `id`'s gearbox over the last control
    /// period \[N·m\], as the simulation computes it (for the host's
    /// fatigue count).
    fn gear_torque(&self, id: u8) -> f32;
}

/// What servo `joint` reads with its joint at `angle` \[rad\] turning at
/// `rate` \[rad/s\] under `load` (a fraction of the stall torque, in the
/// joint's direction) on a `supply_v` supply. The rigs read in the servo's
/// own frame through the robot's one hardware definition
/// (`pada_core::robot::RobotSpec::joints`: its zero and sign), so an offset or
/// flipped servo of the real robot is the same offset or flip here, and the
/// firmware's calibration undoes it.
pub fn servo_reading(joint: &Joint, angle: f64, rate: f64, load: f32, supply_v: f64) -> PresentState {
    let rpm = rate * 60.0 / std::f64::consts::TAU;
    let speed = joint.sign as f64 * rpm / (table::SPEED_UNIT_RPM as f64 * table::MAGNITUDE_MAX as f64);
    PresentState {
        position: joint.position_of(angle),
        speed: table::encode_signed(speed.clamp(-1.0, 1.0) as f32),
        load: table::encode_signed((joint.sign as f32 * load).clamp(-1.0, 1.0)),
        voltage: (supply_v * 10.0).round() as u8,
        temperature: TEMPERATURE_C,
    }
}

/// The voltage a servo applies in its joint's direction when its Moving
/// Speed applies `servo_volts` in its own (counter-clockwise positive).
pub fn joint_volts(joint: &Joint, servo_volts: f64) -> f64 {
    joint.sign as f64 * servo_volts
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_reading_is_in_the_servos_frame_and_the_calibration_undoes_it() {
        for joint in [
            Joint { name: "a", servo: &pada_core::servo::RX28, id: 1, zero: 512, sign: 1, soft_limit: None },
            Joint { name: "b", servo: &pada_core::servo::RX28, id: 4, zero: 300, sign: -1, soft_limit: None },
        ] {
            let r = servo_reading(&joint, 0.4, 2.0, 0.25, 12.0);
            assert!((joint.angle(r.position) - 0.4).abs() <= 0.5 * pada_core::robot::hardware::POSITION_UNIT_RAD);
            // Speed and load turn with the servo.
            let speed = table::present_speed_ratio(r.speed);
            let load = table::present_load_ratio(r.load);
            assert_eq!(speed > 0.0, joint.sign > 0, "{joint:?}");
            assert!((joint.sign as f32 * load - 0.25).abs() < 1e-3, "{joint:?}");
            assert_eq!(r.voltage, 120);
            // A voltage the firmware sends for this joint applies in the joint's direction.
            let ms = joint.moving_speed(6.0, Some(12.0), 12.0);
            let servo_volts = table::ratio_from_moving_speed(ms) as f64 * 12.0;
            assert!((joint_volts(&joint, servo_volts) - 6.0).abs() < 0.02, "{joint:?}");
        }
    }
}
