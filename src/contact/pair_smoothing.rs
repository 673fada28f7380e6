//! The overlap a polyhedron–polyhedron contact hands to the law: the Minkowski overlap with the kink of tied
//! support vertices smoothed within a band, so that the force stays continuous when an edge or a face lands
//! flat on a face and the energy error of velocity Verlet stays second order. (The kink of tied Minkowski
//! faces with different normals is analysed below and left.)
//!
//! # The kinks of the exact overlap
//! The Minkowski overlap is δ_M = min over directions n of φ(n) = h_A(n) + h_B(−n) (h the support
//! function), reached at a facet of A ⊖ B. Near the minimising facet, φ is a minimum of smooth branches,
//! and δ_M has a kink (a jump of its gradient, i.e. of the force) wherever two branches tie:
//! - (a) **tied support vertices**: for a facet made of a face of A (outward normal n_f, offset o_f) and a
//!   vertex of B, φ(n_f) = max_j (o_f − n_f·b_j), the depth of B's deepest vertex below the face plane. When
//!   an edge or a face of B lies (nearly) parallel to the face, two vertices of B tie, and the contact point
//!   c2 jumps from one to the other (the wall's kink, [`super::wall_depth`], with A's face as the wall);
//! - (b) **tied facets**: two facets of A ⊖ B with different normals (a face of A and a face of B when two
//!   faces meet nearly parallel; two faces of A when a vertex of B pokes in near A's edge) give nearly the
//!   same depth, and n_M jumps from one to the other when their depths cross.
//!
//! Either jump makes the force discontinuous in the pose and costs velocity Verlet its second order
//! (diagnosed in the `stress_long_run` slab box: 62 jumps of kind (a) and 29 of kind (b) in 60 000 steps).
//!
//! # Candidates and their smoothed depths
//! Every direction n gives an upper bound φ(n) ≥ δ_M, so δ_M is the minimum over any set of directions that
//! contains the minimising one. We take the candidate directions
//! - the outward normal n_f of every face f of A (contact normal n_f, from A to B);
//! - minus the outward normal of every face g of B (contact normal −m_g);
//! - the exact EPA normal n_M when it is no face normal (an edge–edge facet), with its exact depth δ_M;
//!
//! and for a face candidate replace the maximum over the other body's vertex depths by the smoothed depth
//! D = 2 S_h − S_2h of [`super::wall_depth`]:
//!
//! ```text
//! d_f = D_h({o_f − n_f·b_j}_j)      (face f of A, depths of B's vertices below its plane)
//! d_g = D_h({o_g − m_g·a_i}_i)      (face g of B, depths of A's vertices below its plane)
//! ```
//!
//! Each d_f is a C² function of the poses (n_f and o_f move with A, the b_j with B), never above
//! φ(n_f), equal to it when one vertex leads by 2h (and at exact ties). Its gradient is a single force:
//! with weights w_j = ∂D/∂d_j (summing to 1), a translation t of B changes d_f by −n_f·t, a rotation ω of B
//! about Y by −ω·((c2 − Y) × n_f), and a rotation of A (which carries n_f and o_f) about X by
//! ω·((c2 − X) × n_f), where c2 = Σ_j w_j b_j. So F = k d_f^n along n_f on the line through c2 is exactly
//! the gradient of k d_f^(n+1)/(n+1): equal and opposite forces on one line, energy and angular momentum
//! conserved. (A face of B is the mirror image: the line passes through c1 = Σ_i w_i a_i.)
//!
//! # The overlap the law sees: the lowest candidate
//! The law sees δ̃ = min_k d_k with the normal and the force line of the lowest candidate. Properties:
//! - δ̃ ≤ δ_M: the candidate of the EPA facet is in the set (its face, or the exact edge–edge value), so the
//!   law never acts on shapes that do not overlap, and the contact status stays the exact one;
//! - δ̃ ≥ δ_M − (the shortfall of D, 0.13 h for two tied vertices, 0.22 h for a tilted square): within the
//!   band of the exact overlap;
//! - where one vertex leads by 2h below the EPA facet's face (or the facet is edge–edge and no face
//!   candidate undercuts it), δ̃ = δ_M and the exact geometry is returned unchanged, bit for bit.
//!
//! So kind (a) is removed exactly: the face candidate's D is C² through the tie and its force is its exact
//! gradient. Kind (b), a switch of the lowest candidate between two normals, remains a kink of δ̃ as of
//! δ_M. A smooth minimum of the candidates, δ̃ = −S_h(−d_1, …, −d_K), would be C², but its gradient
//! Σ_k ω_k F_k is a sum of forces on K different lines: a wrench with a couple about the resultant
//! (ω₁ω₂ F |c2₁ − c2₂| sin θ for two normals at θ), which one force at one point — what
//! [`ContactGeometry`] carries — cannot represent. Measured: blending an edge–edge EPA facet with the two
//! face candidates 0.009 rad away (the `single_contact_energy` FaceFace impact, h = the peak overlap)
//! left an energy error of 1.4e-5 that no longer shrank with Δt (order 0.9), where the exact overlap
//! converges at second order. Smoothing kind (b) needs the contact to carry that couple (or a second
//! point) through the laws; it is left open.
//!
//! Limits: edge–edge facets other than the EPA facet are not candidates (scanning edge pairs costs
//! O(E_A E_B)); they never undercut δ_M, so they could only matter for a blend.
//!
//! # The band and the cost
//! h = `band` × min(L_A, L_B), L the bounding diameter: the same rule as the wall (h ≈ the characteristic
//! overlap of the scene; 1e-4 by default, the static overlap of a gravity-loaded bed). A face candidate
//! is evaluated only if its cheap lower bound o_f − n_f·c2 (the exact c2 ∈ B) is within h of δ_M; most
//! faces fail this with one dot product, so a contact costs F_A + F_B dot products plus one scan of the
//! other body's vertices per face within reach, usually one.

