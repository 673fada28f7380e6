//! EPA: the Minkowski overlap δ_M, its normal n_M and the contact points of two intersecting convex shapes.
//!
//! Algorithm (expanding polytope, van den Bergen 2001, §4.3.8, here in a signed form): keep a convex polytope
//! P ⊂ A ⊖ B spanned by support points, with outward triangle faces; repeatedly take the face of smallest
//! plane offset (signed distance of its plane from the origin), fetch the support point `w` along its normal
//! and, unless `w` lies within `epa_gap · L` of that plane, add `w` to P (remove the faces visible from `w`,
//! close the hole with a fan of new faces around the horizon). Termination happens only on the face that is
//! currently the closest one and whose support gap is below the tolerance, so a stale face can never be
//! reported: at exit the chosen normal `n` satisfies min_faces offset ≤ δ_M ≤ h(n) ≤ offset + gap, with
//! h(n) = h_A(n) + h_B(−n) the support distance.
//!
//! The depth returned is recomputed as h(n) from the final support point, so it equals the support distance
//! along the reported normal to round-off (never a face offset). The contact points are the barycentric
//! combinations, on the closest face, of the parents of its vertices (the paper's c1, c2; Feng & Tan's
//! Minkowski overlap, Zhao et al. 2021 eq. 2–3), symmetrised so that c1 − c2 = δ_M n_M exactly.
//!
//! Robustness:
//! - the offsets are signed, so the start polytope need not contain the origin in its interior (touching
//!   contacts, origin on a face, flat GJK simplices): a face with a negative offset always has a positive
//!   support gap and gets expanded;
//! - a degenerate start (GJK simplex with fewer than four points or flat) is replaced by a tetrahedron
//!   built from the support points along the six coordinate axes, picked for maximal spread;
//! - a horizon that is not a single simple loop, a new face without a usable normal, or a full buffer make
//!   the query report `Degenerate` (the caller falls back to the exact SAT answer and counts it), never a
//!   wrong answer.
//!
//! Limits: the buffers live in an [`EpaScratch`] owned by the caller and reused across queries; the per
//! query work is allocation-free once the scratch has reached its working size (it is created at full size).

use super::gjk::{closest_to_origin, Simplex};
use super::minkowski::{MinkowskiPair, SupportPoint};
use super::tolerances::ContactTolerances;
use crate::math::{Real, Vector};
use crate::shape::SupportMap;

#[derive(Copy, Clone, Debug)]
struct Face {
    v: [u32; 3],
    adj: [u32; 3],
    adj_edge: [u8; 3],
    normal: Vector,
    offset: Real,
    alive: bool,
}

/// Neighbours of the start tetrahedron's faces `[p0, p2, p1], [p0, p1, p3], [p0, p3, p2], [p1, p2, p3]`:
/// for face `f` and its edge `e` (from `v[e]` to `v[e + 1]`), the face across that edge and the index of
/// the same edge (reversed) in it.
const TETRAHEDRON_ADJACENCY: [([u32; 3], [u8; 3]); 4] = [
    ([2, 3, 1], [2, 0, 0]),
    ([0, 3, 2], [2, 2, 0]),
    ([1, 3, 0], [2, 1, 0]),
    ([0, 2, 1], [1, 1, 1]),
];

/// Reusable buffers of EPA (and of the other queries that need scratch space). One per thread.
#[derive(Clone, Debug)]
pub struct EpaScratch {
    verts: Vec<SupportPoint>,
    faces: Vec<Face>,
    /// Plane offset of each face, +∞ once the face is removed: the closest-face scan reads only this.
    live_offsets: Vec<Real>,
    horizon: Vec<(u32, u8)>,
    /// The fan of the current iteration: (face, its vertex `v[0]`, its vertex `v[1]`), kept beside the
    /// index so that the fan linking scans this list alone.
    new_faces: Vec<(u32, u32, u32)>,
    max_verts: usize,
    max_faces: usize,
}

impl Default for EpaScratch {
    fn default() -> Self {
        Self::new(&ContactTolerances::default())
    }
}

impl EpaScratch {
    /// Buffers sized for the iteration cap of `tol` (allocated once, here).
    pub fn new(tol: &ContactTolerances) -> Self {
        let max_verts = tol.epa_max_iterations as usize + 16;
        let max_faces = 8 * max_verts + 64;
        Self {
            verts: Vec::with_capacity(max_verts),
            faces: Vec::with_capacity(max_faces),
            live_offsets: Vec::with_capacity(max_faces),
            horizon: Vec::with_capacity(max_faces),
            new_faces: Vec::with_capacity(max_faces),
            max_verts,
            max_faces,
        }
    }
}

