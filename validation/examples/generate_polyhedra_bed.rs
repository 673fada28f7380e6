//! Generates the polyhedral sphere-bed and writes its settled state
//! (`reference/sphere_bed/polyhedra_bed.csv`), or writes a runnable scene file of it.
//!
//! ```sh
//! cargo run --release -p polydem-validation --example generate_polyhedra_bed -- settle [SECONDS] [DAMPING]
//! cargo run --release -p polydem-validation --example generate_polyhedra_bed -- scene a|b OUT.toml
//! ```
//!
//! `settle`: the polyhedra of `polydem_validation::cases::polyhedra_bed::generate` (seeded) at the spheres'
//! centres of `reference/sphere_bed/bed_quick.csv`, their overlaps removed by moving centroids, then settled
//! under gravity for SECONDS (default 0.05 s) with the bed's Hertz–Mindlin law of
//! `scenes/sphere_bed_a_hertz_5ms.toml` and a global viscous damping rate DAMPING (1/s, default 20), one
//! thread; velocities are dropped at the end (as the sphere bed's importers do). `scene`: the polyhedral
//! bed with the projectile of variant a (5 m/s) or b (200 m/s), as the validation case `polyhedra_bed` runs
//! it (about 2.5 MB of TOML, hence not committed).

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{bail, Context, Result};
use polydem::math::Real;
use polydem::scene::parse_scene;
use polydem_validation::cases::polyhedra_bed::generate::{self as g, BedBody};
use polydem_validation::cases::polyhedra_bed::{scene_for_variant, SPHERE_FILE, STATE_FILE};

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .map(Path::to_path_buf)
        .unwrap_or_else(|| PathBuf::from(".."))
}

/// Vertical stretch of the sphere bed's centres before the overlaps are removed.
const STRETCH: Real = 1.2;
/// Time step of the settling run (s): 0.30 of the Rayleigh time of the smallest sphere, the step of the
/// sphere bed's own settling run (reference/sphere_bed/README.md).
const SETTLE_DT: Real = 4e-6;

