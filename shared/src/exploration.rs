//! Temporally correlated exploration noise on the action levels: the
//! Ornstein–Uhlenbeck process of GRL's OU samplers
//! (`docs/reference/grl.md` §6.6) and pink (1/f) noise after
//! Eberhard et al. (ICLR 2023), for the `ou` and `pink` policies
//! ([`crate::policy::PolicyKind`]).
//!
//! Correlated noise keeps its sign for many steps, so the perturbed action
//! reverses less often than ε-greedy's independent draws: fewer backlash
//! re-engagements for the same amount of exploration (Section IV).
//!
//! Both processes draw only `u32`s from the caller's generator and sum them
//! as integers before one conversion to `f32`; what follows is IEEE
//! arithmetic in a fixed order. So the host and the chip, fed the same
//! generator, produce the same noise bit for bit. (`rand_distr`'s normal
//! sampler would need `exp`/`ln` on rejection and a float library whose
//! results the chip must match; twelve uniforms are exact integers.)

use crate::action_space::MAX_ACTION_DIMS;
use rand_core::RngCore;

/// Rows of the Voss–McCartney pink-noise generator: row `k` is redrawn
/// every 2^k steps, so ten rows give a 1/f spectrum over ten octaves,
/// from the control rate down to 1/1024 of it — longer than LEO's
/// 750-step episodes and the pendulum's 60.
pub const PINK_ROWS: usize = 10;

/// √((PINK_ROWS + 1)/3): the standard deviation of the sum of
/// `PINK_ROWS` rows and one white term, each uniform on [−1, 1)
/// (variance 1/3); dividing by it gives pink noise of unit variance, as
/// Eberhard et al. normalise theirs.
const PINK_STD: f32 = 1.914_854_2;

/// 2³² as f32 (exact).
const TWO_32: f32 = 4_294_967_296.0;
/// 2³¹ as f32 (exact).
const TWO_31: f32 = 2_147_483_648.0;

/// An approximately standard normal draw: the sum of twelve uniforms on
/// [0, 1) minus six (mean 0, variance 1, tails cut at ±6), summed exactly
/// as integers.
pub fn normal<R: RngCore + ?Sized>(rng: &mut R) -> f32 {
    let mut sum = 0u64;
    for _ in 0..12 {
        sum += rng.next_u32() as u64;
    }
    (sum as i64 - 6 * (1i64 << 32)) as f32 / TWO_32
}

/// A uniform draw on [−1, 1) as the integer `i32` it is scaled from.
fn uniform_raw<R: RngCore + ?Sized>(rng: &mut R) -> i32 {
    rng.next_u32() as i32
}

/// The noise of one policy, per action dimension.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Noise {
    /// No noise process (every policy but `ou` and `pink`).
    None,
    /// Ornstein–Uhlenbeck: `n ← n − θ·n + σ·N(0, 1)` per step (GRL's
    /// centre c = 0).
    Ou {
        /// Mean reversion θ per step.
        theta: f32,
        /// Noise σ per step.
        sigma: f32,
        /// The process's value per dimension.
        value: [f32; MAX_ACTION_DIMS],
    },
    /// Pink noise by the Voss–McCartney algorithm, scaled by σ.
    Pink {
        /// Scale σ of the unit-variance noise.
        sigma: f32,
        /// The rows per dimension, as raw uniforms (`i32` / 2³¹).
        rows: [[i32; PINK_ROWS]; MAX_ACTION_DIMS],
        /// Samples drawn since the episode started.
        t: u32,
    },
}

impl Noise {
    /// An Ornstein–Uhlenbeck process at its centre.
    pub const fn ou(theta: f32, sigma: f32) -> Noise {
        Noise::Ou { theta, sigma, value: [0.0; MAX_ACTION_DIMS] }
    }

    /// A pink-noise generator before its first sample.
    pub const fn pink(sigma: f32) -> Noise {
        Noise::Pink { sigma, rows: [[0; PINK_ROWS]; MAX_ACTION_DIMS], t: 0 }
    }

    /// Back to the start of an episode: OU at its centre (GRL resets its
    /// noise at t = 0), pink noise drawing a fresh sequence (Eberhard et
    /// al. sample one per episode).
    pub fn reset(&mut self) {
        match self {
            Noise::None => {}
            Noise::Ou { value, .. } => *value = [0.0; MAX_ACTION_DIMS],
            Noise::Pink { t, .. } => *t = 0,
        }
    }

