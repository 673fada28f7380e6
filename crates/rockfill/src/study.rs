//! The paper's size study (section 4.2, Fig. 8) as one command: for every mean rock size and seed, generate,
//! pack (or reuse the saved bed), penetrate, and tabulate against the paper.
//!
//! Each run writes into `OUT/s{size}mm_seed{seed}/`: the bed (checkpoint `bed.pdck`, `bed_info.json`,
//! `bed_*.csv`), `monitors.csv`, `summary.txt` and `section.svg` (the Fig. 7 picture). After every run the
//! study rewrites `OUT/runs.csv` (one row per run, [`StudyRun::CSV_HEADER`]) and `OUT/study.md` (the table
//! per size with min/mean/max over the seeds, against the paper), so an interrupted study keeps what it
//! measured, and `--reuse-beds` resumes from the saved beds. The runs go seed by seed (every size of the
//! first seed, then the next seed), so an interrupted study still covers every size.
//!
//! # Paper figures compared
//! Residual velocity 1000–1025 m/s for 100–200 mm and about 1100 m/s for 290 mm (read here as
//! 1075–1125 m/s: ± the width of the 100–200 mm band); deflection angles 10°–20°, largest for 290 mm;
//! fluctuation of the resistance larger for large rocks (no figure given: we report the coefficient of
//! variation of the axial resistance, [`super::penetration::ResistanceStatistics`]); affected range 6–7 rock
//! sizes (100 mm sample).
//!
//! # Reduced scale
//! `section_sizes = Some(k)` sets the layer's width and height to k mean rock sizes (the length stays that of
//! the experiment file): the cross-section in rock sizes is then the same for every size, and the rock count
//! grows as 1/size instead of 1/size³. This is how the study fits a short session; it is not the paper's
//! layer, and the report says so.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::time::Instant;

use super::bed::has_checkpoint;
use super::config::ExperimentConfig;
use super::experiment::{run_experiment_with, BedSource, ExperimentError, ExperimentResult};
use super::penetration::{writes_files, Outcome, PenetrationFiles, PenetrationOptions};
use super::section::{draw_sections, SectionError, SectionPicture};
use super::stop::StopCheck;
use polydem::math::Real;

