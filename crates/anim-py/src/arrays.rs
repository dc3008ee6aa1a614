//! Arrays in and out: every numpy input is checked here (type, dtype, shape, contiguity,
//! finiteness) with an error naming the argument, then copied into the `Vec`s the crates take;
//! every output is a new numpy array the caller owns (a copy, never a view of solver memory).

use numpy::{
    PyArray1, PyArray2, PyArrayDescrMethods, PyArrayDyn, PyArrayMethods, PyUntypedArray,
    PyUntypedArrayMethods,
};
use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;

/// The array behind `obj`: a numpy array as it is, anything else through `numpy.asarray`
/// (a list of floats becomes float64, a list of ints int64).
fn as_array<'py>(obj: &Bound<'py, PyAny>, name: &str) -> PyResult<Bound<'py, PyUntypedArray>> {
    if let Ok(a) = obj.cast::<PyUntypedArray>() {
        return Ok(a.clone());
    }
    let np = obj.py().import("numpy")?;
    let converted = np
        .call_method1("asarray", (obj,))
        .map_err(|e| PyTypeError::new_err(format!("{name}: cannot be read as an array ({e})")))?;
    converted
        .cast_into::<PyUntypedArray>()
        .map_err(|_| PyTypeError::new_err(format!("{name}: cannot be read as an array")))
}

/// Shape as text, `(n, 3)`.
fn shape_text(shape: &[usize]) -> String {
    let parts: Vec<String> = shape.iter().map(usize::to_string).collect();
    if parts.len() == 1 { format!("({},)", parts[0]) } else { format!("({})", parts.join(", ")) }
}

/// Checks the dimensions of `a` against `expected` (`None`: any length).
fn check_shape(
    a: &Bound<'_, PyUntypedArray>,
    name: &str,
    expected: &[Option<usize>],
) -> PyResult<Vec<usize>> {
    let shape = a.shape().to_vec();
    let ok =
        shape.len() == expected.len() && shape.iter().zip(expected).all(|(s, e)| e.is_none_or(|e| *s == e));
    if !ok {
        let want: Vec<String> =
            expected.iter().map(|e| e.map_or("n".to_string(), |e| e.to_string())).collect();
        return Err(PyValueError::new_err(format!(
            "{name}: expected an array of shape ({}), got shape {}",
            want.join(", "),
            shape_text(&shape)
        )));
    }
    Ok(shape)
}

/// The float64 values of `obj`, row-major, after checking its shape (`None`: any length), its
/// dtype (a numpy array must be float64: no silent cast), its layout (C-contiguous) and that
/// every value is finite. Returns the values and the shape.
pub fn floats(
    obj: &Bound<'_, PyAny>,
    name: &str,
    expected: &[Option<usize>],
) -> PyResult<(Vec<f64>, Vec<usize>)> {
    let was_array = obj.cast::<PyUntypedArray>().is_ok();
    let a = as_array(obj, name)?;
    let f64_type = numpy::dtype::<f64>(obj.py());
    if !a.dtype().is_equiv_to(&f64_type) {
        let kind = a.dtype().kind();
        // A list of ints is a list of numbers: take it as floats. A numpy array keeps its dtype.
        if was_array || !(kind == b'i' || kind == b'u') {
            return Err(PyTypeError::new_err(format!(
                "{name}: expected dtype float64, got {} (convert with .astype(numpy.float64))",
                a.dtype()
            )));
        }
    }
    let shape = check_shape(&a, name, expected)?;
    if !a.is_c_contiguous() {
        return Err(PyValueError::new_err(format!(
            "{name}: the array is not C-contiguous (pass numpy.ascontiguousarray({name}))"
        )));
    }
    let a = if a.dtype().is_equiv_to(&f64_type) {
        a
    } else {
        a.call_method1("astype", ("float64",))?.cast_into()?
    };
    let typed =
        a.cast::<PyArrayDyn<f64>>().map_err(|_| PyTypeError::new_err(format!("{name}: expected float64")))?;
    let ro = typed.try_readonly().map_err(|e| PyValueError::new_err(format!("{name}: {e}")))?;
    let values = ro.as_slice().map_err(|e| PyValueError::new_err(format!("{name}: {e}")))?.to_vec();
    if let Some(k) = values.iter().position(|x| !x.is_finite()) {
        let index = unravel(k, &shape);
        return Err(PyValueError::new_err(format!(
            "{name}: entry {index} is {}, every value must be finite",
            values[k]
        )));
    }
    Ok((values, shape))
}

/// A flat index as `[i, j]` text for the shape.
fn unravel(mut k: usize, shape: &[usize]) -> String {
    let mut idx = vec![0; shape.len()];
    for d in (0..shape.len()).rev() {
        let s = shape[d].max(1);
        idx[d] = k % s;
        k /= s;
    }
    format!("{idx:?}")
}

/// `(n, D)` float64 rows.
pub fn rows<const D: usize>(obj: &Bound<'_, PyAny>, name: &str) -> PyResult<Vec<[f64; D]>> {
    let (values, _) = floats(obj, name, &[None, Some(D)])?;
    Ok(values.chunks_exact(D).map(|c| std::array::from_fn(|i| c[i])).collect())
}

