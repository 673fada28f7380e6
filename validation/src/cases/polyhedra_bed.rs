//! Case `polyhedra_bed`: the sphere-bed penetration with every sphere of the settled bed replaced
//! by a random convex polyhedron of the same volume (polydem only), run beside the sphere bed of the same
//! scene, to show what the shape of the grains does to the penetration.

pub mod bounds;
pub mod crossings;
pub mod generate;

use crate::provenance::workspace_root;
use crate::stats::relative_difference;
use std::path::Path;

use polydem::math::Real;

use generate::BedBody;

use super::projectile_history::{self, History, Metrics, QUANTITIES};

/// The sphere bed whose spheres are replaced (relative to the repository root).
pub const SPHERE_FILE: &str = "reference/sphere_bed/bed_quick.csv";
/// The settled state of the polyhedral bed (relative to the repository root).
pub const STATE_FILE: &str = "reference/sphere_bed/polyhedra_bed.csv";
/// Gap between the projectile and the highest point of the bed at the start (m), as in the sphere bed.
pub const PROJECTILE_GAP: Real = 0.5e-3;
/// Radius of the projectile (m), as in the sphere bed.
pub const PROJECTILE_RADIUS: Real = 5.0e-3;

/// The sphere-bed scene a variant is built from.
pub fn template_scene(variant: &str) -> Result<&'static str, String> {
    match variant {
        "a" | "a_hertz_5ms" => Ok("scenes/sphere_bed_a_hertz_5ms.toml"),
        "b" | "b_hertz_200ms" => Ok("scenes/sphere_bed_b_hertz_200ms.toml"),
        "c" | "c_linear_5ms" => Ok("scenes/sphere_bed_c_linear_5ms.toml"),
        _ => Err(format!("unknown variant '{variant}' (a, b or c)")),
    }
}

/// The polyhedral scene of a variant: the sphere scene's settings, laws, box and projectile, the projectile
/// placed `PROJECTILE_GAP` above the highest vertex of the settled polyhedral bed.
pub fn scene_for_variant(root: &Path, variant: &str) -> Result<(String, Vec<BedBody>), String> {
    let template_path = template_scene(variant)?;
    let template = std::fs::read_to_string(root.join(template_path))
        .map_err(|e| format!("{template_path}: {e}"))?;
    let spheres = generate::read_spheres(&root.join(SPHERE_FILE))?;
    let state =
        std::fs::read_to_string(root.join(STATE_FILE)).map_err(|e| format!("{STATE_FILE}: {e}"))?;
    let bodies = generate::bed_bodies(&spheres, &state)?;
    let z0 = generate::bed_top(&bodies) + PROJECTILE_GAP + PROJECTILE_RADIUS;
    let header = format!(
        "# The sphere-bed penetration of {template_path} with every sphere of {SPHERE_FILE} replaced by a\n\
         # random convex polyhedron of equal volume, settled ({STATE_FILE}); written by\n\
         # validation/examples/generate_polyhedra_bed.rs (validation case polyhedra_bed). Projectile centre\n\
         # {PROJECTILE_GAP} m + its radius above the highest vertex of the bed.\n"
    );
    let text = generate::scene_text(&template, &bodies, Some(z0), &[], &header)?;
    Ok((text, bodies))
}

use std::time::Instant;

use polydem::contact::contact_polyhedron_polyhedron::sat_polyhedra;
use polydem::contact::ContactKind;
use polydem::scene::{load_scene, parse_scene, Simulation};
use polydem::shape::Shape;
use polydem::world::{step, StepScratch};
use serde::Deserialize;

use crate::case::{Case, CaseData, Profile, Target};
use crate::context::CaseContext;
use crate::error::SuiteError;
use crate::plot::{Plot, Series, SeriesStyle};

/// The case (registered in [`crate::cases::registry`]).
pub struct PolyhedraBed;

const NAME: &str = "polyhedra_bed";

