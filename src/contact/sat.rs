//! The exact separating-axis oracle for two convex polyhedra, used by the tests and as the fallback of
//! GJK/EPA.
//!
//! Overlap (Feng & Tan's Minkowski overlap): the Minkowski difference M = A ⊖ B of two convex polytopes is a
//! polytope whose facet normals are among (i) the outward face normals of A, (ii) the negated outward face
//! normals of B and (iii) the cross products of an edge direction of A with an edge direction of B, of
//! either sign. When the origin is inside M, the depth δ_M = min over unit n of h_M(n) is attained at a facet
//! normal, so the minimum of h_A(n) + h_B(−n) over these finitely many candidate axes, each evaluated with
//! brute-force supports, is the exact overlap and the minimising axis the exact normal.
//!
//! Edge–edge axes are built as n = û × ŵ with ŵ the part of v̂ orthogonal to û, re-orthogonalised, so that
//! n is orthogonal to both edges to round-off even for nearly parallel edges (the ill-conditioned part of
//! the axis is then only a rotation about the common edge direction, to which the support distance is
//! insensitive). Only pairs whose sine is below 1e-12 are skipped: their sliver facet is at most 1e-12 of the
//! edge length wide, which bounds the error of skipping it.
//!
//! Distance: for a separated pair the candidate axes give only a lower bound of the gap, so the exact
//! distance is computed by exhaustion over feature pairs (every vertex of A against every face triangle of
//! B and vice versa, every edge of A against every edge of B): the closest points of two disjoint convex
//! polytopes always include a pair of this kind.
//!
//! Contact points: along the optimal axis n with overlap s, the supporting features F_A (vertices of A within
//! 1e-12 L of h_A(n)) and F_B are collected and the closest points between hull(F_A) and hull(F_B) + s n
//! computed; they coincide (up to round-off) and give c1 on A and c2 = c1 − s n on B.
//!
//! Cost: O(F + E_A E_B) support evaluations of O(V) each, plus O(V T + E²) for the distance: fine as an oracle
//! and as a rare fallback, not a hot path. It allocates.

use super::features::{closest_on_triangle, closest_point_sets, closest_segments};
use super::tolerances::{pair_length_scale, ContactTolerances};
use super::{ContactGeometry, ContactKind, SolverStatus};
use crate::math::{Point, Pose, Real, Vector};
use crate::shape::SupportMap;

/// The view of a convex polytope that the exact oracle needs (all in the shape's local frame).
pub trait Polytope: SupportMap {
    /// The vertices (local frame, m).
    fn vertices(&self) -> &[Point];
    /// The same vertices as columns for the vectorised support scan.
    fn vertex_columns(&self) -> &crate::shape::VertexColumns;
    /// Number of faces.
    fn num_faces(&self) -> usize;
    /// Outward unit normal of face `i`.
    fn face_normal(&self, i: usize) -> Vector;
    /// Plane offset of face `i`: the face lies in {x : normal·x = offset}.
    fn face_offset(&self, i: usize) -> Real;
    /// Vertex indices of face `i`, in order around the face (a convex polygon).
    fn face_vertices(&self, i: usize) -> &[u32];
    /// Each edge once, as a pair of vertex indices.
    fn edges(&self) -> &[[u32; 2]];
    /// The vertices sharing an edge with vertex `v` (the edge graph of [`Self::edges`] as adjacency lists).
    fn neighbors(&self, v: u32) -> &[u32];
    /// Radius of a sphere about the local origin that contains the shape.
    fn bounding_radius(&self) -> Real;
    /// The length all contact tolerances are scaled by (the particle size).
    fn length_scale(&self) -> Real;
}

