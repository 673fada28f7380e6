//! A world split over 1, 2, 3 and 4 MPI ranks gives the bits of one process.
//!
//! Run by `cargo test`, this binary launches itself under `mpirun -n P` (MPICH's `mpirun.mpich`, or
//! `$POLYDEM_MPIRUN`; oversubscribed on a small machine) for each scene and P; each launched copy steps the
//! scene both with the engine's `step` on the whole world and with [`DistributedRun`], gathers the
//! distributed bodies in global order, and rank 0 compares FNV-1a hashes of the positions, velocities,
//! orientations and angular velocities of every body. A mismatch names the scene, P and the first body that
//! differs, and aborts every rank.

use std::path::PathBuf;
use std::time::Instant;

use polydem::dynamics::RigidBody;
use polydem::scene::load_scene;
use polydem::world::{step, StepScratch};
use polydem_mpi::launch::launch_each;
use polydem_mpi::mpi::traits::*;
use polydem_mpi::DistributedRun;

/// The scenes and the steps each runs: long enough for contacts between bodies and with walls, and for
/// several rebuilds (cuts).
const CASES: [(&str, u64); 2] = [("settling_box", 3000), ("sphere_bed_a_hertz_5ms", 600)];
const RANKS: [usize; 4] = [1, 2, 3, 4];

fn main() {
    match std::env::var("POLYDEM_MPI_CASE") {
        Ok(case) => child(&case),
        Err(_) => launch(),
    }
}

fn launch() {
    let exe = std::env::current_exe().expect("the test binary's path");
    let mut failures = Vec::new();
    for (case, _) in CASES {
        failures.extend(launch_each(case, &RANKS, &exe, |c| {
            c.env("POLYDEM_MPI_CASE", case);
        }));
    }
    assert!(
        failures.is_empty(),
        "distributed runs that failed: {failures:?}"
    );
}

fn child(case: &str) {
    let universe = polydem_mpi::mpi::initialize().expect("MPI initialised once");
    let comm = universe.world();
    let steps = CASES
        .iter()
        .find(|(c, _)| *c == case)
        .expect("a known case")
        .1;
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join(format!("../../scenes/{case}.toml"));
    let sim = load_scene(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));

    let mut whole = sim.world.clone();
    let mut scratch = StepScratch::default();
    for _ in 0..steps {
        step(&sim.params, &mut whole, &mut scratch).expect("one process steps the scene");
    }

    let policies = match case {
        // Twenty bodies on up to four ranks drift apart in count: this case bisects again at about
        // half its cuts under the default policy already.
        "settling_box" => &POLICIES[..1],
        _ => &POLICIES[..],
    };
    for &policy in policies {
        distributed(case, steps, &sim, policy, whole.bodies(), &comm);
    }
    if comm.rank() == 0 {
        let active = whole
            .contacts()
            .states()
            .iter()
            .filter(|s| s.is_active())
            .count();
        println!(
            "{case} on {} ranks after {steps} steps: the same bits as one process with every cut \
             policy ({} bodies, {active} contacts touching)",
            comm.size(),
            whole.body_count()
        );
    }
}

/// The cut policies run: migrating between neighbours (bisecting again only when the counts drift
/// apart), and bisecting the whole world at every cut.
const POLICIES: [CutPolicy; 2] = [CutPolicy::Migrate, CutPolicy::Bisect];

#[derive(Clone, Copy, Debug, PartialEq)]
enum CutPolicy {
    Migrate,
    Bisect,
}

fn distributed(
    case: &str,
    steps: u64,
    sim: &polydem::scene::Simulation,
    policy: CutPolicy,
    expected: &[RigidBody],
    comm: &polydem_mpi::mpi::topology::SimpleCommunicator,
) {
    let start = Instant::now();
    let mut run =
        DistributedRun::new(sim.world.clone(), sim.params).unwrap_or_else(|e| fail(comm, e));
    if policy == CutPolicy::Bisect {
        run.set_rebalance_above(0.0);
    }
    let (owned, ghosts) = run.part_size();
    for _ in 0..steps {
        run.step().unwrap_or_else(|e| fail(comm, e));
    }
    let elapsed = start.elapsed().as_secs_f64();
    let traffic = run.traffic();
    let per_step = |t: polydem_mpi::exchange::Traffic| {
        format!(
            "{:.0} B in {:.2} messages",
            t.bytes as f64 / steps as f64,
            t.messages as f64 / steps as f64
        )
    };
    let bodies = run.gather_bodies().unwrap_or_else(|e| fail(comm, e));
    println!(
        "{case} {policy:?} rank {}/{}: {owned} owned, {ghosts} ghosts at the first cut, {} cuts ({} \
         bisections, {} lists carried over), {elapsed:.2} s; sent per step: ghosts {}, agreements {}, cuts {}",
        run.rank(),
        comm.size(),
        run.cuts,
        run.bisections,
        run.lists_carried,
        per_step(traffic.ghosts),
        per_step(traffic.agreements),
        per_step(traffic.cuts),
    );
    // On one rank a cut keeps the part (the whole world); on more, a run of this length must migrate at
    // least once, or the migration is not tested.
    let migrated = run.cuts > run.bisections;
    let expect_migration = policy == CutPolicy::Migrate && run.cuts > 1;
    if run.rank() == 0 && comm.size() > 1 && expect_migration != migrated {
        eprintln!(
            "{case} {policy:?} on {} ranks: {} cuts of which {} bisections: migrations expected {}",
            comm.size(),
            run.cuts,
            run.bisections,
            expect_migration
        );
        comm.abort(1);
    }
    if run.rank() == 0 {
        compare(case, comm.size(), steps, expected, &bodies, comm);
    }
}

fn compare(
    case: &str,
    ranks: i32,
    steps: u64,
    expected: &[RigidBody],
    got: &[RigidBody],
    comm: &impl Communicator,
) {
    let quantities: [(&str, Quantity); 4] = [
        ("positions", |b| b.position.coords.iter().copied().collect()),
        ("velocities", |b| b.velocity.iter().copied().collect()),
        ("orientations", |b| {
            b.orientation.coords.iter().copied().collect()
        }),
        ("angular velocities", |b| {
            b.angular_velocity().iter().copied().collect()
        }),
    ];
    for (name, of) in quantities {
        let (h_expected, h_got) = (hash(expected, of), hash(got, of));
        if h_expected != h_got {
            let first = (0..expected.len()).find(|&i| of(&expected[i]) != of(&got[i]));
            let detail = first.map(|i| {
                format!(
                    "first at body {i}: {:?} against {:?}",
                    of(&got[i]),
                    of(&expected[i])
                )
            });
            eprintln!(
                "{case} on {ranks} ranks after {steps} steps: {name} hash {h_got:#018x}, one process \
                 {h_expected:#018x}; {}", detail.unwrap_or_default()
            );
            comm.abort(1);
        }
    }
}

/// One hashed quantity of a body, as its numbers.
type Quantity = fn(&RigidBody) -> Vec<f64>;

/// 64-bit FNV-1a over the little-endian bytes of `of` of every body, in body order.
fn hash(bodies: &[RigidBody], of: Quantity) -> u64 {
    let mut h: u64 = 0xcbf29ce484222325;
    for x in bodies.iter().flat_map(of) {
        for byte in x.to_le_bytes() {
            h = (h ^ byte as u64).wrapping_mul(0x100000001b3);
        }
    }
    h
}

fn fail(comm: &impl Communicator, error: impl std::fmt::Display) -> ! {
    eprintln!("rank {}: {error}", comm.rank());
    comm.abort(1)
}