#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct Variant {
    /// Variant of the sphere bed: `a_hertz_5ms`, `b_hertz_200ms` or `c_linear_5ms`.
    name: String,
    /// Steps to run (at most the scene's); fewer steps compare the first part of the run.
    steps: Option<u64>,
}

#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct Params {
    variants: Vec<Variant>,
    /// The tunnelling monitor observes every this many steps.
    tunnelling_every: u64,
}

fn fail(msg: String) -> SuiteError {
    SuiteError::case(NAME, msg)
}

/// What one bed's run gave.
struct BedRun {
    history: History,
    z0: Real,
    v0: Real,
    ke0: Real,
    steps: u64,
    particles: usize,
    wall_time_s: Real,
    /// Largest |energy balance| / initial kinetic energy of the projectile over the samples.
    ledger_error: Real,
    /// Non-finite values among the sampled quantities and the final state.
    non_finite: u64,
    /// Largest Minkowski overlap of any contact at the end of any step (m).
    max_depth: Real,
    /// Crossings found by the tunnelling monitor.
    crossings: u64,
    /// Highest point of the bed at the start (m).
    bed_top: Real,
}

fn projectile_index(sim: &Simulation) -> Result<usize, SuiteError> {
    sim.world
        .names()
        .iter()
        .position(|n| n == "projectile")
        .ok_or_else(|| fail("no body named 'projectile'".into()))
}

/// Highest point of the bed (every body but the projectile) in the world's current state (m).
fn world_bed_top(sim: &Simulation, projectile: usize) -> Real {
    (0..sim.world.bodies().len())
        .filter(|&i| i != projectile)
        .map(|i| {
            let pose = sim.world.pose(i);
            match sim.world.shape(i) {
                Shape::Polyhedron(p) => p
                    .vertices()
                    .iter()
                    .map(|v| (pose * v).z)
                    .fold(Real::NEG_INFINITY, Real::max),
                Shape::Sphere(s) => pose.translation.vector.z + s.radius(),
                Shape::Plane(_) => Real::NEG_INFINITY,
                other => other
                    .convex()
                    .map_or(Real::NEG_INFINITY, |c| c.aabb(&pose).maxs.z),
            }
        })
        .fold(Real::NEG_INFINITY, Real::max)
}

