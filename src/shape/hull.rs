//! Convex hull of a point cloud as a polygonal mesh: coplanar hull triangles merged into polygonal faces.
//!
//! # Library
//! The triangulated hull comes from `parry3d-f64` (`transformation::try_convex_hull`, an incremental
//! quickhull in f64, maintained by Dimforge, and already the peer library of our validation suite). The
//! `qhull` crate (bindings to Qhull) was evaluated first and rejected: its `qhull-sys` build script runs
//! bindgen, which needs libclang at build time; libclang is not part of a fresh machine or of CI here, so
//! every build would depend on an extra system install. Qhull's own facet merging would also still need our
//! polygon extraction below.
//!
//! # Pipeline
//! 1. Reject unusable input with a typed error: fewer than 4 points, NaN/inf, all points coincident,
//!    collinear or coplanar (largest distance from a line / plane at most `FLAT_REL_TOL × extent`, where
//!    the extent is the diagonal of the cloud's axis-aligned box).
//! 2. Triangulated hull from parry of the affinely whitened cloud (see `whiten`; guarded: a panic inside
//!    the library becomes [`ShapeError::HullFailed`]).
//! 3. Orient every triangle outward (against a point strictly inside the initial tetrahedron).
//! 4. Merge coplanar triangles into faces by region growing: seeds taken by decreasing area, a neighbour
//!    joins when all its vertices lie within the tolerance of the seed's plane. The face's boundary loop is
//!    traced from the region's boundary half-edges, so it keeps the triangles' counter-clockwise order.
//! 5. Drop vertices that lie in fewer than three faces (points on an edge or inside a face).
//! 6. Verify: every input point lies inside every face's supporting plane within the tolerance; any
//!    violation is reported as [`ShapeError::HullFailed`] rather than returned as a wrong hull.
//!
//! Duplicate and interior points never become vertices.

use std::collections::HashMap;

use crate::math::{from_parry_vector, to_parry_vector, Point, Real, Vector};

use super::error::ShapeError;
use super::polygon::supporting_plane;

/// Relative tolerance of hull construction (coplanarity, flatness, verification), multiplied by the cloud's
/// extent. Round-off in coordinates of size L is ~1e-16 L; 1e-10 leaves six orders of magnitude for rounding
/// accumulated by the caller's transformations, while any real feature of a particle is far larger.
pub(crate) const HULL_REL_TOL: Real = 1e-10;

/// Relative thickness below which a cloud is rejected as collinear or coplanar. A face of width w and
/// length ℓ has its normal resolved by f64 only to ~ε ℓ/w, so its far corners sit ~ε ℓ²/w off the computed
/// plane; keeping that below `HULL_REL_TOL × extent` with a margin of ten requires w ≳ 1e-5 ℓ. Particles
/// with aspect ratios beyond 1e5 are outside any DEM use, so such clouds are reported as degenerate.
pub(crate) const FLAT_REL_TOL: Real = 1e-5;

/// A closed convex polygonal mesh: faces are vertex loops, counter-clockwise seen from outside.
#[derive(Clone, Debug)]
pub(crate) struct PolygonMesh {
    pub vertices: Vec<Point>,
    pub faces: Vec<Vec<u32>>,
}

/// Checks the count and finiteness of `points` and returns their extent (diagonal of the bounding box).
pub(crate) fn validate_points(points: &[Point]) -> Result<Real, ShapeError> {
    if points.len() < 4 {
        return Err(ShapeError::TooFewPoints {
            count: points.len(),
        });
    }
    for (index, p) in points.iter().enumerate() {
        if !(p.x.is_finite() && p.y.is_finite() && p.z.is_finite()) {
            return Err(ShapeError::NonFinite {
                index,
                x: p.x,
                y: p.y,
                z: p.z,
            });
        }
    }
    let mut mins = points[0];
    let mut maxs = points[0];
    for p in points {
        mins = mins.inf(p);
        maxs = maxs.sup(p);
    }
    let extent = (maxs - mins).norm();
    if !extent.is_finite() {
        return Err(ShapeError::HullFailed {
            reason: format!("extent of the cloud overflows ({extent})"),
        });
    }
    Ok(extent)
}

