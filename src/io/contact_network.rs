//! The contact network of a run — every active contact's point, normal, depth and force — as an
//! [`Output`]: the force chains of a granular packing, for plotting and for ParaView.
//!
//! - `contacts.csv`: `t,kind,a,b,px,py,pz,nx,ny,nz,depth,fx,fy,fz`, one row per active contact per
//!   output time. `kind` is `body` (a, b: the two bodies' names, a before b in the world's order) or
//!   `wall` (a: the wall's name, b: the body's). (px, py, pz) is the contact point c_M (m), n the unit
//!   normal from a towards b, `depth` the overlap δ_M (m), f the contact force on b (N; a receives its
//!   opposite), all in the world frame.
//! - `vtk/contacts_NNNNNNNNN.vtp` (NNNNNNNNN: the step) with the collection `contacts.pvd`: one line cell
//!   per contact, from a's centre to b's (from the contact point to the body's centre for a wall), with
//!   cell data `force`, `normal`, `point`, `depth` and `normal_force` (f·n, N) — the force-chain lines
//!   LIGGGHTS users get from `dump local/gran/vtk`.
//!
//! Numbers are written with Rust's shortest round-trip formatting, so a value read back is bit-identical.

use std::fmt::Write as _;
use std::fs::File;
use std::io::{self, BufWriter, Write};
use std::path::{Path, PathBuf};

use crate::io::csv_continue::continue_csv;
use crate::io::output::{Output, Schedule};
use crate::io::run_summary::OutputRecord;
use crate::io::vtk::{read_pvd, write_pvd};
use crate::math::{Point, Real, Vector};
use crate::scene::Simulation;
use crate::world::{ContactKey, ContactState, World};

/// Header of `contacts.csv`.
pub const CONTACTS_HEADER: &str = "t,kind,a,b,px,py,pz,nx,ny,nz,depth,fx,fy,fz";

/// The contact network written on a schedule.
pub struct ContactNetwork {
    out_dir: PathBuf,
    csv: BufWriter<File>,
    frames: Vec<(Real, String)>,
    schedule: Schedule,
    bytes_written: u64,
}

/// One active contact, ready to write.
struct Row {
    wall: bool,
    a: String,
    b: String,
    /// The line drawn for it: a's centre (or the contact point for a wall) to b's centre.
    from: Point,
    to: Point,
    state: ContactState,
}

impl ContactNetwork {
    /// A new network in `out_dir` (`contacts.csv` with its header, frames in `out_dir/vtk`).
    pub fn create(out_dir: &Path, schedule: Schedule) -> io::Result<Self> {
        let path = out_dir.join("contacts.csv");
        let file = File::create(&path).map_err(|e| in_file(&path, "cannot create", e))?;
        let mut csv = BufWriter::new(file);
        writeln!(csv, "{CONTACTS_HEADER}")?;
        Self::with(out_dir, csv, Vec::new(), schedule)
    }

    /// Continues the network an earlier run left in `out_dir`: rows before `world`'s time and frames of
    /// steps before its step are kept; the rest is rewritten as the run passes it again.
    pub fn continue_at(out_dir: &Path, world: &World, schedule: Schedule) -> io::Result<Self> {
        let path = out_dir.join("contacts.csv");
        let csv = continue_csv(&path, CONTACTS_HEADER, world.time())
            .map_err(|e| in_file(&path, "cannot continue", e))?;
        let frames = earlier_frames(out_dir, world.step_index())?;
        Self::with(out_dir, csv, frames, schedule)
    }

    fn with(
        out_dir: &Path,
        csv: BufWriter<File>,
        frames: Vec<(Real, String)>,
        schedule: Schedule,
    ) -> io::Result<Self> {
        let vtk = out_dir.join("vtk");
        std::fs::create_dir_all(&vtk).map_err(|e| in_file(&vtk, "cannot create", e))?;
        Ok(Self {
            out_dir: out_dir.to_owned(),
            csv,
            frames,
            schedule,
            bytes_written: 0,
        })
    }

