//! GJK: distance between two convex shapes, or the certificate that they intersect.
//!
//! Algorithm (Gilbert, Johnson & Keerthi 1988, in the form of van den Bergen 2001, §4.3): keep a simplex of
//! at most four support points of A ⊖ B; at each iteration take the support point `w` along −v, where `v`
//! is the point of the simplex closest to the origin, add it, and reduce the simplex to the smallest face
//! that still contains the new closest point. The sub-algorithm here is a Voronoi-region test per simplex
//! size (segment, triangle, tetrahedron), with degenerate (flat or collinear) simplices detected by
//! scale-free volume ratios and handled by taking the best of their faces.
//!
//! Termination, with `L` the pair's length scale:
//! - `|v| − v̂·w ≤ gjk_gap · L` (duality gap; an upper bound of the distance error), or `w` already in the
//!   simplex, or no further decrease of |v| (round-off stall): converged distance |v|;
//! - the simplex is a tetrahedron enclosing the origin, or |v| ≤ `touching · L`: contact, to be measured by
//!   EPA;
//! - the iteration cap: reported, and the caller falls back to the exact SAT answer.
//!
//! The separating normal is computed from the final simplex's feature rather than from `v` alone: the face
//! normal of a terminal triangle, the component of `v` orthogonal to a terminal segment. Its direction is then
//! accurate to round-off even for gaps many orders below the particle size, so that the support distance
//! along the reported normal equals the gap to round-off.
//!
//! Limits: no allocation; all state lives in a fixed-size [`Simplex`]. Tolerances assume coordinates of
//! the order of `L` in frame 1 (true for pairs that are close enough to matter).

use super::minkowski::{MinkowskiPair, SupportPoint};
use super::tolerances::ContactTolerances;
use crate::math::{Real, Vector};
use crate::shape::SupportMap;

/// At most four support points of A ⊖ B with the barycentric weights of the closest point.
#[derive(Copy, Clone, Debug, Default)]
pub struct Simplex {
    pub pts: [SupportPoint; 4],
    pub bary: [Real; 4],
    pub len: usize,
}

/// What GJK found.
#[derive(Copy, Clone, Debug, PartialEq)]
pub enum GjkOutcome {
    /// The shapes are apart by more than the touching band. `normal` (frame 1, unit) points from A to B;
    /// `point_a` and `point_b` (frame 1) are witness points with `point_b − point_a = distance · normal`.
    Separated {
        distance: Real,
        normal: Vector,
        point_a: Vector,
        point_b: Vector,
    },
    /// The origin is inside A ⊖ B or within the touching band of its boundary: measure with EPA.
    Contact,
    /// Boolean mode only: a plane separating the shapes was found (no distance computed).
    SeparatingAxis,
    /// The iteration cap was reached.
    MaxIterations,
}

/// Whether GJK must compute the distance of separated pairs or may stop at the first separating plane.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum GjkMode {
    Distance,
    Boolean,
}

/// Result of one GJK run.
#[derive(Copy, Clone, Debug)]
pub struct GjkResult {
    pub outcome: GjkOutcome,
    pub iterations: u32,
    /// The last search vector `v` (frame 1): a good warm start for the next query of the same pair.
    pub v: Vector,
}

