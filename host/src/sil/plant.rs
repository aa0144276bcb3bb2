//! What stands behind the emulated bus: the robot the servos move and the
//! sensor device reads, in continuous time.
//!
//! A [`Rig`] is advanced to the instant of every bus transaction, so a
//! voltage applies from the moment its Moving Speed reaches the servo (the
//! motor's command is a zero-order hold between writes, as on the real
//! robot) and a reading reflects the state at the moment it is taken.

use crate::pendulum::PhysicalPendulumParams;
use pada_core::dynamixel::table::{self, PresentState};
use std::f64::consts::{PI, TAU};

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
}

/// The encoder count of an angle measured from the pose at boot.
fn encoder_count(angle_from_boot: f64) -> u16 {
    let counts = (angle_from_boot / TAU * ENCODER_COUNTS_PER_REV).round() as i64;
    counts.rem_euclid(1 << 16) as u16
}

/// The raw Present Position of a joint angle (512 at 0, 300° over 1023
/// counts; the potentiometer's dead zone reads as the nearest end).
fn position_raw(angle: f64) -> u16 {
    let unit = table::POSITION_RANGE_RAD as f64 / table::POSITION_MAX as f64;
    (512.0 + angle / unit)
        .round()
        .clamp(0.0, table::POSITION_MAX as f64) as u16
}

/// The physical pendulum of Section VII on one RX-28 in wheel mode (ID 1)
/// with the quadrature encoder on its axis: the constants of
/// [`crate::pendulum::PhysicalPendulum`] (GRL's model), integrated with RK4
/// in steps of at most [`PendulumRig::MAX_STEP_S`].
///
/// With torque on, the motor drives with the applied voltage and brakes
/// with its back-EMF (`J·θ̈ = m·g·l·sin θ − b·θ̇ − (K²/R)·θ̇ + (K/R)·u`);
/// with torque off the RX-28 cuts the motor's power and the pendulum swings
/// freely (`J·θ̈ = m·g·l·sin θ − b·θ̇`).
#[derive(Debug, Clone)]
pub struct PendulumRig {
    params: PhysicalPendulumParams,
    /// θ (0 upright, unwrapped) and θ̇.
    x: [f64; 2],
    t_us: u64,
    torque: bool,
    volts: f64,
}

impl PendulumRig {
    /// The longest integration step \[s\]: the host model's 3 ms.
    pub const MAX_STEP_S: f64 = 0.003;

    /// Hanging at rest at time 0, torque off.
    pub fn new(params: PhysicalPendulumParams) -> Self {
        PendulumRig {
            params,
            x: [PI, 0.0],
            t_us: 0,
            torque: false,
            volts: 0.0,
        }
    }

    /// θ (0 upright, unwrapped) and θ̇ now.
    pub fn state(&self) -> [f64; 2] {
        self.x
    }

    fn derivative(&self, x: &[f64; 2]) -> [f64; 2] {
        let p = &self.params;
        let mut torque = p.mass_kg * p.gravity * p.length_m * x[0].sin() - p.damping * x[1];
        if self.torque {
            let k_over_r = p.torque_constant / p.resistance_ohm;
            let u = self.volts.clamp(-p.voltage_limit, p.voltage_limit);
            torque += k_over_r * u - p.torque_constant * k_over_r * x[1];
        }
        [x[1], torque / p.inertia_kg_m2]
    }
}

impl Rig for PendulumRig {
    fn servo_ids(&self) -> &[u8] {
        &[1]
    }

    fn advance_to(&mut self, t_us: u64) {
        if t_us <= self.t_us {
            return;
        }
        let dt = (t_us - self.t_us) as f64 * 1e-6;
        let steps = (dt / Self::MAX_STEP_S).ceil().max(1.0) as u32;
        let this = self.clone();
        self.x = crate::integrator::integrate(self.x, dt, steps, |y| this.derivative(y));
        self.t_us = t_us;
    }

