//! Oracle test of the generic support-map arm (GJK + EPA to `curved_gap`) on ellipsoids.
//!
//! For convex A and B at x_A, x_B the signed overlap (depth when they overlap, −distance when apart) is
//!   s = min over unit n of f(n),  f(n) = h_A(n) + h_B(−n) − n·(x_B − x_A),
//! with h_K the support function of K about its own centre: f is the support function of A ⊖ B, whose
//! minimum over the sphere is the distance from the origin to the boundary when the origin is inside
//! (penetration depth) and minus the distance to the set when it is outside (separating-axis duality). The
//! arg-min is the contact normal n (from A to B), and the witness points are the support points
//! s_A(n), s_B(−n). For an ellipsoid with semi-axes D and rotation R, h(n) = |D Rᵀ n| and
//! s(n) = x + R D² Rᵀ n / |D Rᵀ n|, written here independently of the engine.
//!
//! The oracle minimises f by a dense Fibonacci sample of the sphere refined by Nelder–Mead in tangent
//! coordinates from the best samples. For separated pairs the distance is also found as the constrained
//! minimum of |p_A − p_B| over surface points p_A = s_A(n), p_B = s_B(−n) (every such pair is a pair of
//! points of A and B, so |p_A − p_B| ≥ d, with equality at the closest pair), and the two oracles must agree.
//!
//! Tolerances, ℓ the length scale (bounding diameter) of the smaller body, F the magnitude of f's terms:
//! - signed overlap: curved_gap·ℓ (the engine's bounds meet within it) + 1e-13 F (the oracle's round-off);
//! - normal: f(n_engine) − s ≤ the same tolerance (the engine's normal attains the minimum), and where f is
//!   smooth and strongly convex on the sphere its angle to the oracle's, from f(n) − s ≥ ½ H θ², with
//!   H ≥ ρ_A + ρ_B − max(s, 0) (ρ the least radius of curvature: c²/a for an ellipsoid, 0 for a polytope);
//! - witness points on an ellipsoid: ρ_max θ_tol + the overlap tolerance (ρ_max = a²/c, the largest radius
//!   of curvature, converts a normal error into a point error).

use nalgebra::Unit;
use polydem::contact::{
    contact_support_maps, ContactTolerances, EpaScratch, PairCache, QueryCounters,
};
use polydem::math::{Point, Pose, Real, Rotation, Vector};
use polydem::shape::{ConvexPolyhedron, ConvexShape, Ellipsoid, Sphere};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// A body as the oracle sees it: its own support function, independent of the engine's.
enum Form {
    Ellipsoid(Vector),
    /// Vertices and faces (local frame).
    Polytope(Vec<Point>, Vec<Vec<u32>>),
}

struct Body {
    form: Form,
    pose: Pose,
    shape: Box<dyn ConvexShape>,
}

impl Body {
    /// World support point and value along the unit `n`.
    fn support(&self, n: &Vector) -> (Point, Real) {
        let d = self.pose.rotation.inverse() * n;
        let local = match &self.form {
            Form::Ellipsoid(axes) => {
                let dd = d.component_mul(axes);
                Point::from(dd.component_mul(axes) / dd.norm())
            }
            Form::Polytope(v, _) => *v
                .iter()
                .max_by(|p, q| d.dot(&p.coords).total_cmp(&d.dot(&q.coords)))
                .expect("vertices"),
        };
        let p = self.pose * local;
        (p, n.dot(&p.coords))
    }

    /// Least and largest radii of curvature (0 and ∞ for a polytope).
    fn curvature_radii(&self) -> (Real, Real) {
        match &self.form {
            Form::Ellipsoid(a) => (a.min() * a.min() / a.max(), a.max() * a.max() / a.min()),
            Form::Polytope(..) => (0.0, Real::INFINITY),
        }
    }

