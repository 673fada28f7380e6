//! Plane–polyhedron contact: exact status and depth from the support along the plane normal; the overlap
//! handed to the law and its force point from the smoothed depth of [`super::wall_depth`].
//!
//! The plane (A, a wall) is the half-space {x : n·x ≤ o}. The exact overlap is the support distance
//! δ = o − min_v n·v over the polyhedron's vertices (B), normal n (from the wall to the body); the contact
//! status (overlap / touching / separated) is always classified from this exact δ, as the SAT oracle would.
//!
//! What the law sees depends on [`ContactTolerances::wall_depth`]:
//! - [`WallDepth::Smoothed`] (default): `depth` is the smoothed depth D ≤ δ of the vertices within 2h of
//!   the deepest one (D = δ when one vertex leads by 2h or more, and at exact ties), and c2 the
//!   ∂D/∂d_i-weighted mean of those vertices, brought to the level of the overlap along n; c1 = c2 + D n on
//!   the plane. A force −U'(D) n at c_M is then exactly the generalised force of U(D), so an elastic law
//!   conserves energy also when a face or an edge lands flat and rocks (see [`super::wall_depth`]). When
//!   D ≤ 0 while δ > 0 (a tilted face just touching), the status is `Overlap` with depth 0: the law exerts
//!   nothing, continuously.
//! - [`WallDepth::DeepestVertex`]: `depth` is δ and c2 the deepest vertex — the gradient point of
//!   δ = max(d_i) — or the centroid of the vertices tied with it within round-off (1e-12 L: a face or an edge
//!   resting exactly flat), the symmetric element of the sub-gradient. The point jumps between vertices as a
//!   flat face rocks through the tie: first-order energy error (measured in `single_contact_energy`).
//!   (A depth-weighted centroid of all penetrating vertices varies continuously but is not the gradient of
//!   any potential; it was measured to lose ~10 % of the energy of an edge landing flat.)
//!
//! Status `Exact`. O(V), no allocation unless more than 64 vertices lie within 2h of the deepest one.

use super::contact_sphere_sphere::classify;
use super::sat::Polytope;
use super::tolerances::ContactTolerances;
use super::wall_depth::{smoothed_depth, WallDepth};
use super::{ContactGeometry, ContactKind, SolverStatus};
use crate::math::{Point, Pose, Real, Vector};

/// Vertices within 2h of the deepest one that are handled on the stack.
const STACK_BAND: usize = 64;

/// Contact of the plane (A: pose `pos1`, local outward normal `normal1`, offset `offset1`) with the
/// polytope `b` at `pos2`.
pub fn contact_plane_polytope<B: Polytope + ?Sized>(
    pos1: &Pose,
    normal1: &Vector,
    offset1: Real,
    pos2: &Pose,
    b: &B,
    tol: &ContactTolerances,
) -> ContactGeometry {
    let (n, n2, o2) = plane_in_frame_of(pos1, normal1, offset1, pos2);
    let verts = b.vertices();
    // The heights n2·v of the vertices, computed once (up to `STACK_BAND` vertices) and read by the
    // smoothing below: the same values in the same order as computing them where they are used.
    let mut heights_buf = [0.0; STACK_BAND];
    let heights = (verts.len() <= STACK_BAND).then(|| {
        for (x, v) in heights_buf.iter_mut().zip(verts) {
            *x = n2.dot(&v.coords);
        }
        &heights_buf[..verts.len()]
    });
    let lowest = match heights {
        Some(heights) => heights.iter().copied().fold(Real::INFINITY, Real::min),
        None => verts
            .iter()
            .map(|v| n2.dot(&v.coords))
            .fold(Real::INFINITY, Real::min),
    };
    let signed = o2 - lowest;
    let touch = tol.touching * b.length_scale();
    let (kind, depth, distance) = classify(signed, touch);
    let (c2_local, law_depth) = match tol.wall_depth {
        WallDepth::Smoothed { band } if kind == ContactKind::Overlap => {
            let h = band * b.length_scale();
            let (point, d) = match heights {
                Some(heights) => smoothed_point_of_heights(verts, heights, &n2, o2, lowest, h),
                None => smoothed_point(verts, &n2, o2, lowest, h),
            };
            (point, d.max(0.0))
        }
        _ => {
            // The deepest vertex, or the centroid of the vertices tied with it within round-off.
            let tie = 1e-12 * b.length_scale();
            let (mut sum, mut count) = (Vector::zeros(), 0.0);
            for v in verts {
                if n2.dot(&v.coords) <= lowest + tie {
                    sum += v.coords;
                    count += 1.0;
                }
            }
            let xbar = sum / count;
            (xbar - n2 * (n2.dot(&xbar) - lowest), depth)
        }
    };
    let point_b = pos2 * Point::from(c2_local);
    // c1 on the plane: c1 − c2 = D n when overlapping, c2 − c1 = d n when apart.
    let point_a = point_b
        + n * if kind == ContactKind::Overlap {
            law_depth
        } else {
            signed
        };
    ContactGeometry::from_points(
        kind,
        law_depth,
        distance,
        n,
        point_a,
        point_b,
        SolverStatus::Exact,
    )
}

