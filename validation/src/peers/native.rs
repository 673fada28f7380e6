//! The C/C++ collision libraries as peers (feature `peers`): libccd 2.1 and Bullet 3.24, called through the
//! shims of `validation/peers/` that `build.rs` compiles against the system's libraries (pkg-config `ccd`
//! and `bullet-float64`, Debian's `libccd-dev` and `libbullet-dev`).
//!
//! Each peer is given polydem's hull vertices (the polyhedron's own frame) and poses, and answers in world
//! coordinates. [`NativePeer::ALL`] lists the variants the contact case runs: each library with its
//! default settings and with its tolerances tightened to the pair's size.
//! - libccd GJK+EPA (`ccdGJKPenetration`) and MPR (`ccdMPRPenetration`): double precision (Debian builds it
//!   with `CCD_DOUBLE`); both answer "intersect or not" and a depth, no distance. Defaults: absolute
//!   tolerances of 1e-4 m (EPA, MPR) and 1e-6 m (distance), no iteration cap. Tight: all three set to
//!   [`TIGHT_REL`] × the pair's size. libccd's EPA has no iteration cap; the shim stops a query after
//!   [`SUPPORT_CAP`] support calls and reports it as failed.
//! - Bullet `btGjkEpaSolver2` (`Penetration`, then `Distance` when not penetrating), compiled with
//!   `BT_USE_DOUBLE_PRECISION` against Debian's float64 libraries, hulls with a zero margin, queried without
//!   margins. Its accuracies are compile-time absolute constants (metres), so the tight variant scales the
//!   pair to unit size before the call (its constants then act as fractions of the size) and the answer back.

use polydem::math::{Pose, Real, Vector};
use polydem::shape::ConvexPolyhedron;

/// Tolerance of the tight libccd variants, × the pair's size.
pub const TIGHT_REL: Real = 1e-10;
/// Support calls after which a libccd query is stopped and counted as failed.
pub const SUPPORT_CAP: u64 = 100_000;

/// A peer's answer on one pair.
#[derive(Copy, Clone, Debug, PartialEq)]
pub enum NativeAnswer {
    /// The shapes intersect; depth (m) and the normal (world) as the peer gives it.
    Overlap { depth: Real, normal: Vector },
    /// The shapes do not intersect; the distance (m) when the peer computes one.
    Separated { distance: Option<Real> },
    /// No answer (an error status, a non-finite value or the support-call cap).
    Failed,
}

/// The peer variants of the contact case.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum NativePeer {
    CcdGjkEpa { tight: bool },
    CcdMpr { tight: bool },
    Bullet { tight: bool },
}

impl NativePeer {
    pub const ALL: [NativePeer; 6] = [
        NativePeer::CcdGjkEpa { tight: false },
        NativePeer::CcdGjkEpa { tight: true },
        NativePeer::CcdMpr { tight: false },
        NativePeer::CcdMpr { tight: true },
        NativePeer::Bullet { tight: false },
        NativePeer::Bullet { tight: true },
    ];

    /// The column label, with the library's version and precision.
    pub fn label(self) -> String {
        let (name, tight) = match self {
            NativePeer::CcdGjkEpa { tight } => ("libccd 2.1 GJK+EPA (f64)", tight),
            NativePeer::CcdMpr { tight } => ("libccd 2.1 MPR (f64)", tight),
            NativePeer::Bullet { tight } => ("Bullet 3.24 btGjkEpaSolver2 (f64)", tight),
        };
        format!("{name}, {}", if tight { "tight" } else { "default" })
    }

    /// Whether the library was found and compiled in.
    pub fn available(self) -> bool {
        match self {
            NativePeer::CcdGjkEpa { .. } | NativePeer::CcdMpr { .. } => cfg!(peer_ccd),
            NativePeer::Bullet { .. } => cfg!(peer_bullet),
        }
    }

    /// Whether the peer computes distances of separated pairs.
    pub fn gives_distance(self) -> bool {
        matches!(self, NativePeer::Bullet { .. })
    }
}

/// Which peers this build has, as one line for the report.
pub fn availability() -> String {
    let found = |ok: bool| {
        if ok {
            "compiled in"
        } else {
            "not found at build time"
        }
    };
    if !cfg!(feature = "peers") {
        return "The C/C++ peers (libccd, Bullet) are not in this build: build with `--features peers` \
                (needs libccd-dev and libbullet-dev)."
            .to_string();
    }
    format!(
        "C/C++ peers: libccd {}; Bullet (float64) {}.",
        found(cfg!(peer_ccd)),
        found(cfg!(peer_bullet))
    )
}

/// A pair prepared for the peers: the vertices of both hulls in their own frames, their poses, the pair's
/// size, and the Bullet shapes (default and unit-size) when Bullet is compiled in.
#[cfg_attr(not(any(peer_ccd, peer_bullet)), allow(dead_code))]
pub struct NativePair {
    verts_a: Vec<f64>,
    verts_b: Vec<f64>,
    pos1: Pose,
    pos2: Pose,
    size: Real,
    #[cfg(peer_bullet)]
    bullet: [bullet::Hulls; 2],
}

