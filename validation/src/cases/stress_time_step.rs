//! Stability stress test, the largest stable time step: for a polyhedron resting on a wall under
//! gravity (linear and Hertz-type laws, several masses and stiffnesses), the largest Δt at which the run
//! stays stable is found by bisection and compared with the scene's theoretical limit
//! Δt_max = f(n) · 2/ω_max (`polydem::scene::time_step`: ω² = κ k_eff/m*, κ = 1 + m r_b²/J_min, f(n) the
//! overshoot factor of a stiffening law, 1 for the linear law and 0.7314 for n = 3/2).
//!
//! The test: the body is placed touching the floor (zero overlap) at rest, tilted so that one vertex
//! touches first; gravity pulls it into the contact, it rocks and rattles on its vertices (e = 1, no
//! friction: nothing damps). A run of a fixed number of steps is *unstable* when a step fails (non-finite
//! state) or its energy error |balance| exceeds `error_limit` × m g L (L the body's size): the integrator
//! has created enough energy to throw the body out of its contact by its own size. Below the limit the
//! error stays bounded (velocity Verlet on an oscillator: by (ωΔt)²/(4 − (ωΔt)²) of the oscillation energy;
//! here also the first-order error of the deepest vertex switching as the body rocks, measured at 10–50
//! times m g δ_peak, i.e. 1e-2 … 1e-5 of m g L), above it the error grows exponentially. Δt is bisected (geometrically) between a stable and an unstable step until they differ
//! by the stated relative resolution. For a nonlinear law the theory needs an impact speed: V is the speed
//! whose head-on impact reaches the overlap δ_peak = ((n+1) m g/k)^(1/n) of the fall from rest.

use polydem::math::{Real, Vector};
use polydem::scene::Simulation;
use polydem::shape::Shape;
use polydem::world::{step, StepScratch};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use serde::Deserialize;

use super::stress_util::{box_points, ellipsoid_points, SceneText};
use crate::case::{Case, CaseData, Profile, Target};
use crate::context::CaseContext;
use crate::error::SuiteError;
use crate::plot::{Plot, Series, SeriesStyle};

pub struct StressTimeStep;