/// What EPA found.
#[derive(Copy, Clone, Debug, PartialEq)]
pub enum EpaOutcome {
    /// `depth` = h_A(n) + h_B(−n) along the unit `normal` (frame 1, from A to B); may be slightly negative for
    /// a pair that only touches. `point_a − point_b = depth · normal` (frame 1).
    Converged {
        depth: Real,
        normal: Vector,
        point_a: Vector,
        point_b: Vector,
        /// Support hints (vertex indices) of the terminal face's three vertices: a warm start for the next
        /// query of the same pair.
        face: [[u32; 2]; 3],
    },
    MaxIterations,
    Degenerate(Degeneracy),
}

/// Why EPA gave up (the caller falls back to the exact answer).
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum Degeneracy {
    /// No proper tetrahedron could be formed from the start points.
    FlatStart,
    /// A buffer of the scratch is full.
    BufferFull,
    /// A new face has no usable normal.
    FaceWithoutNormal,
    /// The horizon is not one simple loop.
    BrokenHorizon,
}

/// Result of one EPA run.
#[derive(Copy, Clone, Debug)]
pub struct EpaResult {
    pub outcome: EpaOutcome,
    pub iterations: u32,
}

fn face_plane(verts: &[SupportPoint], v: [u32; 3]) -> Option<(Vector, Real)> {
    let a = verts[v[0] as usize].w;
    let b = verts[v[1] as usize].w;
    let c = verts[v[2] as usize].w;
    // Cross product of the two edges meeting at the vertex opposite the longest edge (best conditioned).
    let ab = b - a;
    let bc = c - b;
    let ca = a - c;
    let (lab, lbc, lca) = (ab.norm_squared(), bc.norm_squared(), ca.norm_squared());
    let n = if lab >= lbc && lab >= lca {
        bc.cross(&ca)
    } else if lbc >= lab && lbc >= lca {
        ca.cross(&ab)
    } else {
        ab.cross(&bc)
    };
    let nn = n.norm();
    if !nn.is_finite() || nn <= 0.0 {
        return None;
    }
    let n = n * (1.0 / nn);
    let offset = (n.dot(&a) + n.dot(&b) + n.dot(&c)) * (1.0 / 3.0);
    Some((n, offset))
}

impl EpaScratch {
    /// The smallest plane offset among the live faces of the last run's polytope (a lower bound of the
    /// overlap while the polytope is intact), `None` if no face is alive.
    pub fn closest_offset(&self) -> Option<Real> {
        self.live_offsets
            .iter()
            .copied()
            .filter(|o| o.is_finite())
            .min_by(|x, y| x.total_cmp(y))
    }

    fn push_face(&mut self, v: [u32; 3]) -> Option<u32> {
        if self.faces.len() >= self.max_faces {
            return None;
        }
        let (normal, offset) = face_plane(&self.verts, v)?;
        self.faces.push(Face {
            v,
            adj: [u32::MAX; 3],
            adj_edge: [0; 3],
            normal,
            offset,
            alive: true,
        });
        self.live_offsets.push(offset);
        Some(self.faces.len() as u32 - 1)
    }

    /// Builds the start tetrahedron from four vertex indices; `false` if it is flat.
    fn start_tetrahedron(&mut self, idx: [u32; 4]) -> bool {
        let w = |i: u32| self.verts[i as usize].w;
        let e1 = w(idx[1]) - w(idx[0]);
        let e2 = w(idx[2]) - w(idx[0]);
        let e3 = w(idx[3]) - w(idx[0]);
        let vol = e1.dot(&e2.cross(&e3));
        let ref_vol = e1.norm() * e2.norm() * e3.norm();
        if vol.is_nan() || vol.abs() <= 1e-9 * ref_vol {
            return false;
        }
        let [p0, mut p1, mut p2, p3] = idx;
        if vol < 0.0 {
            std::mem::swap(&mut p1, &mut p2);
        }
        self.faces.clear();
        self.live_offsets.clear();
        for f in [[p0, p2, p1], [p0, p1, p3], [p0, p3, p2], [p1, p2, p3]] {
            if self.push_face(f).is_none() {
                return false;
            }
        }
        // The adjacency of these four faces depends only on their vertex order, not on the points: it is
        // the fixed table `TETRAHEDRON_ADJACENCY` (checked against edge matching in the tests), which saves
        // the edge-matching loop on every query.
        for (fi, (adj, adj_edge)) in TETRAHEDRON_ADJACENCY.iter().enumerate() {
            self.faces[fi].adj = *adj;
            self.faces[fi].adj_edge = *adj_edge;
        }
        true
    }

