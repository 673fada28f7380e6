//! Rockfill (issue 6): the paper's experiment through `polydem::rockfill` — generation, packing, penetration.
//!
//! Checks that can fail: the realised size distribution against the law eq. 29 samples, the energy ledger of
//! packing and of penetration, finite state, the projectile leaving the layer, and its residual velocity
//! against the paper's range. Deflection angles and the disturbed zone are reported against the paper's
//! figures, not gated (the quick variant's cross-section is too small for them to be comparable).

use polydem::math::Real;
use polydem::rockfill::config::ExperimentConfig;
use polydem::rockfill::experiment::{run_experiment, BedSource, ExperimentResult};
use polydem::rockfill::penetration::{MonitorRow, Outcome};

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
}

fn case_error(msg: String) -> SuiteError {
    SuiteError::case("rockfill", msg)
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
        let se_tol = data.tolerance(self.name(), "size_mean_se")?.value;
        let packing_tol = data.tolerance(self.name(), "packing_ledger")?.value;
        let penetration_tol = data.tolerance(self.name(), "penetration_ledger")?.value;
        let low = data.reference(self.name(), "residual_low")?.value;
        let high = data.reference(self.name(), "residual_high")?.value;
        ctx.progress().stage("runs", p.seeds.len() as u64);
        let mut rows = Vec::new();
        let mut shape_rows = Vec::new();
        let mut results: Vec<(u64, ExperimentResult)> = Vec::new();
        for &seed in &p.seeds {
            let mut config = base;
            config.rock.seed = seed;
            let mut progress = |_: &str, _: String| {};
            let r = run_experiment(&config, BedSource::Generate { save: None }, &mut progress)
                .map_err(|e| case_error(format!("seed {seed}: {e}")))?;
            let g = r.generation.as_ref().expect("generated");
            let pk = r.packing.as_ref().expect("packed");
            let pen = &r.penetration;
            let tag = format!("seed_{seed}");
            let n = g.statistics.diameter.count as Real;
            let se = g.requested_std / n.sqrt();
            ctx.check(
                &format!("size_mean_error_{tag}"),
                (g.statistics.diameter.mean - g.requested_mean).abs() / se,
                Target::at_most(se_tol),
                "standard errors",
            );
            for (stage, b) in ["deposition", "compaction", "hold"]
                .iter()
                .zip(pk.ledger_balance_relative)
            {
                ctx.check(
                    &format!("packing_ledger_{stage}_{tag}"),
                    b.abs(),
                    Target::at_most(packing_tol),
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
                Target::at_most(penetration_tol),
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
                Target::at_least(low),
                "m/s",
            );
            ctx.check(
                &format!("residual_velocity_high_{tag}"),
                pen.residual_speed,
                Target::at_most(high),
                "m/s",
            );
            rows.push(vec![
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
                format!("{:.2}", pen.disturbed_width_sizes),
                CaseContext::fmt(pen.ledger_balance_relative),
            ]);
            let s = &g.statistics;
            shape_rows.push(vec![
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
            ]);
            results.push((seed, r));
            ctx.progress().inc(1);
        }
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
                "disturbed width (sizes)",
                "ledger balance",
            ],
            &rows,
        )?;
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
            &shape_rows,
        )?;
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
            caption: "Resultant contact force on the projectile, component against the initial direction.".into(),
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
}
