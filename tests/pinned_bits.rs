//! The absolute bits of the final state of seven runs, pinned against hashes recorded at a known-good tree.
//!
//! The bitwise tests elsewhere (`world_parallel.rs`, `sphere_flat_paths.rs`, …) compare two code paths or
//! thread counts with each other: once a refactor has merged the paths they compare nothing. This test
//! compares each run with recorded constants, so a change of the step pipeline that claims to leave every
//! trajectory unchanged can prove it.
//!
//! # The runs
//! Each goes through the library's public entry points: scenes through [`load_scene`] and
//! [`Simulation::run`], the rockfill impact through [`run_experiment_with`].
//! - `settling_box`: `scenes/settling_box.toml`, 20 polyhedra falling into a box of five walls, until both
//!   layers have landed (polyhedron–polyhedron and polyhedron–wall contacts at the end).
//! - `mixed_spheres_polyhedra`: `scenes/mixed_spheres_polyhedra.toml`, spheres and polyhedra of two
//!   materials (linear and Hertz–Mindlin laws) settling into a pile: every contact kind at the end.
//! - `sphere_bed_a` / `_b` / `_c`: `scenes/sphere_bed_*.toml`, 3000 spheres and the projectile, until the
//!   projectile is in contact with the bed.
//! - `rockfill_quick`: a fixed number of impact steps from the saved bed `reference/rockfill/quick_bed/`
//!   with `scenes/rockfill/quick.toml` ([`PenetrationOptions::max_steps`]), the projectile in the bed.
//!
//! The sphere beds take the general step's sphere stages, and the flat sphere layout (ledger off, through
//! `run_observed`) must end on the same bits. Bed c runs a second time, 5000 steps on the flat layout alone
//! (`sphere_bed_c_long`).
//!
//! Each runs on a rayon pool of one thread and of two; the scenes also on two threads with every stage on
//! its parallel path (all [`Parallelism`] thresholds at zero). At the default thresholds only the sphere
//! beds' narrow phase runs in parallel; the other scenes and the rockfill impact (whose step parameters
//! `penetrate_with` builds) run serially whatever the pool. The engine gives the same bits for any thread
//! count, so every variant must give the one pinned value.
//!
//! # What is hashed
//! 64-bit FNV-1a over little-endian bytes, one hash per quantity so that a failure names what moved:
//! - `positions`, `velocities`, `orientations` (w, i, j, k), `angular_velocities` (ω, world frame) and
//!   `angular_momenta` (L, the integrated state ω is derived from): every body, in body order;
//! - `contacts`: every contact-store entry that holds physics (found touching or overlapping at the last
//!   evaluation, or carrying a tangential spring or a force), in store order: its key, the geometry of the
//!   last evaluation, the tangential history (spring, normal, stiffness), the force on B and its damping
//!   part. Left out: the GJK/EPA warm start and the separation proof of the skips (solver caches), and the
//!   geometry of a separated pair (the motion-bound skip keeps it from an earlier step);
//! - `candidates`: every store entry's key and the step it entered the candidate list (the broad phase's
//!   bookkeeping: a change of the skin or of the rebuild rule moves this one alone);
//! - `loads`: the last evaluation's force and torque on every body and force on every wall;
//! - `state`: the whole, body by body (position, velocity, orientation, angular velocity), then every store
//!   entry as in `contacts`;
//! - and, exactly, `world.time` (its bits) and `world.step_index`, the body count and the number of
//!   overlapping contacts.
//!
//! # Regenerating
//! `POLYDEM_PIN_PRINT=1 cargo test --release --test pinned_bits -- --nocapture --test-threads 1` prints the
//! current values as Rust constants, ready to paste over the `const` items below, instead of asserting (and
//! says whether the other thread variants gave the same bits). A change that must move these bits (a new
//! law, a fix of the integrator) re-pins in its own commit, whose message says why the trajectories
//! changed; a refactor never re-pins.

use std::path::{Path, PathBuf};
use std::time::Instant;

