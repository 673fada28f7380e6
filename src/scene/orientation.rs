//! An orientation given as a quaternion `[w, x, y, z]` (a `[[body]]`'s `orientation`, a body file's
//! `qw, qx, qy, qz` columns): it must be a unit quaternion up to [`QUATERNION_NORM_TOLERANCE`], and is
//! normalised within it.

use crate::math::{Real, Rotation};

/// How far from 1 the norm of a given quaternion may be. A quaternion typed with a handful of digits is
/// unit to ~1e-7; within this tolerance it is normalised, and a farther one is refused as a mistake rather
/// than silently rescaled.
pub const QUATERNION_NORM_TOLERANCE: Real = 1e-6;

/// The rotation of `[w, x, y, z]`, normalised, or the norm when it is not within
/// [`QUATERNION_NORM_TOLERANCE`] of 1 (or not finite).
pub fn unit_quaternion([w, x, y, z]: [Real; 4]) -> Result<Rotation, Real> {
    let norm = (w * w + x * x + y * y + z * z).sqrt();
    if !norm.is_finite() || (norm - 1.0).abs() > QUATERNION_NORM_TOLERANCE {
        return Err(norm);
    }
    Ok(Rotation::from_quaternion(nalgebra::Quaternion::new(
        w, x, y, z,
    )))
}
