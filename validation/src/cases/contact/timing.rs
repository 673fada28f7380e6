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