    fn drive(&mut self, t_us: u64, id: u8, torque: bool, volts: f64) {
        if id != 1 {
            return;
        }
        self.advance_to(t_us);
        self.torque = torque;
        self.volts = volts;
    }

    fn present(&mut self, t_us: u64, _id: u8) -> PresentState {
        self.advance_to(t_us);
        let rpm = self.x[1] * 60.0 / TAU;
        let speed_ratio = rpm / (table::SPEED_UNIT_RPM as f64 * table::MAGNITUDE_MAX as f64);
        PresentState {
            position: position_raw(crate::pendulum::wrap_angle(self.x[0] - PI)),
            speed: table::encode_signed(speed_ratio.clamp(-1.0, 1.0) as f32),
            load: 0,
            voltage: (SUPPLY_V * 10.0).round() as u8,
            temperature: TEMPERATURE_C,
        }
    }

    fn sensors(&mut self, t_us: u64) -> (u16, u8) {
        self.advance_to(t_us);
        // The firmware takes the pose at boot (hanging, θ = π) as count 0.
        (encoder_count(self.x[0] - PI), 0)
    }

    fn describe(&self) -> String {
        "the physical pendulum of Section VII (GRL constants, one RX-28 in wheel mode, 4096-count encoder)".into()
    }
}

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

    fn describe(&self) -> String {
        "a LEO stand-in: 7 RX-28s holding the start pose, no dynamics (instruction counts only)"
            .into()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn encoder_counts_wrap_like_a_16_bit_timer() {
        assert_eq!(encoder_count(0.0), 0);
        assert_eq!(encoder_count(PI), 2048);
        assert_eq!(encoder_count(-TAU / 4096.0), 65535);
        assert_eq!(encoder_count(16.0 * TAU), 0);
    }

    #[test]
    fn the_pendulum_hangs_still_without_torque_and_swings_with_it() {
        let mut rig = PendulumRig::new(PhysicalPendulumParams::default());
        rig.advance_to(2_000_000);
        // Hanging still, up to sin(π) ≈ 1e-16 of rounding.
        assert!((rig.state()[0] - PI).abs() < 1e-12 && rig.state()[1].abs() < 1e-12);
        assert_eq!(rig.sensors(2_000_000), (0, 0));
        rig.drive(2_000_000, 1, true, 3.0);
        rig.advance_to(2_030_000);
        // Positive voltage turns it towards positive θ.
        assert!(rig.state()[1] > 0.0);
        let (count, _) = rig.sensors(2_030_000);
        assert!(count > 0 && count < 100, "{count}");
        // The same as the host model's control period (RK4, 10 steps of 3 ms).
        let host = PhysicalPendulumParams::default().advance([PI, 0.0], 3.0);
        assert!(
            (rig.state()[0] - host[0]).abs() < 1e-12,
            "{:?} vs {host:?}",
            rig.state()
        );
    }

    #[test]
    fn without_torque_the_motor_does_not_brake() {
        let p = PhysicalPendulumParams::default();
        let energy = |x: [f64; 2]| {
            0.5 * p.inertia_kg_m2 * x[1] * x[1] + p.mass_kg * p.gravity * p.length_m * x[0].cos()
        };
        let mut free = PendulumRig::new(p);
        let mut braked = PendulumRig::new(p);
        for rig in [&mut free, &mut braked] {
            rig.x = [PI, 10.0];
        }
        let e0 = energy(free.state());
        braked.drive(0, 1, true, 0.0);
        free.advance_to(500_000);
        braked.advance_to(500_000);
        let lost_free = e0 - energy(free.state());
        let lost_braked = e0 - energy(braked.state());
        // Back-EMF (K²/R = 3.0e-4) against friction alone (b = 3e-6).
        assert!(
            lost_braked > 20.0 * lost_free,
            "{lost_braked} vs {lost_free}"
        );
        assert!(lost_free > 0.0);
    }

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
