//! GRL's rate filter: a first-order Butterworth low-pass, discretised with
//! Tustin's method without pre-warping (grl-facts §3.2):
//! `T_c = 2π·f_c/f_s`, `b0 = b1 = T_c/(T_c + 2)`, `a1 = (T_c − 2)/(T_c + 2)`,
//! `y[n] = b0·(x[n] + x[n−1]) − a1·y[n−1]`, cleared at every episode start.

/// One first-order low-pass filter.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Butterworth1 {
    b0: f32,
    a1: f32,
    x1: f32,
    y1: f32,
}

impl Butterworth1 {
    /// A filter with cut-off `cutoff_hz` at sampling rate `sample_hz`.
    pub fn new(cutoff_hz: f32, sample_hz: f32) -> Self {
        let tc = core::f32::consts::TAU * cutoff_hz / sample_hz;
        Butterworth1 { b0: tc / (tc + 2.0), a1: (tc - 2.0) / (tc + 2.0), x1: 0.0, y1: 0.0 }
    }

    /// LEO's servo-joint rates: 10 Hz at 30 Hz.
    pub fn leo_joint() -> Self {
        Self::new(10.0, 30.0)
    }

    /// LEO's torso rate as GRL computes it: the call passes the step time
    /// (1/30) where a sampling rate belongs, with 25 Hz, which makes the
    /// filter practically a pass-through (b0 ≈ 0.99958, a1 ≈ 0.99915).
    /// Kept so the robot sees what the simulation's learner saw.
    pub fn leo_torso() -> Self {
        Self::new(25.0, 1.0 / 30.0)
    }

    /// Filters one sample.
    pub fn step(&mut self, x: f32) -> f32 {
        let y = self.b0 * (x + self.x1) - self.a1 * self.y1;
        self.x1 = x;
        self.y1 = y;
        y
    }

    /// Clears the history (episode start).
    pub fn reset(&mut self) {
        self.x1 = 0.0;
        self.y1 = 0.0;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn coefficients_match_grl() {
        let f = Butterworth1::leo_joint();
        assert!((f.b0 - 0.511_527).abs() < 1e-5, "{}", f.b0);
        assert!((f.a1 - 0.023_055).abs() < 1e-5, "{}", f.a1);
        let t = Butterworth1::leo_torso();
        assert!((t.b0 - 0.999_576).abs() < 1e-5, "{}", t.b0);
        assert!((t.a1 - 0.999_152).abs() < 1e-5, "{}", t.a1);
    }

    #[test]
    fn unit_gain_at_dc() {
        let mut f = Butterworth1::leo_joint();
        let mut y = 0.0;
        for _ in 0..100 {
            y = f.step(2.0);
        }
        assert!((y - 2.0).abs() < 1e-4);
        f.reset();
        assert!((f.step(0.0)).abs() < 1e-9);
    }
}
