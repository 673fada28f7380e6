//! Stability stress test, extreme shapes and ratios: slivers of 20:1 aspect (needles, plates,
//! thin random hulls), a mass ratio of 1:10^4 between bodies of the same shape, and pairs released from
//! initial overlaps of 0.1, 0.25 and 0.5 of the particle size. Every run: no step error, every body–body
//! contact status equal to the exact SAT oracle's at sampled steps (all pairs, not only the broad phase's
//! candidates), overlap depths within the contact core's tolerance of the oracle's, no tunnelling, and the
//! energy error (elastic, frictionless: the ledger balance) within bounds, with its history plotted.

use std::sync::Arc;

use polydem::contact::{
    query_polyhedra_with, sat_polyhedra, ContactGeometry, ContactKind, ContactTolerances,
    EpaScratch, PairCache, PairSmoothing, QueryCounters,
};
use polydem::math::{Point, Pose, Real, Rotation, Vector};
use polydem::scene::Simulation;
use polydem::shape::{ConvexPolyhedron, Shape};
use polydem::world::ContactKey;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use serde::Deserialize;

use super::stress_util::{box_points, ellipsoid_points, random_unit, run_monitored, SceneText};
use crate::case::{Case, CaseData, Profile, Target};
use crate::context::CaseContext;
use crate::error::SuiteError;
use crate::plot::{Plot, Series, SeriesStyle};

pub struct StressShapes;

const CASE: &str = "stress_shapes";

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct Params {
    steps_per_contact: Real,
    normal_stiffness: Real,
    density: Real,
    mass_ratio: Real,
    /// Speed of the slivers (m/s).
    sliver_speed: Real,
    /// Steps of the sliver and mass-ratio runs.
    steps: u64,
    /// Duration of the overlap releases in contact times.
    release_contact_times: Real,
    overlaps: Vec<Real>,
    oracle_every: u64,
    seed: u64,
}

/// Signed gap of a geometry: −depth when overlapping, the distance otherwise (m).
fn signed_gap(g: &ContactGeometry) -> Real {
    match g.kind {
        ContactKind::Overlap => -g.depth,
        _ => g.distance,
    }
}

/// Oracle comparison over every body pair of a world at one instant.
#[derive(Clone, Copy, Debug, Default)]
struct OracleStats {
    pairs: u64,
    overlapping: u64,
    wrong_status: u64,
    /// Largest |depth − depth_SAT| / size of the exact query (GJK/EPA, the narrow phase before the law's
    /// smoothing) over pairs the store and SAT both call overlapping.
    depth_error: Real,
    /// Largest (depth − depth_SAT) / size of the depth the law saw (the stored geometry, smoothed by
    /// `polydem::contact::pair_smoothing`): it must never exceed the exact overlap.
    law_excess: Real,
    /// Largest (depth_SAT − depth) / h of the law's depth, h the pair's smoothing band (0 if exact).
    law_shortfall_over_band: Real,
}

