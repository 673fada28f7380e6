//! Stability stress test, long run: a frictionless, perfectly elastic (e = 1) closed box of
//! spinning polyhedra of several shapes, run for 10^6 steps in the full profile. With no dissipation the
//! energy ledger's balance is the integration error alone; it must stay bounded and show no drift trend.
//!
//! Drift test: a least-squares line is fitted to the balance/E0 history; the change it accounts for over the
//! whole run, |b T|, is compared with the scatter of the history about the line (standard deviation of the
//! residuals). A bounded error has |b T| well below its scatter; a steady gain or loss has |b T| above it.

use nalgebra::Vector3;
use polydem::math::{Real, Vector};
use polydem::world::{step, StepCounters, StepScratch};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use serde::Deserialize;

use super::stress_util::{
    box_points, drift_fit, ellipsoid_points, random_unit, DriftFit, SceneText,
};
use crate::case::{Case, CaseData, Profile, Target};
use crate::context::CaseContext;
use crate::error::SuiteError;
use crate::plot::{Plot, Series, SeriesStyle};

pub struct StressLongRun;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct Params {
    steps: u64,
    /// Bodies on a lattice of this many sites per axis.
    lattice: [usize; 3],
    /// Lattice spacing (m); the box is the lattice's extent.
    spacing: Real,
    steps_per_contact: Real,
    normal_stiffness: Real,
    density: Real,
    speed: Real,
    spin: Real,
    samples: usize,
    seed: u64,
}

const CASE: &str = "stress_long_run";

/// How the box is closed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Container {
    /// Six walls (planes): polyhedron–plane contacts with the smoothed wall depth (band by its rule).
    Walls,
    /// Six fixed polyhedral slabs: every contact is polyhedron–polyhedron (GJK/EPA, Minkowski overlap).
    Slabs,
}

impl Container {
    fn name(self) -> &'static str {
        match self {
            Container::Walls => "walls",
            Container::Slabs => "slabs",
        }
    }
}

/// The scene: four shapes (a tetrahedron, a box, two random hulls) on a lattice in a closed box.
fn scene(p: &Params, container: Container) -> SceneText {
    let mut rng = ChaCha8Rng::seed_from_u64(p.seed);
    let s = p.spacing;
    let extent = Vector::new(
        p.lattice[0] as Real * s,
        p.lattice[1] as Real * s,
        p.lattice[2] as Real * s,
    );
    // Every shape fits in a sphere of radius 0.45 s, so lattice neighbours start apart.
    let r = 0.45 * s;
    let c = r / 3f64.sqrt();
    let shapes: [(&str, Vec<polydem::math::Point>); 4] = [
        (
            "tetrahedron",
            vec![
                [c, c, c].into(),
                [c, -c, -c].into(),
                [-c, c, -c].into(),
                [-c, -c, c].into(),
            ],
        ),
        (
            "slab",
            box_points(&(Vector::new(0.75, 0.5, 0.35).normalize() * r)),
        ),
        (
            "hull12",
            ellipsoid_points(&mut rng, 12, &Vector::new(r, 0.8 * r, 0.6 * r)),
        ),
        (
            "hull30",
            ellipsoid_points(&mut rng, 30, &Vector::new(0.7 * r, r, 0.85 * r)),
        ),
    ];
    let mut t = SceneText::new(
        Vector::zeros(),
        1.0,
        1.0,
        ("steps_per_contact", p.steps_per_contact),
    );
    t.material("rock", p.density)
        .interaction("rock", "rock", p.normal_stiffness, None, 1.0);
    for (name, pts) in &shapes {
        t.polyhedron(name, pts);
    }
    let mut k = 0;
    for i in 0..p.lattice[0] {
        for j in 0..p.lattice[1] {
            for l in 0..p.lattice[2] {
                let pos = Vector3::new(i as Real + 0.5, j as Real + 0.5, l as Real + 0.5) * s;
                let axis_angle = random_unit(&mut rng) * rng.random_range(0.0..3.0);
                let v = random_unit(&mut rng) * p.speed;
                let w = random_unit(&mut rng) * p.spin;
                t.body(
                    &format!("b{k}"),
                    shapes[k % shapes.len()].0,
                    "rock",
                    &pos,
                    &axis_angle,
                    &v,
                    &w,
                );
                k += 1;
            }
        }
    }
    match container {
        Container::Walls => t.closed_box("rock", &Vector::zeros(), &extent),
        Container::Slabs => t.slab_box("rock", &Vector::zeros(), &extent, 0.5 * s),
    };
    t
}

