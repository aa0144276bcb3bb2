//! Fixed-point formats of the learning core.
//!
//! Floats enter the core only at its boundary (observations, rewards and
//! parameters) and are converted once; weights, Q-values, TD errors and trace
//! weights are integers from then on, so that x86-64 and Cortex-M4 compute
//! bit-identical updates.
//!
//! | quantity | type | format | range | resolution |
//! |---|---|---|---|---|
//! | weight, Q-value, reward, TD error | [`Q16`] | signed Q15.16 in an `i32` | ±32768 | 2⁻¹⁶ ≈ 1.5e-5 |
//! | α, γ, γλ, ε-free rates, trace weights | [`Frac`] | unsigned Q2.30 in a `u32` | [0, 4) | 2⁻³⁰ ≈ 9.3e-10 |
//!
//! All arithmetic on [`Q16`] saturates instead of wrapping: a weight driven
//! past the range sticks at the limit (and the agent counts it) rather than
//! flipping sign.

/// Number of fractional bits of [`Q16`].
pub const Q16_FRAC_BITS: u32 = 16;
/// Number of fractional bits of [`Frac`].
pub const FRAC_BITS: u32 = 30;

/// A signed fixed-point number with 16 fractional bits (Q15.16 in an `i32`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, PartialOrd, Ord, Hash)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[repr(transparent)]
pub struct Q16(pub i32);

impl Q16 {
    /// Zero.
    pub const ZERO: Q16 = Q16(0);
    /// The largest representable value, ≈ 32768.
    pub const MAX: Q16 = Q16(i32::MAX);
    /// The smallest representable value, −32768.
    pub const MIN: Q16 = Q16(i32::MIN);

    /// Converts a float, rounding to nearest and saturating at the range.
    /// NaN maps to zero; callers validate finiteness first.
    pub fn from_f32(x: f32) -> Q16 {
        let scaled = x * (1u32 << Q16_FRAC_BITS) as f32;
        // `as` saturates at the i32 range and maps NaN to 0; rounding half
        // away from zero is done by hand because `f32::round` is not in core.
        let rounded = if scaled >= 0.0 { scaled + 0.5 } else { scaled - 0.5 };
        Q16(rounded as i32)
    }

    /// The value as a float (exact for |x| < 256, else rounded).
    pub fn to_f32(self) -> f32 {
        self.0 as f32 / (1u32 << Q16_FRAC_BITS) as f32
    }

    /// Saturating addition.
    pub fn saturating_add(self, other: Q16) -> Q16 {
        Q16(self.0.saturating_add(other.0))
    }

    /// Saturating subtraction.
    pub fn saturating_sub(self, other: Q16) -> Q16 {
        Q16(self.0.saturating_sub(other.0))
    }

    /// `self × f`, rounded to nearest, saturating.
    pub fn mul_frac(self, f: Frac) -> Q16 {
        let p = self.0 as i64 * f.0 as i64;
        Q16(saturate_i64(round_shift(p, FRAC_BITS)))
    }

    /// Converts a wide sum (in Q16 units) back, saturating.
    pub fn from_wide(x: i64) -> Q16 {
        Q16(saturate_i64(x))
    }
}

/// An unsigned fixed-point fraction with 30 fractional bits (Q2.30 in a
/// `u32`): learning rates, discount factors and trace weights.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, PartialOrd, Ord, Hash)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[repr(transparent)]
pub struct Frac(pub u32);

impl Frac {
    /// Zero.
    pub const ZERO: Frac = Frac(0);
    /// One.
    pub const ONE: Frac = Frac(1 << FRAC_BITS);

    /// Converts a float in `[0, 4)`, rounding to nearest; values outside
    /// saturate (callers validate ranges first).
    pub fn from_f32(x: f32) -> Frac {
        // f64 keeps all 30 bits of the conversion exact for f32 inputs.
        let scaled = x as f64 * (1u64 << FRAC_BITS) as f64 + 0.5;
        Frac(scaled as u32)
    }

    /// The value as a float.
    pub fn to_f32(self) -> f32 {
        (self.0 as f64 / (1u64 << FRAC_BITS) as f64) as f32
    }

    /// `self × other`, rounded to nearest, saturating.
    pub fn times(self, other: Frac) -> Frac {
        let p = self.0 as u64 * other.0 as u64;
        let r = (p + (1u64 << (FRAC_BITS - 1))) >> FRAC_BITS;
        Frac(if r > u32::MAX as u64 { u32::MAX } else { r as u32 })
    }
}

/// `x / 2^shift` rounded to nearest (ties away from zero), for `shift ≥ 1`.
fn round_shift(x: i64, shift: u32) -> i64 {
    let half = 1i64 << (shift - 1);
    if x >= 0 {
        (x + half) >> shift
    } else {
        -((-x + half) >> shift)
    }
}

fn saturate_i64(x: i64) -> i32 {
    if x > i32::MAX as i64 {
        i32::MAX
    } else if x < i32::MIN as i64 {
        i32::MIN
    } else {
        x as i32
    }
}

/// `⌊x⌋` as an `i32`, saturating; `f32::floor` is not in `core`, and the
/// `as` cast truncates toward zero, so negative non-integers step down once.
pub fn floor_i32(x: f32) -> i32 {
    let t = x as i32;
    if (t as f32) > x {
        t.saturating_sub(1)
    } else {
        t
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn q16_round_trip_and_saturation() {
        assert_eq!(Q16::from_f32(1.0).0, 65536);
        assert_eq!(Q16::from_f32(-0.5).0, -32768);
        assert_eq!(Q16::from_f32(1e9), Q16::MAX);
        assert_eq!(Q16::from_f32(-1e9), Q16::MIN);
        assert_eq!(Q16::from_f32(3.25).to_f32(), 3.25);
        assert_eq!(Q16::MAX.saturating_add(Q16(1)), Q16::MAX);
        assert_eq!(Q16::MIN.saturating_sub(Q16(1)), Q16::MIN);
    }

    #[test]
    fn mul_frac_rounds_symmetrically() {
        let half = Frac::from_f32(0.5);
        assert_eq!(Q16(3).mul_frac(half), Q16(2));
        assert_eq!(Q16(-3).mul_frac(half), Q16(-2));
        assert_eq!(Q16::from_f32(10.0).mul_frac(Frac::from_f32(0.2)).to_f32(), 2.0);
    }

    #[test]
    fn frac_products() {
        let g = Frac::from_f32(0.99);
        let l = Frac::from_f32(0.92);
        assert!((g.times(l).to_f32() - 0.9108).abs() < 1e-7);
        assert_eq!(Frac::ONE.times(Frac::ONE), Frac::ONE);
    }

    #[test]
    fn floor_matches_std() {
        for &x in &[-2.5f32, -2.0, -0.1, 0.0, 0.1, 1.999, 7.0, -1e-30] {
            assert_eq!(floor_i32(x), x.floor() as i32, "x = {x}");
        }
    }
}
