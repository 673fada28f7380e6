//! Seeded contact pair sets: random pairs of the shape classes at several particle sizes with overlaps
//! log-spread over eight decades, touching and separated pairs, and a set of degenerate configurations.
//!
//! A [`Pair`] is two point clouds in world coordinates, each taken as its convex hull: exactly the input
//! of `polydem contact` (`{"id", "a", "b"}` per JSONL line, see [`write_jsonl`]).

pub mod degenerate;
pub mod placement;
pub mod shapes;

use std::io::Write;
use std::path::Path;

use polydem::math::{Point, Pose, Real, Vector};
use polydem::shape::ConvexPolyhedron;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use crate::error::SuiteError;
use crate::peers::parry::{ParryPair, ParryShape};
pub use placement::Intent;

/// One pair: two point clouds in world coordinates.
#[derive(Clone, Debug)]
pub struct Pair {
    /// `class/s<size index>/<index>`, unique within a set.
    pub id: String,
    pub class: String,
    /// Particle size (m): the diameter the class was generated at.
    pub size: Real,
    /// What the pair was generated to show (the exact answer comes from the oracle).
    pub intent: Intent,
    pub a: Vec<Point>,
    pub b: Vec<Point>,
}

/// Parameters of a random pair set.
#[derive(Clone, Debug)]
pub struct RandomSetSpec {
    pub classes: Vec<String>,
    pub sizes: Vec<f64>,
    pub pairs_per_class_and_size: usize,
    pub seed: u64,
    /// Fraction of touching pairs.
    pub touching_fraction: f64,
    /// Fraction of separated pairs.
    pub separated_fraction: f64,
    /// Overlaps and gaps are log-uniform in [min, max] × size.
    pub overlap_min_rel: f64,
    pub overlap_max_rel: f64,
}

/// The exact signed gap and normal of a pair at given poses (provided by the caller: the SAT oracle).
pub type ExactGap<'a> =
    dyn FnMut(&Pose, &ConvexPolyhedron, &Pose, &ConvexPolyhedron) -> Option<(f64, Vector)> + 'a;

/// SplitMix64 of the set seed and the pair's coordinates: each pair has its own stream, so changing the
/// number of pairs of one class does not change the others.
pub fn pair_seed(seed: u64, class: usize, size: usize, index: usize) -> u64 {
    let mut z = seed ^ ((class as u64) << 48) ^ ((size as u64) << 40) ^ index as u64;
    z = z.wrapping_add(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// Generates pair `index` of shape class `ci` at size `si` of a [`RandomSetSpec`]; `Err` names the class and seed when no draw succeeds.
pub fn random_pair(
    spec: &RandomSetSpec,
    ci: usize,
    si: usize,
    index: usize,
    exact: &mut ExactGap<'_>,
) -> Result<Pair, SuiteError> {
    let class = &spec.classes[ci];
    let size = spec.sizes[si];
    let seed = pair_seed(spec.seed, ci, si, index);
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let fail = |msg: String| SuiteError::Case {
        case: "pairsets".into(),
        msg: format!("class {class}, size {size}, index {index} (seed {seed}): {msg}"),
    };
    let draw_intent = |rng: &mut ChaCha8Rng| {
        let (lo, hi) = (spec.overlap_min_rel.log10(), spec.overlap_max_rel.log10());
        let r: f64 = rng.random();
        let mag = size * 10f64.powf(rng.random_range(lo..hi));
        if r < spec.touching_fraction {
            Intent::Touching
        } else if r < spec.touching_fraction + spec.separated_fraction {
            Intent::Separated(mag)
        } else {
            Intent::Overlap(mag)
        }
    };
    let intent = draw_intent(&mut rng);
    for _attempt in 0..50 {
        let scale = |pts: Vec<Point>, c: Vector| {
            pts.into_iter()
                .map(|p| Point::from(p.coords * size + c))
                .collect::<Vec<_>>()
        };
        let center = Vector::new(
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
        ) * size;
        let a = scale(
            shapes::random_shape(class, &mut rng).ok_or_else(|| fail("unknown class".into()))?,
            center,
        );
        let b_base = scale(
            shapes::random_shape(class, &mut rng).ok_or_else(|| fail("unknown class".into()))?,
            center,
        );
        let u = shapes::random_unit(&mut rng);
        let (poly_a, pos1) =
            ConvexPolyhedron::from_points(&a).map_err(|e| fail(format!("hull of A: {e}")))?;
        let (poly_b, pos2_base) =
            ConvexPolyhedron::from_points(&b_base).map_err(|e| fail(format!("hull of B: {e}")))?;
        let (Some(pa), Some(pb)) = (ParryShape::new(&poly_a), ParryShape::new(&poly_b)) else {
            return Err(fail("parry could not build the hull".into()));
        };
        let peer = ParryPair { a: &pa, b: &pb };
        let pos2_at = |t: f64| nalgebra::Translation3::from(u * t) * pos2_base;
        let t_max = poly_a.bounding_radius()
            + poly_b.bounding_radius()
            + (pos1.translation.vector - pos2_base.translation.vector).norm()
            + size;
        // parry drives the bisections; where it gives no answer (it does near touching for large
        // particles), and for the touching refinement, the exact oracle answers.
        let gap = |t: f64, want_exact: bool| {
            let pos2 = pos2_at(t);
            if !want_exact {
                if let Ok(Some(c)) = peer.contact(&pos1, &pos2, 4.0 * t_max) {
                    return Some((c.signed_gap, c.normal));
                }
            }
            exact(&pos1, &poly_a, &pos2, &poly_b)
        };
        if let Some(t) = placement::place(gap, &u, t_max, intent) {
            let b = b_base.iter().map(|p| p + u * t).collect();
            return Ok(Pair {
                id: format!("{class}/s{si}/{index:05}"),
                class: class.clone(),
                size,
                intent,
                a,
                b,
            });
        }
    }
    Err(fail(format!("no draw realised {intent:?} in 50 attempts")))
}

/// Writes pairs as JSONL in the `polydem contact` input format: `{"id": ..., "a": [[x,y,z],...], "b": [...]}`.
pub fn write_jsonl(path: &Path, pairs: &[Pair]) -> Result<(), SuiteError> {
    let mut f = std::io::BufWriter::new(std::fs::File::create(path).map_err(SuiteError::io(path))?);
    #[derive(serde::Serialize)]
    struct Line<'a> {
        id: &'a str,
        a: Vec<[f64; 3]>,
        b: Vec<[f64; 3]>,
    }
    let pts = |v: &[Point]| v.iter().map(|q| [q.x, q.y, q.z]).collect::<Vec<_>>();
    for p in pairs {
        let line = Line {
            id: &p.id,
            a: pts(&p.a),
            b: pts(&p.b),
        };
        let text = serde_json::to_string(&line).map_err(|e| SuiteError::Case {
            case: "pairsets".into(),
            msg: format!("{}: {e}", p.id),
        })?;
        writeln!(f, "{text}").map_err(SuiteError::io(path))?;
    }
    f.flush().map_err(SuiteError::io(path))
}
