//! Convergence of the experiment's results: the time step of the penetration run, and the rock count
//! through the layer's cross-section, on the residual velocity and the deflection angles; plotted as run time
//! against the change in the result (a work-precision plot).
//!
//! # Time step
//! One packed bed (the checkpoint, so every run starts from the same state bit for bit); the penetration run
//! at Δt / k for each divisor k. The change of a result is taken against the run with the smallest Δt, and
//! the successive differences |r(Δt/k_i) − r(Δt/k_{i+1})| are listed: a converging sequence has them
//! shrinking. (The penetration of a granular bed is a chaotic many-contact process: a change of Δt changes
//! the sequence of rock impacts, so shrinking differences are a finding, not a given.)
//!
//! # Rock count
//! The layer's width = height = w for each w (the length and the rock size fixed), each bed generated and
//! packed anew with the same seed: the rock count grows as w². The change is taken against the largest w.
//! Run time is generation + packing + penetration.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use plotters::prelude::*;

use super::config::ExperimentConfig;
use super::experiment::{run_experiment_with, BedSource};
use super::penetration::{PenetrationFiles, PenetrationOptions, PenetrationReport};
use super::study::{has_bed, run_one, StudyError};
use polydem::math::Real;

/// What to run.
#[derive(Clone, Debug)]
pub struct ConvergenceParams {
    pub base: ExperimentConfig,
    /// Divisors k of the penetration Δt (1 = the experiment's).
    pub dt_divisors: Vec<Real>,
    /// Layer widths = heights (m) of the rock-count sequence; empty to skip it.
    pub sections: Vec<Real>,
    pub out: PathBuf,
    /// A bed directory to start the time-step sequence from (else one is generated and packed).
    pub bed: Option<PathBuf>,
    pub label: String,
}

/// Which sequence a row belongs to.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Sequence {
    TimeStep,
    CrossSection,
}

impl Sequence {
    pub fn name(self) -> &'static str {
        match self {
            Sequence::TimeStep => "time_step",
            Sequence::CrossSection => "cross_section",
        }
    }
}

/// One run of a sequence.
#[derive(Clone, Debug, PartialEq)]
pub struct ConvergenceRow {
    pub sequence: Sequence,
    /// The divisor k (time step) or the width w in m (cross-section).
    pub parameter: Real,
    pub dt: Real,
    pub rocks: usize,
    pub steps: u64,
    /// Run time (s): penetration (time step) or generation + packing + penetration (cross-section).
    pub run_s: Real,
    pub residual_speed: Real,
    pub velocity_deflection: Real,
    pub axis_deflection: Real,
    pub exited: bool,
}

impl ConvergenceRow {
    pub const CSV_HEADER: &'static str = "sequence,parameter,dt_s,rocks,steps,run_s,residual_speed,velocity_deflection_deg,axis_deflection_deg,exited,residual_change,velocity_deflection_change,axis_deflection_change";
}

/// The sequences' rows, with changes against the reference run of each (smallest Δt, largest section).
#[derive(Clone, Debug, Default)]
pub struct ConvergenceResult {
    pub rows: Vec<ConvergenceRow>,
}

impl ConvergenceResult {
    /// The rows of one sequence, in run order.
    pub fn sequence(&self, s: Sequence) -> Vec<&ConvergenceRow> {
        self.rows.iter().filter(|r| r.sequence == s).collect()
    }

    /// The reference row of a sequence: the smallest Δt, the largest cross-section.
    pub fn reference(&self, s: Sequence) -> Option<&ConvergenceRow> {
        let rows = self.sequence(s);
        match s {
            Sequence::TimeStep => rows.into_iter().min_by(|a, b| a.dt.total_cmp(&b.dt)),
            Sequence::CrossSection => rows
                .into_iter()
                .max_by(|a, b| a.parameter.total_cmp(&b.parameter)),
        }
    }

    /// |change| of the residual speed, velocity and axis deflection of `row` against its reference.
    pub fn change(&self, row: &ConvergenceRow) -> [Real; 3] {
        match self.reference(row.sequence) {
            Some(r) => [
                (row.residual_speed - r.residual_speed).abs(),
                (row.velocity_deflection - r.velocity_deflection).abs(),
                (row.axis_deflection - r.axis_deflection).abs(),
            ],
            None => [Real::NAN; 3],
        }
    }

    /// Successive differences of the time-step sequence (in run order): |r_i − r_{i+1}| for the residual
    /// speed, velocity and axis deflection.
    pub fn successive_differences(&self) -> Vec<[Real; 3]> {
        self.sequence(Sequence::TimeStep)
            .windows(2)
            .map(|w| {
                [
                    (w[0].residual_speed - w[1].residual_speed).abs(),
                    (w[0].velocity_deflection - w[1].velocity_deflection).abs(),
                    (w[0].axis_deflection - w[1].axis_deflection).abs(),
                ]
            })
            .collect()
    }