/// What one long run measured.
struct RunResult {
    history: Vec<(Real, Real)>,
    worst: Real,
    step_error: Option<String>,
    outside: usize,
    counters: StepCounters,
    max_overlap: Real,
    bodies: usize,
    dt: Real,
    contact_time: Real,
    e0: Real,
}

fn long_run(
    p: &Params,
    container: Container,
    ctx: &mut CaseContext,
) -> Result<RunResult, SuiteError> {
    let mut sim = scene(p, container).build(CASE, container.name())?;
    // The band of the smoothed wall depth by the rule of `polydem::contact::wall_depth` (h = the scene's
    // characteristic overlap): the peak overlap V √(m/k) of the lightest body hitting a wall at V = `speed`,
    // relative to the largest body size (bodies of every shape then get at least that band).
    let lightest = sim
        .world
        .bodies()
        .iter()
        .filter(|b| b.is_dynamic())
        .map(|b| b.mass)
        .fold(Real::INFINITY, Real::min);
    let size = (0..sim.world.bodies().len())
        .filter(|&i| sim.world.bodies()[i].is_dynamic())
        .map(|i| sim.world.length_scale(i))
        .fold(0.0, Real::max);
    sim.params.tolerances.wall_depth = polydem::contact::WallDepth::Smoothed {
        band: p.speed * (lightest / p.normal_stiffness).sqrt() / size,
    };
    // The same rule for polyhedron pairs (`polydem::contact::pair_smoothing`), whose band is relative to the
    // smaller body of the pair: relative to the smallest body size, every pair gets at least that band.
    let smallest = (0..sim.world.bodies().len())
        .filter(|&i| sim.world.bodies()[i].is_dynamic())
        .map(|i| sim.world.length_scale(i))
        .fold(Real::INFINITY, Real::min);
    sim.params.tolerances.pair_smoothing = polydem::contact::PairSmoothing::Smoothed {
        band: p.speed * (lightest / p.normal_stiffness).sqrt() / smallest,
    };
    let extent = Vector::new(
        p.lattice[0] as Real,
        p.lattice[1] as Real,
        p.lattice[2] as Real,
    ) * p.spacing;
    let e0 = sim.world.energy().mechanical();
    let every = (p.steps / p.samples as u64).max(1);
    let mut history: Vec<(Real, Real)> = vec![(0.0, 0.0)];
    let mut counters = StepCounters::default();
    let mut scratch = StepScratch::default();
    let (mut worst, mut step_error) = (0.0f64, None);
    let mut max_overlap: Real = 0.0;
    ctx.progress().stage(
        &format!("{} steps ({})", p.steps, container.name()),
        p.steps,
    );
    for n in 1..=p.steps {
        match step(&sim.params, &mut sim.world, &mut scratch) {
            Ok(report) => {
                counters.merge(&report.counters);
                max_overlap = max_overlap.max(report.max_overlap_ratio);
            }
            Err(e) => {
                step_error = Some(e.to_string());
                break;
            }
        }
        let err = sim.world.energy().balance / e0;
        worst = worst.max(err.abs());
        if n % every == 0 {
            history.push((sim.world.time(), err));
            ctx.progress().inc(every);
        }
    }
    let outside = sim
        .world
        .bodies()
        .iter()
        .filter(|b| b.is_dynamic())
        .filter(|b| (0..3).any(|a| !(b.position[a] > 0.0 && b.position[a] < extent[a])))
        .count();
    Ok(RunResult {
        history,
        worst,
        step_error,
        outside,
        counters,
        max_overlap,
        bodies: sim.world.bodies().iter().filter(|b| b.is_dynamic()).count(),
        dt: sim.params.dt,
        contact_time: sim.time_step.contact_time,
        e0,
    })
}