/// Runs `steps` steps on one thread, sampling the projectile at the output interval, with the ledger,
/// overlap and tunnelling monitors.
fn run_bed(
    mut sim: Simulation,
    steps: u64,
    tunnelling_every: u64,
    label: &str,
    ctx: &mut CaseContext,
) -> Result<BedRun, SuiteError> {
    let projectile = projectile_index(&sim)?;
    let steps = steps.min(sim.steps);
    let p = &sim.world.bodies()[projectile];
    let (z0, v0) = (p.position.z, p.velocity.norm());
    let ke0 = p.translational_kinetic_energy();
    let bed_top = world_bed_top(&sim, projectile);
    let particles = sim.world.bodies().len();
    let every = sim.output_every;
    ctx.progress().stage(label, steps);
    let progress = ctx.progress();
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .map_err(|e| fail(format!("one-thread pool: {e}")))?;
    let mut history = History::default();
    let mut ledger_error: Real = 0.0;
    let mut non_finite = 0u64;
    let mut max_depth: Real = 0.0;
    let mut crossings = 0u64;
    let mut monitor = crossings::CrossingMonitor::new(&sim.world);
    let mut sample = |sim: &Simulation, history: &mut History| {
        let b = &sim.world.bodies()[projectile];
        let fz = sim
            .world
            .loads()
            .forces()
            .get(projectile)
            .map_or(0.0, |f| f.z);
        let contacts = sim
            .world
            .contacts()
            .keys()
            .iter()
            .zip(sim.world.contacts().states())
            .filter(|(k, s)| {
                s.geometry.kind == ContactKind::Overlap
                    && matches!(k, polydem::world::ContactKey::Body { a, b }
                        if *a as usize == projectile || *b as usize == projectile)
            })
            .count() as Real;
        let values = [sim.world.time(), b.position.z, b.velocity.z, fz];
        non_finite += values.iter().filter(|v| !v.is_finite()).count() as u64;
        history.t.push(values[0]);
        history.z.push(values[1]);
        history.vz.push(values[2]);
        history.fz.push(values[3]);
        history.contacts.push(contacts);
    };
    let mut run_error = None;
    let wall = pool.install(|| {
        let mut scratch = StepScratch::default();
        let start = Instant::now();
        sample(&sim, &mut history);
        for n in 1..=steps {
            if let Err(e) = step(&sim.params, &mut sim.world, &mut scratch) {
                run_error = Some(format!("step {n}: {e}"));
                break;
            }
            for s in sim.world.contacts().states() {
                if s.geometry.kind == ContactKind::Overlap {
                    max_depth = max_depth.max(s.geometry.depth);
                }
            }
            if n % tunnelling_every == 0 {
                crossings += monitor.observe(&sim.world);
            }
            if n % every == 0 || n == steps {
                sample(&sim, &mut history);
                let err = (sim.world.energy().balance / ke0).abs();
                ledger_error = ledger_error.max(if err.is_nan() { Real::INFINITY } else { err });
            }
            if n % 500 == 0 {
                progress.inc(500);
            }
        }
        start.elapsed().as_secs_f64()
    });
    if let Some(e) = run_error {
        return Err(fail(format!("{label}: {e}")));
    }
    non_finite += sim
        .world
        .bodies()
        .iter()
        .filter(|b| {
            !(b.position.coords.iter().all(|v| v.is_finite())
                && b.velocity.iter().all(|v| v.is_finite())
                && b.angular_momentum.iter().all(|v| v.is_finite()))
        })
        .count() as u64;
    Ok(BedRun {
        history,
        z0,
        v0,
        ke0,
        steps,
        particles,
        wall_time_s: wall,
        ledger_error,
        non_finite,
        max_depth,
        crossings,
        bed_top,
    })
}

/// The metrics of a bed run over all its samples.
fn metrics(label: &str, run: &BedRun) -> Result<Metrics, SuiteError> {
    projectile_history::metrics(&run.history, run.z0, run.v0, Real::INFINITY)
        .ok_or_else(|| fail(format!("{label}: the run has no samples")))
}

/// Largest Minkowski overlap of the initial polyhedral bed (m): every pair of bodies within reach, by the
/// exact SAT oracle, and every body against the box's walls.
fn initial_overlap(bodies: &[BedBody], side: Real) -> Result<Real, SuiteError> {
    let placed = generate::place(bodies).map_err(fail)?;
    let mut worst: Real = 0.0;
    for (i, j) in generate::candidate_pairs(bodies, 0.0) {
        let g = sat_polyhedra(
            &generate::world_pose(&bodies[i], &placed[i]),
            &placed[i].poly,
            &generate::world_pose(&bodies[j], &placed[j]),
            &placed[j].poly,
        );
        if g.kind == ContactKind::Overlap {
            worst = worst.max(g.depth);
        }
    }
    for b in bodies {
        for w in generate::box_walls(side) {
            worst = worst.max(generate::wall_depth(b, &w));
        }
    }
    Ok(worst)
}

/// Density of material `name` of a scene file.
fn scene_density(template: &str, name: &str) -> Result<Real, SuiteError> {
    let table: toml::Table =
        toml::from_str(template).map_err(|e| fail(format!("scene template: {e}")))?;
    table
        .get("material")
        .and_then(toml::Value::as_array)
        .and_then(|a| {
            a.iter()
                .find(|m| m.get("name").and_then(toml::Value::as_str) == Some(name))
        })
        .and_then(|m| m.get("density"))
        .and_then(toml::Value::as_float)
        .ok_or_else(|| fail(format!("scene template: no density of material '{name}'")))
}

