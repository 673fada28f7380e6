//! Convex polyhedra: construction (from a point cloud or from vertices and faces), topology, principal frame
//! and the hill-climbing support map.
//!
//! A [`ConvexPolyhedron`] is stored in its **principal frame**: origin at the centroid, axes along the
//! principal axes of inertia, moments ascending, right-handed. Both constructors return, beside the shape,
//! the [`Pose`] that maps principal-frame coordinates back to the coordinates of the input (`pose * v_local`
//! is the input-frame position of local vertex `v_local`), which is the body's initial pose when the input
//! was given in world coordinates.
//!
//! Stored data: vertices; faces as vertex loops (counter-clockwise seen from outside) with outward unit
//! normals and plane offsets; unique edges; vertex adjacency in compressed-sparse-row form; bounding radius
//! about the origin; mass properties per unit density; the vertices again as columns for the vectorised
//! support scan ([`VertexColumns`], derived, not serialised).
//!
//! # Tolerances
//! [`ConvexPolyhedron::length_scale`] is the diameter of the bounding sphere centred at the centroid
//! (twice [`ConvexPolyhedron::bounding_radius`]). Construction tolerances are relative to the input's extent
//! (`hull::hull_tolerance`: 1e-10 of the extent plus the coordinates' own round-off); contact code scales its tolerances by `length_scale()`.

use crate::math::{Matrix, Point, Pose, Real, Rotation, Vector};

use super::aabb::Aabb;
use super::error::ShapeError;
use super::hull;
use super::mass::{polyhedron_mass_properties, MassProperties};
use super::polygon::{newell_normal, supporting_plane};
use super::support::SupportMap;
use super::vertex_columns::VertexColumns;

/// Up to this many vertices the support map scans all vertices instead of hill-climbing: for small
/// polyhedra a branch-predictable linear scan beats graph walking. Measured with `benches/support_map.rs`
/// (ns per call, shared 2-core machine under load, so ±15 %): coherent directions with a carried hint
/// (the GJK pattern) — 12 vertices: scan 17, climb 16; 16: scan 24, climb 17; 32: scan 55, climb 23;
/// independent random directions — 12: scan 14, climb 37; 16: scan 25, climb 40; 32: scan 60, climb 59.
/// Averaged over both patterns the crossover lies near 20 vertices; 16 keeps the scan where it never
/// loses by much.
pub const LINEAR_SCAN_MAX_VERTICES: usize = 16;

/// A solid whose volume is below `VOLUME_ROUNDOFF_FACTOR · ε · extent³` is rejected as having zero volume:
/// the tetrahedral volume sums carry round-off of order ε·extent³, so a smaller volume has no reliable sign
/// or value. Flat inputs are caught earlier by the hull's thickness test; this catches needles.
pub const VOLUME_ROUNDOFF_FACTOR: Real = 1e3;

/// A convex polyhedron in its principal frame (see the module docs).
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
#[serde(from = "PolyhedronData")]
pub struct ConvexPolyhedron {
    vertices: Vec<Point>,
    /// The vertices again, as columns for the vectorised support scan; derived from `vertices`, so not
    /// serialised (the serialised form is [`PolyhedronData`]'s).
    #[serde(skip_serializing)]
    columns: VertexColumns,
    /// Face `f` is `face_indices[face_starts[f]..face_starts[f + 1]]`.
    face_starts: Vec<u32>,
    face_indices: Vec<u32>,
    face_normals: Vec<Vector>,
    face_offsets: Vec<Real>,
    edges: Vec<[u32; 2]>,
    /// Neighbours of vertex `v` are `adjacency[adjacency_starts[v]..adjacency_starts[v + 1]]`.
    adjacency_starts: Vec<u32>,
    adjacency: Vec<u32>,
    bounding_radius: Real,
    mass_properties: MassProperties,
}

/// The serialised fields of a [`ConvexPolyhedron`], in its order: everything but the derived vertex columns,
/// which deserialisation rebuilds.
#[derive(serde::Deserialize)]
struct PolyhedronData {
    vertices: Vec<Point>,
    face_starts: Vec<u32>,
    face_indices: Vec<u32>,
    face_normals: Vec<Vector>,
    face_offsets: Vec<Real>,
    edges: Vec<[u32; 2]>,
    adjacency_starts: Vec<u32>,
    adjacency: Vec<u32>,
    bounding_radius: Real,
    mass_properties: MassProperties,
}

impl From<PolyhedronData> for ConvexPolyhedron {
    fn from(d: PolyhedronData) -> Self {
        ConvexPolyhedron {
            columns: VertexColumns::new(&d.vertices),
            vertices: d.vertices,
            face_starts: d.face_starts,
            face_indices: d.face_indices,
            face_normals: d.face_normals,
            face_offsets: d.face_offsets,
            edges: d.edges,
            adjacency_starts: d.adjacency_starts,
            adjacency: d.adjacency,
            bounding_radius: d.bounding_radius,
            mass_properties: d.mass_properties,
        }
    }
}

impl ConvexPolyhedron {
    /// The convex hull of `points` (at least 4 points, not all coplanar, all finite), with coplanar hull
    /// triangles merged into polygonal faces and interior, duplicate and edge/face-interior points dropped.
    ///
    /// Returns the polyhedron in its principal frame and the pose mapping that frame to the input frame.
    ///
    /// Errors: a [`ShapeError`] for fewer than 4 points, a non-finite coordinate, or points that are
    /// coincident, collinear or coplanar (tolerances relative to the cloud's extent).
    ///
    /// # Example
    /// A 2 × 1 × 1 m box from its corners plus an interior point (dropped):
    ///
    /// ```
    /// use polydem::math::Point;
    /// use polydem::shape::{ConvexPolyhedron, ShapeError};
    ///
    /// let mut points: Vec<Point> = (0..8)
    ///     .map(|i| Point::new(2.0 * (i & 1) as f64, ((i >> 1) & 1) as f64, (i >> 2) as f64))
    ///     .collect();
    /// points.push(Point::new(1.0, 0.5, 0.5));
    /// let (boxed, frame) = ConvexPolyhedron::from_points(&points)?;
    /// assert_eq!(boxed.vertices().len(), 8);
    /// assert_eq!(boxed.num_faces(), 6); // coplanar hull triangles merged into the rectangles
    /// let volume = boxed.mass_properties().volume;
    /// assert!((volume - 2.0).abs() < 1e-12, "volume {volume} m³");
    /// // The principal frame sits at the centroid.
    /// assert!((frame.translation.vector - Point::new(1.0, 0.5, 0.5).coords).norm() < 1e-12);
    ///
    /// // Three points cannot make a solid.
    /// let err = ConvexPolyhedron::from_points(&points[..3]).unwrap_err();
    /// assert!(matches!(err, ShapeError::TooFewPoints { count: 3 }));
    /// # Ok::<(), ShapeError>(())
    /// ```
    pub fn from_points(points: &[Point]) -> Result<(ConvexPolyhedron, Pose), ShapeError> {
        let extent = hull::validate_points(points)?;
        let mesh = hull::convex_hull(points)?;
        Self::from_convex_mesh(&mesh.vertices, &mesh.faces, extent)
    }

