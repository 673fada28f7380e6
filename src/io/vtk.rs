//! VTK output for ParaView: one XML unstructured-grid file (`.vtu`) per frame and per kind of object, and
//! one `.pvd` collection per kind that lists the frames with their times.
//!
//! # Series
//! - `polyhedra.pvd` → `vtk/polyhedra_<step>.vtu`: every polyhedral body as its faces, one `VTK_POLYGON`
//!   cell per face, vertices in world coordinates (each body's vertices written once and shared by its
//!   faces, faces counter-clockwise seen from outside). Cell data (the body's values on each of its faces):
//!   `body` (index), `velocity` (m/s), `angular_velocity` (rad/s), `contact_force` and `contact_torque`
//!   (N, N·m: the resultant of the body's contacts from the last evaluation, gravity not included). Point
//!   data: `body`, and `point_velocity`, the velocity of the material point at the vertex, v + ω × r (m/s).
//! - `spheres.pvd` → `vtk/spheres_<step>.vtu`: every spherical body as its centre, one `VTK_VERTEX` cell
//!   each, with point data `body`, `radius`, `diameter` (m), `velocity`, `angular_velocity`,
//!   `contact_force`, `contact_torque`. This is the usual DEM convention (LIGGGHTS and YADE export spheres the
//!   same way): in ParaView apply *Glyph* with glyph type *Sphere*, *Scale Array* `diameter`, scale factor 1
//!   (the sphere glyph has radius 0.5), which draws exact spheres at any zoom instead of a fixed tessellation.
//! - `walls.pvd` → `vtk/walls_<step>.vtu`: every wall as one `VTK_POLYGON`: the part of its plane inside the
//!   frame's scene box (the axis-aligned box of all bodies' bounding spheres and of the walls' reference
//!   points, widened by 5 % of its diagonal plus the largest body radius; 1 m when there are no bodies) and
//!   on the free side of every other wall, so the walls of a container are drawn as its faces, meeting at
//!   its edges (if that leaves nothing, the uncut patch is drawn). The box is recomputed per frame, so an
//!   open side's patch grows and shrinks with the scene; walls are unbounded planes and the patch only shows
//!   where they are. Cell data: `wall` (index), `velocity` (m/s),
//!   `contact_force` (N, the total force the bodies exert on the wall).
//!
//! A series is written only if the world has objects of its kind. Frame files are named by the step count,
//! so a restarted run in the same directory does not overwrite older frames; the `.pvd` is rewritten after
//! every frame so that it is complete even if the run stops. Numbers are ASCII in Rust's shortest
//! round-trip exponent form, so a value read back is bit-identical (`tests/io_vtk.rs`). The format is
//! documented for users in `docs/output-formats.md`.

use std::fmt::Write as _;
use std::io::{self, Write};
use std::path::{Path, PathBuf};

use crate::math::{Point, Real, Vector};
use crate::shape::Shape;
use crate::world::World;

/// VTK cell type codes used here.
pub const VTK_VERTEX: u8 = 1;
pub const VTK_POLYGON: u8 = 7;

/// What one `.vtu` file holds.
#[derive(Copy, Clone, Debug, Default, PartialEq, Eq)]
pub struct PieceCounts {
    pub points: usize,
    pub cells: usize,
}

/// The kinds of series.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum SeriesKind {
    Polyhedra,
    Spheres,
    Walls,
}

impl SeriesKind {
    pub fn name(self) -> &'static str {
        match self {
            SeriesKind::Polyhedra => "polyhedra",
            SeriesKind::Spheres => "spheres",
            SeriesKind::Walls => "walls",
        }
    }
}

/// Writes the frames of a run and keeps the `.pvd` collections up to date.
#[derive(Debug)]
pub struct VtkWriter {
    out_dir: PathBuf,
    series: Vec<(SeriesKind, Vec<(Real, String)>)>,
    /// Bytes written to frame files so far.
    pub bytes_written: u64,
    pub frames_written: u64,
}

