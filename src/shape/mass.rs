//! Exact mass properties of a closed polyhedron: volume, centroid, inertia tensor, principal moments and axes.
//!
//! # Method
//! Divergence-theorem decomposition into signed tetrahedra: every face is fanned into triangles, and each
//! triangle (a, b, c) forms a tetrahedron with a reference point r (the mean of the vertices, which keeps the
//! coordinates small and the sums free of cancellation far from the origin). For a tetrahedron with one
//! corner at the origin and the others at a, b, c (signed volume V = a·(b×c)/6) the exact moments are
//! - ∫ x dV = V (a + b + c)/4,
//! - ∫ x xᵀ dV = V/20 (a aᵀ + b bᵀ + c cᵀ + s sᵀ), s = a + b + c,
//!
//! (F. Tonon, "Explicit exact formulas for the 3-D tetrahedron inertia tensor in terms of its vertex
//! coordinates", J. Math. Stat. 1(1), 2004). Summing the signed contributions over the closed surface gives
//! the solid's moments exactly (up to round-off); the covariance is moved to the centroid with the parallel
//! axis theorem, and the inertia tensor is I = tr(C) 𝟙 − C.
//!
//! Principal moments and axes come from nalgebra's symmetric eigen-decomposition; moments are sorted
//! ascending and the axes form a right-handed frame. For repeated moments (cube, regular tetrahedron and
//! octahedron, sphere) any orthonormal right-handed frame of the eigenspace is principal; the one returned
//! is whatever the decomposition yields.
//!
//! # Units
//! Every inertia quantity is **per unit density** (m⁵); multiply by the density (kg/m³) for kg·m², or use
//! [`MassProperties::principal_inertia`].

use crate::math::{Matrix, Point, Real, Rotation, Vector};

/// Mass properties of a solid per unit density, in the frame the solid's geometry was given in.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct MassProperties {
    /// Volume (m³).
    pub volume: Real,
    /// Centroid (m).
    pub centroid: Point,
    /// Inertia tensor per unit density about the centroid, along the frame's axes (m⁵).
    pub inertia: Matrix,
    /// Principal moments per unit density, ascending (m⁵).
    pub principal_moments: Vector,
    /// Rotation from the principal frame to the frame of the geometry: its matrix columns are the principal
    /// axes, in the order of `principal_moments`.
    pub principal_axes: Rotation,
}

impl MassProperties {
    /// Mass (kg) for a density in kg/m³.
    pub fn mass(&self, density: Real) -> Real {
        density * self.volume
    }

    /// Principal moments of inertia (kg·m²) for a density in kg/m³, ascending.
    pub fn principal_inertia(&self, density: Real) -> Vector {
        self.principal_moments * density
    }

    /// Inertia tensor about the centroid (kg·m²) for a density in kg/m³, along the frame's axes.
    pub fn inertia_tensor(&self, density: Real) -> Matrix {
        self.inertia * density
    }

    /// Builds the mass properties from volume, centroid and inertia tensor (per unit density) by
    /// diagonalising the tensor.
    pub fn from_inertia(volume: Real, centroid: Point, inertia: Matrix) -> Self {
        let (principal_moments, principal_axes) = principal_frame(&inertia);
        Self {
            volume,
            centroid,
            inertia,
            principal_moments,
            principal_axes,
        }
    }
}

