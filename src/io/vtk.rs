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
//! - `surfaces.pvd` → `vtk/surfaces_<step>.vtu`: every body of another bounded shape (ellipsoids) as the
//!   polygonal surface its [`ConvexShape::surface_mesh`](crate::shape::ConvexShape::surface_mesh) gives
//!   (an ellipsoid: a UV mesh of 16 latitude bands × 32 meridians, vertices on the exact surface), with the
//!   same cells, cell data and point data as the polyhedra.
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
//! every frame so that it is complete even if the run stops. A run continued from a checkpoint in the same
//! directory ([`VtkWriter::resume`]) keeps the frames the `.pvd` already lists up to its own start, so
//! ParaView sees one series across the restart.
//!
//! # Encoding ([`VtkEncoding`])
//! Numbers are inline base64 binary by default or ASCII in Rust's shortest round-trip exponent form
//! ([`VtkFormat`]). Coordinates and fields are `Float64` by default, exact (a value read back is
//! bit-identical, `tests/io_vtk.rs`); [`VtkPrecision::Float32`] halves them, rounding each value to the
//! nearest f32 (relative error ≤ 2^-24 ≈ 6e-8, i.e. 60 nm on a 1 m scene: enough to look at, not to
//! restart from). Binary arrays are zlib-compressed unless asked not to be ([`VtkCompression`], VTK's
//! `vtkZLibDataCompressor`: the raw array cut into 32 KiB blocks, each deflated, behind a UInt64 header
//! [blocks, block size, last block size, compressed sizes…], header and data base64-encoded separately as
//! VTK's own writer does); compression is lossless. Indices are `Int32`. The format is documented for users
//! in `docs/output-formats.md`.

use std::fmt::Write as _;

use base64::Engine as _;
use std::io::{self, Write};
use std::path::{Path, PathBuf};

use crate::math::{Point, Real, Vector};
use crate::shape::{ConvexPolyhedron, Shape, SurfaceMesh};
use crate::world::World;

/// VTK cell type of a single vertex.
pub const VTK_VERTEX: u8 = 1;
/// VTK cell type of a polygon.
pub const VTK_POLYGON: u8 = 7;

/// How the numbers of a `.vtu` are written.
#[derive(Copy, Clone, Debug, Default, PartialEq, Eq)]
pub enum VtkFormat {
    /// Inline base64 of the little-endian values (VTK's `format="binary"`, UInt64 size header), compressed
    /// or not ([`VtkCompression`]): exact and about twice as fast to write as ASCII. Uncompressed it is not
    /// smaller than ASCII (base64 spends 10.7 characters on every f64, ASCII writes a zero in 3); compressed
    /// it is 5–7× smaller (sizes in `docs/output-formats.md`).
    #[default]
    Binary,
    /// Text, shortest round-trip exponent form: exact, readable, larger and slower.
    Ascii,
}

/// The width of the floating-point arrays.
#[derive(Copy, Clone, Debug, Default, PartialEq, Eq)]
pub enum VtkPrecision {
    /// `Float64`: exact.
    #[default]
    Float64,
    /// `Float32`: each value rounded to the nearest f32 (see the module docs).
    Float32,
}

/// Compression of the binary arrays.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum VtkCompression {
    /// Uncompressed.
    None,
    /// zlib (deflate) in 32 KiB blocks, VTK's `vtkZLibDataCompressor`; binary format only.
    Zlib,
}

/// How the numbers of a `.vtu` are encoded: format, float width and compression. The default is binary,
/// Float64, zlib: exact, and on 1000 settling polyhedra 6.9× smaller than uncompressed binary (0.57 against
/// 3.95 MB per frame) and no slower to write (the many zero forces and the per-face repeats of each body's
/// values deflate well).
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub struct VtkEncoding {
    /// Binary or ASCII.
    pub format: VtkFormat,
    /// Width of the floating-point arrays.
    pub precision: VtkPrecision,
    /// Compression of the binary arrays.
    pub compression: VtkCompression,
}

impl Default for VtkEncoding {
    fn default() -> Self {
        VtkFormat::Binary.into()
    }
}

