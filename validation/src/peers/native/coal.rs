//! coal 3 (the `libcoal` wheel) through `peers/coal_shim.cpp`: `GJKSolver::shapeDistance` with penetration
//! on `Convex<Triangle>` hulls built once per pair. coal's normal points from the first body to the second;
//! its signed distance is negative on overlap. A call that throws, or a non-finite answer, is a failed
//! call; coal's statuses are not filtered, since its `distance` and `collide` pass on the value whatever
//! they are.

use super::{parts, unit, NativeAnswer, NativePair, COAL_TIGHT_REL};
use polydem::shape::ConvexPolyhedron;
use std::os::raw::{c_int, c_uint, c_void};

extern "C" {
    fn pd_coal_hull_new(verts: *const f64, n: usize, tris: *const c_uint, m: usize) -> *mut c_void;
    fn pd_coal_hull_free(shape: *mut c_void);
    fn pd_coal_query(
        a: *const c_void,
        ta: *const f64,
        qa: *const f64,
        b: *const c_void,
        tb: *const f64,
        qb: *const f64,
        tolerance: f64,
        distance: *mut f64,
        normal: *mut f64,
        p1: *mut f64,
        p2: *mut f64,
        gjk_status: *mut c_int,
        epa_status: *mut c_int,
    ) -> c_int;
}

/// One hull as a coal shape (null when coal rejected it).
struct Hull(*mut c_void);

impl Hull {
    /// The hull's vertices and its faces split into fans (counter-clockwise seen from outside).
    fn new(poly: &ConvexPolyhedron) -> Self {
        let verts = super::flat(poly, 1.0);
        let mut tris: Vec<c_uint> = Vec::new();
        for f in 0..poly.num_faces() {
            let face = poly.face_vertices(f);
            for k in 1..face.len().saturating_sub(1) {
                tris.extend([face[0], face[k], face[k + 1]]);
            }
        }
        // SAFETY: the shim copies 3 × n coordinates and 3 × m indices (all below n) into the shape.
        Hull(unsafe {
            pd_coal_hull_new(
                verts.as_ptr(),
                verts.len() / 3,
                tris.as_ptr(),
                tris.len() / 3,
            )
        })
    }
}

impl Drop for Hull {
    fn drop(&mut self) {
        if !self.0.is_null() {
            // SAFETY: created by pd_coal_hull_new, freed once.
            unsafe { pd_coal_hull_free(self.0) }
        }
    }
}

/// Both hulls of a pair.
pub struct Hulls {
    a: Hull,
    b: Hull,
}

impl Hulls {
    pub fn new(a: &ConvexPolyhedron, b: &ConvexPolyhedron) -> Self {
        Hulls {
            a: Hull::new(a),
            b: Hull::new(b),
        }
    }
}

/// coal's answer with its default tolerances, or with both tolerances [`COAL_TIGHT_REL`] × size.
pub fn query(p: &NativePair, tight: bool) -> NativeAnswer {
    let h = &p.coal;
    if h.a.0.is_null() || h.b.0.is_null() {
        return NativeAnswer::Failed;
    }
    let (ta, qa) = parts(&p.pos1, 1.0);
    let (tb, qb) = parts(&p.pos2, 1.0);
    let tolerance = if tight { COAL_TIGHT_REL * p.size } else { 0.0 };
    let mut distance = 0.0;
    let (mut n, mut w1, mut w2) = ([0.0; 3], [0.0; 3], [0.0; 3]);
    let (mut gjk, mut epa) = (0, 0);
    // SAFETY: the shapes are live; the output pointers are valid for the call.
    let r = unsafe {
        pd_coal_query(
            h.a.0,
            ta.as_ptr(),
            qa.as_ptr(),
            h.b.0,
            tb.as_ptr(),
            qb.as_ptr(),
            tolerance,
            &mut distance,
            n.as_mut_ptr(),
            w1.as_mut_ptr(),
            w2.as_mut_ptr(),
            &mut gjk,
            &mut epa,
        )
    };
    let normal = unit(n);
    match r {
        0 if distance.is_finite() && distance < 0.0 => NativeAnswer::Overlap {
            depth: -distance,
            normal,
        },
        0 if distance.is_finite() => NativeAnswer::Separated {
            distance: Some(distance),
            normal,
        },
        _ => NativeAnswer::Failed,
    }
}