fn compare_with_oracle(sim: &Simulation, stats: &mut OracleStats) {
    let w = &sim.world;
    // Before the first step the store holds no geometry yet.
    if w.step_index() == 0 {
        return;
    }
    let band = ContactTolerances::default().touching;
    for i in 0..w.bodies().len() {
        for j in i + 1..w.bodies().len() {
            let (Shape::Polyhedron(a), Shape::Polyhedron(b)) = (w.shape(i), w.shape(j)) else {
                continue;
            };
            let size = w.length_scale(i).max(w.length_scale(j));
            let oracle = sat_polyhedra(&w.pose(i), a, &w.pose(j), b);
            let key = ContactKey::Body {
                a: i as u32,
                b: j as u32,
            };
            // The store holds exactly the candidates of the last evaluation; a pair outside it was judged
            // apart by the broad phase: separated.
            let engine_kind = w
                .contacts()
                .get(&key)
                .map(|s| (s.geometry.kind, s.geometry));
            let kind = engine_kind.map_or(ContactKind::Separated, |k| k.0);
            stats.pairs += 1;
            let ambiguous = signed_gap(&oracle).abs() <= 2.0 * band * size;
            if kind != oracle.kind && !ambiguous {
                stats.wrong_status += 1;
            }
            if oracle.kind == ContactKind::Overlap {
                stats.overlapping += 1;
                if let Some((ContactKind::Overlap, g)) = engine_kind {
                    let exact = query_polyhedra_with(
                        &w.pose(i),
                        a,
                        &w.pose(j),
                        b,
                        &sim.params.tolerances,
                        &mut PairCache::default(),
                        &mut EpaScratch::default(),
                        &mut QueryCounters::default(),
                    );
                    stats.depth_error = stats
                        .depth_error
                        .max((exact.depth - oracle.depth).abs() / size);
                    stats.law_excess = stats.law_excess.max((g.depth - oracle.depth) / size);
                    if let PairSmoothing::Smoothed { band } = sim.params.tolerances.pair_smoothing {
                        let h = band * w.length_scale(i).min(w.length_scale(j));
                        stats.law_shortfall_over_band = stats
                            .law_shortfall_over_band
                            .max((oracle.depth - g.depth) / h);
                    }
                }
            }
        }
    }
}

/// One scene's results.
struct ShapeRun {
    name: String,
    bodies: usize,
    dt: Real,
    steps: u64,
    step_error: Option<String>,
    missed: u64,
    pass_through: u64,
    energy_error_max: Real,
    max_overlap: Real,
    oracle: OracleStats,
    history: Vec<(Real, Real)>,
}

fn run_scene(name: &str, mut sim: Simulation, steps: u64, oracle_every: u64) -> ShapeRun {
    let mut oracle = OracleStats::default();
    let mut history = Vec::new();
    let dt = sim.params.dt;
    let every = (steps / 400).max(1);
    let mut n = 0u64;
    let run = run_monitored(&mut sim, steps, 1, |s| {
        if n.is_multiple_of(oracle_every) {
            compare_with_oracle(s, &mut oracle);
        }
        if n.is_multiple_of(every) {
            if let Some(e0) = s.world.ledger().initial_total() {
                history.push((s.world.time(), s.world.energy().balance / e0));
            }
        }
        n += 1;
    });
    ShapeRun {
        name: name.into(),
        bodies: sim.world.bodies().len(),
        dt,
        steps: run.steps,
        step_error: run.step_error,
        missed: run.crossings.missed(),
        pass_through: run.crossings.pass_through_body + run.crossings.pass_through_wall,
        energy_error_max: run.energy_error_max,
        max_overlap: run.max_overlap_ratio,
        oracle,
        history,
    }
}

/// A closed box of walls around a lattice of bodies with random orientations, velocities 1 m/s, spins.
#[allow(clippy::too_many_arguments)]
fn lattice_scene(
    p: &Params,
    rng: &mut ChaCha8Rng,
    shapes: &[(&str, Vec<Point>)],
    materials: &[&str],
    lattice: [usize; 3],
    spacing: Real,
    speed: Real,
    spin: Real,
) -> SceneText {
    let mut t = SceneText::new(
        Vector::zeros(),
        1.0,
        1.0,
        ("steps_per_contact", p.steps_per_contact),
    );
    for (k, m) in materials.iter().enumerate() {
        let density = if k == 0 {
            p.density
        } else {
            p.density / p.mass_ratio
        };
        t.material(m, density);
    }
    for (a, ma) in materials.iter().enumerate() {
        for mb in &materials[a..] {
            t.interaction(ma, mb, p.normal_stiffness, None, 1.0);
        }
    }
    for (name, pts) in shapes {
        t.polyhedron(name, pts);
    }
    let mut k = 0;
    for i in 0..lattice[0] {
        for j in 0..lattice[1] {
            for l in 0..lattice[2] {
                let pos = Vector::new(i as Real + 0.5, j as Real + 0.5, l as Real + 0.5) * spacing;
                let aa = random_unit(rng) * rng.random_range(0.0..3.0);
                t.body(
                    &format!("b{k}"),
                    shapes[k % shapes.len()].0,
                    materials[k % materials.len()],
                    &pos,
                    &aa,
                    &(random_unit(rng) * speed),
                    &(random_unit(rng) * spin),
                );
                k += 1;
            }
        }
    }
    let extent = Vector::new(lattice[0] as Real, lattice[1] as Real, lattice[2] as Real) * spacing;
    t.closed_box(materials[0], &Vector::zeros(), &extent);
    t
}

