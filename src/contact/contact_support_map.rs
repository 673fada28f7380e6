//! The generic support-map arm: contact of any two bounded convex shapes through GJK and EPA on their
//! support maps, for pairs with a curved shape (ellipsoids, and spheres against them).
//!
//! The signed overlap of A and B (depth when they overlap, minus the distance when they are apart) is
//! s = min over unit n of h(n), h(n) = h_A(n) + h_B(−n) the support function of A ⊖ B in frame 1
//! (`minkowski`); every direction gives an upper bound h(n) ≥ s. GJK (apart) and EPA (overlapping)
//! also keep a lower bound: −|v| for GJK's closest simplex point v, the closest face offset of EPA's
//! polytope P ⊂ A ⊖ B. On a polytope both terminate exactly; on a curved surface they stop only by
//! tolerance: when the bounds agree within `curved_gap · ℓ` ([`ContactTolerances::curved_gap`]), ℓ the
//! length scale of the smaller body.
//!
//! A query whose bounds do not meet (iteration cap, degenerate polytope) is never "no contact": it
//! returns the features along its best direction, with depth = h(n) (the upper bound), its bounds in
//! [`SupportMapContact`], a fallback status on the geometry ([`SolverStatus::FallbackAfterMaxIterations`]
//! or [`SolverStatus::FallbackAfterDegenerate`]; there is no exact fallback for curved shapes) and a count in
//! [`QueryCounters::support_map_unconverged`].

use super::contact_polyhedron_polyhedron::{geometry_to_world, PairCache};
use super::contact_sphere_sphere::classify;
use super::counters::QueryCounters;
use super::epa::{closest_face_bounds, epa, EpaOutcome, EpaScratch};
use super::gjk::{gjk, GjkMode, GjkOutcome, Simplex};
use super::minkowski::MinkowskiPair;
use super::tolerances::{pair_length_scale, ContactTolerances};
use super::{ContactGeometry, SolverStatus};
use crate::math::{Pose, Real, Vector};
use crate::shape::{ConvexShape, SupportMap};

/// The answer of the generic arm: the geometry the laws use and what the solver knows about it.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct SupportMapContact {
    /// The contact features the laws use (world frame).
    pub geometry: ContactGeometry,
    /// Bounds `[lower, upper]` on the signed overlap s (m): s = depth when overlapping, −distance when apart.
    pub bounds: [Real; 2],
    /// Whether the bounds met the tolerance (`upper − lower ≤ curved_gap · ℓ`).
    pub converged: bool,
    /// The tolerance the bounds were asked to meet (m).
    pub tolerance: Real,
}

/// Features in frame 1 before classification.
struct Frame1 {
    signed: Real,
    bounds: [Real; 2],
    normal: Vector,
    point_a: Vector,
    point_b: Vector,
    status: SolverStatus,
}

/// Contact of `a` at `pos1` with `b` at `pos2` through GJK and EPA (see the module docs). `cache` warm
/// starts GJK with the pair's last search direction and keeps the support hints.
#[allow(clippy::too_many_arguments)]
pub fn contact_support_maps<A: ConvexShape + ?Sized, B: ConvexShape + ?Sized>(
    pos1: &Pose,
    a: &A,
    pos2: &Pose,
    b: &B,
    tol: &ContactTolerances,
    cache: &mut PairCache,
    scratch: &mut EpaScratch,
    counters: &mut QueryCounters,
) -> SupportMapContact {
    counters.support_map += 1;
    let scale = pair_length_scale(a.length_scale(), b.length_scale());
    let gap = tol.curved_gap * scale;
    let touch = tol.touching * scale;
    let curved = ContactTolerances {
        gjk_gap: tol.curved_gap,
        epa_gap: tol.curved_gap,
        ..*tol
    };
    let pos12 = pos1.inv_mul(pos2);
    let mut pair = MinkowskiPair::new(a, b, &pos12, cache.hint_a, cache.hint_b);
    let f = features(&mut pair, &pos12, scale, &curved, cache, scratch, counters);
    cache.dir = -f.normal * f.signed.abs().max(touch);
    cache.hint_a = pair.hint_a;
    cache.hint_b = pair.hint_b;
    let converged = f.bounds[1] - f.bounds[0] <= gap;
    let status = if converged {
        f.status
    } else {
        counters.support_map_unconverged += 1;
        match f.status {
            SolverStatus::FallbackAfterDegenerate => f.status,
            _ => SolverStatus::FallbackAfterMaxIterations,
        }
    };
    let (kind, depth, distance) = classify(f.signed, touch);
    let geometry = geometry_to_world(
        pos1, kind, depth, distance, &f.normal, &f.point_a, &f.point_b, status,
    );
    counters.record(&geometry);
    SupportMapContact {
        geometry,
        bounds: f.bounds,
        converged,
        tolerance: gap,
    }
}