/// The case's tolerances and references, read once.
struct Gates {
    volume_tol: Real,
    ledger_tol: Real,
    mean_diameter: Real,
    box_side: Real,
}

/// What the variants add to the closing section.
#[derive(Default)]
struct Closing {
    summary_rows: Vec<Vec<String>>,
    speed_rows: Vec<Vec<String>>,
    paragraphs: Vec<String>,
}

impl Case for PolyhedraBed {
    fn name(&self) -> &'static str {
        NAME
    }

    fn data(&self) -> &'static str {
        include_str!("../../cases/polyhedra_bed.toml")
    }

    fn run(
        &self,
        data: &CaseData,
        profile: Profile,
        ctx: &mut CaseContext,
    ) -> Result<(), SuiteError> {
        let p: Params = data.params(NAME, profile)?;
        let gates = Gates {
            volume_tol: data.tolerance(NAME, "volume_rel")?.value,
            ledger_tol: data.tolerance(NAME, "ledger_rel")?.value,
            mean_diameter: data.reference(NAME, "mean_bed_diameter")?.value,
            box_side: data.reference(NAME, "box_side")?.value,
        };
        let root = workspace_root();
        let spheres = generate::read_spheres(&root.join(SPHERE_FILE)).map_err(fail)?;
        intro(ctx, &root)?;
        let mut out = Closing::default();
        for variant in &p.variants {
            run_variant(ctx, &p, variant, &gates, &spheres, &mut out)?;
        }
        closing(ctx, &out)
    }
}

/// How the polyhedral bed was made, with the provenance of its settled state.
fn intro(ctx: &mut CaseContext, root: &Path) -> Result<(), SuiteError> {
    let state_header: Vec<String> = std::fs::read_to_string(root.join(STATE_FILE))
        .map_err(SuiteError::io(root.join(STATE_FILE)))?
        .lines()
        .take_while(|l| l.starts_with('#'))
        .map(|l| l.trim_start_matches('#').trim().to_owned())
        .collect();
    ctx.text(&format!(
        "Every sphere of the settled sphere bed (`{SPHERE_FILE}`, 3000 spheres, radius 1.6–2.4 mm) is \
         replaced by a random convex polyhedron of the same volume: the convex hull of {}–{} seeded \
         random points on a sphere (dart throwing, no two closer than {} of their mean spacing, so no \
         sliver), its centroid at the sphere's centre, scaled to (4/3)πr³; the points are isotropic, \
         so the orientation is random. The polyhedra stick out of the spheres they replace (circumradius \
         1.13–1.43 times the equal-volume radius) and overlapped their neighbours and the walls; they \
         were not shrunk. The overlaps were removed by moving the centroids (the bed's centres \
         stretched vertically by 1.2, then Gauss–Seidel sweeps separating each overlapping pair along \
         the EPA normal), and the bed settled again under gravity with its own Hertz–Mindlin law in \
         polydem, velocities dropped at the end (`validation/examples/generate_polyhedra_bed.rs`, \
         `validation/src/cases/polyhedra_bed/generate.rs`). The settled state is `{STATE_FILE}`; its \
         provenance:\n\n{}\n\n\
         Both beds are then struck by the same steel sphere with the same laws, time step and sampling \
         (the scene files `scenes/sphere_bed_*.toml`; the polyhedral scene is that file with the \
         `[[body_file]]` of spheres replaced, written by the example's `scene` command). The projectile \
         starts 0.5 mm above the highest point of its bed in both; depth is z0 − z from that start. \
         The Hertz–Mindlin law of a polyhedron in polydem (`src/law/pair.rs`) is the sphere law with \
         the Minkowski overlap δ_M as δ and, as R, the radius of the sphere of equal volume — here the \
         radius of the sphere each polyhedron replaced — so a contact of two polyhedra has the \
         stiffness of the two spheres they replaced at the same overlap, whatever the features in \
         contact (vertex, edge or face): the shape changes where and along which normal the contacts \
         act, not the law. The linear spring–dashpot law of variant c has one k_n and one dashpot per \
         pair whatever the shape (f = k_n δ_M + c_n δ̇_M), as LIGGGHTS' `hooke/stiffness` has for \
         spheres.",
        generate::MIN_POINTS,
        generate::MAX_POINTS,
        generate::MIN_SPACING,
        state_header
            .iter()
            .map(|l| format!("- {l}"))
            .collect::<Vec<_>>()
            .join("\n"),
    ));
    Ok(())
}