    /// Distance from the world point `q` (outside) to the solid: an ellipsoid's nearest support point
    /// is not needed here, only the polytope's, by exhaustion over its face triangles.
    fn polytope_distance(&self, q: &Point) -> Real {
        let Form::Polytope(v, faces) = &self.form else {
            unreachable!("polytopes only")
        };
        let p = self.pose.inverse() * q;
        faces
            .iter()
            .flat_map(|f| (1..f.len() - 1).map(move |k| [f[0], f[k], f[k + 1]]))
            .map(|t| (closest_on_triangle(&p, t.map(|i| v[i as usize])) - p).norm())
            .fold(Real::INFINITY, Real::min)
    }

    fn describe(&self) -> String {
        match &self.form {
            Form::Ellipsoid(a) => format!("ellipsoid {:?} at {:?}", a.as_slice(), self.pose),
            Form::Polytope(v, _) => format!("polytope of {} vertices at {:?}", v.len(), self.pose),
        }
    }

    fn length_scale(&self) -> Real {
        self.shape.length_scale()
    }
}

/// The point of the triangle `t` closest to `p` (Ericson, Real-Time Collision Detection, §5.1.5).
fn closest_on_triangle(p: &Point, t: [Point; 3]) -> Point {
    let [a, b, c] = t;
    let (ab, ac, ap) = (b - a, c - a, p - a);
    let (d1, d2) = (ab.dot(&ap), ac.dot(&ap));
    if d1 <= 0.0 && d2 <= 0.0 {
        return a;
    }
    let bp = p - b;
    let (d3, d4) = (ab.dot(&bp), ac.dot(&bp));
    if d3 >= 0.0 && d4 <= d3 {
        return b;
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        return a + ab * (d1 / (d1 - d3));
    }
    let cp = p - c;
    let (d5, d6) = (ab.dot(&cp), ac.dot(&cp));
    if d6 >= 0.0 && d5 <= d6 {
        return c;
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        return a + ac * (d2 / (d2 - d6));
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        return b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)));
    }
    let denom = 1.0 / (va + vb + vc);
    a + ab * (vb * denom) + ac * (vc * denom)
}

/// The distance by constrained minimisation over surface points: p_E = s_E(m) runs over the whole surface
/// of the ellipsoid E as m runs over the sphere (E is strictly convex), and |p_A − p_B| is minimised with the
/// other point s_B(−m) for two ellipsoids, or the exact nearest point of the polytope.
fn surface_distance(a: &Body, b: &Body, samples: &[Vector]) -> Real {
    let f: Box<dyn Fn(&Vector) -> Real> = match (&a.form, &b.form) {
        (Form::Polytope(..), _) => Box::new(|m: &Vector| a.polytope_distance(&b.support(&-m).0)),
        (_, Form::Polytope(..)) => Box::new(|m: &Vector| b.polytope_distance(&a.support(m).0)),
        _ => Box::new(|m: &Vector| (b.support(&-m).0 - a.support(m).0).norm()),
    };
    minimise_on_sphere(f.as_ref(), samples).0
}

/// f(n) = h_A(n) + h_B(−n) for the world supports (the centres' term is inside the world supports).
fn gap_function(a: &Body, b: &Body, n: &Vector) -> Real {
    a.support(n).1 + b.support(&-n).1
}

fn fibonacci_sphere(count: usize) -> Vec<Vector> {
    let golden = std::f64::consts::PI * (3.0 - (5.0 as Real).sqrt());
    (0..count)
        .map(|i| {
            let z = 1.0 - 2.0 * (i as Real + 0.5) / count as Real;
            let r = (1.0 - z * z).sqrt();
            let phi = golden * i as Real;
            Vector::new(r * phi.cos(), r * phi.sin(), z)
        })
        .collect()
}