/// Why the study failed.
#[derive(Debug, thiserror::Error)]
pub enum StudyError {
    #[error("size {size_mm} mm, seed {seed}: {source}")]
    Run {
        size_mm: Real,
        seed: u64,
        #[source]
        source: ExperimentError,
    },
    #[error(transparent)]
    Section(#[from] SectionError),
    #[error("{path}: {source}")]
    Io {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
    #[error("study parameters: {0}")]
    Params(String),
    #[error("sensitivity parameters: {0}")]
    SensitivityParams(String),
}

/// What to run.
#[derive(Clone, Debug)]
pub struct StudyParams {
    pub base: ExperimentConfig,
    pub sizes_mm: Vec<Real>,
    pub seeds: Vec<u64>,
    /// Width and height of the layer in mean rock sizes (reduced scale), or the experiment's layer.
    pub section_sizes: Option<Real>,
    /// Start from a bed saved in the run's directory by an earlier study when there is one.
    pub reuse_beds: bool,
    pub out: PathBuf,
    /// A name for the study's provenance line (the experiment file, the profile).
    pub label: String,
}

/// One run's figures (one row of `runs.csv`).
#[derive(Clone, Debug, PartialEq)]
pub struct StudyRun {
    pub size_mm: Real,
    pub seed: u64,
    pub width: Real,
    pub height: Real,
    pub rocks: usize,
    /// "generated", "checkpoint" or "csv".
    pub bed: &'static str,
    /// Wall times (s): generation and packing of the bed (NaN when unknown, a CSV bed without its info),
    /// and penetration.
    pub generation_s: Real,
    pub packing_s: Real,
    pub penetration_s: Real,
    pub solid_fraction: Real,
    pub exited: bool,
    pub residual_speed: Real,
    pub velocity_deflection: Real,
    pub axis_deflection: Real,
    pub max_velocity_deflection: Real,
    pub max_axis_deflection: Real,
    pub resistance_mean: Real,
    pub resistance_cv: Real,
    pub resistance_cv_window: Real,
    pub disturbed_width_sizes: Real,
    /// The width with a displacement threshold of 0.02 mean sizes instead of the experiment's.
    pub disturbed_width_sizes_002: Real,
    /// Largest overlap / particle size of the run.
    pub max_overlap_ratio: Real,
    pub ledger_balance: Real,
}

impl StudyRun {
    pub const CSV_HEADER: &'static str = "size_mm,seed,width_m,height_m,rocks,bed,generation_s,packing_s,penetration_s,solid_fraction,exited,residual_speed,velocity_deflection_deg,axis_deflection_deg,max_velocity_deflection_deg,max_axis_deflection_deg,resistance_mean_n,resistance_cv,resistance_cv_window,disturbed_width_sizes,disturbed_width_sizes_002,max_overlap_ratio,ledger_balance";

    pub fn from_result(size_mm: Real, config: &ExperimentConfig, r: &ExperimentResult) -> Self {
        let p = &r.penetration;
        let (generation_s, packing_s, solid_fraction) = match &r.bed {
            Some(b) => (b.generation_s, b.packing_s, b.solid_fraction),
            None => (Real::NAN, Real::NAN, Real::NAN),
        };
        Self {
            size_mm,
            seed: config.rock.seed,
            width: config.layer.width,
            height: config.layer.height,
            rocks: p.rocks,
            bed: if r.generation.is_some() {
                "generated"
            } else if r.bed_from_checkpoint {
                "checkpoint"
            } else {
                "csv"
            },
            generation_s,
            packing_s,
            penetration_s: p.wall_time.as_secs_f64(),
            solid_fraction,
            exited: p.outcome == Outcome::Exited,
            residual_speed: p.residual_speed,
            velocity_deflection: p.final_velocity_deflection,
            axis_deflection: p.final_axis_deflection,
            max_velocity_deflection: p.max_velocity_deflection,
            max_axis_deflection: p.max_axis_deflection,
            resistance_mean: p.resistance.mean,
            resistance_cv: p.resistance.cv,
            resistance_cv_window: p.resistance.cv_window,
            disturbed_width_sizes: p.disturbed_width_sizes,
            disturbed_width_sizes_002: p
                .disturbed_by_threshold
                .iter()
                .find(|z| z.0 == 0.02)
                .map_or(Real::NAN, |z| z.2),
            max_overlap_ratio: p.max_overlap_ratio,
            ledger_balance: p.ledger_balance_relative,
        }
    }

    pub fn csv_row(&self) -> String {
        format!(
            "{},{},{},{},{},{},{:.3},{:.3},{:.3},{:.4},{},{:.3},{:.4},{:.4},{:.4},{:.4},{:.6e},{:.4},{:.4},{:.3},{:.3},{:.4},{:.3e}",
            self.size_mm,
            self.seed,
            self.width,
            self.height,
            self.rocks,
            self.bed,
            self.generation_s,
            self.packing_s,
            self.penetration_s,
            self.solid_fraction,
            self.exited,
            self.residual_speed,
            self.velocity_deflection,
            self.axis_deflection,
            self.max_velocity_deflection,
            self.max_axis_deflection,
            self.resistance_mean,
            self.resistance_cv,
            self.resistance_cv_window,
            self.disturbed_width_sizes,
            self.disturbed_width_sizes_002,
            self.max_overlap_ratio,
            self.ledger_balance
        )
    }
}

/// The paper's residual-velocity range for a mean size (m/s), see the module docs.
pub fn paper_residual_range(size_mm: Real) -> (Real, Real) {
    if size_mm >= 245.0 {
        (1075.0, 1125.0)
    } else {
        (1000.0, 1025.0)
    }
}

/// The paper's deflection range (degrees).
pub const PAPER_DEFLECTION: (Real, Real) = (10.0, 20.0);

/// The configuration of one run.
pub fn run_config(params: &StudyParams, size_mm: Real, seed: u64) -> ExperimentConfig {
    let mut c = params.base;
    c.rock.mean_size = size_mm * 1e-3;
    c.rock.seed = seed;
    if let Some(k) = params.section_sizes {
        c.layer.width = k * c.rock.mean_size;
        c.layer.height = k * c.rock.mean_size;
    }
    c
}

/// The run's directory.
pub fn run_dir(out: &Path, size_mm: Real, seed: u64) -> PathBuf {
    out.join(format!("s{size_mm}mm_seed{seed}"))
}

fn io_error(path: &Path) -> impl FnOnce(std::io::Error) -> StudyError + '_ {
    move |source| StudyError::Io {
        path: path.to_owned(),
        source,
    }
}

/// Tip positions of the section instants (m): a quarter of the layer (the projectile before the plane
/// x = L/2), half its length past the plane (its body in the plane), the right face; the fourth panel is the
/// end of the run.
pub fn section_instants(config: &ExperimentConfig) -> Vec<Real> {
    let l = config.layer.length;
    vec![0.25 * l, 0.5 * l + 0.5 * config.projectile.length, l]
}

/// Whether `dir` holds a saved bed (checkpoint or CSV).
pub fn has_bed(dir: &Path) -> bool {
    has_checkpoint(dir) || dir.join("bed_rocks.csv").is_file()
}

/// Runs one experiment with the outputs into `dir` (monitors, summary, section picture, and the bed when it
/// is generated). The bed is read from `bed` when given, else generated and packed.
pub fn run_one(
    config: &ExperimentConfig,
    dir: &Path,
    bed: Option<&Path>,
    title: &str,
    progress: &mut dyn FnMut(&str, String),
) -> Result<ExperimentResult, StudyError> {
    run_one_with_stop(config, dir, bed, title, None, progress)
}

/// [`run_one`] whose packing and penetration ask `stop` before each step whether to end there (an
/// `Interrupted` error; nothing is written after the stop).
pub fn run_one_with_stop(
    config: &ExperimentConfig,
    dir: &Path,
    bed: Option<&Path>,
    title: &str,
    stop: Option<StopCheck>,
    progress: &mut dyn FnMut(&str, String),
) -> Result<ExperimentResult, StudyError> {
    let files = PenetrationFiles::monitors_in(dir);
    run_one_with_files(config, files, bed, title, stop, progress)
}

/// [`run_one_with_stop`] into `files.dir`, with the penetration's files of `files` (the monitor series
/// under its name there, VTK frames when asked for).
pub fn run_one_with_files(
    config: &ExperimentConfig,
    files: PenetrationFiles,
    bed: Option<&Path>,
    title: &str,
    stop: Option<StopCheck>,
    progress: &mut dyn FnMut(&str, String),
) -> Result<ExperimentResult, StudyError> {
    let options = PenetrationOptions {
        stop,
        ..PenetrationOptions::default()
    };
    run_one_with_options(config, files, options, bed, title, progress)
}

/// [`run_one_with_files`] with the penetration's other `options` (the files and the section instants are
/// set here). In a run split over MPI ranks ([`PenetrationOptions::distributed`]) only rank 0 writes: the
/// bed, the penetration's files, the summary and the picture.
pub fn run_one_with_options(
    config: &ExperimentConfig,
    files: PenetrationFiles,
    options: PenetrationOptions,
    bed: Option<&Path>,
    title: &str,
    progress: &mut dyn FnMut(&str, String),
) -> Result<ExperimentResult, StudyError> {
    let dir = &files.dir.clone();
    let writes = writes_files(&options);
    if writes {
        std::fs::create_dir_all(dir).map_err(io_error(dir))?;
    }
    let source = match bed {
        Some(b) => BedSource::Load(b),
        None => BedSource::Generate {
            save: writes.then_some(dir.as_path()),
        },
    };
    let options = PenetrationOptions {
        snapshot_tip_x: section_instants(config),
        files: Some(files),
        ..options
    };
    let mut result = run_experiment_with(config, source, &options, progress).map_err(|source| {
        StudyError::Run {
            size_mm: config.rock.mean_size * 1e3,
            seed: config.rock.seed,
            source,
        }
    })?;
    if writes {
        write_run_files(config, &result, dir, title)?;
    }
    // The snapshots are only needed for the picture.
    result.penetration.snapshots.clear();
    Ok(result)
}

/// The packing trace (of a generated bed), the summary and the section picture of a run into `dir`.
fn write_run_files(
    config: &ExperimentConfig,
    result: &ExperimentResult,
    dir: &Path,
    title: &str,
) -> Result<(), StudyError> {
    if let Some(p) = &result.packing {
        let path = dir.join("packing_trace.csv");
        super::packing::write_packing_trace(&path, &p.trace).map_err(io_error(&path))?;
    }
    let text = super::summary::summary(config, result);
    let path = dir.join("summary.txt");
    std::fs::write(&path, &text).map_err(io_error(&path))?;
    draw_run_sections(config, result, &dir.join("section.svg"), title)
}

/// Draws the section picture of a run made with [`section_instants`] snapshots.
pub fn draw_run_sections(
    config: &ExperimentConfig,
    result: &ExperimentResult,
    path: &Path,
    title: &str,
) -> Result<(), StudyError> {
    let p = &result.penetration;
    let world = &result.world;
    let picture = SectionPicture {
        plane_x: 0.5 * config.layer.length,
        width: config.layer.width,
        height: config.layer.height * 1.1,
        mean_size: config.rock.mean_size,
        // Twice the threshold of the disturbed zone: a rock at the threshold is mid-scale.
        displacement_scale: 2.0 * config.impact.disturbed_threshold,
        projectile: world.bodies().len() - 1,
        title,
    };
    draw_sections(path, world, &p.start_positions, &p.snapshots, &picture)?;
    Ok(())
}

/// Runs the study; `progress` gets one line per event worth showing.
pub fn run_study(
    params: &StudyParams,
    progress: &mut dyn FnMut(String),
) -> Result<Vec<StudyRun>, StudyError> {
    if params.sizes_mm.is_empty() || params.seeds.is_empty() {
        return Err(StudyError::Params("no sizes or no seeds".into()));
    }
    if let Some(&s) = params
        .sizes_mm
        .iter()
        .find(|s| !(s.is_finite() && **s > 0.0))
    {
        return Err(StudyError::Params(format!("size {s} mm")));
    }
    std::fs::create_dir_all(&params.out).map_err(io_error(&params.out))?;
    let total = params.sizes_mm.len() * params.seeds.len();
    let start = Instant::now();
    let mut runs: Vec<StudyRun> = Vec::new();
    // Seed-major: an interrupted study has every size of the first seeds.
    for &seed in &params.seeds {
        for &size in &params.sizes_mm {
            let k = runs.len() + 1;
            let config = run_config(params, size, seed);
            let dir = run_dir(&params.out, size, seed);
            let tag = format!("[run {k}/{total} · {size} mm · seed {seed}]");
            progress(format!(
                "{tag} layer {} × {} × {} m, elapsed {:.0} s",
                config.layer.length,
                config.layer.width,
                config.layer.height,
                start.elapsed().as_secs_f64()
            ));
            let mut last_stage = String::new();
            let mut last_print = Instant::now();
            let mut relay = |stage: &str, text: String| {
                if stage != last_stage || last_print.elapsed().as_secs_f64() > 10.0 {
                    progress(format!("{tag} {stage}: {text}"));
                    last_stage = stage.to_owned();
                    last_print = Instant::now();
                }
            };
            let title = format!("{size} mm rocks, seed {seed}");
            let bed = (params.reuse_beds && has_bed(&dir)).then_some(dir.as_path());
            let result = run_one(&config, &dir, bed, &title, &mut relay)?;
            let run = StudyRun::from_result(size, &config, &result);
            progress(format!(
                "{tag} done: {} rocks, residual {:.1} m/s, deflection {:.2}° / {:.2}°, resistance CV {:.3}, penetration {:.1} s",
                run.rocks,
                run.residual_speed,
                run.velocity_deflection,
                run.axis_deflection,
                run.resistance_cv_window,
                run.penetration_s
            ));
            runs.push(run);
            write_outputs(params, &runs)?;
        }
    }
    Ok(runs)
}

/// A CSV file's text: the header line, then one line per row.
pub fn csv_text(header: &str, rows: impl IntoIterator<Item = String>) -> String {
    let mut csv = String::new();
    csv.push_str(header);
    csv.push('\n');
    for row in rows {
        csv.push_str(&row);
        csv.push('\n');
    }
    csv
}

/// Writes `runs.csv` and `study.md`.
pub fn write_outputs(params: &StudyParams, runs: &[StudyRun]) -> Result<(), StudyError> {
    let csv = csv_text(StudyRun::CSV_HEADER, runs.iter().map(StudyRun::csv_row));
    let path = params.out.join("runs.csv");
    std::fs::write(&path, csv).map_err(io_error(&path))?;
    let path = params.out.join("study.md");
    std::fs::write(&path, study_table(params, runs)).map_err(io_error(&path))
}

/// (min, mean, max) of the finite values.
pub fn spread(values: impl IntoIterator<Item = Real>) -> (Real, Real, Real) {
    let v: Vec<Real> = values.into_iter().filter(|x| x.is_finite()).collect();
    if v.is_empty() {
        return (Real::NAN, Real::NAN, Real::NAN);
    }
    let min = v.iter().copied().fold(Real::INFINITY, Real::min);
    let max = v.iter().copied().fold(Real::NEG_INFINITY, Real::max);
    (min, v.iter().sum::<Real>() / v.len() as Real, max)
}

fn fmt_spread((min, mean, max): (Real, Real, Real), digits: usize) -> String {
    if min == max {
        format!("{mean:.digits$}")
    } else {
        format!("{min:.digits$} / {mean:.digits$} / {max:.digits$}")
    }
}

/// The study's table per size (markdown).
pub fn study_table(params: &StudyParams, runs: &[StudyRun]) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "# Rockfill size study ({})\n", params.label);
    let l = &params.base.layer;
    let layer = match params.section_sizes {
        Some(k) => format!(
            "length {} m, width and height {k} mean rock sizes (reduced scale; the paper's layer is 3.5 m × 2.7 m × 3.5 m)",
            l.length
        ),
        None => format!("{} m × {} m × {} m", l.length, l.width, l.height),
    };
    let _ = writeln!(
        s,
        "Layer {layer}; polydem {}. Values min / mean / max over the seeds (one value when equal). \
         Deflections at the end of the run. Resistance CV: std/mean of the axial resistance averaged over \
         windows of one rock size of travel, while the projectile is in the layer.\n",
        env!("CARGO_PKG_VERSION")
    );
    let _ = writeln!(
        s,
        "| size (mm) | seeds | rocks | generation (s) | packing (s) | penetration (s) | exited | residual (m/s) | paper (m/s) | velocity deflection (°) | axis deflection (°) | paper (°) | resistance CV | disturbed width (sizes) |"
    );
    let _ = writeln!(
        s,
        "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"
    );
    for &size in &params.sizes_mm {
        let r: Vec<&StudyRun> = runs.iter().filter(|r| r.size_mm == size).collect();
        if r.is_empty() {
            continue;
        }
        let (lo, hi) = paper_residual_range(size);
        let seeds: Vec<String> = r.iter().map(|x| x.seed.to_string()).collect();
        let _ = writeln!(
            s,
            "| {size} | {} | {} | {} | {} | {} | {}/{} | {} | {lo}–{hi} | {} | {} | {}–{} | {} | {} |",
            seeds.join(","),
            fmt_spread(spread(r.iter().map(|x| x.rocks as Real)), 0),
            fmt_spread(spread(r.iter().map(|x| x.generation_s)), 2),
            fmt_spread(spread(r.iter().map(|x| x.packing_s)), 0),
            fmt_spread(spread(r.iter().map(|x| x.penetration_s)), 1),
            r.iter().filter(|x| x.exited).count(),
            r.len(),
            fmt_spread(spread(r.iter().map(|x| x.residual_speed)), 1),
            fmt_spread(spread(r.iter().map(|x| x.velocity_deflection)), 2),
            fmt_spread(spread(r.iter().map(|x| x.axis_deflection)), 2),
            PAPER_DEFLECTION.0,
            PAPER_DEFLECTION.1,
            fmt_spread(spread(r.iter().map(|x| x.resistance_cv_window)), 3),
            fmt_spread(spread(r.iter().map(|x| x.disturbed_width_sizes)), 2),
        );
    }
    s
}