/// Mass ratio: a 3 × 3 lattice of aligned cubes with 10 mm gaps; the centre one of density ρ moves
/// diagonally and spins, the others (density ρ/ratio) are at rest.
fn mass_ratio_scene(p: &Params) -> SceneText {
    let mut t = SceneText::new(
        Vector::zeros(),
        1.0,
        1.0,
        ("steps_per_contact", p.steps_per_contact),
    );
    t.material("heavy", p.density)
        .material("light", p.density / p.mass_ratio)
        .interaction("heavy", "heavy", p.normal_stiffness, None, 1.0)
        .interaction("heavy", "light", p.normal_stiffness, None, 1.0)
        .interaction("light", "light", p.normal_stiffness, None, 1.0)
        .polyhedron("cube", &box_points(&Vector::repeat(0.05)));
    let spacing = 0.11;
    for i in 0..3 {
        for j in 0..3 {
            let centre = i == 1 && j == 1;
            let pos = Vector::new(i as Real + 0.5, j as Real + 0.5, 0.5) * spacing;
            let (v, w) = if centre {
                (Vector::new(1.5, 1.0, 0.2), Vector::new(0.0, 0.0, 20.0))
            } else {
                (Vector::zeros(), Vector::zeros())
            };
            t.body(
                &format!("c{i}{j}"),
                "cube",
                if centre { "heavy" } else { "light" },
                &pos,
                &Vector::zeros(),
                &v,
                &w,
            );
        }
    }
    let extent = Vector::new(3.0 * spacing, 3.0 * spacing, spacing) + Vector::repeat(0.01);
    t.closed_box("heavy", &Vector::repeat(-0.01), &extent);
    t
}