/// Nelder–Mead on the sphere around `n0` in tangent coordinates: returns (min value, arg-min).
fn nelder_mead(f: &dyn Fn(&Vector) -> Real, n0: &Vector, step: Real) -> (Real, Vector) {
    let t1 = n0
        .cross(&if n0.x.abs() < 0.9 {
            Vector::x()
        } else {
            Vector::y()
        })
        .normalize();
    let t2 = n0.cross(&t1);
    let at = |u: &[Real; 2]| (n0 + t1 * u[0] + t2 * u[1]).normalize();
    let mut simplex: Vec<([Real; 2], Real)> = [[0.0, 0.0], [step, 0.0], [0.0, step]]
        .into_iter()
        .map(|u| (u, f(&at(&u))))
        .collect();
    for _ in 0..4000 {
        simplex.sort_by(|x, y| x.1.total_cmp(&y.1));
        let size = (0..2)
            .map(|k| {
                (simplex[1].0[k] - simplex[0].0[k])
                    .abs()
                    .max((simplex[2].0[k] - simplex[0].0[k]).abs())
            })
            .fold(0.0, Real::max);
        if size < 1e-15 {
            break;
        }
        let c = [0, 1].map(|k| 0.5 * (simplex[0].0[k] + simplex[1].0[k]));
        let lerp = |t: Real| [0, 1].map(|k| c[k] + t * (simplex[2].0[k] - c[k]));
        let reflected = lerp(-1.0);
        let fr = f(&at(&reflected));
        if fr < simplex[0].1 {
            let expanded = lerp(-2.0);
            let fe = f(&at(&expanded));
            simplex[2] = if fe < fr {
                (expanded, fe)
            } else {
                (reflected, fr)
            };
        } else if fr < simplex[1].1 {
            simplex[2] = (reflected, fr);
        } else {
            let contracted = lerp(0.5);
            let fc = f(&at(&contracted));
            if fc < simplex[2].1 {
                simplex[2] = (contracted, fc);
            } else {
                let best = simplex[0].0;
                for v in simplex.iter_mut().skip(1) {
                    v.0 = [0, 1].map(|k| best[k] + 0.5 * (v.0[k] - best[k]));
                    v.1 = f(&at(&v.0));
                }
            }
        }
    }
    simplex.sort_by(|x, y| x.1.total_cmp(&y.1));
    (simplex[0].1, at(&simplex[0].0))
}

/// Global minimum of `f` on the sphere: the best of Nelder–Mead runs (restarted once at their end) from
/// the eight best samples of a 4000-point Fibonacci sphere.
fn minimise_on_sphere(f: &dyn Fn(&Vector) -> Real, samples: &[Vector]) -> (Real, Vector) {
    let mut ranked: Vec<(Real, Vector)> = samples.iter().map(|n| (f(n), *n)).collect();
    ranked.sort_by(|x, y| x.0.total_cmp(&y.0));
    ranked
        .iter()
        .take(8)
        .map(|(_, n)| {
            let (_, n1) = nelder_mead(f, n, 0.05);
            nelder_mead(f, &n1, 1e-4)
        })
        .min_by(|x, y| x.0.total_cmp(&y.0))
        .expect("samples")
}

fn random_rotation(rng: &mut ChaCha8Rng) -> Rotation {
    let axis = Unit::new_normalize(Vector::new(
        rng.random_range(-1.0..1.0),
        rng.random_range(-1.0..1.0),
        rng.random_range(-1.0..1.0),
    ));
    Rotation::from_axis_angle(&axis, rng.random_range(0.0..std::f64::consts::PI))
}

fn random_unit(rng: &mut ChaCha8Rng) -> Vector {
    random_rotation(rng) * Vector::z()
}

/// An ellipsoid of size about `size` (largest semi-axis) with aspect ratio up to 10.
fn ellipsoid(rng: &mut ChaCha8Rng, size: Real) -> Body {
    let mut axes = [
        size,
        size * rng.random_range(0.1..1.0),
        size * rng.random_range(0.1..1.0),
    ];
    axes.rotate_left(rng.random_range(0..3));
    let axes = Vector::from(axes);
    Body {
        form: Form::Ellipsoid(axes),
        pose: Pose::from_parts(Vector::zeros().into(), random_rotation(rng)),
        shape: Box::new(Ellipsoid::new(axes.x, axes.y, axes.z).expect("valid axes")),
    }
}

fn sphere(size: Real) -> Body {
    Body {
        form: Form::Ellipsoid(Vector::repeat(size)),
        pose: Pose::identity(),
        shape: Box::new(Sphere::new(size).expect("valid radius")),
    }
}