/// Mass properties (per unit density) of the closed polyhedron whose faces are the vertex loops `faces`
/// (counter-clockwise seen from outside). With inward-oriented faces the volume comes out negative; the
/// caller checks it.
pub fn polyhedron_mass_properties<F: AsRef<[u32]>>(
    vertices: &[Point],
    faces: &[F],
) -> MassProperties {
    let mut reference = Vector::zeros();
    for v in vertices {
        reference += v.coords;
    }
    reference /= vertices.len().max(1) as Real;

    let mut volume = 0.0;
    let mut first = Vector::zeros();
    let mut second = Matrix::zeros();
    for face in faces {
        let face = face.as_ref();
        if face.len() < 3 {
            continue;
        }
        let a = vertices[face[0] as usize].coords - reference;
        for k in 1..face.len() - 1 {
            let b = vertices[face[k] as usize].coords - reference;
            let c = vertices[face[k + 1] as usize].coords - reference;
            let v = a.dot(&b.cross(&c)) / 6.0;
            let s = a + b + c;
            volume += v;
            first += s * (v / 4.0);
            second +=
                (a * a.transpose() + b * b.transpose() + c * c.transpose() + s * s.transpose())
                    * (v / 20.0);
        }
    }
    let centroid_rel = if volume != 0.0 {
        first / volume
    } else {
        Vector::zeros()
    };
    let covariance = second - centroid_rel * centroid_rel.transpose() * volume;
    let inertia = Matrix::identity() * covariance.trace() - covariance;
    // Symmetrise against round-off before the eigen-decomposition.
    let inertia = (inertia + inertia.transpose()) * 0.5;
    MassProperties::from_inertia(volume, Point::from(reference + centroid_rel), inertia)
}

