//! The robot behind a board's servos and sensors: what the servos move and
//! the sensors read, driven by the firmware's own controller — through the
//! emulated bus of the software-in-the-loop run (`pada sil`), or directly
//! on the host (`pada run --board`). One interface, two drivers.
//!
//! A [`Rig`] is advanced to the instant of every bus transaction (or
//! control period), so a voltage applies from the moment its Moving Speed
//! reaches the servo (the motor's command is a zero-order hold between
//! writes, as on the real robot) and a reading reflects the state at the
//! moment it is taken.
//!
//! | rig | what |
//! |---|---|
//! | [`pendulum::PendulumRig`] | the physical pendulum's model, one RX-28 in wheel mode, the encoder on its axis |
//! | [`leo::LeoRig`] | the rapier3d LEO: seven RX-28s, the boom's encoder, the foot switches, an operator between episodes |
//! | [`stand_in::LeoStandIn`] | seven RX-28s holding LEO's start pose, no dynamics (instruction counts) |

pub mod leo;
pub mod pendulum;
pub mod stand_in;

pub use leo::LeoRig;
pub use pendulum::PendulumRig;
pub use stand_in::LeoStandIn;

use pada_core::dynamixel::table::{self, PresentState};
use std::f64::consts::TAU;

/// Counts per revolution of the emulated encoder (a 1024-line encoder
/// after ×4 decoding, as `pada_firmware::config::EncoderConfig`).
pub const ENCODER_COUNTS_PER_REV: f64 = 4096.0;
/// The servos' supply \[V\] (Present Voltage 120 = 12.0 V).
pub const SUPPLY_V: f64 = 12.0;
/// Present Temperature every emulated servo reports \[°C\].
pub const TEMPERATURE_C: u8 = 40;

/// The robot behind the bus.
pub trait Rig: Send {
    /// The Dynamixel IDs of its servos.
    fn servo_ids(&self) -> &[u8];

    /// Advances the simulation to `t_us` with the drive in force.
    fn advance_to(&mut self, t_us: u64);

    /// From `t_us` on, servo `id` has torque `torque` and applies `volts`
    /// (its Moving Speed times its supply; ignored without torque).
    fn drive(&mut self, t_us: u64, id: u8, torque: bool, volts: f64);

    /// What servo `id` reads at `t_us` (Present Position … Temperature).
    fn present(&mut self, t_us: u64, id: u8) -> PresentState;

    /// The encoder's 16-bit count and the foot contacts at `t_us`.
    fn sensors(&mut self, t_us: u64) -> (u16, u8);

    /// A one-line description for reports.
    fn describe(&self) -> String;

    /// The firmware reported the end of an episode (and now waits until
    /// the robot is back at its start): a rig with an operator puts the
    /// robot back in its start pose and holds it there.
    fn episode_ended(&mut self) {}

    /// The firmware started an episode: the operator lets go.
    fn episode_started(&mut self) {}

    /// The mean torque on servo `id`'s gearbox over the last control
    /// period \[N·m\], as the simulation computes it (for the host's
    /// fatigue count).
    fn gear_torque(&self, id: u8) -> f32;
}

/// The encoder count of an angle measured from the pose at boot.
pub fn encoder_count(angle_from_boot: f64) -> u16 {
    let counts = (angle_from_boot / TAU * ENCODER_COUNTS_PER_REV).round() as i64;
    counts.rem_euclid(1 << 16) as u16
}

/// The raw Present Position of a joint angle (512 at 0, 300° over 1023
/// counts; the potentiometer's dead zone reads as the nearest end).
pub fn position_raw(angle: f64) -> u16 {
    let unit = table::POSITION_RANGE_RAD as f64 / table::POSITION_MAX as f64;
    (512.0 + angle / unit)
        .round()
        .clamp(0.0, table::POSITION_MAX as f64) as u16
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    #[test]
    fn encoder_counts_wrap_like_a_16_bit_timer() {
        assert_eq!(encoder_count(0.0), 0);
        assert_eq!(encoder_count(PI), 2048);
        assert_eq!(encoder_count(-TAU / 4096.0), 65535);
        assert_eq!(encoder_count(16.0 * TAU), 0);
    }
}