use super::sat::Polytope;
use super::wall_depth::smoothed_depth;
use super::{ContactGeometry, ContactKind};
use crate::math::{Point, Pose, Real, Rotation, Vector};

/// What a polyhedron–polyhedron contact hands to the law.
#[derive(Copy, Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub enum PairSmoothing {
    /// The exact Minkowski overlap δ_M, n_M, c1, c2 of EPA (the paper's law; force jumps at ties).
    Exact,
    /// The smoothed overlap of the module docs with h = `band` × min(L_A, L_B).
    Smoothed {
        /// Smoothing width as a fraction of the smaller shape's length scale (dimensionless).
        band: Real,
    },
}

impl Default for PairSmoothing {
    /// `Smoothed { band: 1e-4 }`: the default band of the wall ([`super::wall_depth`]), for the same reason.
    fn default() -> Self {
        PairSmoothing::Smoothed { band: 1e-4 }
    }
}

/// Candidates further than this many bands above δ_M (by their lower bound) are not evaluated: their
/// smoothed depth is at least φ − 0.22 h > δ_M, so they cannot be the lowest.
const REACH: Real = 1.0;
/// Two unit normals closer than this (|n₁ × n₂|) are the same direction (the EPA normal of a face facet).
const SAME_NORMAL: Real = 1e-9;
/// At most this many candidates are kept (more would need a degenerate configuration: many faces within
/// h of δ_M); the deepest ones are dropped, which never drops the lowest.
const MAX_CANDIDATES: usize = 8;

/// The candidates found so far: at most `MAX_CANDIDATES`, the deepest dropped first.
struct Candidates {
    list: [Candidate; MAX_CANDIDATES],
    len: usize,
    /// Whether a face candidate has the EPA normal.
    has_epa_normal: bool,
}

impl Default for Candidates {
    fn default() -> Self {
        let none = Candidate {
            depth: 0.0,
            normal: Vector::zeros(),
            point_b: Vector::zeros(),
            smoothed: false,
        };
        Self {
            list: [none; MAX_CANDIDATES],
            len: 0,
            has_epa_normal: false,
        }
    }
}

impl Candidates {
    /// Adds `c`, replacing the deepest one when full.
    #[inline(always)]
    fn add(&mut self, c: Candidate) {
        if self.len < MAX_CANDIDATES {
            self.list[self.len] = c;
            self.len += 1;
        } else if let Some(worst) = (0..MAX_CANDIDATES)
            .max_by(|&i, &j| self.list[i].depth.total_cmp(&self.list[j].depth))
            .filter(|&k| self.list[k].depth > c.depth)
        {
            self.list[worst] = c;
        }
    }
}

#[derive(Copy, Clone, Debug)]
struct Candidate {
    depth: Real,
    /// Contact normal from A to B (A's frame).
    normal: Vector,
    /// A point of B on the force line (A's frame).
    point_b: Vector,
    /// True when the value is not the exact single-vertex depth (a tie was smoothed).
    smoothed: bool,
}

/// A small stack buffer of (depth, vertex) pairs, spilling to the heap beyond its capacity.
struct Band {
    depths: [Real; 32],
    index: [u32; 32],
    len: usize,
    spill: Vec<(Real, u32)>,
}

impl Band {
    fn new() -> Self {
        Self {
            depths: [0.0; 32],
            index: [0; 32],
            len: 0,
            spill: Vec::new(),
        }
    }
    fn clear(&mut self) {
        self.len = 0;
        self.spill.clear();
    }
    /// Keeps the entries with depth > `floor`, in order.
    fn retain_above(&mut self, floor: Real) {
        if self.spill.is_empty() {
            let mut kept = 0;
            for k in 0..self.len {
                if self.depths[k] > floor {
                    self.depths[kept] = self.depths[k];
                    self.index[kept] = self.index[k];
                    kept += 1;
                }
            }
            self.len = kept;
        } else {
            self.spill.retain(|e| e.0 > floor);
        }
    }
    fn push(&mut self, d: Real, i: u32) {
        if self.spill.is_empty() && self.len < self.depths.len() {
            self.depths[self.len] = d;
            self.index[self.len] = i;
            self.len += 1;
        } else {
            if self.spill.is_empty() {
                self.spill
                    .extend((0..self.len).map(|k| (self.depths[k], self.index[k])));
            }
            self.spill.push((d, i));
        }
    }
}

/// Polytopes with more vertices than this find the vertices within the band by walking their edge graph
/// ([`band_by_walk`]); smaller ones scan ([`band_by_scan`]). Both give the same band, bit for bit; the
/// walk's bookkeeping does not pay on a rock's hull of ~22 vertices: instructions of the quick rockfill
/// penetration from a saved bed (callgrind), walking hulls of more than 16 vertices (the ogive, 469):
/// 15.12e9; walking every hull of 4 or more: 15.19e9; scanning all: 15.85e9.
const WALK_MIN_VERTICES: usize = 17;
/// The walk keeps at most this many explored vertices (on the stack); beyond, the scan answers.
const WALK_CAPACITY: usize = 64;
/// The walk marks explored vertices in a bit set of this many 64-bit words; larger polytopes scan.
const WALK_MARK_WORDS: usize = 16;
/// The walk explores every vertex whose depth lies within 2h + `WALK_MARGIN` × (|s| + R) of its start (s the
/// depth offset, R the bounding radius): 10^7 times the round-off of a computed depth, and 100 times the
/// hull's coplanarity tolerance (1e-10 of the extent), so that the exactness argument of [`band_by_walk`]
/// holds for the computed depths of the stored hull.
const WALK_MARGIN: Real = 1e-8;