/// The plane (A: pose `pos1`, local outward normal `normal1`, offset `offset1`) in the frame of B at
/// `pos2`: the world normal n, B's local normal n2 = R2ᵀ n and offset o2 = o − n·t2.
#[inline]
fn plane_in_frame_of(
    pos1: &Pose,
    normal1: &Vector,
    offset1: Real,
    pos2: &Pose,
) -> (Vector, Vector, Real) {
    let n = pos1.rotation * normal1;
    let o = offset1 + n.dot(&pos1.translation.vector);
    let n2 = pos2.rotation.inverse_transform_vector(&n);
    (n, n2, o - n.dot(&pos2.translation.vector))
}

/// The exact overlap of the polytope `b` at `pos2` with the plane (arguments of
/// [`contact_plane_polytope`]): the depth of its deepest vertex, max_i d_i, 0 when apart. What
/// [`WallDepth::DeepestVertex`] hands to the law, and what the step's overlap statistic measures with
/// either rule (the smoothed depth falls short of it by up to 0.22 h; see [`super::wall_depth`]).
pub fn plane_polytope_depth<B: Polytope + ?Sized>(
    pos1: &Pose,
    normal1: &Vector,
    offset1: Real,
    pos2: &Pose,
    b: &B,
) -> Real {
    let (_, n2, o2) = plane_in_frame_of(pos1, normal1, offset1, pos2);
    let lowest = b
        .vertices()
        .iter()
        .map(|v| n2.dot(&v.coords))
        .fold(Real::INFINITY, Real::min);
    (o2 - lowest).max(0.0)
}

/// [`smoothed_point`] from the vertex heights `heights[i]` = n2·v_i (at most `STACK_BAND` vertices),
/// the same arithmetic on the same values, so the same bits: one pass finds the band; a single vertex in
/// it (the usual case) is its own smoothed depth with weight 1 (D = 2 S_h − S_2h = 2d − d = d exactly, and
/// Newton stops at once with ψ(0) = 1), so the two Newton solves are not run for it.
fn smoothed_point_of_heights(
    verts: &[Point],
    heights: &[Real],
    n2: &Vector,
    o2: Real,
    lowest: Real,
    h: Real,
) -> (Vector, Real) {
    let limit = lowest + 2.0 * h;
    let mut band = [0u8; STACK_BAND];
    let mut count = 0;
    for (i, &x) in heights.iter().enumerate() {
        if x < limit {
            band[count] = i as u8;
            count += 1;
        }
    }
    let band = &band[..count];
    let mut xbar = Vector::zeros();
    let d = if let [i] = band {
        let (i, weight) = (*i as usize, 1.0);
        xbar += verts[i].coords * weight;
        o2 - heights[i]
    } else {
        let mut stack = [[0.0; STACK_BAND]; 3];
        let [depths, weights, scratch] = &mut stack;
        let (depths, weights, scratch) = (
            &mut depths[..count],
            &mut weights[..count],
            &mut scratch[..count],
        );
        for (d, &i) in depths.iter_mut().zip(band) {
            *d = o2 - heights[i as usize];
        }
        let d = smoothed_depth(depths, h, weights, scratch);
        for (w, &i) in weights.iter().zip(band) {
            xbar += verts[i as usize].coords * *w;
        }
        d
    };
    // Level of the overlap: n2·c2 = o2 − D.
    (xbar - n2 * (n2.dot(&xbar) - (o2 - d)), d)
}