impl VtkWriter {
    /// A writer for the series the world needs, with frames in `out_dir/vtk` (created).
    pub fn new(out_dir: &Path, world: &World) -> io::Result<Self> {
        std::fs::create_dir_all(out_dir.join("vtk"))?;
        let has = |pred: fn(&Shape) -> bool| (0..world.bodies.len()).any(|i| pred(world.shape(i)));
        let mut series = Vec::new();
        if has(|s| matches!(s, Shape::Polyhedron(_))) {
            series.push((SeriesKind::Polyhedra, Vec::new()));
        }
        if has(|s| matches!(s, Shape::Sphere(_))) {
            series.push((SeriesKind::Spheres, Vec::new()));
        }
        if !world.walls.is_empty() {
            series.push((SeriesKind::Walls, Vec::new()));
        }
        Ok(Self {
            out_dir: out_dir.to_owned(),
            series,
            bytes_written: 0,
            frames_written: 0,
        })
    }

    /// The series this writer produces.
    pub fn kinds(&self) -> Vec<SeriesKind> {
        self.series.iter().map(|(k, _)| *k).collect()
    }

    /// Writes one frame of every series at the world's current time and step, and rewrites the `.pvd` files.
    pub fn write_frame(&mut self, world: &World) -> io::Result<()> {
        for (kind, entries) in &mut self.series {
            let relative = format!("vtk/{}_{:09}.vtu", kind.name(), world.step_index);
            let mut text = String::new();
            match kind {
                SeriesKind::Polyhedra => polyhedra_vtu(&mut text, world),
                SeriesKind::Spheres => spheres_vtu(&mut text, world),
                SeriesKind::Walls => walls_vtu(&mut text, world),
            };
            std::fs::write(self.out_dir.join(&relative), &text)?;
            self.bytes_written += text.len() as u64;
            entries.retain(|(_, f)| *f != relative);
            entries.push((world.time, relative));
            let pvd = self.out_dir.join(format!("{}.pvd", kind.name()));
            let mut out = io::BufWriter::new(std::fs::File::create(&pvd)?);
            write_pvd(&mut out, entries)?;
            out.flush()?;
        }
        self.frames_written += 1;
        Ok(())
    }
}

/// Writes a `.pvd` collection of `(time, file)` entries (file paths relative to the `.pvd`).
pub fn write_pvd(out: &mut impl Write, entries: &[(Real, String)]) -> io::Result<()> {
    writeln!(out, "<?xml version=\"1.0\"?>")?;
    writeln!(
        out,
        "<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"LittleEndian\">"
    )?;
    writeln!(out, "  <Collection>")?;
    for (t, file) in entries {
        writeln!(
            out,
            "    <DataSet timestep=\"{t:e}\" group=\"\" part=\"0\" file=\"{file}\"/>"
        )?;
    }
    writeln!(out, "  </Collection>")?;
    writeln!(out, "</VTKFile>")
}