/// The band by a full scan: every i with depth(i) > deepest − 2h (deepest = max_i depth(i)) pushed into
/// `band` in increasing index order; returns (deepest, the smallest index reaching it).
///
/// One pass: a vertex is kept when it lies within 2h of the running maximum, and the kept ones are
/// filtered against the final maximum at the end. The running maximum never exceeds the final one (and
/// x ↦ x − 2h is monotone in floating point), so every vertex of the band is kept, and the filter leaves
/// exactly the band, in index order.
///
/// Stops with [`Found::Rejected`] as soon as a depth exceeds `reject_above`.
fn band_by_scan(
    n: usize,
    depth: &impl Fn(usize) -> Real,
    h: Real,
    reject_above: Real,
    band: &mut Band,
) -> Found {
    let mut deepest = Real::NEG_INFINITY;
    let mut arg = 0;
    band.clear();
    for i in 0..n {
        let d = depth(i);
        if d > deepest {
            if d > reject_above {
                return Found::Rejected;
            }
            deepest = d;
            arg = i;
        }
        if d > deepest - 2.0 * h {
            band.push(d, i as u32);
        }
    }
    band.retain_above(deepest - 2.0 * h);
    Found::Band(deepest, arg)
}

/// What a band search found.
enum Found {
    /// The deepest depth and the smallest index reaching it; the band is in the [`Band`] buffer.
    Band(Real, usize),
    /// A vertex lies deeper than the rejection level (see [`smoothed_support`]).
    Rejected,
    /// The walk outgrew its buffers (the scan answers instead).
    Overflow,
}

/// The band of [`band_by_scan`], the same values in the same order, found by walking the edge graph of
/// `p` from vertex `*start` (any value accepted; left at the deepest vertex found, a warm start for the
/// next call). [`Found::Overflow`] when the polytope or the explored set exceeds the walk's buffers (then
/// scan); [`Found::Rejected`] as soon as a depth exceeds `reject_above`.
///
/// 1. Hill-climb: move to a strictly deeper neighbour while there is one.
/// 2. Explore from that vertex t (breadth-first over neighbours) every vertex with
///    depth > depth(t) − 2h − m, m = `margin`; collect their depths.
/// 3. Keep those within 2h of the deepest collected one, sorted by index.
///
/// Why this is exact: the depth is an affine function f of the vertex position. On a convex polytope, the
/// vertices with f ≥ L form a connected subgraph of the edge graph for every level L ≤ max f: a vertex
/// that is not a maximiser has an edge to a strictly deeper neighbour (otherwise the polytope, which lies
/// in the cone of the edges leaving that vertex, would have f no larger there), so strictly deepening
/// edges lead from it to the face of maximisers without leaving the set, and the edge graph of that face
/// (a vertex, an edge or a polygon) is connected. Take L = depth(t) − 2h − m + 2ε, ε a bound on the
/// round-off of a computed depth (m ≥ 3ε): the exact superlevel set contains t, is connected, and its
/// vertices all pass the test of step 2, so step 2 explores all of it. It holds the global maximiser of
/// the computed depths (exact value ≥ computed − ε ≥ depth(t) − ε ≥ L) and every vertex within 2h of it
/// (exact value > max − 2h − ε ≥ L). So the collected maximum is the scan's `deepest` (and its smallest
/// index the scan's `arg`), and the kept set is the scan's band, whatever vertex the climb stopped at:
/// the climb only keeps the explored set small. Tested against the definition on random hulls, a
/// projectile-like body of revolution and tied directions (`band_scan_and_walk_equal_the_definition_*`).
fn band_by_walk<P: Polytope + ?Sized>(
    p: &P,
    depth: &impl Fn(usize) -> Real,
    h: Real,
    margin: Real,
    reject_above: Real,
    start: &mut u32,
    band: &mut Band,
) -> Found {
    let n = p.vertices().len();
    if n > 64 * WALK_MARK_WORDS {
        return Found::Overflow;
    }
    let mut top = if (*start as usize) < n { *start } else { 0 };
    let mut d_top = depth(top as usize);
    loop {
        let current = top;
        for &k in p.neighbors(current) {
            let d = depth(k as usize);
            if d > d_top {
                top = k;
                d_top = d;
            }
        }
        *start = top;
        if d_top > reject_above {
            return Found::Rejected;
        }
        if top == current {
            break;
        }
    }
    let floor = d_top - 2.0 * h - margin;
    let mut marks = [0u64; WALK_MARK_WORDS];
    let mut found = [(0u32, 0.0); WALK_CAPACITY];
    found[0] = (top, d_top);
    marks[top as usize / 64] |= 1 << (top % 64);
    let (mut len, mut next) = (1, 0);
    while next < len {
        let v = found[next].0;
        next += 1;
        for &k in p.neighbors(v) {
            let (word, bit) = (k as usize / 64, 1u64 << (k % 64));
            if marks[word] & bit != 0 {
                continue;
            }
            let d = depth(k as usize);
            if d > floor {
                if d > reject_above {
                    return Found::Rejected;
                }
                if len == WALK_CAPACITY {
                    return Found::Overflow;
                }
                marks[word] |= bit;
                found[len] = (k, d);
                len += 1;
            }
        }
    }
    let found = &mut found[..len];
    found.sort_unstable_by_key(|f| f.0);
    let mut deepest = Real::NEG_INFINITY;
    let mut arg = 0;
    for &(k, d) in found.iter() {
        if d > deepest {
            deepest = d;
            arg = k as usize;
        }
    }
    band.clear();
    for &(k, d) in found.iter() {
        if d > deepest - 2.0 * h {
            band.push(d, k);
        }
    }
    Found::Band(deepest, arg)
}