impl Case for StressLongRun {
    fn name(&self) -> &'static str {
        CASE
    }
    fn data(&self) -> &'static str {
        include_str!("../../cases/stress_long_run.toml")
    }
    fn run(
        &self,
        data: &CaseData,
        profile: Profile,
        ctx: &mut CaseContext,
    ) -> Result<(), SuiteError> {
        let p: Params = data.params(CASE, profile)?;
        let gates = Gates {
            drift: data.tolerance(CASE, "drift_to_scatter")?.value,
            min_contacts: data.tolerance(CASE, "body_contacts_min")?.value,
        };
        let mut rows = Vec::new();
        let mut series = Vec::new();
        let mut jump_rows = Vec::new();
        for container in [Container::Slabs, Container::Walls] {
            let c = container.name();
            let max_error = data
                .tolerance(CASE, &format!("energy_error_max_{c}"))?
                .value;
            let r = long_run(&p, container, ctx)?;
            let fit = drift_fit(&r.history);
            check_run(ctx, c, &r, &fit, &gates, max_error);
            jump_rows.extend(largest_jumps(c, &r.history));
            rows.push(run_row(c, &r, &fit));
            let t_end = r.history.last().map_or(0.0, |h| h.0);
            series.push(Series {
                label: format!("{c}: balance/E0"),
                style: SeriesStyle::Line,
                points: r.history,
            });
            series.push(Series {
                label: format!("{c}: least-squares line"),
                style: SeriesStyle::Line,
                points: vec![
                    (0.0, fit.intercept),
                    (t_end, fit.intercept + fit.slope * t_end),
                ],
            });
        }
        report(ctx, &p, rows, jump_rows, series)
    }
}

/// The gates common to both containers.
struct Gates {
    /// The drift's fitted change over the scatter.
    drift: Real,
    /// Store entries a run must create.
    min_contacts: Real,
}

/// The gates of one container's run; a step error is also shown in the report.
fn check_run(
    ctx: &mut CaseContext,
    c: &str,
    r: &RunResult,
    fit: &DriftFit,
    gates: &Gates,
    max_error: Real,
) {
    let ratio = fit.fitted_change.abs() / fit.residual_std;
    ctx.check(
        &format!("{c}_step_errors"),
        if r.step_error.is_some() { 1.0 } else { 0.0 },
        Target::equal(0.0),
        "1",
    );
    ctx.check(
        &format!("{c}_energy_error_max"),
        r.worst,
        Target::at_most(max_error),
        "1",
    );
    ctx.check(
        &format!("{c}_drift_fitted_change_over_scatter"),
        ratio,
        Target::at_most(gates.drift),
        "1",
    );
    ctx.check(
        &format!("{c}_bodies_outside_box"),
        r.outside as f64,
        Target::equal(0.0),
        "1",
    );
    ctx.check(
        &format!("{c}_contact_pairs_created"),
        r.counters.contacts_created as f64,
        Target::at_least(gates.min_contacts),
        "1",
    );
    if let Some(e) = &r.step_error {
        ctx.text(&format!("**The {c} run stopped with a step error:** {e}"));
    }
}

/// The three largest changes of the energy error between two samples, as rows.
fn largest_jumps(c: &str, history: &[(Real, Real)]) -> Vec<Vec<String>> {
    let mut jumps: Vec<(Real, Real, Real)> = history
        .windows(2)
        .map(|w| (w[1].1 - w[0].1, w[0].0, w[1].0))
        .collect();
    jumps.sort_by(|a, b| b.0.abs().total_cmp(&a.0.abs()));
    jumps
        .iter()
        .take(3)
        .map(|(jump, t0, t1)| {
            vec![
                c.to_string(),
                format!("{t0:.5} – {t1:.5}"),
                format!("{jump:+.3e}"),
            ]
        })
        .collect()
}

