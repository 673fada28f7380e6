//! Closest points between small convex features (point–triangle, segment–segment, point sets): the exact
//! building blocks of the SAT oracle's distance and contact points.
//!
//! Point–triangle by Voronoi regions and segment–segment by the clamped parametric solution (Ericson,
//! Real-Time Collision Detection, 2005, §5.1.5 and §5.1.9). Everything is in one frame; no allocation.

use super::gjk::{closest_to_origin, Simplex};
use crate::math::{Real, Vector};

/// The point of the triangle (a, b, c) closest to `p` (degenerate triangles included).
pub fn closest_on_triangle(p: &Vector, a: &Vector, b: &Vector, c: &Vector) -> Vector {
    let mut s = Simplex::default();
    s.pts[0].w = a - p;
    s.pts[1].w = b - p;
    s.pts[2].w = c - p;
    s.len = 3;
    closest_to_origin(&mut s) + p
}

/// The closest points (on segment p1q1, on segment p2q2) of two segments (degenerate ones included).
pub fn closest_segments(p1: &Vector, q1: &Vector, p2: &Vector, q2: &Vector) -> (Vector, Vector) {
    let d1 = q1 - p1;
    let d2 = q2 - p2;
    let r = p1 - p2;
    let a = d1.norm_squared();
    let e = d2.norm_squared();
    let f = d2.dot(&r);
    let (s, t);
    if a == 0.0 && e == 0.0 {
        return (*p1, *p2);
    }
    if a == 0.0 {
        s = 0.0;
        t = (f / e).clamp(0.0, 1.0);
    } else {
        let c = d1.dot(&r);
        if e == 0.0 {
            t = 0.0;
            s = (-c / a).clamp(0.0, 1.0);
        } else {
            let b = d1.dot(&d2);
            let denom = a * e - b * b;
            let mut s0 = if denom > 1e-15 * a * e {
                ((b * f - c * e) / denom).clamp(0.0, 1.0)
            } else {
                0.0
            };
            let mut t0 = (b * s0 + f) / e;
            if t0 < 0.0 {
                t0 = 0.0;
                s0 = (-c / a).clamp(0.0, 1.0);
            } else if t0 > 1.0 {
                t0 = 1.0;
                s0 = ((b - c) / a).clamp(0.0, 1.0);
            }
            s = s0;
            t = t0;
        }
    }
    (p1 + d1 * s, p2 + d2 * t)
}

/// Closest points between the convex hulls of two small point sets `pa`, `pb` (each a vertex, an edge or a
/// planar polygon in practice), by exhaustion over point–triangle and segment–segment pairs drawn from all
/// triples and pairs of the sets (by Carathéodory's theorem these cover the hulls of planar sets).
/// Returns (point on hull of pa, point on hull of pb, squared distance).
pub fn closest_point_sets(pa: &[Vector], pb: &[Vector]) -> (Vector, Vector, Real) {
    let mut best = (pa[0], pb[0], (pa[0] - pb[0]).norm_squared());
    let mut consider = |x: Vector, y: Vector| {
        let d = (x - y).norm_squared();
        if d < best.2 {
            best = (x, y, d);
        }
    };
    for_each_simplex(pa, |sa| {
        for_each_simplex(pb, |sb| match (sa, sb) {
            (Simp::P(x), Simp::P(y)) => consider(x, y),
            (Simp::P(x), Simp::T(a, b, c)) => consider(x, closest_on_triangle(&x, &a, &b, &c)),
            (Simp::T(a, b, c), Simp::P(y)) => consider(closest_on_triangle(&y, &a, &b, &c), y),
            (Simp::S(p, q), Simp::S(r, s)) => {
                let (x, y) = closest_segments(&p, &q, &r, &s);
                consider(x, y)
            }
            _ => {}
        })
    });
    best
}

#[derive(Copy, Clone)]
enum Simp {
    P(Vector),
    S(Vector, Vector),
    T(Vector, Vector, Vector),
}

fn for_each_simplex(p: &[Vector], mut f: impl FnMut(Simp)) {
    let n = p.len();
    for i in 0..n {
        f(Simp::P(p[i]));
        for j in i + 1..n {
            f(Simp::S(p[i], p[j]));
            for k in j + 1..n {
                f(Simp::T(p[i], p[j], p[k]));
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn crossing_segments_meet() {
        let (x, y) = closest_segments(
            &Vector::new(-1.0, 0.0, 0.0),
            &Vector::new(1.0, 0.0, 0.0),
            &Vector::new(0.0, -1.0, 1.0),
            &Vector::new(0.0, 1.0, 1.0),
        );
        assert!((x - Vector::zeros()).norm() < 1e-15, "x = {x:?}");
        assert!((y - Vector::new(0.0, 0.0, 1.0)).norm() < 1e-15, "y = {y:?}");
    }

    #[test]
    fn parallel_squares_touch_in_their_overlap() {
        let sq = |z: Real, s: Real| {
            vec![
                Vector::new(-s, -s, z),
                Vector::new(s, -s, z),
                Vector::new(s, s, z),
                Vector::new(-s, s, z),
            ]
        };
        let (x, y, d2) = closest_point_sets(&sq(0.0, 1.0), &sq(0.5, 0.3));
        assert!((d2 - 0.25).abs() < 1e-15, "d2 = {d2}");
        assert!(x.x.abs() <= 0.3 + 1e-15 && y.z == 0.5);
    }
}