/// The smoothed depth of the vertex depths `depth(i)` (i over the vertices of `p`) and the weighted point
/// Σ w_i x_i: (D, point, smoothed?). `smoothed` is false when one vertex leads by 2h (then D is its depth).
///
/// The band is found by a walk of the edge graph from `*start` ([`band_by_walk`], with its `margin`) when
/// `walk` is `Some(margin)`, by a scan otherwise; `*start` is left at a deep vertex, a warm start for the
/// next call. `None` when some vertex lies deeper than `reject_above`, checked first at `*start`: the
/// caller sets it to reach + 2h + m, and D ≥ deepest − 2h (S_h ≥ the deepest depth: Newton climbs to it
/// from there; S_2h < deepest + 2h: ψ vanishes beyond) up to round-off far below m, so such a candidate
/// has D > reach and would be dropped anyway. Most face candidates that pass the cheap lower bound
/// (the faces around a vertex that pokes into the other body) end here after one or a few dot products.
#[allow(clippy::too_many_arguments)]
fn smoothed_support<P: Polytope + ?Sized>(
    p: &P,
    depth: impl Fn(usize) -> Real,
    point: impl Fn(usize) -> Vector,
    h: Real,
    start: &mut u32,
    walk: Option<Real>,
    reject_above: Real,
    band: &mut Band,
) -> Option<(Real, Vector, bool)> {
    let n = p.vertices().len();
    if (*start as usize) < n && depth(*start as usize) > reject_above {
        return None;
    }
    let mut found = match walk {
        Some(margin) => band_by_walk(p, &depth, h, margin, reject_above, start, band),
        None => Found::Overflow,
    };
    if let Found::Overflow = found {
        found = band_by_scan(n, &depth, h, reject_above, band);
    }
    let (deepest, arg) = match found {
        Found::Band(deepest, arg) => (deepest, arg),
        Found::Rejected | Found::Overflow => return None,
    };
    if walk.is_none() {
        *start = arg as u32;
    }
    let count = if band.spill.is_empty() {
        band.len
    } else {
        band.spill.len()
    };
    if count <= 1 {
        return Some((deepest, point(arg), false));
    }
    let (ds, idx): (Vec<Real>, Vec<u32>);
    let (ds, idx): (&[Real], &[u32]) = if band.spill.is_empty() {
        (&band.depths[..band.len], &band.index[..band.len])
    } else {
        ds = band.spill.iter().map(|p| p.0).collect();
        idx = band.spill.iter().map(|p| p.1).collect();
        (&ds, &idx)
    };
    let mut w = [0.0; 32];
    let mut s = [0.0; 32];
    let (mut wv, mut sv);
    let (w, s): (&mut [Real], &mut [Real]) = if count <= 32 {
        (&mut w[..count], &mut s[..count])
    } else {
        wv = vec![0.0; count];
        sv = vec![0.0; count];
        (&mut wv, &mut sv)
    };
    let d = smoothed_depth(ds, h, w, s);
    let mut c = Vector::zeros();
    for (wi, &i) in w.iter().zip(idx) {
        c += point(i as usize) * *wi;
    }
    Some((d, c, true))
}

/// The smoothed overlap of the module docs for an overlapping polyhedron pair, from the exact geometry
/// `exact` (world frame, kind `Overlap`) of A at `pos1` and B at `pos2`. Returns `exact` itself, bit for
/// bit, when no tie lies within the band. Kind and status are kept; the depth is max(δ̃, 0).
///
/// `starts` are vertex indices of A and B near the contact (the pair cache's support hints; any value is
/// accepted) where the band walks of polytopes with more than 16 vertices start; the answer does not
/// depend on them.
pub fn smooth_pair_overlap<A: Polytope + ?Sized, B: Polytope + ?Sized>(
    pos1: &Pose,
    a: &A,
    pos2: &Pose,
    b: &B,
    exact: &ContactGeometry,
    band: Real,
    starts: [u32; 2],
) -> ContactGeometry {
    smooth_pair_overlap_by(pos1, a, pos2, b, exact, band, Some(starts))
}

/// [`smooth_pair_overlap`], walking the edge graphs from `starts` and rejecting deep candidates early when
/// `starts` is given; with `None`, the reference: every vertex of every face candidate scanned.
fn smooth_pair_overlap_by<A: Polytope + ?Sized, B: Polytope + ?Sized>(
    pos1: &Pose,
    a: &A,
    pos2: &Pose,
    b: &B,
    exact: &ContactGeometry,
    band: Real,
    starts: Option<[u32; 2]>,
) -> ContactGeometry {
    if exact.kind != ContactKind::Overlap {
        return *exact;
    }
    let h = band * a.length_scale().min(b.length_scale());
    let pos12 = pos1.inv_mul(pos2);
    let n0 = pos1.rotation.inverse_transform_vector(&exact.normal);
    let pa = pos1.inverse_transform_point(&exact.point_a).coords;
    let pb = pos1.inverse_transform_point(&exact.point_b).coords;
    let frame = Frame {
        h,
        reach: exact.depth + REACH * h,
        rot12: pos12.rotation,
        t12: pos12.translation.vector,
        n0,
        // Without starts (the reference of the tests): every face candidate's band in full, no early
        // rejection.
        rejecting: starts.is_some(),
    };
    let [start_a, start_b] = starts.unwrap_or_default();
    let mut walk_a = Walk {
        enabled: starts.is_some() && a.vertices().len() >= WALK_MIN_VERTICES,
        start: start_a,
    };
    let mut walk_b = Walk {
        enabled: starts.is_some() && b.vertices().len() >= WALK_MIN_VERTICES,
        start: start_b,
    };
    let mut out = FaceSearch {
        band: Band::new(),
        candidates: Candidates::default(),
    };
    frame.faces_of_a(a, b, &pb, &mut walk_b, &mut out);
    let pa_b = pos12.inverse_transform_point(&Point::from(pa)).coords;
    frame.faces_of_b(a, b, &pa_b, &mut walk_a, &mut out);
    let found = &mut out.candidates;
    if !found.has_epa_normal {
        found.add(Candidate {
            depth: exact.depth,
            normal: n0,
            point_b: pb,
            smoothed: false,
        });
    }
    let lead = found.list[..found.len]
        .iter()
        .min_by(|x, y| x.depth.total_cmp(&y.depth))
        .expect("the EPA facet is a candidate");
    if !lead.smoothed && lead.normal.cross(&n0).norm() < SAME_NORMAL {
        // No tie within the band: the exact answer, unchanged.
        return *exact;
    }
    let (depth, normal, point_b) = (lead.depth, lead.normal, lead.point_b);
    let depth = depth.clamp(0.0, exact.depth);
    let point_a = point_b + normal * depth;
    ContactGeometry::from_points(
        exact.kind,
        depth,
        exact.distance,
        pos1.rotation * normal,
        pos1 * Point::from(point_a),
        pos1 * Point::from(point_b),
        exact.status,
    )
}

