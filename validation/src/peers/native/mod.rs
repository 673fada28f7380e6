//! The C/C++ collision libraries as peers (feature `peers`): libccd 2.1, Bullet 3.24 and coal 3, called
//! through the shims of `validation/peers/` that `build.rs` compiles (libccd and Bullet against the
//! system's libraries, pkg-config `ccd` and `bullet-float64`, Debian's `libccd-dev` and `libbullet-dev`;
//! coal against its `libcoal` wheel, `POLYDEM_COAL_PREFIX`).
//!
//! Each peer is given polydem's hull vertices (the polyhedron's own frame) and poses, and answers in world
//! coordinates; every normal is turned to point from the first body to the second. [`NativePeer::ALL`]
//! lists the variants the contact case runs: each library with its default settings and with its
//! tolerances tightened to the pair's size.
//! - libccd GJK+EPA (`ccdGJKPenetration`) and MPR (`ccdMPRPenetration`): double precision (Debian builds it
//!   with `CCD_DOUBLE`); both answer "intersect or not" and a depth, no distance. Defaults: absolute
//!   tolerances of 1e-4 m (EPA, MPR) and 1e-6 m (distance), no iteration cap. Tight: all three set to
//!   [`TIGHT_REL`] × the pair's size. libccd's EPA has no iteration cap; the shim stops a query after
//!   [`SUPPORT_CAP`] support calls and reports it as failed.
//! - Bullet `btGjkEpaSolver2` (`Penetration`, then `Distance` when not penetrating), compiled with
//!   `BT_USE_DOUBLE_PRECISION` against Debian's float64 libraries, hulls with a zero margin, queried without
//!   margins. Its accuracies are compile-time absolute constants (metres), so the tight variant scales the
//!   pair to unit size before the call (its constants then act as fractions of the size) and the answer back.
//! - coal `GJKSolver::shapeDistance` with penetration (GJK, then EPA on overlap) on `Convex<Triangle>`
//!   hulls: signed distance, normal and witness points. Defaults: GJK and EPA tolerances of 1e-6 (coal's
//!   `GJK_DEFAULT_TOLERANCE`, `EPA_DEFAULT_TOLERANCE`), 128 GJK and 64 EPA iterations. Tight: both
//!   tolerances [`COAL_TIGHT_REL`] × the pair's size, the iteration caps unchanged.

#[cfg(peer_bullet)]
mod bullet;
#[cfg(peer_ccd)]
mod ccd;
#[cfg(peer_coal)]
mod coal;
#[cfg(test)]
mod tests;

use polydem::math::{Pose, Real, Vector};
use polydem::shape::ConvexPolyhedron;

/// Tolerance of the tight libccd variants, × the pair's size.
pub const TIGHT_REL: Real = 1e-10;
/// GJK and EPA tolerances of the tight coal variant, × the pair's size.
pub const COAL_TIGHT_REL: Real = 1e-12;
/// Support calls after which a libccd query is stopped and counted as failed.
pub const SUPPORT_CAP: u64 = 100_000;

/// A peer's answer on one pair. Normals are unit vectors (world) from the first body to the second.
#[derive(Copy, Clone, Debug, PartialEq)]
pub enum NativeAnswer {
    /// The shapes intersect: depth (m) and normal (`None` when the peer gives no direction, as libccd's
    /// MPR on touching shapes).
    Overlap { depth: Real, normal: Option<Vector> },
    /// The shapes do not intersect: the distance (m) and normal when the peer computes them.
    Separated {
        distance: Option<Real>,
        normal: Option<Vector>,
    },
    /// No answer (an error status, a non-finite value or the support-call cap).
    Failed,
}

/// The peer variants of the contact case.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum NativePeer {
    CcdGjkEpa { tight: bool },
    CcdMpr { tight: bool },
    Bullet { tight: bool },
    Coal { tight: bool },
}

impl NativePeer {
    pub const ALL: [NativePeer; 8] = [
        NativePeer::CcdGjkEpa { tight: false },
        NativePeer::CcdGjkEpa { tight: true },
        NativePeer::CcdMpr { tight: false },
        NativePeer::CcdMpr { tight: true },
        NativePeer::Bullet { tight: false },
        NativePeer::Bullet { tight: true },
        NativePeer::Coal { tight: false },
        NativePeer::Coal { tight: true },
    ];

    /// The column label, with the library's version and precision.
    pub fn label(self) -> String {
        let coal = format!(
            "coal {} GJKSolver (f64)",
            option_env!("POLYDEM_COAL_VERSION").unwrap_or("(not built)")
        );
        let (name, tight) = match self {
            NativePeer::CcdGjkEpa { tight } => ("libccd 2.1 GJK+EPA (f64)".to_string(), tight),
            NativePeer::CcdMpr { tight } => ("libccd 2.1 MPR (f64)".to_string(), tight),
            NativePeer::Bullet { tight } => {
                ("Bullet 3.24 btGjkEpaSolver2 (f64)".to_string(), tight)
            }
            NativePeer::Coal { tight } => (coal, tight),
        };
        format!("{name}, {}", if tight { "tight" } else { "default" })
    }

