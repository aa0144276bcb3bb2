//! A joint's reading on a robot that is not its model: the link's angle
//! seen through play (backlash) and noise.
//!
//! The play is the classic play operator: the reading stays put until the
//! link has moved half the play past it, then follows at that distance
//! (a sensor on the motor's side of gears with play, seen from the link).
//! The gears' play itself is not simulated in the dynamics: the link is
//! driven as if the gears had none. The noise is Gaussian, drawn anew for
//! every reading.

use super::{normal, PlantDraw};
use pada_core::limits::MAX_SERVOS;
use rand_core::SeedableRng;
use rand_pcg::Pcg64;

/// The readings of every joint of one plant.
#[derive(Debug, Clone)]
pub struct Sensor {
    half_play: f64,
    noise_rad: f64,
    rng: Pcg64,
    /// Where each joint's play holds its reading \[rad\].
    held: [f64; MAX_SERVOS],
}

impl Sensor {
    /// The sensor of `draw` with its noise from `seed`, or `None` when it
    /// reads like the model's (no play, no noise).
    pub fn of(draw: &PlantDraw, seed: u64) -> Option<Sensor> {
        draw.senses_differently().then(|| Sensor {
            half_play: draw.backlash_rad / 2.0,
            noise_rad: draw.noise_rad,
            rng: Pcg64::seed_from_u64(seed),
            held: [0.0; MAX_SERVOS],
        })
    }

    /// A new episode with joint `k` at `angle`: the play centred on it.
    pub fn settle(&mut self, k: usize, angle: f64) {
        if let Some(h) = self.held.get_mut(k) {
            *h = angle;
        }
    }

    /// The reading of joint `k` whose link is at `angle` \[rad\].
    pub fn read(&mut self, k: usize, angle: f64) -> f64 {
        let Some(h) = self.held.get_mut(k) else { return angle };
        if !angle.is_finite() {
            return angle;
        }
        if angle > *h + self.half_play {
            *h = angle - self.half_play;
        } else if angle < *h - self.half_play {
            *h = angle + self.half_play;
        }
        let noise = if self.noise_rad > 0.0 { self.noise_rad * normal(&mut self.rng) } else { 0.0 };
        *h + noise
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn play_holds_the_reading_until_the_link_takes_it_up() {
        let draw = PlantDraw { backlash_rad: 0.2, ..PlantDraw::MODEL };
        let mut s = Sensor::of(&draw, 1).unwrap();
        s.settle(0, 0.0);
        assert_eq!(s.read(0, 0.05), 0.0); // within the play
        assert!((s.read(0, 0.3) - 0.2).abs() < 1e-12); // dragged, 0.1 behind
        assert!((s.read(0, 0.25) - 0.2).abs() < 1e-12); // reversing: held
        assert!((s.read(0, 0.0) - 0.1).abs() < 1e-12); // dragged the other way
        assert!(Sensor::of(&PlantDraw::MODEL, 1).is_none());
    }

    #[test]
    fn noise_has_the_drawn_deviation_and_repeats_with_the_seed() {
        let draw = PlantDraw { noise_rad: 0.01, ..PlantDraw::MODEL };
        let (mut a, mut b) = (Sensor::of(&draw, 5).unwrap(), Sensor::of(&draw, 5).unwrap());
        let x: Vec<f64> = (0..5000).map(|_| a.read(1, 1.0) - 1.0).collect();
        let sd = (x.iter().map(|v| v * v).sum::<f64>() / x.len() as f64).sqrt();
        assert!((sd - 0.01).abs() < 0.0005, "{sd}");
        let mut a2 = Sensor::of(&draw, 5).unwrap();
        assert_eq!(a2.read(1, 1.0), 1.0 + x[0]);
        assert_ne!(b.read(1, 1.0), Sensor::of(&draw, 6).unwrap().read(1, 1.0));
    }
}
