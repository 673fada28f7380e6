//! Wall-clock timing of contact queries, ours and parry's on the same pairs in the same run.
//!
//! Each figure is the minimum over `repeats` passes of (pass time / queries per pass): the minimum is the
//! least noisy estimator on a shared machine. Results are consumed with `black_box` so nothing is elided.

use std::hint::black_box;
use std::time::Instant;

use polydem::contact::ContactTolerances;

use super::eval::Built;
use super::ours::{sat, Ours};
use crate::peers::parry::ParryPair;

/// Nanoseconds per call of `f` over `n` items, minimum over `repeats` passes.
pub fn ns_per_item(n: usize, repeats: usize, mut f: impl FnMut(usize)) -> f64 {
    let mut best = f64::INFINITY;
    for _ in 0..repeats.max(1) {
        let start = Instant::now();
        for i in 0..n {
            f(i);
        }
        best = best.min(start.elapsed().as_secs_f64() * 1e9 / n.max(1) as f64);
    }
    best
}

/// Our contact query (cold cache) with tolerances `tol`, ns per query.
pub fn ours_query_ns(pairs: &[Built], tol: ContactTolerances, repeats: usize) -> f64 {
    let mut ours = Ours::new(tol);
    ns_per_item(pairs.len(), repeats, |i| {
        let p = &pairs[i];
        black_box(ours.query(&p.pos1, &p.a, &p.pos2, &p.b));
    })
}

/// parry's contact query (prediction 0), ns per query.
pub fn parry_query_ns(pairs: &[Built], repeats: usize) -> f64 {
    ns_per_item(pairs.len(), repeats, |i| {
        let p = &pairs[i];
        let peer = ParryPair {
            a: &p.parry_a,
            b: &p.parry_b,
        };
        let _ = black_box(peer.contact(&p.pos1, &p.pos2, 0.0));
    })
}

/// The exact SAT oracle, ns per query.
pub fn sat_query_ns(pairs: &[Built], repeats: usize) -> f64 {
    ns_per_item(pairs.len(), repeats, |i| {
        let p = &pairs[i];
        black_box(sat(&p.pos1, &p.a, &p.pos2, &p.b));
    })
}

/// Our boolean intersection test (cold cache), ns per query.
pub fn ours_intersects_ns(pairs: &[Built], repeats: usize) -> f64 {
    let mut ours = Ours::new(ContactTolerances::default());
    ns_per_item(pairs.len(), repeats, |i| {
        let p = &pairs[i];
        black_box(ours.intersects(&p.pos1, &p.a, &p.pos2, &p.b));
    })
}

/// parry's `intersection_test`, ns per query.
pub fn parry_intersects_ns(pairs: &[Built], repeats: usize) -> f64 {
    ns_per_item(pairs.len(), repeats, |i| {
        let p = &pairs[i];
        let peer = ParryPair {
            a: &p.parry_a,
            b: &p.parry_b,
        };
        black_box(peer.intersects(&p.pos1, &p.pos2));
    })
}

/// The vertex-count classes of the per-class timings: bounds on nA + nB, the hull vertices of both bodies.
pub const VERTEX_CLASSES: [(&str, usize, usize); 4] = [
    ("≤16", 0, 16),
    ("17–32", 17, 32),
    ("33–48", 33, 48),
    ("≥49", 49, usize::MAX),
];

/// The index in [`VERTEX_CLASSES`] of a pair with `vertices` hull vertices in all.
pub fn vertex_class(vertices: usize) -> usize {
    VERTEX_CLASSES
        .iter()
        .position(|(_, lo, hi)| (*lo..=*hi).contains(&vertices))
        .unwrap_or(VERTEX_CLASSES.len() - 1)
}

/// The pool's items grouped by vertex class: `classes[i]` is item i's class index.
pub fn class_members(classes: &[usize]) -> [Vec<usize>; 4] {
    let mut members: [Vec<usize>; 4] = Default::default();
    for (i, c) in classes.iter().enumerate() {
        members[*c].push(i);
    }
    members
}

/// ns per call of `f` over the whole pool and over each vertex class of it (NaN for an empty class),
/// each the minimum over `repeats` passes ([`ns_per_item`]).
pub fn ns_pool_and_classes(
    members: &[Vec<usize>; 4],
    repeats: usize,
    mut f: impl FnMut(usize),
) -> (f64, [f64; 4]) {
    let n: usize = members.iter().map(Vec::len).sum();
    let all = if n == 0 {
        f64::NAN
    } else {
        ns_per_item(n, repeats, &mut f)
    };
    let by_class = std::array::from_fn(|c| {
        let idx = &members[c];
        if idx.is_empty() {
            f64::NAN
        } else {
            ns_per_item(idx.len(), repeats, |k| f(idx[k]))
        }
    });
    (all, by_class)
}
