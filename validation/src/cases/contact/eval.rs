//! Evaluating one pair: the exact answer, ours and parry's, and their errors against the exact one.
//!
//! Every error is measured against the SAT oracle on the same polyhedra and expressed in metres; the
//! tolerance of a pair is `tol = depth_abs · size + depth_rel · |reference overlap or gap|`, with `size`
//! the particle size (the pair's length scale: the smaller of the two polyhedra's `length_scale()`, the
//! diameter of the centroid-centred bounding sphere, as the core's tolerances take it).
//! - gap error: |signed gap − reference signed gap| (signed gap = distance − overlap), which covers the
//!   depth of overlapping pairs and the distance of separated ones;
//! - normal error: |normal excess|, where the normal excess ([`normal_excess`]) is the overlap of the two
//!   bodies along the reported normal (support functions evaluated by brute force over the input points)
//!   minus the exact overlap (for separated pairs: the exact distance minus the separation along the
//!   normal). It is ≥ 0 for every direction up to round-off, and zero exactly when the normal is an
//!   optimal axis;
//! - point error: the largest of |plane distance of c1 to ∂A|, |plane distance of c2 to ∂B| and
//!   |c1 − c2 + gap · n| (the witness points must realise the reported gap along the normal);
//! - wrong status: the kind (overlap/touching/separated) differs from the reference, unless the reference
//!   signed gap lies within `tol` of the edge of the touching band (where either answer is right).

use polydem::contact::tolerances::pair_length_scale;
use polydem::contact::{ContactGeometry, ContactKind, ContactTolerances};
use polydem::math::{Point, Pose, Vector};
use polydem::shape::ConvexPolyhedron;

use crate::pairsets::Pair;
use crate::peers::parry::{ParryPair, ParryShape};

use super::ours::{sat, Ours};

/// A method's answer in common terms.
#[derive(Copy, Clone, Debug)]
pub struct Answer {
    pub kind: ContactKind,
    /// distance − overlap (m)
    pub signed_gap: f64,
    pub normal: Vector,
    pub point_a: Point,
    pub point_b: Point,
}

impl Answer {
    pub fn from_geometry(g: &ContactGeometry) -> Self {
        Answer {
            kind: g.kind,
            signed_gap: g.distance - g.depth,
            normal: g.normal,
            point_a: g.point_a,
            point_b: g.point_b,
        }
    }
}

/// A method's errors on one pair (metres); `failed` when the method gave no answer (panic, unsupported).
#[derive(Copy, Clone, Debug, Default)]
pub struct Errors {
    pub failed: bool,
    pub wrong_status: bool,
    pub gap: f64,
    pub normal: f64,
    /// The normal excess (m, signed; `normal` is its magnitude), ∞ without a usable normal.
    pub normal_excess: f64,
    pub point: f64,
}

impl Errors {
    /// The largest of the three errors relative to the pair tolerance (∞ when failed or wrong status).
    pub fn worst_ratio(&self, tol: f64) -> f64 {
        if self.failed || self.wrong_status {
            f64::INFINITY
        } else {
            self.gap.max(self.normal).max(self.point) / tol
        }
    }
}

/// The evaluation of one pair.
#[derive(Clone, Debug)]
pub struct Eval {
    pub id: String,
    pub class: String,
    /// Index of the particle size in the set's size list.
    pub size_index: usize,
    /// Particle size (m), see the module docs.
    pub size: f64,
    pub reference: Answer,
    /// Pair tolerance (m).
    pub tol: f64,
    pub ours: Errors,
    pub ours_kind: ContactKind,
    pub parry: Errors,
    pub parry_kind: Option<ContactKind>,
}

/// The polyhedra of a pair, in the world.
pub struct Built {
    pub a: ConvexPolyhedron,
    pub pos1: Pose,
    pub b: ConvexPolyhedron,
    pub pos2: Pose,
    pub parry_a: ParryShape,
    pub parry_b: ParryShape,
}

/// Builds the polyhedra of a pair (ours and parry's).
pub fn build(pair: &Pair) -> Result<Built, String> {
    let (a, pos1) = ConvexPolyhedron::from_points(&pair.a)
        .map_err(|e| format!("{}: hull of A: {e}", pair.id))?;
    let (b, pos2) = ConvexPolyhedron::from_points(&pair.b)
        .map_err(|e| format!("{}: hull of B: {e}", pair.id))?;
    let parry_a =
        ParryShape::new(&a).ok_or_else(|| format!("{}: parry hull of A failed", pair.id))?;
    let parry_b =
        ParryShape::new(&b).ok_or_else(|| format!("{}: parry hull of B failed", pair.id))?;
    Ok(Built {
        a,
        pos1,
        b,
        pos2,
        parry_a,
        parry_b,
    })
}

/// The normal excess of unit `n` (from A to B) on the pair: overlap of the clouds along `n` plus the
/// reference signed gap (m). The exact overlap is the least overlap over all directions, and the exact
/// distance the largest separation, so the excess is ≥ 0 up to round-off; 0 when `n` is optimal.
pub fn normal_excess(pair: &Pair, n: &Vector, reference_signed_gap: f64) -> f64 {
    overlap_along(&pair.a, &pair.b, n) + reference_signed_gap
}