    fn silhouette(&mut self, f: u32, edge: u8, w: &Vector, vis_eps: Real) {
        let face = &mut self.faces[f as usize];
        if !face.alive {
            return;
        }
        if face.normal.dot(w) - face.offset <= vis_eps {
            self.horizon.push((f, edge));
            return;
        }
        face.alive = false;
        let (adj, adj_edge) = (face.adj, face.adj_edge);
        self.live_offsets[f as usize] = Real::INFINITY;
        for j in 1..3u8 {
            let e = ((edge + j) % 3) as usize;
            self.silhouette(adj[e], adj_edge[e], w, vis_eps);
        }
    }
}

/// Runs EPA on an intersecting (or touching) pair. `simplex` is GJK's terminal simplex (used when it is a
/// proper tetrahedron), `scale` the pair's length scale.
pub fn epa<A: SupportMap + ?Sized, B: SupportMap + ?Sized>(
    pair: &mut MinkowskiPair<'_, A, B>,
    simplex: &Simplex,
    scale: Real,
    tol: &ContactTolerances,
    scratch: &mut EpaScratch,
) -> EpaResult {
    let gap_tol = tol.epa_gap * scale;
    let vis_eps = 0.5 * gap_tol;
    if let Err(why) = start_polytope(pair, simplex, scratch) {
        return EpaResult {
            outcome: EpaOutcome::Degenerate(why),
            iterations: 0,
        };
    }
    let degenerate = |iterations, why| EpaResult {
        outcome: EpaOutcome::Degenerate(why),
        iterations,
    };
    let mut iterations = 0u32;
    loop {
        // The closest face (smallest signed plane offset) among the live ones.
        let mut best = u32::MAX;
        let mut best_offset = Real::INFINITY;
        for (i, &o) in scratch.live_offsets.iter().enumerate() {
            if o < best_offset {
                best_offset = o;
                best = i as u32;
            }
        }
        if best == u32::MAX {
            return degenerate(iterations, Degeneracy::BrokenHorizon);
        }
        let face = scratch.faces[best as usize];
        let n = face.normal;
        let s = pair.support(&n);
        let h = n.dot(&s.a) - n.dot(&s.b);
        let gap = h - face.offset;
        let duplicate = face.v.iter().any(|&i| scratch.verts[i as usize].w == s.w);
        if gap <= gap_tol || duplicate {
            return EpaResult {
                outcome: finish(scratch, best, h, 2.0 * gap_tol),
                iterations,
            };
        }
        if iterations >= tol.epa_max_iterations {
            return EpaResult {
                outcome: EpaOutcome::MaxIterations,
                iterations,
            };
        }
        iterations += 1;
        if scratch.verts.len() >= scratch.max_verts {
            return degenerate(iterations, Degeneracy::BufferFull);
        }
        scratch.verts.push(s);
        let wi = scratch.verts.len() as u32 - 1;

        if let Err(why) = scratch.replace_visible(best, &face, &s.w, wi, vis_eps) {
            return degenerate(iterations, why);
        }
    }
}