/// The hull of 24 random points on an ellipsoid of aspect up to 3 (about `size` across).
fn polytope(rng: &mut ChaCha8Rng, size: Real) -> Body {
    let axes = Vector::new(
        size,
        size * rng.random_range(0.33..1.0),
        size * rng.random_range(0.33..1.0),
    );
    let pts: Vec<Point> = (0..24)
        .map(|_| Point::from(random_unit(rng).component_mul(&axes)))
        .collect();
    let (poly, _) = ConvexPolyhedron::from_points(&pts).expect("hull");
    let faces = (0..poly.num_faces())
        .map(|f| poly.face_vertices(f).to_vec())
        .collect();
    Body {
        form: Form::Polytope(poly.vertices().to_vec(), faces),
        pose: Pose::from_parts(Vector::zeros().into(), random_rotation(rng)),
        shape: Box::new(poly),
    }
}

/// Places B against A along a random direction u, at `eps` times their support width along u.
fn place(rng: &mut ChaCha8Rng, a: &mut Body, b: &mut Body, eps: Real) {
    let u = random_unit(rng);
    a.pose.translation.vector = Vector::new(
        rng.random_range(-1.0..1.0),
        rng.random_range(-1.0..1.0),
        rng.random_range(-1.0..1.0),
    ) * a.length_scale();
    b.pose.translation.vector = a.pose.translation.vector;
    let t0 = gap_function(a, b, &u);
    // Touching at one point with the common normal u (B's support point along −u moved onto A's along u),
    // then moved along u by eps·t0: apart by exactly that for eps > 0, overlapping by about it otherwise.
    let touching = a.support(&u).0 - b.support(&-u).0;
    b.pose.translation.vector += touching + u * t0 * eps;
}

#[derive(Default)]
struct Worst {
    overlap: Real,
    normal_attains: Real,
    angle: Real,
    point: Real,
    distance_oracles: Real,
    unconverged: usize,
    pairs: usize,
    overlapping: usize,
    counters: QueryCounters,
}

/// Runs the engine and both oracles on one pair and checks them; records the worst relative errors.
fn check_pair(label: &str, a: &Body, b: &Body, samples: &[Vector], worst: &mut Worst) {
    let tol = ContactTolerances::default();
    let mut counters = QueryCounters::default();
    let r = contact_support_maps(
        &a.pose,
        a.shape.as_ref(),
        &b.pose,
        b.shape.as_ref(),
        &tol,
        &mut PairCache::default(),
        &mut EpaScratch::default(),
        &mut counters,
    );
    worst.pairs += 1;
    worst.counters.merge(&counters);
    let g = r.geometry;
    let ell = a.length_scale().min(b.length_scale());
    let f = |n: &Vector| gap_function(a, b, n);
    let (s, n_o) = minimise_on_sphere(&f, samples);
    let big = a.length_scale()
        + b.length_scale()
        + (b.pose.translation.vector - a.pose.translation.vector).norm();
    let tol_s = tol.curved_gap * ell + 1e-13 * big;
    let measured = g.depth - g.distance;
    worst.overlapping += usize::from(s > 0.0);
    let pair = format!("{label}: A {}, B {}", a.describe(), b.describe());
    if !r.converged {
        worst.unconverged += 1;
        assert!(
            r.bounds[0] - tol_s <= s && s <= r.bounds[1] + tol_s,
            "{pair}: unconverged bounds {:?} exclude the oracle's {s}",
            r.bounds
        );
        return;
    }
    let err = (measured - s).abs();
    worst.overlap = worst.overlap.max(err / ell);
    assert!(
        err <= tol_s,
        "{pair}: signed overlap {measured}, expected {s}, tolerance {tol_s:e}"
    );
    let attained = f(&g.normal) - s;
    worst.normal_attains = worst.normal_attains.max(attained / ell);
    assert!(
        attained <= tol_s,
        "{pair}: f(engine normal {:?}) − s = {attained:e}, tolerance {tol_s:e}",
        g.normal
    );
    if s < 0.0 {
        let d2 = surface_distance(a, b, samples);
        let e = (d2 + s).abs();
        worst.distance_oracles = worst.distance_oracles.max(e / ell);
        assert!(
            e <= tol_s,
            "{pair}: oracles disagree: −min f = {}, min |p_A − p_B| = {d2}, tolerance {tol_s:e}",
            -s
        );
    }
    let (rho_a, rho_b) = (a.curvature_radii(), b.curvature_radii());
    let h = rho_a.0 + rho_b.0 - s.max(0.0);
    if h <= 0.0 {
        return;
    }
    let tol_angle = (2.0 * tol_s / h).sqrt();
    let angle = g.normal.angle(&n_o);
    worst.angle = worst.angle.max(angle / tol_angle);
    assert!(
        angle <= tol_angle,
        "{pair}: normal {:?} vs {n_o:?}: angle {angle:e}, tolerance {tol_angle:e}",
        g.normal
    );
    for (name, body, point, dir) in [("A", a, g.point_a, n_o), ("B", b, g.point_b, -n_o)] {
        if let Form::Ellipsoid(_) = body.form {
            let expected = body.support(&dir).0;
            let tol_p = body.curvature_radii().1 * tol_angle + tol_s;
            let e = (point - expected).norm();
            worst.point = worst.point.max(e / tol_p);
            assert!(e <= tol_p, "{pair}: point on {name} {point:?}, expected {expected:?}, error {e:e}, tolerance {tol_p:e}");
        }
    }
}