/// A format with its default precision (Float64) and compression (zlib for binary, none for ASCII).
impl From<VtkFormat> for VtkEncoding {
    fn from(format: VtkFormat) -> Self {
        Self {
            format,
            precision: VtkPrecision::Float64,
            compression: match format {
                VtkFormat::Binary => VtkCompression::Zlib,
                VtkFormat::Ascii => VtkCompression::None,
            },
        }
    }
}

impl VtkEncoding {
    /// Refuses the combination VTK cannot express: compressed ASCII.
    pub fn check(&self) -> io::Result<()> {
        if self.format == VtkFormat::Ascii && self.compression != VtkCompression::None {
            return Err(io::Error::other(
                "VTK compression applies to the binary format only (ASCII arrays cannot be compressed)",
            ));
        }
        Ok(())
    }

    fn float_type(&self) -> &'static str {
        match self.precision {
            VtkPrecision::Float64 => "Float64",
            VtkPrecision::Float32 => "Float32",
        }
    }
}

/// What one `.vtu` file holds.
#[derive(Copy, Clone, Debug, Default, PartialEq, Eq)]
pub struct PieceCounts {
    /// Number of points.
    pub points: usize,
    /// Number of cells.
    pub cells: usize,
}

/// The kinds of series.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum SeriesKind {
    /// Polyhedral bodies as their faces.
    Polyhedra,
    /// Spherical bodies as their centres.
    Spheres,
    /// Walls as polygons.
    Walls,
    /// Curved bodies (ellipsoids) as tessellated surfaces.
    Surfaces,
}

impl SeriesKind {
    /// The series' file name stem (`polyhedra`, `spheres`, `walls`, `surfaces`).
    pub fn name(self) -> &'static str {
        match self {
            SeriesKind::Polyhedra => "polyhedra",
            SeriesKind::Spheres => "spheres",
            SeriesKind::Walls => "walls",
            SeriesKind::Surfaces => "surfaces",
        }
    }
}

/// Writes the frames of a run and keeps the `.pvd` collections up to date.
#[derive(Debug)]
pub struct VtkWriter {
    out_dir: PathBuf,
    encoding: VtkEncoding,
    series: Vec<(SeriesKind, Vec<(Real, String)>)>,
    /// Bytes written to frame files so far.
    pub bytes_written: u64,
    /// Frames written so far.
    pub frames_written: u64,
}

impl VtkWriter {
    /// A writer for the series the world needs, with frames in `out_dir/vtk` (created). Any `.pvd` already
    /// in `out_dir` is replaced by the new run's series.
    pub fn new(
        out_dir: &Path,
        world: &World,
        encoding: impl Into<VtkEncoding>,
    ) -> io::Result<Self> {
        let encoding = encoding.into();
        encoding.check()?;
        std::fs::create_dir_all(out_dir.join("vtk"))?;
        let series = series_kinds(world)
            .into_iter()
            .map(|kind| (kind, Vec::new()))
            .collect();
        Ok(Self {
            out_dir: out_dir.to_owned(),
            encoding,
            series,
            bytes_written: 0,
            frames_written: 0,
        })
    }

    /// A writer for a run continued from a checkpoint in `out_dir`: each series starts with the frames its
    /// existing `.pvd` lists *before* the world's current step (frames at or after it belong to the part of
    /// the earlier run that the restart replaces, and are rewritten as the run passes them again). A
    /// missing `.pvd` starts an empty series; a `.pvd` that is not a polydem collection is an error naming
    /// the file and line.
    pub fn resume(
        out_dir: &Path,
        world: &World,
        encoding: impl Into<VtkEncoding>,
    ) -> io::Result<Self> {
        let mut writer = Self::new(out_dir, world, encoding)?;
        for (kind, entries) in &mut writer.series {
            *entries = earlier_entries(out_dir, *kind, world.step_index())?;
        }
        Ok(writer)
    }

    /// The series this writer produces.
    pub fn kinds(&self) -> Vec<SeriesKind> {
        self.series.iter().map(|(k, _)| *k).collect()
    }