const CASE: &str = "stress_time_step";
const GRAVITY: Real = 9.81;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct Setting {
    name: String,
    /// "cube" (0.1 m) or "hull" (a random 12-point hull of the same size).
    shape: String,
    /// 1 = linear law, else the power law's exponent.
    exponent: Real,
    stiffness: Real,
    density: Real,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct Params {
    settings: Vec<Setting>,
    steps: u64,
    /// A run is unstable when its largest |balance| exceeds this many times m g L.
    error_limit: Real,
    resolution: Real,
    scan_points: usize,
    seed: u64,
}

/// The scene of a setting (built with Δt = t_c/1000, which the guard admits; trials set their own step
/// afterwards), and the energy scale m g L (J).
fn build(s: &Setting, seed: u64) -> Result<(Simulation, Real), SuiteError> {
    let pts = match s.shape.as_str() {
        "cube" => box_points(&Vector::repeat(0.05)),
        "hull" => ellipsoid_points(
            &mut ChaCha8Rng::seed_from_u64(seed),
            12,
            &Vector::new(0.06, 0.05, 0.04),
        ),
        other => {
            return Err(SuiteError::Case {
                case: CASE.into(),
                msg: format!("setting {}: unknown shape {other}", s.name),
            })
        }
    };
    // The peak overlap of a fall from zero overlap at rest, and the impact speed with the same peak.
    let mass_guess = {
        let (p, _) =
            polydem::shape::ConvexPolyhedron::from_points(&pts).map_err(|e| SuiteError::Case {
                case: CASE.into(),
                msg: format!("setting {}: {e}", s.name),
            })?;
        p.mass_properties().volume * s.density
    };
    let n = s.exponent;
    let delta_peak = ((n + 1.0) * mass_guess * GRAVITY / s.stiffness).powf(1.0 / n);
    let speed = (2.0 * s.stiffness * delta_peak.powf(n + 1.0) / ((n + 1.0) * mass_guess)).sqrt();
    let mut t = SceneText::new(
        Vector::new(0.0, 0.0, -GRAVITY),
        1.0,
        1.0,
        ("steps_per_contact", 1000.0),
    );
    if n != 1.0 {
        t.simulation_line(&format!("characteristic_speed = {speed:e}"));
    }
    // The bisection runs steps beyond the stability limit on purpose, and a failed step is its verdict
    // of instability: the run-time check of the step would stop those runs for its own reason.
    t.simulation_line("time_step_check = \"off\"");
    t.material("m", s.density)
        .interaction("m", "m", s.stiffness, (n != 1.0).then_some(n), 1.0)
        .polyhedron("body", &pts)
        .body(
            "body",
            "body",
            "m",
            &Vector::new(0.0, 0.0, 1.0),
            &Vector::new(0.013, -0.007, 0.002),
            &Vector::zeros(),
            &Vector::zeros(),
        )
        .wall("floor", "m", &Vector::zeros(), &Vector::z());
    let mut sim = t.build(CASE, &s.name)?;
    // Touching the floor with zero overlap.
    let pose = sim.world.pose(0);
    let min_z = match sim.world.shape(0) {
        Shape::Polyhedron(p) => p
            .vertices()
            .iter()
            .map(|v| (pose * v).z)
            .fold(Real::INFINITY, Real::min),
        _ => 0.0,
    };
    let mut position = sim.world.body(0).position;
    position.z -= min_z;
    sim.world
        .set_body_position(0, position)
        .map_err(|e| SuiteError::case(CASE, e.to_string()))?;
    let e_scale = sim.world.bodies()[0].mass * GRAVITY * sim.world.length_scale(0);
    Ok((sim, e_scale))
}

/// Whether a run of `steps` at `dt` is stable, and its largest |balance| / `e_scale` (= m g L).
fn trial(
    base: &Simulation,
    e_scale: Real,
    dt: Real,
    steps: u64,
    error_limit: Real,
) -> (bool, Real) {
    let mut sim = base.clone();
    sim.params.dt = dt;
    let mut scratch = StepScratch::default();
    let mut worst = 0.0f64;
    for _ in 0..steps {
        if step(&sim.params, &mut sim.world, &mut scratch).is_err() {
            return (false, Real::INFINITY);
        }
        let err = sim.world.energy().balance.abs() / e_scale;
        if !err.is_finite() {
            return (false, Real::INFINITY);
        }
        worst = worst.max(err);
        if worst > error_limit {
            return (false, worst);
        }
    }
    (true, worst)
}

impl Case for StressTimeStep {
    fn name(&self) -> &'static str {
        CASE
    }
    fn data(&self) -> &'static str {
        include_str!("../../cases/stress_time_step.toml")
    }
    fn run(
        &self,
        data: &CaseData,
        profile: Profile,
        ctx: &mut CaseContext,
    ) -> Result<(), SuiteError> {
        let p: Params = data.params(CASE, profile)?;
        let min_ratio = data.tolerance(CASE, "found_over_theory_min")?.value;
        ctx.progress().stage("settings", p.settings.len() as u64);
        let mut rows = Vec::new();
        let mut scan_series = Vec::new();
        let mut bar_found = Vec::new();
        for (k, s) in p.settings.iter().enumerate() {
            let (base, e_scale) = build(s, p.seed)?;
            let theory = base.time_step.stability_limit;
            let is = |dt: Real| trial(&base, e_scale, dt, p.steps, p.error_limit);
            let limit = bisect_limit(&is, theory, p.resolution);
            check_limit(ctx, s, &limit, theory, min_ratio);
            rows.push(setting_row(s, &base, &limit));
            bar_found.push((k as Real, limit.found / theory));
            // A scan of the growth ratio around the limit, for the plot.
            let points: Vec<(Real, Real)> = (0..p.scan_points)
                .map(|i| {
                    let f = 0.25 * (40.0f64).powf(i as Real / (p.scan_points - 1).max(1) as Real);
                    (f, is(f * theory).1.min(1e12))
                })
                .collect();
            scan_series.push(Series {
                label: s.name.clone(),
                style: SeriesStyle::LinePoints,
                points,
            });
            ctx.progress().inc(1);
        }
        report(ctx, &p, rows, scan_series, bar_found)
    }
}

/// The largest stable step of one setting, by bisection between 0.05 and 50 times the theory.
struct Limit {
    /// Whether the ends of the bracket are stable.
    lo_ok: bool,
    hi_ok: bool,
    /// The largest stable step found (NaN when the bracket does not hold the limit).
    found: Real,
    bisections: u32,
}

/// Bisects `is` (stable at a step?) in a geometric bracket about `theory` to a relative `resolution`.
fn bisect_limit(is: &impl Fn(Real) -> (bool, Real), theory: Real, resolution: Real) -> Limit {
    let (mut lo, mut hi) = (0.05 * theory, 50.0 * theory);
    let (lo_ok, _) = is(lo);
    let (hi_ok, _) = is(hi);
    let mut bisections = 0;
    if lo_ok && !hi_ok {
        while hi / lo > 1.0 + resolution {
            let mid = (lo * hi).sqrt();
            if is(mid).0 {
                lo = mid;
            } else {
                hi = mid;
            }
            bisections += 1;
        }
    }
    let found = if lo_ok && !hi_ok { lo } else { Real::NAN };
    Limit {
        lo_ok,
        hi_ok,
        found,
        bisections,
    }
}

