//! The flat sphere path (`src/world/sphere_flat/`) steps a world of free spheres to the same bits as the
//! general step, on one and two threads.
//!
//! The scenes are the sphere-bed penetrations (`scenes/sphere_bed_a_hertz_5ms.toml`:
//! Hertz–Mindlin with the tangential dashpot, friction and the force limit; `scenes/sphere_bed_c_linear_5ms.toml`:
//! the linear spring–dashpot; 3000 settled spheres in an open box of five walls, a steel ball striking at
//! 5 m/s), run for their first 300 steps: the ball lands at step ~50, so the runs have new, persistent and
//! opening contacts between spheres and against the walls, and the flat path's lists are rebuilt. The
//! flat path keeps the operations and their order (see the module docs of `sphere_flat`), so the
//! comparison is exact: bodies, loads, walls and the springs of every overlapping pair.

#[path = "support/world_bits.rs"]
mod world_bits;

use std::ops::ControlFlow;
use std::path::Path;

use polydem::law::SpringRotation;
use polydem::scene::{load_scene, Simulation};
use polydem::world::sphere_flat::TeamSplit;
use polydem::world::{step, ContactKey, SphereSim, StepScratch, World};

const STEPS: u64 = 300;

fn scene(file: &str) -> Simulation {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join(file);
    let mut sim = load_scene(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    // The flat path books no per-contact ledger terms; neither does the general step with this switch.
    sim.params.energy_ledger = false;
    sim
}

fn general(sim: &Simulation, steps: u64) -> World {
    let mut world = sim.world.clone();
    let mut scratch = StepScratch::default();
    for _ in 0..steps {
        step(&sim.params, &mut world, &mut scratch).unwrap_or_else(|e| panic!("general step: {e}"));
    }
    world
}

fn flat(sim: &Simulation, steps: u64) -> (SphereSim, World) {
    let mut flat = SphereSim::from_world(&sim.world, &sim.params)
        .unwrap_or_else(|e| panic!("the sphere bed must take the flat path: {e}"));
    for _ in 0..steps {
        flat.step().unwrap_or_else(|e| panic!("flat step: {e}"));
    }
    let mut world = sim.world.clone();
    flat.write_back(&mut world);
    (flat, world)
}

/// The first difference in bits between the bodies, walls, loads and time of two worlds, if any.
fn first_difference(a: &World, b: &World) -> Option<String> {
    if let Some(d) = world_bits::body_difference(a, b) {
        return Some(d);
    }
    let extra = |w: &World| {
        [
            w.time(),
            w.ledger().external_work(),
            w.ledger().initial_total().unwrap_or(f64::NAN),
        ]
    };
    let (la, lb) = (
        world_bits::load_values(a, &extra(a)),
        world_bits::load_values(b, &extra(b)),
    );
    if let Some((k, x, y)) = world_bits::first_value_difference(&la, &lb) {
        return Some(format!(
            "loads differ at value {k} of {}: {x} against {y}",
            la.len()
        ));
    }
    if a.step_index() != b.step_index() {
        return Some(format!(
            "step {} against {}",
            a.step_index(),
            b.step_index()
        ));
    }
    None
}

/// Every overlapping pair of the general store is in the written-back store with the same spring, forces
/// and geometry, and every pair of the written-back store that the general store does not hold carries
/// no spring and no force.
fn compare_stores(general: &World, flat: &World) -> Result<usize, String> {
    let mut compared = 0;
    for (key, state) in general
        .contacts()
        .keys()
        .iter()
        .zip(general.contacts().states())
    {
        if !state.is_active() {
            continue;
        }
        let Some(other) = flat.contacts().get(key) else {
            return Err(format!(
                "{key:?}: overlapping in the general store, not listed by the flat path"
            ));
        };
        if (
            other.history,
            other.force_on_b,
            other.damping_force,
            other.geometry,
        ) != (
            state.history,
            state.force_on_b,
            state.damping_force,
            state.geometry,
        ) {
            return Err(format!(
                "{key:?}: flat entry {other:?} against general {state:?}"
            ));
        }
        compared += 1;
    }
    for (key, state) in flat.contacts().keys().iter().zip(flat.contacts().states()) {
        if general.contacts().get(key).is_none()
            && (state.history != Default::default()
                || state.force_on_b != polydem::math::Vector::zeros())
        {
            return Err(format!(
                "{key:?}: a spring or force in the flat store only: {state:?}"
            ));
        }
    }
    Ok(compared)
}

fn same_bits_as_the_general_step(file: &str) {
    same_bits_of(file, scene(file));
}

/// The scene with every material pair's spring carried by the other rule than its file says
/// (`SpringRotation::Exact` ↔ `Projection`): both rules are the same pure function on both paths.
fn other_rotation(file: &str) -> Simulation {
    let mut sim = scene(file);
    let n = sim.world.materials().len() as u32;
    let mut flipped = 0;
    for a in 0..n {
        for b in 0..n {
            if let Some(&model) = sim.world.materials().model(a, b) {
                let other = match model.tangential.rotation() {
                    SpringRotation::Exact => SpringRotation::Projection,
                    SpringRotation::Projection => SpringRotation::Exact,
                };
                let mut flip = model;
                flip.tangential = model.tangential.with_rotation(other);
                flipped += usize::from(flip != model);
                let mut laws = sim.world.materials().clone();
                laws.set_model(a, b, flip);
                sim.world.set_materials(laws).expect("the same materials");
            }
        }
    }
    assert!(
        flipped > 0,
        "{file}: no material pair with a tangential spring"
    );
    sim
}

fn same_bits_of(file: &str, sim: Simulation) {
    let reference = general(&sim, STEPS);
    let (flat_sim, written) = flat(&sim, STEPS);
    if let Some(d) = first_difference(&reference, &written) {
        panic!("{file}, {STEPS} steps, flat against general: {d}");
    }
    let compared = compare_stores(&reference, &written)
        .unwrap_or_else(|e| panic!("{file}, {STEPS} steps, contact stores: {e}"));
    // The run must have contacts between spheres and walls, and have rebuilt the lists.
    let walls = reference
        .contacts()
        .keys()
        .iter()
        .zip(reference.contacts().states())
        .filter(|(k, s)| matches!(k, ContactKey::Wall { .. }) && s.is_active())
        .count();
    assert!(
        compared > 2000 && walls > 100 && flat_sim.neighbours().builds() > 1,
        "{file}: {compared} overlapping pairs compared ({walls} against walls), {} list builds: \
         expected > 2000, > 100 and > 1 for a test that can fail",
        flat_sim.neighbours().builds()
    );
    // And the general step continues from the written-back world with the same bits as without the
    // detour (its store holds the same springs, its broad phase rebuilds).
    let mut continued = written.clone();
    let mut scratch = StepScratch::default();
    let mut straight = reference.clone();
    let mut scratch2 = StepScratch::default();
    for _ in 0..20 {
        step(&sim.params, &mut continued, &mut scratch).expect("general step after write-back");
        step(&sim.params, &mut straight, &mut scratch2).expect("general step");
    }
    if let Some(d) = first_difference(&straight, &continued) {
        panic!("{file}: 20 general steps after the write-back differ from the straight run: {d}");
    }
}

#[test]
fn flat_path_is_the_general_step_bit_for_bit_hertz_mindlin() {
    same_bits_as_the_general_step("scenes/sphere_bed_a_hertz_5ms.toml");
}

#[test]
fn flat_path_is_the_general_step_bit_for_bit_linear() {
    same_bits_as_the_general_step("scenes/sphere_bed_c_linear_5ms.toml");
}

#[test]
fn flat_path_is_the_general_step_bit_for_bit_with_the_other_spring_rotation() {
    for file in [
        "scenes/sphere_bed_a_hertz_5ms.toml",
        "scenes/sphere_bed_c_linear_5ms.toml",
    ] {
        same_bits_of(file, other_rotation(file));
    }
}

#[test]
fn flat_path_is_the_same_on_one_two_and_four_threads() {
    let sim = scene("scenes/sphere_bed_a_hertz_5ms.toml");
    let run = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .expect("pool");
        pool.install(|| flat(&sim, STEPS).1)
    };
    let one = run(1);
    // 2 and 4 threads: 4 and 8 blocks of the pair loop, with roughly 15 % and 35 % of the spheres'
    // loads gathered instead of summed by the pair loop (one block on one thread).
    for threads in [2, 4] {
        let other = run(threads);
        if let Some(d) = first_difference(&one, &other) {
            panic!("sphere bed a, {STEPS} flat steps, 1 against {threads} threads: {d}");
        }
        assert!(
            one.contacts() == other.contacts(),
            "sphere bed a: the written-back contact stores of 1 and {threads} threads differ"
        );
    }
}