/// Both beds of one variant run, compared, checked and plotted.
fn run_variant(
    ctx: &mut CaseContext,
    p: &Params,
    variant: &Variant,
    gates: &Gates,
    spheres: &[polydem::scene::body_file::SphereRow],
    out: &mut Closing,
) -> Result<(), SuiteError> {
    let root = workspace_root();
    let v = &variant.name;
    let template_path = template_scene(v).map_err(fail)?;
    let template = std::fs::read_to_string(root.join(template_path))
        .map_err(SuiteError::io(root.join(template_path)))?;
    let (text, bodies) = scene_for_variant(&root, v).map_err(fail)?;
    let bed = BedBounds::of(&bodies, spheres, &template, gates)?;
    let sim_poly = parse_scene(&text, Path::new(&format!("polyhedra_bed_{v}.toml")))
        .map_err(|e| fail(e.to_string()))?;
    let sim_sphere = load_scene(&root.join(template_path)).map_err(|e| fail(e.to_string()))?;
    let steps = variant.steps.unwrap_or(u64::MAX).min(sim_poly.steps);
    let spheres_run = run_bed(
        sim_sphere,
        steps,
        p.tunnelling_every,
        &format!("{v} spheres"),
        ctx,
    )?;
    let poly_run = run_bed(
        sim_poly,
        steps,
        p.tunnelling_every,
        &format!("{v} polyhedra"),
        ctx,
    )?;
    let overlap_bound = bed.law.energy_overlap(poly_run.ke0, 0.5 * bed.r_min);
    let t_end = *poly_run.history.t.last().unwrap_or(&0.0);

    ctx.section(&format!("{v} (t ≤ {:.4} ms)", t_end * 1e3));
    let (ms, mp) = (
        metrics(&format!("{v} spheres"), &spheres_run)?,
        metrics(&format!("{v} polyhedra"), &poly_run)?,
    );
    let solid_fraction = |top: Real| {
        spheres
            .iter()
            .map(|s| 4.0 / 3.0 * std::f64::consts::PI * s.radius.powi(3))
            .sum::<Real>()
            / (gates.box_side * gates.box_side * top)
    };
    ctx.text(&format!(
        "Scene `{template_path}` and its polyhedral version; {steps} steps (t ≤ {:.4} ms) of the \
         scene's {}. Both beds hold the same 3000 grain volumes; the sphere bed's top is at {:.2} mm \
         (solid fraction below the top {:.3}), the polyhedral bed's at {:.2} mm ({:.3}).",
        t_end * 1e3,
        spheres_run.steps.max(steps),
        spheres_run.bed_top * 1e3,
        solid_fraction(spheres_run.bed_top),
        poly_run.bed_top * 1e3,
        solid_fraction(poly_run.bed_top),
    ));
    comparison_table(ctx, v, &ms, &mp)?;
    checks_table(ctx, p, gates, &spheres_run, &poly_run)?;
    check_variant(ctx, v, gates, &bed, &poly_run, overlap_bound);
    plot_variant(ctx, v, &spheres_run, &poly_run)?;
    out.paragraphs.push(paragraph(v, t_end, &ms, &mp));
    closing_rows(out, v, (&ms, &mp), (&spheres_run, &poly_run));
    Ok(())
}

/// The generated bed's gated facts and the bounds its overlaps are held to.
struct BedBounds {
    /// The largest relative volume error of a polyhedron against its sphere.
    volume_error: Real,
    law: bounds::BedLaw,
    /// The smallest grain radius.
    r_min: Real,
    /// The bed's whole weight on one contact of the two smallest grains: no static contact carries more.
    static_bound: Real,
    /// The largest initial overlap.
    initial: Real,
}

