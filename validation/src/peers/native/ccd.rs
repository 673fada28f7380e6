//! libccd 2.1 through `peers/ccd_shim.c`: GJK+EPA and MPR penetration queries. libccd's direction is the
//! one the second body moves along to separate, from the first body to the second already.

use super::{parts, unit, NativeAnswer, NativePair, SUPPORT_CAP, TIGHT_REL};
use std::os::raw::{c_int, c_ulong};

extern "C" {
    fn pd_ccd_penetration(
        va: *const f64,
        na: usize,
        ta: *const f64,
        qa: *const f64,
        vb: *const f64,
        nb: usize,
        tb: *const f64,
        qb: *const f64,
        method: c_int,
        tolerance: f64,
        support_cap: c_ulong,
        depth: *mut f64,
        dir: *mut f64,
    ) -> c_int;
}

/// `method` 0: GJK+EPA, 1: MPR.
pub fn query(p: &NativePair, method: c_int, tight: bool) -> NativeAnswer {
    let (ta, qa) = parts(&p.pos1, 1.0);
    let (tb, qb) = parts(&p.pos2, 1.0);
    let tolerance = if tight { TIGHT_REL * p.size } else { 0.0 };
    let mut depth = 0.0;
    let mut dir = [0.0; 3];
    // SAFETY: the vertex slices hold 3 × n values; the output pointers are valid for the call.
    let r = unsafe {
        pd_ccd_penetration(
            p.verts_a.as_ptr(),
            p.verts_a.len() / 3,
            ta.as_ptr(),
            qa.as_ptr(),
            p.verts_b.as_ptr(),
            p.verts_b.len() / 3,
            tb.as_ptr(),
            qb.as_ptr(),
            method,
            tolerance,
            SUPPORT_CAP as c_ulong,
            &mut depth,
            dir.as_mut_ptr(),
        )
    };
    match r {
        1 if depth.is_finite() => NativeAnswer::Overlap {
            depth,
            normal: unit(dir),
        },
        0 => NativeAnswer::Separated {
            distance: None,
            normal: None,
        },
        _ => NativeAnswer::Failed,
    }
}