/// Overlap of the point clouds along unit `n`: max_a n·a − min_b n·b (brute force).
fn overlap_along(a: &[Point], b: &[Point], n: &Vector) -> f64 {
    let ha = a
        .iter()
        .map(|p| n.dot(&p.coords))
        .fold(f64::NEG_INFINITY, f64::max);
    let lb = b
        .iter()
        .map(|p| n.dot(&p.coords))
        .fold(f64::INFINITY, f64::min);
    ha - lb
}

/// Largest plane distance of world point `p` to the faces of `poly` at `pose` (0 on the surface).
fn plane_distance(poly: &ConvexPolyhedron, pose: &Pose, p: &Point) -> f64 {
    let local = pose.inverse_transform_point(p);
    (0..poly.num_faces())
        .map(|i| poly.face_normal(i).dot(&local.coords) - poly.face_offset(i))
        .fold(f64::NEG_INFINITY, f64::max)
}

fn errors(
    pair: &Pair,
    built: &Built,
    ans: &Answer,
    reference: &Answer,
    band: f64,
    tol: f64,
) -> Errors {
    let n_norm = ans.normal.norm();
    let finite = ans.signed_gap.is_finite()
        && ans
            .point_a
            .coords
            .iter()
            .chain(ans.point_b.coords.iter())
            .all(|x| x.is_finite());
    let normal_excess = if (n_norm - 1.0).abs() <= 1e-9 && finite {
        normal_excess(pair, &(ans.normal / n_norm), reference.signed_gap)
    } else {
        f64::INFINITY
    };
    let point = plane_distance(&built.a, &built.pos1, &ans.point_a)
        .abs()
        .max(plane_distance(&built.b, &built.pos2, &ans.point_b).abs())
        .max((ans.point_a - ans.point_b + ans.normal * ans.signed_gap).norm());
    let ambiguous = (reference.signed_gap.abs() - band).abs() <= tol;
    Errors {
        failed: !finite,
        wrong_status: ans.kind != reference.kind && !ambiguous,
        gap: (ans.signed_gap - reference.signed_gap).abs(),
        normal: normal_excess.abs(),
        normal_excess,
        point: if finite { point } else { f64::INFINITY },
    }
}

/// Classifies a signed gap with the core's touching band.
pub fn classify(signed_gap: f64, band: f64) -> ContactKind {
    if signed_gap < -band {
        ContactKind::Overlap
    } else if signed_gap > band {
        ContactKind::Separated
    } else {
        ContactKind::Touching
    }
}

/// Evaluates a pair with the default tolerances; `depth_abs`, `depth_rel` define the pair tolerance.
pub fn evaluate(
    pair: &Pair,
    size_index: usize,
    ours: &mut Ours,
    depth_abs: f64,
    depth_rel: f64,
) -> Result<Eval, String> {
    let built = build(pair)?;
    let Built {
        a, pos1, b, pos2, ..
    } = &built;
    let size = pair_length_scale(a.length_scale(), b.length_scale());
    let band = ContactTolerances::default().touching * size;
    let reference = Answer::from_geometry(&sat(pos1, a, pos2, b));
    let tol = depth_abs * size + depth_rel * reference.signed_gap.abs();
    let g = ours.query(pos1, a, pos2, b);
    let ours_answer = Answer::from_geometry(&g);
    let ours_errors = errors(pair, &built, &ours_answer, &reference, band, tol);
    let peer = ParryPair {
        a: &built.parry_a,
        b: &built.parry_b,
    };
    let parry_answer = match peer.contact(pos1, pos2, size) {
        Ok(Some(c)) => Some(Answer {
            kind: classify(c.signed_gap, band),
            signed_gap: c.signed_gap,
            normal: c.normal,
            point_a: c.point_a,
            point_b: c.point_b,
        }),
        // No contact within the prediction (one particle size): parry's distance, no features.
        Ok(None) => peer.distance(pos1, pos2).map(|d| Answer {
            kind: classify(d, band),
            signed_gap: d,
            normal: reference.normal,
            point_a: reference.point_a,
            point_b: reference.point_b,
        }),
        Err(()) => None,
    };
    let (parry_errors, parry_kind) = match &parry_answer {
        Some(p) => (errors(pair, &built, p, &reference, band, tol), Some(p.kind)),
        None => (
            Errors {
                failed: true,
                wrong_status: true,
                gap: f64::INFINITY,
                normal: f64::INFINITY,
                normal_excess: f64::INFINITY,
                point: f64::INFINITY,
            },
            None,
        ),
    };
    Ok(Eval {
        id: pair.id.clone(),
        class: pair.class.clone(),
        size_index,
        size,
        reference,
        tol,
        ours: ours_errors,
        ours_kind: ours_answer.kind,
        parry: parry_errors,
        parry_kind,
    })
}