#[cfg_attr(not(any(peer_ccd, peer_bullet)), allow(dead_code))]
fn flat(poly: &ConvexPolyhedron, scale: Real) -> Vec<f64> {
    poly.vertices()
        .iter()
        .flat_map(|p| [p.x * scale, p.y * scale, p.z * scale])
        .collect()
}

/// Translation and quaternion (w, x, y, z) of a pose, the translation times `scale`.
#[cfg_attr(not(any(peer_ccd, peer_bullet)), allow(dead_code))]
fn parts(pose: &Pose, scale: Real) -> ([f64; 3], [f64; 4]) {
    let t = pose.translation.vector * scale;
    let q = pose.rotation.quaternion();
    ([t.x, t.y, t.z], [q.w, q.i, q.j, q.k])
}

impl NativePair {
    /// `size`: the pair's length scale (m), used by the tight variants.
    pub fn new(
        a: &ConvexPolyhedron,
        pos1: &Pose,
        b: &ConvexPolyhedron,
        pos2: &Pose,
        size: Real,
    ) -> Self {
        NativePair {
            verts_a: flat(a, 1.0),
            verts_b: flat(b, 1.0),
            pos1: *pos1,
            pos2: *pos2,
            size,
            #[cfg(peer_bullet)]
            bullet: [
                bullet::Hulls::new(a, b, 1.0),
                bullet::Hulls::new(a, b, 1.0 / size),
            ],
        }
    }

    /// The answer of `peer` (`Failed` when the peer is not compiled in).
    pub fn answer(&self, peer: NativePeer) -> NativeAnswer {
        match peer {
            #[cfg(peer_ccd)]
            NativePeer::CcdGjkEpa { tight } => ccd::query(self, 0, tight),
            #[cfg(peer_ccd)]
            NativePeer::CcdMpr { tight } => ccd::query(self, 1, tight),
            #[cfg(peer_bullet)]
            NativePeer::Bullet { tight } => bullet::query(self, tight, bullet::Calls::Both),
            #[allow(unreachable_patterns)]
            _ => NativeAnswer::Failed,
        }
    }

    /// The call a user makes for an overlapping pair (libccd: the penetration query; Bullet:
    /// `Penetration` alone), for timing; `Failed` when the peer is not compiled in.
    pub fn answer_overlap_only(&self, peer: NativePeer) -> NativeAnswer {
        match peer {
            #[cfg(peer_bullet)]
            NativePeer::Bullet { tight } => bullet::query(self, tight, bullet::Calls::Penetration),
            _ => self.answer(peer),
        }
    }

    /// The call a user makes for the distance of a separated pair (Bullet: `Distance` alone), for timing;
    /// the full answer for the peers without a distance query.
    pub fn answer_separated_only(&self, peer: NativePeer) -> NativeAnswer {
        match peer {
            #[cfg(peer_bullet)]
            NativePeer::Bullet { tight } => bullet::query(self, tight, bullet::Calls::Distance),
            _ => self.answer(peer),
        }
    }
}

#[cfg(peer_ccd)]
mod ccd {
    use super::{parts, NativeAnswer, NativePair, SUPPORT_CAP, TIGHT_REL};
    use polydem::math::Vector;
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
        let normal = Vector::new(dir[0], dir[1], dir[2]);
        match r {
            1 if depth.is_finite() && normal.iter().all(|x| x.is_finite()) => {
                NativeAnswer::Overlap { depth, normal }
            }
            0 => NativeAnswer::Separated { distance: None },
            _ => NativeAnswer::Failed,
        }
    }
}

#[cfg(peer_bullet)]
mod bullet {
    use super::{flat, parts, NativeAnswer, NativePair};
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

    fn call(h: &Hulls, p: &NativePair, mode: c_int) -> (bool, c_int, f64, Vector) {
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
        (
            ok == 1,
            status,
            distance / h.scale,
            Vector::new(n[0], n[1], n[2]),
        )
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
    /// The normal is passed on as Bullet gives it (the case scores depths and distances, not normals).
    pub fn query(p: &NativePair, tight: bool, calls: Calls) -> NativeAnswer {
        let h = &p.bullet[tight as usize];
        if calls != Calls::Distance {
            let (ok, status, signed, normal) = call(h, p, 0);
            let finite = signed.is_finite() && normal.iter().all(|x| x.is_finite());
            if ok && finite {
                return NativeAnswer::Overlap {
                    depth: -signed,
                    normal,
                };
            }
            if status != 0 || calls == Calls::Penetration {
                return NativeAnswer::Failed;
            }
        }
        let (ok, _, distance, _) = call(h, p, 1);
        if ok && distance.is_finite() {
            NativeAnswer::Separated {
                distance: Some(distance),
            }
        } else {
            NativeAnswer::Failed
        }
    }
}
