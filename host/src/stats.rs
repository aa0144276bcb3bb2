//! Means with Student-t 95% confidence intervals, as the paper reports its
//! averages over trials ("-851 … has a 95% confidence interval of 39",
//! Section VII).
//!
//! The t quantile is computed, not tabulated: the t distribution's CDF is
//! `1 − ½·I_{ν/(ν+t²)}(ν/2, ½)` for t > 0 (I the regularised incomplete
//! beta function, by its continued fraction), inverted by bisection.

use serde::Serialize;

/// A mean over trials with the half-width of its 95% confidence interval.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Estimate {
    /// Mean (`null` in JSON when infinite: some trial had no damage).
    pub mean: f64,
    /// Half-width of the 95% interval `t(0.975, n−1)·s/√n` (`null` in JSON
    /// for fewer than two trials or an infinite mean).
    pub ci95: f64,
    /// Number of values.
    pub n: usize,
}

impl Estimate {
    /// The mean and Student-t 95% interval of `values`. Empty input gives
    /// NaN for both; one value gives a NaN interval.
    pub fn of(values: &[f64]) -> Estimate {
        let n = values.len();
        if n == 0 {
            return Estimate {
                mean: f64::NAN,
                ci95: f64::NAN,
                n,
            };
        }
        let mean = values.iter().sum::<f64>() / n as f64;
        if n < 2 || !mean.is_finite() {
            return Estimate {
                mean,
                ci95: f64::NAN,
                n,
            };
        }
        let var = values.iter().map(|v| (v - mean) * (v - mean)).sum::<f64>() / (n - 1) as f64;
        let ci95 = student_t_quantile(0.975, (n - 1) as f64) * (var / n as f64).sqrt();
        Estimate { mean, ci95, n }
    }

    /// `mean − ci95`.
    pub fn lower(&self) -> f64 {
        self.mean - self.ci95
    }

    /// `mean + ci95`.
    pub fn upper(&self) -> f64 {
        self.mean + self.ci95
    }
}

/// The `p` quantile (0.5 < p < 1) of Student's t distribution with `df > 0`
/// degrees of freedom, to about 1e-10.
pub fn student_t_quantile(p: f64, df: f64) -> f64 {
    debug_assert!(p > 0.5 && p < 1.0 && df > 0.0);
    let (mut lo, mut hi) = (0.0f64, 1.0f64);
    while student_t_cdf(hi, df) < p {
        hi *= 2.0;
    }
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if student_t_cdf(mid, df) < p {
            lo = mid;
        } else {
            hi = mid;
        }
        if hi - lo < 1e-12 * hi.max(1.0) {
            break;
        }
    }
    0.5 * (lo + hi)
}

/// `P(T ≤ t)` for Student's t with `df` degrees of freedom.
pub fn student_t_cdf(t: f64, df: f64) -> f64 {
    let x = df / (df + t * t);
    let tail = 0.5 * regularized_incomplete_beta(x, df / 2.0, 0.5);
    if t >= 0.0 {
        1.0 - tail
    } else {
        tail
    }
}

/// The regularised incomplete beta function `I_x(a, b)`.
pub fn regularized_incomplete_beta(x: f64, a: f64, b: f64) -> f64 {
    if x <= 0.0 {
        return 0.0;
    }
    if x >= 1.0 {
        return 1.0;
    }
    let ln_front = ln_gamma(a + b) - ln_gamma(a) - ln_gamma(b) + a * x.ln() + b * (1.0 - x).ln();
    let front = ln_front.exp();
    // The continued fraction converges quickly for x < (a + 1)/(a + b + 2);
    // otherwise use the symmetry I_x(a, b) = 1 − I_(1−x)(b, a).
    if x < (a + 1.0) / (a + b + 2.0) {
        front * beta_continued_fraction(x, a, b) / a
    } else {
        1.0 - front * beta_continued_fraction(1.0 - x, b, a) / b
    }
}

