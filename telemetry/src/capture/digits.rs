//! How many digits `telemetry.csv` gives a number.
//!
//! The CSV is the file a person reads; `telemetry.bin` (and the MCAP) keep
//! every value exactly. Printed in full (`f32`'s and `f64`'s shortest
//! round-trip decimals), a LEO step row was 334 bytes, 20 MB for a 30-minute
//! run, and most of its digits were below anything the robot can resolve:
//!
//! - an observation is made of joint angles read from encoders and their
//!   differences over a control period. The finest encoder of every servo in
//!   `pada_core::servo::SERVOS` is 4096 counts a turn, 1.53 mrad a count, so three
//!   decimals ([`fixed3`]) still tell every two counts apart (a test checks
//!   this for every count of a turn);
//! - a motor output is a voltage the servo applies by PWM in steps of
//!   several mV (RX-28: 1023 steps of 12 V), so three decimals (1 mV) keep
//!   it;
//! - a reward, a TD error or a gearbox's damage is read as a magnitude:
//!   four significant digits ([`sig4`]).

/// `x` to three decimals, trailing zeros dropped (`0.1`, `-1.197`, `3`);
/// `-0.000` is written `0`. Not finite: `NaN`, `inf`, `-inf`.
pub fn fixed3(x: f64) -> String {
    if !x.is_finite() {
        return non_finite(x);
    }
    let s = format!("{x:.3}");
    let s = trim_fraction(&s);
    if s == "-0" {
        "0".into()
    } else {
        s.into()
    }
}

/// `x` to four significant digits, as C's `%.4g` writes it: plain decimals
/// for 10⁻⁴ ≤ |x| < 10⁴ (`-5.543`, `0.0123`, `1234`), otherwise an exponent
/// (`1.982e-5`, `-3.48e5`); trailing zeros dropped, zero is `0`.
pub fn sig4(x: f64) -> String {
    if !x.is_finite() {
        return non_finite(x);
    }
    if x == 0.0 {
        return "0".into();
    }
    // The exponent after rounding to four digits (9999.6 is 1.000e4).
    let e = format!("{x:.3e}");
    let (mantissa, exponent) = e.split_once('e').expect("`{:e}` writes an exponent");
    let exponent: i32 = exponent.parse().expect("`{:e}`'s exponent is an integer");
    if (-4..4).contains(&exponent) {
        let decimals = (3 - exponent) as usize;
        trim_fraction(&format!("{x:.decimals$}")).into()
    } else {
        format!("{}e{exponent}", trim_fraction(mantissa))
    }
}

/// `s` without the trailing zeros of its fraction, nor a bare point.
fn trim_fraction(s: &str) -> &str {
    if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.')
    } else {
        s
    }
}

fn non_finite(x: f64) -> String {
    if x.is_nan() {
        "NaN".into()
    } else if x > 0.0 {
        "inf".into()
    } else {
        "-inf".into()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn three_decimals() {
        assert_eq!(fixed3(0.34667966), "0.347");
        assert_eq!(fixed3(-1.1972558), "-1.197");
        assert_eq!(fixed3(-10.7), "-10.7");
        assert_eq!(fixed3(3.0), "3");
        assert_eq!(fixed3(-0.0001), "0");
        assert_eq!(fixed3(-0.0), "0");
        assert_eq!(fixed3(f64::NAN), "NaN");
        assert_eq!(fixed3(f64::NEG_INFINITY), "-inf");
    }

    #[test]
    fn four_significant_digits() {
        assert_eq!(sig4(-5.5429516), "-5.543");
        assert_eq!(sig4(1.982080277371736e-1), "0.1982");
        assert_eq!(sig4(8.595551609147378e-6), "8.596e-6");
        assert_eq!(sig4(-347961.0 / 65536.0), "-5.309");
        assert_eq!(sig4(-347961.0), "-3.48e5");
        assert_eq!(sig4(1234.4), "1234");
        assert_eq!(sig4(9999.6), "1e4");
        assert_eq!(sig4(0.00012345), "0.0001234");
        assert_eq!(sig4(0.0), "0");
        assert_eq!(sig4(f64::INFINITY), "inf");
    }

    /// The reason [`fixed3`] is enough for an observation: the angles of two
    /// different counts of the finest encoder in the catalogue never print
    /// alike, anywhere in ±one turn.
    #[test]
    fn three_decimals_tell_every_count_of_the_finest_encoder_apart() {
        let finest = pada_core::servo::SERVOS
            .iter()
            .map(|m| m.encoding.position.unit_rad() as f64)
            .fold(f64::INFINITY, f64::min);
        assert!(finest >= 0.0015, "an encoder of {finest} rad a count needs a fourth decimal");
        let counts = (core::f64::consts::TAU / finest).ceil() as i64;
        let rad_per_count = finest;
        let mut printed: Vec<String> =
            (-counts..=counts).map(|k| fixed3(k as f64 * rad_per_count)).collect();
        let n = printed.len();
        printed.sort();
        printed.dedup();
        assert_eq!(printed.len(), n);
    }
}