/// Finds four points spanning a tetrahedron of non-negligible thickness, or reports the cloud as coincident,
/// collinear or coplanar. Returns the indices of the four points.
fn spanning_tetrahedron(
    points: &[Point],
    extent: Real,
    tol: Real,
) -> Result<[usize; 4], ShapeError> {
    if extent <= 0.0 {
        return Err(ShapeError::Coincident { extent });
    }
    // The two farthest-apart points among the six axis extremes: at least extent/√3 apart.
    let mut extremes = [0usize; 6];
    for (i, p) in points.iter().enumerate() {
        for axis in 0..3 {
            if p[axis] < points[extremes[2 * axis]][axis] {
                extremes[2 * axis] = i;
            }
            if p[axis] > points[extremes[2 * axis + 1]][axis] {
                extremes[2 * axis + 1] = i;
            }
        }
    }
    let (mut ia, mut ib, mut best) = (0, 0, -1.0);
    for &i in &extremes {
        for &j in &extremes {
            let d = (points[i] - points[j]).norm_squared();
            if d > best {
                (ia, ib, best) = (i, j, d);
            }
        }
    }
    let a = points[ia];
    let axis = (points[ib] - a).normalize();
    let (ic, line_distance) = farthest(points, |p| (p - a).cross(&axis).norm());
    if line_distance <= tol {
        return Err(ShapeError::Collinear {
            distance: line_distance,
            tolerance: tol,
        });
    }
    let normal = axis.cross(&(points[ic] - a)).normalize();
    let (id, plane_distance) = farthest(points, |p| (p - a).dot(&normal).abs());
    if plane_distance <= tol {
        return Err(ShapeError::Coplanar {
            distance: plane_distance,
            tolerance: tol,
        });
    }
    Ok([ia, ib, ic, id])
}

fn farthest(points: &[Point], distance: impl Fn(&Point) -> Real) -> (usize, Real) {
    let mut best = (0, Real::NEG_INFINITY);
    for (i, p) in points.iter().enumerate() {
        let d = distance(p);
        if d > best.1 {
            best = (i, d);
        }
    }
    best
}

/// The convex hull of `points` with coplanar triangles merged into polygonal faces (see the module docs).
pub(crate) fn convex_hull(points: &[Point]) -> Result<PolygonMesh, ShapeError> {
    let extent = validate_points(points)?;
    let tol = HULL_REL_TOL * extent;
    let tetra = spanning_tetrahedron(points, extent, FLAT_REL_TOL * extent)?;
    let interior = Point::from(
        (points[tetra[0]].coords
            + points[tetra[1]].coords
            + points[tetra[2]].coords
            + points[tetra[3]].coords)
            / 4.0,
    );

    let whitened = whiten(points);
    let input: Vec<_> = whitened.iter().map(to_parry_vector).collect();
    let hull = std::panic::catch_unwind(|| parry3d_f64::transformation::try_convex_hull(&input));
    let (hull_vertices, triangles) = match hull {
        Ok(Ok(hull)) => hull,
        Ok(Err(e)) => {
            return Err(ShapeError::HullFailed {
                reason: format!("parry3d: {e}"),
            })
        }
        Err(_) => {
            return Err(ShapeError::HullFailed {
                reason: "parry3d panicked".to_string(),
            })
        }
    };
    // parry returns copies of (some of) its input points: find each one's original point, bit for bit.
    let key = |p: &Point| [p.x.to_bits(), p.y.to_bits(), p.z.to_bits()];
    let mut original: HashMap<[u64; 3], usize> = HashMap::with_capacity(whitened.len());
    for (i, w) in whitened.iter().enumerate() {
        original.entry(key(w)).or_insert(i);
    }
    let mut vertices = Vec::with_capacity(hull_vertices.len());
    for v in hull_vertices {
        let Some(&i) = original.get(&key(&from_parry_vector(v))) else {
            return Err(ShapeError::HullFailed {
                reason: "parry3d returned a vertex that is not an input point".to_string(),
            });
        };
        vertices.push(points[i]);
    }
    if triangles.len() < 4 || vertices.len() < 4 {
        return Err(ShapeError::HullFailed {
            reason: format!(
                "{} triangles on {} vertices",
                triangles.len(),
                vertices.len()
            ),
        });
    }

    let triangles = orient_outward(&vertices, triangles, &interior)?;
    let faces = merge_coplanar(&vertices, &triangles, tol)?;
    let mesh = drop_non_corner_vertices(vertices, faces)?;
    verify_contains(&mesh, points, tol)?;
    Ok(mesh)
}

