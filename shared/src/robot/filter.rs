//! GRL's rate filter (docs/reference/grl.md §3.2): a first-order Butterworth low-pass
//! discretised with Tustin's method without pre-warping,
//! `T_c = 2π·f_c/f_s`, `b0 = b1 = T_c/(T_c + 2)`, `a1 = (T_c − 2)/(T_c + 2)`,
//! `y[n] = b0·(x[n] + x[n−1]) − a1·y[n−1]`, cleared at every episode start.
//!
//! LEO's simulation filters the simulated joint rates with it and the
//! firmware filters the rates it differences from servo positions, so both
//! learners see rates shaped the same way.

/// One first-order low-pass filter.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RateFilter {
    b: f32,
    a1: f32,
    x_prev: f32,
    y_prev: f32,
}

impl RateFilter {
    /// A filter for sampling frequency `fs` and cut-off `fc` \[Hz\], state 0.
    pub fn new(fs: f32, fc: f32) -> Self {
        let tc = 2.0 * core::f32::consts::PI * fc / fs;
        RateFilter { b: tc / (tc + 2.0), a1: (tc - 2.0) / (tc + 2.0), x_prev: 0.0, y_prev: 0.0 }
    }

    /// Coefficients `(b0 = b1, a1)`.
    pub fn coefficients(&self) -> (f32, f32) {
        (self.b, self.a1)
    }

    /// Clears the history (every episode start, §3.2).
    pub fn reset(&mut self) {
        self.x_prev = 0.0;
        self.y_prev = 0.0;
    }

    /// Filters one sample.
    pub fn update(&mut self, x: f32) -> f32 {
        let y = self.b * (x + self.x_prev) - self.a1 * self.y_prev;
        self.x_prev = x;
        self.y_prev = y;
        y
    }

    /// The last output.
    pub fn value(&self) -> f32 {
        self.y_prev
    }
}
