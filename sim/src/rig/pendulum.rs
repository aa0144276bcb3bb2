//! The physical pendulum behind the bus.

use super::{joint_volts, servo_reading, JointState, Rig};
use crate::pendulum::PhysicalPendulumParams;
use pada_core::dynamixel::table::PresentState;
use pada_core::robot::pendulum::gearbox_torque;
use pada_core::robot::pendulum::{ENCODER, SPEC_33HZ};
use pada_core::robot::{EncoderSpec, RobotSpec};
use std::f64::consts::PI;

/// The physical pendulum of Section VII on one RX-28 in wheel mode (ID 1)
/// with the quadrature encoder on its axis: the constants of
/// [`crate::pendulum::PhysicalPendulum`] (GRL's model), integrated with RK4
/// in steps of [`PendulumRig::STEP_US`].
///
/// With torque on, the motor drives with the applied voltage and brakes
/// with its back-EMF (`J·θ̈ = m·g·l·sin θ − b·θ̇ − (K²/R)·θ̇ + (K/R)·u`);
/// with torque off the RX-28 cuts the motor's power and the pendulum swings
/// freely (`J·θ̈ = m·g·l·sin θ − b·θ̇`).
///
/// The integration steps lie on a grid that starts at the last command (a
/// drive change or the operator's hand); a reading between grid points is
/// one shorter step from the last grid point and is not kept. So the
/// trajectory depends only on the commands, not on when or how often the
/// rig is read, and [`Rig::peek_present`] reads exactly what
/// [`Rig::present`] would.
#[derive(Debug, Clone)]
pub struct PendulumRig {
    params: PhysicalPendulumParams,
    /// θ (0 upright, unwrapped) and θ̇ at `t_us`.
    x: [f64; 2],
    /// A grid point: the last command plus whole steps \[µs\].
    t_us: u64,
    torque: bool,
    volts: f64,
    /// Whether a hand stops the pendulum at every episode's end.
    operator: bool,
    /// Its servo's ID and calibration and the encoder: the robot's one
    /// hardware definition.
    hw: &'static RobotSpec,
    /// The encoder on its axis.
    encoder: EncoderSpec,
}

impl PendulumRig {
    /// The integration step \[µs\]: the host model's 3 ms.
    pub const STEP_US: u64 = 3000;

    /// Hanging at rest at time 0, torque off.
    pub fn new(params: PhysicalPendulumParams) -> Self {
        PendulumRig {
            params,
            x: [PI, 0.0],
            t_us: 0,
            torque: false,
            volts: 0.0,
            operator: false,
            hw: &SPEC_33HZ,
            encoder: ENCODER,
        }
    }


    /// The same, stopped hanging at rest by hand whenever the firmware ends
    /// an episode ([`Rig::episode_ended`]).
    pub fn with_operator(params: PhysicalPendulumParams) -> Self {
        PendulumRig { operator: true, ..Self::new(params) }
    }

    /// θ (0 upright, unwrapped) and θ̇ at the last grid point.
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

    /// One RK4 step of `us` from `x`.
    fn step(&self, x: [f64; 2], us: u64) -> [f64; 2] {
        crate::integrator::integrate(x, us as f64 * 1e-6, 1, |y| self.derivative(y))
    }

    /// The state at `t_us` (at or after the last grid point, before the
    /// next), without keeping it.
    fn state_at(&self, t_us: u64) -> [f64; 2] {
        match t_us.saturating_sub(self.t_us) {
            0 => self.x,
            us => self.step(self.x, us),
        }
    }

    /// Starts a new grid at `t_us` from the state there (a command).
    fn restart_at(&mut self, t_us: u64) {
        self.advance_to(t_us);
        self.x = self.state_at(t_us);
        self.t_us = self.t_us.max(t_us);
    }

    /// The joint as the servo senses it: its angle measured from hanging,
    /// counting whole turns (an X-series servo's encoder does); no load is
    /// modelled.
    fn sensed(&self, x: [f64; 2]) -> JointState {
        JointState { angle: x[0] - PI, rate: x[1], load: 0.0 }
    }

