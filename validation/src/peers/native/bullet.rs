//! Bullet 3.24 (float64) through `peers/bullet_shim.cpp`: `btGjkEpaSolver2::Penetration` and `Distance`.
//! Bullet's normal (rotated to the world by the shim) points from the second body to the first
//! (`witnesses[0] − witnesses[1]` for a distance, minus EPA's normal for a penetration); it is turned
//! around here.

use super::{flat, parts, unit, NativeAnswer, NativePair};
use polydem::math::{Real, Vector};
use polydem::shape::ConvexPolyhedron;
use std::os::raw::{c_int, c_void};

extern "C" {
    fn pd_bt_hull_new(verts: *const f64, n: usize) -> *mut c_void;
    fn pd_bt_hull_free(shape: *mut c_void);
    fn pd_bt_query(
        a: *const c_void,
        ta: *const f64,
        qa: *const f64,
        b: *const c_void,
        tb: *const f64,
        qb: *const f64,
        mode: c_int,
        status: *mut c_int,
        distance: *mut f64,
        normal: *mut f64,
        wa: *mut f64,
        wb: *mut f64,
    ) -> c_int;
}

/// Both hulls as Bullet shapes, coordinates times `scale`.
pub struct Hulls {
    a: *mut c_void,
    b: *mut c_void,
    scale: Real,
}

impl Hulls {
    pub fn new(a: &ConvexPolyhedron, b: &ConvexPolyhedron, scale: Real) -> Self {
        let (va, vb) = (flat(a, scale), flat(b, scale));
        // SAFETY: the shim copies the 3 × n values into the shape.
        unsafe {
            Hulls {
                a: pd_bt_hull_new(va.as_ptr(), va.len() / 3),
                b: pd_bt_hull_new(vb.as_ptr(), vb.len() / 3),
                scale,
            }
        }
    }
}

impl Drop for Hulls {
    fn drop(&mut self) {
        // SAFETY: created by pd_bt_hull_new, freed once.
        unsafe {
            pd_bt_hull_free(self.a);
            pd_bt_hull_free(self.b);
        }
    }
}

fn call(h: &Hulls, p: &NativePair, mode: c_int) -> (bool, c_int, f64, Option<Vector>) {
    let (ta, qa) = parts(&p.pos1, h.scale);
    let (tb, qb) = parts(&p.pos2, h.scale);
    let (mut status, mut distance) = (0, 0.0);
    let (mut n, mut wa, mut wb) = ([0.0; 3], [0.0; 3], [0.0; 3]);
    // SAFETY: the shapes are live; the output pointers are valid for the call.
    let ok = unsafe {
        pd_bt_query(
            h.a,
            ta.as_ptr(),
            qa.as_ptr(),
            h.b,
            tb.as_ptr(),
            qb.as_ptr(),
            mode,
            &mut status,
            &mut distance,
            n.as_mut_ptr(),
            wa.as_mut_ptr(),
            wb.as_mut_ptr(),
        )
    };
    let normal = unit([-n[0], -n[1], -n[2]]);
    (ok == 1, status, distance / h.scale, normal)
}

/// Which of Bullet's calls a query makes.
#[derive(Copy, Clone, PartialEq, Eq)]
pub enum Calls {
    /// `Penetration`, then `Distance` when it reports the shapes separated.
    Both,
    Penetration,
    Distance,
}

/// Bullet's statuses (`sResults::eStatus`): Separated 0, Penetrating 1, GJK_Failed 2, EPA_Failed 3.
pub fn query(p: &NativePair, tight: bool, calls: Calls) -> NativeAnswer {
    let h = &p.bullet[tight as usize];
    if calls != Calls::Distance {
        let (ok, status, signed, normal) = call(h, p, 0);
        if ok && signed.is_finite() {
            return NativeAnswer::Overlap {
                depth: -signed,
                normal,
            };
        }
        if status != 0 || calls == Calls::Penetration {
            return NativeAnswer::Failed;
        }
    }
    let (ok, _, distance, normal) = call(h, p, 1);
    if ok && distance.is_finite() {
        NativeAnswer::Separated {
            distance: Some(distance),
            normal,
        }
    } else {
        NativeAnswer::Failed
    }
}