/// The gates of one setting: the bracket holds the limit, and the found step is at least `min_ratio`
/// times the theory.
fn check_limit(ctx: &mut CaseContext, s: &Setting, limit: &Limit, theory: Real, min_ratio: Real) {
    ctx.check(
        &format!("{}_stable_at_0.05_theory", s.name),
        if limit.lo_ok { 1.0 } else { 0.0 },
        Target::equal(1.0),
        "1",
    );
    ctx.check(
        &format!("{}_unstable_at_50_theory", s.name),
        if limit.hi_ok { 0.0 } else { 1.0 },
        Target::equal(1.0),
        "1",
    );
    ctx.check(
        &format!("{}_found_over_theory", s.name),
        limit.found / theory,
        Target::at_least(min_ratio),
        "1",
    );
}

/// One setting's row of the bisection table.
fn setting_row(s: &Setting, base: &Simulation, limit: &Limit) -> Vec<String> {
    let (theory, found) = (base.time_step.stability_limit, limit.found);
    let mass = base.world.bodies()[0].mass;
    let (n, k_n) = (s.exponent, s.stiffness);
    // Translation alone (κ = 1) at the peak overlap: the Verlet limit 2/ω of the normal mode.
    let delta_peak = ((n + 1.0) * mass * GRAVITY / k_n).powf(1.0 / n);
    let k_tangent = n * k_n * delta_peak.powf(n - 1.0);
    let translation_limit = 2.0 * (mass / k_tangent).sqrt();
    vec![
        s.name.clone(),
        s.shape.clone(),
        if n == 1.0 {
            "linear".into()
        } else {
            format!("power n = {n}")
        },
        format!("{k_n:.1e}"),
        format!("{mass:.4e}"),
        format!("{:.4e}", base.time_step.contact_time),
        format!("{theory:.4e}"),
        format!("{translation_limit:.4e}"),
        format!("{found:.4e}"),
        format!("{:.3}", found / theory),
        format!("{:.3}", found / translation_limit),
        limit.bisections.to_string(),
    ]
}

/// The bisection table, the growth scan and the found-over-theory plot.
fn report(
    ctx: &mut CaseContext,
    p: &Params,
    rows: Vec<Vec<String>>,
    scan_series: Vec<Series>,
    bar_found: Vec<(Real, Real)>,
) -> Result<(), SuiteError> {
    ctx.section("Largest stable step against the theory");
    ctx.text(&format!(
            "Δt_max(theory) is the scene's stability limit f(n) · 2/ω_max with κ = 1 + m r_b²/J_min and the overshoot factor f(n) (1 linear, 0.7314 for n = 3/2); the translation-only \
             limit is 2√(m/k_eff) with k_eff the tangent stiffness at the peak overlap. Found: the largest stable Δt \
             by bisection to a relative {:.0e} ({} steps per trial, unstable when the energy error exceeds {} \
             m g L (L the body's size: enough to throw it its own size out of the contact), or a step fails).",
            p.resolution, p.steps, p.error_limit
        ));
    ctx.table(
        Some("bisection"),
        &[
            "setting",
            "shape",
            "law",
            "k_n (N/m^n)",
            "m (kg)",
            "t_c (s)",
            "Δt_max theory (s)",
            "translation-only 2/ω (s)",
            "found (s)",
            "found / theory",
            "found / translation-only",
            "bisection steps",
        ],
        &rows,
    )?;
    ctx.plot(&Plot {
            name: "growth_scan".into(),
            title: "Energy error against the time step".into(),
            x_label: "Δt / Δt_max(theory) (1)".into(),
            y_label: "max abs(balance) / (m g L) (1)".into(),
            x_log: true,
            y_log: true,
            series: scan_series,
            caption: format!(
                "Each point is one run of {} steps (stopped early once above the limit); unstable above {} (or when \
                 a step fails, drawn at 1e12).",
                p.steps, p.error_limit
            ),
        })?;
    ctx.plot(&Plot {
            name: "found_over_theory".into(),
            title: "Largest stable step / theoretical limit, per setting".into(),
            x_label: "setting index (table order)".into(),
            y_label: "Δt_found / Δt_max (1)".into(),
            x_log: false,
            y_log: false,
            series: vec![
                Series {
                    label: "found / theory".into(),
                    style: SeriesStyle::Points,
                    points: bar_found,
                },
                Series {
                    label: "theory".into(),
                    style: SeriesStyle::Line,
                    points: vec![(0.0, 1.0), ((p.settings.len().max(2) - 1) as Real, 1.0)],
                },
            ],
            caption: "Above 1: the guard is conservative (it refuses only steps that are stable); below 1 it would admit unstable steps.".into(),
        })?;
    Ok(())
}
