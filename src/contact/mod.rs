//! Contact geometry between convex shapes: the Minkowski contact features of the paper (section 2.1).
//!
//! The narrow phase answers one question per pair — where and how much do these two shapes overlap — and
//! returns a [`ContactGeometry`]. It never computes forces: contact laws live elsewhere and consume the
//! geometry.
//!
//! Files, one job each: `minkowski` (support of A ⊖ B in A's frame), `gjk` (distance / intersection),
//! `epa` (Minkowski overlap), [`sat`] (exact oracle and fallback), [`features`] (closest points of small
//! features), one file per shape pair ([`contact_polyhedron_polyhedron`], [`contact_sphere_polyhedron`],
//! [`contact_polyhedron_plane`], [`contact_sphere_plane`], [`contact_sphere_sphere`](mod@contact_sphere_sphere)),
//! the generic arms for any [`ConvexShape`](crate::shape::ConvexShape) ([`contact_support_map`]: GJK + EPA
//! to a tolerance; [`contact_convex_plane`]: closed form against a wall), [`dispatch`] (over
//! [`Shape`](crate::shape::Shape)), [`counters`], [`tolerances`].
//!
//! Entry points: [`query`] (any shapes, hot path), [`query_polyhedra_cached`] / [`query_polyhedra`] /
//! [`sat_polyhedra`] (polyhedra: hot path, convenience, exact oracle), [`intersect_polyhedra_cached`]
//! (rejection test). References: Gilbert, Johnson & Keerthi (1988); van den Bergen, *Collision Detection in
//! Interactive 3D Environments* (2001); Feng & Tan's Minkowski overlap as used by Zhao et al. (2021).

pub mod contact_convex_plane;
pub mod contact_polyhedron_plane;
pub mod contact_polyhedron_polyhedron;
pub mod contact_sphere_plane;
pub mod contact_sphere_polyhedron;
pub mod contact_sphere_sphere;
pub mod contact_support_map;
pub mod counters;
pub mod dispatch;
pub(crate) mod epa;
pub mod features;
mod geometry;
pub(crate) mod gjk;
pub(crate) mod minkowski;
pub mod pair_smoothing;
pub mod sat;
pub mod tolerances;
pub mod wall_depth;

#[cfg(test)]
pub(crate) mod testing;
#[cfg(test)]
mod tests_degenerate;
#[cfg(test)]
mod tests_oracle;
#[cfg(test)]
mod tests_support_map;

pub use contact_convex_plane::contact_plane_convex;
pub use contact_polyhedron_plane::contact_plane_polytope;
pub use contact_polyhedron_polyhedron::{
    intersect_polyhedra_cached, intersect_polytopes_cached, query_polyhedra,
    query_polyhedra_cached, query_polyhedra_with, query_polytopes_cached, sat_polyhedra,
    warm_overlap_polytopes, PairCache,
};
pub use contact_sphere_plane::contact_plane_sphere;
pub use contact_sphere_polyhedron::contact_polytope_sphere;
pub use contact_sphere_sphere::contact_sphere_sphere;
pub use contact_support_map::{contact_support_maps, SupportMapContact};
pub use counters::QueryCounters;
pub use dispatch::{query, query_with, swap_pair, warm_overlap_with, ContactError};
pub use epa::EpaScratch;
pub use geometry::{ContactGeometry, ContactKind, SolverStatus};
pub use pair_smoothing::PairSmoothing;
pub use sat::{sat_polytopes, Polytope};
pub use tolerances::ContactTolerances;
pub use wall_depth::WallDepth;