/// The pair's features in frame 1: GJK from the cached direction (else from B's centre towards A's), then
/// EPA if the shapes overlap.
fn features<A: SupportMap + ?Sized, B: SupportMap + ?Sized>(
    pair: &mut MinkowskiPair<'_, A, B>,
    pos12: &Pose,
    scale: Real,
    curved: &ContactTolerances,
    cache: &PairCache,
    scratch: &mut EpaScratch,
    counters: &mut QueryCounters,
) -> Frame1 {
    let v_init = if cache.dir.norm_squared() > 0.0 {
        cache.dir
    } else {
        -pos12.translation.vector
    };
    let mut simplex = Simplex::default();
    let gr = gjk(
        pair,
        &v_init,
        scale,
        curved,
        GjkMode::Distance,
        &mut simplex,
    );
    counters.gjk_runs += 1;
    counters.gjk_iterations += gr.iterations as u64;
    match gr.outcome {
        GjkOutcome::Separated {
            distance,
            normal,
            point_a,
            point_b,
        } => {
            let upper = pair.overlap_along(&normal).0;
            Frame1 {
                signed: -distance,
                bounds: [-distance, upper.max(-distance)],
                normal,
                point_a,
                point_b,
                status: SolverStatus::Converged,
            }
        }
        GjkOutcome::Contact => {
            let er = epa(pair, &simplex, scale, curved, scratch);
            counters.epa_runs += 1;
            counters.epa_iterations += er.iterations as u64;
            let touch = curved.touching * scale;
            overlap_features(pair, er.outcome, scratch, touch)
        }
        GjkOutcome::MaxIterations | GjkOutcome::SeparatingAxis => unconverged_gjk(pair, &gr.v),
    }
}

/// Features of an overlapping (or touching) pair from EPA's outcome. At the cap, the closest face of the
/// intact polytope gives both bounds; a degenerate polytope leaves the upper bound along the best of a few
/// directions and GJK's certificate s ≥ −touch as the lower bound.
fn overlap_features<A: SupportMap + ?Sized, B: SupportMap + ?Sized>(
    pair: &mut MinkowskiPair<'_, A, B>,
    outcome: EpaOutcome,
    scratch: &EpaScratch,
    touch: Real,
) -> Frame1 {
    let converged = |outcome: EpaOutcome, lower: Real, status| match outcome {
        EpaOutcome::Converged {
            depth,
            normal,
            point_a,
            point_b,
            ..
        } => Some(Frame1 {
            signed: depth,
            bounds: [lower.min(depth), depth],
            normal,
            point_a,
            point_b,
            status,
        }),
        _ => None,
    };
    let found = match outcome {
        EpaOutcome::Converged { depth, .. } => {
            // EPA stopped on its closest face with h(n) − offset ≤ gap: offset is the lower bound.
            let lower = scratch.closest_offset().unwrap_or(depth);
            converged(outcome, lower, SolverStatus::Converged)
        }
        EpaOutcome::MaxIterations => closest_face_bounds(pair, scratch)
            .and_then(|(lower, o)| converged(o, lower, SolverStatus::FallbackAfterMaxIterations)),
        EpaOutcome::Degenerate(_) => None,
    };
    found.unwrap_or_else(|| best_direction(pair, touch))
}

/// The least upper bound h(n) over the centre line and fourteen fixed directions, with s ≥ −touch (GJK
/// found the origin within the touching band of A ⊖ B or inside it).
fn best_direction<A: SupportMap + ?Sized, B: SupportMap + ?Sized>(
    pair: &mut MinkowskiPair<'_, A, B>,
    touch: Real,
) -> Frame1 {
    let centre = pair.translation12();
    let mut best = (Real::INFINITY, Vector::x(), None);
    let first = (centre.norm() > 0.0).then(|| centre.normalize());
    for n in first.into_iter().chain(super::epa::start_directions()) {
        let (h, s) = pair.overlap_along(&n);
        if h < best.0 {
            best = (h, n, Some(s));
        }
    }
    let (h, n, s) = best;
    let s = s.expect("at least one direction");
    Frame1 {
        signed: h,
        bounds: [(-touch).min(h), h],
        normal: n,
        point_a: s.a,
        point_b: s.b,
        status: SolverStatus::FallbackAfterDegenerate,
    }
}

/// GJK at its cap on a separated (or barely touching) pair: s ≥ −|v| (v lies in A ⊖ B) and s ≤ h(−v̂);
/// the features are the support points along n = −v̂.
fn unconverged_gjk<A: SupportMap + ?Sized, B: SupportMap + ?Sized>(
    pair: &mut MinkowskiPair<'_, A, B>,
    v: &Vector,
) -> Frame1 {
    let dist = v.norm();
    let n = if dist > 0.0 { -v / dist } else { Vector::x() };
    let (h, s) = pair.overlap_along(&n);
    Frame1 {
        signed: h,
        bounds: [(-dist).min(h), h],
        normal: n,
        point_a: s.a,
        point_b: s.b,
        status: SolverStatus::FallbackAfterMaxIterations,
    }
}
