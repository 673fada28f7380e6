//! Rockfill: the paper's experiment through `polydem_rockfill` — generation, packing, penetration.
//!
//! Checks that can fail: the realised size distribution against the law eq. 29 samples, the energy ledger of
//! packing and of penetration, finite state, the projectile leaving the layer, and its residual velocity
//! against the paper's range; the time-step sequence of the penetration run (Δt, Δt/2, Δt/4, Δt/8 from the
//! same saved bed checkpoint) converging, i.e. successive differences of the residual speed and of the axis
//! deflection shrinking over a fourfold refinement of Δt. Deflection angles, the resistance fluctuation and
//! the disturbed zone are reported against the paper's figures, not gated (the quick variant's cross-section
//! is too small for them to be comparable). The section picture (paper Fig. 7) of the first seed goes into
//! the case's folder.

use polydem::math::Real;
use polydem_rockfill::config::ExperimentConfig;
use polydem_rockfill::convergence::{
    run_convergence, ConvergenceParams, ConvergenceResult, ConvergenceRow, Sequence,
};
use polydem_rockfill::experiment::ExperimentResult;
use polydem_rockfill::penetration::{MonitorRow, Outcome};
use polydem_rockfill::study::run_one;

use super::rockfill_dt_spread::{check_pair, SpreadParams};
use crate::case::{Case, CaseData, Profile, Target};
use crate::context::CaseContext;
use crate::error::SuiteError;
use crate::plot::{Plot, Series, SeriesStyle};

pub struct Rockfill;

#[derive(serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct Params {
    /// "quick" or "paper": the compiled-in experiment file.
    config: String,
    seeds: Vec<u64>,
    /// Divisors k of the penetration Δt for the time-step sequence (from the first seed's bed); empty: none.
    /// Must include 1, 2 and `coarse_dt_divisor`, half of it.
    dt_divisors: Vec<Real>,
    /// A divisor below 1 (a coarse Δt) at which the convergence check must flag the change.
    coarse_dt_divisor: Real,
    /// The aim displacement of the perturbed runs, in mean rock sizes.
    perturbation_size_fraction: Real,
    /// Number of perturbed runs per judged time step.
    perturbations: usize,
}

fn case_error(msg: String) -> SuiteError {
    SuiteError::case("rockfill", msg)
}

/// The gates of one seed's run, read once from the case data.
struct Gates {
    size_mean_se: Real,
    packing_ledger: Real,
    penetration_ledger: Real,
    residual_low: Real,
    residual_high: Real,
}

impl Gates {
    fn read(data: &CaseData) -> Result<Self, SuiteError> {
        let name = "rockfill";
        Ok(Gates {
            size_mean_se: data.tolerance(name, "size_mean_se")?.value,
            packing_ledger: data.tolerance(name, "packing_ledger")?.value,
            penetration_ledger: data.tolerance(name, "penetration_ledger")?.value,
            residual_low: data.reference(name, "residual_low")?.value,
            residual_high: data.reference(name, "residual_high")?.value,
        })
    }
}

impl Case for Rockfill {
    fn name(&self) -> &'static str {
        "rockfill"
    }

    fn data(&self) -> &'static str {
        include_str!("../../cases/rockfill.toml")
    }

    fn run(
        &self,
        data: &CaseData,
        profile: Profile,
        ctx: &mut CaseContext,
    ) -> Result<(), SuiteError> {
        let p: Params = data.params(self.name(), profile)?;
        let base = match p.config.as_str() {
            "quick" => ExperimentConfig::quick(),
            "paper" => ExperimentConfig::paper(),
            other => {
                return Err(case_error(format!(
                    "unknown config '{other}' (quick or paper)"
                )))
            }
        };
        let gates = Gates::read(data)?;
        ctx.progress()
            .stage("runs", (p.seeds.len() + p.dt_divisors.len()) as u64);
        let mut rows = Vec::new();
        let mut shape_rows = Vec::new();
        let mut results: Vec<(u64, ExperimentResult)> = Vec::new();
        // Beds (checkpoints) and per-run files go to a scratch directory; the section picture is copied into
        // the report folder.
        let scratch =
            std::env::temp_dir().join(format!("polydem_rockfill_case_{}", std::process::id()));
        for &seed in &p.seeds {
            let r = run_seed(ctx, base, seed, &scratch.join(format!("seed_{seed}")))?;
            check_seed(ctx, &gates, seed, &r);
            rows.push(run_row(seed, &r));
            shape_rows.push(shape_row(seed, &r));
            results.push((seed, r));
            ctx.progress().inc(1);
        }
        report_runs(ctx, &base, &p.seeds, &rows)?;
        if let (Some(&seed), false) = (p.seeds.first(), p.dt_divisors.is_empty()) {
            let mut config = base;
            config.rock.seed = seed;
            let bed = scratch.join(format!("seed_{seed}"));
            let first = results.first().map(|(_, r)| r);
            time_step_convergence(ctx, data, &p, &config, &bed, &scratch, first)?;
        }
        std::fs::remove_dir_all(&scratch).ok();
        report_shapes(ctx, &shape_rows)?;
        monitor_plots(ctx, &results)
    }
}