/// One container's row of the runs table.
fn run_row(c: &str, r: &RunResult, fit: &DriftFit) -> Vec<String> {
    let t_end = r.history.last().map_or(0.0, |h| h.0);
    vec![
        c.to_string(),
        r.bodies.to_string(),
        r.counters.steps.to_string(),
        format!("{:.3e} = t_c/{}", r.dt, r.contact_time / r.dt),
        format!("{t_end:.3}"),
        format!("{:.4e}", r.e0),
        format!("{:.3e}", r.worst),
        format!("{:.3e}", r.history.last().map_or(0.0, |h| h.1)),
        format!("{:.3e}", fit.slope),
        format!("{:.3e}", fit.fitted_change),
        format!("{:.3e}", fit.residual_std),
        format!("{:.3e}", r.max_overlap),
        r.counters.contacts_created.to_string(),
        r.counters.contacts.to_string(),
        format!(
            "{}/{}",
            r.counters.query.fallback_max_iterations, r.counters.query.fallback_degenerate
        ),
        format!("{:.1}", r.counters.total_time().as_secs_f64()),
    ]
}

/// The runs table, the largest jumps and the energy plot.
fn report(
    ctx: &mut CaseContext,
    p: &Params,
    rows: Vec<Vec<String>>,
    jump_rows: Vec<Vec<String>>,
    series: Vec<Series>,
) -> Result<(), SuiteError> {
    ctx.section("Runs");
    ctx.table(
        Some("runs"),
        &[
            "container",
            "bodies",
            "steps",
            "Δt (s)",
            "simulated (s)",
            "E0 (J)",
            "max abs(balance)/E0",
            "final balance/E0",
            "fitted slope (1/s)",
            "fitted change",
            "scatter (std)",
            "max overlap/size",
            "store entries created",
            "contact evaluations",
            "SAT fallbacks (max it./degenerate)",
            "wall time (s)",
        ],
        &rows,
    )?;
    ctx.section("Largest changes of the energy error between two samples");
    ctx.text(
            "A discretisation error shrinks with Δt; a change that does not is a jump of the potential. \
             A diagnosis (every step with |Δ balance| > 2e-5 E0 logged with the contacts that changed, \
             quick profile): no contact appears with a finite depth and every depth is continuous, so the \
             potential does not jump; what jumps is the force. Slab box, 88 such steps in 60000: 62 have a \
             body–slab contact whose point c_M moves by 2e-2 to 6.5e-2 m in one step with the normal unchanged \
             (two vertices of the body equally deep below the slab's face: the polyhedron–polyhedron path has \
             the wall's deepest-vertex kink, e.g. bodies 6/18 at t = 0.870 s, +7.6e-4 E0), and 29 a normal \
             that turns by 0.3–1.9 rad between two faces of the Minkowski difference of nearly equal depth \
             (δ_M = min over faces, e.g. bodies 8/12 at t = 0.0975 s). Both are first-order force \
             discontinuities: at t_c/400 the steps above 2e-5 E0 in the first 0.6 s fall from 40 to 19 and \
             their summed change from 3.2e-3 to 1.3e-3 E0, while the largest single events (2.9e-4 and 2.7e-4) \
             are set by the chaotic trajectory. The wall box uses the smoothed wall depth with the band of \
             its rule (h = V √(m/k), the peak overlap at the scene's speed); with the default band (1e-4 L, \
             100 times below these overlaps) its wall contacts jump in the same way (point moves of 5e-2 m).",
        );
    ctx.table(
        Some("jumps"),
        &["container", "interval (s)", "change of balance/E0"],
        &jump_rows,
    )?;
    ctx.plot(&Plot {
            name: "energy_error".into(),
            title: "Energy error of the elastic box over the run".into(),
            x_label: "t (s)".into(),
            y_label: "balance / E0 (1)".into(),
            x_log: false,
            y_log: false,
            series,
            caption: format!(
                "16 polyhedra (4 shapes), frictionless, e = 1, closed by six fixed polyhedral slabs or six walls; \
                 {} steps of Δt = t_c/{} each. The straight lines are the least-squares fits of the drift test.",
                p.steps, p.steps_per_contact
            ),
        })?;
    Ok(())
}