use polydem::math::{Point, Rotation, Vector};
use polydem::scene::{load_scene, RunObserver, Simulation, StepPath};
use polydem::shape::Shape;
use polydem::world::{ContactKey, ContactState, Parallelism, World};
use polydem_rockfill::config::ExperimentConfig;
use polydem_rockfill::experiment::{run_experiment_with, BedSource};
use polydem_rockfill::penetration::{Outcome, PenetrationOptions};

// ---------------------------------------------------------------------------------------------------------
// The recorded values (see the module docs to regenerate).

const SETTLING_BOX_STEPS: u64 = 6000;
const MIXED_STEPS: u64 = 8000;
const SPHERE_BED_A_STEPS: u64 = 600;
const SPHERE_BED_B_STEPS: u64 = 300;
const SPHERE_BED_C_STEPS: u64 = 600;
const ROCKFILL_STEPS: u64 = 300;
/// Bed c on the flat sphere layout alone, past step 4494, where its trajectory depends on the width of the
/// sphere pairs' touching band; the short pins above end before it.
const SPHERE_BED_C_LONG_STEPS: u64 = 5000;

const SETTLING_BOX: Pin = Pin {
    time_bits: 0x3fcebf650d7c2730,
    step_index: 6000,
    bodies: 20,
    active_contacts: 14,
    positions: 0xc3ce46ae8dddeb7e,
    velocities: 0x74ecaf1812d3d5ed,
    orientations: 0xc39498df53bdc98b,
    angular_velocities: 0x9d3b3da347fea8bb,
    angular_momenta: 0xa6180ffcd7955621,
    contacts: 0x6a08bb35142fc47d,
    candidates: 0xfa29cd92970a03e8,
    loads: 0xe944e921321b76c5,
    state: 0xa47210b32cecee42,
};

const MIXED_SPHERES_POLYHEDRA: Pin = Pin {
    time_bits: 0x3fc86131a2faa3df,
    step_index: 8000,
    bodies: 8,
    active_contacts: 11,
    positions: 0xf7cb7b37b7b67913,
    velocities: 0x945b6128e138b012,
    orientations: 0x3ce0021d0d4c35a9,
    angular_velocities: 0xb746b868cb4c4e10,
    angular_momenta: 0x8b94895e974967a2,
    contacts: 0xeb28ebacb6e4de92,
    candidates: 0x8372159c00b4bed4,
    loads: 0x2fa581e65f517405,
    state: 0x2964b3a7019d52dc,
};

const SPHERE_BED_A_HERTZ_5MS: Pin = Pin {
    time_bits: 0x3f53a92a305532ac,
    step_index: 600,
    bodies: 3001,
    active_contacts: 6955,
    positions: 0x62c86bd5404cf21a,
    velocities: 0x008fdc075db6f556,
    orientations: 0x87b2bff9c6f89dbe,
    angular_velocities: 0x251661759596b4ee,
    angular_momenta: 0x57d7a9c727dd8f30,
    contacts: 0x754c2c256151f88f,
    candidates: 0xfd248c328a7f048f,
    loads: 0x37fbf4712cd12dbc,
    state: 0xecb8b7585e0103e3,
};

const SPHERE_BED_B_HERTZ_200MS: Pin = Pin {
    time_bits: 0x3f0f75104d551d4e,
    step_index: 300,
    bodies: 3001,
    active_contacts: 7325,
    positions: 0xbfb18c84bd9bd971,
    velocities: 0xab37b9d23cbb342f,
    orientations: 0x02ee1bc8179cbb9a,
    angular_velocities: 0xd1346ce5db1d03bf,
    angular_momenta: 0xc61b8f4cf8d7a89d,
    contacts: 0xe93acdf26e56cf14,
    candidates: 0x1969912539c8b60e,
    loads: 0x6b8316cefb160a57,
    state: 0x8a0918455606224c,
};