/// A run of steps (`SphereSim::run_steps`, which on several threads holds the pool's threads for the
/// whole run) steps to the same bits as `SphereSim::step` called as often, on 1, 2 and 3 threads, with
/// the same reports, through builds of the lists; it calls back after every step and stops after the step at which it is told to.
#[test]
fn run_of_steps_is_the_same_as_stepping() {
    // Long enough for the lists to be rebuilt a few times (the ball lands at step ~50).
    const RUN_STEPS: u64 = 1000;
    for file in [
        "scenes/sphere_bed_a_hertz_5ms.toml",
        "scenes/sphere_bed_c_linear_5ms.toml",
    ] {
        let sim = scene(file);
        for threads in [1, 2, 3] {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .expect("pool");
            let start = || {
                SphereSim::from_world(&sim.world, &sim.params)
                    .unwrap_or_else(|e| panic!("{file}: {e}"))
            };
            let (stepped, stepped_reports) = pool.install(|| {
                let mut flat = start();
                let reports: Vec<_> = (0..RUN_STEPS)
                    .map(|_| {
                        let r = flat.step().unwrap_or_else(|e| panic!("{file}: step: {e}"));
                        (r.contacts, r.counters.broad_rebuilds, r.max_overlap_ratio)
                    })
                    .collect();
                (flat, reports)
            });
            let (ran, ran_reports, steps_seen) = pool.install(|| {
                let mut flat = start();
                let mut reports = Vec::new();
                let mut steps_seen = Vec::new();
                let done = flat
                    .run_steps(RUN_STEPS, |flat, r| {
                        steps_seen.push(flat.step_index());
                        reports.push((r.contacts, r.counters.broad_rebuilds, r.max_overlap_ratio));
                        ControlFlow::Continue(())
                    })
                    .unwrap_or_else(|e| panic!("{file}: run_steps: {e}"));
                assert_eq!(done, RUN_STEPS, "{file}, {threads} thread(s): steps run");
                (flat, reports, steps_seen)
            });
            assert_eq!(
                steps_seen,
                (1..=RUN_STEPS).collect::<Vec<_>>(),
                "{file}, {threads} thread(s): the step index seen by each call back"
            );
            assert!(
                ran_reports == stepped_reports,
                "{file}, {threads} thread(s): the reports of run_steps and step differ"
            );
            let rebuilds: u64 = ran_reports.iter().map(|r| r.1).sum();
            assert!(
                rebuilds >= 2,
                "{file}: {rebuilds} builds of the lists in {RUN_STEPS} steps: the run must rebuild them"
            );
            let write = |flat: &SphereSim| {
                let mut world = sim.world.clone();
                flat.write_back(&mut world);
                world
            };
            let (a, b) = (write(&stepped), write(&ran));
            if let Some(d) = first_difference(&a, &b) {
                panic!(
                    "{file}, {RUN_STEPS} steps on {threads} thread(s), step against run_steps: {d}"
                );
            }
            compare_stores(&a, &b)
                .unwrap_or_else(|e| panic!("{file}, {threads} thread(s), contact stores: {e}"));
            // Told to stop after its 7th step, a run stops there.
            let stopped = pool.install(|| {
                let mut flat = start();
                let done = flat
                    .run_steps(RUN_STEPS, |flat, _| {
                        if flat.step_index() == 7 {
                            ControlFlow::Break(())
                        } else {
                            ControlFlow::Continue(())
                        }
                    })
                    .unwrap_or_else(|e| panic!("{file}: run_steps: {e}"));
                (done, flat.step_index())
            });
            assert_eq!(
                stopped,
                (7, 7),
                "{file}, {threads} thread(s): (steps run, step index)"
            );
        }
    }
}