/// The `.vtu` text of the polyhedral bodies (see the module docs).
pub fn polyhedra_vtu(out: &mut String, world: &World) -> PieceCounts {
    let bodies: Vec<usize> = (0..world.bodies.len())
        .filter(|&i| matches!(world.shape(i), Shape::Polyhedron(_)))
        .collect();
    let poly = |i: usize| match world.shape(i) {
        Shape::Polyhedron(p) => p,
        _ => unreachable!("filtered to polyhedra"),
    };
    let points: usize = bodies.iter().map(|&i| poly(i).vertices().len()).sum();
    let cells: usize = bodies.iter().map(|&i| poly(i).num_faces()).sum();
    let counts = PieceCounts { points, cells };
    begin_piece(out, counts);

    out.push_str("      <Points>\n");
    data_array(out, "Points", "Float64", 3, |s| {
        for &i in &bodies {
            let pose = world.pose(i);
            for v in poly(i).vertices() {
                push_vec(s, &(pose * v).coords);
            }
        }
    });
    out.push_str("      </Points>\n");

    out.push_str("      <Cells>\n");
    data_array(out, "connectivity", "Int64", 1, |s| {
        let mut base = 0usize;
        for &i in &bodies {
            let p = poly(i);
            for f in 0..p.num_faces() {
                for &v in p.face_vertices(f) {
                    push_int(s, base + v as usize);
                }
                s.push('\n');
            }
            base += p.vertices().len();
        }
    });
    data_array(out, "offsets", "Int64", 1, |s| {
        let mut end = 0usize;
        for &i in &bodies {
            let p = poly(i);
            for f in 0..p.num_faces() {
                end += p.face_vertices(f).len();
                push_int(s, end);
            }
        }
    });
    data_array(out, "types", "UInt8", 1, |s| {
        for _ in 0..cells {
            push_int(s, VTK_POLYGON as usize);
        }
    });
    out.push_str("      </Cells>\n");

    // Per-body values repeated on each face of the body.
    let faces = |i: usize| poly(i).num_faces();
    out.push_str("      <CellData Scalars=\"body\" Vectors=\"velocity\">\n");
    data_array(out, "body", "Int64", 1, |s| {
        for &i in &bodies {
            for _ in 0..faces(i) {
                push_int(s, i);
            }
        }
    });
    for (name, value) in body_vectors() {
        data_array(out, name, "Float64", 3, |s| {
            for &i in &bodies {
                let v = value(world, i);
                for _ in 0..faces(i) {
                    push_vec(s, &v);
                }
            }
        });
    }
    out.push_str("      </CellData>\n");

    out.push_str("      <PointData Scalars=\"body\" Vectors=\"point_velocity\">\n");
    data_array(out, "body", "Int64", 1, |s| {
        for &i in &bodies {
            for _ in poly(i).vertices() {
                push_int(s, i);
            }
        }
    });
    data_array(out, "point_velocity", "Float64", 3, |s| {
        for &i in &bodies {
            let pose = world.pose(i);
            let body = &world.bodies[i];
            for v in poly(i).vertices() {
                push_vec(s, &body.velocity_at(&(pose * v)));
            }
        }
    });
    out.push_str("      </PointData>\n");
    end_piece(out);
    counts
}

/// The `.vtu` text of the spherical bodies (see the module docs).
pub fn spheres_vtu(out: &mut String, world: &World) -> PieceCounts {
    let spheres: Vec<(usize, Real)> = (0..world.bodies.len())
        .filter_map(|i| match world.shape(i) {
            Shape::Sphere(s) => Some((i, s.radius())),
            _ => None,
        })
        .collect();
    let counts = PieceCounts {
        points: spheres.len(),
        cells: spheres.len(),
    };
    begin_piece(out, counts);
    out.push_str("      <Points>\n");
    data_array(out, "Points", "Float64", 3, |s| {
        for &(i, _) in &spheres {
            push_vec(s, &world.bodies[i].position.coords);
        }
    });
    out.push_str("      </Points>\n");
    out.push_str("      <Cells>\n");
    data_array(out, "connectivity", "Int64", 1, |s| {
        (0..spheres.len()).for_each(|k| push_int(s, k))
    });
    data_array(out, "offsets", "Int64", 1, |s| {
        (1..=spheres.len()).for_each(|k| push_int(s, k))
    });
    data_array(out, "types", "UInt8", 1, |s| {
        (0..spheres.len()).for_each(|_| push_int(s, VTK_VERTEX as usize))
    });
    out.push_str("      </Cells>\n");
    out.push_str("      <PointData Scalars=\"diameter\" Vectors=\"velocity\">\n");
    data_array(out, "body", "Int64", 1, |s| {
        spheres.iter().for_each(|&(i, _)| push_int(s, i))
    });
    data_array(out, "radius", "Float64", 1, |s| {
        spheres.iter().for_each(|&(_, r)| push_real(s, r))
    });
    data_array(out, "diameter", "Float64", 1, |s| {
        spheres.iter().for_each(|&(_, r)| push_real(s, 2.0 * r))
    });
    for (name, value) in body_vectors() {
        data_array(out, name, "Float64", 3, |s| {
            spheres
                .iter()
                .for_each(|&(i, _)| push_vec(s, &value(world, i)))
        });
    }
    out.push_str("      </PointData>\n");
    end_piece(out);
    counts
}