/// Principal moments (ascending) and the right-handed rotation whose matrix columns are the matching axes.
pub fn principal_frame(inertia: &Matrix) -> (Vector, Rotation) {
    let eigen = nalgebra::SymmetricEigen::new(*inertia);
    let mut order = [0usize, 1, 2];
    order.sort_by(|&i, &j| eigen.eigenvalues[i].total_cmp(&eigen.eigenvalues[j]));
    let moments = Vector::new(
        eigen.eigenvalues[order[0]],
        eigen.eigenvalues[order[1]],
        eigen.eigenvalues[order[2]],
    );
    let mut axes = Matrix::from_columns(&[
        eigen.eigenvectors.column(order[0]).into_owned(),
        eigen.eigenvectors.column(order[1]).into_owned(),
        eigen.eigenvectors.column(order[2]).into_owned(),
    ]);
    if axes.determinant() < 0.0 {
        axes.set_column(2, &(-axes.column(2)));
    }
    let rotation =
        Rotation::from_rotation_matrix(&nalgebra::Rotation3::from_matrix_unchecked(axes));
    (moments, rotation)
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    fn cuboid(a: Real, b: Real, c: Real) -> (Vec<Point>, Vec<Vec<u32>>) {
        let (x, y, z) = (a / 2.0, b / 2.0, c / 2.0);
        let vertices = vec![
            Point::new(-x, -y, -z),
            Point::new(x, -y, -z),
            Point::new(x, y, -z),
            Point::new(-x, y, -z),
            Point::new(-x, -y, z),
            Point::new(x, -y, z),
            Point::new(x, y, z),
            Point::new(-x, y, z),
        ];
        let faces = vec![
            vec![0, 3, 2, 1],
            vec![4, 5, 6, 7],
            vec![0, 1, 5, 4],
            vec![2, 3, 7, 6],
            vec![1, 2, 6, 5],
            vec![0, 4, 7, 3],
        ];
        (vertices, faces)
    }

    fn assert_close(what: &str, measured: Real, expected: Real, tol: Real) {
        assert!(
            (measured - expected).abs() <= tol,
            "{what}: measured {measured:e}, expected {expected:e}, |diff| {:e} > tolerance {tol:e}",
            (measured - expected).abs()
        );
    }

    #[test]
    fn cuboid_matches_closed_form() {
        let (a, b, c) = (1.0, 2.0, 3.0);
        let (vertices, faces) = cuboid(a, b, c);
        let mp = polyhedron_mass_properties(&vertices, &faces);
        let v = a * b * c;
        let tol = 1e-13;
        assert_close("volume of 1x2x3 cuboid", mp.volume, v, tol * v);
        assert_close("centroid norm", mp.centroid.coords.norm(), 0.0, tol);
        let expected = [
            v * (b * b + c * c) / 12.0,
            v * (a * a + c * c) / 12.0,
            v * (a * a + b * b) / 12.0,
        ];
        for k in 0..3 {
            assert_close(
                &format!("I[{k}{k}] of 1x2x3 cuboid"),
                mp.inertia[(k, k)],
                expected[k],
                tol * expected[2],
            );
        }
        let mut sorted = expected;
        sorted.sort_by(Real::total_cmp);
        for k in 0..3 {
            assert_close(
                &format!("principal moment {k}"),
                mp.principal_moments[k],
                sorted[k],
                tol * sorted[2],
            );
        }
        assert!(
            mp.principal_axes
                .to_rotation_matrix()
                .matrix()
                .determinant()
                > 0.0
        );
    }

    fn regular_tetrahedron(edge: Real) -> (Vec<Point>, Vec<Vec<u32>>) {
        // Alternate corners of a cube of side edge/√2.
        let h = edge / (2.0 * 2.0_f64.sqrt());
        let vertices = vec![
            Point::new(h, h, h),
            Point::new(h, -h, -h),
            Point::new(-h, h, -h),
            Point::new(-h, -h, h),
        ];
        let faces = vec![vec![0, 1, 2], vec![0, 3, 1], vec![0, 2, 3], vec![1, 3, 2]];
        (vertices, faces)
    }

    fn regular_octahedron(edge: Real) -> (Vec<Point>, Vec<Vec<u32>>) {
        let r = edge / 2.0_f64.sqrt();
        let vertices = vec![
            Point::new(r, 0.0, 0.0),
            Point::new(-r, 0.0, 0.0),
            Point::new(0.0, r, 0.0),
            Point::new(0.0, -r, 0.0),
            Point::new(0.0, 0.0, r),
            Point::new(0.0, 0.0, -r),
        ];
        let faces = vec![
            vec![0, 2, 4],
            vec![2, 1, 4],
            vec![1, 3, 4],
            vec![3, 0, 4],
            vec![2, 0, 5],
            vec![1, 2, 5],
            vec![3, 1, 5],
            vec![0, 3, 5],
        ];
        (vertices, faces)
    }

    #[test]
    fn regular_tetrahedron_matches_closed_form() {
        let a = 1.7;
        let (vertices, faces) = regular_tetrahedron(a);
        let mp = polyhedron_mass_properties(&vertices, &faces);
        let v = a.powi(3) / (6.0 * 2.0_f64.sqrt());
        let i = v * a * a / 20.0;
        assert_close("tetrahedron volume", mp.volume, v, 1e-14 * v);
        assert_close(
            "tetrahedron centroid",
            mp.centroid.coords.norm(),
            0.0,
            1e-15 * a,
        );
        for k in 0..3 {
            assert_close(
                &format!("tetrahedron principal moment {k}"),
                mp.principal_moments[k],
                i,
                1e-13 * i,
            );
        }
        let off_diagonal = (mp.inertia - Matrix::identity() * i).norm();
        assert_close(
            "tetrahedron inertia is isotropic",
            off_diagonal,
            0.0,
            1e-13 * i,
        );
    }

    #[test]
    fn regular_octahedron_matches_closed_form() {
        let a = 0.6;
        let (vertices, faces) = regular_octahedron(a);
        let mp = polyhedron_mass_properties(&vertices, &faces);
        let v = 2.0_f64.sqrt() / 3.0 * a.powi(3);
        let i = v * a * a / 10.0;
        assert_close("octahedron volume", mp.volume, v, 1e-14 * v);
        for k in 0..3 {
            assert_close(
                &format!("octahedron principal moment {k}"),
                mp.principal_moments[k],
                i,
                1e-13 * i,
            );
        }
    }

    fn random_pose(rng: &mut ChaCha8Rng) -> crate::math::Pose {
        let axis = Vector::new(
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
        );
        let rotation = Rotation::from_scaled_axis(
            axis.normalize() * rng.random_range(0.0..std::f64::consts::PI),
        );
        let shift = Vector::new(
            rng.random_range(-100.0..100.0),
            rng.random_range(-100.0..100.0),
            rng.random_range(-100.0..100.0),
        );
        crate::math::Pose::from_parts(shift.into(), rotation)
    }

    #[test]
    fn mass_properties_are_invariant_under_rigid_motion() {
        let mut rng = ChaCha8Rng::seed_from_u64(2021);
        let (a, b, c) = (0.5, 1.25, 2.0);
        let (vertices, faces) = cuboid(a, b, c);
        let reference = polyhedron_mass_properties(&vertices, &faces);
        for case in 0..50 {
            let pose = random_pose(&mut rng);
            let moved: Vec<Point> = vertices.iter().map(|v| pose * v).collect();
            let mp = polyhedron_mass_properties(&moved, &faces);
            let tol = 1e-12;
            assert_close(
                &format!("case {case}: volume"),
                mp.volume,
                reference.volume,
                tol * reference.volume,
            );
            assert_close(
                &format!("case {case}: centroid vs pose translation"),
                (mp.centroid.coords - pose.translation.vector).norm(),
                0.0,
                tol * 100.0,
            );
            for k in 0..3 {
                assert_close(
                    &format!("case {case}: principal moment {k}"),
                    mp.principal_moments[k],
                    reference.principal_moments[k],
                    tol * reference.principal_moments[2],
                );
            }
            // Distinct moments: each principal axis is the image of a cuboid axis (up to sign). The smallest
            // moment belongs to the longest side c (z), the largest to the shortest side a (x).
            let axes = mp.principal_axes.to_rotation_matrix();
            let rotation = pose.rotation.to_rotation_matrix();
            for (k, cuboid_axis) in [2usize, 1, 0].into_iter().enumerate() {
                let alignment = axes
                    .matrix()
                    .column(k)
                    .dot(&rotation.matrix().column(cuboid_axis))
                    .abs();
                assert_close(
                    &format!("case {case}: principal axis {k} alignment"),
                    alignment,
                    1.0,
                    1e-9,
                );
            }
        }
    }

    #[test]
    fn volume_scales_cubically_and_inertia_to_the_fifth_power() {
        let (vertices, faces) = regular_octahedron(1.0);
        let reference = polyhedron_mass_properties(&vertices, &faces);
        for s in [1e-3, 0.37, 12.0, 1e3] {
            let scaled: Vec<Point> = vertices.iter().map(|v| v * s).collect();
            let mp = polyhedron_mass_properties(&scaled, &faces);
            let v = reference.volume * s.powi(3);
            assert_close(&format!("volume at scale {s}"), mp.volume, v, 1e-13 * v);
            for k in 0..3 {
                let i = reference.principal_moments[k] * s.powi(5);
                assert_close(
                    &format!("moment {k} at scale {s}"),
                    mp.principal_moments[k],
                    i,
                    1e-13 * i,
                );
            }
        }
    }

    #[test]
    fn density_scales_mass_and_inertia() {
        let (vertices, faces) = cuboid(1.0, 2.0, 3.0);
        let mp = polyhedron_mass_properties(&vertices, &faces);
        let density = 2650.0;
        assert_close(
            "mass",
            mp.mass(density),
            6.0 * density,
            1e-12 * 6.0 * density,
        );
        let expected_x = 6.0 * density * (4.0 + 9.0) / 12.0;
        assert_close(
            "I_max",
            mp.principal_inertia(density)[2],
            expected_x,
            1e-12 * expected_x,
        );
        assert_close(
            "tensor I_xx",
            mp.inertia_tensor(density)[(0, 0)],
            expected_x,
            1e-12 * expected_x,
        );
    }
}