    /// A polyhedron from explicit vertices and faces (vertex index loops, counter-clockwise seen from
    /// outside). The mesh is validated: at least 4 vertices, all finite and used; every face has ≥ 3 distinct
    /// valid indices and is planar; the surface is closed, consistently oriented, of sphere topology, with
    /// outward orientation and positive volume; and the solid is convex. Tolerances are relative to the
    /// vertices' extent (`hull::hull_tolerance`).
    ///
    /// Returns the polyhedron in its principal frame and the pose mapping that frame to the input frame.
    pub fn from_vertices_faces(
        vertices: &[Point],
        faces: &[Vec<u32>],
    ) -> Result<(ConvexPolyhedron, Pose), ShapeError> {
        let extent = hull::validate_points(vertices)?;
        let tol = hull::hull_tolerance(vertices, extent);
        validate_topology(vertices.len(), faces)?;
        let signed_volume = polyhedron_mass_properties(vertices, faces).volume;
        if signed_volume < 0.0 {
            return Err(ShapeError::InwardOrientation { signed_volume });
        }
        for (f, face) in faces.iter().enumerate() {
            let normal = newell_normal(vertices, face);
            let norm = normal.norm();
            if !norm.is_finite() || norm <= 0.0 {
                return Err(ShapeError::MalformedFace {
                    face: f,
                    reason: "zero area".to_string(),
                });
            }
            let normal = normal / norm;
            let mean = face
                .iter()
                .map(|&v| normal.dot(&vertices[v as usize].coords))
                .sum::<Real>()
                / face.len() as Real;
            for &v in face {
                let distance = (normal.dot(&vertices[v as usize].coords) - mean).abs();
                if distance > tol {
                    return Err(ShapeError::NonPlanarFace {
                        face: f,
                        vertex: v,
                        distance,
                        tolerance: tol,
                    });
                }
            }
            for (v, p) in vertices.iter().enumerate() {
                let distance = normal.dot(&p.coords) - mean;
                if distance > tol {
                    return Err(ShapeError::NotConvex {
                        face: f,
                        vertex: v as u32,
                        distance,
                        tolerance: tol,
                    });
                }
            }
        }
        Self::from_convex_mesh(vertices, faces, extent)
    }

    /// Shared tail of both constructors: mass properties, principal frame, topology, planes.
    fn from_convex_mesh(
        vertices: &[Point],
        faces: &[Vec<u32>],
        extent: Real,
    ) -> Result<(ConvexPolyhedron, Pose), ShapeError> {
        let (pose, mass) = refined_principal_frame(vertices, faces, extent)?;
        let local: Vec<Point> = vertices
            .iter()
            .map(|v| pose.inverse_transform_point(v))
            .collect();
        let planes = FacePlanes::of(&local, faces)?;
        let edges = edges_of(faces);
        let (adjacency_starts, adjacency) = vertex_adjacency(local.len(), &edges);
        let bounding_radius = local.iter().map(|v| v.coords.norm()).fold(0.0, Real::max);
        let mass_properties = MassProperties {
            volume: mass.volume,
            centroid: Point::origin(),
            inertia: Matrix::from_diagonal(&mass.principal_moments),
            principal_moments: mass.principal_moments,
            principal_axes: Rotation::identity(),
        };
        let shape = ConvexPolyhedron {
            columns: VertexColumns::new(&local),
            vertices: local,
            face_starts: planes.starts,
            face_indices: planes.indices,
            face_normals: planes.normals,
            face_offsets: planes.offsets,
            edges,
            adjacency_starts,
            adjacency,
            bounding_radius,
            mass_properties,
        };
        Ok((shape, pose))
    }

    /// Checks the index structure of a polyhedron that was not built here (e.g. decoded from a checkpoint):
    /// at least four vertices, every face, edge and adjacency index in range, monotone face and adjacency
    /// starts, one normal and offset per face, all coordinates finite. Returns what is wrong. It does not
    /// re-prove convexity; a checkpoint's checksum guards the values themselves.
    pub fn check_structure(&self) -> Result<(), String> {
        let n = self.vertices.len();
        if n < 4 {
            return Err(format!("{n} vertices (at least 4 needed)"));
        }
        let faces = self.face_normals.len();
        let starts_ok = |starts: &[u32], count: usize, len: usize| {
            starts.len() == count + 1
                && starts.first() == Some(&0)
                && starts.last().map(|&s| s as usize) == Some(len)
                && starts.windows(2).all(|w| w[0] <= w[1])
        };
        if faces < 4 || self.face_offsets.len() != faces {
            return Err(format!(
                "{faces} face normals and {} face offsets",
                self.face_offsets.len()
            ));
        }
        if !starts_ok(&self.face_starts, faces, self.face_indices.len()) {
            return Err("face starts do not partition the face indices".into());
        }
        if !starts_ok(&self.adjacency_starts, n, self.adjacency.len()) {
            return Err("adjacency starts do not partition the adjacency list".into());
        }
        let in_range = |&i: &u32| (i as usize) < n;
        if !self.face_indices.iter().all(in_range)
            || !self.adjacency.iter().all(in_range)
            || !self.edges.iter().flatten().all(in_range)
        {
            return Err(format!("a vertex index is out of range ({n} vertices)"));
        }
        let finite = self
            .vertices
            .iter()
            .all(|p| p.iter().all(|x| x.is_finite()))
            && self
                .face_normals
                .iter()
                .all(|v| v.iter().all(|x| x.is_finite()))
            && self.face_offsets.iter().all(|x| x.is_finite())
            && self.bounding_radius.is_finite()
            && self.bounding_radius > 0.0;
        if !finite {
            return Err("a coordinate, normal, offset or the bounding radius is not finite".into());
        }
        Ok(())
    }

    /// Vertices in the principal frame (m).
    pub fn vertices(&self) -> &[Point] {
        &self.vertices
    }

    /// The vertices as columns for the vectorised support scan (the same points, in the same order).
    pub fn vertex_columns(&self) -> &VertexColumns {
        &self.columns
    }

