//! Fixed-step classical Runge–Kutta (RK4) integration with a zero-order
//! hold: the plants hold the motor command constant over one control period
//! and split it into equal sub-steps.
//!
//! A fixed step (rather than an adaptive one) keeps every trial's arithmetic
//! identical from run to run, so a seed reproduces a run bit for bit.

/// One RK4 step of size `h` for `ẋ = f(x)`.
#[inline]
pub fn rk4_step<const N: usize>(
    x: &[f64; N],
    h: f64,
    f: impl Fn(&[f64; N]) -> [f64; N],
) -> [f64; N] {
    let k1 = f(x);
    let k2 = f(&add_scaled(x, &k1, h / 2.0));
    let k3 = f(&add_scaled(x, &k2, h / 2.0));
    let k4 = f(&add_scaled(x, &k3, h));
    let mut out = *x;
    for i in 0..N {
        out[i] += h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
    }
    out
}

/// Integrates `ẋ = f(x)` over `duration` with `substeps` equal RK4 steps.
#[inline]
pub fn integrate<const N: usize>(
    mut x: [f64; N],
    duration: f64,
    substeps: u32,
    f: impl Fn(&[f64; N]) -> [f64; N],
) -> [f64; N] {
    let h = duration / substeps as f64;
    for _ in 0..substeps {
        x = rk4_step(&x, h, &f);
    }
    x
}

#[inline]
fn add_scaled<const N: usize>(x: &[f64; N], k: &[f64; N], s: f64) -> [f64; N] {
    let mut out = *x;
    for i in 0..N {
        out[i] += s * k[i];
    }
    out
}

/// `sin θ` near a point where `sin` and `cos` are known: within one
/// sub-step the stages of RK4 move θ by a few hundredths of a radian, so
/// `sin(θ₀ + δ) = sin θ₀·cos δ + cos θ₀·sin δ` with short Taylor series
/// for the small δ replaces four library `sin` calls per sub-step by one
/// `sin_cos`. Exact to rounding (~1e-16) for |δ| ≤ 0.1; larger δ (not met
/// by the pendulums at their speeds) falls back to the library.
#[derive(Debug, Clone, Copy)]
pub struct SinNear {
    theta0: f64,
    sin0: f64,
    cos0: f64,
}

impl SinNear {
    /// Prepares for angles near `theta0`.
    #[inline]
    pub fn new(theta0: f64) -> SinNear {
        let (sin0, cos0) = theta0.sin_cos();
        SinNear { theta0, sin0, cos0 }
    }

    /// `sin theta`.
    #[inline]
    pub fn sin(&self, theta: f64) -> f64 {
        let d = theta - self.theta0;
        if d.abs() > 0.1 {
            return theta.sin();
        }
        // Taylor to d⁹ and d¹⁰: the first omitted terms are below
        // 0.1¹¹/11! ≈ 2.5e-19 and 0.1¹²/12! ≈ 2e-21.
        // Coefficients as products (no division in the hot path).
        const S3: f64 = -1.0 / 6.0;
        const S5: f64 = 1.0 / 120.0;
        const S7: f64 = -1.0 / 5040.0;
        const S9: f64 = 1.0 / 362_880.0;
        const C2: f64 = -0.5;
        const C4: f64 = 1.0 / 24.0;
        const C6: f64 = -1.0 / 720.0;
        const C8: f64 = 1.0 / 40_320.0;
        const C10: f64 = -1.0 / 3_628_800.0;
        let d2 = d * d;
        let sin_d = d + d * d2 * (S3 + d2 * (S5 + d2 * (S7 + d2 * S9)));
        let cos_d = 1.0 + d2 * (C2 + d2 * (C4 + d2 * (C6 + d2 * (C8 + d2 * C10))));
        self.sin0 * cos_d + self.cos0 * sin_d
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sin_near_matches_the_library() {
        for i in 0..200 {
            let theta0 = -7.0 + i as f64 * 0.07;
            let near = SinNear::new(theta0);
            for j in -50..=50 {
                let theta = theta0 + j as f64 * 0.0025;
                assert!(
                    (near.sin(theta) - theta.sin()).abs() < 4e-16,
                    "{theta0} + {}",
                    theta - theta0
                );
            }
            // Far away: the library itself.
            assert_eq!(near.sin(theta0 + 1.0), (theta0 + 1.0).sin());
        }
    }

    #[test]
    fn rk4_is_fourth_order_on_exponential_decay() {
        // ẋ = −x, x(1) = e⁻¹; the global error of RK4 scales with h⁴, so
        // halving the step divides it by about 16.
        let exact = (-1.0f64).exp();
        let err = |n| (integrate([1.0], 1.0, n, |x| [-x[0]])[0] - exact).abs();
        let ratio = err(10) / err(20);
        assert!((14.0..18.0).contains(&ratio), "error ratio {ratio}");
        assert!(err(10) < 1e-6);
    }

    #[test]
    fn harmonic_oscillator_returns_after_one_period() {
        // ẍ = −x: after 2π the state is back at (1, 0).
        let x = integrate([1.0, 0.0], 2.0 * std::f64::consts::PI, 1000, |x| {
            [x[1], -x[0]]
        });
        assert!((x[0] - 1.0).abs() < 1e-10 && x[1].abs() < 1e-10, "{x:?}");
    }
}
