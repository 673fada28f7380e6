//! polydem's run of a variant: the scene through `Simulation::run_observed` on a pool of threads, the
//! projectile sampled every output interval, timed with the load of the machine beside it.

use std::time::Instant;

use polydem::host::{core_round_trip_text, load_average, thread_cpu_time, CpuTicks};
use polydem::math::Real;
use polydem::scene::{load_scene, RunObserver, Simulation, StepPath};

use super::{fail, Variant};
use crate::cases::projectile_history::History;
use crate::context::CaseContext;
use crate::error::SuiteError;
use crate::provenance::workspace_root;

pub(super) struct Run {
    pub(super) history: History,
    pub(super) z0: Real,
    pub(super) v0: Real,
    pub(super) steps: u64,
    pub(super) particles: usize,
    pub(super) wall_time_s: Real,
    pub(super) cpu_time_s: Option<Real>,
    /// The load average before the run and the share of the machine's CPU time the hypervisor stole
    /// during it, as the speed rows print them.
    pub(super) load: String,
    pub(super) max_overlap_ratio: Real,
}

/// Runs polydem on the variant's scene on a pool of `threads` threads, sampling the projectile every
/// output interval.
pub(super) fn run_polydem(
    variant: &Variant,
    ctx: &mut CaseContext,
    threads: usize,
) -> Result<Run, SuiteError> {
    let path = workspace_root().join(&variant.scene);
    let mut sim = load_scene(&path).map_err(|e| fail(e.to_string()))?;
    if let Some(steps) = variant.steps {
        sim.steps = sim.steps.min(steps);
    }
    // The case compares trajectories and speed; YADE and LIGGGHTS keep no energy ledger, so neither does
    // this run (bodies and forces are the same bits with it: `tests/world_sphere_fast_paths.rs`), which
    // lets the pipeline take the flat sphere layout, as `polydem run` of the scene with
    // `energy_ledger = false` does.
    sim.params.energy_ledger = false;
    let projectile = sim
        .world
        .names()
        .iter()
        .position(|n| n == "projectile")
        .ok_or_else(|| fail(format!("{}: no body named 'projectile'", path.display())))?;
    let z0 = sim.world.bodies()[projectile].position.z;
    let v0 = sim.world.bodies()[projectile].velocity.norm();
    let particles = sim.world.bodies().len();
    let mut history = History::default();
    let steps = sim.steps;
    let stage = if threads == 1 {
        variant.name.clone()
    } else {
        format!("{} ({threads} threads)", variant.name)
    };
    ctx.progress().stage(&stage, steps);
    let load = load_average();
    // The step's parallel stages run on rayon's current pool, here one of `threads` threads; the CPU time
    // is that of the thread that runs the loop, read inside the pool (all of it with one thread).
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .map_err(|e| fail(format!("pool of {threads} thread(s): {e}")))?;
    let progress = ctx.progress();
    let ticks = CpuTicks::now();
    let (max_overlap_ratio, wall_time_s, cpu_time_s, round_trips) = pool.install(|| {
        // On two threads: the state of the host's cores just before and after the run
        // (`host::core_round_trip_ns`), read outside the timed loop.
        let before = (threads > 1).then(core_round_trip_text);
        let cpu_start = thread_cpu_time();
        let start = Instant::now();
        let mut reported = 0;
        let max_overlap = run_steps(&mut sim, projectile, &mut history, &mut |n| {
            if n >= reported + 500 {
                progress.inc(n - reported);
                reported = n;
            }
        });
        let wall = start.elapsed().as_secs_f64();
        let cpu = match (cpu_start, thread_cpu_time()) {
            (Some(a), Some(b)) if b > a => Some(b - a),
            _ => None,
        };
        let after = before.is_some().then(core_round_trip_text);
        (max_overlap, wall, cpu, before.zip(after))
    });
    // A busy host slows a run on two threads more than one on one: each step waits for both.
    let load = match CpuTicks::now()
        .zip(ticks)
        .and_then(|(now, then)| now.steal_since(&then))
    {
        Some(steal) => format!("{load}; host steal {:.1} %", 100.0 * steal),
        None => load,
    };
    let load = match round_trips {
        Some((before, after)) => format!("{load}; core round trip {before} / {after}"),
        None => load,
    };
    let max_overlap_ratio =
        max_overlap_ratio.map_err(|e| fail(format!("{}: {e}", variant.scene)))?;
    Ok(Run {
        history,
        z0,
        v0,
        steps,
        particles,
        wall_time_s,
        cpu_time_s,
        load,
        max_overlap_ratio,
    })
}

/// The steps of `sim` from its world's step to its end, sampling the projectile at the start and every
/// output interval (and after the last step), through the run `polydem run` uses
/// ([`Simulation::run_observed`]): the pipeline takes the flat sphere layout for a world of free spheres
/// with the ledger off (the same bits as the general step, `tests/pinned_bits.rs`). `on_step` gets the
/// number of steps done. Returns the largest overlap ratio of any step.
fn run_steps(
    sim: &mut Simulation,
    projectile: usize,
    history: &mut History,
    on_step: &mut (dyn FnMut(u64) + Send),
) -> Result<Real, String> {
    let mut samples = ProjectileSamples {
        projectile,
        output_every: sim.output_every,
        last: sim.steps,
        history,
        on_step,
    };
    let summary = sim.run_observed(&mut samples).map_err(|e| e.to_string())?;
    if summary.path != StepPath::FlatSpheres {
        eprintln!("sphere_bed: the general step");
    }
    Ok(summary.max_overlap_ratio)
}

/// The projectile's height, vertical velocity and vertical force at every output step of a run.
struct ProjectileSamples<'a> {
    projectile: usize,
    output_every: u64,
    last: u64,
    history: &'a mut History,
    on_step: &'a mut (dyn FnMut(u64) + Send),
}

impl RunObserver for ProjectileSamples<'_> {
    fn wants_state(&self, n: u64) -> bool {
        n.is_multiple_of(self.output_every) || n == self.last
    }

    fn observe(&mut self, s: &Simulation, _: u64) -> std::io::Result<()> {
        let b = &s.world.bodies()[self.projectile];
        // No loads before the first step: the projectile starts out of contact.
        let fz = s
            .world
            .loads()
            .forces()
            .get(self.projectile)
            .map_or(0.0, |f| f.z);
        let h = &mut *self.history;
        h.t.push(s.world.time());
        h.z.push(b.position.z);
        h.vz.push(b.velocity.z);
        h.fz.push(fz);
        Ok(())
    }

    fn progress(&mut self, n: u64) {
        (self.on_step)(n);
    }

    fn reads_contacts(&self, _: u64) -> bool {
        false
    }
}