impl BedBounds {
    fn of(
        bodies: &[generate::BedBody],
        spheres: &[polydem::scene::body_file::SphereRow],
        template: &str,
        gates: &Gates,
    ) -> Result<Self, SuiteError> {
        let placed = generate::place(bodies).map_err(fail)?;
        let volume_error = bodies
            .iter()
            .zip(&placed)
            .map(|(b, pl)| {
                let sphere = 4.0 / 3.0 * std::f64::consts::PI * b.radius.powi(3);
                (pl.poly.mass_properties().volume / sphere - 1.0).abs()
            })
            .fold(0.0, Real::max);
        let bed_density = scene_density(template, "bed")?;
        let law = bounds::BedLaw::from_scene(template).map_err(fail)?;
        let r_min = spheres
            .iter()
            .map(|s| s.radius)
            .fold(Real::INFINITY, Real::min);
        let bed_mass: Real = spheres
            .iter()
            .map(|s| bed_density * 4.0 / 3.0 * std::f64::consts::PI * s.radius.powi(3))
            .sum();
        let static_bound = law.static_overlap(bed_mass * 9.81, 0.5 * r_min);
        Ok(Self {
            volume_error,
            law,
            r_min,
            static_bound,
            initial: initial_overlap(bodies, gates.box_side)?,
        })
    }
}

/// The quantities of both beds side by side.
fn comparison_table(
    ctx: &mut CaseContext,
    v: &str,
    ms: &Metrics,
    mp: &Metrics,
) -> Result<(), SuiteError> {
    // Both runs count the projectile's contacts at every sample.
    let contacts = |m: &Metrics| m.mean_contacts.unwrap_or(Real::NAN);
    let row = |heading: String, a: Real, b: Real| {
        vec![
            heading,
            CaseContext::fmt(a),
            CaseContext::fmt(b),
            CaseContext::fmt(b / a),
        ]
    };
    let mut rows: Vec<Vec<String>> = QUANTITIES
        .iter()
        .map(|q| row(q.heading(), q.of(ms), q.of(mp)))
        .collect();
    rows.push(row(
        "mean projectile contacts after first contact [-]".into(),
        contacts(ms),
        contacts(mp),
    ));
    ctx.table(
        Some(&format!("{v}_table")),
        &["quantity", "spheres", "polyhedra", "polyhedra / spheres"],
        &rows,
    )
}

/// The checks of both runs (the polyhedral one gated).
fn checks_table(
    ctx: &mut CaseContext,
    p: &Params,
    gates: &Gates,
    spheres_run: &BedRun,
    poly_run: &BedRun,
) -> Result<(), SuiteError> {
    let checks_rows = [("spheres", spheres_run), ("polyhedra", poly_run)]
        .iter()
        .map(|(bed, r)| {
            vec![
                (*bed).to_owned(),
                CaseContext::fmt(r.ledger_error),
                CaseContext::fmt(r.max_depth / gates.mean_diameter),
                format!("{}", r.crossings),
                format!("{}", r.non_finite),
            ]
        })
        .collect::<Vec<_>>();
    ctx.text(&format!(
        "Checks on both runs (the rows below gate the polyhedral one): the energy ledger's largest \
         |balance| over the samples relative to the projectile's initial kinetic energy \
         ({:.4e} J); the largest Minkowski overlap of any contact at the end of any step; body \
         centres that went through another body or a wall (the definition of \
         `polydem::world::tunnelling`, candidates from a grid: `polyhedra_bed/crossings.rs`; observed \
         every {} steps); non-finite sampled values.",
        poly_run.ke0, p.tunnelling_every
    ));
    ctx.table(
        None,
        &[
            "bed",
            "ledger |balance| / KE0",
            "max overlap [mean diameters]",
            "crossings",
            "non-finite values",
        ],
        &checks_rows,
    )
}