/// A float64 vector of any length, or of `len` when given.
///
/// The common case, a contiguous 1-D float64 array of the right length with finite values, is
/// copied at once (`q`, `v`, `a` of the rigid-body calls, made thousands of times from Python
/// loops); anything else goes through [`floats`], whose checks name what is wrong.
pub fn vector(obj: &Bound<'_, PyAny>, name: &str, len: Option<usize>) -> PyResult<Vec<f64>> {
    if let Ok(a) = obj.cast::<PyArray1<f64>>()
        && let Ok(values) = a.to_vec()
        && len.is_none_or(|n| values.len() == n)
        && values.iter().all(|x| x.is_finite())
    {
        return Ok(values);
    }
    Ok(floats(obj, name, &[len])?.0)
}

/// A fixed-size float64 vector (a point, a direction).
pub fn point<const D: usize>(obj: &Bound<'_, PyAny>, name: &str) -> PyResult<[f64; D]> {
    let v = vector(obj, name, Some(D))?;
    Ok(std::array::from_fn(|i| v[i]))
}

/// `(n, D)` non-negative integer indices below `bound` (mesh elements), from any integer dtype.
pub fn indices<const D: usize>(
    obj: &Bound<'_, PyAny>,
    name: &str,
    bound: usize,
) -> PyResult<Vec<[usize; D]>> {
    let flat = index_values(obj, name, &[None, Some(D)], bound)?;
    Ok(flat.chunks_exact(D).map(|c| std::array::from_fn(|i| c[i])).collect())
}

/// One index below `bound` (a Python int) or a list of them, for the argument `name`.
pub fn index_or_list(obj: &Bound<'_, PyAny>, name: &str, bound: usize) -> PyResult<Vec<usize>> {
    match obj.extract::<i64>() {
        Ok(i) if i >= 0 && (i as u64) < bound as u64 => Ok(vec![i as usize]),
        Ok(i) => Err(PyValueError::new_err(format!("{name}: {i} is outside 0..{bound}"))),
        Err(_) => index_list(obj, name, bound),
    }
}

/// A time step: positive and finite, or a `ValueError` naming `dt`.
pub fn time_step(dt: f64) -> PyResult<f64> {
    if dt > 0.0 && dt.is_finite() {
        Ok(dt)
    } else {
        Err(PyValueError::new_err(format!("dt: must be positive and finite, got {dt}")))
    }
}

/// A list of non-negative integer indices below `bound`.
pub fn index_list(obj: &Bound<'_, PyAny>, name: &str, bound: usize) -> PyResult<Vec<usize>> {
    index_values(obj, name, &[None], bound)
}

fn index_values(
    obj: &Bound<'_, PyAny>,
    name: &str,
    expected: &[Option<usize>],
    bound: usize,
) -> PyResult<Vec<usize>> {
    let a = as_array(obj, name)?;
    let kind = a.dtype().kind();
    // An empty list arrives as float64: no value to misread, take it as no index.
    let empty = a.shape().iter().product::<usize>() == 0;
    if !(kind == b'i' || kind == b'u' || empty) {
        return Err(PyTypeError::new_err(format!(
            "{name}: expected an integer array, got dtype {}",
            a.dtype()
        )));
    }
    let shape = if empty && a.ndim() == 1 && expected.len() == 2 {
        vec![0, expected[1].unwrap_or(0)]
    } else {
        check_shape(&a, name, expected)?
    };
    if empty {
        return Ok(Vec::new());
    }
    if !a.is_c_contiguous() {
        return Err(PyValueError::new_err(format!(
            "{name}: the array is not C-contiguous (pass numpy.ascontiguousarray({name}))"
        )));
    }
    let a64 = a.call_method1("astype", ("int64",))?;
    let typed = a64
        .cast::<PyArrayDyn<i64>>()
        .map_err(|_| PyTypeError::new_err(format!("{name}: expected integers")))?;
    let ro = typed.try_readonly().map_err(|e| PyValueError::new_err(format!("{name}: {e}")))?;
    let values = ro.as_slice().map_err(|e| PyValueError::new_err(format!("{name}: {e}")))?;
    let mut out = Vec::with_capacity(values.len());
    for (k, &i) in values.iter().enumerate() {
        if i < 0 || i as u64 >= bound as u64 {
            return Err(PyValueError::new_err(format!(
                "{name}: entry {} is {i}, outside 0..{bound}",
                unravel(k, &shape)
            )));
        }
        out.push(i as usize);
    }
    Ok(out)
}

/// A new `(n, D)` float64 array from flat row-major values (a copy).
pub fn to_rows<'py>(py: Python<'py>, values: &[f64], d: usize) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let n = values.len() / d.max(1);
    PyArray1::from_slice(py, &values[..n * d]).reshape([n, d])
}

/// A new float64 array of any shape from flat row-major values (a copy).
pub fn to_array<'py>(
    py: Python<'py>,
    values: &[f64],
    shape: &[usize],
) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
    PyArray1::from_slice(py, values).reshape(shape.to_vec())
}

/// A new `(n, D)` int64 array from index rows (a copy).
pub fn to_index_rows<'py, const D: usize>(
    py: Python<'py>,
    rows: &[[usize; D]],
) -> PyResult<Bound<'py, PyArray2<i64>>> {
    let flat: Vec<i64> = rows.iter().flatten().map(|&i| i as i64).collect();
    PyArray1::from_vec(py, flat).reshape([rows.len(), D])
}

/// A mesh as new arrays: vertices (n, 3) float64 and elements (m, k) int64.
pub type MeshArrays<'py> = (Bound<'py, PyArray2<f64>>, Bound<'py, PyArray2<i64>>);
