//! Argument checks: each failure is a `ValueError` that names the argument,
//! the value and the valid range.

use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyFloat;

/// `ValueError("<name> = <value> is out of range: valid is <valid>")`.
pub fn out_of_range(name: &str, value: impl std::fmt::Display, valid: &str) -> PyErr {
    PyValueError::new_err(format!("{name} = {value} is out of range: valid is {valid}"))
}

/// A control rate in Hz: finite, `0 < rate_hz <= 1e6` (as `pada mtbf --rate`).
pub fn rate_hz(name: &str, rate: f64) -> PyResult<f64> {
    if rate.is_finite() && rate > 0.0 && rate <= 1e6 {
        Ok(rate)
    } else {
        Err(out_of_range(name, rate, "0 < rate_hz <= 1000000 (Hz)"))
    }
}

/// A count in `lo..=hi`.
pub fn count(name: &str, value: i64, lo: i64, hi: i64) -> PyResult<usize> {
    if (lo..=hi).contains(&value) {
        Ok(value as usize)
    } else {
        Err(out_of_range(name, value, &format!("{lo} <= {name} <= {hi}")))
    }
}

/// Reads `n` finite numbers from `obj` into `out`: a sequence (list, tuple,
/// numpy array) of length `n`, or a single number when `n == 1`. Nothing is
/// written unless all are valid.
pub fn finite_values(name: &str, obj: &Bound<'_, PyAny>, n: usize, what: &str, out: &mut [f64]) -> PyResult<()> {
    if let Ok(f) = obj.cast::<PyFloat>() {
        return single(name, f.value(), n, what, out);
    }
    let Ok(len) = obj.len() else {
        // A number that is not a float (an int, a numpy scalar).
        let x: f64 = obj.extract().map_err(|_| {
            PyValueError::new_err(format!(
                "{name} must be a number or a sequence of {n} numbers ({what}), got {}",
                type_name(obj)
            ))
        })?;
        return single(name, x, n, what, out);
    };
    if len != n {
        return Err(PyValueError::new_err(format!(
            "{name} has {len} values, expected {n} ({what})"
        )));
    }
    for (i, item) in obj.try_iter()?.enumerate() {
        let item = item?;
        let v: f64 = item.extract().map_err(|_| {
            PyValueError::new_err(format!(
                "{name}[{i}] is not a number ({}); expected {n} numbers ({what})",
                type_name(&item)
            ))
        })?;
        if !v.is_finite() {
            return Err(PyValueError::new_err(format!(
                "{name}[{i}] = {v} is not finite: valid is a finite number ({what})"
            )));
        }
        out[i] = v;
    }
    Ok(())
}

fn single(name: &str, v: f64, n: usize, what: &str, out: &mut [f64]) -> PyResult<()> {
    if n != 1 {
        return Err(PyValueError::new_err(format!(
            "{name} is one number, expected {n} values ({what})"
        )));
    }
    if !v.is_finite() {
        return Err(PyValueError::new_err(format!(
            "{name} = {v} is not finite: valid is a finite number ({what})"
        )));
    }
    out[0] = v;
    Ok(())
}

fn type_name(obj: &Bound<'_, PyAny>) -> String {
    obj.get_type()
        .name()
        .map(|n| n.to_string())
        .unwrap_or_else(|_| "?".into())
}