/// A pair's frame for the band search, in A's frame (copied into each face loop, so that its values stay
/// in registers).
#[derive(Clone, Copy)]
struct Frame {
    /// The smoothing band (m).
    h: Real,
    /// Faces whose depth exceeds this (δ_M + `REACH` h) cannot win.
    reach: Real,
    /// B's pose in A's frame.
    rot12: Rotation,
    t12: Vector,
    /// The EPA normal in A's frame.
    n0: Vector,
    /// Whether deep candidates are dropped early (not in the reference).
    rejecting: bool,
}

/// Where a side's vertex walks start (updated as they go), and whether that side walks at all.
struct Walk {
    enabled: bool,
    start: u32,
}

/// What the face loops fill: the candidates, and the band buffer they reuse.
struct FaceSearch {
    band: Band,
    candidates: Candidates,
}

impl Frame {
    /// A candidate is dropped once a vertex lies deeper than this: its smoothed depth cannot win then.
    #[inline(always)]
    fn reject_beyond(self, margin: Real) -> Real {
        if self.rejecting {
            self.reach + 2.0 * self.h + margin
        } else {
            Real::INFINITY
        }
    }

    /// Faces of A (`pb`: the EPA point of B in A's frame): B's vertices below each face plane.
    #[inline(never)]
    fn faces_of_a<A: Polytope + ?Sized, B: Polytope + ?Sized>(
        self,
        a: &A,
        b: &B,
        pb: &Vector,
        walk_b: &mut Walk,
        out: &mut FaceSearch,
    ) {
        let (rot12, t12, vb) = (self.rot12, self.t12, b.vertices());
        for f in 0..a.num_faces() {
            let n = a.face_normal(f);
            let o = a.face_offset(f);
            if o - n.dot(pb) > self.reach {
                continue;
            }
            let u = rot12.inverse_transform_vector(&n);
            let s = o - n.dot(&t12);
            let margin = WALK_MARGIN * (s.abs() + b.bounding_radius());
            let Some((d, c2, smoothed)) = smoothed_support(
                b,
                |j| s - u.dot(&vb[j].coords),
                |j| rot12 * vb[j].coords + t12,
                self.h,
                &mut walk_b.start,
                walk_b.enabled.then_some(margin),
                self.reject_beyond(margin),
                &mut out.band,
            ) else {
                continue;
            };
            if d > self.reach {
                continue;
            }
            out.candidates.has_epa_normal |= n.cross(&self.n0).norm() < SAME_NORMAL;
            out.candidates.add(Candidate {
                depth: d,
                normal: n,
                point_b: c2,
                smoothed,
            });
        }
    }