    /// Number of faces.
    pub fn num_faces(&self) -> usize {
        self.face_normals.len()
    }

    /// Vertex indices of face `i`, counter-clockwise seen from outside.
    pub fn face_vertices(&self, i: usize) -> &[u32] {
        &self.face_indices[self.face_starts[i] as usize..self.face_starts[i + 1] as usize]
    }

    /// Outward unit normal of face `i` (principal frame).
    pub fn face_normal(&self, i: usize) -> &Vector {
        &self.face_normals[i]
    }

    /// Plane offset of face `i`: the face lies in n·x = offset and the whole solid in n·x ≤ offset (m). It is
    /// the maximum of n·v over all vertices, so the plane supports the solid exactly.
    pub fn face_offset(&self, i: usize) -> Real {
        self.face_offsets[i]
    }

    /// Unique edges as vertex pairs `[a, b]` with `a < b`, sorted.
    pub fn edges(&self) -> &[[u32; 2]] {
        &self.edges
    }

    /// Vertices sharing an edge with vertex `v`.
    pub fn neighbors(&self, v: u32) -> &[u32] {
        &self.adjacency[self.adjacency_starts[v as usize] as usize
            ..self.adjacency_starts[v as usize + 1] as usize]
    }

    /// Radius of the smallest origin-centred (centroid-centred) sphere containing the solid (m).
    pub fn bounding_radius(&self) -> Real {
        self.bounding_radius
    }

    /// The characteristic length all tolerances are scaled by: the diameter of the centroid-centred
    /// bounding sphere, `2 × bounding_radius()` (m).
    pub fn length_scale(&self) -> Real {
        2.0 * self.bounding_radius
    }

    /// Mass properties per unit density in the principal frame: centroid at the origin, diagonal inertia.
    pub fn mass_properties(&self) -> &MassProperties {
        &self.mass_properties
    }

    /// World-frame axis-aligned bounding box of the solid placed at `pose`.
    pub fn aabb(&self, pose: &Pose) -> Aabb {
        let first = pose * self.vertices[0];
        let mut aabb = Aabb {
            mins: first,
            maxs: first,
        };
        for v in &self.vertices[1..] {
            let p = pose * v;
            aabb.mins = aabb.mins.inf(&p);
            aabb.maxs = aabb.maxs.sup(&p);
        }
        aabb
    }

    /// Index of a vertex maximising `dir·v`, by a full scan.
    pub fn support_vertex_linear(&self, dir: &Vector) -> u32 {
        let mut best = 0;
        let mut best_value = dir.dot(&self.vertices[0].coords);
        for (i, v) in self.vertices.iter().enumerate().skip(1) {
            let value = dir.dot(&v.coords);
            if value > best_value {
                best = i;
                best_value = value;
            }
        }
        best as u32
    }

    /// Index of a vertex maximising `dir·v`, by hill-climbing over the vertex graph from `start` (clamped to
    /// a valid index). A move is taken only to a strictly better neighbour, so the walk cannot cycle on a
    /// plateau of equal values; it stops at a vertex with no better neighbour, which on a convex polytope
    /// is a global maximiser (the solid lies in the cone spanned by the edges leaving that vertex).
    pub fn support_vertex_hill_climb(&self, dir: &Vector, start: u32) -> u32 {
        let mut best = if (start as usize) < self.vertices.len() {
            start
        } else {
            0
        };
        let mut best_value = dir.dot(&self.vertices[best as usize].coords);
        loop {
            let current = best;
            for &n in self.neighbors(current) {
                let value = dir.dot(&self.vertices[n as usize].coords);
                if value > best_value {
                    best = n;
                    best_value = value;
                }
            }
            if best == current {
                return best;
            }
        }
    }
}

impl SupportMap for ConvexPolyhedron {
    fn local_support(&self, dir_local: &Vector, hint: &mut u32) -> Point {
        let i = if self.vertices.len() <= LINEAR_SCAN_MAX_VERTICES {
            // The vectorised scan picks the vertex `support_vertex_linear` picks (the first maximiser).
            self.columns.support_index(dir_local) as u32
        } else {
            self.support_vertex_hill_climb(dir_local, *hint)
        };
        *hint = i;
        self.vertices[i as usize]
    }
}

/// Checks that `faces` form a closed, consistently oriented 2-manifold surface of sphere topology over
/// `num_vertices` vertices, each used.
fn validate_topology(num_vertices: usize, faces: &[Vec<u32>]) -> Result<(), ShapeError> {
    if faces.len() < 4 {
        return Err(ShapeError::NotClosed {
            reason: format!("{} faces, a solid needs at least 4", faces.len()),
        });
    }
    let mut half_edges = crate::fixed_hash::FixedHashSet::default();
    let mut used = vec![false; num_vertices];
    for (f, face) in faces.iter().enumerate() {
        if face.len() < 3 {
            return Err(ShapeError::MalformedFace {
                face: f,
                reason: format!("{} vertices, at least 3 needed", face.len()),
            });
        }
        for (k, &v) in face.iter().enumerate() {
            if v as usize >= num_vertices {
                return Err(ShapeError::IndexOutOfRange {
                    face: f,
                    index: v,
                    num_vertices,
                });
            }
            if face[..k].contains(&v) {
                return Err(ShapeError::MalformedFace {
                    face: f,
                    reason: format!("vertex {v} appears twice"),
                });
            }
            used[v as usize] = true;
        }
        for k in 0..face.len() {
            let edge = (face[k], face[(k + 1) % face.len()]);
            if !half_edges.insert(edge) {
                return Err(ShapeError::NotClosed {
                    reason: format!(
                        "edge ({}, {}) is traversed twice in the same direction (inconsistent orientation or more than two faces on one edge)",
                        edge.0, edge.1
                    ),
                });
            }
        }
    }
    if let Some(index) = used.iter().position(|&u| !u) {
        return Err(ShapeError::UnusedVertex { index });
    }
    for &(a, b) in &half_edges {
        if !half_edges.contains(&(b, a)) {
            return Err(ShapeError::NotClosed {
                reason: format!("edge ({a}, {b}) has no opposite edge ({b}, {a})"),
            });
        }
    }
    let num_edges = half_edges.len() / 2;
    let euler = num_vertices as i64 - num_edges as i64 + faces.len() as i64;
    if euler != 2 {
        return Err(ShapeError::NotClosed {
            reason: format!("Euler characteristic V − E + F = {euler}, a convex solid has 2"),
        });
    }
    Ok(())
}