/// The continued fraction of the incomplete beta function (modified Lentz).
fn beta_continued_fraction(x: f64, a: f64, b: f64) -> f64 {
    const TINY: f64 = 1e-300;
    let (qab, qap, qam) = (a + b, a + 1.0, a - 1.0);
    let mut c = 1.0;
    let mut d = 1.0 - qab * x / qap;
    if d.abs() < TINY {
        d = TINY;
    }
    d = 1.0 / d;
    let mut h = d;
    for m in 1..1000 {
        let m = m as f64;
        let m2 = 2.0 * m;
        let aa = m * (b - m) * x / ((qam + m2) * (a + m2));
        d = 1.0 + aa * d;
        if d.abs() < TINY {
            d = TINY;
        }
        c = 1.0 + aa / c;
        if c.abs() < TINY {
            c = TINY;
        }
        d = 1.0 / d;
        h *= d * c;
        let aa = -(a + m) * (qab + m) * x / ((a + m2) * (qap + m2));
        d = 1.0 + aa * d;
        if d.abs() < TINY {
            d = TINY;
        }
        c = 1.0 + aa / c;
        if c.abs() < TINY {
            c = TINY;
        }
        d = 1.0 / d;
        let del = d * c;
        h *= del;
        if (del - 1.0).abs() < 1e-15 {
            break;
        }
    }
    h
}

/// `ln Γ(x)` for x > 0 (Lanczos, g = 7, 9 terms; ~1e-15 relative).
pub fn ln_gamma(x: f64) -> f64 {
    const G: f64 = 7.0;
    const C: [f64; 9] = [
        0.999_999_999_999_809_9,
        676.520_368_121_885_1,
        -1_259.139_216_722_402_8,
        771.323_428_777_653_1,
        -176.615_029_162_140_6,
        12.507_343_278_686_905,
        -0.138_571_095_265_720_12,
        9.984_369_578_019_572e-6,
        1.505_632_735_149_311_6e-7,
    ];
    if x < 0.5 {
        // Reflection: Γ(x)Γ(1−x) = π / sin(πx).
        return (std::f64::consts::PI / (std::f64::consts::PI * x).sin()).ln() - ln_gamma(1.0 - x);
    }
    let x = x - 1.0;
    let mut a = C[0];
    let t = x + G + 0.5;
    for (i, c) in C.iter().enumerate().skip(1) {
        a += c / (x + i as f64);
    }
    0.5 * (2.0 * std::f64::consts::PI).ln() + (x + 0.5) * t.ln() - t + a.ln()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn t_quantiles_match_tables() {
        // Two-sided 95% critical values from standard t tables.
        for (df, expected) in [
            (1.0, 12.706_204_736),
            (2.0, 4.302_652_730),
            (4.0, 2.776_445_105),
            (7.0, 2.364_624_252),
            (10.0, 2.228_138_852),
            (27.0, 2.051_830_516),
            (28.0, 2.048_407_142),
            (100.0, 1.983_971_519),
            (1e6, 1.959_966_0),
        ] {
            let q = student_t_quantile(0.975, df);
            assert!((q - expected).abs() < 1e-6, "df {df}: {q} vs {expected}");
        }
        assert!((student_t_quantile(0.95, 5.0) - 2.015_048_373).abs() < 1e-6);
    }

    #[test]
    fn ln_gamma_known_values() {
        assert!(ln_gamma(1.0).abs() < 1e-13);
        assert!((ln_gamma(0.5) - std::f64::consts::PI.sqrt().ln()).abs() < 1e-13);
        assert!((ln_gamma(10.0) - 362_880f64.ln()).abs() < 1e-12);
    }

    #[test]
    fn estimate_against_a_hand_computation() {
        // 1..=5: mean 3, s = √2.5, CI = 2.776445·√(2.5/5) = 1.963243.
        let e = Estimate::of(&[1.0, 2.0, 3.0, 4.0, 5.0]);
        assert_eq!(e.mean, 3.0);
        assert!((e.ci95 - 1.963_243_6).abs() < 1e-6, "{}", e.ci95);
        assert_eq!(e.n, 5);
        // Constant values: zero width.
        assert_eq!(Estimate::of(&[7.0; 4]).ci95, 0.0);
        // One value: no interval.
        assert!(Estimate::of(&[7.0]).ci95.is_nan());
        assert!(Estimate::of(&[]).mean.is_nan());
        // An infinite value makes the mean infinite, the interval undefined.
        let inf = Estimate::of(&[1.0, f64::INFINITY]);
        assert!(inf.mean.is_infinite() && inf.ci95.is_nan());
    }

    #[test]
    fn cdf_is_symmetric_and_monotone() {
        for df in [1.0, 3.0, 30.0] {
            assert!((student_t_cdf(0.0, df) - 0.5).abs() < 1e-12);
            let mut prev = 0.0;
            for i in -50..=50 {
                let t = i as f64 * 0.2;
                let c = student_t_cdf(t, df);
                assert!((c + student_t_cdf(-t, df) - 1.0).abs() < 1e-12);
                assert!(c >= prev);
                prev = c;
            }
        }
    }
}