/// The `.vtu` text of the walls (see the module docs).
pub fn walls_vtu(out: &mut String, world: &World) -> PieceCounts {
    let (lo, hi) = scene_box(world);
    let planes: Vec<(Vector, Point)> = world
        .walls
        .iter()
        .map(|w| {
            let n = w.normal_world();
            (n, w.pose * Point::from(w.plane.normal() * w.plane.offset()))
        })
        .collect();
    let polygons: Vec<Vec<Point>> = planes
        .iter()
        .enumerate()
        .map(|(k, (n, on_plane))| {
            let full = plane_box_polygon(n, on_plane, &lo, &hi);
            // The part on the free side of every other wall: the faces of a container meet at its edges.
            let mut clipped = full.clone();
            for (j, (n_j, p_j)) in planes.iter().enumerate() {
                if j != k {
                    clipped = clip_polygon(&clipped, n_j, p_j);
                }
            }
            if clipped.len() >= 3 {
                clipped
            } else {
                full
            }
        })
        .collect();
    let counts = PieceCounts {
        points: polygons.iter().map(Vec::len).sum(),
        cells: polygons.len(),
    };
    begin_piece(out, counts);
    out.push_str("      <Points>\n");
    data_array(out, "Points", "Float64", 3, |s| {
        polygons
            .iter()
            .flatten()
            .for_each(|p| push_vec(s, &p.coords))
    });
    out.push_str("      </Points>\n");
    out.push_str("      <Cells>\n");
    data_array(out, "connectivity", "Int64", 1, |s| {
        (0..counts.points).for_each(|k| push_int(s, k))
    });
    data_array(out, "offsets", "Int64", 1, |s| {
        let mut end = 0;
        for p in &polygons {
            end += p.len();
            push_int(s, end);
        }
    });
    data_array(out, "types", "UInt8", 1, |s| {
        (0..polygons.len()).for_each(|_| push_int(s, VTK_POLYGON as usize))
    });
    out.push_str("      </Cells>\n");
    out.push_str("      <CellData Scalars=\"wall\" Vectors=\"contact_force\">\n");
    data_array(out, "wall", "Int64", 1, |s| {
        (0..polygons.len()).for_each(|k| push_int(s, k))
    });
    data_array(out, "velocity", "Float64", 3, |s| {
        world.walls.iter().for_each(|w| push_vec(s, &w.velocity))
    });
    data_array(out, "contact_force", "Float64", 3, |s| {
        (0..world.walls.len()).for_each(|k| {
            push_vec(
                s,
                &world
                    .loads
                    .wall_forces
                    .get(k)
                    .copied()
                    .unwrap_or_else(Vector::zeros),
            )
        })
    });
    out.push_str("      </CellData>\n");
    end_piece(out);
    counts
}

/// The box the wall patches are cut from (see the module docs).
pub fn scene_box(world: &World) -> (Point, Point) {
    let mut lo = Point::from(Vector::repeat(Real::INFINITY));
    let mut hi = Point::from(Vector::repeat(Real::NEG_INFINITY));
    let mut grow = |p: &Point, r: Real| {
        for k in 0..3 {
            lo[k] = lo[k].min(p[k] - r);
            hi[k] = hi[k].max(p[k] + r);
        }
    };
    let mut largest_radius: Real = 0.0;
    for (b, &r) in world.bodies.iter().zip(&world.radii) {
        grow(&b.position, r);
        largest_radius = largest_radius.max(r);
    }
    for w in &world.walls {
        grow(
            &(w.pose * Point::from(w.plane.normal() * w.plane.offset())),
            0.0,
        );
    }
    if !lo.x.is_finite() {
        return (Point::origin(), Point::origin());
    }
    let margin = if world.bodies.is_empty() {
        1.0
    } else {
        0.05 * (hi - lo).norm() + largest_radius
    };
    (lo - Vector::repeat(margin), hi + Vector::repeat(margin))
}