/// A variant's rows of the closing summary and speed tables.
fn closing_rows(
    out: &mut Closing,
    v: &str,
    (ms, mp): (&Metrics, &Metrics),
    (spheres_run, poly_run): (&BedRun, &BedRun),
) {
    out.summary_rows.push(vec![
        v.to_owned(),
        format!("{:.3}", ms.final_depth * 1e3),
        format!("{:.3}", mp.final_depth * 1e3),
        format!("{:.3}", ms.peak_force),
        format!("{:.3}", mp.peak_force),
        format!("{:.3}", ms.final_vz),
        format!("{:.3}", mp.final_vz),
        format!("{:.3}", relative_difference(ms.impulse, mp.impulse)),
    ]);
    for (bed, r) in [("spheres", spheres_run), ("polyhedra", poly_run)] {
        out.speed_rows.push(vec![
            v.to_owned(),
            bed.to_owned(),
            format!("{}", r.steps),
            format!("{:.2}", r.wall_time_s),
            format!(
                "{:.3e}",
                r.particles as Real * r.steps as Real / r.wall_time_s
            ),
        ]);
    }
}

/// The gated rows of a variant (the polyhedral run's).
fn check_variant(
    ctx: &mut CaseContext,
    v: &str,
    gates: &Gates,
    bed: &BedBounds,
    poly_run: &BedRun,
    overlap_bound: Real,
) {
    let BedBounds {
        volume_error,
        ref law,
        static_bound,
        initial,
        ..
    } = *bed;
    ctx.check(
        &format!("{v}_volume_rel_error"),
        volume_error,
        Target::at_most(gates.volume_tol),
        "1 (max over the 3000 polyhedra of |V / ((4/3)πr³) − 1|)",
    );
    ctx.check(
        &format!("{v}_initial_max_overlap"),
        initial / gates.mean_diameter,
        Target::at_most(static_bound / gates.mean_diameter),
        &format!("mean bed diameters (exact SAT oracle and walls, settled bed; bound: {} overlap of the bed's whole weight on one contact of the two smallest grains)", law.describe()),
    );
    ctx.check(
        &format!("{v}_non_finite_values"),
        poly_run.non_finite as Real,
        Target::equal(0.0),
        "count",
    );
    ctx.check(
        &format!("{v}_ledger_error"),
        poly_run.ledger_error,
        Target::at_most(gates.ledger_tol),
        "1 (max |balance| / projectile's initial kinetic energy)",
    );
    ctx.check(
        &format!("{v}_max_overlap"),
        poly_run.max_depth / gates.mean_diameter,
        Target::at_most(overlap_bound / gates.mean_diameter),
        &format!("mean bed diameters (bound: one {} contact of the softest pair holding the projectile's whole kinetic energy)", law.describe()),
    );
    ctx.check(
        &format!("{v}_tunnelling_crossings"),
        poly_run.crossings as Real,
        Target::equal(0.0),
        "count",
    );
}

/// The projectile's depth, velocity and force against time, spheres and polyhedra overlaid.
fn plot_variant(
    ctx: &mut CaseContext,
    v: &str,
    spheres_run: &BedRun,
    poly_run: &BedRun,
) -> Result<(), SuiteError> {
    let series = |run: &BedRun, label: &str, f: &dyn Fn(&BedRun, usize) -> Real| Series {
        label: label.into(),
        style: SeriesStyle::Line,
        points: (0..run.history.t.len())
            .map(|i| (run.history.t[i] * 1e3, f(run, i)))
            .collect(),
    };
    for (quantity, y_label, pick) in [
        (
            "depth",
            "depth z0 − z (mm)",
            &(|r: &BedRun, i: usize| (r.z0 - r.history.z[i]) * 1e3)
                as &dyn Fn(&BedRun, usize) -> Real,
        ),
        (
            "velocity",
            "vertical velocity (m/s)",
            &|r: &BedRun, i: usize| r.history.vz[i],
        ),
        (
            "force",
            "vertical contact force (N)",
            &|r: &BedRun, i: usize| r.history.fz[i],
        ),
    ] {
        ctx.plot(&Plot {
            name: format!("{v}_{quantity}"),
            title: format!("{v}: projectile {quantity}, spheres vs polyhedra"),
            x_label: "t (ms)".into(),
            y_label: y_label.into(),
            x_log: false,
            y_log: false,
            series: vec![
                series(spheres_run, "sphere bed", pick),
                series(poly_run, "polyhedral bed (equal volumes)", pick),
            ],
            caption: format!(
                "Projectile {quantity} against time in the sphere bed and in the same bed of \
                 polyhedra of equal volume (polydem, same law and step)."
            ),
        })?;
    }
    Ok(())
}