    /// Writes one frame of every series at the world's current time and step, and rewrites the `.pvd` files.
    pub fn write_frame(&mut self, world: &World) -> io::Result<()> {
        let (mut points, mut cells, mut connectivity) = (0usize, 0usize, 0usize);
        for i in 0..world.bodies().len() {
            if let Shape::Polyhedron(p) = world.shape(i) {
                points += p.vertices().len();
                cells += p.num_faces();
                connectivity += (0..p.num_faces())
                    .map(|f| p.face_vertices(f).len())
                    .sum::<usize>();
            }
        }
        check_int32(PieceCounts { points, cells }, connectivity)?;
        for (kind, entries) in &mut self.series {
            let relative = format!("vtk/{}_{:09}.vtu", kind.name(), world.step_index());
            let mut text = String::new();
            match kind {
                SeriesKind::Polyhedra => polyhedra_vtu(&mut text, world, self.encoding),
                SeriesKind::Spheres => spheres_vtu(&mut text, world, self.encoding),
                SeriesKind::Walls => walls_vtu(&mut text, world, self.encoding),
                SeriesKind::Surfaces => surfaces_vtu(&mut text, world, self.encoding),
            };
            std::fs::write(self.out_dir.join(&relative), &text)?;
            self.bytes_written += text.len() as u64;
            entries.retain(|(_, f)| *f != relative);
            entries.push((world.time(), relative));
            replace_pvd(&self.out_dir, *kind, entries)?;
        }
        self.frames_written += 1;
        Ok(())
    }
}

/// The series a run of `world` writes: polyhedra, spheres, walls and other bounded surfaces, those the
/// world has.
pub fn series_kinds(world: &World) -> Vec<SeriesKind> {
    let has = |pred: fn(&Shape) -> bool| (0..world.bodies().len()).any(|i| pred(world.shape(i)));
    let mut series = Vec::new();
    if has(|s| matches!(s, Shape::Polyhedron(_))) {
        series.push(SeriesKind::Polyhedra);
    }
    if has(|s| matches!(s, Shape::Sphere(_))) {
        series.push(SeriesKind::Spheres);
    }
    if !world.walls().is_empty() {
        series.push(SeriesKind::Walls);
    }
    if has(|s| surface_body(s).is_some()) {
        series.push(SeriesKind::Surfaces);
    }
    series
}

/// The entries of `out_dir/<kind>.pvd` whose frames (`vtk/<kind>_<step>.vtu` or `.pvtu`) come before step
/// `step`: the frames a run restarted at `step` keeps. A missing `.pvd` lists none; one that is not a
/// polydem collection is an error naming the file and line.
pub fn earlier_entries(
    out_dir: &Path,
    kind: SeriesKind,
    step: u64,
) -> io::Result<Vec<(Real, String)>> {
    let pvd = out_dir.join(format!("{}.pvd", kind.name()));
    let text = match std::fs::read_to_string(&pvd) {
        Ok(text) => text,
        Err(e) if e.kind() == io::ErrorKind::NotFound => return Ok(Vec::new()),
        Err(e) => return Err(io::Error::new(e.kind(), format!("{}: {e}", pvd.display()))),
    };
    let earlier = read_pvd(&text).map_err(|(line, what)| {
        io::Error::new(
            io::ErrorKind::InvalidData,
            format!("{}:{line}: {what}", pvd.display()),
        )
    })?;
    Ok(earlier
        .into_iter()
        .filter(|(_, file)| frame_step(kind.name(), file).is_some_and(|s| s < step))
        .collect())
}