fn settle(seconds: Real, damping: Real) -> Result<()> {
    let root = root();
    let spheres = g::read_spheres(&root.join(SPHERE_FILE)).map_err(anyhow::Error::msg)?;
    let mut bodies = g::initial_bodies(&spheres).map_err(anyhow::Error::msg)?;
    let walls = g::box_walls(0.05);
    let gap = 1e-6;
    let t0 = Instant::now();
    // Stretch the bed vertically first (centres' z times STRETCH): it must grow anyway, and Gauss–Seidel
    // sweeps move a whole column up only slowly.
    for b in bodies.iter_mut() {
        b.position.z *= STRETCH;
    }
    let push = g::push_apart(&mut bodies, &walls, gap, 3000, |sweep, pairs, worst| {
        if sweep % 50 == 0 {
            eprintln!("push-apart sweep {sweep}: {pairs} overlapping pairs, largest {worst:.3e} m");
        }
    })
    .map_err(anyhow::Error::msg)?;
    eprintln!(
        "push-apart: {push:?} in {:.1} s",
        t0.elapsed().as_secs_f64()
    );
    if push.final_max_overlap > 0.0 {
        bail!("push-apart left overlaps: {push:?}");
    }
    let top_pushed = g::bed_top(&bodies);
    let template = std::fs::read_to_string(root.join("scenes/sphere_bed_a_hertz_5ms.toml"))?;
    let text = g::scene_text(
        &template,
        &bodies,
        None,
        &[
            ("end_time", seconds),
            ("time_step", SETTLE_DT),
            ("viscous_damping_rate", damping),
        ],
        "",
    )
    .map_err(anyhow::Error::msg)?;
    let mut sim = parse_scene(&text, Path::new("polyhedra_bed_settle.toml"))?;
    let pool = rayon::ThreadPoolBuilder::new().num_threads(1).build()?;
    let t1 = Instant::now();
    let steps = sim.steps;
    let summary = pool.install(|| {
        sim.run(
            |_| Ok(()),
            |s, n| {
                if n % 2500 == 0 {
                    let e = s.world.energy();
                    eprintln!(
                        "settle step {n}/{steps}: kinetic {:.3e} J, {:.0} s",
                        e.translational_kinetic + e.rotational_kinetic,
                        t1.elapsed().as_secs_f64()
                    );
                }
                Ok(())
            },
        )
    })?;
    let settle_wall = t1.elapsed().as_secs_f64();
    let e = sim.world.energy();
    let vmax = sim
        .world
        .bodies()
        .iter()
        .map(|b| b.velocity.norm())
        .fold(0.0, Real::max);
    // The settled state: the origin of each body's own frame (its centroid, to round-off) and orientation.
    let names: Vec<&String> = sim.world.names().iter().collect();
    for b in bodies.iter_mut() {
        let name = format!("bed{}", b.id);
        let i = names
            .iter()
            .position(|n| **n == name)
            .with_context(|| format!("settled world lacks {name}"))?;
        let r_in = sim.input_orientation(i);
        let body = &sim.world.bodies()[i];
        b.position = body.position.coords - r_in * sim.frames[i].translation.vector;
        b.orientation = r_in;
    }
    let header = vec![
        "polyhedra_bed.csv: the sphere bed of bed_quick.csv with every sphere replaced by a random convex polyhedron of equal volume, settled (reference/sphere_bed/README.md, validation case polyhedra_bed)".to_owned(),
        format!(
            "generator: validation/examples/generate_polyhedra_bed.rs settle {seconds} {damping} (shapes: validation/src/cases/polyhedra_bed/generate.rs, seed {}, {}-{} points on the unit sphere per shape)",
            g::SEED, g::MIN_POINTS, g::MAX_POINTS
        ),
        format!("centres' z stretched by {STRETCH} first"),
        format!(
            "push-apart: {} overlapping pairs before, largest overlap {:.4e} m (body-body) and {:.4e} m (walls); {} Gauss-Seidel sweeps, gap {gap:e} m; largest centroid displacement {:.4e} m; bed top {:.6e} m after it",
            push.initial_overlapping_pairs, push.initial_max_overlap, push.initial_max_wall_overlap, push.sweeps, push.max_displacement, top_pushed
        ),
        format!(
            "settle: polydem, gravity 9.81 m/s^2, bed Hertz-Mindlin law of scenes/sphere_bed_a_hertz_5ms.toml, dt {:e} s, {} steps ({seconds} s), global viscous damping rate {damping} 1/s, one thread, wall time {settle_wall:.1} s",
            sim.params.dt, summary.steps
        ),
        format!(
            "settled: kinetic energy {:.4e} J, largest speed {:.4e} m/s, largest overlap / particle size {:.4e} during the settle; velocities dropped; bed top {:.6e} m",
            e.translational_kinetic + e.rotational_kinetic,
            vmax,
            summary.max_overlap_ratio,
            g::bed_top(&bodies)
        ),
        format!("date: {}", polydem_validation::provenance::utc_now()),
        "columns: id (of the sphere replaced), centroid x,y,z (m), orientation of the body's own frame as a unit quaternion qw,qx,qy,qz, radius of the sphere replaced (m)".to_owned(),
    ];
    let out = root.join(STATE_FILE);
    std::fs::write(&out, g::write_state(&bodies, &header))?;
    eprintln!("wrote {}", out.display());
    Ok(())
}

fn scene(variant: &str, out: &Path) -> Result<()> {
    let root = root();
    let (text, _bodies): (String, Vec<BedBody>) =
        scene_for_variant(&root, variant).map_err(anyhow::Error::msg)?;
    std::fs::write(out, text)?;
    eprintln!("wrote {}", out.display());
    Ok(())
}

fn main() -> Result<()> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    match args.first().map(String::as_str) {
        Some("settle") => {
            let seconds = args.get(1).map_or(Ok(0.05), |s| s.parse())?;
            let damping = args.get(2).map_or(Ok(20.0), |s| s.parse())?;
            settle(seconds, damping)
        }
        Some("stats") => {
            let spheres = g::read_spheres(&root().join(SPHERE_FILE)).map_err(anyhow::Error::msg)?;
            let bodies = g::initial_bodies(&spheres).map_err(anyhow::Error::msg)?;
            let mut ratios: Vec<Real> = bodies
                .iter()
                .map(|b| {
                    b.points
                        .iter()
                        .map(|p| p.coords.norm())
                        .fold(0.0, Real::max)
                        / b.radius
                })
                .collect();
            ratios.sort_by(Real::total_cmp);
            let n = ratios.len();
            eprintln!(
                "circumradius / equal-volume radius: min {:.3}, median {:.3}, p99 {:.3}, max {:.3}",
                ratios[0],
                ratios[n / 2],
                ratios[n * 99 / 100],
                ratios[n - 1]
            );
            Ok(())
        }
        Some("scene") if args.len() == 3 => scene(&args[1], Path::new(&args[2])),
        _ => bail!("usage: generate_polyhedra_bed settle [SECONDS] [DAMPING] | scene a|b OUT.toml"),
    }
}