const SPHERE_BED_C_LINEAR_5MS: Pin = Pin {
    time_bits: 0x3f53a92a305532ac,
    step_index: 600,
    bodies: 3001,
    active_contacts: 4721,
    positions: 0x6f2aa0ca63f984fe,
    velocities: 0x0c858252fcfaae3f,
    orientations: 0x36ef7ec28bab02b5,
    angular_velocities: 0x93eed73bd9dd63e9,
    angular_momenta: 0xc44cbc5986b00770,
    contacts: 0xda7613b1df3e4cc6,
    candidates: 0x941e2eabbf26c695,
    loads: 0x09f989bd4923da0b,
    state: 0x62f5220c73452c34,
};

/// Flat layout only: `candidates` and `state` are not compared there (see [`run_scene_flat`]).
const SPHERE_BED_C_LINEAR_5MS_LONG: Pin = Pin {
    time_bits: 0x3f847ae147ae1602,
    step_index: 5000,
    bodies: 3001,
    active_contacts: 1453,
    positions: 0xe24468dd613998d4,
    velocities: 0xe29c2d17fa79735e,
    orientations: 0xa5f8849378ec8c27,
    angular_velocities: 0x899ba4fd409b0869,
    angular_momenta: 0x3c05d401aa890062,
    contacts: 0xff56c9f8bf4678e5,
    candidates: 0x0000000000000000,
    loads: 0x31dc5e61c5ae7d53,
    state: 0x0000000000000000,
};

const ROCKFILL_QUICK: Pin = Pin {
    time_bits: 0x4005a42385093fe8,
    step_index: 22216,
    bodies: 352,
    active_contacts: 1017,
    positions: 0xbbe80fad738618d6,
    velocities: 0x9fc3f4bacfbac515,
    orientations: 0x660599c469afa18d,
    angular_velocities: 0xc363843058044f63,
    angular_momenta: 0x68b80fbcd5685854,
    contacts: 0x8e72c8f80e83efc0,
    candidates: 0x93c94685651fb1d3,
    loads: 0xde7279ebe48e3ce2,
    state: 0x9584e5080046ded0,
};

// ---------------------------------------------------------------------------------------------------------
// The runs.

#[test]
fn settling_box_bits_are_pinned() {
    let pinned = run_scene("settling_box", SETTLING_BOX_STEPS, &SETTLING_BOX);
    let kinds = ContactKinds::of(&pinned);
    assert!(
        kinds.polyhedron_polyhedron > 0 && kinds.wall_polyhedron > 0,
        "settling_box after {SETTLING_BOX_STEPS} steps: the pin must end with polyhedra touching each other and \
         the walls; overlapping contacts {kinds:?}"
    );
}

#[test]
fn mixed_spheres_polyhedra_bits_are_pinned() {
    let pinned = run_scene(
        "mixed_spheres_polyhedra",
        MIXED_STEPS,
        &MIXED_SPHERES_POLYHEDRA,
    );
    let kinds = ContactKinds::of(&pinned);
    assert!(
        kinds.all_present(),
        "mixed_spheres_polyhedra after {MIXED_STEPS} steps: the pin must end with every contact kind \
         (sphere–sphere, sphere–polyhedron, polyhedron–polyhedron, wall–sphere, wall–polyhedron); \
         overlapping contacts {kinds:?}"
    );
}

#[test]
fn sphere_bed_a_bits_are_pinned() {
    sphere_bed(
        "sphere_bed_a_hertz_5ms",
        SPHERE_BED_A_STEPS,
        &SPHERE_BED_A_HERTZ_5MS,
    );
}

#[test]
fn sphere_bed_b_bits_are_pinned() {
    sphere_bed(
        "sphere_bed_b_hertz_200ms",
        SPHERE_BED_B_STEPS,
        &SPHERE_BED_B_HERTZ_200MS,
    );
}

#[test]
fn sphere_bed_c_bits_are_pinned() {
    sphere_bed(
        "sphere_bed_c_linear_5ms",
        SPHERE_BED_C_STEPS,
        &SPHERE_BED_C_LINEAR_5MS,
    );
}