    /// The servo's reading as an RX-28, whose potentiometer reads the
    /// angle within a turn.
    fn reading(&self, x: [f64; 2]) -> PresentState {
        let s = self.sensed(x);
        servo_reading(&self.hw.joints[0], crate::pendulum::wrap_angle(s.angle), s.rate, s.load, self.supply_v())
    }

    /// The firmware takes the pose at boot (hanging, θ = π) as count 0.
    fn encoder(&self, x: [f64; 2]) -> (u16, u8) {
        (self.encoder.count_of(x[0] - PI), 0)
    }
}

impl Rig for PendulumRig {
    fn servo_ids(&self) -> &[u8] {
        core::slice::from_ref(&self.hw.joints[0].id)
    }

    /// The nominal supply of the hardware definition (12 V).
    fn supply_v(&self) -> f64 {
        self.hw.supply_nominal_v as f64
    }

    fn advance_to(&mut self, t_us: u64) {
        while self.t_us + Self::STEP_US <= t_us {
            self.x = self.step(self.x, Self::STEP_US);
            self.t_us += Self::STEP_US;
        }
    }

    fn drive(&mut self, t_us: u64, id: u8, torque: bool, volts: f64) {
        let volts = joint_volts(&self.hw.joints[0], volts);
        if id != self.hw.joints[0].id || (torque, volts) == (self.torque, self.volts) {
            return;
        }
        self.restart_at(t_us);
        self.torque = torque;
        self.volts = volts;
    }

    fn present(&mut self, t_us: u64, _id: u8) -> PresentState {
        self.advance_to(t_us);
        self.reading(self.state_at(t_us))
    }

    fn joint_state(&mut self, t_us: u64, _id: u8) -> JointState {
        self.advance_to(t_us);
        self.sensed(self.state_at(t_us))
    }

    fn sensors(&mut self, t_us: u64) -> (u16, u8) {
        self.advance_to(t_us);
        self.encoder(self.state_at(t_us))
    }

    fn peek_present(&self, t_us: u64, _id: u8) -> Option<PresentState> {
        let mut ahead = self.clone();
        Some(ahead.present(t_us, self.hw.joints[0].id))
    }

    fn peek_sensors(&self, t_us: u64) -> Option<(u16, u8)> {
        let mut ahead = self.clone();
        Some(ahead.sensors(t_us))
    }

    fn describe(&self) -> String {
        let hand = if self.operator { ", stopped by hand between episodes" } else { "" };
        format!("the physical pendulum of Section VII (GRL constants, one RX-28 in wheel mode, {}-count encoder){hand}", self.encoder.counts_per_rev)
    }

    /// With an operator, the pendulum is stopped hanging at rest: the
    /// firmware then waits its second of stillness, and every episode
    /// starts as the simulated pendulum's do, without the up to 15 s of
    /// swinging out that the free pendulum takes.
    fn episode_ended(&mut self, t_us: u64) {
        if self.operator {
            self.restart_at(t_us);
            self.x = [PI, 0.0];
        }
    }

    fn gear_torque(&self, _id: u8) -> f32 {
        if self.torque {
            gearbox_torque(self.volts) as f32
        } else {
            0.0
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

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
    fn reading_does_not_change_the_trajectory_and_a_peek_reads_what_a_read_would() {
        let params = PhysicalPendulumParams::default();
        let mut read_often = PendulumRig::new(params);
        let mut never_read = PendulumRig::new(params);
        for k in 0..40u64 {
            let t = k * 30_000 + 612;
            let volts = if k % 3 == 0 { 3.0 } else { -2.0 };
            for rig in [&mut read_often, &mut never_read] {
                rig.drive(t, 1, true, volts);
            }
            for r in 1..30 {
                let at = t + r * 997;
                let peeked = read_often.peek_present(at, 1).unwrap();
                assert_eq!(read_often.present(at, 1), peeked);
                assert_eq!(read_often.peek_sensors(at + 5), Some(read_often.sensors(at + 5)));
            }
        }
        let end = 40 * 30_000 + 612;
        assert_eq!(read_often.present(end, 1), never_read.present(end, 1));
        // Bit for bit, not just to the servo's resolution.
        assert_eq!(read_often.state_at(end), never_read.state_at(end));
        assert_ne!(read_often.state()[1], 0.0);
    }
}