    fn write_frame(&mut self, rows: &[Row], world: &World) -> io::Result<()> {
        let relative = frame_name(world.step_index());
        let text = vtp(rows);
        let path = self.out_dir.join(&relative);
        std::fs::write(&path, &text).map_err(|e| in_file(&path, "cannot write", e))?;
        self.bytes_written += text.len() as u64;
        self.frames.retain(|(_, f)| *f != relative);
        self.frames.push((world.time(), relative));
        // The collection is replaced whole, so a reader never sees half of it.
        let pvd = self.out_dir.join("contacts.pvd");
        let partial = self.out_dir.join("contacts.pvd.partial");
        let mut out = BufWriter::new(
            File::create(&partial).map_err(|e| in_file(&partial, "cannot create", e))?,
        );
        write_pvd(&mut out, &self.frames)?;
        out.flush()?;
        drop(out);
        std::fs::rename(&partial, &pvd).map_err(|e| in_file(&pvd, "cannot replace", e))
    }
}

fn frame_name(step: u64) -> String {
    format!("vtk/contacts_{step:09}.vtp")
}

fn in_file(path: &Path, what: &str, e: io::Error) -> io::Error {
    io::Error::new(e.kind(), format!("{what} {}: {e}", path.display()))
}

/// The frames an earlier run's `contacts.pvd` lists for steps before `step` (none if there is no file).
fn earlier_frames(out_dir: &Path, step: u64) -> io::Result<Vec<(Real, String)>> {
    let pvd = out_dir.join("contacts.pvd");
    let text = match std::fs::read_to_string(&pvd) {
        Ok(text) => text,
        Err(e) if e.kind() == io::ErrorKind::NotFound => return Ok(Vec::new()),
        Err(e) => return Err(in_file(&pvd, "cannot read", e)),
    };
    let entries = read_pvd(&text).map_err(|(line, what)| {
        io::Error::new(
            io::ErrorKind::InvalidData,
            format!("{}:{line}: {what}", pvd.display()),
        )
    })?;
    let step_of = |file: &str| -> Option<u64> {
        file.strip_prefix("vtk/contacts_")?
            .strip_suffix(".vtp")?
            .parse()
            .ok()
    };
    Ok(entries
        .into_iter()
        .filter(|(_, file)| step_of(file).is_some_and(|s| s < step))
        .collect())
}

/// The active contacts of the world's contact store, in the store's order.
fn active_contacts(world: &World) -> Vec<Row> {
    let store = &world.contacts();
    store
        .keys()
        .iter()
        .zip(store.states())
        .filter(|(_, state)| state.is_active())
        .map(|(key, state)| match *key {
            ContactKey::Body { a, b } => Row {
                wall: false,
                a: world.names()[a as usize].clone(),
                b: world.names()[b as usize].clone(),
                from: world.bodies()[a as usize].position,
                to: world.bodies()[b as usize].position,
                state: *state,
            },
            ContactKey::Wall { body, wall } => Row {
                wall: true,
                a: world.walls()[wall as usize].name.clone(),
                b: world.names()[body as usize].clone(),
                from: state.geometry.point,
                to: world.bodies()[body as usize].position,
                state: *state,
            },
        })
        .collect()
}

fn write_csv_rows(out: &mut impl Write, t: Real, rows: &[Row]) -> io::Result<()> {
    for r in rows {
        let g = &r.state.geometry;
        let (p, n, f) = (g.point, g.normal, r.state.force_on_b);
        writeln!(
            out,
            "{t},{},{},{},{},{},{},{},{},{},{},{},{},{}",
            if r.wall { "wall" } else { "body" },
            r.a,
            r.b,
            p.x,
            p.y,
            p.z,
            n.x,
            n.y,
            n.z,
            g.depth,
            f.x,
            f.y,
            f.z
        )?;
    }
    Ok(())
}

