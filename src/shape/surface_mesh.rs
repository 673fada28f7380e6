//! Surface meshes of shapes, for output only: the [`SurfaceMesh`] type and the UV tessellation of an
//! ellipsoid (a sphere is the ellipsoid r, r, r).

use crate::math::{Point, Real};

/// A closed triangulated or polygonal surface in the body frame, for output only: vertices and faces
/// (vertex indices, counter-clockwise seen from outside).
#[derive(Clone, Debug, PartialEq)]
pub struct SurfaceMesh {
    /// Vertices (body frame, m).
    pub vertices: Vec<Point>,
    /// Faces as vertex indices, counter-clockwise seen from outside.
    pub faces: Vec<Vec<u32>>,
}

/// Latitude bands of the VTK surface (pole to pole): 16 bands of 11.25°. The chordal error of a band edge
/// is r(1 − cos(π/32)) ≈ 4.8e-3 r, below a pixel for a body drawn 200 pixels across.
pub const SURFACE_LATITUDE_BANDS: usize = 16;
/// Meridians of the VTK surface: 32, so that the facets are about square near the equator.
pub const SURFACE_MERIDIANS: usize = 32;

/// The UV tessellation of the ellipsoid (a, b, c): two poles on ±z and [`SURFACE_LATITUDE_BANDS`] − 1 rings
/// of [`SURFACE_MERIDIANS`] vertices, all on the exact surface; triangle fans at the poles, two triangles
/// per quad elsewhere, counter-clockwise seen from outside.
pub fn uv_surface(a: Real, b: Real, c: Real) -> SurfaceMesh {
    uv_surface_with(a, b, c, SURFACE_LATITUDE_BANDS, SURFACE_MERIDIANS)
}

/// [`uv_surface`] with `bands` ≥ 2 latitude bands and `meridians` ≥ 3 meridians.
pub(crate) fn uv_surface_with(
    a: Real,
    b: Real,
    c: Real,
    bands: usize,
    meridians: usize,
) -> SurfaceMesh {
    let pi = std::f64::consts::PI;
    let mut vertices = vec![Point::new(0.0, 0.0, c)];
    for i in 1..bands {
        let theta = pi * i as Real / bands as Real;
        for j in 0..meridians {
            let phi = 2.0 * pi * j as Real / meridians as Real;
            vertices.push(Point::new(
                a * theta.sin() * phi.cos(),
                b * theta.sin() * phi.sin(),
                c * theta.cos(),
            ));
        }
    }
    vertices.push(Point::new(0.0, 0.0, -c));
    let south = (vertices.len() - 1) as u32;
    let ring = |i: usize, j: usize| (1 + (i - 1) * meridians + j % meridians) as u32;
    let mut faces = Vec::with_capacity(2 * meridians * (bands - 1));
    for j in 0..meridians {
        faces.push(vec![0, ring(1, j), ring(1, j + 1)]);
    }
    for i in 1..bands - 1 {
        for j in 0..meridians {
            faces.push(vec![ring(i, j), ring(i + 1, j), ring(i + 1, j + 1)]);
            faces.push(vec![ring(i, j), ring(i + 1, j + 1), ring(i, j + 1)]);
        }
    }
    for j in 0..meridians {
        faces.push(vec![south, ring(bands - 1, j + 1), ring(bands - 1, j)]);
    }
    SurfaceMesh { vertices, faces }
}