/// Runs the experiment of `seed` in `dir` and copies its section picture into the report folder.
fn run_seed(
    ctx: &mut CaseContext,
    base: ExperimentConfig,
    seed: u64,
    dir: &std::path::Path,
) -> Result<ExperimentResult, SuiteError> {
    let mut config = base;
    config.rock.seed = seed;
    let mut progress = |_: &str, _: String| {};
    let title = format!(
        "quick variant, {} mm rocks, seed {seed}",
        config.rock.mean_size * 1e3
    );
    let r = run_one(&config, dir, None, &title, &mut progress)
        .map_err(|e| case_error(format!("seed {seed}: {e}")))?;
    if let Some(out) = ctx.output_dir()? {
        let to = out.join(format!("section_seed_{seed}.svg"));
        std::fs::copy(dir.join("section.svg"), &to).map_err(|e| {
            case_error(format!(
                "copying the section picture to {}: {e}",
                to.display()
            ))
        })?;
    }
    Ok(r)
}

/// The gated rows of one seed's run: the size law, the ledgers, finite state, the exit and the residual
/// speed against the paper's range.
fn check_seed(ctx: &mut CaseContext, gates: &Gates, seed: u64, r: &ExperimentResult) {
    let g = r.generation.as_ref().expect("generated");
    let pk = r.packing.as_ref().expect("packed");
    let pen = &r.penetration;
    let tag = format!("seed_{seed}");
    let n = g.statistics.diameter.count as Real;
    let se = g.requested_std / n.sqrt();
    ctx.check(
        &format!("size_mean_error_{tag}"),
        (g.statistics.diameter.mean - g.requested_mean).abs() / se,
        Target::at_most(gates.size_mean_se),
        "standard errors",
    );
    for (stage, b) in ["deposition", "compaction", "hold"]
        .iter()
        .zip(pk.ledger_balance_relative)
    {
        ctx.check(
            &format!("packing_ledger_{stage}_{tag}"),
            b.abs(),
            Target::at_most(gates.packing_ledger),
            "1",
        );
    }
    let finite = pen.rows.iter().all(|row| {
        row.velocity
            .iter()
            .chain(row.position.iter())
            .all(|x| x.is_finite())
    });
    ctx.check(
        &format!("finite_state_{tag}"),
        finite as u8 as f64,
        Target::equal(1.0),
        "1",
    );
    ctx.check(
        &format!("penetration_ledger_{tag}"),
        pen.ledger_balance_relative.abs(),
        Target::at_most(gates.penetration_ledger),
        "1",
    );
    ctx.check(
        &format!("projectile_exits_{tag}"),
        (pen.outcome == Outcome::Exited) as u8 as f64,
        Target::equal(1.0),
        "1",
    );
    ctx.check(
        &format!("residual_velocity_low_{tag}"),
        pen.residual_speed,
        Target::at_least(gates.residual_low),
        "m/s",
    );
    ctx.check(
        &format!("residual_velocity_high_{tag}"),
        pen.residual_speed,
        Target::at_most(gates.residual_high),
        "m/s",
    );
}