    pub fn csv(&self) -> String {
        let mut s = String::from(ConvergenceRow::CSV_HEADER);
        s.push('\n');
        for r in &self.rows {
            let c = self.change(r);
            let _ = writeln!(
                s,
                "{},{},{:.6e},{},{},{:.3},{:.4},{:.4},{:.4},{},{:.4},{:.4},{:.4}",
                r.sequence.name(),
                r.parameter,
                r.dt,
                r.rocks,
                r.steps,
                r.run_s,
                r.residual_speed,
                r.velocity_deflection,
                r.axis_deflection,
                r.exited,
                c[0],
                c[1],
                c[2]
            );
        }
        s
    }
}

fn io_error(path: &Path) -> impl FnOnce(std::io::Error) -> StudyError + '_ {
    move |source| StudyError::Io {
        path: path.to_owned(),
        source,
    }
}

/// Runs the sequences (see the module docs); writes `convergence.csv`, `work_precision.svg` into `out`.
pub fn run_convergence(
    params: &ConvergenceParams,
    progress: &mut dyn FnMut(String),
) -> Result<ConvergenceResult, StudyError> {
    check_params(params)?;
    std::fs::create_dir_all(&params.out).map_err(io_error(&params.out))?;
    let mut result = ConvergenceResult::default();
    if !params.dt_divisors.is_empty() {
        time_step_sequence(params, &mut result, progress)?;
    }
    for &w in &params.sections {
        section_run(params, w, &mut result, progress)?;
    }
    Ok(result)
}

/// Refuses divisors and sections that are not finite and positive.
fn check_params(params: &ConvergenceParams) -> Result<(), StudyError> {
    if params
        .dt_divisors
        .iter()
        .any(|k| !(k.is_finite() && *k > 0.0))
    {
        return Err(StudyError::Params(format!(
            "time-step divisors {:?}: each must be positive (below 1 coarsens the step)",
            params.dt_divisors
        )));
    }
    if params.sections.iter().any(|w| !(w.is_finite() && *w > 0.0)) {
        return Err(StudyError::Params(format!(
            "sections {:?}: each must be positive (m)",
            params.sections
        )));
    }
    Ok(())
}

/// The time-step sequence: one bed (given, or generated and packed into `out/bed`), penetrated at each
/// divisor of the experiment's Δt; the outputs rewritten after each run.
fn time_step_sequence(
    params: &ConvergenceParams,
    result: &mut ConvergenceResult,
    progress: &mut dyn FnMut(String),
) -> Result<(), StudyError> {
    let mut quiet = |_: &str, _: String| {};
    let bed_dir = match &params.bed {
        Some(dir) => dir.clone(),
        None => {
            let dir = params.out.join("bed");
            progress(format!(
                "time step: generating and packing the bed into {}",
                dir.display()
            ));
            let reuse = has_bed(&dir).then_some(dir.as_path());
            run_one(&params.base, &dir, reuse, "convergence bed", &mut quiet)?;
            dir
        }
    };
    for &k in &params.dt_divisors {
        let options = PenetrationOptions {
            dt_divisor: k,
            files: Some(PenetrationFiles {
                monitors: format!("monitors_dt_div{k}.csv"),
                ..PenetrationFiles::monitors_in(&params.out)
            }),
            ..PenetrationOptions::default()
        };
        let r = run_experiment_with(
            &params.base,
            BedSource::Load(&bed_dir),
            &options,
            &mut quiet,
        )
        .map_err(|source| StudyError::Run {
            size_mm: params.base.rock.mean_size * 1e3,
            seed: params.base.rock.seed,
            source,
        })?;
        let p = &r.penetration;
        progress(format!(
            "time step Δt/{k} = {:.3e} s: {} steps, {:.1} s, residual {:.2} m/s, deflection {:.3}° / {:.3}°",
            p.dt,
            p.steps,
            p.wall_time.as_secs_f64(),
            p.residual_speed,
            p.final_velocity_deflection,
            p.final_axis_deflection
        ));
        let run_s = p.wall_time.as_secs_f64();
        result
            .rows
            .push(ConvergenceRow::of(Sequence::TimeStep, k, p, run_s));
        write_outputs(params, result)?;
    }
    Ok(())
}

/// One run of the cross-section sequence: a layer `w` × `w` generated, packed and penetrated (its bed
/// kept in `out/section_<w>m` and reused when there); the outputs rewritten after it.
fn section_run(
    params: &ConvergenceParams,
    w: Real,
    result: &mut ConvergenceResult,
    progress: &mut dyn FnMut(String),
) -> Result<(), StudyError> {
    let mut quiet = |_: &str, _: String| {};
    let mut config = params.base;
    config.layer.width = w;
    config.layer.height = w;
    let dir = params.out.join(format!("section_{w}m"));
    let title = format!("cross-section {w} m × {w} m");
    let reuse = has_bed(&dir).then_some(dir.as_path());
    let r = run_one(&config, &dir, reuse, &title, &mut quiet)?;
    let p = &r.penetration;
    let run_s = r
        .bed
        .as_ref()
        .map_or(Real::NAN, |b| b.generation_s + b.packing_s)
        + p.wall_time.as_secs_f64();
    progress(format!(
        "cross-section {w} m: {} rocks, {:.1} s, residual {:.2} m/s, deflection {:.3}° / {:.3}°",
        p.rocks, run_s, p.residual_speed, p.final_velocity_deflection, p.final_axis_deflection
    ));
    result
        .rows
        .push(ConvergenceRow::of(Sequence::CrossSection, w, p, run_s));
    write_outputs(params, result)
}