/// The start polytope: GJK's terminal simplex when it is a proper tetrahedron, else a tetrahedron of
/// supports along fixed directions (and, for a flat set, along the plane's normals).
#[inline]
fn start_polytope<A: SupportMap + ?Sized, B: SupportMap + ?Sized>(
    pair: &mut MinkowskiPair<'_, A, B>,
    simplex: &Simplex,
    scratch: &mut EpaScratch,
) -> Result<(), Degeneracy> {
    scratch.verts.clear();
    scratch.faces.clear();
    scratch.live_offsets.clear();
    if simplex.len == 4 {
        scratch.verts.extend_from_slice(&simplex.pts);
        if scratch.start_tetrahedron([0, 1, 2, 3]) {
            return Ok(());
        }
    }
    scratch.verts.clear();
    scratch.verts.extend_from_slice(&simplex.pts[..simplex.len]);
    // Supports along the axes of a fixed, irregular frame (coordinate axes are tie-prone for aligned
    // shapes), then along the diagonals of that frame if the first six are not enough.
    for d in START_DIRECTIONS[..6].iter() {
        let s = pair.support(d);
        scratch.verts.push(s);
    }
    if spread_tetrahedron(&scratch.verts).is_none() {
        for d in START_DIRECTIONS[6..].iter() {
            let s = pair.support(d);
            scratch.verts.push(s);
        }
    }
    // Still flat (all supports so far in one plane through a face of A ⊖ B's symmetric core): the
    // supports along the plane's two normals leave it, since A ⊖ B has volume.
    if let Some((i0, i1, i2)) = spread_triangle(&scratch.verts) {
        if spread_tetrahedron(&scratch.verts).is_none() {
            let (p0, p1, p2) = (
                scratch.verts[i0].w,
                scratch.verts[i1].w,
                scratch.verts[i2].w,
            );
            let nrm = (p1 - p0).cross(&(p2 - p0));
            let nrm = nrm / nrm.norm();
            let up = pair.support(&nrm);
            let down = pair.support(&-nrm);
            scratch.verts.push(up);
            scratch.verts.push(down);
        }
    }
    match spread_tetrahedron(&scratch.verts) {
        Some(idx) if scratch.start_tetrahedron(idx) => Ok(()),
        _ => Err(Degeneracy::FlatStart),
    }
}

impl EpaScratch {
    /// Removes face `best` (a copy: `face`) and every face visible from the new vertex `w` (index `wi`),
    /// and closes the hole with a fan of faces from the horizon to `w`.
    #[inline(always)]
    fn replace_visible(
        &mut self,
        best: u32,
        face: &Face,
        w: &Vector,
        wi: u32,
        vis_eps: Real,
    ) -> Result<(), Degeneracy> {
        self.horizon.clear();
        self.faces[best as usize].alive = false;
        self.live_offsets[best as usize] = Real::INFINITY;
        for e in 0..3 {
            self.silhouette(face.adj[e], face.adj_edge[e], w, vis_eps);
        }
        if self.horizon.len() < 3 {
            return Err(Degeneracy::BrokenHorizon);
        }
        // A fan of new faces, one per horizon edge: [end, start, w] of the (reversed) horizon edge.
        self.new_faces.clear();
        for h_idx in 0..self.horizon.len() {
            let (g, k) = self.horizon[h_idx];
            let gf = &self.faces[g as usize];
            let p = gf.v[(k as usize + 1) % 3];
            let q = gf.v[k as usize];
            let Some(nf) = self.push_face([p, q, wi]) else {
                return Err(Degeneracy::FaceWithoutNormal);
            };
            self.faces[nf as usize].adj[0] = g;
            self.faces[nf as usize].adj_edge[0] = k;
            self.faces[g as usize].adj[k as usize] = nf;
            self.faces[g as usize].adj_edge[k as usize] = 0;
            self.new_faces.push((nf, p, q));
        }
        self.link_fan()
    }

    /// Links the fan: face j's edge 1 (q_j → w) meets face i's edge 2 (w → p_i) where p_i = q_j. The
    /// horizon must be one simple loop: every q matches exactly one p.
    #[inline(always)]
    fn link_fan(&mut self) -> Result<(), Degeneracy> {
        for &(fj, _, qj) in self.new_faces.iter() {
            let mut found = u32::MAX;
            for &(fi, pi, _) in self.new_faces.iter() {
                if pi == qj {
                    if found != u32::MAX {
                        return Err(Degeneracy::BrokenHorizon);
                    }
                    found = fi;
                }
            }
            if found == u32::MAX || self.faces[found as usize].adj[2] != u32::MAX {
                return Err(Degeneracy::BrokenHorizon);
            }
            self.faces[fj as usize].adj[1] = found;
            self.faces[fj as usize].adj_edge[1] = 2;
            self.faces[found as usize].adj[2] = fj;
            self.faces[found as usize].adj_edge[2] = 1;
        }
        Ok(())
    }
}