/// One seed's row of the runs table.
fn run_row(seed: u64, r: &ExperimentResult) -> Vec<String> {
    let g = r.generation.as_ref().expect("generated");
    let pk = r.packing.as_ref().expect("packed");
    let pen = &r.penetration;
    vec![
        format!("{seed}"),
        format!("{}", g.rocks),
        format!("{:.2}", g.wall_time.as_secs_f64()),
        format!("{:.1}", pk.wall_time.as_secs_f64()),
        format!("{:.3}", pk.solid_fraction),
        format!("{:.3}", pk.top_wall),
        format!("{:.1}", pen.wall_time.as_secs_f64()),
        format!("{:?}", pen.outcome),
        format!("{:.1}", pen.residual_speed),
        format!("{:.2}", pen.final_velocity_deflection),
        format!("{:.2}", pen.final_axis_deflection),
        format!("{:.3}", pen.resistance.cv_window),
        format!("{:.2}", pen.disturbed_width_sizes),
        CaseContext::fmt(pen.ledger_balance_relative),
    ]
}

/// One seed's row of the sample table: realised sizes and shapes.
fn shape_row(seed: u64, r: &ExperimentResult) -> Vec<String> {
    let g = r.generation.as_ref().expect("generated");
    let s = &g.statistics;
    vec![
        format!("{seed}"),
        format!("{:.4} / {:.4}", s.diameter.mean, g.requested_mean),
        format!("{:.4} / {:.4}", s.diameter.std, g.requested_std),
        format!(
            "{:.1} ({:.0}–{:.0})",
            s.vertices.mean, s.vertices.min, s.vertices.max
        ),
        format!(
            "{:.1} ({:.0}–{:.0})",
            s.faces.mean, s.faces.min, s.faces.max
        ),
        format!(
            "{:.2} ({:.2}–{:.2})",
            s.aspect_ellipsoid.mean, s.aspect_ellipsoid.min, s.aspect_ellipsoid.max
        ),
        format!("{}", g.dropped_small_cells),
    ]
}

/// The runs table and the section pictures.
fn report_runs(
    ctx: &mut CaseContext,
    base: &ExperimentConfig,
    seeds: &[u64],
    rows: &[Vec<String>],
) -> Result<(), SuiteError> {
    let l = &base.layer;
    ctx.section("Runs");
    ctx.text(&format!(
        "Layer {} m × {} m × {} m, mean rock size {} mm, Table 1 contact parameters, rock density {} kg/m³. \
         Paper (§4.2): residual velocity 1000–1025 m/s for 100–200 mm and ≈ 1100 m/s for 290 mm; deflection \
         angles 10°–20°; affected range 6–7 rock sizes (100 mm sample).",
        l.length, l.width, l.height, base.rock.mean_size * 1e3, base.rock.density
    ));
    ctx.table(
        Some("runs"),
        &[
            "seed",
            "rocks",
            "generation (s)",
            "packing (s)",
            "solid fraction",
            "layer height (m)",
            "penetration (s)",
            "outcome",
            "residual speed (m/s)",
            "velocity deflection (°)",
            "axis deflection (°)",
            "resistance CV",
            "disturbed width (sizes)",
            "ledger balance",
        ],
        rows,
    )?;
    ctx.text(
        "Resistance CV: standard deviation / mean of the axial resistance −F·e₀ averaged over windows of one \
         mean rock size of travel, while the projectile is in the layer (the paper: the fluctuation is larger \
         for large rocks, no figure given).",
    );
    if ctx.writes_files() {
        ctx.section("Section at x = L/2 (paper Fig. 7)");
        for &seed in seeds {
            ctx.text(&format!(
                "![Section, seed {seed}](rockfill/section_seed_{seed}.svg)\n\nRocks cut by the plane x = L/2, \
                 coloured by their displacement since the start of the run (0 to ≥ twice the disturbed-zone \
                 threshold, i.e. {} mean sizes); the projectile in red (its section when it crosses the plane, \
                 else its outline projected, thin). Instants: tip at L/4, at L/2 + half the projectile's length, \
                 at L, and the end of the run.",
                2.0 * base.impact.disturbed_threshold
            ));
        }
    }
    Ok(())
}

