//! The STS3215's position loop driving its own motor model on a one-joint
//! arm with dry friction: the step response settles, the P gain leaves a
//! dead band that halves when P doubles (LeRobot's P = 16 against the
//! factory's 32), and flipping the goal flips the gear torque's sign.

extern crate std;

use super::*;
use crate::servo::feetech::STS3215;
use crate::servo::DcMotor;
use std::vec::Vec;

/// A link's own inertia about the joint \[kg·m²\]: about an SO-101 forearm
/// (0.3 kg at 0.13 m).
const LINK_INERTIA: f32 = 0.005;
/// The supply \[V\].
const SUPPLY: f32 = 7.4;
/// The simulation step \[s\]: ten steps a loop period.
const DT: f32 = 1.0e-4;

/// One joint turned by `motor` through `servo`'s loop, with Coulomb
/// friction `friction` at the joint; stepped semi-implicitly.
struct Joint {
    motor: DcMotor,
    servo: PositionLoop,
    friction: f32,
    q: f32,
    qd: f32,
    /// The torque the gears carried over the last step.
    gear_torque: f32,
}

impl Joint {
    fn new(gains: LoopGains, friction: f32, q: f32) -> Joint {
        Joint {
            motor: STS3215.motor(),
            servo: PositionLoop::new(STS3215.position_loop(gains).expect("the STS3215 runs its own loop")),
            friction,
            q,
            qd: 0.0,
            gear_torque: 0.0,
        }
    }

    /// The rotor's inertia at the joint, η·J_a·G².
    fn reflected(&self) -> f32 {
        self.motor.to_rx28().reduced().armature
    }

    fn step(&mut self, goal: f32) {
        let u = self.servo.step(goal, self.q, SUPPLY, DT);
        let drive = self.motor.joint_torque(u, self.qd);
        let inertia = LINK_INERTIA + self.reflected();
        // Coulomb friction: it holds the joint while the drive is within
        // it, and opposes the motion otherwise.
        let qdd = if self.qd == 0.0 && drive.abs() <= self.friction {
            0.0
        } else {
            let dir = if self.qd != 0.0 { self.qd.signum() } else { drive.signum() };
            (drive - self.friction * dir) / inertia
        };
        let before = self.qd;
        self.qd += qdd * DT;
        if before != 0.0 && before.signum() != self.qd.signum() {
            // Friction stops the joint rather than reversing it.
            self.qd = 0.0;
        }
        self.q += self.qd * DT;
        self.gear_torque = drive - self.reflected() * (self.qd - before) / DT;
    }

    fn run(&mut self, goal: f32, seconds: f32) {
        for _ in 0..(seconds / DT) as usize {
            self.step(goal);
        }
    }
}

/// The half-width of the band where the loop's torque cannot overcome
/// `friction` \[counts\].
fn band_counts(gains: LoopGains, friction: f32) -> f32 {
    let spec = STS3215.position_loop(gains).expect("the STS3215 runs its own loop");
    let motor = STS3215.motor();
    // The motor's torque is linear in the voltage below the clip.
    let torque_per_rad = motor.stall_torque(1.0) * spec.volts_per_rad(SUPPLY);
    friction / torque_per_rad * spec.counts_per_rad
}

#[test]
fn sts3215_loop_constants() {
    let s = PositionLoopSpec::sts3215(LoopGains::FACTORY);
    // 4096 counts per turn; P·e/4 in 0.1 % units, as BAM measured.
    assert_eq!(s.counts(core::f32::consts::TAU), 4096);
    assert!((s.duty_per_count * 1000.0 - 0.2546).abs() < 1e-3, "{}", s.duty_per_count);
    assert_eq!((s.cw_dead_zone, s.ccw_dead_zone, s.max_duty), (1, 1, 0.97));
    assert_eq!(LoopGains::FACTORY, LoopGains { p: 32, d: 32, i: 0 });
    assert_eq!(LoopGains::LEROBOT, LoopGains { p: 16, d: 32, i: 0 });
    assert_eq!(STS3215.loop_gains, Some(LoopGains::FACTORY));
}