/// Maps the cloud by the affine whitening transform (centre at the mean, principal axes of the point
/// covariance scaled to unit variance). The hull's combinatorics are affine-invariant, and the hull library
/// judges degeneracy with absolute epsilons on a unit-box-normalised cloud, so thin or elongated clouds
/// (slabs, needles) are handed to it as well-conditioned, roughly round ones. Vertex indices are unchanged,
/// and the hull's geometry is always taken from the original points.
fn whiten(points: &[Point]) -> Vec<Point> {
    let n = points.len() as Real;
    let mean = points.iter().fold(Vector::zeros(), |acc, p| acc + p.coords) / n;
    let covariance = points.iter().fold(crate::math::Matrix::zeros(), |acc, p| {
        let d = p.coords - mean;
        acc + d * d.transpose()
    }) / n;
    let eigen = nalgebra::SymmetricEigen::new(covariance);
    let scale = eigen
        .eigenvalues
        .map(|l| if l > 0.0 { 1.0 / l.sqrt() } else { 1.0 });
    let to_principal = eigen.eigenvectors.transpose();
    points
        .iter()
        .map(|p| Point::from((to_principal * (p.coords - mean)).component_mul(&scale)))
        .collect()
}

fn orient_outward(
    vertices: &[Point],
    triangles: Vec<[u32; 3]>,
    interior: &Point,
) -> Result<Vec<[u32; 3]>, ShapeError> {
    let mut oriented = Vec::with_capacity(triangles.len());
    for t in triangles {
        if t.iter().any(|&i| i as usize >= vertices.len()) {
            return Err(ShapeError::HullFailed {
                reason: format!("triangle {t:?} has an invalid index"),
            });
        }
        let [a, b, c] = t.map(|i| vertices[i as usize]);
        let normal = (b - a).cross(&(c - a));
        // Which side the interior point is on is decided by the triangle's own (possibly tiny) normal; for a
        // zero-area sliver the orientation does not matter for the merge below.
        if normal.dot(&(a - interior)) >= 0.0 {
            oriented.push(t);
        } else {
            oriented.push([t[0], t[2], t[1]]);
        }
    }
    Ok(oriented)
}

/// Region-growing merge of coplanar triangles; returns each face as a counter-clockwise vertex loop.
fn merge_coplanar(
    vertices: &[Point],
    triangles: &[[u32; 3]],
    tol: Real,
) -> Result<Vec<Vec<u32>>, ShapeError> {
    // Half-edge (a, b) → triangle owning it.
    let mut owner: HashMap<(u32, u32), usize> = HashMap::with_capacity(3 * triangles.len());
    for (t, tri) in triangles.iter().enumerate() {
        for k in 0..3 {
            if owner.insert((tri[k], tri[(k + 1) % 3]), t).is_some() {
                return Err(ShapeError::HullFailed {
                    reason: format!("half-edge ({}, {}) used twice", tri[k], tri[(k + 1) % 3]),
                });
            }
        }
    }
    let twin = |a: u32, b: u32| owner.get(&(b, a)).copied();

    let area2 = |t: &[u32; 3]| {
        let [a, b, c] = t.map(|i| vertices[i as usize]);
        (b - a).cross(&(c - a)).norm()
    };
    let mut order: Vec<usize> = (0..triangles.len()).collect();
    order.sort_by(|&i, &j| area2(&triangles[j]).total_cmp(&area2(&triangles[i])));

    let mut region_of = vec![usize::MAX; triangles.len()];
    let mut faces = Vec::new();
    let mut stack = Vec::new();
    let mut members = Vec::new();
    for &seed in &order {
        if region_of[seed] != usize::MAX {
            continue;
        }
        let region = faces.len();
        let [a, b, c] = triangles[seed].map(|i| vertices[i as usize]);
        let normal = (b - a).cross(&(c - a));
        let norm = normal.norm();
        if !norm.is_finite() || norm <= 0.0 {
            return Err(ShapeError::HullFailed {
                reason: "a zero-area triangle is not adjacent to any face".to_string(),
            });
        }
        let normal: Vector = normal / norm;
        let offset = normal.dot(&a.coords);
        let on_plane = |t: &[u32; 3]| {
            t.iter()
                .all(|&i| (normal.dot(&vertices[i as usize].coords) - offset).abs() <= tol)
        };

        members.clear();
        stack.clear();
        stack.push(seed);
        region_of[seed] = region;
        while let Some(t) = stack.pop() {
            members.push(t);
            let tri = triangles[t];
            for k in 0..3 {
                let Some(n) = twin(tri[k], tri[(k + 1) % 3]) else {
                    return Err(ShapeError::HullFailed {
                        reason: format!("hull edge ({}, {}) has no twin", tri[k], tri[(k + 1) % 3]),
                    });
                };
                if region_of[n] == usize::MAX && on_plane(&triangles[n]) {
                    region_of[n] = region;
                    stack.push(n);
                }
            }
        }
        faces.push(boundary_loop(
            triangles, &members, &region_of, region, &twin,
        )?);
    }
    Ok(faces)
}