    /// Faces of B (`pa_b`: the EPA point of A in B's frame): A's vertices below each face plane (contact
    /// normal −m, m the face normal in A's frame).
    #[inline(never)]
    fn faces_of_b<A: Polytope + ?Sized, B: Polytope + ?Sized>(
        self,
        a: &A,
        b: &B,
        pa_b: &Vector,
        walk_a: &mut Walk,
        out: &mut FaceSearch,
    ) {
        let (rot12, t12, va) = (self.rot12, self.t12, a.vertices());
        for g in 0..b.num_faces() {
            let m_b = b.face_normal(g);
            let o_b = b.face_offset(g);
            if o_b - m_b.dot(pa_b) > self.reach {
                continue;
            }
            let m = rot12 * m_b;
            let s = o_b + m.dot(&t12);
            let margin = WALK_MARGIN * (s.abs() + a.bounding_radius());
            let Some((d, c1, smoothed)) = smoothed_support(
                a,
                |i| s - m.dot(&va[i].coords),
                |i| va[i].coords,
                self.h,
                &mut walk_a.start,
                walk_a.enabled.then_some(margin),
                self.reject_beyond(margin),
                &mut out.band,
            ) else {
                continue;
            };
            if d > self.reach {
                continue;
            }
            out.candidates.has_epa_normal |= m.cross(&self.n0).norm() < SAME_NORMAL;
            out.candidates.add(Candidate {
                depth: d,
                normal: -m,
                point_b: c1 + m * d,
                smoothed,
            });
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::contact::contact_polyhedron_polyhedron::{query_polytopes_cached, PairCache};
    use crate::contact::counters::QueryCounters;
    use crate::contact::epa::EpaScratch;
    use crate::contact::testing::{random_pose, TestPolytope};
    use crate::contact::tolerances::ContactTolerances;
    use crate::math::Rotation;
    type Translation = nalgebra::Translation3<Real>;
    use rand::{Rng, SeedableRng};

    fn exact<A: Polytope, B: Polytope>(p1: &Pose, a: &A, p2: &Pose, b: &B) -> ContactGeometry {
        query_polytopes_cached(
            p1,
            a,
            p2,
            b,
            &ContactTolerances::default(),
            &mut PairCache::default(),
            &mut EpaScratch::default(),
            &mut QueryCounters::default(),
        )
    }

    fn smoothed<A: Polytope, B: Polytope>(
        p1: &Pose,
        a: &A,
        p2: &Pose,
        b: &B,
        band: Real,
    ) -> ContactGeometry {
        smooth_pair_overlap(p1, a, p2, b, &exact(p1, a, p2, b), band, [0, 0])
    }

    /// A cube of half-side 0.1 on a slab of half-extents (1, 1, 0.1), sunk by `sink`, rotated about x by
    /// `tilt` (an edge parallel to x lands) and about y by `roll` (which breaks the tie of its two ends).
    fn cube_on_slab(
        tilt: Real,
        roll: Real,
        sink: Real,
    ) -> (TestPolytope, Pose, TestPolytope, Pose) {
        let slab = TestPolytope::cuboid(Vector::new(1.0, 1.0, 0.1));
        let cube = TestPolytope::cuboid(Vector::new(0.1, 0.1, 0.1));
        let rot = Rotation::from_axis_angle(&Vector::y_axis(), roll)
            * Rotation::from_axis_angle(&Vector::x_axis(), tilt);
        let lowest = cube
            .verts
            .iter()
            .map(|v| (rot * v).z)
            .fold(Real::INFINITY, Real::min);
        let pose_b = Pose::from_parts(Translation::new(0.05, -0.02, 0.1 - lowest - sink), rot);
        (slab, Pose::identity(), cube, pose_b)
    }

    /// Away from ties the smoothed answer is the exact one, bit for bit; everywhere it is within the band
    /// below the exact depth (random pairs of boxes, random poses, a band of 1e-3 L).
    #[test]
    fn no_tie_gives_the_exact_answer_and_ties_stay_within_the_band() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(11);
        let band = 1e-3;
        let (mut same, mut overlapping) = (0, 0);
        for _ in 0..2000 {
            let a = TestPolytope::cuboid(Vector::new(
                rng.random_range(0.2..1.0),
                rng.random_range(0.2..1.0),
                rng.random_range(0.2..1.0),
            ));
            let b = TestPolytope::cuboid(Vector::new(
                rng.random_range(0.2..1.0),
                rng.random_range(0.2..1.0),
                rng.random_range(0.2..1.0),
            ));
            let (p1, p2) = (random_pose(&mut rng, 0.5), random_pose(&mut rng, 0.5));
            let g = exact(&p1, &a, &p2, &b);
            if g.kind != ContactKind::Overlap {
                continue;
            }
            overlapping += 1;
            let s = smooth_pair_overlap(&p1, &a, &p2, &b, &g, band, [0, 0]);
            let h = band * a.length_scale().min(b.length_scale());
            assert!(
                s.depth <= g.depth && s.depth >= g.depth - 0.5 * h,
                "smoothed depth {} outside [δ_M − 0.5 h, δ_M] = [{}, {}], h = {h}",
                s.depth,
                g.depth - 0.5 * h,
                g.depth
            );
            if s == g {
                same += 1;
            }
        }
        assert!(overlapping > 500, "only {overlapping} overlapping pairs");
        assert!(
            same as f64 > 0.95 * overlapping as f64,
            "{same} of {overlapping} random overlapping pairs answered exactly (expected ≥ 95 %: ties within 1e-3 L are rare)"
        );
    }

    /// The potential U = δ̃²/2 of the smoothed overlap: the force δ̃ n̄ on B at c_M and its torques on A and
    /// B are its gradient (central differences in translation and rotation of B and rotation of A), through a
    /// tie of two vertices of the cube under the slab's face, and the contact point moves continuously.
    #[test]
    fn force_through_a_vertex_tie_is_the_gradient_of_the_smoothed_overlap() {
        let band = 1e-3;
        // The exact overlap's point jumps across the tie from one end of the edge to the other.
        let ends: Vec<Point> = [-3.5e-4, 3.5e-4]
            .iter()
            .map(|&roll| {
                let (a, pa, b, pb) = cube_on_slab(0.2, roll, 2e-3);
                exact(&pa, &a, &pb, &b).point
            })
            .collect();
        assert!(
            (ends[1] - ends[0]).norm() > 0.15,
            "exact points {ends:?}: no jump across the tie, the test would not test the smoothing"
        );
        let mut last: Option<Vector> = None;
        for k in -12..=12 {
            // h = 1e-3 × 0.346; the two tied ends are 0.2 apart: a roll of 2h/0.2 takes the tie out of the band.
            let roll = k as Real * 3.5e-4;
            let (a, pa, b, pb) = cube_on_slab(0.2, roll, 2e-3);
            let g = smoothed(&pa, &a, &pb, &b, band);
            assert_eq!(g.kind, ContactKind::Overlap);
            let u = |pa: &Pose, pb: &Pose| 0.5 * smoothed(pa, &a, pb, &b, band).depth.powi(2);
            let f = g.normal * g.depth;
            let tau_b = (g.point - pb.translation.vector).coords.cross(&f);
            let tau_a = (g.point - pa.translation.vector).coords.cross(&-f);
            let e = 1e-7;
            for axis in 0..3 {
                let dir = Vector::ith(axis, 1.0);
                let moved = |s: Real| {
                    Pose::from_parts(
                        Translation::from(pb.translation.vector + dir * s),
                        pb.rotation,
                    )
                };
                let fd = (u(&pa, &moved(e)) - u(&pa, &moved(-e))) / (2.0 * e);
                assert!(
                    (fd + f[axis]).abs() < 1e-8,
                    "roll {roll}: −∂U/∂x_B[{axis}] = {} against force {}",
                    -fd,
                    f[axis]
                );
                let turned = |p: &Pose, s: Real| {
                    Pose::from_parts(
                        p.translation,
                        Rotation::from_scaled_axis(dir * s) * p.rotation,
                    )
                };
                let fd = (u(&pa, &turned(&pb, e)) - u(&pa, &turned(&pb, -e))) / (2.0 * e);
                assert!(
                    (fd + tau_b[axis]).abs() < 1e-8,
                    "roll {roll}: −∂U/∂θ_B[{axis}] = {} against torque on B {}",
                    -fd,
                    tau_b[axis]
                );
                let fd = (u(&turned(&pa, e), &pb) - u(&turned(&pa, -e), &pb)) / (2.0 * e);
                assert!(
                    (fd + tau_a[axis]).abs() < 1e-8,
                    "roll {roll}: −∂U/∂θ_A[{axis}] = {} against torque on A {}",
                    -fd,
                    tau_a[axis]
                );
            }
            if let Some(prev) = last {
                let jump = (g.point.coords - prev).norm();
                assert!(
                    jump < 0.05,
                    "roll {roll}: the contact point moved {jump} m in one roll step of 3.5e-4 rad (ends 0.2 m apart)"
                );
            }
            last = Some(g.point.coords);
        }
    }

    /// The shapes of the band-walk sweeps: every class of the oracle tests (boxes with exactly parallel
    /// faces, ellipsoid hulls of 8–64 points, Voronoi cells, plates, needles), hulls of points on an
    /// integer grid (many exactly tied vertices along the axes and diagonals) and a body of revolution like
    /// the rockfill's projectile ([`ringed_body`]: rings of 36 tied vertices along its axis).
    fn walk_shapes(rng: &mut rand_chacha::ChaCha8Rng) -> Vec<crate::shape::ConvexPolyhedron> {
        use crate::contact::tests_oracle::random_polyhedron;
        let mut shapes = Vec::new();
        for class in 0..10 {
            for _ in 0..4 {
                shapes.push(random_polyhedron(rng, 0.3, class));
            }
        }
        for _ in 0..8 {
            let pts: Vec<Point> = (0..60)
                .map(|_| {
                    Point::new(
                        rng.random_range(-3..=3) as Real,
                        rng.random_range(-3..=3) as Real,
                        rng.random_range(-2..=2) as Real,
                    ) * 0.05
                })
                .collect();
            shapes.push(crate::shape::ConvexPolyhedron::from_points(&pts).unwrap().0);
        }
        shapes.push(ringed_body());
        shapes
    }

    /// A body of revolution like the rockfill's projectile: a conical nose on a cylinder, 13 rings of 36
    /// vertices around the z axis and the tip (469 vertices; every ring's vertices tie on depth along z).
    fn ringed_body() -> crate::shape::ConvexPolyhedron {
        let mut pts = vec![Point::new(0.0, 0.0, 0.0)];
        for ring in 1..=13 {
            let z = 0.06 * ring as Real;
            let radius = 0.075 * (ring as Real / 6.0).min(1.0);
            for k in 0..36 {
                let angle = std::f64::consts::TAU * k as Real / 36.0;
                pts.push(Point::new(radius * angle.cos(), radius * angle.sin(), z));
            }
        }
        crate::shape::ConvexPolyhedron::from_points(&pts).unwrap().0
    }

    /// The band as defined (two passes: the deepest depth, then every vertex within 2h of it, in index
    /// order), as (depth bits, vertex) pairs.
    fn band_by_definition(
        n: usize,
        depth: &impl Fn(usize) -> Real,
        h: Real,
    ) -> (Real, usize, Vec<(u64, u32)>) {
        let mut deepest = Real::NEG_INFINITY;
        let mut arg = 0;
        for i in 0..n {
            if depth(i) > deepest {
                deepest = depth(i);
                arg = i;
            }
        }
        let band = (0..n)
            .filter(|&i| depth(i) > deepest - 2.0 * h)
            .map(|i| (depth(i).to_bits(), i as u32))
            .collect();
        (deepest, arg, band)
    }

    fn entries(b: &Band) -> Vec<(u64, u32)> {
        if b.spill.is_empty() {
            (0..b.len)
                .map(|i| (b.depths[i].to_bits(), b.index[i]))
                .collect()
        } else {
            b.spill.iter().map(|e| (e.0.to_bits(), e.1)).collect()
        }
    }

    /// The one-pass scan and the band walk find the band of its definition — the same vertices, depths,
    /// order, deepest depth and deepest index, bit for bit — on every shape of [`walk_shapes`], for random
    /// directions, directions along face normals and edges (exact ties of two or more vertices), bands from
    /// 0 to 0.3 of the size, and random start vertices (including out-of-range ones).
    #[test]
    fn band_scan_and_walk_equal_the_definition_on_random_hulls_and_tied_directions() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(29);
        let shapes = walk_shapes(&mut rng);
        let (mut compared, mut multi, mut overflow) = (0usize, 0usize, 0usize);
        for (k, p) in shapes.iter().enumerate() {
            let l = p.length_scale();
            let n = p.vertices().len();
            let mut dirs: Vec<Vector> = (0..40)
                .map(|_| crate::contact::testing::random_unit(&mut rng))
                .collect();
            for f in 0..p.num_faces().min(40) {
                dirs.push(-*p.face_normal(f));
            }
            for e in p.edges().iter().take(20) {
                let t = p.vertices()[e[1] as usize] - p.vertices()[e[0] as usize];
                let side = t.cross(&crate::contact::testing::random_unit(&mut rng));
                dirs.push(side.normalize());
            }
            dirs.extend([Vector::x(), -Vector::x(), Vector::y(), -Vector::z()]);
            for u in dirs {
                for rel_h in [0.0, 1e-4, 1e-2, 0.3] {
                    let h = rel_h * l;
                    let s = rng.random_range(-1.0..1.0) * l;
                    let depth = |j: usize| s - u.dot(&p.vertices()[j].coords);
                    let (d_ref, arg_ref, band_ref) = band_by_definition(n, &depth, h);
                    let mut scan = Band::new();
                    let Found::Band(d_scan, arg_scan) =
                        band_by_scan(n, &depth, h, Real::INFINITY, &mut scan)
                    else {
                        panic!("the scan without a rejection level always finds the band");
                    };
                    assert!(
                        d_scan.to_bits() == d_ref.to_bits()
                            && arg_scan == arg_ref
                            && entries(&scan) == band_ref,
                        "shape {k} ({n} vertices), direction {u:?}, s = {s}, h = {h}: one-pass scan \
                         (deepest {d_scan:e}, vertex {arg_scan}, band {:?}) against the definition \
                         (deepest {d_ref:e}, vertex {arg_ref}, band {band_ref:?}); expected identical",
                        entries(&scan)
                    );
                    let mut start = rng.random_range(0..n as u32 + 3);
                    let start_in = start;
                    let margin = WALK_MARGIN * (s.abs() + p.bounding_radius());
                    let mut walk = Band::new();
                    let Found::Band(d_walk, arg_walk) =
                        band_by_walk(p, &depth, h, margin, Real::INFINITY, &mut start, &mut walk)
                    else {
                        overflow += 1;
                        continue;
                    };
                    let (es, ew) = (entries(&scan), entries(&walk));
                    assert!(
                        d_scan.to_bits() == d_walk.to_bits() && arg_scan == arg_walk && es == ew,
                        "shape {k} ({n} vertices), direction {u:?}, s = {s}, h = {h}, start {start_in}: \
                         scan (deepest {d_scan:e}, vertex {arg_scan}, band {es:?}) against walk \
                         (deepest {d_walk:e}, vertex {arg_walk}, band {ew:?}); expected identical"
                    );
                    compared += 1;
                    multi += usize::from(es.len() > 1);
                }
            }
        }
        assert!(
            compared > 10_000 && multi > 3_000,
            "only {compared} comparisons, {multi} with two or more vertices in the band"
        );
        assert!(
            overflow * 20 < compared,
            "{overflow} walks overflowed the buffers out of {}",
            compared + overflow
        );
    }