/// Runs GJK on `pair`, starting from the direction guess `v_init` (frame 1; the last `v` of this pair, or
/// anything nonzero), with `scale` the pair's length scale. `simplex` receives the terminal simplex.
pub fn gjk<A: SupportMap + ?Sized, B: SupportMap + ?Sized>(
    pair: &mut MinkowskiPair<'_, A, B>,
    v_init: &Vector,
    scale: Real,
    tol: &ContactTolerances,
    mode: GjkMode,
    simplex: &mut Simplex,
) -> GjkResult {
    let touch = tol.touching * scale;
    let gap_tol = tol.gjk_gap * scale;
    let mut v = if v_init.norm_squared() > 0.0 && v_init.iter().all(|x| x.is_finite()) {
        *v_init
    } else {
        Vector::x()
    };
    simplex.len = 0;
    let mut iterations = 0u32;
    loop {
        if iterations >= tol.gjk_max_iterations {
            return GjkResult {
                outcome: GjkOutcome::MaxIterations,
                iterations,
                v,
            };
        }
        iterations += 1;
        let s = pair.support(&(-v));
        let vv = v.norm_squared();
        let vw = v.dot(&s.w);
        if mode == GjkMode::Boolean && vw > touch * vv.sqrt() {
            // The plane through `w` orthogonal to `v` separates the origin from A ⊖ B by more than the
            // touching band.
            return GjkResult {
                outcome: GjkOutcome::SeparatingAxis,
                iterations,
                v,
            };
        }
        if simplex.len > 0 {
            let converged = vv - vw <= gap_tol * vv.sqrt()
                || simplex.pts[..simplex.len].iter().any(|p| p.w == s.w);
            if converged {
                break;
            }
        }
        simplex.pts[simplex.len] = s;
        simplex.len += 1;
        let new_v = closest_to_origin(simplex);
        if simplex.len == 4 {
            return GjkResult {
                outcome: GjkOutcome::Contact,
                iterations,
                v,
            };
        }
        let new_vv = new_v.norm_squared();
        if new_vv <= touch * touch {
            return GjkResult {
                outcome: GjkOutcome::Contact,
                iterations,
                v: if new_vv > 0.0 { new_v } else { v },
            };
        }
        let stalled = vv <= new_vv && iterations > 1;
        v = new_v;
        if stalled {
            break;
        }
    }
    let distance = v.norm();
    if distance <= touch {
        return GjkResult {
            outcome: GjkOutcome::Contact,
            iterations,
            v,
        };
    }
    separated(simplex, &v, distance, iterations)
}

/// The result of a run that stopped apart: distance and normal from the terminal feature, the witness
/// points from the simplex's barycentric weights, made to obey point_b − point_a = distance · normal
/// exactly (they differ from it by round-off).
#[inline(always)]
fn separated(simplex: &Simplex, v: &Vector, distance: Real, iterations: u32) -> GjkResult {
    let (distance, normal) = feature_normal(simplex, v, distance);
    let mut pa = Vector::zeros();
    let mut pb = Vector::zeros();
    for i in 0..simplex.len {
        pa += simplex.pts[i].a * simplex.bary[i];
        pb += simplex.pts[i].b * simplex.bary[i];
    }
    let mid = (pa + pb) * 0.5;
    let half = normal * (0.5 * distance);
    GjkResult {
        outcome: GjkOutcome::Separated {
            distance,
            normal,
            point_a: mid - half,
            point_b: mid + half,
        },
        iterations,
        v: *v,
    }
}

/// The unit normal from A to B (= −v̂) computed from the terminal feature of the simplex, and the distance
/// along it. For a segment the normal is made exactly orthogonal to the segment, for a triangle it is the
/// triangle's normal: both are accurate to round-off independently of how small the gap is.
fn feature_normal(simplex: &Simplex, v: &Vector, dist: Real) -> (Real, Vector) {
    let fallback = (dist, -v / dist);
    match simplex.len {
        2 => {
            let e = simplex.pts[1].w - simplex.pts[0].w;
            let ee = e.norm_squared();
            if ee == 0.0 {
                return fallback;
            }
            let vp = v - e * (v.dot(&e) / ee);
            let d = vp.norm();
            if d == 0.0 {
                return fallback;
            }
            (d, -vp / d)
        }
        3 => {
            let p = &simplex.pts;
            let n = (p[1].w - p[0].w).cross(&(p[2].w - p[0].w));
            let nn = n.norm();
            if nn == 0.0 {
                return fallback;
            }
            let mut n = n / nn;
            if n.dot(v) > 0.0 {
                n = -n;
            }
            // n points away from the face as seen from... the origin is on the side of +n: distance = −n·w.
            let d = -(n.dot(&p[0].w) + n.dot(&p[1].w) + n.dot(&p[2].w)) / 3.0;
            if d <= 0.0 {
                return fallback;
            }
            (d, n)
        }
        _ => fallback,
    }
}

/// Replaces the simplex by its smallest face containing the point closest to the origin, sets the
/// barycentric weights, and returns that point. A tetrahedron that encloses the origin is kept whole
/// (length 4) and the zero vector returned.
pub fn closest_to_origin(s: &mut Simplex) -> Vector {
    match s.len {
        1 => {
            s.bary[0] = 1.0;
            s.pts[0].w
        }
        2 => closest_segment(s),
        3 => closest_triangle(s),
        4 => closest_tetrahedron(s),
        _ => unreachable!("simplex length is 1..=4 by construction"),
    }
}