/// What the shape did in a variant, in words.
fn paragraph(v: &str, t_end: Real, ms: &Metrics, mp: &Metrics) -> String {
    let contacts = |m: &Metrics| m.mean_contacts.unwrap_or(Real::NAN);
    format!(
                "**{v}** (first {:.2} ms): in the polyhedral bed the projectile reaches a depth of {:.2} mm \
                 against {:.2} mm in the sphere bed ({:+.0} %); its peak contact force is {:.3} N against \
                 {:.3} N ({:+.0} %), at {:.3} ms against {:.3} ms; the vertical contact impulse is {:.4} N s \
                 against {:.4} N s; {}; vertical velocity at the end {:.3} m/s against {:.3} m/s; it touches \
                 {:.2} grains on average against {:.2}.",
                t_end * 1e3,
                mp.final_depth * 1e3,
                ms.final_depth * 1e3,
                100.0 * (mp.final_depth / ms.final_depth - 1.0),
                mp.peak_force,
                ms.peak_force,
                100.0 * (mp.peak_force / ms.peak_force - 1.0),
                mp.peak_time * 1e3,
                ms.peak_time * 1e3,
                mp.impulse,
                ms.impulse,
                match (mp.slow_time.is_nan(), ms.slow_time.is_nan()) {
                    (true, true) => "in neither bed does its speed fall below 10 % of v0 within the window"
                        .to_owned(),
                    (false, false) => format!(
                        "its speed falls below 10 % of v0 at {:.3} ms against {:.3} ms",
                        mp.slow_time * 1e3,
                        ms.slow_time * 1e3
                    ),
                    (false, true) => format!(
                        "its speed falls below 10 % of v0 at {:.3} ms, in the sphere bed not within the window",
                        mp.slow_time * 1e3
                    ),
                    (true, false) => format!(
                        "its speed stays above 10 % of v0 within the window, in the sphere bed it falls below at {:.3} ms",
                        ms.slow_time * 1e3
                    ),
                },
                mp.final_vz,
                ms.final_vz,
                contacts(mp),
                contacts(ms),
            )
}

/// The summary of every variant and the cost table.
fn closing(ctx: &mut CaseContext, out: &Closing) -> Result<(), SuiteError> {
    ctx.section("What the shape does");
    ctx.text(&out.paragraphs.join("\n\n"));
    ctx.table(
        Some("summary"),
        &[
            "variant",
            "final depth spheres [mm]",
            "polyhedra [mm]",
            "peak force spheres [N]",
            "polyhedra [N]",
            "final v_z spheres [m/s]",
            "polyhedra [m/s]",
            "impulse, relative difference",
        ],
        &out.summary_rows,
    )?;
    ctx.section("Cost (one thread, with the monitors)");
    ctx.text(
        "Wall time of the stepping loop including this case's monitors (overlap scan every step, \
         tunnelling monitor), so not a speed figure of the engine; the machine is shared.",
    );
    ctx.table(
        Some("cost"),
        &[
            "variant",
            "bed",
            "steps",
            "wall time [s]",
            "particle-steps/s",
        ],
        &out.speed_rows,
    )?;
    Ok(())
}