/// Pairs of hulls placed at the given overlaps (fractions of the particle size), far apart from each other,
/// in free space. Returns the scene and the overlaps reached (SAT depth / size).
fn overlap_scene(
    p: &Params,
    rng: &mut ChaCha8Rng,
    overlaps: &[Real],
) -> Result<(SceneText, Vec<Real>), SuiteError> {
    let pts = ellipsoid_points(rng, 40, &Vector::new(0.05, 0.045, 0.04));
    let (poly, frame) = ConvexPolyhedron::from_points(&pts).map_err(|e| SuiteError::Case {
        case: CASE.into(),
        msg: format!("overlap hull: {e}"),
    })?;
    let poly = Arc::new(poly);
    let size = poly.length_scale();
    let mut t = SceneText::new(
        Vector::zeros(),
        1.0,
        1.0,
        ("steps_per_contact", p.steps_per_contact),
    );
    t.material("rock", p.density)
        .interaction("rock", "rock", p.normal_stiffness, None, 1.0)
        .polyhedron("hull", &pts);
    let pose_of = |position: &Vector, aa: &Vector| {
        Pose::from_parts((*position).into(), Rotation::from_scaled_axis(*aa)) * frame
    };
    let mut reached = Vec::new();
    for (k, &f) in overlaps.iter().enumerate() {
        let base = Vector::new(2.0 * k as Real, 0.0, 0.0);
        let (aa_a, aa_b) = (random_unit(rng) * 1.0, random_unit(rng) * 2.0);
        let d = random_unit(rng);
        let pose_a = pose_of(&base, &aa_a);
        let depth_at = |s: Real| {
            let g = sat_polyhedra(&pose_a, &poly, &pose_of(&(base + s * d), &aa_b), &poly);
            -signed_gap(&g)
        };
        let target = f * size;
        let (mut lo, mut hi) = (0.0, 2.0 * size);
        for _ in 0..60 {
            let mid = 0.5 * (lo + hi);
            if depth_at(mid) >= target {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        reached.push(depth_at(lo) / size);
        t.body(
            &format!("a{k}"),
            "hull",
            "rock",
            &base,
            &aa_a,
            &Vector::zeros(),
            &Vector::zeros(),
        );
        t.body(
            &format!("b{k}"),
            "hull",
            "rock",
            &(base + lo * d),
            &aa_b,
            &Vector::zeros(),
            &Vector::zeros(),
        );
    }
    Ok((t, reached))
}

impl Case for StressShapes {
    fn name(&self) -> &'static str {
        CASE
    }
    fn data(&self) -> &'static str {
        include_str!("../../cases/stress_shapes.toml")
    }
    fn run(
        &self,
        data: &CaseData,
        profile: Profile,
        ctx: &mut CaseContext,
    ) -> Result<(), SuiteError> {
        let p: Params = data.params(CASE, profile)?;
        let gates = Gates {
            depth: data.tolerance(CASE, "depth_error")?.value,
            shortfall: data.tolerance(CASE, "law_depth_shortfall_over_band")?.value,
            walls: data.tolerance(CASE, "energy_error_max_walls")?.value,
            free: data.tolerance(CASE, "energy_error_max_free")?.value,
        };
        ctx.progress().stage("scenes", 3);
        let sliver_run = sliver_run(&p)?;
        ctx.progress().inc(1);
        let (mass_run, ratio) = mass_ratio_run(&p)?;
        ctx.progress().inc(1);
        let releases = overlap_releases(&p)?;
        ctx.progress().inc(1);
        check_runs(ctx, &p, &gates, &sliver_run, &mass_run, ratio, &releases);
        report_runs(ctx, &sliver_run, &mass_run, ratio, &releases)?;
        report_sweep(ctx, &releases.sweep)?;
        plot_energy(ctx, &p, &sliver_run, &mass_run, &releases)
    }
}

/// The case's tolerances.
struct Gates {
    depth: Real,
    shortfall: Real,
    /// The energy error of the runs in a box of walls.
    walls: Real,
    /// The energy error of the releases in free space.
    free: Real,
}