impl Polytope for crate::shape::ConvexPolyhedron {
    fn vertices(&self) -> &[Point] {
        crate::shape::ConvexPolyhedron::vertices(self)
    }
    fn vertex_columns(&self) -> &crate::shape::VertexColumns {
        crate::shape::ConvexPolyhedron::vertex_columns(self)
    }
    fn num_faces(&self) -> usize {
        crate::shape::ConvexPolyhedron::num_faces(self)
    }
    fn face_normal(&self, i: usize) -> Vector {
        *crate::shape::ConvexPolyhedron::face_normal(self, i)
    }
    fn face_offset(&self, i: usize) -> Real {
        crate::shape::ConvexPolyhedron::face_offset(self, i)
    }
    fn face_vertices(&self, i: usize) -> &[u32] {
        crate::shape::ConvexPolyhedron::face_vertices(self, i)
    }
    fn edges(&self) -> &[[u32; 2]] {
        crate::shape::ConvexPolyhedron::edges(self)
    }
    fn neighbors(&self, v: u32) -> &[u32] {
        crate::shape::ConvexPolyhedron::neighbors(self, v)
    }
    fn bounding_radius(&self) -> Real {
        crate::shape::ConvexPolyhedron::bounding_radius(self)
    }
    fn length_scale(&self) -> Real {
        crate::shape::ConvexPolyhedron::length_scale(self)
    }
}

fn max_dot(pts: &[Vector], n: &Vector) -> Real {
    pts.iter().fold(Real::NEG_INFINITY, |m, p| m.max(n.dot(p)))
}

/// Overlap along n (unit, frame 1): h_A(n) + h_B(−n), by brute force.
fn overlap_along(va: &[Vector], vb: &[Vector], n: &Vector) -> Real {
    max_dot(va, n) + max_dot(vb, &-n)
}

/// The scale-free edge–edge axis of unit directions `u`, `v`; `None` when (nearly) parallel.
pub(crate) fn edge_edge_axis(u: &Vector, v: &Vector) -> Option<Vector> {
    let w = v - u * u.dot(v);
    let s = w.norm();
    if s.is_nan() || s <= 1e-12 {
        return None;
    }
    let w = w / s;
    let w = w - u * u.dot(&w);
    let n = u.cross(&w.normalize());
    Some(n.normalize())
}

/// The best SAT axis and its overlap, over all candidate axes (frame 1).
fn best_axis<A: Polytope + ?Sized, B: Polytope + ?Sized>(
    a: &A,
    b: &B,
    va: &[Vector],
    vb: &[Vector],
    rot12: &crate::math::Rotation,
) -> (Real, Vector) {
    let mut best = (Real::INFINITY, Vector::x());
    let mut consider = |n: Vector| {
        let s = overlap_along(va, vb, &n);
        if s < best.0 {
            best = (s, n);
        }
    };
    for i in 0..a.num_faces() {
        consider(a.face_normal(i));
    }
    for i in 0..b.num_faces() {
        consider(-(rot12 * b.face_normal(i)));
    }
    let ea: Vec<Vector> = a
        .edges()
        .iter()
        .map(|e| (va[e[1] as usize] - va[e[0] as usize]).normalize())
        .collect();
    let eb: Vec<Vector> = b
        .edges()
        .iter()
        .map(|e| (vb[e[1] as usize] - vb[e[0] as usize]).normalize())
        .collect();
    for u in &ea {
        for v in &eb {
            if let Some(n) = edge_edge_axis(u, v) {
                consider(n);
                consider(-n);
            }
        }
    }
    best
}

/// Exact distance between two disjoint polytopes given by vertices (frame 1) and face/edge topology:
/// (point on A, point on B, distance).
fn exact_distance<A: Polytope + ?Sized, B: Polytope + ?Sized>(
    a: &A,
    b: &B,
    va: &[Vector],
    vb: &[Vector],
) -> (Vector, Vector, Real) {
    let mut best = (va[0], vb[0], Real::INFINITY);
    let mut consider = |x: Vector, y: Vector| {
        let d = (x - y).norm_squared();
        if d < best.2 {
            best = (x, y, d);
        }
    };
    for fi in 0..b.num_faces() {
        let fv = b.face_vertices(fi);
        for k in 1..fv.len().saturating_sub(1) {
            let (t0, t1, t2) = (
                vb[fv[0] as usize],
                vb[fv[k] as usize],
                vb[fv[k + 1] as usize],
            );
            for x in va {
                consider(*x, closest_on_triangle(x, &t0, &t1, &t2));
            }
        }
    }
    for fi in 0..a.num_faces() {
        let fv = a.face_vertices(fi);
        for k in 1..fv.len().saturating_sub(1) {
            let (t0, t1, t2) = (
                va[fv[0] as usize],
                va[fv[k] as usize],
                va[fv[k + 1] as usize],
            );
            for y in vb {
                consider(closest_on_triangle(y, &t0, &t1, &t2), *y);
            }
        }
    }
    for ea in a.edges() {
        for eb in b.edges() {
            let (x, y) = closest_segments(
                &va[ea[0] as usize],
                &va[ea[1] as usize],
                &vb[eb[0] as usize],
                &vb[eb[1] as usize],
            );
            consider(x, y);
        }
    }
    (best.0, best.1, best.2.sqrt())
}