/// Replaces `out_dir/<kind>.pvd` by the collection of `entries`, written aside and then renamed, so a
/// reader or a restart never sees half of it.
pub fn replace_pvd(out_dir: &Path, kind: SeriesKind, entries: &[(Real, String)]) -> io::Result<()> {
    let pvd = out_dir.join(format!("{}.pvd", kind.name()));
    let partial = out_dir.join(format!("{}.pvd.partial", kind.name()));
    let mut out = io::BufWriter::new(std::fs::File::create(&partial)?);
    write_pvd(&mut out, entries)?;
    out.flush()?;
    drop(out);
    std::fs::rename(&partial, &pvd)
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

/// The `(time, file)` entries of a `.pvd` collection written by [`write_pvd`]; an error is the 1-based line
/// and what is wrong with it.
pub fn read_pvd(text: &str) -> Result<Vec<(Real, String)>, (usize, String)> {
    let attribute = |line: &str, name: &str| -> Option<String> {
        let start = line.find(&format!(" {name}=\""))? + name.len() + 3;
        let len = line[start..].find('"')?;
        Some(line[start..start + len].to_owned())
    };
    if !text.contains("<VTKFile type=\"Collection\"") {
        return Err((
            1,
            "not a VTK collection (.pvd): no <VTKFile type=\"Collection\">".into(),
        ));
    }
    let mut entries = Vec::new();
    for (k, line) in text.lines().enumerate() {
        if !line.trim_start().starts_with("<DataSet") {
            continue;
        }
        let (Some(t), Some(file)) = (attribute(line, "timestep"), attribute(line, "file")) else {
            return Err((
                k + 1,
                format!("DataSet without timestep or file: {}", line.trim()),
            ));
        };
        let t: Real = t
            .parse()
            .map_err(|_| (k + 1, format!("timestep \"{t}\" is not a number")))?;
        entries.push((t, file));
    }
    Ok(entries)
}

/// The step of a frame file named `vtk/<series>_<step>.vtu` (or `.pvtu`, the frames of a run over MPI
/// ranks), if the name has that form.
fn frame_step(series: &str, file: &str) -> Option<u64> {
    let stem = file
        .strip_prefix("vtk/")?
        .strip_prefix(series)?
        .strip_prefix('_')?;
    // `.pvtu` first: a name ending in `.pvtu` also ends in `.vtu`.
    let step = stem
        .strip_suffix(".pvtu")
        .or_else(|| stem.strip_suffix(".vtu"))?;
    step.parse().ok()
}

/// The `.vtu` text of the polyhedral bodies (see the module docs).
pub fn polyhedra_vtu(out: &mut String, world: &World, format: VtkEncoding) -> PieceCounts {
    polyhedra_piece_vtu(out, world, format, &BodyPiece::whole(world))
}

/// The bodies a `.vtu` of bodies holds: a piece of a world split over processes writes the bodies its
/// process owns, each labelled (in the `body` arrays) by its index in the whole world.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct BodyPiece {
    /// Indices of the bodies written, increasing.
    pub bodies: Vec<usize>,
    /// The `body` value written for each.
    pub labels: Vec<usize>,
}

impl BodyPiece {
    /// Every body of `world`, labelled by its index.
    pub fn whole(world: &World) -> Self {
        let all: Vec<usize> = (0..world.bodies().len()).collect();
        Self {
            bodies: all.clone(),
            labels: all,
        }
    }

    fn items(&self) -> impl Iterator<Item = (usize, usize)> + '_ {
        self.bodies.iter().copied().zip(self.labels.iter().copied())
    }
}

/// [`polyhedra_vtu`] of the bodies of `piece`.
pub fn polyhedra_piece_vtu(
    out: &mut String,
    world: &World,
    format: VtkEncoding,
    piece: &BodyPiece,
) -> PieceCounts {
    let items: Vec<(usize, usize, &ConvexPolyhedron)> = piece
        .items()
        .filter_map(|(i, label)| match world.shape(i) {
            Shape::Polyhedron(p) => Some((i, label, p.as_ref())),
            _ => None,
        })
        .collect();
    mesh_vtu(out, world, format, &items)
}

/// The `.vtu` text of the bodies of the other bounded shapes (ellipsoids, …) as their
/// [`ConvexShape::surface_mesh`](crate::shape::ConvexShape::surface_mesh), written like the polyhedra.
pub fn surfaces_vtu(out: &mut String, world: &World, format: VtkEncoding) -> PieceCounts {
    surfaces_piece_vtu(out, world, format, &BodyPiece::whole(world))
}

/// [`surfaces_vtu`] of the bodies of `piece`.
pub fn surfaces_piece_vtu(
    out: &mut String,
    world: &World,
    format: VtkEncoding,
    piece: &BodyPiece,
) -> PieceCounts {
    let meshes: Vec<(usize, usize, SurfaceMesh)> = piece
        .items()
        .filter_map(|(i, label)| surface_body(world.shape(i)).map(|m| (i, label, m)))
        .collect();
    let items: Vec<(usize, usize, &SurfaceMesh)> =
        meshes.iter().map(|(i, label, m)| (*i, *label, m)).collect();
    mesh_vtu(out, world, format, &items)
}