/// After an [`epa`] run that stopped at its iteration cap (the polytope is then intact): the offset of the
/// closest live face, a lower bound of the overlap since the polytope lies inside A ⊖ B, and the features
/// along that face's normal as [`EpaOutcome::Converged`] reports them, whose depth h(n) is an upper bound.
/// `None` if no face is alive.
pub fn closest_face_bounds<A: SupportMap + ?Sized, B: SupportMap + ?Sized>(
    pair: &mut MinkowskiPair<'_, A, B>,
    scratch: &EpaScratch,
) -> Option<(Real, EpaOutcome)> {
    let (best, offset) = scratch
        .live_offsets
        .iter()
        .enumerate()
        .filter(|(i, _)| scratch.faces[*i].alive)
        .min_by(|x, y| x.1.total_cmp(y.1))?;
    let n = scratch.faces[best].normal;
    let s = pair.support(&n);
    let h = n.dot(&s.a) - n.dot(&s.b);
    Some((*offset, finish(scratch, best as u32, h, 0.0)))
}

/// Start directions: ±axes and the eight diagonals of the frame rotated by the Euler angles (0.3, 0.7, 1.1)
/// rad: a fixed, irregular frame, so that aligned shapes do not produce ties between start supports.
static START_DIRECTIONS: std::sync::LazyLock<[Vector; 14]> = std::sync::LazyLock::new(|| {
    let r = crate::math::Rotation::from_euler_angles(0.3, 0.7, 1.1);
    let s3 = 1.0 / (3.0 as Real).sqrt();
    let local = [
        Vector::x(),
        -Vector::x(),
        Vector::y(),
        -Vector::y(),
        Vector::z(),
        -Vector::z(),
        Vector::new(s3, s3, s3),
        Vector::new(-s3, -s3, -s3),
        Vector::new(s3, -s3, s3),
        Vector::new(-s3, s3, -s3),
        Vector::new(s3, s3, -s3),
        Vector::new(-s3, -s3, s3),
        Vector::new(-s3, s3, s3),
        Vector::new(s3, -s3, -s3),
    ];
    local.map(|d| r * d)
});

/// The fixed start directions of EPA (unit, frame 1), for callers that need a few well-spread probes.
pub(crate) fn start_directions() -> impl Iterator<Item = Vector> {
    START_DIRECTIONS.iter().copied()
}

/// Three of `pts` with maximal spread (farthest from the centroid, farthest from it, farthest from their
/// line); `None` if all are collinear.
fn spread_triangle(pts: &[SupportPoint]) -> Option<(usize, usize, usize)> {
    let n = pts.len();
    let c = pts.iter().fold(Vector::zeros(), |acc, p| acc + p.w) / n as Real;
    let far = |from: Vector| {
        (0..n).max_by(|&i, &j| {
            (pts[i].w - from)
                .norm_squared()
                .total_cmp(&(pts[j].w - from).norm_squared())
        })
    };
    let i0 = far(c)?;
    let p0 = pts[i0].w;
    let i1 = far(p0)?;
    let d1 = pts[i1].w - p0;
    if d1.norm_squared() == 0.0 {
        return None;
    }
    let i2 = (0..n).max_by(|&i, &j| {
        d1.cross(&(pts[i].w - p0))
            .norm_squared()
            .total_cmp(&d1.cross(&(pts[j].w - p0)).norm_squared())
    })?;
    let nrm = d1.cross(&(pts[i2].w - p0));
    let nn = nrm.norm_squared();
    if nn.is_nan() || nn <= 1e-24 * d1.norm_squared() * d1.norm_squared() {
        return None;
    }
    Some((i0, i1, i2))
}

/// Four of `pts` with maximal spread: [`spread_triangle`] and the point farthest from its plane. `None` if
/// they span no proper volume (relative volume below 1e-9).
fn spread_tetrahedron(pts: &[SupportPoint]) -> Option<[u32; 4]> {
    let (i0, i1, i2) = spread_triangle(pts)?;
    let p0 = pts[i0].w;
    let e1 = pts[i1].w - p0;
    let e2 = pts[i2].w - p0;
    let nrm = e1.cross(&e2);
    let i3 = (0..pts.len()).max_by(|&i, &j| {
        nrm.dot(&(pts[i].w - p0))
            .abs()
            .total_cmp(&nrm.dot(&(pts[j].w - p0)).abs())
    })?;
    let e3 = pts[i3].w - p0;
    let vol = nrm.dot(&e3);
    if vol.is_nan() || vol.abs() <= 1e-9 * e1.norm() * e2.norm() * e3.norm() {
        return None;
    }
    Some([i0 as u32, i1 as u32, i2 as u32, i3 as u32])
}

