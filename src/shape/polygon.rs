//! Planar polygon helpers shared by the hull builder and the polyhedron: Newell's normal and plane fit.

use crate::math::{Point, Real, Vector};

/// Newell's area-weighted normal of the polygon `loop_` (indices into `vertices`, counter-clockwise seen from
/// the side the normal points to). The returned vector's norm is twice the polygon's area; it is robust for
/// nearly-degenerate and slightly non-planar polygons because every edge contributes (Newell's method, as
/// described by Sutherland, Sproull & Schumacker 1974). Coordinates are taken relative to the loop's mean to
/// avoid cancellation far from the origin.
pub(crate) fn newell_normal(vertices: &[Point], loop_: &[u32]) -> Vector {
    let n = loop_.len();
    let mut mean = Vector::zeros();
    for &i in loop_ {
        mean += vertices[i as usize].coords;
    }
    mean /= n as Real;
    let mut normal = Vector::zeros();
    for k in 0..n {
        let a = vertices[loop_[k] as usize].coords - mean;
        let b = vertices[loop_[(k + 1) % n] as usize].coords - mean;
        normal += a.cross(&b);
    }
    normal
}

/// The supporting plane of a face of a convex solid: the unit Newell normal of the face loop and the offset
/// `max_v n·v` over all `vertices` of the solid, so that the whole solid satisfies `n·x ≤ offset`.
/// Returns `None` when the loop has zero area.
pub(crate) fn supporting_plane(vertices: &[Point], loop_: &[u32]) -> Option<(Vector, Real)> {
    let normal = newell_normal(vertices, loop_);
    let norm = normal.norm();
    if !norm.is_finite() || norm <= 0.0 {
        return None;
    }
    let normal = normal / norm;
    let offset = vertices
        .iter()
        .map(|v| normal.dot(&v.coords))
        .fold(Real::NEG_INFINITY, Real::max);
    Some((normal, offset))
}