#[test]
fn the_dead_zone_gives_no_output_and_outside_it_at_least_the_minimum() {
    let mut l = PositionLoop::new(PositionLoopSpec::sts3215(LoopGains { p: 1, d: 0, i: 0 }));
    assert_eq!(l.tick(100, 99), 0.0);
    assert_eq!(l.tick(100, 101), 0.0);
    // Two counts at P = 1: 5·10⁻⁴ of full duty, raised to the minimum.
    assert_eq!(l.tick(100, 98), 0.016);
    assert_eq!(l.tick(100, 102), -0.016);
    // Far off: saturated.
    assert_eq!(l.tick(100_000, 0), 0.97);
    assert_eq!(l.tick(-100_000, 0), -0.97);
    // Non-finite angles read as 0.
    let mut l = PositionLoop::new(PositionLoopSpec::sts3215(LoopGains::FACTORY));
    assert_eq!(l.step(f32::NAN, f32::INFINITY, SUPPLY, DT), 0.0);
    let mut l = PositionLoop::new(PositionLoopSpec::sts3215(LoopGains::FACTORY));
    assert_eq!(l.step(0.5, 0.0, f32::NAN, DT), 0.0);
    assert!(l.duty() > 0.0);
}

#[test]
fn the_loop_ticks_at_its_own_rate_and_holds_between() {
    let mut l = PositionLoop::new(PositionLoopSpec::sts3215(LoopGains::FACTORY));
    let first = l.step(0.01, 0.0, SUPPLY, DT);
    assert!(first > 0.0);
    // Nine more steps of 0.1 ms hold the output though the goal moved.
    for _ in 0..9 {
        assert_eq!(l.step(-0.01, 0.0, SUPPLY, DT), first);
    }
    assert!(l.step(-0.01, 0.0, SUPPLY, DT) < 0.0, "the tenth step is the next tick");
}

#[test]
fn a_step_of_the_goal_settles_within_the_friction_band() {
    let friction = STS3215.motor().dry_friction;
    for gains in [LoopGains::FACTORY, LoopGains::LEROBOT] {
        let mut j = Joint::new(gains, friction, 0.0);
        let goal = 0.5;
        j.run(goal, 1.0);
        let settled = j.q;
        j.run(goal, 0.5);
        assert_eq!(j.q, settled, "{gains:?}: still moving after 1 s");
        assert_eq!(j.qd, 0.0);
        let spec = STS3215.position_loop(gains).expect("the STS3215 runs its own loop");
        let e = (goal - j.q).abs() * spec.counts_per_rad;
        let band = band_counts(gains, friction);
        assert!(e <= band + 1.0, "{gains:?}: {e} counts off, band {band}");
    }
    // Without friction it settles to the dead zone.
    let mut j = Joint::new(LoopGains::FACTORY, 0.0, 0.0);
    j.run(0.5, 1.5);
    let spec = STS3215.position_loop(LoopGains::FACTORY).expect("the STS3215 runs its own loop");
    assert!((0.5 - j.q).abs() * spec.counts_per_rad <= 1.5, "{}", j.q);
}

/// Where the joint comes to rest when it approaches `goal` from `from`.
fn rest_from(gains: LoopGains, friction: f32, goal: f32, from: f32) -> f32 {
    let mut j = Joint::new(gains, friction, from);
    j.run(goal, 1.5);
    j.q
}

