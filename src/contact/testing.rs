//! Test-only shapes and generators: polytopes with explicit topology and brute-force supports, seeded
//! random poses. Independent of the production shape code on purpose.

use super::sat::Polytope;
use crate::math::{Point, Pose, Real, Rotation, Vector};
use crate::shape::{SupportMap, VertexColumns};
use rand::Rng;

/// A polytope given by vertices and (ordered, outward) faces; support by linear scan.
#[derive(Clone, Debug)]
pub struct TestPolytope {
    pub verts: Vec<Point>,
    pub faces: Vec<Vec<u32>>,
    pub normals: Vec<Vector>,
    pub edges: Vec<[u32; 2]>,
    /// Neighbours of each vertex, from `edges`.
    pub adjacency: Vec<Vec<u32>>,
    pub radius: Real,
    /// `verts` as columns (the query's vectorised scan reads these).
    pub columns: VertexColumns,
}

impl TestPolytope {
    pub fn from_faces(verts: Vec<Point>, faces: Vec<Vec<u32>>) -> Self {
        let centroid =
            verts.iter().fold(Vector::zeros(), |a, p| a + p.coords) / verts.len() as Real;
        let mut normals = Vec::new();
        let mut faces_out = Vec::new();
        for f in faces {
            let a = verts[f[0] as usize].coords;
            let b = verts[f[1] as usize].coords;
            let c = verts[f[2] as usize].coords;
            let mut n = (b - a).cross(&(c - a)).normalize();
            let mut f = f;
            if n.dot(&(a - centroid)) < 0.0 {
                n = -n;
                f.reverse();
            }
            normals.push(n);
            faces_out.push(f);
        }
        let mut edges: Vec<[u32; 2]> = Vec::new();
        for f in &faces_out {
            for k in 0..f.len() {
                let (i, j) = (f[k], f[(k + 1) % f.len()]);
                let e = [i.min(j), i.max(j)];
                if !edges.contains(&e) {
                    edges.push(e);
                }
            }
        }
        let mut adjacency = vec![Vec::new(); verts.len()];
        for &[i, j] in &edges {
            adjacency[i as usize].push(j);
            adjacency[j as usize].push(i);
        }
        let radius = verts.iter().map(|p| p.coords.norm()).fold(0.0, Real::max);
        Self {
            columns: VertexColumns::new(&verts),
            verts,
            faces: faces_out,
            normals,
            edges,
            adjacency,
            radius,
        }
    }

    pub fn cuboid(h: Vector) -> Self {
        let mut verts = Vec::new();
        for i in 0..8 {
            let s = |b: usize| if i & (1 << b) != 0 { 1.0 } else { -1.0 };
            verts.push(Point::new(s(0) * h.x, s(1) * h.y, s(2) * h.z));
        }
        let faces = vec![
            vec![0, 2, 6, 4],
            vec![1, 5, 7, 3],
            vec![0, 4, 5, 1],
            vec![2, 3, 7, 6],
            vec![0, 1, 3, 2],
            vec![4, 6, 7, 5],
        ];
        Self::from_faces(verts, faces)
    }

    /// Tetrahedron with its centroid moved to the origin.
    pub fn tetrahedron(p: [Point; 4]) -> Self {
        let c = (p[0].coords + p[1].coords + p[2].coords + p[3].coords) / 4.0;
        let verts = p.iter().map(|q| q - c).collect();
        Self::from_faces(
            verts,
            vec![vec![0, 1, 2], vec![0, 1, 3], vec![0, 2, 3], vec![1, 2, 3]],
        )
    }
}

impl SupportMap for TestPolytope {
    fn local_support(&self, dir: &Vector, hint: &mut u32) -> Point {
        let mut best = 0;
        let mut bd = Real::NEG_INFINITY;
        for (i, p) in self.verts.iter().enumerate() {
            let d = dir.dot(&p.coords);
            if d > bd {
                bd = d;
                best = i;
            }
        }
        *hint = best as u32;
        self.verts[best]
    }
}

impl Polytope for TestPolytope {
    fn vertices(&self) -> &[Point] {
        &self.verts
    }
    fn vertex_columns(&self) -> &VertexColumns {
        &self.columns
    }
    fn num_faces(&self) -> usize {
        self.faces.len()
    }
    fn face_normal(&self, i: usize) -> Vector {
        self.normals[i]
    }
    fn face_offset(&self, i: usize) -> Real {
        self.normals[i].dot(&self.verts[self.faces[i][0] as usize].coords)
    }
    fn face_vertices(&self, i: usize) -> &[u32] {
        &self.faces[i]
    }
    fn edges(&self) -> &[[u32; 2]] {
        &self.edges
    }
    fn neighbors(&self, v: u32) -> &[u32] {
        &self.adjacency[v as usize]
    }
    fn bounding_radius(&self) -> Real {
        self.radius
    }
    fn length_scale(&self) -> Real {
        2.0 * self.radius
    }
}

/// A uniformly random rotation (Shoemake's method).
pub fn random_rotation(rng: &mut impl Rng) -> Rotation {
    let (u1, u2, u3): (Real, Real, Real) = (rng.random(), rng.random(), rng.random());
    let tau = std::f64::consts::TAU;
    let (a, b) = ((1.0 - u1).sqrt(), u1.sqrt());
    let q = nalgebra::Quaternion::new(
        b * (tau * u3).cos(),
        a * (tau * u2).sin(),
        a * (tau * u2).cos(),
        b * (tau * u3).sin(),
    );
    Rotation::from_quaternion(q)
}

/// A uniformly random unit vector.
pub fn random_unit(rng: &mut impl Rng) -> Vector {
    random_rotation(rng) * Vector::z()
}

/// A random pose with translation in a cube of half-side `t`.
pub fn random_pose(rng: &mut impl Rng, t: Real) -> Pose {
    let tr = Vector::new(
        rng.random_range(-t..t),
        rng.random_range(-t..t),
        rng.random_range(-t..t),
    );
    Pose::from_parts(tr.into(), random_rotation(rng))
}
