//! numpy arrays to and from the core's splines, and JSON values (reports, certificates,
//! events) to Python objects.

use numpy::ndarray::{Array1, Array2, ArrayD};
use numpy::{IntoPyArray, PyArray1, PyArray2, PyArrayDyn, PyArrayMethods, PyReadonlyArrayDyn};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};
use serde_json::Value;
use winslow::{Error, Point};

use crate::errors::{invalid, IntoPy};

/// `obj` as a float64 numpy array (`numpy.asarray(obj, dtype=float64)`: a view when it
/// already is one, no copy).
pub fn f64_array<'py>(py: Python<'py>, obj: &Bound<'py, PyAny>) -> PyResult<PyReadonlyArrayDyn<'py, f64>> {
    let arr = py.import("numpy")?.call_method1("asarray", (obj, "float64"))?;
    let arr = arr.cast_into::<PyArrayDyn<f64>>().map_err(PyErr::from)?;
    Ok(arr.readonly())
}

/// Points from an `(n, 2)` array (`what` names it in the error).
pub fn points(py: Python<'_>, obj: &Bound<'_, PyAny>, what: &str) -> PyResult<Vec<Point>> {
    let a = f64_array(py, obj)?;
    let v = a.as_array();
    if v.ndim() != 2 || v.shape()[1] != 2 {
        return Err(invalid(format!("{what} must be an array of shape (n, 2), got shape {:?}", v.shape())));
    }
    Ok(v.outer_iter().map(|r| [r[0], r[1]]).collect())
}

/// A vector from a one-dimensional array.
pub fn vector(py: Python<'_>, obj: &Bound<'_, PyAny>, what: &str) -> PyResult<Vec<f64>> {
    let a = f64_array(py, obj)?;
    let v = a.as_array();
    if v.ndim() != 1 {
        return Err(invalid(format!("{what} must be a one-dimensional array, got shape {:?}", v.shape())));
    }
    Ok(v.iter().copied().collect())
}

/// `(n, 2)` array of points.
pub fn points_array<'py>(py: Python<'py>, p: &[Point]) -> Bound<'py, PyArray2<f64>> {
    let flat: Vec<f64> = p.iter().flatten().copied().collect();
    // the shape matches the length by construction
    Array2::from_shape_vec((p.len(), 2), flat).unwrap_or_default().into_pyarray(py)
}

/// One-dimensional array.
pub fn vector_array<'py>(py: Python<'py>, v: &[f64]) -> Bound<'py, PyArray1<f64>> {
    Array1::from_vec(v.to_vec()).into_pyarray(py)
}

/// Parameters `(u, v)` of the same shape, each in `[0, 1]` and finite: the flat values
/// and the common shape.
pub fn parameters<'py>(
    py: Python<'py>,
    u: &Bound<'py, PyAny>,
    v: &Bound<'py, PyAny>,
) -> PyResult<(Vec<[f64; 2]>, Vec<usize>)> {
    let (u, v) = (f64_array(py, u)?, f64_array(py, v)?);
    let (u, v) = (u.as_array(), v.as_array());
    if u.shape() != v.shape() {
        return Err(invalid(format!("u and v must have the same shape, got {:?} and {:?}", u.shape(), v.shape())));
    }
    let out: Vec<[f64; 2]> = u.iter().zip(v.iter()).map(|(&a, &b)| [a, b]).collect();
    if let Some(p) = out.iter().find(|p| !p.iter().all(|x| (0.0..=1.0).contains(x))) {
        return Err(crate::errors::to_py(&Error::Range {
            what: format!("the parameter ({}, {}) is outside the parameter domain [0, 1]^2", p[0], p[1]),
        }));
    }
    Ok((out, u.shape().to_vec()))
}

/// Values on a grid of `shape` with `tail` trailing axes.
pub fn shaped<'py>(
    py: Python<'py>,
    values: Vec<f64>,
    shape: &[usize],
    tail: &[usize],
) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
    let full: Vec<usize> = shape.iter().chain(tail).copied().collect();
    let a = ArrayD::from_shape_vec(full, values).map_err(|e| invalid(e.to_string()))?;
    Ok(a.into_pyarray(py))
}

/// A JSON value as Python objects (dicts, lists, floats, ints, strings, None).
pub fn json_to_py<'py>(py: Python<'py>, v: &Value) -> PyResult<Bound<'py, PyAny>> {
    Ok(match v {
        Value::Null => py.None().into_bound(py),
        Value::Bool(b) => b.into_pyobject(py)?.to_owned().into_any(),
        Value::Number(n) => match (n.as_i64(), n.as_u64()) {
            (Some(i), _) => i.into_pyobject(py)?.into_any(),
            (None, Some(u)) => u.into_pyobject(py)?.into_any(),
            _ => n.as_f64().unwrap_or(f64::NAN).into_pyobject(py)?.into_any(),
        },
        Value::String(s) => s.into_pyobject(py)?.into_any(),
        Value::Array(a) => {
            let items = a.iter().map(|x| json_to_py(py, x)).collect::<PyResult<Vec<_>>>()?;
            PyList::new(py, items)?.into_any()
        }
        Value::Object(m) => {
            let d = PyDict::new(py);
            for (k, x) in m {
                d.set_item(k, json_to_py(py, x)?)?;
            }
            d.into_any()
        }
    })
}

/// A serializable value as Python objects (through [`json_to_py`]).
pub fn to_py<'py, T: serde::Serialize>(py: Python<'py>, x: &T) -> PyResult<Bound<'py, PyAny>> {
    let v = serde_json::to_value(x).map_err(|e| Error::Invalid(e.to_string())).py_err()?;
    json_to_py(py, &v)
}