fn run(
    label: &str,
    seed: u64,
    pairs: usize,
    make: &dyn Fn(&mut ChaCha8Rng, Real) -> (Body, Body),
) -> Worst {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let samples = fibonacci_sphere(4000);
    let mut worst = Worst::default();
    for k in 0..pairs {
        let size = (10.0 as Real).powf(rng.random_range(-3.0..3.0));
        let (mut a, mut b) = make(&mut rng, size);
        let eps = match k % 4 {
            0 => rng.random_range(-1e-6..1e-6),
            1 => rng.random_range(-0.1..-0.01),
            2 => rng.random_range(-0.01..0.0),
            _ => rng.random_range(0.0..0.1),
        };
        place(&mut rng, &mut a, &mut b, eps);
        check_pair(
            &format!("{label} pair {k} (seed {seed}, eps {eps:e})"),
            &a,
            &b,
            &samples,
            &mut worst,
        );
    }
    eprintln!(
        "{label}: {} pairs, worst |s − s_oracle|/ℓ {:.3e}, worst (f(n) − s)/ℓ {:.3e}, worst angle/tol {:.3e}, \
         worst point error/tol {:.3e}, worst oracle disagreement/ℓ {:.3e}, unconverged {}",
        worst.pairs, worst.overlap, worst.normal_attains, worst.angle, worst.point, worst.distance_oracles,
        worst.unconverged
    );
    eprintln!(
        "{label}: {} overlapping by the oracle; {}",
        worst.overlapping, worst.counters
    );
    assert!(
        worst.overlapping * 4 >= worst.pairs,
        "{label}: only {} of {} pairs overlap: EPA is not exercised",
        worst.overlapping,
        worst.pairs
    );
    worst
}

#[test]
fn ellipsoid_pairs_match_the_support_gap_oracle() {
    let w = run("ellipsoid-ellipsoid", 11, 240, &|rng, size| {
        let b_size = size * rng.random_range(0.3..3.0);
        (ellipsoid(rng, size), ellipsoid(rng, b_size))
    });
    assert_eq!(w.unconverged, 0, "unconverged queries");
}

#[test]
fn ellipsoid_polyhedron_pairs_match_the_support_gap_oracle() {
    let w = run("ellipsoid-polyhedron", 12, 160, &|rng, size| {
        let b_size = size * rng.random_range(0.3..3.0);
        if rng.random_bool(0.5) {
            (ellipsoid(rng, size), polytope(rng, b_size))
        } else {
            (polytope(rng, size), ellipsoid(rng, b_size))
        }
    });
    assert_eq!(w.unconverged, 0, "unconverged queries");
}

#[test]
fn ellipsoid_sphere_pairs_match_the_support_gap_oracle() {
    let w = run("ellipsoid-sphere", 13, 120, &|rng, size| {
        let b_size = size * rng.random_range(0.3..3.0);
        (ellipsoid(rng, size), sphere(b_size))
    });
    assert_eq!(w.unconverged, 0, "unconverged queries");
}