/// The time-step sequence of the penetration run from the first seed's bed (`bed`), judged against the
/// spread over perturbed aims; `first` is that seed's run straight after packing.
fn time_step_convergence(
    ctx: &mut CaseContext,
    data: &CaseData,
    p: &Params,
    config: &ExperimentConfig,
    bed: &std::path::Path,
    scratch: &std::path::Path,
    first: Option<&ExperimentResult>,
) -> Result<(), SuiteError> {
    let seed = config.rock.seed;
    let conv = run_convergence(
        &ConvergenceParams {
            base: *config,
            dt_divisors: p.dt_divisors.clone(),
            sections: Vec::new(),
            out: scratch.join("convergence"),
            bed: Some(bed.to_path_buf()),
            label: "quick variant".into(),
        },
        &mut |_| ctx.progress().inc(1),
    )
    .map_err(|e| case_error(format!("time-step sequence: {e}")))?;
    let seq = conv.sequence(Sequence::TimeStep);
    let diffs = conv.successive_differences();
    if let (Some(r1), Some(first)) = (seq.iter().find(|r| r.parameter == 1.0), first) {
        // The run at Δt/1 from the saved bed is the seed's run straight after packing, bit for bit.
        ctx.check(
            &format!("bed_checkpoint_residual_difference_seed_{seed}"),
            (r1.residual_speed - first.penetration.residual_speed).abs(),
            Target::equal(0.0),
            "m/s",
        );
    }
    let trows = time_step_rows(&seq, &diffs);
    // Judged against the spread over perturbed initial states (see `rockfill_dt_spread`).
    let spread_params = SpreadParams {
        size_fraction: p.perturbation_size_fraction,
        count: p.perturbations,
        tolerance: data.tolerance("rockfill", "dt_change_over_spread")?.value,
    };
    let mut spread_rows = Vec::new();
    let coarse = p.coarse_dt_divisor;
    for (pair, converged) in [((1.0, 2.0), true), ((coarse, 2.0 * coarse), false)] {
        check_pair(
            ctx,
            config,
            bed,
            &seq,
            pair,
            converged,
            &spread_params,
            &mut spread_rows,
        )?;
    }
    report_time_step(ctx, p, seed, spread_params.tolerance, &trows, &spread_rows)?;
    work_precision_plot(ctx, &conv, &seq)
}

/// The time-step table's rows: k, Δt, steps, run time, the results and their changes from the previous k.
fn time_step_rows(seq: &[&ConvergenceRow], diffs: &[[Real; 3]]) -> Vec<Vec<String>> {
    let mut trows = Vec::new();
    for (k, r) in seq.iter().enumerate() {
        let d = if k == 0 { None } else { Some(diffs[k - 1]) };
        trows.push(vec![
            format!("{}", r.parameter),
            CaseContext::fmt(r.dt),
            format!("{}", r.steps),
            format!("{:.1}", r.run_s),
            format!("{:.3}", r.residual_speed),
            format!("{:.3}", r.velocity_deflection),
            format!("{:.3}", r.axis_deflection),
            d.map_or("–".into(), |d| format!("{:.3}", d[0])),
            d.map_or("–".into(), |d| format!("{:.3}", d[2])),
        ]);
    }
    trows
}

/// The time-step section's text and its two tables.
fn report_time_step(
    ctx: &mut CaseContext,
    p: &Params,
    seed: u64,
    tolerance: Real,
    trows: &[Vec<String>],
    spread_rows: &[Vec<String>],
) -> Result<(), SuiteError> {
    let coarse = p.coarse_dt_divisor;
    ctx.section("Time-step convergence of the penetration run");
    ctx.text(&format!(
        "Seed {seed}'s packed bed (engine checkpoint, so every run starts from the same state bit for bit), \
         penetration at Δt/k (k < 1: a coarser step). The result of a many-contact penetration moves \
         with its initial state, so a time step is judged against that motion: Δt/k is converged when \
         halving it changes the result by at most {tol} of the result's range over {n} runs at Δt/k \
         whose aim is displaced by {frac} rock sizes around the flight axis. The shipped Δt (k = 1) \
         must pass; the coarse step k = {coarse} must be flagged, which shows the check can fail.",
        tol = tolerance,
        n = p.perturbations,
        frac = p.perturbation_size_fraction,
    ));
    ctx.table(
        Some("time_step"),
        &[
            "k",
            "Δt (s)",
            "steps",
            "run time (s)",
            "residual speed (m/s)",
            "velocity deflection (°)",
            "axis deflection (°)",
            "|Δ residual| to previous (m/s)",
            "|Δ axis deflection| to previous (°)",
        ],
        trows,
    )?;
    ctx.table(
        Some("time_step_spread"),
        &[
            "time steps",
            "result",
            "|change|",
            "range under aim displacements",
            "change / range",
            "verdict",
        ],
        spread_rows,
    )?;
    Ok(())
}

