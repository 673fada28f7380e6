//! The result of a contact query: the Minkowski contact features and how they were obtained.

use crate::math::{Point, Real, Vector};

/// Whether two shapes overlap, touch or are apart.
#[derive(Copy, Clone, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum ContactKind {
    /// The origin is strictly inside the Minkowski difference A ⊖ B by more than the touching tolerance.
    Overlap,
    /// The boundaries meet within the touching tolerance (relative to the particle size).
    Touching,
    /// A positive distance separates the shapes (more than the touching tolerance).
    Separated,
}

/// How the answer was obtained. A numerical failure is never reported as "no contact": a query whose
/// iterative solver did not converge falls back to the exact separating-axis computation and says so here.
#[derive(Copy, Clone, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum SolverStatus {
    /// Closed-form answer (sphere–sphere, sphere–plane, polyhedron–plane).
    Exact,
    /// GJK (and EPA when overlapping) converged within tolerance.
    Converged,
    /// The iterative solver hit its iteration cap; the answer comes from the exact SAT fallback (polyhedra)
    /// or, for a pair with a curved shape (no exact fallback), is the solver's best direction with the depth
    /// its upper bound ([`contact_support_map`](super::contact_support_map)).
    FallbackAfterMaxIterations,
    /// The iterative solver met a degenerate configuration; the answer comes from the exact SAT fallback
    /// (polyhedra) or, for a pair with a curved shape, the best of a few probe directions.
    FallbackAfterDegenerate,
}

/// The Minkowski contact features of a pair (A, B), all in the world frame, SI units.
///
/// Conventions (paper eqs. 2–3):
/// - `normal` n_M is a unit vector pointing from A towards B: the direction in which B must move to
///   separate (when overlapping) or in which B lies (when separated).
/// - `depth` δ_M ≥ 0 is the Minkowski overlap, zero unless `kind == Overlap`; it equals the support
///   distance h_A(n) + h_B(−n) along the reported normal.
/// - `distance` ≥ 0 is the gap, zero unless `kind == Separated`.
/// - `point_a` c1 lies on the surface of A, `point_b` c2 on the surface of B, with
///   c1 − c2 = δ_M n_M when overlapping and c2 − c1 = d n_M when separated; `point` c_M = (c1 + c2)/2 is
///   where the contact force acts.
#[derive(Copy, Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct ContactGeometry {
    /// Overlap, touching or separated.
    pub kind: ContactKind,
    /// Minkowski overlap δ_M ≥ 0 (m); zero unless overlapping.
    pub depth: Real,
    /// Gap d ≥ 0 (m); zero unless separated.
    pub distance: Real,
    /// Unit normal n_M, from A towards B (world frame).
    pub normal: Vector,
    /// Contact point c1 on the surface of A (world frame, m).
    pub point_a: Point,
    /// Contact point c2 on the surface of B (world frame, m).
    pub point_b: Point,
    /// Midpoint c_M = (c1 + c2)/2 where the force acts (world frame, m).
    pub point: Point,
    /// Which solver produced the answer and whether it fell back.
    pub status: SolverStatus,
}

impl ContactGeometry {
    /// The features from the two contact points: c_M = (c1 + c2)/2 (paper eq. 3) is derived here, so that
    /// every query path reports the midpoint and none can get it wrong.
    pub fn from_points(
        kind: ContactKind,
        depth: Real,
        distance: Real,
        normal: Vector,
        point_a: Point,
        point_b: Point,
        status: SolverStatus,
    ) -> Self {
        Self {
            kind,
            depth,
            distance,
            normal,
            point_a,
            point_b,
            point: nalgebra::center(&point_a, &point_b),
            status,
        }
    }
}