    /// The next sample of the first `dims` dimensions (0 elsewhere), in
    /// units of the action's scale; advances the process.
    pub fn sample<R: RngCore + ?Sized>(&mut self, dims: usize, rng: &mut R) -> [f32; MAX_ACTION_DIMS] {
        let mut out = [0.0; MAX_ACTION_DIMS];
        match self {
            Noise::None => {}
            Noise::Ou { theta, sigma, value } => {
                for i in 0..dims {
                    let n = value[i];
                    value[i] = n - *theta * n + *sigma * normal(rng);
                    out[i] = value[i];
                }
            }
            Noise::Pink { sigma, rows, t } => {
                for i in 0..dims {
                    let rows = &mut rows[i];
                    if *t == 0 {
                        for r in rows.iter_mut() {
                            *r = uniform_raw(rng);
                        }
                    } else {
                        // Row k changes every 2^k samples.
                        let k = t.trailing_zeros() as usize;
                        if k < PINK_ROWS {
                            rows[k] = uniform_raw(rng);
                        }
                    }
                    let white = uniform_raw(rng) as i64;
                    let sum: i64 = rows.iter().map(|&r| r as i64).sum::<i64>() + white;
                    out[i] = *sigma * (sum as f32 / TWO_31) / PINK_STD;
                }
                *t = t.wrapping_add(1);
            }
        }
        out
    }
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::*;
    use rand_core::SeedableRng;
    use rand_pcg::Pcg32;
    use std::vec::Vec;

    fn mean_var(x: &[f32]) -> (f64, f64) {
        let n = x.len() as f64;
        let m = x.iter().map(|&v| v as f64).sum::<f64>() / n;
        (m, x.iter().map(|&v| (v as f64 - m).powi(2)).sum::<f64>() / n)
    }

    /// Lag-`k` autocorrelation.
    fn autocorrelation(x: &[f32], k: usize) -> f64 {
        let (m, v) = mean_var(x);
        let n = x.len() - k;
        (0..n).map(|i| (x[i] as f64 - m) * (x[i + k] as f64 - m)).sum::<f64>() / n as f64 / v
    }

    #[test]
    fn normal_draws_have_unit_variance() {
        let mut rng = Pcg32::seed_from_u64(3);
        let x: Vec<f32> = (0..200_000).map(|_| normal(&mut rng)).collect();
        let (m, v) = mean_var(&x);
        assert!(m.abs() < 0.01, "mean {m}");
        assert!((v - 1.0).abs() < 0.01, "variance {v}");
        assert!(x.iter().all(|v| v.abs() <= 6.0));
    }

    #[test]
    fn ou_has_its_stationary_variance_and_reverts_to_zero() {
        let (theta, sigma) = (0.15f32, 0.2f32);
        let mut ou = Noise::ou(theta, sigma);
        let mut rng = Pcg32::seed_from_u64(5);
        let x: Vec<f32> = (0..400_000).map(|_| ou.sample(1, &mut rng)[0]).collect();
        // AR(1) with coefficient 1 − θ: variance σ²/(1 − (1 − θ)²).
        let expected = (sigma as f64).powi(2) / (1.0 - (1.0 - theta as f64).powi(2));
        let (_, v) = mean_var(&x[1000..]);
        assert!((v / expected - 1.0).abs() < 0.05, "variance {v}, expected {expected}");
        assert!((autocorrelation(&x[1000..], 1) - (1.0 - theta as f64)).abs() < 0.01);
        ou.reset();
        assert_eq!(ou, Noise::ou(theta, sigma));
    }

    #[test]
    fn pink_noise_is_unit_variance_and_correlated_over_octaves() {
        let mut pink = Noise::pink(1.0);
        let mut rng = Pcg32::seed_from_u64(9);
        let x: Vec<f32> = (0..1 << 18).map(|_| pink.sample(1, &mut rng)[0]).collect();
        let (m, v) = mean_var(&x);
        assert!(m.abs() < 0.05, "mean {m}");
        assert!((v - 1.0).abs() < 0.05, "variance {v}");
        // 1/f: correlation decays slowly over octaves (white noise would
        // give 0 at every lag; OU of the same lag-1 correlation decays
        // geometrically).
        let r: Vec<f64> = [1, 4, 16, 64].iter().map(|&k| autocorrelation(&x, k)).collect();
        assert!(r[0] > 0.5 && r[1] > 0.4 && r[2] > 0.25 && r[3] > 0.1, "{r:?}");
        assert!(r.windows(2).all(|w| w[0] > w[1]), "{r:?}");
    }

    #[test]
    fn a_reset_starts_a_fresh_pink_sequence() {
        let mut rng = Pcg32::seed_from_u64(1);
        let mut pink = Noise::pink(0.5);
        pink.sample(2, &mut rng);
        pink.sample(2, &mut rng);
        pink.reset();
        let mut again = Noise::pink(0.5);
        let mut rng_a = rng.clone();
        assert_eq!(pink.sample(2, &mut rng), again.sample(2, &mut rng_a));
    }
}