/// Any split of the team's work gives the same bits as one thread: blocks only (`TeamSplit::fixed`),
/// the default, and middles as wide as a thread's share in every pass (the threads share out most of
/// each pass while it runs), on 2 and 3 threads, the split changed halfway through a build of the lists.
#[test]
fn flat_path_is_the_same_for_any_split_of_the_team() {
    let sim = scene("scenes/sphere_bed_a_hertz_5ms.toml");
    let wide = TeamSplit {
        middle_share: 1.0,
        pass_middle_share: 1.0,
        follow_speeds: true,
    };
    let run = |threads: usize, first: TeamSplit, then: TeamSplit| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .expect("pool");
        pool.install(|| {
            let mut flat = SphereSim::from_world(&sim.world, &sim.params)
                .unwrap_or_else(|e| panic!("the sphere bed must take the flat path: {e}"));
            flat.set_team_split(first);
            let half = STEPS / 2 + 7;
            flat.run_steps(half, |_, _| ControlFlow::Continue(()))
                .unwrap_or_else(|e| panic!("flat steps: {e}"));
            flat.set_team_split(then);
            flat.run_steps(STEPS - half, |_, _| ControlFlow::Continue(()))
                .unwrap_or_else(|e| panic!("flat steps: {e}"));
            let mut world = sim.world.clone();
            flat.write_back(&mut world);
            world
        })
    };
    let one = run(1, TeamSplit::default(), TeamSplit::default());
    let splits = [
        ("fixed", TeamSplit::fixed()),
        ("default", TeamSplit::default()),
        ("wide", wide),
    ];
    for threads in [2, 3] {
        for (k, (name, split)) in splits.iter().enumerate() {
            let (then_name, then) = splits[(k + 1) % splits.len()];
            let other = run(threads, *split, then);
            if let Some(d) = first_difference(&one, &other) {
                panic!(
                    "sphere bed a, {STEPS} flat steps, 1 thread against {threads} with the split \
                     {name} then {then_name}: {d}"
                );
            }
            compare_stores(&one, &other).unwrap_or_else(|e| {
                panic!("sphere bed a, {threads} threads, split {name} then {then_name}: {e}")
            });
        }
    }
}

