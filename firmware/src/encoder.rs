//! Quadrature counts → an unwrapped angle.
//!
//! The timer counts 16 bits and wraps; the control loop samples it every
//! period, far more often than it can move half its range (32 768 counts:
//! 8 turns of a 1024-line encoder in one 33 ms period), so the signed
//! 16-bit difference of two samples is the true motion.

/// Tracks whole turns of a wrapping 16-bit counter.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Unwrapper {
    last: Option<u16>,
    total: i64,
}

impl Unwrapper {
    /// A tracker whose first sample is count 0.
    pub const fn new() -> Self {
        Unwrapper { last: None, total: 0 }
    }

    /// Takes a sample; returns the counts since the first sample.
    pub fn update(&mut self, count: u16) -> i64 {
        if let Some(last) = self.last {
            self.total += count.wrapping_sub(last) as i16 as i64;
        }
        self.last = Some(count);
        self.total
    }

    /// Counts since the first sample, as of the last update.
    pub fn total(&self) -> i64 {
        self.total
    }
}

/// Wraps an angle into (−π, π].
pub fn wrap_pi(x: f32) -> f32 {
    use core::f32::consts::{PI, TAU};
    let w = x - TAU * libm::floorf(x / TAU); // [0, 2π)
    let w = if w >= TAU { 0.0 } else { w };
    if w > PI {
        w - TAU
    } else {
        w
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use core::f32::consts::PI;

    #[test]
    fn unwraps_across_the_counter_boundary() {
        let mut u = Unwrapper::new();
        assert_eq!(u.update(65_530), 0);
        assert_eq!(u.update(4), 10);
        assert_eq!(u.update(65_000), 10 - 540);
        // A true position moving by up to ±20 000 counts per sample,
        // sampled through a 16-bit counter.
        let mut u = Unwrapper::new();
        let start: i64 = 1_234_567;
        let mut pos = start;
        u.update((pos as u64 % 65_536) as u16);
        for k in 0..1000i64 {
            pos += (k * 7919 % 40_001) - 20_000;
            assert_eq!(u.update(pos.rem_euclid(65_536) as u16), pos - start);
        }
    }

    #[test]
    fn wrap_into_half_open_interval() {
        assert!((wrap_pi(PI) - PI).abs() < 1e-6);
        assert!((wrap_pi(-PI) - PI).abs() < 1e-6);
        assert!((wrap_pi(3.0 * PI / 2.0) + PI / 2.0).abs() < 1e-5);
        assert!((wrap_pi(4.0 * PI + 0.25) - 0.25).abs() < 1e-5);
        for k in -100..100 {
            let w = wrap_pi(k as f32 * 0.37);
            assert!(w > -PI - 1e-6 && w <= PI + 1e-6, "{w}");
        }
    }
}
