//! Stages 1–8 of a flat step as one job of the team: the drift, the pair loop and the kick run one
//! after the other on every thread, separated by barriers, instead of as three jobs.
//!
//! Why: each job of the team (`rayon::broadcast`) cost ~4–10 µs to start and join on the 2-core VM, on
//! top of the work of its parts (a pass's wall time less its slowest part's, per-part timestamps on the
//! sphere beds, 2026-11-23): about 20 µs of a two-thread step of ~200 µs. A barrier between two phases of
//! one job costs the wait for the slower thread only.
//!
//! How: part k of each pass runs on thread k, as in the pass-by-pass step ([`super::step`]), with the
//! same functions ([`super::passes`]), so the bits are the same. After the drift, every thread reads
//! every thread's displacements and decides for itself whether the lists hold
//! ([`StaleTest`](super::neighbours::StaleTest): the same
//! inputs, so the same answer). If they do not, the job ends there and the step goes on pass by pass
//! (the lists are rebuilt serially); otherwise the pair loop and the kick follow in the same job. A
//! block that fails (a pair without a law) makes every thread skip the kick, as the pass-by-pass step
//! returns before it.
//!
//! The arrays that one phase writes in parts and another reads whole are shared as [`PhaseSlice`]s:
//!
//! ```text
//!               drift (ranges D)   pair loop (blocks B, their pairs P)   kick (ranges K)
//!  kin          write D_k          read all                             write K_k
//!  spin         write D_k          -                                    write K_k
//!  force/torque read all           write B_k                            write K_k (gathered: read outs)
//!  springs, flags, outputs  -      write P_k                            read all
//! ```

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Mutex;
use std::time::Instant;

use crate::math::Real;

use super::super::step::StepReport;
use super::neighbours::TopTwo;
use super::pair::PairContext;
use super::passes::{BlockPart, Drift, Found, Kick, PairBlocks, Rows};
use super::team::{Barrier, PhaseSlice};
use super::SphereSim;