/// The principal frame of the solid with these `vertices` and `faces` (pose of the frame in the input
/// frame) and its mass properties in that frame; refused when its volume is not distinguishable from
/// round-off at size `extent`.
fn refined_principal_frame(
    vertices: &[Point],
    faces: &[Vec<u32>],
    extent: Real,
) -> Result<(Pose, MassProperties), ShapeError> {
    let mass = polyhedron_mass_properties(vertices, faces);
    // Volume distinguishable from the round-off of the tetrahedral sums (~ε·extent³).
    let volume_tol = VOLUME_ROUNDOFF_FACTOR * Real::EPSILON * extent.powi(3);
    if mass.volume.is_nan() || mass.volume <= volume_tol {
        return Err(ShapeError::ZeroVolume {
            volume: mass.volume,
            tolerance: volume_tol,
        });
    }
    // First estimate of the principal frame, then one refinement computed in that frame, where the
    // solid is centred and axis-aligned: it removes the residual centroid offset and off-diagonal
    // inertia of the first pass (measured: local centroid of a 1e-3-thin needle 5e-15 L instead of
    // 3e-13 L). Thin solids stay ill-conditioned at ε·L⁴/V whatever the frame.
    let first = Pose::from_parts(mass.centroid.coords.into(), mass.principal_axes);
    let local: Vec<Point> = vertices
        .iter()
        .map(|v| first.inverse_transform_point(v))
        .collect();
    let refined = polyhedron_mass_properties(&local, faces);
    let pose = first * Pose::from_parts(refined.centroid.coords.into(), refined.principal_axes);
    Ok((pose, refined))
}

/// The faces as index lists with offsets (CSR) and their outward planes.
struct FacePlanes {
    starts: Vec<u32>,
    indices: Vec<u32>,
    normals: Vec<Vector>,
    offsets: Vec<Real>,
}

impl FacePlanes {
    /// The planes of `faces` over the vertices `local`; a face of zero area is refused.
    fn of(local: &[Point], faces: &[Vec<u32>]) -> Result<Self, ShapeError> {
        let mut planes = FacePlanes {
            starts: Vec::with_capacity(faces.len() + 1),
            indices: Vec::new(),
            normals: Vec::with_capacity(faces.len()),
            offsets: Vec::with_capacity(faces.len()),
        };
        planes.starts.push(0);
        for (f, face) in faces.iter().enumerate() {
            let Some((normal, offset)) = supporting_plane(local, face) else {
                return Err(ShapeError::MalformedFace {
                    face: f,
                    reason: "zero area".to_string(),
                });
            };
            planes.indices.extend_from_slice(face);
            planes.starts.push(planes.indices.len() as u32);
            planes.normals.push(normal);
            planes.offsets.push(offset);
        }
        Ok(planes)
    }
}

/// The edges of `faces` as sorted vertex pairs [a, b], a < b, each once.
fn edges_of(faces: &[Vec<u32>]) -> Vec<[u32; 2]> {
    let mut edges: Vec<[u32; 2]> = Vec::new();
    for face in faces {
        for k in 0..face.len() {
            let (a, b) = (face[k], face[(k + 1) % face.len()]);
            if a < b {
                edges.push([a, b]);
            }
        }
    }
    edges.sort_unstable();
    edges.dedup();
    edges
}