fn closest_segment(s: &mut Simplex) -> Vector {
    let a = s.pts[0].w;
    let b = s.pts[1].w;
    let ab = b - a;
    let denom = ab.norm_squared();
    let t_num = -a.dot(&ab);
    if t_num <= 0.0 || denom == 0.0 {
        if denom == 0.0 && b.norm_squared() < a.norm_squared() {
            s.pts[0] = s.pts[1];
        }
        s.len = 1;
        s.bary[0] = 1.0;
        return s.pts[0].w;
    }
    if t_num >= denom {
        s.pts[0] = s.pts[1];
        s.len = 1;
        s.bary[0] = 1.0;
        return b;
    }
    let t = t_num / denom;
    s.bary[0] = 1.0 - t;
    s.bary[1] = t;
    a + ab * t
}

/// Keeps only the points `idx` of the simplex, in this order.
fn keep(s: &mut Simplex, idx: &[usize]) {
    let old = s.pts;
    for (k, &i) in idx.iter().enumerate() {
        s.pts[k] = old[i];
    }
    s.len = idx.len();
}

fn closest_triangle(s: &mut Simplex) -> Vector {
    let a = s.pts[0].w;
    let b = s.pts[1].w;
    let c = s.pts[2].w;
    let ab = b - a;
    let ac = c - a;
    let n = ab.cross(&ac);
    let nn = n.norm_squared();
    // Collinear (or coincident) points: the triangle has no interior; take the best of its edges.
    if nn <= 1e-24 * ab.norm_squared() * ac.norm_squared() || nn == 0.0 {
        return best_of_faces(s, &[[0, 1], [1, 2], [0, 2]]);
    }
    // Voronoi regions (Ericson, Real-Time Collision Detection, §5.1.5) with the query point at the origin.
    let d1 = -ab.dot(&a);
    let d2 = -ac.dot(&a);
    if d1 <= 0.0 && d2 <= 0.0 {
        keep(s, &[0]);
        s.bary[0] = 1.0;
        return a;
    }
    let d3 = -ab.dot(&b);
    let d4 = -ac.dot(&b);
    if d3 >= 0.0 && d4 <= d3 {
        keep(s, &[1]);
        s.bary[0] = 1.0;
        return b;
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        keep(s, &[0, 1]);
        return closest_segment(s);
    }
    let d5 = -ab.dot(&c);
    let d6 = -ac.dot(&c);
    if d6 >= 0.0 && d5 <= d6 {
        keep(s, &[2]);
        s.bary[0] = 1.0;
        return c;
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        keep(s, &[0, 2]);
        return closest_segment(s);
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        keep(s, &[1, 2]);
        return closest_segment(s);
    }
    // Interior: the projection of the origin on the plane, computed along the normal for accuracy.
    let sum = va + vb + vc;
    s.bary[0] = va / sum;
    s.bary[1] = vb / sum;
    s.bary[2] = vc / sum;
    n * (n.dot(&a) / nn)
}

/// Sets `s` to the best (closest to the origin) of the given sub-simplices and returns its closest point;
/// the first of equally close faces wins. Each face is reduced in one reused buffer and copied out only
/// when it improves on the best so far.
fn best_of_faces<const K: usize>(s: &mut Simplex, faces: &[[usize; K]]) -> Vector {
    let pts = s.pts;
    let mut sub = *s;
    let mut best: Option<(Real, Vector)> = None;
    for f in faces {
        for (k, &i) in f.iter().enumerate() {
            sub.pts[k] = pts[i];
        }
        sub.len = K;
        let v = closest_to_origin(&mut sub);
        let d = v.norm_squared();
        if best.is_none_or(|(bd, _)| d < bd) {
            best = Some((d, v));
            s.pts[..sub.len].copy_from_slice(&sub.pts[..sub.len]);
            s.bary[..sub.len].copy_from_slice(&sub.bary[..sub.len]);
            s.len = sub.len;
        }
    }
    best.expect("at least one face").1
}

fn det(a: &Vector, b: &Vector, c: &Vector) -> Real {
    a.dot(&b.cross(c))
}