/// One pair smoothing band's energy error at Δt or Δt/2, for an overlap level:
/// (level, band name, band, error, step error).
type SweepRow = (Real, &'static str, PairSmoothing, Real, Option<String>);

/// The initial-overlap releases: one run per level, the levels reached, and the band sweep.
struct Releases {
    runs: Vec<ShapeRun>,
    reached: Vec<Real>,
    sweep: Vec<SweepRow>,
}

/// Slivers (needles 20:1:1, plates 20:20:1, thin random hulls 20:1) in a closed box.
fn sliver_run(p: &Params) -> Result<ShapeRun, SuiteError> {
    let mut rng = ChaCha8Rng::seed_from_u64(p.seed);
    let slivers = [
        ("needle", box_points(&Vector::new(0.1, 0.005, 0.005))),
        ("plate", box_points(&Vector::new(0.1, 0.1, 0.005))),
        (
            "sliver_hull",
            ellipsoid_points(&mut rng, 14, &Vector::new(0.1, 0.005, 0.004)),
        ),
    ];
    let t = lattice_scene(
        p,
        &mut rng,
        &slivers,
        &["rock"],
        [3, 2, 2],
        0.3,
        p.sliver_speed,
        10.0,
    );
    let sim = t.build(CASE, "slivers")?;
    let sliver_run = run_scene("slivers", sim, p.steps, p.oracle_every);
    Ok(sliver_run)
}

/// Cubes of one size with densities ρ and ρ/ratio, alternating; the run and the mass ratio reached.
fn mass_ratio_run(p: &Params) -> Result<(ShapeRun, Real), SuiteError> {
    let mut sim = mass_ratio_scene(p).build(CASE, "mass_ratio")?;
    // The smoothing bands of walls and pairs by the rule of `polydem::contact::wall_depth` (h = the
    // scene's characteristic overlap): the peak overlap V √(m/k) of a light cube struck at the heavy
    // cube's speed, relative to the cube size (one size here).
    let light = sim
        .world
        .bodies()
        .iter()
        .map(|b| b.mass)
        .fold(Real::INFINITY, Real::min);
    let heavy_speed = sim
        .world
        .bodies()
        .iter()
        .map(|b| b.velocity.norm())
        .fold(0.0, Real::max);
    let band = heavy_speed * (light / p.normal_stiffness).sqrt() / sim.world.length_scale(0);
    sim.params.tolerances.wall_depth = polydem::contact::WallDepth::Smoothed { band };
    sim.params.tolerances.pair_smoothing = PairSmoothing::Smoothed { band };
    let masses: Vec<Real> = sim.world.bodies().iter().map(|b| b.mass).collect();
    let ratio = masses.iter().cloned().fold(0.0, Real::max)
        / masses.iter().cloned().fold(Real::INFINITY, Real::min);
    let mass_run = run_scene("mass_ratio", sim, p.steps, p.oracle_every);
    Ok((mass_run, ratio))
}

/// Initial overlaps released in free space: one run per level, the pair smoothing band by the rule of
/// `polydem::contact::wall_depth` (h ≈ the scene's characteristic overlap: here the initial overlap,
/// f × L). The band sweep shows what the default band (1e-4 L) does.
fn overlap_releases(p: &Params) -> Result<Releases, SuiteError> {
    let mut overlap_runs = Vec::new();
    let mut reached = Vec::new();
    let mut sweep = Vec::new();
    for (k, &f) in p.overlaps.iter().enumerate() {
        let mut level_rng = ChaCha8Rng::seed_from_u64(p.seed + 1 + k as u64);
        let (t, r) = overlap_scene(p, &mut level_rng, &[f])?;
        reached.extend(r);
        let mut sim = t.build(CASE, "overlaps")?;
        let default_band = sim.params.tolerances.pair_smoothing;
        let rule_band = PairSmoothing::Smoothed { band: f };
        sim.params.tolerances.pair_smoothing = rule_band;
        let steps =
            (p.release_contact_times * sim.time_step.contact_time / sim.params.dt).ceil() as u64;
        // The sweep: each band at Δt and Δt/2; the rule band at Δt is the checked run itself.
        let checked = run_scene(&format!("overlap_{f}"), sim.clone(), steps, 4);
        for (band_name, band) in [("default", default_band), ("rule", rule_band)] {
            for refine in [1u64, 2] {
                let (error, step_error) = if band_name == "rule" && refine == 1 {
                    (checked.energy_error_max, checked.step_error.clone())
                } else {
                    let mut s = sim.clone();
                    s.params.tolerances.pair_smoothing = band;
                    s.params.dt /= refine as Real;
                    let run = run_monitored(&mut s, steps * refine, 1, |_| {});
                    (run.energy_error_max, run.step_error)
                };
                sweep.push((f, band_name, band, error, step_error));
            }
        }
        overlap_runs.push(checked);
    }
    Ok(Releases {
        runs: overlap_runs,
        reached,
        sweep,
    })
}

/// The gated rows: the extremes reached, then per run its step errors, its contacts against the SAT
/// oracle, tunnelling and its energy error.
fn check_runs(
    ctx: &mut CaseContext,
    p: &Params,
    gates: &Gates,
    sliver_run: &ShapeRun,
    mass_run: &ShapeRun,
    ratio: Real,
    releases: &Releases,
) {
    let (reached, overlap_runs) = (&releases.reached, &releases.runs);
    let reached_max = reached.iter().cloned().fold(0.0, Real::max);
    let wanted_max = p.overlaps.iter().cloned().fold(0.0, Real::max);
    ctx.check(
        "mass_ratio_reached",
        ratio,
        Target::at_least(p.mass_ratio * (1.0 - 1e-9)),
        "1",
    );
    ctx.check(
        "initial_overlap_max_over_size",
        reached_max,
        Target::at_least(wanted_max * (1.0 - 1e-6)),
        "1",
    );
    let mut all = vec![(sliver_run, gates.walls), (mass_run, gates.walls)];
    all.extend(overlap_runs.iter().map(|r| (r, gates.free)));
    for (r, tol) in all {
        let n = &r.name;
        ctx.check(
            &format!("{n}_step_errors"),
            if r.step_error.is_some() { 1.0 } else { 0.0 },
            Target::equal(0.0),
            "1",
        );
        ctx.check(
            &format!("{n}_wrong_status_vs_sat"),
            r.oracle.wrong_status as f64,
            Target::equal(0.0),
            "1",
        );
        ctx.check(
            &format!("{n}_depth_error_vs_sat"),
            r.oracle.depth_error,
            Target::at_most(gates.depth),
            "1",
        );
        ctx.check(
            &format!("{n}_law_depth_excess_over_sat"),
            r.oracle.law_excess,
            Target::at_most(gates.depth),
            "1",
        );
        ctx.check(
            &format!("{n}_law_depth_shortfall_over_band"),
            r.oracle.law_shortfall_over_band,
            Target::at_most(gates.shortfall),
            "1",
        );
        ctx.check(
            &format!("{n}_oracle_overlapping_pairs"),
            r.oracle.overlapping as f64,
            Target::at_least(1.0),
            "1",
        );
        ctx.check(
            &format!("{n}_tunnelling"),
            (r.missed + r.pass_through) as f64,
            Target::equal(0.0),
            "1",
        );
        ctx.check(
            &format!("{n}_energy_error_max"),
            r.energy_error_max,
            Target::at_most(tol),
            "1",
        );
    }
}

/// The runs table.
fn report_runs(
    ctx: &mut CaseContext,
    sliver_run: &ShapeRun,
    mass_run: &ShapeRun,
    ratio: Real,
    releases: &Releases,
) -> Result<(), SuiteError> {
    let (reached, overlap_runs) = (&releases.reached, &releases.runs);
    ctx.section("Runs");
    let mut runs = vec![sliver_run, mass_run];
    runs.extend(overlap_runs.iter());
    let rows: Vec<Vec<String>> = runs
        .iter()
        .map(|r| {
            vec![
                r.name.clone(),
                r.bodies.to_string(),
                format!("{:.3e}", r.dt),
                r.steps.to_string(),
                r.step_error.clone().unwrap_or_else(|| "none".into()),
                r.oracle.pairs.to_string(),
                r.oracle.overlapping.to_string(),
                r.oracle.wrong_status.to_string(),
                format!("{:.2e}", r.oracle.depth_error),
                format!("{}/{}", r.missed, r.pass_through),
                format!("{:.3e}", r.max_overlap),
                format!("{:.3e}", r.energy_error_max),
            ]
        })
        .collect();
    ctx.table(
        Some("runs"),
        &[
            "scene",
            "bodies",
            "Δt (s)",
            "steps",
            "step error",
            "pair checks vs SAT",
            "overlapping (SAT)",
            "wrong status",
            "max depth error / size",
            "tunnelling missed/pass-through",
            "max overlap / size",
            "max abs(balance)/E0",
        ],
        &rows,
    )?;
    ctx.text(&format!(
        "Mass ratio reached: {ratio:.4e}. Initial overlaps (SAT depth / size) reached: {}.",
        reached
            .iter()
            .map(|r| format!("{r:.4}"))
            .collect::<Vec<_>>()
            .join(", ")
    ));
    Ok(())
}

/// The band sweep of the overlap releases.
fn report_sweep(ctx: &mut CaseContext, sweep: &[SweepRow]) -> Result<(), SuiteError> {
    ctx.section("Overlap releases: smoothing band and time step");
    let rows: Vec<Vec<String>> = sweep
        .chunks(2)
        .map(|pair| {
            let (f, name, band, e1, err1) = &pair[0];
            let (_, _, _, e2, err2) = &pair[1];
            let band = match band {
                PairSmoothing::Smoothed { band } => format!("{band:.1e} L ({name})"),
                PairSmoothing::Exact => format!("exact ({name})"),
            };
            let error = |e: &Real, err: &Option<String>| match err {
                Some(msg) => format!("step error: {msg}"),
                None => format!("{e:.3e}"),
            };
            vec![
                format!("{f}"),
                band,
                error(e1, err1),
                error(e2, err2),
                format!("{:.2}", (e1 / e2).log2()),
            ]
        })
        .collect();
    ctx.table(
        Some("overlap_band_sweep"),
        &[
            "initial overlap / L",
            "pair smoothing band h",
            "max abs(balance)/E0 at Δt",
            "at Δt/2",
            "observed order",
        ],
        &rows,
    )?;
    ctx.text(
        "The checked runs above use the rule band (h = the initial overlap). With the default band, \
         1e-4 L, far below these overlaps, the switch of the deepest vertex below a face (a kink of \
         kind (a) of `polydem::contact::pair_smoothing`) happens within one step: the force line jumps. \
         At the 0.25 level the balance read at that one step is off by an amount proportional to Δt \
         (the observed order about 1), while the steps before and after it stay an order of magnitude \
         lower. The rule band smooths the switch over many steps: second order at every level.",
    );
    Ok(())
}

/// The energy error against time of every run.
fn plot_energy(
    ctx: &mut CaseContext,
    p: &Params,
    sliver_run: &ShapeRun,
    mass_run: &ShapeRun,
    releases: &Releases,
) -> Result<(), SuiteError> {
    let (reached, overlap_runs) = (&releases.reached, &releases.runs);
    ctx.plot(&Plot {
        name: "energy_error".into(),
        title: "Energy error of the extreme-shape runs".into(),
        x_label: "t (s)".into(),
        y_label: "balance / E0 (1)".into(),
        x_log: false,
        y_log: false,
        series: vec![
            Series {
                label: "slivers (20:1 needles, plates, hulls)".into(),
                style: SeriesStyle::Line,
                points: sliver_run.history.clone(),
            },
            Series {
                label: format!("mass ratio 1:{:.0e}", p.mass_ratio),
                style: SeriesStyle::Line,
                points: mass_run.history.clone(),
            },
        ],
        caption: "Elastic, frictionless, closed box of walls; E0 the initial energy.".into(),
    })?;
    ctx.plot(&Plot {
        name: "overlap_release_energy".into(),
        title: "Energy error while releasing initial overlaps".into(),
        x_label: "t (s)".into(),
        y_label: "balance / E0 (1)".into(),
        x_log: false,
        y_log: false,
        series: overlap_runs
            .iter()
            .zip(reached)
            .map(|(r, f)| Series {
                label: format!("initial overlap {f:.3} of the size"),
                style: SeriesStyle::Line,
                points: r.history.clone(),
            })
            .collect(),
        caption:
            "One pair per run, released from rest; E0 is the elastic energy of the initial overlap."
                .into(),
    })?;
    Ok(())
}