/// The smoothed depth D of the vertices within 2h of the deepest one (depths d_i = o2 − n2·v_i, deepest
/// o2 − `lowest`) and the ∂D/∂d_i-weighted mean of those vertices moved along n2 to the level o2 − D, in B's
/// frame.
fn smoothed_point(verts: &[Point], n2: &Vector, o2: Real, lowest: Real, h: Real) -> (Vector, Real) {
    let in_band = |v: &Point| n2.dot(&v.coords) < lowest + 2.0 * h;
    let count = verts.iter().filter(|v| in_band(v)).count();
    let mut stack = [[0.0; STACK_BAND]; 3];
    let mut heap;
    let [depths, weights, scratch]: [&mut [Real]; 3] = if count <= STACK_BAND {
        let [a, b, c] = &mut stack;
        [&mut a[..count], &mut b[..count], &mut c[..count]]
    } else {
        heap = vec![0.0; 3 * count];
        let (a, rest) = heap.split_at_mut(count);
        let (b, c) = rest.split_at_mut(count);
        [a, b, c]
    };
    for (d, v) in depths.iter_mut().zip(verts.iter().filter(|v| in_band(v))) {
        *d = o2 - n2.dot(&v.coords);
    }
    let d = smoothed_depth(depths, h, weights, scratch);
    let mut xbar = Vector::zeros();
    for (w, v) in weights.iter().zip(verts.iter().filter(|v| in_band(v))) {
        xbar += v.coords * *w;
    }
    // Level of the overlap: n2·c2 = o2 − D.
    (xbar - n2 * (n2.dot(&xbar) - (o2 - d)), d)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::contact::testing::{random_rotation, TestPolytope};
    use crate::contact::ContactKind;
    use rand::{Rng, SeedableRng};

    /// The derivative of `depth` under a small turn of body 2 about each axis (central differences, step
    /// 1e-7 rad) equals the torque arm of the contact point `g.point_b`: −((c − x₂) × n)·e, to 1e-6.
    fn assert_turn_derivative_is_the_torque_arm(
        depth: &dyn Fn(&Pose) -> Real,
        pos2: &Pose,
        g: &ContactGeometry,
        label: &str,
    ) {
        let arm = g.point_b - Point::from(pos2.translation.vector);
        let h = 1e-7;
        for e in [Vector::x(), Vector::y(), Vector::z()] {
            let turn = |s: Real| {
                let r = crate::math::Rotation::from_scaled_axis(e * s);
                Pose::from_parts(pos2.translation, r * pos2.rotation)
            };
            let fd = (depth(&turn(h)) - depth(&turn(-h))) / (2.0 * h);
            let want = -arm.cross(&g.normal).dot(&e);
            assert!(
                (fd - want).abs() < 1e-6,
                "{label}, axis {e:?}: dδ/dθ = {fd}, torque arm gives {want} (tolerance 1e-6)"
            );
        }
    }

    #[test]
    fn box_resting_on_a_wall_reports_its_face_centroid() {
        let tol = ContactTolerances::default();
        let h = Vector::new(1.0, 0.5, 0.25);
        let bx = TestPolytope::cuboid(h);
        for scale in [1e-3, 1.0, 1e3] {
            let bxs = TestPolytope::cuboid(h * scale);
            let pos2 = Pose::translation(2.0 * scale, -scale, (0.25 - 1e-7) * scale);
            let g = contact_plane_polytope(&Pose::identity(), &Vector::z(), 0.0, &pos2, &bxs, &tol);
            assert_eq!(g.kind, ContactKind::Overlap, "{g:?}");
            assert!(
                (g.depth - 1e-7 * scale).abs() <= 1e-15 * scale,
                "depth {} scale {scale}",
                g.depth
            );
            let want = Point::new(2.0 * scale, -scale, 0.0);
            assert!(
                (g.point_a - want).norm() <= 1e-14 * scale,
                "c1 {:?} want {want:?}",
                g.point_a
            );
            assert!((g.point_a - g.point_b - g.normal * g.depth).norm() <= 1e-15 * scale);
        }
        let _ = bx;
    }

    /// The torque of the contact force about the body's centre is the gradient of δ with respect to the
    /// body's rotation: d δ / d θ (about axis e) = −((c2 − x_B) × n)·e, checked by central differences on
    /// random tilted poses. This is what makes an elastic law energy-conserving.
    fn deepest_vertex() -> ContactTolerances {
        ContactTolerances {
            wall_depth: WallDepth::DeepestVertex,
            ..ContactTolerances::default()
        }
    }

    #[test]
    fn contact_point_is_the_gradient_point_of_the_overlap() {
        let tol = deepest_vertex();
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(9);
        let bx = TestPolytope::cuboid(Vector::new(1.0, 0.5, 0.25));
        let depth_at = |pos2: &Pose| {
            let lowest = bx
                .verts
                .iter()
                .map(|v| (pos2 * v).z)
                .fold(Real::INFINITY, Real::min);
            -lowest
        };
        for k in 0..200 {
            // Half random orientations (one vertex below the wall), half nearly flat (a face tilted by
            // ~1e-3 rad: several vertices below, one deepest).
            let rot = if k % 2 == 0 {
                random_rotation(&mut rng)
            } else {
                let axis = Vector::new(
                    rng.random_range(-1.0..1.0),
                    rng.random_range(-1.0..1.0),
                    0.0,
                );
                crate::math::Rotation::from_scaled_axis(axis * 1e-3)
            };
            let low = bx
                .verts
                .iter()
                .map(|v| (rot * v).z)
                .fold(Real::INFINITY, Real::min);
            let pos2 = Pose::from_parts(Vector::new(0.3, -0.2, -low - 1e-3).into(), rot);
            let g = contact_plane_polytope(&Pose::identity(), &Vector::z(), 0.0, &pos2, &bx, &tol);
            assert_eq!(g.kind, ContactKind::Overlap);
            assert_turn_derivative_is_the_torque_arm(&depth_at, &pos2, &g, "deepest vertex");
        }
    }

    #[test]
    fn depth_is_the_support_distance_for_random_poses() {
        let tol = deepest_vertex();
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(5);
        let bx = TestPolytope::cuboid(Vector::new(1.0, 0.7, 0.3));
        let wall = Pose::from_parts(
            Vector::new(0.1, 0.2, -0.3).into(),
            random_rotation(&mut rng),
        );
        for _ in 0..200 {
            let rot = random_rotation(&mut rng);
            let pos2 = Pose::from_parts((wall * Point::new(0.0, 0.0, 0.5)).coords.into(), rot);
            let g = contact_plane_polytope(&wall, &Vector::z(), 0.0, &pos2, &bx, &tol);
            let n = wall.rotation * Vector::z();
            let o = n.dot(&wall.translation.vector);
            let lowest = bx
                .verts
                .iter()
                .map(|v| n.dot(&(pos2 * v).coords))
                .fold(Real::INFINITY, Real::min);
            let want = o - lowest;
            let got = if g.kind == ContactKind::Overlap {
                g.depth
            } else {
                -g.distance
            };
            assert!((got - want).abs() <= 1e-14, "depth {got} want {want}");
            assert!(
                (n.dot(&g.point_a.coords) - o).abs() <= 1e-14,
                "c1 off the wall"
            );
        }
    }

    /// Smoothed wall depth: the status is the exact one of the support distance δ, the law's depth D never
    /// exceeds δ and equals it when one vertex leads by 2h or more, on random and on nearly flat poses.
    #[test]
    fn smoothed_depth_keeps_the_exact_status_and_never_exceeds_the_overlap() {
        let tol = ContactTolerances::default();
        let WallDepth::Smoothed { band } = tol.wall_depth else {
            panic!(
                "the default wall depth is the smoothed one: {:?}",
                tol.wall_depth
            );
        };
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(21);
        for scale in [1e-3, 1.0, 1e3] {
            let bx = TestPolytope::cuboid(Vector::new(1.0, 0.7, 0.3) * scale);
            let h = band * bx.length_scale();
            for k in 0..400 {
                let rot = if k % 2 == 0 {
                    random_rotation(&mut rng)
                } else {
                    let axis = Vector::new(
                        rng.random_range(-1.0..1.0),
                        rng.random_range(-1.0..1.0),
                        0.0,
                    );
                    crate::math::Rotation::from_scaled_axis(axis * 3.0 * band)
                };
                let heights: Vec<Real> = bx.verts.iter().map(|v| (rot * v).z).collect();
                let low = heights.iter().copied().fold(Real::INFINITY, Real::min);
                let offset = rng.random_range(-2.0..2.0) * h;
                let pos2 = Pose::from_parts(Vector::new(0.1, 0.2, -low - offset).into(), rot);
                let g =
                    contact_plane_polytope(&Pose::identity(), &Vector::z(), 0.0, &pos2, &bx, &tol);
                let exact = -heights
                    .iter()
                    .map(|z| z + pos2.translation.z)
                    .fold(Real::INFINITY, Real::min);
                let (kind, _, distance) = classify(exact, tol.touching * bx.length_scale());
                assert_eq!(g.kind, kind, "scale {scale}, pose {k}: δ = {exact}, {g:?}");
                assert!(
                    (g.distance - distance).abs() <= 1e-15 * scale,
                    "distance {} want {distance}",
                    g.distance
                );
                assert!(
                    g.depth <= exact.max(0.0) + 1e-15 * scale,
                    "scale {scale}, pose {k}: law depth {} above the overlap {exact}",
                    g.depth
                );
                let mut sorted = heights.clone();
                sorted.sort_by(Real::total_cmp);
                if kind == ContactKind::Overlap && sorted[1] - sorted[0] >= 2.0 * h {
                    assert!(
                        (g.depth - exact).abs() <= 1e-14 * scale,
                        "scale {scale}, pose {k}: one vertex leads by {} ≥ 2h = {}, depth {} want {exact}",
                        sorted[1] - sorted[0],
                        2.0 * h,
                        g.depth
                    );
                }
                let gap = if kind == ContactKind::Overlap {
                    g.point_a - g.point_b - g.normal * g.depth
                } else {
                    g.point_b - g.point_a - g.normal * g.distance
                };
                assert!(
                    gap.norm() <= 1e-14 * scale + tol.touching * bx.length_scale(),
                    "scale {scale}, pose {k}: c1, c2 inconsistent with the depth: {g:?}"
                );
            }
        }
    }

    /// The smoothing from the heights computed once ([`smoothed_point_of_heights`], the path of polytopes of
    /// up to `STACK_BAND` vertices) gives the bits of the reference that recomputes them where it needs them
    /// ([`smoothed_point`]): a box landing flat, on an edge and tilted (bands of 1, 2 and 4 vertices and
    /// everything between), at sizes 1e-3, 1 and 1e3 m.
    #[test]
    fn smoothing_from_the_heights_is_bit_identical_to_the_reference() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(23);
        let mut band_sizes = [0usize; 9];
        for scale in [1e-3, 1.0, 1e3] {
            let bx = TestPolytope::cuboid(Vector::new(1.0, 0.5, 0.25) * scale);
            let h = 1e-4 * bx.length_scale();
            for k in 0..300 {
                // Tilts from exactly flat to a few bands: ties of 4, 2 and single leading vertices.
                let tilt = [0.0, 1e-6, 1e-4, 1e-2][k % 4];
                let axis = Vector::new(
                    rng.random_range(-1.0..1.0),
                    rng.random_range(-1.0..1.0),
                    if k % 8 < 4 {
                        0.0
                    } else {
                        rng.random_range(-1.0..1.0)
                    },
                );
                let rot = crate::math::Rotation::from_scaled_axis(axis * tilt);
                let n2 = rot.inverse_transform_vector(&Vector::z());
                let heights: Vec<Real> = bx.verts.iter().map(|v| n2.dot(&v.coords)).collect();
                let lowest = heights.iter().copied().fold(Real::INFINITY, Real::min);
                let o2 = lowest + rng.random_range(0.0..4.0) * h;
                let count = heights.iter().filter(|&&x| x < lowest + 2.0 * h).count();
                band_sizes[count] += 1;
                let (p_ref, d_ref) = smoothed_point(&bx.verts, &n2, o2, lowest, h);
                let (p, d) = smoothed_point_of_heights(&bx.verts, &heights, &n2, o2, lowest, h);
                assert!(
                    d.to_bits() == d_ref.to_bits()
                        && (0..3).all(|i| p[i].to_bits() == p_ref[i].to_bits()),
                    "scale {scale}, pose {k} (tilt {tilt}, band of {count}): heights path D = {d:e}, \
                     c2 = {p:?}; reference D = {d_ref:e}, c2 = {p_ref:?} (tolerance: equal bits)"
                );
            }
        }
        assert!(
            band_sizes[1] > 0 && band_sizes[2] > 0 && band_sizes[4] > 0,
            "band sizes seen {band_sizes:?}: want bands of 1, 2 and 4 vertices"
        );
    }

    /// Smoothed wall depth: the force point is the gradient point of the law's depth D. With the body
    /// nearly flat (several vertices within the band), central differences of D give dD/dθ about each axis
    /// = −((c2 − x_B) × n)·e, dD/dx along −n = 1 and 0 along the wall: a force −U'(D) n at c_M is the
    /// generalised force of U(D).
    #[test]
    fn smoothed_force_point_is_the_gradient_point_of_the_law_depth() {
        let tol = ContactTolerances::default();
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(17);
        let bx = TestPolytope::cuboid(Vector::new(1.0, 0.5, 0.25));
        let law_depth = |pos2: &Pose| {
            contact_plane_polytope(&Pose::identity(), &Vector::z(), 0.0, pos2, &bx, &tol).depth
        };
        for k in 0..200 {
            let axis = Vector::new(
                rng.random_range(-1.0..1.0),
                rng.random_range(-1.0..1.0),
                0.0,
            );
            let rot = crate::math::Rotation::from_scaled_axis(axis * 4e-3 * (k % 4) as Real);
            let low = bx
                .verts
                .iter()
                .map(|v| (rot * v).z)
                .fold(Real::INFINITY, Real::min);
            let pos2 = Pose::from_parts(Vector::new(0.3, -0.2, -low - 1e-2).into(), rot);
            let g = contact_plane_polytope(&Pose::identity(), &Vector::z(), 0.0, &pos2, &bx, &tol);
            assert_eq!(g.kind, ContactKind::Overlap);
            assert!(g.depth > 0.0);
            assert_turn_derivative_is_the_torque_arm(&law_depth, &pos2, &g, &format!("pose {k}"));
            let e_fd = 1e-7;
            for e in [Vector::x(), Vector::y(), Vector::z()] {
                let shift = |s: Real| {
                    Pose::from_parts((pos2.translation.vector + e * s).into(), pos2.rotation)
                };
                let fd = (law_depth(&shift(e_fd)) - law_depth(&shift(-e_fd))) / (2.0 * e_fd);
                let want = -e.dot(&g.normal);
                assert!(
                    (fd - want).abs() < 1e-6,
                    "pose {k}, shift {e:?}: dD/dx = {fd}, want {want}"
                );
            }
        }
    }
}