#[test]
fn lerobots_p_of_16_leaves_a_dead_band_twice_the_factory_p_of_32s() {
    // The same goal approached from below and from above lands apart by
    // up to twice the band where the loop's torque cannot overcome the
    // friction; the band is inversely proportional to P.
    let friction = STS3215.motor().dry_friction;
    let goal = 0.2;
    let spec = STS3215.position_loop(LoopGains::FACTORY).expect("the STS3215 runs its own loop");
    let mut spreads = Vec::new();
    for gains in [LoopGains::LEROBOT, LoopGains::FACTORY] {
        let below = rest_from(gains, friction, goal, goal - 0.3);
        let above = rest_from(gains, friction, goal, goal + 0.3);
        let band = band_counts(gains, friction);
        for q in [below, above] {
            let e = (q - goal).abs() * spec.counts_per_rad;
            assert!(e <= band + 1.0, "{gains:?}: {e} counts off, band {band}");
        }
        // At P = 32 the joint overshoots and lands past the goal; the
        // distance between the two landings is what a user sees.
        spreads.push(((above - below) * spec.counts_per_rad).abs());
    }
    let (p16, p32) = (spreads[0], spreads[1]);
    assert!((1.5..=3.0).contains(&(p16 / p32)), "P = 16 lands {p16} counts apart, P = 32 {p32}");
    // With the estimated friction the band at P = 16 is over a degree wide,
    // 13 counts either side of the goal.
    assert!(p16 > 4096.0 / 360.0, "{p16}");
    assert!((12.0..14.0).contains(&band_counts(LoopGains::LEROBOT, friction)));
    // Without friction there is no band beyond the dead zone.
    let below = rest_from(LoopGains::LEROBOT, 0.0, goal, goal - 0.3);
    let above = rest_from(LoopGains::LEROBOT, 0.0, goal, goal + 0.3);
    assert!((above - below).abs() * spec.counts_per_rad <= 3.0);
}

#[test]
fn flipping_the_goal_flips_the_gear_torque() {
    let mut j = Joint::new(LoopGains::LEROBOT, STS3215.motor().dry_friction, 0.0);
    j.run(0.3, 0.8);
    assert_eq!(j.qd, 0.0, "at rest before the flip");
    let mut torques = Vec::new();
    for _ in 0..(0.8 / DT) as usize {
        j.step(-0.3);
        torques.push(j.gear_torque);
    }
    // The first tick after the flip saturates the bridge: the motor gives
    // its stall torque at 97 % of the supply, negative, and the gears pass
    // on the part that accelerates the link (the rotor takes the rest).
    let stall = j.motor.stall_torque(0.97 * SUPPLY);
    let link_share = LINK_INERTIA / (LINK_INERTIA + j.reflected());
    assert!(torques[0] < -link_share * (stall - j.friction), "{} vs {stall}", torques[0]);
    assert!(torques.iter().all(|t| t.abs() <= stall), "never above the stall torque");
    // It drives negative, then brakes positive as the joint nears the goal.
    let first_positive = torques.iter().position(|t| *t > 0.0).expect("the loop brakes");
    assert!(torques[..first_positive].iter().all(|t| *t <= 0.0));
    assert!(torques[first_positive..].iter().any(|t| *t > 0.05 * stall), "braking torque");
    assert!((j.q + 0.3).abs() < 0.02, "{}", j.q);
}

#[test]
fn the_integral_removes_a_steady_offset_under_load() {
    // No friction, a constant load torque against the joint: P alone
    // leaves load/K of error; I drives it to the dead zone.
    let load = 0.3;
    let spec_counts = PositionLoopSpec::sts3215(LoopGains::FACTORY).counts_per_rad;
    let mut offsets = Vec::new();
    for gains in [LoopGains { p: 32, d: 32, i: 0 }, LoopGains { p: 32, d: 32, i: 32 }] {
        let mut j = Joint::new(gains, 0.0, 0.0);
        for _ in 0..(5.0 / DT) as usize {
            let u = j.servo.step(0.0, j.q, SUPPLY, DT);
            let drive = j.motor.joint_torque(u, j.qd) - load;
            j.qd += drive / (LINK_INERTIA + j.reflected()) * DT;
            j.q += j.qd * DT;
        }
        offsets.push((j.q * spec_counts).abs());
    }
    assert!(offsets[0] > 10.0, "P alone: {} counts", offsets[0]);
    assert!(offsets[1] <= 2.0, "with I: {} counts", offsets[1]);
}