#[test]
fn sphere_bed_c_long_flat_bits_are_pinned() {
    run_scene_flat(
        "sphere_bed_c_linear_5ms",
        SPHERE_BED_C_LONG_STEPS,
        &SPHERE_BED_C_LINEAR_5MS_LONG,
    );
}

#[test]
fn rockfill_quick_penetration_bits_are_pinned() {
    let root = root();
    let config = ExperimentConfig::load(&root.join("scenes/rockfill/quick.toml"))
        .expect("scenes/rockfill/quick.toml loads");
    let dir = root.join("reference/rockfill/quick_bed");
    let options = PenetrationOptions {
        max_steps: Some(ROCKFILL_STEPS),
        ..Default::default()
    };
    let run = Run {
        name: "rockfill_quick",
        steps: ROCKFILL_STEPS,
    };
    let mut first = None;
    for threads in [Threads::One, Threads::Two] {
        let start = Instant::now();
        let result = threads.install(|| {
            run_experiment_with(&config, BedSource::Load(&dir), &options, &mut |_, _| {})
                .expect("the quick penetration runs from the saved bed")
        });
        let elapsed = start.elapsed();
        assert!(
            result.bed_from_checkpoint,
            "rockfill_quick: the bed must come from {}/bed.pdck bit for bit (it was read from its CSV files: the \
             checkpoint format changed; save the bed again with this build and re-pin)",
            dir.display()
        );
        let report = &result.penetration;
        assert_eq!(
            (report.outcome, report.steps),
            (Outcome::StepLimit, ROCKFILL_STEPS),
            "rockfill_quick, {}: the run must stop at the step limit",
            threads.label()
        );
        let projectile_contacts = report.rows.last().map_or(0, |row| row.contacts);
        assert!(
            projectile_contacts > 0,
            "rockfill_quick after {ROCKFILL_STEPS} steps, {}: the projectile must be in the bed (contacts with a \
             force on it: {projectile_contacts})",
            threads.label()
        );
        let measured = Pin::of(&result.world);
        println!(
            "// {} after {} steps, {}: {} bodies, {} overlapping contacts, projectile contacts {projectile_contacts}, {:.2} s",
            run.name,
            run.steps,
            threads.label(),
            measured.bodies,
            measured.active_contacts,
            elapsed.as_secs_f64()
        );
        check(
            &run,
            threads,
            &measured,
            &result.world,
            &ROCKFILL_QUICK,
            &mut first,
        );
    }
}

/// A sphere-bed scene, with the projectile in contact with the bed at the end; run again with the energy
/// ledger off through [`Simulation::run_observed`], where the pipeline takes the flat sphere layout.
fn sphere_bed(scene: &'static str, steps: u64, expected: &Pin) {
    let world = run_scene(scene, steps, expected);
    run_scene_flat(scene, steps, expected);
    let projectile = world
        .names()
        .iter()
        .position(|name| name == "projectile")
        .expect("the sphere bed has a body named 'projectile'") as u32;
    let touching = world
        .contacts()
        .keys()
        .iter()
        .zip(world.contacts().states())
        .filter(|(key, state)| {
            state.is_active()
                && match **key {
                    ContactKey::Body { a, b } => a == projectile || b == projectile,
                    ContactKey::Wall { body, .. } => body == projectile,
                }
        })
        .count();
    assert!(
        touching > 0,
        "{scene} after {steps} steps: the pin must end with the projectile in contact with the bed (overlapping \
         contacts of the projectile: {touching})"
    );
}

