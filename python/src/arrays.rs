//! Conversion of Python inputs (numpy arrays, lists, tuples) into engine values, with a `ValueError` that
//! names the argument and the problem for every input the engine cannot take: a wrong shape, a dtype that
//! is not a real number, a NaN or an infinity, a quaternion that is not of unit length.

use numpy::{
    PyArrayDescrMethods, PyArrayDyn, PyArrayMethods, PyUntypedArray, PyUntypedArrayMethods,
};
use polydem::math::{Point, Pose, Real, Rotation, Vector};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;

/// How far a quaternion's norm may be from 1 before it is refused rather than normalised: far above the
/// rounding of any quaternion written out in full precision, far below a mistake.
const QUATERNION_NORM_TOLERANCE: Real = 1e-6;

fn value_error(what: &str, message: impl std::fmt::Display) -> PyErr {
    PyValueError::new_err(format!("{what}: {message}"))
}

/// Any array-like of real numbers (integer or floating dtype) as its shape and its float64 values in
/// C order.
fn real_array(obj: &Bound<'_, PyAny>, what: &str) -> PyResult<(Vec<usize>, Vec<Real>)> {
    let numpy = obj.py().import("numpy")?;
    let array = numpy
        .call_method1("asarray", (obj,))
        .map_err(|e| value_error(what, format!("not an array of numbers ({e})")))?;
    let untyped = array.cast::<PyUntypedArray>()?;
    let dtype = untyped.dtype();
    if !matches!(dtype.kind(), b'i' | b'u' | b'f') {
        return Err(value_error(
            what,
            format!("expected real numbers, got an array of dtype {dtype}"),
        ));
    }
    let floats = numpy.call_method1("ascontiguousarray", (untyped, "float64"))?;
    let floats = floats.cast::<PyArrayDyn<Real>>()?.readonly();
    let values = floats
        .as_slice()
        .map_err(|e| value_error(what, e))?
        .to_vec();
    Ok((floats.shape().to_vec(), values))
}

/// A shape as Python writes it: `(4, 2)`, `(3,)`.
fn shape_text(shape: &[usize]) -> String {
    match shape {
        [n] => format!("({n},)"),
        _ => {
            let dims: Vec<String> = shape.iter().map(|d| d.to_string()).collect();
            format!("({})", dims.join(", "))
        }
    }
}

fn check_finite(values: &[Real], what: &str) -> PyResult<()> {
    match values.iter().position(|x| !x.is_finite()) {
        Some(i) => Err(value_error(
            what,
            format!("element {i} is not finite ({})", values[i]),
        )),
        None => Ok(()),
    }
}

/// An (N, K) array of finite numbers, as N rows; `item` names a row in messages ("point", "pose").
pub fn rows<const K: usize>(
    obj: &Bound<'_, PyAny>,
    what: &str,
    item: &str,
) -> PyResult<Vec<[Real; K]>> {
    let (shape, values) = real_array(obj, what)?;
    if shape.len() != 2 || shape[1] != K {
        return Err(value_error(
            what,
            format!(
                "expected an array of shape (N, {K}), got shape {}",
                shape_text(&shape)
            ),
        ));
    }
    if let Some(i) = values.iter().position(|x| !x.is_finite()) {
        let row = &values[i / K * K..i / K * K + K];
        return Err(value_error(
            what,
            format!("{item} {} has a non-finite value {row:?}", i / K),
        ));
    }
    Ok(values
        .chunks_exact(K)
        .map(|c| std::array::from_fn(|k| c[k]))
        .collect())
}

/// An (N, 3) array of finite points.
pub fn points(obj: &Bound<'_, PyAny>, what: &str) -> PyResult<Vec<Point>> {
    let rows = rows::<3>(obj, what, "point")?;
    Ok(rows.iter().map(|c| Point::new(c[0], c[1], c[2])).collect())
}

/// A vector of `N` finite numbers.
pub fn fixed<const N: usize>(obj: &Bound<'_, PyAny>, what: &str) -> PyResult<[Real; N]> {
    let (shape, values) = real_array(obj, what)?;
    if shape != [N] {
        return Err(value_error(
            what,
            format!(
                "expected an array of shape ({N},), got shape {}",
                shape_text(&shape)
            ),
        ));
    }
    check_finite(&values, what)?;
    let mut out = [0.0; N];
    out.copy_from_slice(&values);
    Ok(out)
}

/// A unit quaternion given as (w, x, y, z).
pub fn quaternion(obj: &Bound<'_, PyAny>, what: &str) -> PyResult<Rotation> {
    unit_quaternion(fixed::<4>(obj, what)?, what)
}

/// The rotation of a quaternion (w, x, y, z) of unit length (to [`QUATERNION_NORM_TOLERANCE`]).
pub fn unit_quaternion([w, x, y, z]: [Real; 4], what: &str) -> PyResult<Rotation> {
    let q = nalgebra::Quaternion::new(w, x, y, z);
    if (q.norm() - 1.0).abs() > QUATERNION_NORM_TOLERANCE {
        return Err(value_error(
            what,
            format!(
                "quaternion (w, x, y, z) = {:?} has norm {}, expected 1 (tolerance {QUATERNION_NORM_TOLERANCE:e})",
                [w, x, y, z],
                q.norm()
            ),
        ));
    }
    Ok(Rotation::new_normalize(q))
}

/// A pose given as `(position[3], quaternion[4] w,x,y,z)`.
pub fn pose(obj: &Bound<'_, PyAny>, what: &str) -> PyResult<Pose> {
    let (position, orientation): (Bound<'_, PyAny>, Bound<'_, PyAny>) =
        obj.extract().map_err(|_| {
            value_error(
                what,
                "expected a pair (position[3], quaternion[4] as w, x, y, z)",
            )
        })?;
    let [x, y, z] = fixed::<3>(&position, &format!("{what} position"))?;
    let rotation = quaternion(&orientation, &format!("{what} quaternion"))?;
    Ok(Pose::from_parts(Vector::new(x, y, z).into(), rotation))
}