/// A `.vtp` (VTK XML PolyData, ASCII) of one line per contact.
fn vtp(rows: &[Row]) -> String {
    let mut s = String::new();
    let vectors = |s: &mut String, name: &str, of: &dyn Fn(&Row) -> Vector| {
        let _ = writeln!(s, "<DataArray type=\"Float64\" Name=\"{name}\" NumberOfComponents=\"3\" format=\"ascii\">");
        for r in rows {
            let v = of(r);
            let _ = writeln!(s, "{} {} {}", v.x, v.y, v.z);
        }
        s.push_str("</DataArray>\n");
    };
    let scalars = |s: &mut String, name: &str, of: &dyn Fn(&Row) -> Real| {
        let _ = writeln!(
            s,
            "<DataArray type=\"Float64\" Name=\"{name}\" format=\"ascii\">"
        );
        for r in rows {
            let _ = writeln!(s, "{}", of(r));
        }
        s.push_str("</DataArray>\n");
    };
    s.push_str("<?xml version=\"1.0\"?>\n<VTKFile type=\"PolyData\" version=\"0.1\" byte_order=\"LittleEndian\">\n<PolyData>\n");
    let _ = writeln!(
        s,
        "<Piece NumberOfPoints=\"{}\" NumberOfLines=\"{}\">",
        2 * rows.len(),
        rows.len()
    );
    // The points are the two ends of each line.
    s.push_str(
        "<Points>\n<DataArray type=\"Float64\" NumberOfComponents=\"3\" format=\"ascii\">\n",
    );
    for r in rows {
        let _ = writeln!(
            s,
            "{} {} {}\n{} {} {}",
            r.from.x, r.from.y, r.from.z, r.to.x, r.to.y, r.to.z
        );
    }
    s.push_str("</DataArray>\n</Points>\n<Lines>\n<DataArray type=\"Int64\" Name=\"connectivity\" format=\"ascii\">\n");
    for k in 0..rows.len() {
        let _ = writeln!(s, "{} {}", 2 * k, 2 * k + 1);
    }
    s.push_str("</DataArray>\n<DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">\n");
    for k in 0..rows.len() {
        let _ = writeln!(s, "{}", 2 * (k + 1));
    }
    s.push_str("</DataArray>\n</Lines>\n<CellData Vectors=\"force\">\n");
    vectors(&mut s, "force", &|r| r.state.force_on_b);
    vectors(&mut s, "normal", &|r| r.state.geometry.normal);
    vectors(&mut s, "point", &|r| r.state.geometry.point.coords);
    scalars(&mut s, "depth", &|r| r.state.geometry.depth);
    scalars(&mut s, "normal_force", &|r| {
        r.state.force_on_b.dot(&r.state.geometry.normal)
    });
    s.push_str("</CellData>\n</Piece>\n</PolyData>\n</VTKFile>\n");
    s
}

impl Output for ContactNetwork {
    fn due(&self, step: u64) -> bool {
        self.schedule.due(step)
    }

    fn reads_contacts(&self) -> bool {
        true
    }

    fn write(&mut self, sim: &Simulation, _step: u64) -> io::Result<()> {
        let rows = active_contacts(&sim.world);
        write_csv_rows(&mut self.csv, sim.world.time(), &rows)?;
        self.write_frame(&rows, &sim.world)
    }

    fn flush(&mut self) -> io::Result<()> {
        let path = self.out_dir.join("contacts.csv");
        self.csv
            .flush()
            .and_then(|()| self.csv.get_ref().sync_data())
            .map_err(|e| in_file(&path, "writing", e))
    }

    fn record(&self, record: &mut OutputRecord) {
        record.contacts_every = self.schedule.every;
        record.contact_frames = self.frames.len() as u64;
        record.contact_bytes = self.bytes_written;
    }
}
