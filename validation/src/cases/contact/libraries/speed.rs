//! ns per query of every method on the same timing pools in the same run, over each pool and over its
//! vertex-count classes ([`VERTEX_CLASSES`]).
//!
//! Overlapping pairs: the call that returns the depth (ours: the full query from a cold pair cache; parry:
//! `query::contact`; Bullet: `Penetration`; libccd and coal: their one query). Separated pairs: the call
//! that returns the distance (ours: the full query; parry: `query::distance`; Bullet: `Distance`; coal:
//! its one query); none for libccd, which answers only whether the shapes intersect.

use std::hint::black_box;

use polydem::contact::tolerances::pair_length_scale;
use polydem::contact::ContactTolerances;

use super::super::eval::Built;
use super::super::ours::Ours;
use super::super::timing::{class_members, ns_pool_and_classes, vertex_class, VERTEX_CLASSES};
use super::Method;
use crate::peers::native::NativePair;
use crate::peers::parry::ParryPair;

/// ns per query over a pool and per vertex class (NaN: not measured or empty class).
#[derive(Copy, Clone)]
pub struct Times {
    pub all: f64,
    pub by_class: [f64; 4],
}

const NOT_MEASURED: Times = Times {
    all: f64::NAN,
    by_class: [f64::NAN; 4],
};

/// A timing pool: the pairs, the same pairs for the C/C++ peers, and their vertex classes.
pub struct Pool<'a> {
    pub built: &'a [Built],
    native: Vec<NativePair>,
    pub members: [Vec<usize>; 4],
}

impl<'a> Pool<'a> {
    pub fn new(built: &'a [Built], with_native: bool) -> Self {
        let native = if with_native {
            built
                .iter()
                .map(|b| {
                    let size = pair_length_scale(b.a.length_scale(), b.b.length_scale());
                    NativePair::new(&b.a, &b.pos1, &b.b, &b.pos2, size)
                })
                .collect()
        } else {
            Vec::new()
        };
        let classes: Vec<usize> = built
            .iter()
            .map(|b| vertex_class(b.a.vertices().len() + b.b.vertices().len()))
            .collect();
        Pool {
            built,
            native,
            members: class_members(&classes),
        }
    }

    /// Header cells "<what> <class> (n pairs)" for each vertex class.
    pub fn class_headers(&self, what: &str) -> Vec<String> {
        VERTEX_CLASSES
            .iter()
            .zip(&self.members)
            .map(|((name, _, _), m)| format!("{what} {name} ({} pairs)", m.len()))
            .collect()
    }
}

fn times((all, by_class): (f64, [f64; 4])) -> Times {
    Times { all, by_class }
}

/// (overlapping, separated) ns per query of `method` on the two pools.
pub fn time_method<'a>(
    method: Method,
    ov: &Pool<'a>,
    sep: &Pool<'a>,
    repeats: usize,
) -> (Times, Times) {
    match method {
        Method::Ours => {
            let mut ours = Ours::new(ContactTolerances::default());
            let mut run = |pool: &Pool| {
                times(ns_pool_and_classes(&pool.members, repeats, |i| {
                    let b = &pool.built[i];
                    black_box(ours.query(&b.pos1, &b.a, &b.pos2, &b.b));
                }))
            };
            (run(ov), run(sep))
        }
        Method::Parry => {
            let parry = |b: &'a Built| ParryPair {
                a: &b.parry_a,
                b: &b.parry_b,
            };
            let o = ns_pool_and_classes(&ov.members, repeats, |i| {
                let b = &ov.built[i];
                let _ = black_box(parry(b).contact(&b.pos1, &b.pos2, 0.0));
            });
            let s = ns_pool_and_classes(&sep.members, repeats, |i| {
                let b = &sep.built[i];
                black_box(parry(b).distance(&b.pos1, &b.pos2));
            });
            (times(o), times(s))
        }
        Method::Native(peer) => {
            let o = ns_pool_and_classes(&ov.members, repeats, |i| {
                black_box(ov.native[i].answer_overlap_only(peer));
            });
            let s = if peer.gives_distance() {
                times(ns_pool_and_classes(&sep.members, repeats, |i| {
                    black_box(sep.native[i].answer_separated_only(peer));
                }))
            } else {
                NOT_MEASURED
            };
            (times(o), s)
        }
    }
}