    /// Whether the library was found and compiled in.
    pub fn available(self) -> bool {
        match self {
            NativePeer::CcdGjkEpa { .. } | NativePeer::CcdMpr { .. } => cfg!(peer_ccd),
            NativePeer::Bullet { .. } => cfg!(peer_bullet),
            NativePeer::Coal { .. } => cfg!(peer_coal),
        }
    }

    /// Whether the peer computes distances of separated pairs.
    pub fn gives_distance(self) -> bool {
        matches!(self, NativePeer::Bullet { .. } | NativePeer::Coal { .. })
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
        return "The C/C++ peers (libccd, Bullet, coal) are not in this build: build with `--features \
                peers` (needs libccd-dev and libbullet-dev, and for coal the `libcoal` and `cmeel-eigen` \
                wheels with POLYDEM_COAL_PREFIX set to their `cmeel.prefix`; `.ci/peers.sh` does all of it)."
            .to_string();
    }
    format!(
        "C/C++ peers: libccd {}; Bullet (float64) {}; coal {}.",
        found(cfg!(peer_ccd)),
        found(cfg!(peer_bullet)),
        if cfg!(peer_coal) {
            "compiled in"
        } else {
            "not found at build time (POLYDEM_COAL_PREFIX unset or wrong)"
        }
    )
}

/// A pair prepared for the peers: the vertices of both hulls in their own frames, their poses, the pair's
/// size, and the library shapes (Bullet: default and unit-size; coal) when compiled in.
#[cfg_attr(not(any(peer_ccd, peer_bullet, peer_coal)), allow(dead_code))]
pub struct NativePair {
    verts_a: Vec<f64>,
    verts_b: Vec<f64>,
    pos1: Pose,
    pos2: Pose,
    size: Real,
    #[cfg(peer_bullet)]
    bullet: [bullet::Hulls; 2],
    #[cfg(peer_coal)]
    coal: coal::Hulls,
}

#[cfg_attr(not(any(peer_ccd, peer_bullet, peer_coal)), allow(dead_code))]
fn flat(poly: &ConvexPolyhedron, scale: Real) -> Vec<f64> {
    poly.vertices()
        .iter()
        .flat_map(|p| [p.x * scale, p.y * scale, p.z * scale])
        .collect()
}

/// Translation and quaternion (w, x, y, z) of a pose, the translation times `scale`.
#[cfg_attr(not(any(peer_ccd, peer_bullet, peer_coal)), allow(dead_code))]
fn parts(pose: &Pose, scale: Real) -> ([f64; 3], [f64; 4]) {
    let t = pose.translation.vector * scale;
    let q = pose.rotation.quaternion();
    ([t.x, t.y, t.z], [q.w, q.i, q.j, q.k])
}

/// A normal from a peer, made unit; `None` when it is not finite or has no direction.
#[cfg_attr(not(any(peer_ccd, peer_bullet, peer_coal)), allow(dead_code))]
fn unit(v: [f64; 3]) -> Option<Vector> {
    let n = Vector::new(v[0], v[1], v[2]);
    let len = n.norm();
    (len.is_finite() && len > 0.0).then(|| n / len)
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
            #[cfg(peer_coal)]
            coal: coal::Hulls::new(a, b),
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
            #[cfg(peer_coal)]
            NativePeer::Coal { tight } => coal::query(self, tight),
            #[allow(unreachable_patterns)]
            _ => NativeAnswer::Failed,
        }
    }

    /// The call a user makes for an overlapping pair (libccd: the penetration query; Bullet:
    /// `Penetration` alone; coal: its one query), for timing; `Failed` when the peer is not compiled in.
    pub fn answer_overlap_only(&self, peer: NativePeer) -> NativeAnswer {
        match peer {
            #[cfg(peer_bullet)]
            NativePeer::Bullet { tight } => bullet::query(self, tight, bullet::Calls::Penetration),
            _ => self.answer(peer),
        }
    }

    /// The call a user makes for the distance of a separated pair (Bullet: `Distance` alone), for timing;
    /// the full answer for the other peers.
    pub fn answer_separated_only(&self, peer: NativePeer) -> NativeAnswer {
        match peer {
            #[cfg(peer_bullet)]
            NativePeer::Bullet { tight } => bullet::query(self, tight, bullet::Calls::Distance),
            _ => self.answer(peer),
        }
    }
}