/// Contact points along the axis `n` with overlap `s` (frame 1): c1 on A, c2 on B, c1 − c2 = s n.
fn points_along(
    va: &[Vector],
    vb: &[Vector],
    n: &Vector,
    s: Real,
    scale: Real,
) -> (Vector, Vector) {
    let eps = 1e-12 * scale;
    let ha = max_dot(va, n);
    let hb = max_dot(vb, &-n);
    let fa: Vec<Vector> = va
        .iter()
        .filter(|p| n.dot(p) >= ha - eps)
        .copied()
        .collect();
    let fb: Vec<Vector> = vb
        .iter()
        .filter(|p| -n.dot(p) >= hb - eps)
        .map(|p| p + n * s)
        .collect();
    if fa.is_empty() || fb.is_empty() {
        // Only with non-finite input (every comparison false): no feature, report the centres' points.
        return (va[0], vb[0]);
    }
    let (x, y, _) = closest_point_sets(&fa, &fb);
    let mid = (x + y) * 0.5;
    (mid, mid - n * s)
}

/// The exact answer for two polytopes placed at `pos1`, `pos2` (world), with the given tolerances.
/// `status` is written into the result (the oracle reports `Exact`; the fallback its reason).
pub fn sat_polytopes<A: Polytope + ?Sized, B: Polytope + ?Sized>(
    pos1: &Pose,
    a: &A,
    pos2: &Pose,
    b: &B,
    tol: &ContactTolerances,
    status: SolverStatus,
) -> ContactGeometry {
    let pos12 = pos1.inv_mul(pos2);
    let va: Vec<Vector> = a.vertices().iter().map(|p| p.coords).collect();
    let vb: Vec<Vector> = b.vertices().iter().map(|p| (pos12 * p).coords).collect();
    let scale = pair_length_scale(a.length_scale(), b.length_scale());
    let touch = tol.touching * scale;
    let (s, n) = best_axis(a, b, &va, &vb, &pos12.rotation);
    let to_world = |n1: Vector, c1: Vector, c2: Vector, kind, depth, distance| {
        let point_a = pos1 * Point::from(c1);
        let point_b = pos1 * Point::from(c2);
        ContactGeometry::from_points(
            kind,
            depth,
            distance,
            pos1.rotation * n1,
            point_a,
            point_b,
            status,
        )
    };
    if s > touch {
        let (c1, c2) = points_along(&va, &vb, &n, s, scale);
        return to_world(n, c1, c2, ContactKind::Overlap, s, 0.0);
    }
    let (x, y, d) = exact_distance(a, b, &va, &vb);
    if d > touch {
        // The best axis is exact when it realises the distance (facet or edge–edge closest features); it is
        // then better conditioned than the witness difference.
        let n_w = (y - x) / d;
        let n1 = if (-s - d).abs() <= 1e-12 * scale {
            n
        } else {
            n_w
        };
        let mid = (x + y) * 0.5;
        let half = n1 * (0.5 * d);
        return to_world(n1, mid - half, mid + half, ContactKind::Separated, 0.0, d);
    }
    let (c1, c2) = points_along(&va, &vb, &n, s, scale);
    to_world(n, c1, c2, ContactKind::Touching, 0.0, 0.0)
}
