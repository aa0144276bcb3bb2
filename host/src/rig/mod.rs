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
use std::f64::consts::TAU;

/// Counts per revolution of the emulated encoder (a 1024-line encoder
/// after ×4 decoding, as `pada_firmware::config::EncoderConfig`).
pub const ENCODER_COUNTS_PER_REV: f64 = 4096.0;
/// The pendulum servo's supply \[V\] (Present Voltage 120 = 12.0 V).
pub const SUPPLY_V: f64 = 12.0;
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