impl ConvergenceRow {
    /// The row of a run of `sequence` at `parameter` that took `run_s` seconds.
    fn of(sequence: Sequence, parameter: Real, p: &PenetrationReport, run_s: f64) -> Self {
        Self {
            sequence,
            parameter,
            dt: p.dt,
            rocks: p.rocks,
            steps: p.steps,
            run_s,
            residual_speed: p.residual_speed,
            velocity_deflection: p.final_velocity_deflection,
            axis_deflection: p.final_axis_deflection,
            exited: p.outcome == super::penetration::Outcome::Exited,
        }
    }
}

fn write_outputs(params: &ConvergenceParams, result: &ConvergenceResult) -> Result<(), StudyError> {
    let path = params.out.join("convergence.csv");
    std::fs::write(&path, result.csv()).map_err(io_error(&path))?;
    let path = params.out.join("work_precision.svg");
    work_precision_plot(&path, result, &params.label)
}

/// Run time against |change| of the residual speed (left) and of the axis deflection (right), log–log; the
/// reference run of each sequence (change 0) is not drawn.
pub fn work_precision_plot(
    path: &Path,
    result: &ConvergenceResult,
    label: &str,
) -> Result<(), StudyError> {
    let err = |e: String| StudyError::Io {
        path: path.to_owned(),
        source: std::io::Error::other(e),
    };
    let root = SVGBackend::new(path, (1000, 440)).into_drawing_area();
    root.fill(&WHITE).map_err(|e| err(e.to_string()))?;
    let panels = root.split_evenly((1, 2));
    let quantities = [
        (0usize, "|change of residual speed| (m/s)"),
        (2usize, "|change of axis deflection| (°)"),
    ];
    for (area, (q, y_label)) in panels.iter().zip(quantities) {
        let points: Vec<(Sequence, Real, Real)> = result
            .rows
            .iter()
            .map(|r| (r.sequence, r.run_s, result.change(r)[q]))
            .filter(|(_, t, c)| t.is_finite() && *t > 0.0 && c.is_finite() && *c > 0.0)
            .collect();
        let (t_lo, t_hi, c_lo, c_hi) = if points.is_empty() {
            (1.0, 10.0, 1e-3, 1.0)
        } else {
            let f = |it: &dyn Fn(&(Sequence, Real, Real)) -> Real, min: bool| {
                points.iter().map(it).fold(
                    if min { Real::INFINITY } else { 0.0 },
                    if min { Real::min } else { Real::max },
                )
            };
            (
                f(&|p| p.1, true) / 2.0,
                f(&|p| p.1, false) * 2.0,
                f(&|p| p.2, true) / 3.0,
                f(&|p| p.2, false) * 3.0,
            )
        };
        let mut chart = ChartBuilder::on(area)
            .caption(format!("Work–precision, {label}"), ("sans-serif", 15))
            .margin(10)
            .x_label_area_size(36)
            .y_label_area_size(60)
            .build_cartesian_2d((t_lo..t_hi).log_scale(), (c_lo..c_hi).log_scale())
            .map_err(|e| err(e.to_string()))?;
        chart
            .configure_mesh()
            .x_desc("run time (s)")
            .y_desc(y_label)
            .draw()
            .map_err(|e| err(e.to_string()))?;
        for (seq, colour, name) in [
            (
                Sequence::TimeStep,
                BLUE,
                "time step Δt/k (penetration time)",
            ),
            (
                Sequence::CrossSection,
                RED,
                "cross-section (generation + packing + penetration)",
            ),
        ] {
            let pts: Vec<(Real, Real)> = points
                .iter()
                .filter(|p| p.0 == seq)
                .map(|p| (p.1, p.2))
                .collect();
            if pts.is_empty() {
                continue;
            }
            chart
                .draw_series(LineSeries::new(pts.clone(), colour.stroke_width(2)))
                .map_err(|e| err(e.to_string()))?
                .label(name)
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], colour));
            chart
                .draw_series(pts.iter().map(|&p| Circle::new(p, 4, colour.filled())))
                .map_err(|e| err(e.to_string()))?;
        }
        chart
            .configure_series_labels()
            .position(SeriesLabelPosition::LowerRight)
            .background_style(WHITE.mix(0.8))
            .border_style(BLACK)
            .draw()
            .map_err(|e| err(e.to_string()))?;
    }
    root.present().map_err(|e| err(e.to_string()))?;
    Ok(())
}