/// The polygon where the plane through `point` with unit normal `n` cuts the box [lo, hi], counter-clockwise
/// about `n`. The point must lie in the box (it does for [`scene_box`]), so the polygon has 3–6 vertices
/// unless the box is flat.
pub fn plane_box_polygon(n: &Vector, point: &Point, lo: &Point, hi: &Point) -> Vec<Point> {
    let corner = |k: usize| {
        Point::new(
            if k & 1 == 0 { lo.x } else { hi.x },
            if k & 2 == 0 { lo.y } else { hi.y },
            if k & 4 == 0 { lo.z } else { hi.z },
        )
    };
    let d = n.dot(&point.coords);
    let mut pts: Vec<Point> = Vec::new();
    for a in 0..8usize {
        for bit in [1usize, 2, 4] {
            let b = a | bit;
            if b == a {
                continue;
            }
            let (pa, pb) = (corner(a), corner(b));
            let (sa, sb) = (n.dot(&pa.coords) - d, n.dot(&pb.coords) - d);
            if sa == 0.0 {
                pts.push(pa);
            }
            if sb == 0.0 {
                pts.push(pb);
            }
            if (sa < 0.0 && sb > 0.0) || (sa > 0.0 && sb < 0.0) {
                pts.push(pa + (pb - pa) * (sa / (sa - sb)));
            }
        }
    }
    let size = (hi - lo).norm();
    let mut unique: Vec<Point> = Vec::new();
    for p in pts {
        if unique.iter().all(|q| (q - p).norm() > 1e-12 * size) {
            unique.push(p);
        }
    }
    let centre =
        unique.iter().fold(Vector::zeros(), |acc, p| acc + p.coords) / unique.len().max(1) as Real;
    let t1 = n
        .cross(&if n.x.abs() < 0.9 {
            Vector::x()
        } else {
            Vector::y()
        })
        .normalize();
    let t2 = n.cross(&t1);
    unique.sort_by(|p, q| {
        let angle = |p: &Point| {
            (p.coords - centre)
                .dot(&t2)
                .atan2((p.coords - centre).dot(&t1))
        };
        angle(p).total_cmp(&angle(q))
    });
    unique
}

/// The part of the convex polygon `poly` on the free side `n·(x − p) ≥ 0` of the plane through `p`
/// (Sutherland–Hodgman for one plane).
pub fn clip_polygon(poly: &[Point], n: &Vector, p: &Point) -> Vec<Point> {
    let side = |x: &Point| n.dot(&(x - p));
    let mut out = Vec::with_capacity(poly.len() + 1);
    for (k, a) in poly.iter().enumerate() {
        let b = &poly[(k + 1) % poly.len()];
        let (sa, sb) = (side(a), side(b));
        if sa >= 0.0 {
            out.push(*a);
        }
        if (sa >= 0.0) != (sb >= 0.0) {
            out.push(a + (b - a) * (sa / (sa - sb)));
        }
    }
    out
}

/// The per-body vector fields written for bodies, by name.
#[allow(clippy::type_complexity)]
fn body_vectors() -> [(&'static str, fn(&World, usize) -> Vector); 4] {
    [
        ("velocity", |w, i| w.bodies[i].velocity),
        ("angular_velocity", |w, i| w.bodies[i].angular_velocity()),
        ("contact_force", |w, i| {
            w.loads.forces.get(i).copied().unwrap_or_else(Vector::zeros)
        }),
        ("contact_torque", |w, i| {
            w.loads
                .torques
                .get(i)
                .copied()
                .unwrap_or_else(Vector::zeros)
        }),
    ]
}

fn begin_piece(out: &mut String, counts: PieceCounts) {
    out.push_str("<?xml version=\"1.0\"?>\n");
    out.push_str(
        "<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\">\n",
    );
    out.push_str("  <UnstructuredGrid>\n");
    let _ = writeln!(
        out,
        "    <Piece NumberOfPoints=\"{}\" NumberOfCells=\"{}\">",
        counts.points, counts.cells
    );
}

fn end_piece(out: &mut String) {
    out.push_str("    </Piece>\n  </UnstructuredGrid>\n</VTKFile>\n");
}

fn data_array(
    out: &mut String,
    name: &str,
    ty: &str,
    components: usize,
    body: impl FnOnce(&mut String),
) {
    let _ = writeln!(
        out,
        "        <DataArray type=\"{ty}\" Name=\"{name}\" NumberOfComponents=\"{components}\" format=\"ascii\">"
    );
    body(out);
    if !out.ends_with('\n') {
        out.push('\n');
    }
    out.push_str("        </DataArray>\n");
}

fn push_real(s: &mut String, x: Real) {
    let _ = write!(s, "{x:e} ");
}

fn push_vec(s: &mut String, v: &Vector) {
    let _ = writeln!(s, "{:e} {:e} {:e}", v.x, v.y, v.z);
}

fn push_int(s: &mut String, k: usize) {
    let _ = write!(s, "{k} ");
}