/// How a fused step ended.
pub(super) enum Fused {
    /// The lists must be rebuilt: only the drift ran, with these displacements since the build.
    Stale { top: TopTwo, large: TopTwo },
    /// Stages 1–8 ran: what the pair loop found (not yet [`Found::finish`]ed) and the first non-finite
    /// quantity of the kick (none if a block failed: the kick was skipped).
    Stepped {
        found: Found,
        non_finite: Option<(usize, &'static str)>,
    },
}

/// What one thread of the job brings back.
struct ThreadEnd {
    /// The pair loop's block and the kick's first non-finite quantity, unless the lists were stale.
    stepped: Option<(Found, Option<(usize, &'static str)>)>,
    /// When the drift and the pair loop ended (timers of the step's stages).
    drift_end: Instant,
    pairs_end: Instant,
}

impl SphereSim {
    /// Whether the next step runs as one job of the current pool's team: several threads, the
    /// per-sphere passes on the pool, and one block per thread made for the current lists (the first
    /// step after a build of the lists or a change of pool goes pass by pass and makes them).
    pub(super) fn fuses(&self) -> bool {
        let threads = rayon::current_num_threads();
        let blocks = &self.blocks;
        self.parallel_bodies()
            && threads > 1
            && blocks.built_for == (self.list.builds(), threads)
            && blocks.bodies.len() == threads
            && blocks.kick.len() == threads
            && blocks.drift.len() == threads
            && self.out.len() == self.list.body_pairs()
            && self.wall_out.len() == self.list.wall_pairs()
    }

    /// Stages 1–8 as one job of the team, when the passes run on it with the blocks of the current lists
    /// (else `None`: nothing ran).
    pub(super) fn fused_step(&mut self, dt: Real, report: &mut StepReport) -> Option<Fused> {
        if !self.fuses() {
            return None;
        }
        let threads = rayon::current_num_threads();
        let start = Instant::now();
        let stale_test = self.list.stale_test(&self.planes);
        let fraction = self.params.overlap_warning_fraction;
        let step_index = self.step_index;
        let (gravity, form, track_orientation) = (self.gravity, self.form, self.track_orientation);
        let list = &mut self.list;
        let blocks = &self.blocks;
        // Per block, its range of body pairs and of wall pairs.
        let pair_ranges: Vec<_> = blocks
            .bodies
            .iter()
            .map(|r| list.row_start[r.start] as usize..list.row_start[r.end] as usize)
            .collect();
        let wall_ranges: Vec<_> = blocks
            .bodies
            .iter()
            .map(|r| list.wall_start[r.start] as usize..list.wall_start[r.end] as usize)
            .collect();
        let kin = PhaseSlice::new(&mut self.kin);
        let spin = PhaseSlice::new(&mut self.spin);
        let force = PhaseSlice::new(&mut self.force);
        let torque = PhaseSlice::new(&mut self.torque);
        let histories = PhaseSlice::new(&mut list.histories);
        let in_contact = PhaseSlice::new(&mut list.in_contact);
        let out = PhaseSlice::new(&mut self.out);
        let wall_histories = PhaseSlice::new(&mut list.wall_histories);
        let wall_in_contact = PhaseSlice::new(&mut list.wall_in_contact);
        let wall_out = PhaseSlice::new(&mut self.wall_out);
        let (props, planes) = (&self.props, &self.planes);
        let (a, b, row_start, wall_start) = (&list.a, &list.b, &list.row_start, &list.wall_start);
        let (wall_body, wall_of) = (&list.wall_body, &list.wall_of);
        let (as_b_start, as_b) = (&list.as_b_start, &list.as_b);
        let (at_build, large_flags) = (&list.centres_at_build, &list.large_flags);
        let (reach, constants, wall_constants) =
            (&self.reach, &self.pair_constants, &self.wall_constants);
        let moved: Vec<Mutex<(TopTwo, TopTwo)>> = (0..threads).map(|_| Mutex::default()).collect();
        let failed = AtomicBool::new(false);
        let barrier = Barrier::new(threads);

        let ends: Vec<ThreadEnd> = rayon::broadcast(|ctx| {
            let k = ctx.index();
            // Drift.
            {
                let range = blocks.drift[k].clone();
                // SAFETY: the drift ranges tile the spheres, one per thread; nobody reads kin or spin
                // whole, or writes force or torque, in this phase.
                let (kin, spin) = unsafe { (kin.part(range.clone()), spin.part(range.clone())) };
                let drift = Drift {
                    props,
                    // SAFETY: as above.
                    force: unsafe { force.whole() },
                    torque: unsafe { torque.whole() },
                    at_build,
                    large_flags,
                    gravity,
                    form,
                    dt,
                    track_orientation,
                };
                let m = drift.run(range.start, kin, spin);
                *moved[k].lock().unwrap_or_else(|e| e.into_inner()) = m;
            }
            barrier.wait(1);
            let drift_end = Instant::now();
            let (top, large) = moved
                .iter()
                .map(|m| *m.lock().unwrap_or_else(|e| e.into_inner()))
                .fold((TopTwo::default(), TopTwo::default()), |(a, b), (c, d)| {
                    (a.merge(c), b.merge(d))
                });
            if stale_test.is_stale(top, large) {
                return ThreadEnd {
                    stepped: None,
                    drift_end,
                    pairs_end: drift_end,
                };
            }
            // Pair loop.
            let found = {
                let (body_range, pairs, walls) = (
                    blocks.bodies[k].clone(),
                    pair_ranges[k].clone(),
                    wall_ranges[k].clone(),
                );
                // SAFETY: blocks, their pairs and their walls are disjoint between threads; in this
                // phase kin is only read, and the pair outputs, springs and flags only in parts.
                let (part, kin) = unsafe {
                    (
                        BlockPart {
                            histories: histories.part(pairs.clone()),
                            in_contact: in_contact.part(pairs.clone()),
                            outs: out.part(pairs),
                            wall_histories: wall_histories.part(walls.clone()),
                            wall_in_contact: wall_in_contact.part(walls.clone()),
                            wall_outs: wall_out.part(walls),
                            force: force.part(body_range.clone()),
                            torque: torque.part(body_range.clone()),
                        },
                        kin.whole(),
                    )
                };
                let pass = PairBlocks {
                    ctx: PairContext {
                        kin,
                        props,
                        walls: planes,
                        dt,
                        step_index,
                    },
                    a,
                    b,
                    row_start,
                    wall_start,
                    wall_body,
                    wall_of,
                    reach,
                    constants,
                    wall_constants,
                    gathered: &blocks.gathered,
                    fraction,
                };
                pass.run(body_range.start, part)
            };
            if found.failed() {
                failed.store(true, Ordering::Release);
            }
            barrier.wait(2);
            let pairs_end = Instant::now();
            if failed.load(Ordering::Acquire) {
                return ThreadEnd {
                    stepped: Some((found, None)),
                    drift_end,
                    pairs_end,
                };
            }
            // Kick.
            let non_finite = {
                let range = blocks.kick[k].clone();
                // SAFETY: the kick ranges tile the spheres, one per thread; the outputs, springs and
                // flags are only read in this phase.
                let (f, t, kin, spin, rows, out, wall_out) = unsafe {
                    (
                        force.part(range.clone()),
                        torque.part(range.clone()),
                        kin.part(range.clone()),
                        spin.part(range.clone()),
                        Rows {
                            row_start,
                            as_b_start,
                            as_b,
                            wall_start,
                            in_contact: in_contact.whole(),
                            wall_in_contact: wall_in_contact.whole(),
                        },
                        out.whole(),
                        wall_out.whole(),
                    )
                };
                let kick = Kick {
                    rows,
                    out,
                    wall_out,
                    gathered: &blocks.gathered,
                    scattered: true,
                    props,
                    gravity,
                    dt,
                };
                kick.run(range.start, f, t, kin, spin)
            };
            ThreadEnd {
                stepped: Some((found, non_finite)),
                drift_end,
                pairs_end,
            }
        });

        // Stage timers as thread 0 saw the phases end.
        let end = Instant::now();
        let (drift_end, pairs_end) = ends
            .first()
            .map_or((end, end), |e| (e.drift_end, e.pairs_end));
        report.counters.integrate += (drift_end - start) + (end - pairs_end);
        report.counters.narrow += pairs_end.saturating_duration_since(drift_end);
        let mut stepped = Vec::with_capacity(ends.len());
        for e in ends {
            match e.stepped {
                Some(s) => stepped.push(s),
                None => {
                    let (top, large) = moved
                        .into_iter()
                        .map(|m| m.into_inner().unwrap_or_else(|e| e.into_inner()))
                        .fold((TopTwo::default(), TopTwo::default()), |(a, b), (c, d)| {
                            (a.merge(c), b.merge(d))
                        });
                    return Some(Fused::Stale { top, large });
                }
            }
        }
        self.outs_valid = true;
        let mut non_finite = None;
        let mut found = Found::default();
        for (f, nf) in stepped {
            found = found.merge(f);
            non_finite = non_finite.or(nf);
        }
        Some(Fused::Stepped { found, non_finite })
    }
}

#[cfg(test)]
mod tests {
    use crate::scene::load_scene;
    use crate::world::SphereSim;

    /// On two threads the steps of a sphere bed run as one job from the first on (the blocks are made
    /// with the simulation) and again after every build of the lists; on one thread never.
    #[test]
    fn steps_fuse_on_two_threads_only() {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("scenes/sphere_bed_c_linear_5ms.toml");
        let mut scene = load_scene(&path).expect("scene");
        scene.params.energy_ledger = false;
        for threads in [1, 2] {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .expect("pool");
            pool.install(|| {
                let mut sim = SphereSim::from_world(&scene.world, &scene.params).expect("flat");
                let mut fused = 0;
                for _ in 0..200 {
                    fused += usize::from(sim.fuses());
                    sim.step().expect("step");
                }
                let builds = sim.list.builds();
                match threads {
                    1 => assert_eq!(fused, 0, "one thread: {fused} of 200 steps fused"),
                    _ => assert!(
                        fused >= 200 - builds as usize && builds >= 2,
                        "two threads: {fused} of 200 steps fused with {builds} builds"
                    ),
                }
            });
        }
    }
}
