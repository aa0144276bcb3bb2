//! Floating-point numbers stored exactly in JSON, for `serde(with = ...)`.
//!
//! A merged report must equal the local one byte for byte, so a result read
//! back from its file must be the same `f64` bit for bit. serde_json writes
//! the shortest representation that parses back to the same number (ryu)
//! and, with its `float_roundtrip` feature, parses it back exactly; but it
//! writes NaN and ±∞ as `null`, and a trial's rise time can be NaN and its
//! MTBF ∞. Finite values are therefore stored as JSON numbers and the
//! others as the strings `"NaN"`, `"inf"` and `"-inf"`.

use serde::de::{self, Visitor};
use serde::{Deserialize, Deserializer, Serialize, Serializer};
use std::fmt;

/// `f64` fields: `#[serde(with = "crate::plan::exact::f64")]`.
pub mod f64 {
    use super::*;

    /// Writes a finite number as a number, the others by name.
    pub fn serialize<S: Serializer>(x: &::core::primitive::f64, s: S) -> Result<S::Ok, S::Error> {
        if x.is_finite() {
            s.serialize_f64(*x)
        } else if x.is_nan() {
            s.serialize_str("NaN")
        } else if *x > 0.0 {
            s.serialize_str("inf")
        } else {
            s.serialize_str("-inf")
        }
    }

    /// Reads what [`serialize`] wrote.
    pub fn deserialize<'de, D: Deserializer<'de>>(
        d: D,
    ) -> Result<::core::primitive::f64, D::Error> {
        d.deserialize_any(ExactVisitor)
    }
}

/// `Option<f64>` fields: `#[serde(with = "crate::plan::exact::opt_f64")]`
/// (with `#[serde(default)]` when the field may be absent).
pub mod opt_f64 {
    use super::*;

    /// `None` as `null`, a value as [`super::f64::serialize`] writes it.
    pub fn serialize<S: Serializer>(
        x: &Option<::core::primitive::f64>,
        s: S,
    ) -> Result<S::Ok, S::Error> {
        match x {
            Some(v) => s.serialize_some(&Exact(*v)),
            None => s.serialize_none(),
        }
    }

    /// Reads what [`serialize`] wrote.
    pub fn deserialize<'de, D: Deserializer<'de>>(
        d: D,
    ) -> Result<Option<::core::primitive::f64>, D::Error> {
        Ok(Option::<Exact>::deserialize(d)?.map(|e| e.0))
    }
}

/// A list of f64, each exact as [`f64`](mod@self::f64) writes it.
pub mod vec_f64 {
    use super::*;

    /// Writes each value as [`f64`](mod@super::f64) does.
    pub fn serialize<S: Serializer>(x: &[::core::primitive::f64], s: S) -> Result<S::Ok, S::Error> {
        s.collect_seq(x.iter().map(|v| Exact(*v)))
    }

    /// Reads each value as [`f64`](mod@super::f64) does.
    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<Vec<::core::primitive::f64>, D::Error> {
        Ok(Vec::<Exact>::deserialize(d)?.into_iter().map(|e| e.0).collect())
    }
}

/// One exactly stored `f64`.
struct Exact(f64);

impl Serialize for Exact {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        self::f64::serialize(&self.0, s)
    }
}

impl<'de> Deserialize<'de> for Exact {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        d.deserialize_any(ExactVisitor).map(Exact)
    }
}

struct ExactVisitor;

impl Visitor<'_> for ExactVisitor {
    type Value = f64;

    fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
        f.write_str("a number or one of \"NaN\", \"inf\", \"-inf\"")
    }

    fn visit_f64<E: de::Error>(self, v: f64) -> Result<f64, E> {
        Ok(v)
    }

    fn visit_u64<E: de::Error>(self, v: u64) -> Result<f64, E> {
        Ok(v as f64)
    }

    fn visit_i64<E: de::Error>(self, v: i64) -> Result<f64, E> {
        Ok(v as f64)
    }

    fn visit_str<E: de::Error>(self, v: &str) -> Result<f64, E> {
        match v {
            "NaN" => Ok(f64::NAN),
            "inf" => Ok(f64::INFINITY),
            "-inf" => Ok(f64::NEG_INFINITY),
            _ => Err(E::invalid_value(de::Unexpected::Str(v), &self)),
        }
    }
}

#[cfg(test)]
mod tests {
    use serde::{Deserialize, Serialize};

    #[derive(Debug, Serialize, Deserialize)]
    struct Both {
        #[serde(with = "super::f64")]
        x: f64,
        #[serde(with = "super::opt_f64")]
        y: Option<f64>,
    }

    fn round_trip(x: f64, y: Option<f64>) -> (f64, Option<f64>) {
        let text = serde_json::to_string(&Both { x, y }).unwrap();
        let b: Both = serde_json::from_str(&text).unwrap();
        (b.x, b.y)
    }

    #[test]
    fn every_kind_of_value_comes_back_bit_for_bit() {
        // Values whose shortest decimal form the default (fast) parser of
        // serde_json can read one ULP off, and the non-finite ones.
        let values = [
            0.1,
            -785.231_712_341_234_5,
            1.0e-310,
            f64::MAX,
            f64::MIN_POSITIVE,
            -0.0,
            2.225_073_858_507_201e-308,
            9_007_199_254_740_993.0,
            f64::INFINITY,
            f64::NEG_INFINITY,
        ];
        for &v in &values {
            let (x, y) = round_trip(v, Some(v));
            assert_eq!(x.to_bits(), v.to_bits(), "{v:e}");
            assert_eq!(y.map(f64::to_bits), Some(v.to_bits()), "{v:e}");
        }
        let (x, y) = round_trip(f64::NAN, None);
        assert!(x.is_nan());
        assert_eq!(y, None);
        // Many values from a generator: every bit pattern of a finite f64.
        let mut z = 0x9E37_79B9_7F4A_7C15u64;
        for _ in 0..20_000 {
            z = crate::seed::splitmix64(z);
            let v = f64::from_bits(z);
            if v.is_finite() {
                assert_eq!(round_trip(v, None).0.to_bits(), v.to_bits(), "{v:e}");
            }
        }
    }

    #[test]
    fn an_unknown_name_is_refused() {
        let e = serde_json::from_str::<Both>(r#"{"x": "infinity", "y": null}"#).unwrap_err();
        assert!(e.to_string().contains("\"NaN\", \"inf\", \"-inf\""), "{e}");
    }
}