/// Runs scene `name` (`scenes/NAME.toml`) for `steps` steps in every thread variant, checks each against
/// `expected` and returns the world of the first.
fn run_scene(name: &'static str, steps: u64, expected: &Pin) -> World {
    let path = root().join("scenes").join(format!("{name}.toml"));
    let run = Run { name, steps };
    let mut first = None;
    let mut kept = None;
    for threads in [Threads::One, Threads::Two, Threads::TwoEveryStageParallel] {
        let mut sim = load_scene(&path)
            .unwrap_or_else(|e| panic!("{}: the scene does not load: {e}", path.display()));
        sim.steps = steps;
        if threads == Threads::TwoEveryStageParallel {
            sim.params.parallel = Parallelism {
                min_candidates: 0,
                min_bodies: 0,
            };
        }
        let start = Instant::now();
        let sim = threads.install(move || {
            let summary = sim
                .run(|_: &Simulation| Ok(()), |_: &Simulation, _| Ok(()))
                .unwrap_or_else(|e| panic!("{name}: the run failed: {e}"));
            assert_eq!(summary.steps, steps, "{name}: steps run");
            sim
        });
        let elapsed = start.elapsed();
        let measured = Pin::of(&sim.world);
        println!(
            "// {name} after {steps} steps, {}: {} bodies, {} overlapping contacts, {:.2} s",
            threads.label(),
            measured.bodies,
            measured.active_contacts,
            elapsed.as_secs_f64()
        );
        check(&run, threads, &measured, &sim.world, expected, &mut first);
        kept.get_or_insert(sim.world);
    }
    kept.expect("at least one variant ran")
}

/// An observer that reads the state every `every` steps (and at the last), as `polydem run`'s outputs do.
struct Every {
    every: u64,
    observed: u64,
}

impl RunObserver for Every {
    fn wants_state(&self, step: u64) -> bool {
        step.is_multiple_of(self.every)
    }
    fn observe(&mut self, _: &Simulation, _: u64) -> std::io::Result<()> {
        self.observed += 1;
        Ok(())
    }
}

/// Runs scene `name` with `energy_ledger = false` through [`Simulation::run_observed`] (state read every
/// 100 steps), on one thread and on two: the pipeline must take the flat sphere layout and end on the
/// pinned bits. The ledger books energy only (bodies, forces and contact state are the same bits without
/// it). Not compared: `candidates` and `state`, which hash every store entry, the separated candidate pairs
/// too: which separated pairs are listed is the broad phase's bookkeeping, and the flat layout keeps lists
/// of its own (the store it writes back lists its pairs). Every physical group is compared.
fn run_scene_flat(name: &'static str, steps: u64, expected: &Pin) {
    let path = root().join("scenes").join(format!("{name}.toml"));
    let run = Run { name, steps };
    let mut first = None;
    for threads in [Threads::One, Threads::Two] {
        let mut sim = load_scene(&path)
            .unwrap_or_else(|e| panic!("{}: the scene does not load: {e}", path.display()));
        sim.steps = steps;
        sim.params.energy_ledger = false;
        let start = Instant::now();
        let (sim, observed) = threads.install(move || {
            let mut observer = Every {
                every: 100,
                observed: 0,
            };
            let summary = sim
                .run_observed(&mut observer)
                .unwrap_or_else(|e| panic!("{name}: the run failed: {e}"));
            assert_eq!(summary.steps, steps, "{name}: steps run");
            assert_eq!(
                summary.path,
                StepPath::FlatSpheres,
                "{name}, ledger off, run_observed: the pipeline must take the flat sphere layout"
            );
            (sim, observer.observed)
        });
        assert_eq!(
            observed,
            1 + steps / 100 + u64::from(!steps.is_multiple_of(100)),
            "{name}: observed at the start, every 100 steps and at the last"
        );
        let mut measured = Pin::of(&sim.world);
        println!(
            "// {name} after {steps} steps, {}, ledger off, flat sphere layout: {:.2} s",
            threads.label(),
            start.elapsed().as_secs_f64()
        );
        measured.candidates = expected.candidates;
        measured.state = expected.state;
        check(&run, threads, &measured, &sim.world, expected, &mut first);
    }
}

// ---------------------------------------------------------------------------------------------------------
// Thread variants.

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Threads {
    One,
    Two,
    /// Two threads with every [`Parallelism`] threshold at zero.
    TwoEveryStageParallel,
}