fn closest_tetrahedron(s: &mut Simplex) -> Vector {
    let w = [s.pts[0].w, s.pts[1].w, s.pts[2].w, s.pts[3].w];
    let e1 = w[1] - w[0];
    let e2 = w[2] - w[0];
    let e3 = w[3] - w[0];
    let vol = det(&e1, &e2, &e3);
    let ref_vol = e1.norm() * e2.norm() * e3.norm();
    const FACES: [[usize; 3]; 4] = [[1, 2, 3], [0, 2, 3], [0, 1, 3], [0, 1, 2]];
    if vol.abs() <= 1e-12 * ref_vol || vol == 0.0 {
        // Flat tetrahedron: its hull is covered by its four triangles.
        return best_of_faces(s, &FACES);
    }
    let mut outside = [[0usize; 3]; 4];
    let mut n_out = 0;
    for (l, f) in FACES.iter().enumerate() {
        let (i, j, k) = (f[0], f[1], f[2]);
        let eij = w[j] - w[i];
        let eik = w[k] - w[i];
        let side_origin = det(&eij, &eik, &(-w[i]));
        let side_opp = det(&eij, &eik, &(w[l] - w[i]));
        if side_origin * side_opp < 0.0 {
            outside[n_out] = *f;
            n_out += 1;
        }
    }
    if n_out == 0 {
        let inv = 1.0 / vol;
        // Barycentric weights of the origin (not needed by EPA, kept for completeness).
        s.bary[1] = det(&(-w[0]), &e2, &e3) * inv;
        s.bary[2] = det(&e1, &(-w[0]), &e3) * inv;
        s.bary[3] = det(&e1, &e2, &(-w[0])) * inv;
        s.bary[0] = 1.0 - s.bary[1] - s.bary[2] - s.bary[3];
        return Vector::zeros();
    }
    best_of_faces(s, &outside[..n_out])
}

#[cfg(test)]
mod tests {
    use super::*;

    fn simplex_of(points: &[Vector]) -> Simplex {
        let mut s = Simplex::default();
        for (i, p) in points.iter().enumerate() {
            s.pts[i].w = *p;
            s.pts[i].a = *p;
        }
        s.len = points.len();
        s
    }

    #[test]
    fn triangle_interior_projection_is_orthogonal() {
        let mut s = simplex_of(&[
            Vector::new(-1.0, -1.0, 2.0),
            Vector::new(3.0, -1.0, 2.0),
            Vector::new(-1.0, 3.0, 2.0),
        ]);
        let v = closest_to_origin(&mut s);
        assert_eq!(s.len, 3);
        assert!((v - Vector::new(0.0, 0.0, 2.0)).norm() < 1e-15, "v = {v:?}");
        let sum: Real = s.bary[..3].iter().sum();
        assert!((sum - 1.0).abs() < 1e-15);
    }

    #[test]
    fn collinear_triangle_reduces_to_an_edge() {
        let mut s = simplex_of(&[
            Vector::new(-1.0, 1.0, 0.0),
            Vector::new(0.0, 1.0, 0.0),
            Vector::new(1.0, 1.0, 0.0),
        ]);
        let v = closest_to_origin(&mut s);
        assert!((v - Vector::new(0.0, 1.0, 0.0)).norm() < 1e-15, "v = {v:?}");
        assert!(s.len <= 2);
    }

    #[test]
    fn tetrahedron_enclosing_origin_is_kept() {
        let mut s = simplex_of(&[
            Vector::new(1.0, 0.0, -0.5),
            Vector::new(-1.0, 1.0, -0.5),
            Vector::new(-1.0, -1.0, -0.5),
            Vector::new(0.0, 0.0, 1.0),
        ]);
        let v = closest_to_origin(&mut s);
        assert_eq!(s.len, 4);
        assert_eq!(v, Vector::zeros());
    }

    #[test]
    fn tetrahedron_outside_reduces_to_closest_face() {
        let mut s = simplex_of(&[
            Vector::new(1.0, 0.0, 1.0),
            Vector::new(-1.0, 1.0, 1.0),
            Vector::new(-1.0, -1.0, 1.0),
            Vector::new(0.0, 0.0, 3.0),
        ]);
        let v = closest_to_origin(&mut s);
        assert_eq!(s.len, 3);
        assert!((v - Vector::new(0.0, 0.0, 1.0)).norm() < 1e-15, "v = {v:?}");
    }
}