/// The neighbours of each of `vertex_count` vertices along `edges`, as offsets and a flat list (CSR).
fn vertex_adjacency(vertex_count: usize, edges: &[[u32; 2]]) -> (Vec<u32>, Vec<u32>) {
    let mut degree = vec![0u32; vertex_count];
    for &[a, b] in edges {
        degree[a as usize] += 1;
        degree[b as usize] += 1;
    }
    let mut starts = Vec::with_capacity(vertex_count + 1);
    starts.push(0u32);
    for d in &degree {
        starts.push(starts.last().copied().unwrap_or(0) + d);
    }
    let mut fill: Vec<u32> = starts[..vertex_count].to_vec();
    let mut adjacency = vec![0u32; 2 * edges.len()];
    for &[a, b] in edges {
        adjacency[fill[a as usize] as usize] = b;
        fill[a as usize] += 1;
        adjacency[fill[b as usize] as usize] = a;
        fill[b as usize] += 1;
    }
    (starts, adjacency)
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    fn box_corners(a: Real, b: Real, c: Real) -> Vec<Point> {
        let mut corners = Vec::new();
        for &x in &[-a / 2.0, a / 2.0] {
            for &y in &[-b / 2.0, b / 2.0] {
                for &z in &[-c / 2.0, c / 2.0] {
                    corners.push(Point::new(x, y, z));
                }
            }
        }
        corners
    }

    fn random_rotation(rng: &mut ChaCha8Rng) -> Rotation {
        let axis = Vector::new(
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
        );
        Rotation::from_scaled_axis(axis.normalize() * rng.random_range(0.0..std::f64::consts::PI))
    }

    fn random_cloud(rng: &mut ChaCha8Rng, n: usize, semi_axes: Vector) -> Vec<Point> {
        (0..n)
            .map(|_| {
                let d = Vector::new(
                    rng.random_range(-1.0..1.0),
                    rng.random_range(-1.0..1.0),
                    rng.random_range(-1.0..1.0),
                )
                .normalize();
                Point::from(d.component_mul(&semi_axes))
            })
            .collect()
    }

    /// Checks the invariants every polyhedron must satisfy: Euler, closed faces, planar faces, convexity,
    /// outward normals, CSR adjacency symmetric, centroid at origin.
    fn check_invariants(p: &ConvexPolyhedron, context: &str) {
        let tol = 1e-9 * p.length_scale();
        assert_eq!(
            p.vertices().len() as i64 - p.edges().len() as i64 + p.num_faces() as i64,
            2,
            "{context}: Euler characteristic of V={} E={} F={}",
            p.vertices().len(),
            p.edges().len(),
            p.num_faces()
        );
        for f in 0..p.num_faces() {
            let n = p.face_normal(f);
            assert!(
                (n.norm() - 1.0).abs() < 1e-12,
                "{context}: face {f} normal norm {}",
                n.norm()
            );
            for &v in p.face_vertices(f) {
                let d = (n.dot(&p.vertices()[v as usize].coords) - p.face_offset(f)).abs();
                assert!(
                    d <= tol,
                    "{context}: face {f} vertex {v} off plane by {d:e} > {tol:e}"
                );
            }
            for (v, x) in p.vertices().iter().enumerate() {
                let d = n.dot(&x.coords) - p.face_offset(f);
                assert!(
                    d <= tol,
                    "{context}: vertex {v} outside face {f} by {d:e} > {tol:e}"
                );
            }
            assert!(
                p.face_offset(f) > 0.0,
                "{context}: face {f} offset {} must be positive (origin inside)",
                p.face_offset(f)
            );
        }
        for v in 0..p.vertices().len() as u32 {
            assert!(
                p.neighbors(v).len() >= 3,
                "{context}: vertex {v} has {} neighbours",
                p.neighbors(v).len()
            );
            for &n in p.neighbors(v) {
                assert!(
                    p.neighbors(n).contains(&v),
                    "{context}: adjacency not symmetric for {v}-{n}"
                );
            }
        }
        let mp = polyhedron_mass_properties(
            p.vertices(),
            &(0..p.num_faces())
                .map(|f| p.face_vertices(f).to_vec())
                .collect::<Vec<_>>(),
        );
        // The centroid of a thin solid is ill-conditioned: vertex round-off ε·L changes the tetrahedra's
        // volumes by a relative ε·L³/V, so the tolerance is 8 ε L · max(1, L³/V).
        let l = p.length_scale();
        let centroid_tol = 8.0 * Real::EPSILON * l * (l.powi(3) / mp.volume).max(1.0);
        assert!(
            mp.centroid.coords.norm() <= centroid_tol,
            "{context}: local centroid {:?} not at the origin (tolerance {centroid_tol:e})",
            mp.centroid
        );
    }

    #[test]
    fn box_has_six_faces_eight_vertices_twelve_edges() {
        let (p, _) = ConvexPolyhedron::from_points(&box_corners(1.0, 2.0, 3.0)).unwrap();
        assert_eq!(
            (p.vertices().len(), p.num_faces(), p.edges().len()),
            (8, 6, 12)
        );
        for f in 0..6 {
            assert_eq!(p.face_vertices(f).len(), 4, "face {f} of a box");
        }
        check_invariants(&p, "1x2x3 box");
    }

    #[test]
    fn interior_duplicate_edge_and_face_points_are_dropped() {
        let mut points = box_corners(2.0, 2.0, 2.0);
        points.extend_from_slice(&box_corners(2.0, 2.0, 2.0)); // duplicates
        points.push(Point::origin()); // interior
        points.push(Point::new(0.3, -0.2, 0.5)); // interior
        points.push(Point::new(1.0, 0.0, 0.0)); // face centre
        points.push(Point::new(1.0, 1.0, 0.0)); // edge midpoint
        points.push(Point::new(0.0, -1.0, 1.0)); // edge midpoint
        let (p, pose) = ConvexPolyhedron::from_points(&points).unwrap();
        assert_eq!(
            (p.vertices().len(), p.num_faces(), p.edges().len()),
            (8, 6, 12),
            "cube with extra points"
        );
        check_invariants(&p, "cube with extra points");
        for v in p.vertices() {
            let w = pose * v;
            let corner = w.coords.abs();
            assert!(
                (corner - Vector::repeat(1.0)).norm() < 1e-12,
                "vertex {w:?} is not a cube corner"
            );
        }
    }

    #[test]
    fn nearly_coplanar_box_faces_are_merged() {
        // Corners of a rotated, translated box: coordinates carry round-off of the rotation, and every face
        // also gets points jittered within 1e-13 of its plane.
        let mut rng = ChaCha8Rng::seed_from_u64(7);
        for case in 0..20 {
            let rotation = random_rotation(&mut rng);
            let shift = Vector::new(rng.random_range(-5.0..5.0), 3.0, -1.0);
            let mut local = box_corners(1.0, 1.5, 0.7);
            for _ in 0..30 {
                let axis = rng.random_range(0..3);
                let sign = if rng.random_bool(0.5) { 1.0 } else { -1.0 };
                let half = [0.5, 0.75, 0.35];
                let mut q = Point::new(
                    rng.random_range(-0.5..0.5),
                    rng.random_range(-0.75..0.75),
                    rng.random_range(-0.35..0.35),
                );
                q[axis] = sign * half[axis] + rng.random_range(-1e-13..0.0);
                local.push(q);
            }
            let points: Vec<Point> = local.iter().map(|q| rotation * q + shift).collect();
            let (p, _) = ConvexPolyhedron::from_points(&points).unwrap();
            assert_eq!(
                (p.vertices().len(), p.num_faces(), p.edges().len()),
                (8, 6, 12),
                "case {case}: jittered rotated box"
            );
            check_invariants(&p, &format!("jittered box case {case}"));
        }
    }

    #[test]
    fn pose_maps_local_vertices_to_input_points() {
        let mut rng = ChaCha8Rng::seed_from_u64(11);
        let points = random_cloud(&mut rng, 40, Vector::new(3.0, 1.0, 2.0));
        let shift = Vector::new(10.0, -4.0, 2.5);
        let points: Vec<Point> = points.iter().map(|q| q + shift).collect();
        let (p, pose) = ConvexPolyhedron::from_points(&points).unwrap();
        check_invariants(&p, "ellipsoid cloud");
        for v in p.vertices() {
            let w = pose * v;
            let nearest = points
                .iter()
                .map(|q| (q - w).norm())
                .fold(Real::INFINITY, Real::min);
            assert!(
                nearest < 1e-3 * p.length_scale(),
                "local vertex {v:?} maps to {w:?}, {nearest:e} from any input point"
            );
        }
        let m = p.mass_properties().principal_moments;
        assert!(
            m[0] <= m[1] && m[1] <= m[2],
            "principal moments not ascending: {m:?}"
        );
        let det = pose.rotation.to_rotation_matrix().matrix().determinant();
        assert!((det - 1.0).abs() < 1e-12, "pose rotation determinant {det}");
    }

    #[test]
    fn degenerate_point_clouds_are_typed_errors() {
        let p = |x, y, z| Point::new(x, y, z);
        let three = vec![p(0., 0., 0.), p(1., 0., 0.), p(0., 1., 0.)];
        assert!(matches!(
            ConvexPolyhedron::from_points(&three),
            Err(ShapeError::TooFewPoints { count: 3 })
        ));
        let coplanar = vec![
            p(0., 0., 0.),
            p(1., 0., 0.),
            p(0., 1., 0.),
            p(1., 1., 0.),
            p(0.5, 0.2, 1e-14),
        ];
        assert!(
            matches!(
                ConvexPolyhedron::from_points(&coplanar),
                Err(ShapeError::Coplanar { .. })
            ),
            "{:?}",
            ConvexPolyhedron::from_points(&coplanar).err()
        );
        let collinear = vec![p(0., 0., 0.), p(1., 1., 1.), p(2., 2., 2.), p(3., 3., 3.)];
        assert!(matches!(
            ConvexPolyhedron::from_points(&collinear),
            Err(ShapeError::Collinear { .. })
        ));
        // Too thin to resolve (below the 1e-5 flatness threshold): a slab and a needle.
        let slab = box_corners(1.0, 1.0, 1e-7);
        assert!(matches!(
            ConvexPolyhedron::from_points(&slab),
            Err(ShapeError::Coplanar { .. })
        ));
        let needle = box_corners(1.0, 1e-7, 1e-7);
        assert!(matches!(
            ConvexPolyhedron::from_points(&needle),
            Err(ShapeError::Collinear { .. })
        ));
        let same = vec![p(1., 2., 3.); 5];
        assert!(matches!(
            ConvexPolyhedron::from_points(&same),
            Err(ShapeError::Coincident { .. })
        ));
        let nan = vec![
            p(0., 0., 0.),
            p(1., 0., 0.),
            p(0., 1., 0.),
            p(0., 0., Real::NAN),
        ];
        assert!(matches!(
            ConvexPolyhedron::from_points(&nan),
            Err(ShapeError::NonFinite { index: 3, .. })
        ));
        let inf = vec![
            p(0., 0., 0.),
            p(Real::INFINITY, 0., 0.),
            p(0., 1., 0.),
            p(0., 0., 1.),
        ];
        assert!(matches!(
            ConvexPolyhedron::from_points(&inf),
            Err(ShapeError::NonFinite { index: 1, .. })
        ));
    }

    #[test]
    fn tiny_and_huge_scales_build_the_same_shape() {
        let mut rng = ChaCha8Rng::seed_from_u64(5);
        let cloud = random_cloud(&mut rng, 32, Vector::new(1.0, 2.0, 3.0));
        let (reference, _) = ConvexPolyhedron::from_points(&cloud).unwrap();
        for scale in [1e-3, 1e3] {
            let scaled: Vec<Point> = cloud.iter().map(|q| q * scale).collect();
            let (p, _) = ConvexPolyhedron::from_points(&scaled).unwrap();
            assert_eq!(
                (p.vertices().len(), p.num_faces(), p.edges().len()),
                (
                    reference.vertices().len(),
                    reference.num_faces(),
                    reference.edges().len()
                ),
                "scale {scale}"
            );
            let rel = (p.length_scale() / reference.length_scale() - scale).abs() / scale;
            assert!(
                rel < 1e-12,
                "length scale at scale {scale}: relative error {rel:e}"
            );
        }
    }

    fn cube_faces() -> (Vec<Point>, Vec<Vec<u32>>) {
        let v = box_corners(1.0, 1.0, 1.0); // index = 4*ix + 2*iy + iz
        let faces = vec![
            vec![0, 2, 6, 4], // z = -
            vec![1, 5, 7, 3], // z = +
            vec![0, 4, 5, 1], // y = -
            vec![2, 3, 7, 6], // y = +
            vec![0, 1, 3, 2], // x = -
            vec![4, 6, 7, 5], // x = +
        ];
        (v, faces)
    }

    #[test]
    fn from_vertices_faces_accepts_a_valid_cube() {
        let (v, f) = cube_faces();
        let (p, pose) = ConvexPolyhedron::from_vertices_faces(&v, &f).unwrap();
        assert_eq!(
            (p.vertices().len(), p.num_faces(), p.edges().len()),
            (8, 6, 12)
        );
        check_invariants(&p, "cube from faces");
        let volume = p.mass_properties().volume;
        assert!((volume - 1.0).abs() < 1e-14, "cube volume {volume}");
        assert!(
            pose.translation.vector.norm() < 1e-15,
            "cube centroid {:?}",
            pose.translation.vector
        );
    }

    #[test]
    fn from_vertices_faces_rejects_invalid_meshes() {
        let (v, f) = cube_faces();
        let inward: Vec<Vec<u32>> = f
            .iter()
            .map(|face| face.iter().rev().copied().collect())
            .collect();
        assert!(matches!(
            ConvexPolyhedron::from_vertices_faces(&v, &inward),
            Err(ShapeError::InwardOrientation { .. })
        ));
        let mut open = f.clone();
        open.pop();
        assert!(matches!(
            ConvexPolyhedron::from_vertices_faces(&v, &open),
            Err(ShapeError::NotClosed { .. })
        ));
        let mut flipped = f.clone();
        flipped[0].reverse();
        assert!(matches!(
            ConvexPolyhedron::from_vertices_faces(&v, &flipped),
            Err(ShapeError::NotClosed { .. })
        ));
        let mut out_of_range = f.clone();
        out_of_range[1][0] = 99;
        assert!(matches!(
            ConvexPolyhedron::from_vertices_faces(&v, &out_of_range),
            Err(ShapeError::IndexOutOfRange { index: 99, .. })
        ));
        let mut nonplanar = v.clone();
        nonplanar[7].x += 0.1;
        nonplanar[7].y += 0.1;
        nonplanar[7].z += 0.1;
        assert!(matches!(
            ConvexPolyhedron::from_vertices_faces(&nonplanar, &f),
            Err(ShapeError::NonPlanarFace { .. })
        ));
        // A dented cube: vertex 7 pushed inward along the diagonal, with the three faces around it split
        // into triangles so every face stays planar; the solid is then non-convex.
        let mut dented = v.clone();
        dented[7] = Point::new(0.3, 0.3, 0.3);
        let dented_faces = vec![
            vec![0, 2, 6, 4],
            vec![0, 4, 5, 1],
            vec![0, 1, 3, 2],
            vec![1, 5, 7],
            vec![1, 7, 3],
            vec![2, 3, 7],
            vec![2, 7, 6],
            vec![4, 6, 7],
            vec![4, 7, 5],
        ];
        assert!(matches!(
            ConvexPolyhedron::from_vertices_faces(&dented, &dented_faces),
            Err(ShapeError::NotConvex { .. })
        ));
        let mut extra = v.clone();
        extra.push(Point::new(5.0, 5.0, 5.0));
        assert!(matches!(
            ConvexPolyhedron::from_vertices_faces(&extra, &f),
            Err(ShapeError::UnusedVertex { index: 8 })
        ));
    }

    #[test]
    fn hill_climb_support_equals_linear_scan() {
        let mut rng = ChaCha8Rng::seed_from_u64(3);
        for case in 0..20 {
            let n = [8, 16, 32, 64, 200][case % 5];
            let cloud = random_cloud(&mut rng, n, Vector::new(3.0, 1.0, 1.5));
            let (p, _) = ConvexPolyhedron::from_points(&cloud).unwrap();
            let mut hint = rng.random_range(0..10_000u32); // possibly out of range: must be clamped
            for _ in 0..200 {
                let dir = Vector::new(
                    rng.random_range(-1.0..1.0),
                    rng.random_range(-1.0..1.0),
                    rng.random_range(-1.0..1.0),
                );
                let linear = p.support_vertex_linear(&dir);
                let climbed = p.support_vertex_hill_climb(&dir, hint);
                let (lv, cv) = (
                    dir.dot(&p.vertices()[linear as usize].coords),
                    dir.dot(&p.vertices()[climbed as usize].coords),
                );
                let tol = 1e-14 * p.length_scale() * dir.norm();
                assert!(
                    lv - cv <= tol,
                    "case {case}, n {n}, dir {dir:?}: hill climb {cv} vs scan {lv} (tol {tol:e})"
                );
                let point = p.local_support(&dir, &mut hint);
                assert!(
                    lv - dir.dot(&point.coords) <= tol,
                    "local_support not maximal for {dir:?}"
                );
                assert_eq!(
                    point,
                    p.vertices()[hint as usize],
                    "hint must hold the returned vertex"
                );
            }
        }
    }

    #[test]
    fn hill_climb_terminates_on_plateaus() {
        // Axis directions on a cube: whole faces are plateaus of equal support value.
        let (p, _) = ConvexPolyhedron::from_points(&box_corners(1.0, 1.0, 1.0)).unwrap();
        let (p_faces, _) =
            ConvexPolyhedron::from_vertices_faces(&cube_faces().0, &cube_faces().1).unwrap();
        for shape in [&p, &p_faces] {
            for f in 0..shape.num_faces() {
                let dir = *shape.face_normal(f);
                for start in 0..shape.vertices().len() as u32 + 2 {
                    let i = shape.support_vertex_hill_climb(&dir, start);
                    let value = dir.dot(&shape.vertices()[i as usize].coords);
                    let best = dir
                        .dot(&shape.vertices()[shape.support_vertex_linear(&dir) as usize].coords);
                    assert!(
                        best - value <= 1e-15,
                        "face {f} start {start}: {value} < {best}"
                    );
                }
            }
        }
    }

    #[test]
    fn aabb_contains_all_world_vertices() {
        let mut rng = ChaCha8Rng::seed_from_u64(9);
        let cloud = random_cloud(&mut rng, 24, Vector::new(1.0, 2.0, 0.5));
        let (p, pose) = ConvexPolyhedron::from_points(&cloud).unwrap();
        let aabb = p.aabb(&pose);
        for q in &cloud {
            for k in 0..3 {
                assert!(
                    q[k] >= aabb.mins[k] - 1e-12 && q[k] <= aabb.maxs[k] + 1e-12,
                    "point {q:?} outside aabb {aabb:?}"
                );
            }
        }
    }

    #[test]
    fn lattices_and_near_degenerate_clouds_build_valid_polyhedra() {
        let mut rng = ChaCha8Rng::seed_from_u64(17);
        // A 5×5×5 lattice: many coplanar and collinear points; the hull is the cube.
        let mut lattice = Vec::new();
        for i in 0..5 {
            for j in 0..5 {
                for k in 0..5 {
                    lattice.push(Point::new(i as Real, j as Real, k as Real) * 0.25);
                }
            }
        }
        let (p, _) = ConvexPolyhedron::from_points(&lattice).unwrap();
        assert_eq!(
            (p.vertices().len(), p.num_faces(), p.edges().len()),
            (8, 6, 12),
            "5x5x5 lattice"
        );
        check_invariants(&p, "lattice");

        // Near-duplicates: every point of a 32-point cloud repeated with 1e-13 relative jitter.
        let base = random_cloud(&mut rng, 32, Vector::new(1.0, 1.0, 1.0));
        let mut jittered = base.clone();
        for q in &base {
            let j = Vector::new(
                rng.random_range(-1.0..1.0),
                rng.random_range(-1.0..1.0),
                rng.random_range(-1.0..1.0),
            );
            jittered.push(q + j * 1e-13);
        }
        let (p, _) = ConvexPolyhedron::from_points(&jittered).unwrap();
        check_invariants(&p, "near-duplicate cloud");

        // Thin slabs and needles (down to 2e-5 of the extent, above the 1e-5 flatness threshold): thin but
        // genuine solids, with extra points on a large face. Thinner ones are typed errors.
        for (name, thin) in [
            ("slab", 1e-3),
            ("slab", 2e-5),
            ("needle", 1e-3),
            ("needle", 2e-5),
        ] {
            {
                let dims = if name == "slab" {
                    [1.0, 1.0, thin]
                } else {
                    [1.0, thin, thin]
                };
                let mut cloud = box_corners(dims[0], dims[1], dims[2]);
                for _ in 0..20 {
                    let q = Point::new(
                        rng.random_range(-0.5..0.5) * dims[0],
                        rng.random_range(-0.5..0.5) * dims[1],
                        0.5 * dims[2],
                    );
                    cloud.push(q);
                }
                let rotation = random_rotation(&mut rng);
                let cloud: Vec<Point> = cloud.iter().map(|q| rotation * q).collect();
                let built = ConvexPolyhedron::from_points(&cloud);
                let Ok((p, _)) = built else {
                    panic!("{name} of thickness {thin}: {:?}", built.err());
                };
                assert_eq!(
                    (p.vertices().len(), p.num_faces()),
                    (8, 6),
                    "{name} of thickness {thin}"
                );
                check_invariants(&p, &format!("{name} of thickness {thin}"));
            }
        }

        // Many points on a sphere.
        for n in [500, 2000] {
            let cloud = random_cloud(&mut rng, n, Vector::new(1.0, 1.0, 1.0));
            let (p, _) = ConvexPolyhedron::from_points(&cloud).unwrap();
            check_invariants(&p, &format!("{n} points on a sphere"));
        }
    }

    /// The vertex columns are derived data: not in the encoded form (the checkpoint's postcard bytes are
    /// those of the fields without them) and rebuilt on decoding, equal to the built shape's.
    #[test]
    fn encoding_omits_and_decoding_rebuilds_the_vertex_columns() {
        let mut rng = ChaCha8Rng::seed_from_u64(5);
        let cloud = random_cloud(&mut rng, 30, Vector::new(1.0, 0.7, 0.4));
        let (p, _) = ConvexPolyhedron::from_points(&cloud).expect("hull");
        let bytes = postcard::to_stdvec(&p).expect("encode");
        #[derive(serde::Serialize)]
        struct Fields<'a> {
            vertices: &'a Vec<Point>,
            face_starts: &'a Vec<u32>,
            face_indices: &'a Vec<u32>,
            face_normals: &'a Vec<Vector>,
            face_offsets: &'a Vec<Real>,
            edges: &'a Vec<[u32; 2]>,
            adjacency_starts: &'a Vec<u32>,
            adjacency: &'a Vec<u32>,
            bounding_radius: Real,
            mass_properties: &'a MassProperties,
        }
        let fields = Fields {
            vertices: &p.vertices,
            face_starts: &p.face_starts,
            face_indices: &p.face_indices,
            face_normals: &p.face_normals,
            face_offsets: &p.face_offsets,
            edges: &p.edges,
            adjacency_starts: &p.adjacency_starts,
            adjacency: &p.adjacency,
            bounding_radius: p.bounding_radius,
            mass_properties: &p.mass_properties,
        };
        assert_eq!(
            bytes,
            postcard::to_stdvec(&fields).expect("encode fields"),
            "the encoding carries more than the serialised fields"
        );
        let back: ConvexPolyhedron = postcard::from_bytes(&bytes).expect("decode");
        assert_eq!(back.vertex_columns(), p.vertex_columns());
        assert_eq!(back.vertex_columns().len(), p.vertices().len());
    }

    #[test]
    fn random_rigid_motion_preserves_the_built_polyhedron() {
        let mut rng = ChaCha8Rng::seed_from_u64(23);
        let cloud = random_cloud(&mut rng, 30, Vector::new(2.0, 1.0, 0.5));
        let (reference, _) = ConvexPolyhedron::from_points(&cloud).unwrap();
        let r = reference.mass_properties();
        for case in 0..10 {
            let rotation = random_rotation(&mut rng);
            let shift = Vector::new(
                rng.random_range(-50.0..50.0),
                rng.random_range(-50.0..50.0),
                rng.random_range(-50.0..50.0),
            );
            let moved: Vec<Point> = cloud.iter().map(|q| rotation * q + shift).collect();
            let (p, pose) = ConvexPolyhedron::from_points(&moved).unwrap();
            assert_eq!(
                (p.vertices().len(), p.num_faces(), p.edges().len()),
                (
                    reference.vertices().len(),
                    reference.num_faces(),
                    reference.edges().len()
                ),
                "case {case}: topology after rigid motion"
            );
            let m = p.mass_properties();
            let tol = 1e-10;
            assert!(
                (m.volume - r.volume).abs() <= tol * r.volume,
                "case {case}: volume {} vs {}",
                m.volume,
                r.volume
            );
            for k in 0..3 {
                let (got, want) = (m.principal_moments[k], r.principal_moments[k]);
                assert!(
                    (got - want).abs() <= tol * r.principal_moments[2],
                    "case {case}: moment {k} {got} vs {want} (tol {tol:e})"
                );
            }
            for v in p.vertices() {
                let w = pose * v;
                let nearest = moved
                    .iter()
                    .map(|q| (q - w).norm())
                    .fold(Real::INFINITY, Real::min);
                assert!(
                    nearest <= 1e-12 * 100.0,
                    "case {case}: vertex maps {nearest:e} away from the input"
                );
            }
        }
    }

    #[test]
    fn small_boxes_far_from_the_origin_keep_their_faces() {
        // Particle size 1e-3 placed 1e3 away: coordinates carry round-off ~1e-13, a 1e-10 fraction of the
        // size, which the hull tolerance must absorb (it includes the coordinates' own round-off).
        let mut rng = ChaCha8Rng::seed_from_u64(31);
        for case in 0..50 {
            let rotation = random_rotation(&mut rng);
            let shift = Vector::new(
                rng.random_range(-1e3..1e3),
                rng.random_range(-1e3..1e3),
                1e3,
            );
            let points: Vec<Point> = box_corners(1e-3, 2e-3, 1.5e-3)
                .iter()
                .map(|q| rotation * q + shift)
                .collect();
            let built = ConvexPolyhedron::from_points(&points);
            let Ok((p, pose)) = built else {
                panic!("case {case}: {:?}", built.err());
            };
            assert_eq!(
                (p.vertices().len(), p.num_faces(), p.edges().len()),
                (8, 6, 12),
                "case {case}: box of size 1e-3 at {shift:?}"
            );
            let volume = p.mass_properties().volume;
            let expected = 1e-3 * 2e-3 * 1.5e-3;
            assert!(
                (volume - expected).abs() <= 1e-6 * expected,
                "case {case}: volume {volume:e}, expected {expected:e}"
            );
            let centre_error = (pose.translation.vector - shift).norm();
            assert!(
                centre_error <= 1e-12,
                "case {case}: centroid off by {centre_error:e}"
            );
        }
    }

    #[test]
    fn from_vertices_faces_pose_maps_back_to_a_moved_cuboid() {
        let mut rng = ChaCha8Rng::seed_from_u64(41);
        let (cube, faces) = cube_faces();
        let stretch = Vector::new(0.5, 2.0, 1.25);
        let local: Vec<Point> = cube
            .iter()
            .map(|q| Point::from(q.coords.component_mul(&stretch)))
            .collect();
        for case in 0..10 {
            let rotation = random_rotation(&mut rng);
            let shift = Vector::new(
                rng.random_range(-10.0..10.0),
                rng.random_range(-10.0..10.0),
                4.0,
            );
            let moved: Vec<Point> = local.iter().map(|q| rotation * q + shift).collect();
            let (p, pose) = ConvexPolyhedron::from_vertices_faces(&moved, &faces).unwrap();
            check_invariants(&p, &format!("moved cuboid case {case}"));
            for (v, q) in p.vertices().iter().zip(&moved) {
                let err = (pose * v - q).norm();
                assert!(
                    err <= 1e-13,
                    "case {case}: vertex maps back with error {err:e}"
                );
            }
            // Principal moments ascending: smallest about the longest side (y, 2.0).
            let (a, b, c) = (stretch.x, stretch.y, stretch.z);
            let volume = a * b * c;
            let mut expected = [
                volume * (b * b + c * c) / 12.0,
                volume * (a * a + c * c) / 12.0,
                volume * (a * a + b * b) / 12.0,
            ];
            expected.sort_by(Real::total_cmp);
            let m = p.mass_properties().principal_moments;
            for k in 0..3 {
                assert!(
                    (m[k] - expected[k]).abs() <= 1e-12 * expected[2],
                    "case {case}: moment {k} {} vs {} (tol {:e})",
                    m[k],
                    expected[k],
                    1e-12 * expected[2]
                );
            }
        }
    }
}