impl Threads {
    fn label(self) -> &'static str {
        match self {
            Threads::One => "1 thread",
            Threads::Two => "2 threads",
            Threads::TwoEveryStageParallel => "2 threads, every stage parallel",
        }
    }

    fn install<T: Send>(self, go: impl FnOnce() -> T + Send) -> T {
        let n = match self {
            Threads::One => 1,
            Threads::Two | Threads::TwoEveryStageParallel => 2,
        };
        rayon::ThreadPoolBuilder::new()
            .num_threads(n)
            .build()
            .expect("rayon thread pool")
            .install(go)
    }
}

// ---------------------------------------------------------------------------------------------------------
// Pins: measuring, printing, checking.

/// A run: its name and step count, for the messages.
struct Run {
    name: &'static str,
    steps: u64,
}

/// The pinned quantities of a world (see the module docs).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct Pin {
    time_bits: u64,
    step_index: u64,
    bodies: usize,
    active_contacts: usize,
    positions: u64,
    velocities: u64,
    orientations: u64,
    angular_velocities: u64,
    angular_momenta: u64,
    contacts: u64,
    candidates: u64,
    loads: u64,
    state: u64,
}

impl Pin {
    fn of(world: &World) -> Self {
        let bodies = &world.bodies();
        let per_body = |f: &dyn Fn(&mut Fnv1a, &polydem::dynamics::RigidBody)| {
            let mut h = Fnv1a::new();
            bodies.iter().for_each(|b| f(&mut h, b));
            h.finish()
        };
        let store = || {
            world
                .contacts()
                .keys()
                .iter()
                .zip(world.contacts().states())
        };

        let mut state = Fnv1a::new();
        for b in bodies.iter() {
            state.point(&b.position);
            state.vector(&b.velocity);
            state.rotation(&b.orientation);
            state.vector(&b.angular_velocity());
        }
        let mut contacts = Fnv1a::new();
        let mut candidates = Fnv1a::new();
        for (key, entry) in store() {
            state.contact(key, entry);
            if holds_physics(entry) {
                contacts.contact(key, entry);
            }
            candidates.key(key);
            candidates.u64(entry.since_step);
        }
        let mut loads = Fnv1a::new();
        let l = &world.loads();
        for v in l.forces().iter().chain(l.torques()).chain(l.wall_forces()) {
            loads.vector(v);
        }

        Self {
            time_bits: world.time().to_bits(),
            step_index: world.step_index(),
            bodies: bodies.len(),
            active_contacts: store().filter(|(_, s)| s.is_active()).count(),
            positions: per_body(&|h, b| h.point(&b.position)),
            velocities: per_body(&|h, b| h.vector(&b.velocity)),
            orientations: per_body(&|h, b| h.rotation(&b.orientation)),
            angular_velocities: per_body(&|h, b| h.vector(&b.angular_velocity())),
            angular_momenta: per_body(&|h, b| h.vector(&b.angular_momentum)),
            contacts: contacts.finish(),
            candidates: candidates.finish(),
            loads: loads.finish(),
            state: state.finish(),
        }
    }

