//! How a bundle writes an `f64` value: a number, except that JSON has no
//! number for NaN and the infinities, so in JSON (and any other
//! human-readable format) those are the strings `"NaN"`, `"inf"` and
//! `"-inf"`, as the wire protocol and recordings write them
//! (`docs/protocol.md`). Binary formats carry the float itself.
//!
//! A condition may compare with `inf` or `-inf` (`docs/language.md`, 2.5):
//! serde_json would write those as `null`, and the bundle of a program
//! without errors would not read back. Finite values are written exactly
//! as before, so bundles without such a value are unchanged.

use serde::de::{self, Visitor};
use serde::{Deserializer, Serializer};
use std::fmt;

/// The name of a non-finite value, as the language spells it.
fn name(x: f64) -> &'static str {
    if x.is_nan() {
        "NaN"
    } else if x > 0.0 {
        "inf"
    } else {
        "-inf"
    }
}

pub(super) fn serialize<S: Serializer>(x: &f64, s: S) -> Result<S::Ok, S::Error> {
    if x.is_finite() || !s.is_human_readable() {
        s.serialize_f64(*x)
    } else {
        s.serialize_str(name(*x))
    }
}

pub(super) fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<f64, D::Error> {
    if d.is_human_readable() {
        d.deserialize_any(Float)
    } else {
        d.deserialize_f64(Float)
    }
}

struct Float;

impl Visitor<'_> for Float {
    type Value = f64;

    fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
        f.write_str("a number, or \"NaN\", \"inf\" or \"-inf\"")
    }

    fn visit_f64<E: de::Error>(self, x: f64) -> Result<f64, E> {
        Ok(x)
    }

    fn visit_i64<E: de::Error>(self, x: i64) -> Result<f64, E> {
        Ok(x as f64)
    }

    fn visit_u64<E: de::Error>(self, x: u64) -> Result<f64, E> {
        Ok(x as f64)
    }

    fn visit_str<E: de::Error>(self, s: &str) -> Result<f64, E> {
        match s {
            "NaN" => Ok(f64::NAN),
            "inf" => Ok(f64::INFINITY),
            "-inf" => Ok(f64::NEG_INFINITY),
            _ => Err(E::invalid_value(de::Unexpected::Str(s), &self)),
        }
    }
}

#[cfg(test)]
mod tests {
    use crate::Value;

    #[test]
    fn json_writes_non_finite_values_by_name_and_reads_them_back() {
        for (x, text) in [(f64::INFINITY, r#"{"f64":"inf"}"#), (f64::NEG_INFINITY, r#"{"f64":"-inf"}"#)] {
            let json = serde_json::to_string(&Value::F64(x)).unwrap();
            assert_eq!(json, text);
            assert_eq!(serde_json::from_str::<Value>(&json).unwrap(), Value::F64(x));
        }
        let nan = serde_json::to_string(&Value::F64(f64::NAN)).unwrap();
        assert_eq!(nan, r#"{"f64":"NaN"}"#);
        assert!(matches!(serde_json::from_str::<Value>(&nan).unwrap(), Value::F64(x) if x.is_nan()));
    }

    #[test]
    fn finite_values_are_numbers_as_before() {
        assert_eq!(serde_json::to_string(&Value::F64(0.5)).unwrap(), r#"{"f64":0.5}"#);
        assert_eq!(serde_json::from_str::<Value>(r#"{"f64":3}"#).unwrap(), Value::F64(3.0));
        assert_eq!(serde_json::from_str::<Value>(r#"{"f64":-2}"#).unwrap(), Value::F64(-2.0));
        for bad in [r#"{"f64":"Inf"}"#, r#"{"f64":null}"#, r#"{"f64":true}"#] {
            assert!(serde_json::from_str::<Value>(bad).is_err(), "{bad}");
        }
    }
}