    /// The smoothed overlap as computed in production (band walks on hulls of more than 16 vertices, early
    /// rejection of deep candidates, warm starts) equals the reference that scans every vertex of every face
    /// candidate, bit for bit, on random overlapping pairs of the shapes of [`walk_shapes`] (pairs with the
    /// projectile-like body included), with bands of 1e-4 and 1e-2 of the size (the larger one puts ties in the band
    /// often), from random start vertices.
    #[test]
    fn smoothed_overlap_by_walks_and_early_rejection_equals_the_full_scan_on_random_pairs() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(31);
        let shapes = walk_shapes(&mut rng);
        let (mut overlapping, mut smoothed) = (0usize, 0usize);
        for trial in 0..6000 {
            let ia = rng.random_range(0..shapes.len());
            let ib = if trial % 4 == 0 {
                shapes.len() - 1
            } else {
                rng.random_range(0..shapes.len())
            };
            let (a, b) = (&shapes[ia], &shapes[ib]);
            let reach = 0.5 * (a.bounding_radius() + b.bounding_radius());
            let (p1, p2) = (random_pose(&mut rng, 0.3), random_pose(&mut rng, 0.3));
            let p2 = Pose::from_parts(
                Translation::from(
                    p1.translation.vector
                        + (p2.translation.vector - p1.translation.vector).normalize() * reach,
                ),
                p2.rotation,
            );
            let g = exact(&p1, a, &p2, b);
            if g.kind != ContactKind::Overlap {
                continue;
            }
            overlapping += 1;
            for band in [1e-4, 1e-2] {
                let starts = [
                    rng.random_range(0..a.vertices().len() as u32 + 2),
                    rng.random_range(0..b.vertices().len() as u32 + 2),
                ];
                let by_scan = smooth_pair_overlap_by(&p1, a, &p2, b, &g, band, None);
                let by_walk = smooth_pair_overlap_by(&p1, a, &p2, b, &g, band, Some(starts));
                let bits = |g: &ContactGeometry| {
                    [
                        g.depth,
                        g.normal.x,
                        g.normal.y,
                        g.normal.z,
                        g.point.x,
                        g.point.y,
                        g.point.z,
                        g.point_a.x,
                        g.point_b.z,
                    ]
                    .map(Real::to_bits)
                };
                assert!(
                    by_scan == by_walk && bits(&by_scan) == bits(&by_walk),
                    "shapes {ia} ({} vertices) and {ib} ({} vertices), band {band}, starts {starts:?}: \
                     scan {by_scan:?} against walk {by_walk:?}; expected identical",
                    a.vertices().len(),
                    b.vertices().len()
                );
                smoothed += usize::from(by_scan != g);
            }
        }
        assert!(
            overlapping > 2000 && smoothed > 200,
            "only {overlapping} overlapping pairs, {smoothed} answers changed by the smoothing"
        );
    }
}