    /// (quantity, value) in the order of the messages; hashes as `hash`, the rest as `value`.
    fn fields(&self) -> [(&'static str, bool, u64); 13] {
        [
            ("time_bits", false, self.time_bits),
            ("step_index", false, self.step_index),
            ("bodies", false, self.bodies as u64),
            ("active_contacts", false, self.active_contacts as u64),
            ("positions", true, self.positions),
            ("velocities", true, self.velocities),
            ("orientations", true, self.orientations),
            ("angular_velocities", true, self.angular_velocities),
            ("angular_momenta", true, self.angular_momenta),
            ("contacts", true, self.contacts),
            ("candidates", true, self.candidates),
            ("loads", true, self.loads),
            ("state", true, self.state),
        ]
    }

    /// The pin as a Rust constant named `name`.
    fn rust_const(&self, name: &str) -> String {
        let mut out = format!("const {name}: Pin = Pin {{\n");
        for (field, _, value) in self.fields() {
            let value = match field {
                "step_index" | "bodies" | "active_contacts" => value.to_string(),
                _ => format!("{value:#018x}"),
            };
            out += &format!("    {field}: {value},\n");
        }
        out + "};"
    }
}

/// Whether a store entry holds physics: found touching or overlapping, or carrying a spring or a force.
fn holds_physics(entry: &ContactState) -> bool {
    use polydem::contact::ContactKind;
    entry.geometry.kind != ContactKind::Separated
        || !entry.history.is_cleared()
        || entry.force_on_b != Vector::zeros()
        || entry.damping_force != Vector::zeros()
}

/// Checks `measured` against `expected` (or, with `POLYDEM_PIN_PRINT=1`, prints it as a constant for the
/// first variant and compares later ones with the first). `first` holds the first variant's pin.
fn check(
    run: &Run,
    threads: Threads,
    measured: &Pin,
    world: &World,
    expected: &Pin,
    first: &mut Option<Pin>,
) {
    let context = format!(
        "{} after {} steps, {}",
        run.name,
        run.steps,
        threads.label()
    );
    if std::env::var("POLYDEM_PIN_PRINT").is_ok_and(|v| v == "1") {
        match first {
            None => {
                let name = run.name.to_uppercase();
                println!("{}", measured.rust_const(&name));
                *first = Some(*measured);
            }
            Some(reference) => match differences(&context, measured, reference) {
                None => println!("// {context}: the same bits"),
                Some(lines) => {
                    println!("// {context}: OTHER BITS than the first variant:\n// {lines}")
                }
            },
        }
        return;
    }
    if let Some(lines) = differences(&context, measured, expected) {
        let body0 = world.bodies().first().map_or("none".to_owned(), |b| {
            format!("{:?}", b.position.coords.as_slice())
        });
        panic!(
            "{lines}\n({context}: {} bodies, {} overlapping contacts, time {} s, first body at {body0}; if the \
             change must move these bits, re-pin with POLYDEM_PIN_PRINT=1 in a commit of its own that says why)",
            measured.bodies, measured.active_contacts, world.time()
        );
    }
}

/// One line per quantity that differs, or `None`.
fn differences(context: &str, measured: &Pin, expected: &Pin) -> Option<String> {
    let lines: Vec<String> = measured
        .fields()
        .iter()
        .zip(expected.fields())
        .filter(|((_, _, m), (_, _, e))| m != e)
        .map(|((field, is_hash, m), (_, _, e))| {
            if *is_hash {
                format!("{context}: {field} hash {m:#018x} expected {e:#018x}")
            } else if *field == "time_bits" {
                format!(
                    "{context}: time {} s ({m:#018x}) expected {} s ({e:#018x})",
                    f64::from_bits(*m),
                    f64::from_bits(e)
                )
            } else {
                format!("{context}: {field} {m} expected {e}")
            }
        })
        .collect();
    (!lines.is_empty()).then(|| lines.join("\n"))
}

// ---------------------------------------------------------------------------------------------------------
// Contact kinds at the end of a run.

/// Overlapping contacts by the kinds of shapes they join.
#[derive(Debug, Default)]
struct ContactKinds {
    sphere_sphere: usize,
    sphere_polyhedron: usize,
    polyhedron_polyhedron: usize,
    wall_sphere: usize,
    wall_polyhedron: usize,
}

impl ContactKinds {
    fn of(world: &World) -> Self {
        let is_sphere = |i: u32| matches!(world.shape(i as usize), Shape::Sphere(_));
        let mut kinds = Self::default();
        for (key, state) in world
            .contacts()
            .keys()
            .iter()
            .zip(world.contacts().states())
        {
            if !state.is_active() {
                continue;
            }
            let count = match *key {
                ContactKey::Body { a, b } => match (is_sphere(a), is_sphere(b)) {
                    (true, true) => &mut kinds.sphere_sphere,
                    (false, false) => &mut kinds.polyhedron_polyhedron,
                    _ => &mut kinds.sphere_polyhedron,
                },
                ContactKey::Wall { body, .. } if is_sphere(body) => &mut kinds.wall_sphere,
                ContactKey::Wall { .. } => &mut kinds.wall_polyhedron,
            };
            *count += 1;
        }
        kinds
    }