/// Traces the boundary of a merged region: the half-edges whose twin lies outside the region, chained.
fn boundary_loop(
    triangles: &[[u32; 3]],
    members: &[usize],
    region_of: &[usize],
    region: usize,
    twin: &impl Fn(u32, u32) -> Option<usize>,
) -> Result<Vec<u32>, ShapeError> {
    let mut next: HashMap<u32, u32> = HashMap::new();
    for &t in members {
        let tri = triangles[t];
        for k in 0..3 {
            let (a, b) = (tri[k], tri[(k + 1) % 3]);
            let outside = twin(a, b).is_none_or(|n| region_of[n] != region);
            if outside && next.insert(a, b).is_some() {
                return Err(ShapeError::HullFailed {
                    reason: format!("merged face boundary is not a simple loop at vertex {a}"),
                });
            }
        }
    }
    let Some(&start) = next.keys().min() else {
        return Err(ShapeError::HullFailed {
            reason: "merged face has no boundary".to_string(),
        });
    };
    let mut loop_ = vec![start];
    let mut current = next[&start];
    while current != start {
        if loop_.len() > next.len() {
            return Err(ShapeError::HullFailed {
                reason: "merged face boundary does not close".to_string(),
            });
        }
        loop_.push(current);
        current = next[&current];
    }
    if loop_.len() != next.len() {
        return Err(ShapeError::HullFailed {
            reason: "merged face boundary has several loops (the face has a hole)".to_string(),
        });
    }
    Ok(loop_)
}

/// Removes from the face loops every vertex that lies in fewer than three faces (it sits on an edge or
/// inside a face, so it is not a corner of the solid), then renumbers the vertices that remain.
fn drop_non_corner_vertices(
    vertices: Vec<Point>,
    faces: Vec<Vec<u32>>,
) -> Result<PolygonMesh, ShapeError> {
    let mut face_count = vec![0u32; vertices.len()];
    for face in &faces {
        for &v in face {
            face_count[v as usize] += 1;
        }
    }
    let mut new_index = vec![u32::MAX; vertices.len()];
    let mut kept = Vec::new();
    for (v, &count) in face_count.iter().enumerate() {
        if count >= 3 {
            new_index[v] = kept.len() as u32;
            kept.push(vertices[v]);
        }
    }
    let mut new_faces = Vec::with_capacity(faces.len());
    for face in faces {
        let loop_: Vec<u32> = face
            .iter()
            .filter(|&&v| face_count[v as usize] >= 3)
            .map(|&v| new_index[v as usize])
            .collect();
        if loop_.len() < 3 {
            return Err(ShapeError::HullFailed {
                reason: format!("a merged face kept only {} corners", loop_.len()),
            });
        }
        new_faces.push(loop_);
    }
    Ok(PolygonMesh {
        vertices: kept,
        faces: new_faces,
    })
}

/// Every input point must lie inside every face's supporting plane (within `tol`), and every face must be
/// planar within `tol`.
fn verify_contains(mesh: &PolygonMesh, points: &[Point], tol: Real) -> Result<(), ShapeError> {
    for (f, face) in mesh.faces.iter().enumerate() {
        let Some((normal, offset)) = supporting_plane(&mesh.vertices, face) else {
            return Err(ShapeError::HullFailed {
                reason: format!("face {f} has zero area"),
            });
        };
        for &v in face {
            let depth = offset - normal.dot(&mesh.vertices[v as usize].coords);
            if depth > tol {
                return Err(ShapeError::HullFailed {
                    reason: format!("face {f} is not planar: vertex {v} is {depth:e} below it (tolerance {tol:e})"),
                });
            }
        }
        for (i, p) in points.iter().enumerate() {
            let excess = normal.dot(&p.coords) - offset;
            if excess > tol {
                return Err(ShapeError::HullFailed {
                    reason: format!(
                        "input point {i} lies {excess:e} outside face {f} (tolerance {tol:e})"
                    ),
                });
            }
        }
    }
    Ok(())
}
