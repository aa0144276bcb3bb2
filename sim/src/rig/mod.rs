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
pub mod periodic;

pub use leo::{LeoOnBoom, LeoRig};
pub use pendulum::PendulumRig;

use pada_core::dynamixel::control_table::{self, x_series};
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

    /// What servo `id` reads at `t_us` (Present Position … Temperature)
    /// as an RX-28 (the definition's servo of both built-in robots).
    fn present(&mut self, t_us: u64, id: u8) -> PresentState;

    /// The state of servo `id`'s joint at `t_us`, whatever the servo's
    /// model: what a virtual servo of any model reads in its own units
    /// ([`x_reading`] for the X series; [`present`](Self::present) is
    /// [`servo_reading`] of it). Reading it changes nothing, as
    /// [`present`](Self::present).
    fn joint_state(&mut self, t_us: u64, id: u8) -> JointState;

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

/// A joint as its servo senses it.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct JointState {
    /// The joint's angle \[rad\], in the joint's frame (the definition's
    /// zero and sign apply on the way to the servo's counts).
    pub angle: f64,
    /// Its rate \[rad/s\].
    pub rate: f64,
    /// The load: a fraction of the stall torque, in the joint's direction.
    pub load: f32,
}

/// What an X-series servo in PWM Control Mode reads (addresses 124–146)
/// with its joint in `s` on a `supply_v` supply: Present Position in 4096
/// counts per turn through the joint's calibration
/// ([`Joint::counts_of`]), Present Velocity in 0.229 rev/min, Present
/// Current as the load's share of the model's stall current in the unit
/// its control table gives (XM430-W350: 2.69 mA, XL330-M288: 1 mA), or
/// Present Load in 0.1 % (XL430-W250, which has no current sensor);
/// Present PWM as `pwm`; no trajectory (PWM mode has none).
pub fn x_reading(joint: &Joint, s: JointState, pwm: i16, supply_v: f64) -> x_series::PresentState {
    let sign = joint.sign as f64;
    let rpm = s.rate * 60.0 / std::f64::consts::TAU;
    let velocity = (sign * rpm / joint.servo.encoding.speed_unit_rpm as f64).round();
    let load = (sign * s.load as f64).clamp(-1.0, 1.0);
    let model = control_table::by_model_number(joint.servo.model_number);
    let current = match model.and_then(|t| t.item_named("Present Current")) {
        Some(item) => load * joint.servo.datasheet.stall_current_a as f64 * 1000.0 / item.unit.per_count as f64,
        None => load * 1000.0,
    };
    x_series::PresentState {
        pwm,
        current: current.round().clamp(i16::MIN as f64, i16::MAX as f64) as i16,
        velocity: velocity.clamp(i32::MIN as f64, i32::MAX as f64) as i32,
        position: joint.counts_of(s.angle),
        velocity_trajectory: 0,
        position_trajectory: 0,
        input_voltage: (supply_v * 10.0).round() as u16,
        temperature: TEMPERATURE_C,
    }
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
    fn an_x_series_reading_is_in_its_own_units() {
        let joint = Joint { name: "x", servo: &pada_core::servo::XM430_W350, id: 1, zero: 2048, sign: -1, soft_limit: None };
        let s = JointState { angle: 7.0, rate: 2.0, load: 0.5 };
        let r = x_reading(&joint, s, 100, 12.0);
        assert!((joint.angle_of(r.position) as f64 - 7.0).abs() < 0.002, "more than a turn, no clamp");
        // 2 rad/s = 19.1 rev/min = 83 units, turning against the counts.
        assert_eq!(r.velocity, -83);
        // Half the stall current (2.3 A) in 2.69 mA units, against the counts.
        assert_eq!(r.current, -428);
        assert_eq!((r.pwm, r.input_voltage, r.temperature), (100, 120, TEMPERATURE_C));
        let xl = Joint { servo: &pada_core::servo::XL430_W250, sign: 1, ..joint };
        assert_eq!(x_reading(&xl, s, 0, 12.0).current, 500, "Present Load in 0.1 %");
    }

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