/// The surface of a body that belongs to the surfaces series: bounded, neither a polyhedron nor a sphere.
fn surface_body(shape: &Shape) -> Option<SurfaceMesh> {
    match shape {
        Shape::Polyhedron(_) | Shape::Sphere(_) | Shape::Plane(_) => None,
        other => other.convex().map(|c| c.surface_mesh()),
    }
}

/// A closed polygonal surface in a body frame, as the mesh writer reads it.
trait MeshView {
    fn vertices(&self) -> &[Point];
    fn num_faces(&self) -> usize;
    fn face_vertices(&self, f: usize) -> &[u32];
}

impl MeshView for ConvexPolyhedron {
    fn vertices(&self) -> &[Point] {
        ConvexPolyhedron::vertices(self)
    }
    fn num_faces(&self) -> usize {
        ConvexPolyhedron::num_faces(self)
    }
    fn face_vertices(&self, f: usize) -> &[u32] {
        ConvexPolyhedron::face_vertices(self, f)
    }
}

impl MeshView for SurfaceMesh {
    fn vertices(&self) -> &[Point] {
        &self.vertices
    }
    fn num_faces(&self) -> usize {
        self.faces.len()
    }
    fn face_vertices(&self, f: usize) -> &[u32] {
        &self.faces[f]
    }
}

/// The `.vtu` text of bodies drawn as polygonal surfaces: `items` are (body index, its label, its mesh).
fn mesh_vtu<M: MeshView + ?Sized>(
    out: &mut String,
    world: &World,
    format: VtkEncoding,
    items: &[(usize, usize, &M)],
) -> PieceCounts {
    let points: usize = items.iter().map(|(_, _, m)| m.vertices().len()).sum();
    let cells: usize = items.iter().map(|(_, _, m)| m.num_faces()).sum();
    let counts = PieceCounts { points, cells };
    begin_piece(out, counts, format);
    out.push_str("      <Points>\n");
    data_array(out, format, "Points", "Real", 3, |s| {
        for &(i, _, mesh) in items {
            let pose = world.pose(i);
            for v in mesh.vertices() {
                s.vec(&(pose * v).coords);
            }
        }
    });
    out.push_str("      </Points>\n");
    mesh_cells(out, format, items, cells);
    mesh_cell_data(out, world, format, items);
    mesh_point_data(out, world, format, items);
    end_piece(out);
    counts
}

/// The `<Cells>` of [`mesh_vtu`]: one polygon per face, `cells` in all.
fn mesh_cells<M: MeshView + ?Sized>(
    out: &mut String,
    format: VtkEncoding,
    items: &[(usize, usize, &M)],
    cells: usize,
) {
    out.push_str("      <Cells>\n");
    data_array(out, format, "connectivity", "Int32", 1, |s| {
        let mut base = 0usize;
        for &(_, _, mesh) in items {
            for f in 0..mesh.num_faces() {
                for &v in mesh.face_vertices(f) {
                    s.int(base + v as usize);
                }
            }
            base += mesh.vertices().len();
        }
    });
    data_array(out, format, "offsets", "Int32", 1, |s| {
        let mut end = 0usize;
        for &(_, _, mesh) in items {
            for f in 0..mesh.num_faces() {
                end += mesh.face_vertices(f).len();
                s.int(end);
            }
        }
    });
    data_array(out, format, "types", "UInt8", 1, |s| {
        for _ in 0..cells {
            s.int(VTK_POLYGON as usize);
        }
    });
    out.push_str("      </Cells>\n");
}

/// The `<CellData>` of [`mesh_vtu`]: per-body values repeated on each face of the body.
fn mesh_cell_data<M: MeshView + ?Sized>(
    out: &mut String,
    world: &World,
    format: VtkEncoding,
    items: &[(usize, usize, &M)],
) {
    out.push_str("      <CellData Scalars=\"body\" Vectors=\"velocity\">\n");
    data_array(out, format, "body", "Int32", 1, |s| {
        for &(_, label, mesh) in items {
            for _ in 0..mesh.num_faces() {
                s.int(label);
            }
        }
    });
    for (name, value) in body_vectors() {
        data_array(out, format, name, "Real", 3, |s| {
            for &(i, _, mesh) in items {
                let v = value(world, i);
                for _ in 0..mesh.num_faces() {
                    s.vec(&v);
                }
            }
        });
    }
    out.push_str("      </CellData>\n");
}