    fn all_present(&self) -> bool {
        [
            self.sphere_sphere,
            self.sphere_polyhedron,
            self.polyhedron_polyhedron,
            self.wall_sphere,
            self.wall_polyhedron,
        ]
        .iter()
        .all(|&n| n > 0)
    }
}

// ---------------------------------------------------------------------------------------------------------
// The hash.

/// 64-bit FNV-1a (Fowler–Noll–Vo) over bytes: fixed constants, no seed, the same on every platform.
struct Fnv1a(u64);

impl Fnv1a {
    const OFFSET_BASIS: u64 = 0xcbf2_9ce4_8422_2325;
    const PRIME: u64 = 0x0000_0100_0000_01b3;

    fn new() -> Self {
        Self(Self::OFFSET_BASIS)
    }

    fn finish(&self) -> u64 {
        self.0
    }

    fn bytes(&mut self, bytes: &[u8]) {
        for &byte in bytes {
            self.0 ^= u64::from(byte);
            self.0 = self.0.wrapping_mul(Self::PRIME);
        }
    }

    fn u8(&mut self, x: u8) {
        self.bytes(&[x]);
    }

    fn u32(&mut self, x: u32) {
        self.bytes(&x.to_le_bytes());
    }

    fn u64(&mut self, x: u64) {
        self.bytes(&x.to_le_bytes());
    }

    fn f64(&mut self, x: f64) {
        self.bytes(&x.to_le_bytes());
    }

    fn vector(&mut self, v: &Vector) {
        for &x in v.iter() {
            self.f64(x);
        }
    }

    fn point(&mut self, p: &Point) {
        self.vector(&p.coords);
    }

    /// The unit quaternion as w, i, j, k.
    fn rotation(&mut self, q: &Rotation) {
        for x in [q.w, q.i, q.j, q.k] {
            self.f64(x);
        }
    }

    fn key(&mut self, key: &ContactKey) {
        match *key {
            ContactKey::Body { a, b } => {
                self.u8(0);
                self.u32(a);
                self.u32(b);
            }
            ContactKey::Wall { body, wall } => {
                self.u8(1);
                self.u32(body);
                self.u32(wall);
            }
        }
    }

    /// An entry's key and physics (see the module docs); the geometry only when not separated.
    fn contact(&mut self, key: &ContactKey, entry: &ContactState) {
        use polydem::contact::{ContactKind, SolverStatus};
        self.key(key);
        let g = &entry.geometry;
        self.u8(match g.kind {
            ContactKind::Overlap => 0,
            ContactKind::Touching => 1,
            ContactKind::Separated => 2,
        });
        if g.kind != ContactKind::Separated {
            self.f64(g.depth);
            self.f64(g.distance);
            self.vector(&g.normal);
            self.point(&g.point_a);
            self.point(&g.point_b);
            self.point(&g.point);
            self.u8(match g.status {
                SolverStatus::Exact => 0,
                SolverStatus::Converged => 1,
                SolverStatus::FallbackAfterMaxIterations => 2,
                SolverStatus::FallbackAfterDegenerate => 3,
            });
        }
        let h = &entry.history;
        self.vector(&h.displacement);
        self.vector(&h.normal);
        self.f64(h.stiffness);
        self.vector(&entry.force_on_b);
        self.vector(&entry.damping_force);
    }
}

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).to_path_buf()
}

#[test]
fn fnv1a_matches_its_published_test_vectors() {
    // From the FNV reference test suite (Fowler, Noll, Vo; draft-eastlake-fnv): "" and "a" and "foobar".
    for (input, hash) in [
        ("", 0xcbf2_9ce4_8422_2325_u64),
        ("a", 0xaf63_dc4c_8601_ec8c),
        ("foobar", 0x8594_4171_f739_67e8),
    ] {
        let mut h = Fnv1a::new();
        h.bytes(input.as_bytes());
        assert_eq!(
            h.finish(),
            hash,
            "FNV-1a 64 of {input:?}: got {:#018x}, expected {hash:#018x}",
            h.finish()
        );
    }
}