/// Contact features from the terminal face: depth `h` (the support distance along its normal), the points
/// as barycentric combinations at the projection p = offset·n of the origin on the face plane.
///
/// When the terminal plane is a facet of A ⊖ B split into several coplanar triangles (face–face and
/// edge–edge contacts), the face picked by the scan need not contain p; the walk moves across edges to the
/// coplanar neighbour that does, so that c1 − c2 = p exactly and both points stay on the surfaces. Only when p
/// lies outside every coplanar face (origin outside P: touching pairs) is it clamped to the face.
fn finish(scratch: &EpaScratch, start: u32, h: Real, coplanar_tol: Real) -> EpaOutcome {
    let verts = &scratch.verts;
    let mut fi = start;
    let n = scratch.faces[start as usize].normal;
    let p = n * scratch.faces[start as usize].offset;
    let mut s = Simplex::default();
    for _step in 0..64 {
        let face = &scratch.faces[fi as usize];
        let w: [Vector; 3] = std::array::from_fn(|k| verts[face.v[k] as usize].w - p);
        // Unclamped barycentric weights of p in the face (signed areas along n).
        let area = |x: &Vector, y: &Vector| n.dot(&x.cross(y));
        let lam = [area(&w[1], &w[2]), area(&w[2], &w[0]), area(&w[0], &w[1])];
        let total = lam[0] + lam[1] + lam[2];
        let (kmin, lmin) = (0..3)
            .map(|k| (k, lam[k]))
            .min_by(|x, y| x.1.total_cmp(&y.1))
            .expect("three weights");
        if total > 0.0 && lmin >= -1e-14 * total {
            let mut pa = Vector::zeros();
            let mut pb = Vector::zeros();
            for k in 0..3 {
                let sp = verts[face.v[k] as usize];
                pa += sp.a * (lam[k].max(0.0) / total);
                pb += sp.b * (lam[k].max(0.0) / total);
            }
            return symmetric(pa, pb, n, h, face_ids(verts, face));
        }
        // Cross the edge opposite the most negative weight, if the neighbour lies in the same plane.
        let e = (kmin + 1) % 3;
        let g = face.adj[e];
        let gf = &scratch.faces[g as usize];
        let same_plane = gf.alive
            && gf.normal.dot(&n) > 1.0 - 1e-12
            && (gf.offset - scratch.faces[start as usize].offset).abs() <= coplanar_tol;
        if !same_plane || g == start {
            break;
        }
        fi = g;
    }
    let face = &scratch.faces[fi as usize];
    for k in 0..3 {
        let sp = verts[face.v[k] as usize];
        s.pts[k] = SupportPoint { w: sp.w - p, ..sp };
    }
    s.len = 3;
    closest_to_origin(&mut s);
    let mut pa = Vector::zeros();
    let mut pb = Vector::zeros();
    for k in 0..s.len {
        pa += s.pts[k].a * s.bary[k];
        pb += s.pts[k].b * s.bary[k];
    }
    symmetric(pa, pb, n, h, face_ids(verts, face))
}

fn face_ids(verts: &[SupportPoint], face: &Face) -> [[u32; 2]; 3] {
    face.v.map(|i| [verts[i as usize].ia, verts[i as usize].ib])
}

/// Points with c1 − c2 = h n exactly, centred on the barycentric pair (pa, pb).
fn symmetric(pa: Vector, pb: Vector, n: Vector, h: Real, face: [[u32; 2]; 3]) -> EpaOutcome {
    let mid = (pa + pb) * 0.5;
    let half = n * (0.5 * h);
    EpaOutcome::Converged {
        depth: h,
        normal: n,
        point_a: mid + half,
        point_b: mid - half,
        face,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The fixed adjacency table of the start tetrahedron equals the one found by matching reversed edges.
    #[test]
    fn tetrahedron_adjacency_table_matches_edge_matching() {
        let faces: [[u32; 3]; 4] = [[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]];
        for (fi, f) in faces.iter().enumerate() {
            for e in 0..3 {
                let (a, b) = (f[e], f[(e + 1) % 3]);
                let mut found = Vec::new();
                for (gj, g) in faces.iter().enumerate() {
                    for k in 0..3 {
                        if gj != fi && g[k] == b && g[(k + 1) % 3] == a {
                            found.push((gj as u32, k as u8));
                        }
                    }
                }
                let table = (
                    TETRAHEDRON_ADJACENCY[fi].0[e],
                    TETRAHEDRON_ADJACENCY[fi].1[e],
                );
                assert_eq!(
                    found,
                    vec![table],
                    "face {fi} {f:?}, edge {e}: edge matching gives {found:?}, table gives {table:?}"
                );
            }
        }
    }
}
