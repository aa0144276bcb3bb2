//! Argument checks: each failure is a `ValueError` that names the argument,
//! the value and the valid range.

use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::{PyFloat, PyList, PyTuple};

/// `ValueError("<name> = <value> is out of range: valid is <valid>")`.
pub fn out_of_range(name: &str, value: impl std::fmt::Display, valid: &str) -> PyErr {
    PyValueError::new_err(format!(
        "{name} = {value} is out of range: valid is {valid}"
    ))
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
        Err(out_of_range(
            name,
            value,
            &format!("{lo} <= {name} <= {hi}"),
        ))
    }
}

/// Reads `n` finite numbers from `obj` into `out`: a sequence (list, tuple,
/// numpy array) of length `n`, or a single number when `n == 1`. Nothing is
/// written unless all are valid.
pub fn finite_values(
    name: &str,
    obj: &Bound<'_, PyAny>,
    n: usize,
    what: &str,
    out: &mut [f64],
) -> PyResult<()> {
    if let Ok(f) = obj.cast::<PyFloat>() {
        return single(name, f.value(), n, what, out);
    }
    if let Ok(list) = obj.cast::<PyList>() {
        return items(name, list.len(), |i| list.get_item(i), n, what, out);
    }
    if let Ok(t) = obj.cast::<PyTuple>() {
        return items(name, t.len(), |i| t.get_item(i), n, what, out);
    }
    // A numpy array (or anything with tolist): one call turns it into
    // Python numbers, far cheaper than iterating the array.
    if let Ok(listed) = obj.call_method0(pyo3::intern!(obj.py(), "tolist")) {
        if let Ok(list) = listed.cast::<PyList>() {
            if list.iter().all(|x| !x.is_instance_of::<PyList>()) {
                return items(name, list.len(), |i| list.get_item(i), n, what, out);
            }
            return Err(PyValueError::new_err(format!(
                "{name} must be one-dimensional: {n} numbers ({what})"
            )));
        }
        if let Ok(x) = listed.extract::<f64>() {
            return single(name, x, n, what, out);
        }
    }
    if obj.len().is_ok() {
        let list =
            pyo3::types::PyList::new(obj.py(), obj.try_iter()?.collect::<PyResult<Vec<_>>>()?)?;
        return items(name, list.len(), |i| list.get_item(i), n, what, out);
    }
    // A number that is not a float (an int, a numpy scalar).
    let x: f64 = obj.extract().map_err(|_| {
        PyValueError::new_err(format!(
            "{name} must be a number or a sequence of {n} numbers ({what}), got {}",
            type_name(obj)
        ))
    })?;
    single(name, x, n, what, out)
}

fn items<'py>(
    name: &str,
    len: usize,
    get: impl Fn(usize) -> PyResult<Bound<'py, PyAny>>,
    n: usize,
    what: &str,
    out: &mut [f64],
) -> PyResult<()> {
    if len != n {
        return Err(PyValueError::new_err(format!(
            "{name} has {len} values, expected {n} ({what})"
        )));
    }
    let mut tmp = [0.0f64; 64];
    let tmp = &mut tmp[..n.min(64)];
    for i in 0..n {
        let item = get(i)?;
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
        if i < tmp.len() {
            tmp[i] = v;
        } else {
            out[i] = v;
        }
    }
    out[..tmp.len()].copy_from_slice(tmp);
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