/// Run time against the change of the result from the smallest Δt, log–log.
fn work_precision_plot(
    ctx: &mut CaseContext,
    conv: &ConvergenceResult,
    seq: &[&ConvergenceRow],
) -> Result<(), SuiteError> {
    let point = |q: usize| -> Vec<(Real, Real)> {
        seq.iter()
            .map(|r| (r.run_s, conv.change(r)[q]))
            .filter(|(_, c)| *c > 0.0)
            .collect()
    };
    ctx.plot(&Plot {
        name: "work_precision".into(),
        title: "Work–precision of the time step (penetration run)".into(),
        x_label: "run time (s)".into(),
        y_label: "|change| against the smallest Δt".into(),
        x_log: true,
        y_log: true,
        series: vec![
            Series {
                label: "residual speed (m/s)".into(),
                style: SeriesStyle::LinePoints,
                points: point(0),
            },
            Series {
                label: "axis deflection (°)".into(),
                style: SeriesStyle::LinePoints,
                points: point(2),
            },
        ],
        caption:
            "Penetration wall time at Δt/k against the change of the result from the run at the \
                  smallest Δt (that run itself is not drawn). The rock-count sequence is run by \
                  `polydem rockfill convergence --sections …` (reports/rockfill_study/)."
                .into(),
    })?;
    Ok(())
}

/// The sample table: realised sizes and shapes per seed.
fn report_shapes(ctx: &mut CaseContext, shape_rows: &[Vec<String>]) -> Result<(), SuiteError> {
    ctx.section("Sample: realised sizes and shapes");
    ctx.table(
        Some("shapes"),
        &[
            "seed",
            "mean size realised / requested (m)",
            "std realised / requested (m)",
            "vertices mean (range)",
            "faces mean (range)",
            "aspect ratio, inertia ellipsoid (range)",
            "cells too small (dropped)",
        ],
        shape_rows,
    )?;
    Ok(())
}

/// The monitors of every seed's run (paper Fig. 8): speed, resistance and deflection angles.
fn monitor_plots(
    ctx: &mut CaseContext,
    results: &[(u64, ExperimentResult)],
) -> Result<(), SuiteError> {
    let series = |f: &dyn Fn(&MonitorRow) -> Real| -> Vec<Series> {
        results
            .iter()
            .map(|(seed, r)| Series {
                label: format!("seed {seed}"),
                style: SeriesStyle::Line,
                points: r
                    .penetration
                    .rows
                    .iter()
                    .step_by(5)
                    .map(|row| (row.time * 1e3, f(row)))
                    .collect(),
            })
            .collect()
    };
    ctx.section("Monitors (paper Fig. 8)");
    ctx.plot(&Plot {
        name: "velocity".into(),
        title: "Projectile speed".into(),
        x_label: "t (ms)".into(),
        y_label: "speed (m/s)".into(),
        x_log: false,
        y_log: false,
        series: series(&|r| r.velocity.norm()),
        caption: "The tip reaches the left face at 0.5 ms.".into(),
    })?;
    ctx.plot(&Plot {
        name: "resistance".into(),
        title: "Penetration resistance along the initial axis".into(),
        x_label: "t (ms)".into(),
        y_label: "−F·e₀ (N)".into(),
        x_log: false,
        y_log: false,
        series: series(&|r| -r.axial_force),
        caption:
            "Resultant contact force on the projectile, component against the initial direction."
                .into(),
    })?;
    ctx.plot(&Plot {
        name: "deflection".into(),
        title: "Deflection angles".into(),
        x_label: "t (ms)".into(),
        y_label: "angle (°)".into(),
        x_log: false,
        y_log: false,
        series: results
            .iter()
            .flat_map(|(seed, r)| {
                let rows = &r.penetration.rows;
                [
                    Series {
                        label: format!("velocity, seed {seed}"),
                        style: SeriesStyle::Line,
                        points: rows.iter().step_by(5).map(|x| (x.time * 1e3, x.velocity_deflection)).collect(),
                    },
                    Series {
                        label: format!("axis, seed {seed}"),
                        style: SeriesStyle::Line,
                        points: rows.iter().step_by(5).map(|x| (x.time * 1e3, x.axis_deflection)).collect(),
                    },
                ]
            })
            .collect(),
        caption: "Angle between the velocity and the initial direction, and between the axis and the initial axis.".into(),
    })?;
    Ok(())
}