/// The `<PointData>` of [`mesh_vtu`]: the body label and the velocity of the material point at each
/// vertex.
fn mesh_point_data<M: MeshView + ?Sized>(
    out: &mut String,
    world: &World,
    format: VtkEncoding,
    items: &[(usize, usize, &M)],
) {
    out.push_str("      <PointData Scalars=\"body\" Vectors=\"point_velocity\">\n");
    data_array(out, format, "body", "Int32", 1, |s| {
        for &(_, label, mesh) in items {
            for _ in mesh.vertices() {
                s.int(label);
            }
        }
    });
    data_array(out, format, "point_velocity", "Real", 3, |s| {
        for &(i, _, mesh) in items {
            let pose = world.pose(i);
            let body = &world.bodies()[i];
            for v in mesh.vertices() {
                s.vec(&body.velocity_at(&(pose * v)));
            }
        }
    });
    out.push_str("      </PointData>\n");
}

/// The `.vtu` text of the spherical bodies (see the module docs).
pub fn spheres_vtu(out: &mut String, world: &World, format: VtkEncoding) -> PieceCounts {
    spheres_piece_vtu(out, world, format, &BodyPiece::whole(world))
}

/// [`spheres_vtu`] of the bodies of `piece`.
pub fn spheres_piece_vtu(
    out: &mut String,
    world: &World,
    format: VtkEncoding,
    piece: &BodyPiece,
) -> PieceCounts {
    let spheres: Vec<(usize, Real, usize)> = piece
        .items()
        .filter_map(|(i, label)| match world.shape(i) {
            Shape::Sphere(s) => Some((i, s.radius(), label)),
            _ => None,
        })
        .collect();
    let counts = PieceCounts {
        points: spheres.len(),
        cells: spheres.len(),
    };
    begin_piece(out, counts, format);
    out.push_str("      <Points>\n");
    data_array(out, format, "Points", "Real", 3, |s| {
        for &(i, _, _) in &spheres {
            s.vec(&world.bodies()[i].position.coords);
        }
    });
    out.push_str("      </Points>\n");
    out.push_str("      <Cells>\n");
    data_array(out, format, "connectivity", "Int32", 1, |s| {
        (0..spheres.len()).for_each(|k| s.int(k))
    });
    data_array(out, format, "offsets", "Int32", 1, |s| {
        (1..=spheres.len()).for_each(|k| s.int(k))
    });
    data_array(out, format, "types", "UInt8", 1, |s| {
        (0..spheres.len()).for_each(|_| s.int(VTK_VERTEX as usize))
    });
    out.push_str("      </Cells>\n");
    out.push_str("      <PointData Scalars=\"diameter\" Vectors=\"velocity\">\n");
    data_array(out, format, "body", "Int32", 1, |s| {
        spheres.iter().for_each(|&(_, _, label)| s.int(label))
    });
    data_array(out, format, "radius", "Real", 1, |s| {
        spheres.iter().for_each(|&(_, r, _)| s.real(r))
    });
    data_array(out, format, "diameter", "Real", 1, |s| {
        spheres.iter().for_each(|&(_, r, _)| s.real(2.0 * r))
    });
    for (name, value) in body_vectors() {
        data_array(out, format, name, "Real", 3, |s| {
            spheres
                .iter()
                .for_each(|&(i, _, _)| s.vec(&value(world, i)))
        });
    }
    out.push_str("      </PointData>\n");
    end_piece(out);
    counts
}

