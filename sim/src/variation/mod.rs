//! A robot that is not its model: the simulation runs a plant whose
//! masses, motor constants, friction, backlash, command delay and sensor
//! noise differ from the model the learner was built for, within the
//! ranges of [`PlantRanges`] (`robot.toml`'s `[plant]`, or `pada run
//! --plant-ranges`).
//!
//! | file | its one job |
//! |---|---|
//! | `mod.rs` | one plant drawn from the ranges ([`PlantDraw`]) and the draws' random numbers |
//! | `sensor.rs` | a joint's reading with play and noise ([`Sensor`]) |
//! | `varied.rs` | a task whose plants are drawn ([`Varied`]): once per trial, or every episode (domain randomisation) |
//! | `ranges.rs` | the ranges pada states for its own robots, with their sources |
//!
//! The model itself ([`PlantRanges::MODEL`]) is never wrapped: a run
//! without a differing plant is the run it always was, bit for bit.

mod ranges;
mod sensor;
mod varied;
#[cfg(test)]
mod plant_tests;

pub use pada_robot_file::plant::{PlantRanges, Span};
pub use ranges::{physical_pendulum_ranges, simulated_pendulum_ranges};
pub use sensor::Sensor;
pub use varied::{Redraw, Vary, Varied, VariedPlant};

use rand_core::RngCore;

/// One plant within the ranges: the value of every parameter.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct PlantDraw {
    /// Factor on every moving link's mass and inertia.
    pub mass: f64,
    /// Factor on each motor's torque constant.
    pub motor_constant: f64,
    /// Dry friction added at each joint \[N·m\].
    pub friction_nm: f64,
    /// Play between each joint's sensor and its link \[rad\].
    pub backlash_rad: f64,
    /// Control periods each command arrives late.
    pub delay_periods: u32,
    /// Standard deviation of the noise on each angle reading \[rad\].
    pub noise_rad: f64,
}

impl PlantDraw {
    /// The model's own values.
    pub const MODEL: PlantDraw =
        PlantDraw { mass: 1.0, motor_constant: 1.0, friction_nm: 0.0, backlash_rad: 0.0, delay_periods: 0, noise_rad: 0.0 };

    /// A plant drawn uniformly within each of `ranges` from `rng` (a
    /// single value is taken as it is, without a draw).
    pub fn draw(ranges: &PlantRanges, rng: &mut dyn RngCore) -> PlantDraw {
        let mut pick = |s: Span| if s.lo == s.hi { s.lo } else { s.lo + unit(rng) * (s.hi - s.lo) };
        let mass = pick(ranges.mass);
        let motor_constant = pick(ranges.motor_constant);
        let friction_nm = pick(ranges.friction_nm);
        let backlash_rad = pick(ranges.backlash_rad);
        // Whole periods, each of lo..=hi equally likely.
        let d = ranges.delay_periods;
        let delay = if d.lo == d.hi { d.lo } else { (d.lo + (pick(Span { lo: 0.0, hi: d.hi - d.lo + 1.0 })).floor()).min(d.hi) };
        let noise_rad = pick(ranges.noise_rad);
        PlantDraw { mass, motor_constant, friction_nm, backlash_rad, delay_periods: delay as u32, noise_rad }
    }

    /// Whether the sensor differs from the model's (play or noise).
    pub fn senses_differently(&self) -> bool {
        self.backlash_rad > 0.0 || self.noise_rad > 0.0
    }
}

/// A uniform number in [0, 1) from 53 random bits.
pub fn unit(rng: &mut dyn RngCore) -> f64 {
    (rng.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
}

/// A standard normal number (Box–Muller on two uniform ones).
pub fn normal(rng: &mut dyn RngCore) -> f64 {
    let u1 = 1.0 - unit(rng); // (0, 1]: the logarithm stays finite
    let u2 = unit(rng);
    (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos()
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand_core::SeedableRng;

    #[test]
    fn draws_stay_within_their_ranges_and_repeat_with_the_seed() {
        let r = PlantRanges::MODEL.with_arg("mass=0.9..1.1,motor_constant=0.8..1.0,delay_periods=0..2,noise_rad=0.01").unwrap();
        let mut rng = rand_pcg::Pcg64::seed_from_u64(7);
        let draws: Vec<PlantDraw> = (0..2000).map(|_| PlantDraw::draw(&r, &mut rng)).collect();
        let mut delays = [0u32; 3];
        for d in &draws {
            assert!((0.9..=1.1).contains(&d.mass) && (0.8..=1.0).contains(&d.motor_constant), "{d:?}");
            assert_eq!((d.friction_nm, d.backlash_rad, d.noise_rad), (0.0, 0.0, 0.01));
            delays[d.delay_periods as usize] += 1;
        }
        // Each of 0, 1 and 2 periods about a third of the time.
        assert!(delays.iter().all(|&n| (550..=780).contains(&n)), "{delays:?}");
        let mut again = rand_pcg::Pcg64::seed_from_u64(7);
        assert_eq!(PlantDraw::draw(&r, &mut again), draws[0]);
        assert_eq!(PlantDraw::draw(&PlantRanges::MODEL, &mut again), PlantDraw::MODEL);
    }

    #[test]
    fn normal_numbers_have_mean_0_and_deviation_1() {
        let mut rng = rand_pcg::Pcg64::seed_from_u64(3);
        let x: Vec<f64> = (0..20000).map(|_| normal(&mut rng)).collect();
        let mean = x.iter().sum::<f64>() / x.len() as f64;
        let sd = (x.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / x.len() as f64).sqrt();
        assert!(mean.abs() < 0.03 && (sd - 1.0).abs() < 0.03, "{mean} {sd}");
    }
}
