//! VTK frames of a run split over ranks, as parallel pieces that ParaView opens as one dataset.
//!
//! At each frame every rank writes the bodies it owns as a piece, `vtk/<series>_<step>_<rank>.vtu` (the
//! engine's writer of the series, [`polydem::io::vtk`], on the rank's part: the same arrays, each body's
//! `body` value its index in the whole world), and rank 0 writes `vtk/<series>_<step>.pvtu` listing the
//! pieces and `<series>.pvd` listing the `.pvtu` files with their times. The walls are one file written by
//! rank 0 from the gathered world, `vtk/walls_<step>.vtu` in `walls.pvd`, as in a run of one process. The
//! `.pvtu` declares the arrays of rank 0's piece (every piece has the same arrays, an empty one included).
//! A run of one process writes `.vtu` frames of the whole world instead (`polydem::io::vtk`).

use std::fmt::Write as _;
use std::io;
use std::path::{Path, PathBuf};

use polydem::io::output::Schedule;
use polydem::io::vtk::{
    earlier_entries, polyhedra_piece_vtu, replace_pvd, series_kinds, spheres_piece_vtu,
    surfaces_piece_vtu, walls_vtu, BodyPiece, SeriesKind, VtkEncoding,
};
use polydem::math::Real;
use polydem::world::World;

/// The piece writer of one rank.
pub struct VtkPieces {
    out_dir: PathBuf,
    encoding: VtkEncoding,
    schedule: Schedule,
    rank: usize,
    ranks: usize,
    /// The series and, on rank 0, the entries of their `.pvd`.
    series: Vec<(SeriesKind, Vec<(Real, String)>)>,
    /// Bytes this rank wrote to frame files.
    pub bytes_written: u64,
    /// Frames written.
    pub frames_written: u64,
}

impl VtkPieces {
    /// The writer of rank `rank` of `ranks` for the series `whole` needs, frames in `out_dir/vtk` at the
    /// steps of `schedule`. With `resume` (a restart into the same directory) rank 0 keeps the frames the
    /// `.pvd` files list before the world's step.
    pub fn new(
        out_dir: &Path,
        whole: &World,
        encoding: VtkEncoding,
        schedule: Schedule,
        (rank, ranks): (usize, usize),
        resume: bool,
    ) -> io::Result<Self> {
        encoding.check()?;
        std::fs::create_dir_all(out_dir.join("vtk")).map_err(|e| {
            io::Error::new(
                e.kind(),
                format!("cannot create {}/vtk: {e}", out_dir.display()),
            )
        })?;
        let series = series_kinds(whole)
            .into_iter()
            .map(|kind| (kind, Vec::new()))
            .collect();
        let mut pieces = Self {
            out_dir: out_dir.to_owned(),
            encoding,
            schedule,
            rank,
            ranks,
            series,
            bytes_written: 0,
            frames_written: 0,
        };
        if resume && rank == 0 {
            pieces.resume(whole.step_index())?;
        }
        Ok(pieces)
    }

    /// Whether a frame is due after step `step`.
    pub fn due(&self, step: u64) -> bool {
        self.schedule.due(step)
    }

    fn resume(&mut self, step: u64) -> io::Result<()> {
        for (kind, entries) in &mut self.series {
            *entries = earlier_entries(&self.out_dir, *kind, step)?;
        }
        Ok(())
    }

    /// Writes this rank's pieces of the frame: the bodies `piece` of its part `part`; rank 0 also the
    /// `.pvtu` files, the walls from the gathered `whole` and the `.pvd` collections.
    pub fn write(
        &mut self,
        part: &World,
        piece: &BodyPiece,
        whole: Option<&World>,
    ) -> io::Result<()> {
        let step = part.step_index();
        for k in 0..self.series.len() {
            let kind = self.series[k].0;
            let stem = format!("{}_{step:09}", kind.name());
            let mut text = String::new();
            let frame = if kind == SeriesKind::Walls {
                let Some(whole) = whole else { continue };
                walls_vtu(&mut text, whole, self.encoding);
                format!("vtk/{stem}.vtu")
            } else {
                body_piece(&mut text, kind, part, piece, self.encoding);
                self.write_file(&format!("vtk/{stem}_{:04}.vtu", self.rank), &text)?;
                if self.rank != 0 {
                    continue;
                }
                text = parallel_file(&text, &stem, self.ranks);
                format!("vtk/{stem}.pvtu")
            };
            self.write_file(&frame, &text)?;
            let entries = &mut self.series[k].1;
            entries.retain(|(_, f)| *f != frame);
            entries.push((part.time(), frame));
            replace_pvd(&self.out_dir, kind, entries)?;
        }
        self.frames_written += 1;
        Ok(())
    }

    fn write_file(&mut self, relative: &str, text: &str) -> io::Result<()> {
        let path = self.out_dir.join(relative);
        std::fs::write(&path, text)
            .map_err(|e| io::Error::new(e.kind(), format!("writing {}: {e}", path.display())))?;
        self.bytes_written += text.len() as u64;
        Ok(())
    }
}

fn body_piece(out: &mut String, kind: SeriesKind, part: &World, piece: &BodyPiece, e: VtkEncoding) {
    match kind {
        SeriesKind::Polyhedra => polyhedra_piece_vtu(out, part, e, piece),
        SeriesKind::Spheres => spheres_piece_vtu(out, part, e, piece),
        SeriesKind::Surfaces => surfaces_piece_vtu(out, part, e, piece),
        SeriesKind::Walls => unreachable!("walls are not a body series"),
    };
}

/// The `.pvtu` of the pieces `<stem>_<rank>.vtu` of `ranks` ranks, declaring the arrays of `piece` (the
/// text of one of them).
fn parallel_file(piece: &str, stem: &str, ranks: usize) -> String {
    let mut out = String::new();
    out.push_str("<?xml version=\"1.0\"?>\n");
    let header = piece
        .lines()
        .find(|l| l.starts_with("<VTKFile"))
        .unwrap_or("<VTKFile>");
    out.push_str(&header.replace("\"UnstructuredGrid\"", "\"PUnstructuredGrid\""));
    out.push('\n');
    out.push_str("  <PUnstructuredGrid GhostLevel=\"0\">\n");
    let mut section: Option<&str> = None;
    for line in piece.lines().map(str::trim) {
        let opened = ["Points", "PointData", "CellData"]
            .into_iter()
            .find(|s| line.starts_with(&format!("<{s}>")) || line.starts_with(&format!("<{s} ")));
        if let Some(s) = opened {
            section = Some(s);
            let _ = writeln!(out, "    <P{}", &line[1..]);
        } else if let Some(s) = section.filter(|s| line == format!("</{s}>")) {
            let _ = writeln!(out, "    </P{s}>");
            section = None;
        } else if section.is_some() && line.starts_with("<DataArray ") {
            let declaration = line.split(" format=").next().unwrap_or(line);
            let _ = writeln!(out, "      <P{}/>", &declaration[1..]);
        }
    }
    for rank in 0..ranks {
        let _ = writeln!(out, "    <Piece Source=\"{stem}_{rank:04}.vtu\"/>");
    }
    out.push_str("  </PUnstructuredGrid>\n</VTKFile>\n");
    out
}