/// The `.vtu` text of the walls (see the module docs).
pub fn walls_vtu(out: &mut String, world: &World, format: VtkEncoding) -> PieceCounts {
    let (lo, hi) = scene_box(world);
    let planes: Vec<(Vector, Point)> = world
        .walls()
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
    begin_piece(out, counts, format);
    out.push_str("      <Points>\n");
    data_array(out, format, "Points", "Real", 3, |s| {
        polygons.iter().flatten().for_each(|p| s.vec(&p.coords))
    });
    out.push_str("      </Points>\n");
    out.push_str("      <Cells>\n");
    data_array(out, format, "connectivity", "Int32", 1, |s| {
        (0..counts.points).for_each(|k| s.int(k))
    });
    data_array(out, format, "offsets", "Int32", 1, |s| {
        let mut end = 0;
        for p in &polygons {
            end += p.len();
            s.int(end);
        }
    });
    data_array(out, format, "types", "UInt8", 1, |s| {
        (0..polygons.len()).for_each(|_| s.int(VTK_POLYGON as usize))
    });
    out.push_str("      </Cells>\n");
    out.push_str("      <CellData Scalars=\"wall\" Vectors=\"contact_force\">\n");
    data_array(out, format, "wall", "Int32", 1, |s| {
        (0..polygons.len()).for_each(|k| s.int(k))
    });
    data_array(out, format, "velocity", "Real", 3, |s| {
        world.walls().iter().for_each(|w| s.vec(&w.velocity))
    });
    data_array(out, format, "contact_force", "Real", 3, |s| {
        (0..world.walls().len()).for_each(|k| {
            s.vec(
                &world
                    .loads()
                    .wall_forces()
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
    for (b, &r) in world.bodies().iter().zip(world.radii()) {
        grow(&b.position, r);
        largest_radius = largest_radius.max(r);
    }
    for w in world.walls() {
        grow(
            &(w.pose * Point::from(w.plane.normal() * w.plane.offset())),
            0.0,
        );
    }
    if !lo.x.is_finite() {
        return (Point::origin(), Point::origin());
    }
    let margin = if world.bodies().is_empty() {
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
        ("velocity", |w, i| w.bodies()[i].velocity),
        ("angular_velocity", |w, i| w.bodies()[i].angular_velocity()),
        ("contact_force", |w, i| {
            w.loads()
                .forces()
                .get(i)
                .copied()
                .unwrap_or_else(Vector::zeros)
        }),
        ("contact_torque", |w, i| {
            w.loads()
                .torques()
                .get(i)
                .copied()
                .unwrap_or_else(Vector::zeros)
        }),
    ]
}

fn begin_piece(out: &mut String, counts: PieceCounts, encoding: VtkEncoding) {
    out.push_str("<?xml version=\"1.0\"?>\n");
    out.push_str(
        "<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\"",
    );
    if encoding.compression == VtkCompression::Zlib {
        out.push_str(" compressor=\"vtkZLibDataCompressor\"");
    }
    out.push_str(">\n");
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

/// The values of one data array, collected before they are written in the chosen encoding.
#[derive(Default)]
struct Values {
    reals: Vec<Real>,
    ints: Vec<i64>,
}

impl Values {
    fn real(&mut self, x: Real) {
        self.reals.push(x);
    }

    fn vec(&mut self, v: &Vector) {
        self.reals.extend_from_slice(&[v.x, v.y, v.z]);
    }

    fn int(&mut self, k: usize) {
        self.ints.push(k as i64);
    }
}

/// Integer arrays (indices, connectivity, offsets) are `Int32`: a frame has far fewer than 2³¹ points. A
/// frame that would not fit is refused rather than written with wrapped indices.
fn check_int32(counts: PieceCounts, connectivity: usize) -> io::Result<()> {
    if counts.points.max(counts.cells).max(connectivity) > i32::MAX as usize {
        return Err(io::Error::other(format!(
            "VTK frame too large for Int32 indices: {} points, {} cells, {connectivity} connectivity entries",
            counts.points, counts.cells
        )));
    }
    Ok(())
}

/// Writes one `DataArray` with the values `fill` collects. `ty` is `"Real"` (written as the encoding's float
/// type), `"Int32"` or `"UInt8"`.
fn data_array(
    out: &mut String,
    encoding: VtkEncoding,
    name: &str,
    ty: &str,
    components: usize,
    fill: impl FnOnce(&mut Values),
) {
    let mut values = Values::default();
    fill(&mut values);
    let real = ty == "Real";
    let ty = if real { encoding.float_type() } else { ty };
    let format = match encoding.format {
        VtkFormat::Ascii => "ascii",
        VtkFormat::Binary => "binary",
    };
    let _ = writeln!(
        out,
        "        <DataArray type=\"{ty}\" Name=\"{name}\" NumberOfComponents=\"{components}\" format=\"{format}\">"
    );
    match encoding.format {
        VtkFormat::Ascii => {
            let per_line = if real { components } else { 16 };
            match (real, encoding.precision) {
                (true, VtkPrecision::Float64) => {
                    write_lines(out, &values.reals, per_line, |s, x| {
                        let _ = write!(s, "{x:e}");
                    })
                }
                (true, VtkPrecision::Float32) => {
                    write_lines(out, &values.reals, per_line, |s, x| {
                        let _ = write!(s, "{:e}", x as f32);
                    })
                }
                _ => write_lines(out, &values.ints, per_line, |s, k| {
                    let _ = write!(s, "{k}");
                }),
            }
        }
        VtkFormat::Binary => {
            let mut raw: Vec<u8> = Vec::new();
            match (real, ty) {
                (true, "Float32") => values
                    .reals
                    .iter()
                    .for_each(|&x| raw.extend_from_slice(&(x as f32).to_le_bytes())),
                (true, _) => values
                    .reals
                    .iter()
                    .for_each(|x| raw.extend_from_slice(&x.to_le_bytes())),
                (false, "UInt8") => values.ints.iter().for_each(|&k| raw.push(k as u8)),
                _ => values
                    .ints
                    .iter()
                    .for_each(|&k| raw.extend_from_slice(&(k as i32).to_le_bytes())),
            }
            out.push_str("          ");
            match encoding.compression {
                VtkCompression::None => {
                    // VTK's inline binary: base64 of [byte count as UInt64 (header_type)] + raw data.
                    let mut block = (raw.len() as u64).to_le_bytes().to_vec();
                    block.extend_from_slice(&raw);
                    base64::engine::general_purpose::STANDARD.encode_string(&block, out);
                }
                VtkCompression::Zlib => zlib_blocks(out, &raw),
            }
            out.push('\n');
        }
    }
    out.push_str("        </DataArray>\n");
}

/// Uncompressed block size of VTK's compressed arrays (VTK's default, 32 KiB).
const ZLIB_BLOCK: usize = 1 << 15;

/// Appends VTK's compressed inline array: base64 of the UInt64 header [blocks, block size, last block's
/// size, compressed size of each block], then base64 of the deflated blocks, one after the other. Fast
/// compression (level 1): the frames are mostly floats, which deflate shrinks little more at higher levels.
fn zlib_blocks(out: &mut String, raw: &[u8]) {
    use flate2::{write::ZlibEncoder, Compression};
    let blocks: Vec<Vec<u8>> = raw
        .chunks(ZLIB_BLOCK)
        .map(|chunk| {
            let mut z = ZlibEncoder::new(Vec::new(), Compression::fast());
            // Writing to a Vec cannot fail.
            let _ = z.write_all(chunk);
            z.finish().unwrap_or_default()
        })
        .collect();
    let last = match raw.len() % ZLIB_BLOCK {
        0 if !raw.is_empty() => ZLIB_BLOCK,
        r => r,
    };
    let mut header: Vec<u8> = Vec::with_capacity(8 * (3 + blocks.len()));
    for n in [blocks.len(), ZLIB_BLOCK, last]
        .into_iter()
        .chain(blocks.iter().map(Vec::len))
    {
        header.extend_from_slice(&(n as u64).to_le_bytes());
    }
    let engine = base64::engine::general_purpose::STANDARD;
    engine.encode_string(&header, out);
    engine.encode_string(blocks.concat(), out);
}

fn write_lines<T: Copy>(
    out: &mut String,
    values: &[T],
    per_line: usize,
    put: impl Fn(&mut String, T),
) {
    for line in values.chunks(per_line.max(1)) {
        for (k, &v) in line.iter().enumerate() {
            if k > 0 {
                out.push(' ');
            }
            put(out, v);
        }
        out.push('\n');
    }
}