/// The passes' x86-64-v3 build (AVX2, chosen at run time where the CPU has it) steps to the same bits
/// as the baseline build, on one thread and on two (the fused job), for both laws. On a CPU without the
/// features there is one build, and the test says so and checks that it cannot be turned on.
#[test]
fn flat_path_is_the_same_with_and_without_wide_instructions() {
    for file in [
        "scenes/sphere_bed_a_hertz_5ms.toml",
        "scenes/sphere_bed_c_linear_5ms.toml",
    ] {
        let sim = scene(file);
        for threads in [1, 2] {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .expect("pool");
            let run = |wide: bool| {
                pool.install(|| {
                    let mut flat = SphereSim::from_world(&sim.world, &sim.params)
                        .unwrap_or_else(|e| panic!("{file}: {e}"));
                    let on = flat.set_wide_instructions(wide);
                    for _ in 0..STEPS {
                        flat.step()
                            .unwrap_or_else(|e| panic!("{file}: flat step: {e}"));
                    }
                    let mut world = sim.world.clone();
                    flat.write_back(&mut world);
                    (on, world)
                })
            };
            let (on, wide) = run(true);
            let (off, narrow) = run(false);
            assert!(!off, "{file}: the wide instructions were not turned off");
            if !on {
                eprintln!("{file}: this CPU lacks AVX2/BMI: only the baseline build ran");
                continue;
            }
            if let Some(d) = first_difference(&narrow, &wide) {
                panic!(
                    "{file}, {STEPS} flat steps on {threads} thread(s), baseline against AVX2: {d}"
                );
            }
            compare_stores(&narrow, &wide)
                .unwrap_or_else(|e| panic!("{file}, {threads} thread(s), contact stores: {e}"));
        }
    }
}

/// Every step reports the same overlap warnings on both paths, pairs between spheres then pairs with
/// walls, on one thread (one block of the pair loop) and on two (four blocks). The warning fraction is 0,
/// so every overlapping contact is a warning: the lists compared are the steps' whole contact lists.
#[test]
fn flat_path_reports_the_overlap_warnings_of_the_general_step() {
    let mut sim = scene("scenes/sphere_bed_a_hertz_5ms.toml");
    sim.params.overlap_warning_fraction = 0.0;
    let steps = 60;
    let mut world = sim.world.clone();
    let mut scratch = StepScratch::default();
    let reference: Vec<_> = (0..steps)
        .map(|_| {
            step(&sim.params, &mut world, &mut scratch)
                .unwrap_or_else(|e| panic!("general step: {e}"))
                .overlap_warnings
        })
        .collect();
    for threads in [1, 2] {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .expect("pool");
        let warnings: Vec<_> = pool.install(|| {
            let mut flat = SphereSim::from_world(&sim.world, &sim.params)
                .unwrap_or_else(|e| panic!("the sphere bed must take the flat path: {e}"));
            (0..steps)
                .map(|_| {
                    flat.step()
                        .unwrap_or_else(|e| panic!("flat step: {e}"))
                        .overlap_warnings
                })
                .collect()
        });
        for (k, (flat, general)) in warnings.iter().zip(&reference).enumerate() {
            let walls = |w: &[polydem::world::step::OverlapWarning]| {
                w.iter()
                    .filter(|w| matches!(w.key, ContactKey::Wall { .. }))
                    .count()
            };
            assert!(
                flat == general,
                "step {k}, {threads} thread(s): {} flat warnings ({} with walls) against {} general \
                 ({} with walls)",
                flat.len(),
                walls(flat),
                general.len(),
                walls(general)
            );
            assert!(
                walls(general) > 100 && general.len() > walls(general) + 1000,
                "step {k}: {} warnings, {} with walls: expected > 100 with walls and > 1000 between \
                 spheres for a test that can fail",
                general.len(),
                walls(general)
            );
        }
    }
}
