//! Stages 1–8 of a flat step as one job of the team: the drift, the pair loop and the kick run one
//! after the other on every thread, separated by barriers, instead of as three jobs.
//!
//! Why: each job of the team (`rayon::broadcast`) costs a start and a join on top of the work of its
//! parts, about a tenth of a two-thread step of the sphere beds (`docs/tuning.md`). A barrier between
//! two phases of one job costs the wait for the slower thread only. In a run of steps ([`SphereSim::run_steps`]) the
//! job is a task of the run's [`Crew`], whose threads are already running, instead of a broadcast.
//!
//! How: thread k runs part k of each pass, then takes pieces of the pass's middles until it meets the
//! neighbouring thread ([`super::blocks::Blocks`], [`TwoEnded`]), with the functions of the pass-by-pass
//! step ([`super::step`], [`super::passes`]), so the bits are the same. After the drift, every thread reads
//! every thread's displacements and decides for itself whether the lists hold ([`StaleTest`]: the same
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
//!
//!  (D_k, B_k, K_k: thread k's range and the pieces of the middles it took; P_k: their pairs)
//! ```

use std::ops::Range;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Mutex;
use std::time::Instant;

use crate::dynamics::rotation::SubRotation;
use crate::law::TangentialHistory;
use crate::math::{Point, Real, Vector};

use super::super::energy::ContactWork;
use super::super::step::StepReport;
use super::super::world::Wall;
use super::blocks::Blocks;
use super::crew::Crew;
use super::ledger::LastContact;
use super::neighbours::{StaleTest, TopTwo};
use super::pair::{
    Kinematic, PairConstants, PairContext, PairOut, Props, WallConstants, WallPlane,
};
use super::passes::{
    wall_sums, BlockPart, Drift, Found, Kick, KickPart, LedgerPart, PairBlocks, Rows,
};
use super::team::{pieces_of, Barrier, PhaseSlice, TwoEnded};
use super::{SphereSim, Spin};

/// How a fused step ended.
// One per step, returned by value and matched at once: boxing the larger variant would only add an
// allocation per step.
#[allow(clippy::large_enum_variant)]
pub(super) enum Fused {
    /// The lists must be rebuilt: only the drift ran, with these displacements since the build.
    Stale { top: TopTwo, large: TopTwo },
    /// Stages 1–8 ran: what the pair loop found (not yet [`Found::finish`]ed) and the first non-finite
    /// quantity of the kick (none if a block failed: the kick was skipped).
    Stepped {
        found: Found,
        non_finite: Option<(usize, &'static str)>,
        /// Stage 9's wall sums (forces, power), formed by the team's last thread in the kick phase
        /// (none if a block failed).
        walls: Option<(Vec<Vector>, Real)>,
    },
}

/// What one thread of the job brings back.
struct ThreadEnd {
    /// The pair loop's block and the kick's first non-finite quantity, unless the lists were stale.
    stepped: Option<(Found, Option<(usize, &'static str)>)>,
    /// When the drift and the pair loop ended (timers of the step's stages).
    drift_end: Instant,
    pairs_end: Instant,
    /// The time the thread took for its block of the pair loop (s), if it ran.
    block_seconds: Option<f64>,
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
    /// (else `None`: nothing ran): a task of `crew` when the run holds one (of the pool's size), else a
    /// broadcast on the pool.
    pub(super) fn fused_step(
        &mut self,
        dt: Real,
        report: &mut StepReport,
        crew: Option<&Crew>,
    ) -> Option<Fused> {
        if !self.fuses() {
            return None;
        }
        let threads = rayon::current_num_threads();
        let start = Instant::now();
        let stale_test = self.list.stale_test(&self.planes);
        let list = &mut self.list;
        let blocks = &self.blocks;
        let two_ended =
            |ranges: &[Range<usize>]| ranges.iter().cloned().map(TwoEnded::new).collect();
        let job = Job {
            middles: two_ended(&blocks.middles),
            kick_middles: two_ended(&blocks.kick_middles),
            drift_middles: two_ended(&blocks.drift_middles),
            blocks,
            kin: PhaseSlice::new(&mut self.kin),
            spin: PhaseSlice::new(&mut self.spin),
            force: PhaseSlice::new(&mut self.force),
            torque: PhaseSlice::new(&mut self.torque),
            histories: PhaseSlice::new(&mut list.histories),
            in_contact: PhaseSlice::new(&mut list.in_contact),
            out: PhaseSlice::new(&mut self.out),
            wall_histories: PhaseSlice::new(&mut list.wall_histories),
            wall_in_contact: PhaseSlice::new(&mut list.wall_in_contact),
            wall_out: PhaseSlice::new(&mut self.wall_out),
            ledger: self.params.energy_ledger,
            last: PhaseSlice::new(&mut self.pair_ledger.last),
            work: PhaseSlice::new(&mut self.pair_ledger.work),
            wall_last: PhaseSlice::new(&mut self.pair_ledger.wall_last),
            wall_work: PhaseSlice::new(&mut self.pair_ledger.wall_work),
            props: &self.props,
            planes: &self.planes,
            a: &list.a,
            b: &list.b,
            row_start: &list.row_start,
            wall_start: &list.wall_start,
            wall_body: &list.wall_body,
            wall_of: &list.wall_of,
            as_b_start: &list.as_b_start,
            as_b: &list.as_b,
            at_build: &list.centres_at_build,
            large_flags: &list.large_flags,
            reach: &self.reach,
            constants: &self.pair_constants,
            wall_constants: &self.wall_constants,
            gravity: self.gravity,
            form: self.form,
            track_orientation: self.track_orientation,
            v3: self.v3,
            fraction: self.params.overlap_warning_fraction,
            step_index: self.step_index,
            dt,
            stale_test,
            moved: (0..threads).map(|_| Mutex::default()).collect(),
            failed: AtomicBool::new(false),
            barrier: Barrier::new(threads),
            walls: &self.walls,
            wall_sums: Mutex::new(None),
        };
        let ends: Vec<ThreadEnd> = match crew {
            Some(crew) if crew.threads() == threads => crew.together(|k| job.run(k)),
            _ => rayon::broadcast(|ctx| job.run(ctx.index())),
        };

        record_stage_times(&ends, start, report);
        let mut stepped = Vec::with_capacity(ends.len());
        for (k, e) in ends.iter().enumerate() {
            if let (Some(seconds), Some(&weight)) = (e.block_seconds, blocks.block_weights.get(k)) {
                self.speeds.add(k, weight, seconds);
            }
        }
        for e in ends {
            match e.stepped {
                Some(s) => stepped.push(s),
                None => {
                    let (top, large) = job.moved();
                    return Some(Fused::Stale { top, large });
                }
            }
        }
        let walls = job
            .wall_sums
            .into_inner()
            .unwrap_or_else(|e| e.into_inner());
        self.outs_valid = true;
        let (found, non_finite) = merged(stepped);
        Some(Fused::Stepped {
            found,
            non_finite,
            walls,
        })
    }
}

/// The stage timers of a fused step that began at `start`, as thread 0 saw its phases end.
fn record_stage_times(ends: &[ThreadEnd], start: Instant, report: &mut StepReport) {
    let end = Instant::now();
    let (drift_end, pairs_end) = ends
        .first()
        .map_or((end, end), |e| (e.drift_end, e.pairs_end));
    report.counters.integrate += (drift_end - start) + (end - pairs_end);
    report.counters.narrow += pairs_end.saturating_duration_since(drift_end);
}

/// The threads' blocks of the pair loop merged, and the lowest sphere's first non-finite quantity (see
/// `Job::kick`).
fn merged(
    stepped: Vec<(Found, Option<(usize, &'static str)>)>,
) -> (Found, Option<(usize, &'static str)>) {
    let mut non_finite: Option<(usize, &str)> = None;
    let mut found = Found::default();
    for (f, nf) in stepped {
        found = found.merge(f);
        non_finite = match (non_finite, nf) {
            (Some(a), Some(b)) if b.0 < a.0 => Some(b),
            (a, b) => a.or(b),
        };
    }
    (found, non_finite)
}

/// One fused job: the arrays its phases share (see the module docs' table), the inputs they read, and
/// what the threads exchange (the drift's displacements, a failed block, the barrier).
struct Job<'a> {
    blocks: &'a Blocks,
    /// The middles of the pair loop, the kick and the drift, as their two threads share them out.
    middles: Vec<TwoEnded>,
    kick_middles: Vec<TwoEnded>,
    drift_middles: Vec<TwoEnded>,
    kin: PhaseSlice<'a, Kinematic>,
    spin: PhaseSlice<'a, Spin>,
    force: PhaseSlice<'a, Vector>,
    torque: PhaseSlice<'a, Vector>,
    histories: PhaseSlice<'a, TangentialHistory>,
    in_contact: PhaseSlice<'a, bool>,
    out: PhaseSlice<'a, PairOut>,
    wall_histories: PhaseSlice<'a, TangentialHistory>,
    wall_in_contact: PhaseSlice<'a, bool>,
    wall_out: PhaseSlice<'a, PairOut>,
    /// Whether the pairs book the energy ledger, and its slots (written in the pair phase only; empty
    /// when it is off).
    ledger: bool,
    last: PhaseSlice<'a, LastContact>,
    work: PhaseSlice<'a, ContactWork>,
    wall_last: PhaseSlice<'a, LastContact>,
    wall_work: PhaseSlice<'a, ContactWork>,
    props: &'a [Props],
    planes: &'a [WallPlane],
    a: &'a [u32],
    b: &'a [u32],
    row_start: &'a [u32],
    wall_start: &'a [u32],
    wall_body: &'a [u32],
    wall_of: &'a [u32],
    as_b_start: &'a [u32],
    as_b: &'a [u32],
    at_build: &'a [Point],
    large_flags: &'a [bool],
    reach: &'a [Real],
    constants: &'a [PairConstants],
    wall_constants: &'a [WallConstants],
    gravity: Vector,
    form: SubRotation,
    track_orientation: bool,
    v3: bool,
    fraction: Real,
    step_index: u64,
    dt: Real,
    stale_test: StaleTest,
    /// Each thread's two largest squared displacements since the build (small spheres, large ones).
    moved: Vec<Mutex<(TopTwo, TopTwo)>>,
    /// Whether a block of the pair loop failed (then no thread kicks).
    failed: AtomicBool,
    barrier: Barrier,
    /// The walls, and their sums as the last thread forms them in the kick phase.
    walls: &'a [Wall],
    wall_sums: Mutex<Option<(Vec<Vector>, Real)>>,
}

impl Job<'_> {
    /// The phases on thread `k` of the team: drift, the decision whether the lists hold, pair loop,
    /// kick, with a barrier after the drift and after the pair loop.
    fn run(&self, k: usize) -> ThreadEnd {
        // SAFETY (of the three phases' calls): every thread of the team runs `run` once with its own
        // index k, and the barriers keep the phases apart.
        let moved = unsafe { self.drift(k) };
        *self.moved[k].lock().unwrap_or_else(|e| e.into_inner()) = moved;
        self.barrier.wait(1);
        let drift_end = Instant::now();
        let (top, large) = self.moved();
        if self.stale_test.is_stale(top, large) {
            return ThreadEnd {
                stepped: None,
                drift_end,
                pairs_end: drift_end,
                block_seconds: None,
            };
        }
        let (found, block_seconds) = unsafe { self.pairs(k) };
        if found.failed() {
            self.failed.store(true, Ordering::Release);
        }
        self.barrier.wait(2);
        let pairs_end = Instant::now();
        let non_finite = if self.failed.load(Ordering::Acquire) {
            None
        } else {
            if k + 1 == self.blocks.kick.len() {
                // SAFETY: the wall outputs and flags are only read in the kick phase.
                let sums = unsafe { self.sum_walls() };
                *self.wall_sums.lock().unwrap_or_else(|e| e.into_inner()) = Some(sums);
            }
            unsafe { self.kick(k) }
        };
        ThreadEnd {
            stepped: Some((found, non_finite)),
            drift_end,
            pairs_end,
            block_seconds: Some(block_seconds),
        }
    }

    /// The displacements of all threads' drifts, merged.
    fn moved(&self) -> (TopTwo, TopTwo) {
        self.moved
            .iter()
            .map(|m| *m.lock().unwrap_or_else(|e| e.into_inner()))
            .fold((TopTwo::default(), TopTwo::default()), |(a, b), (c, d)| {
                (a.merge(c), b.merge(d))
            })
    }

    /// Thread `k`'s part of the drift: its range, then pieces of the drift's middles, taken as in the
    /// pair loop ([`Job::pairs`]); the two largest displacements of each kind among its spheres.
    ///
    /// # Safety
    /// Called once per thread index in the drift phase.
    unsafe fn drift(&self, k: usize) -> (TopTwo, TopTwo) {
        let merge = |(a, b): (TopTwo, TopTwo), (c, d): (TopTwo, TopTwo)| (a.merge(c), b.merge(d));
        // SAFETY (of each `drift_spheres`): the drift's ranges, middles and pieces are disjoint.
        let mut moved = unsafe { self.drift_spheres(self.blocks.drift[k].clone()) };
        for (piece, _) in pieces_of(&self.drift_middles, k) {
            moved = merge(moved, unsafe { self.drift_spheres(piece) });
        }
        moved
    }

    /// The drift of spheres `range`.
    ///
    /// # Safety
    /// Called in the drift phase with `range` disjoint from every other call's: kin and spin are
    /// written only in these parts, and force and torque only read.
    unsafe fn drift_spheres(&self, range: Range<usize>) -> (TopTwo, TopTwo) {
        // SAFETY: the caller's promise.
        let (kin, spin, force, torque) = unsafe {
            (
                self.kin.part(range.clone()),
                self.spin.part(range.clone()),
                self.force.whole(),
                self.torque.whole(),
            )
        };
        let drift = Drift {
            props: self.props,
            force,
            torque,
            at_build: self.at_build,
            large_flags: self.large_flags,
            gravity: self.gravity,
            form: self.form,
            dt: self.dt,
            track_orientation: self.track_orientation,
            v3: self.v3,
        };
        drift.run(range.start, kin, spin)
    }

    /// Thread `k`'s part of the pair loop: its block, then pieces of the middle after it from the front
    /// and of the middle before it from the back, until the middles' other threads meet it; what it
    /// found, in pair order, and the seconds its block took. A thread stops at the first failed piece: the pieces it leaves lie after
    /// that failure, so the first failure in pair order is still found.
    ///
    /// # Safety
    /// Called once per thread index in the pair phase.
    unsafe fn pairs(&self, k: usize) -> (Found, f64) {
        // SAFETY (of each `segment`): blocks, middles and the middles' pieces are disjoint.
        let start = Instant::now();
        let mut found = unsafe { self.segment(self.blocks.bodies[k].clone()) };
        let block_seconds = start.elapsed().as_secs_f64();
        let mut pieces = pieces_of(&self.middles, k);
        // Checked before each piece is taken: a piece taken is run by no other thread.
        while !found.failed() {
            let Some((piece, from_back)) = pieces.next() else {
                break;
            };
            let more = unsafe { self.segment(piece) };
            // A piece from the back comes before what this thread found so far.
            found = match from_back {
                true => more.merge(found),
                false => found.merge(more),
            };
        }
        (found, block_seconds)
    }

    /// The pair loop over the rows and walls of spheres `bodies`, summing the loads of the spheres no
    /// other segment's pair reaches (none in a middle).
    ///
    /// # Safety
    /// Called in the pair phase with `bodies` disjoint from every other call's: their pairs and walls
    /// are then disjoint too, the springs, flags, outputs and loads are written only in these parts,
    /// and kin only read.
    unsafe fn segment(&self, bodies: Range<usize>) -> Found {
        let pairs = self.row_start[bodies.start] as usize..self.row_start[bodies.end] as usize;
        let walls = self.wall_start[bodies.start] as usize..self.wall_start[bodies.end] as usize;
        // SAFETY: the caller's promise.
        let (part, kin) = unsafe {
            let ledger = if self.ledger {
                LedgerPart {
                    in_order: false,
                    last: self.last.part(pairs.clone()),
                    work: self.work.part(pairs.clone()),
                    wall_last: self.wall_last.part(walls.clone()),
                    wall_work: self.wall_work.part(walls.clone()),
                }
            } else {
                LedgerPart::default()
            };
            (
                BlockPart {
                    histories: self.histories.part(pairs.clone()),
                    in_contact: self.in_contact.part(pairs.clone()),
                    outs: self.out.part(pairs),
                    wall_histories: self.wall_histories.part(walls.clone()),
                    wall_in_contact: self.wall_in_contact.part(walls.clone()),
                    wall_outs: self.wall_out.part(walls),
                    force: self.force.part(bodies.clone()),
                    torque: self.torque.part(bodies.clone()),
                    ledger,
                },
                self.kin.whole(),
            )
        };
        let pass = PairBlocks {
            ctx: PairContext {
                kin,
                props: self.props,
                walls: self.planes,
                dt: self.dt,
                step_index: self.step_index,
            },
            a: self.a,
            b: self.b,
            row_start: self.row_start,
            wall_start: self.wall_start,
            wall_body: self.wall_body,
            wall_of: self.wall_of,
            reach: self.reach,
            constants: self.constants,
            wall_constants: self.wall_constants,
            gathered: &self.blocks.gathered,
            fraction: self.fraction,
            v3: self.v3,
            ledger: self.ledger,
        };
        pass.run(bodies.start, part)
    }

    /// Stage 9's wall sums, taken inside the job: serially by the lead after it they would add a
    /// serial stretch of a few per cent of a two-thread step.
    ///
    /// # Safety
    /// Called in the kick phase, which only reads the wall outputs and flags.
    unsafe fn sum_walls(&self) -> (Vec<Vector>, Real) {
        // SAFETY: the caller's promise.
        let (wall_out, wall_in_contact) =
            unsafe { (self.wall_out.whole(), self.wall_in_contact.whole()) };
        let mut forces = vec![Vector::zeros(); self.walls.len()];
        let power = wall_sums(
            wall_out,
            wall_in_contact,
            self.wall_of,
            self.walls,
            &mut forces,
        );
        (forces, power)
    }

    /// Thread `k`'s part of the kick: its range, then pieces of the kick's middles, taken as in the pair
    /// loop ([`Job::pairs`]); the first non-finite quantity it met (the lowest sphere), where it
    /// stopped. The lowest over the threads is the first of all: the pieces a thread leaves lie after
    /// its find or are taken by the middle's other thread.
    ///
    /// # Safety
    /// Called once per thread index in the kick phase.
    unsafe fn kick(&self, k: usize) -> Option<(usize, &'static str)> {
        // SAFETY (of each `kick_spheres`): the kick's ranges, middles and pieces are disjoint.
        let mut first = unsafe { self.kick_spheres(self.blocks.kick[k].clone()) };
        let mut pieces = pieces_of(&self.kick_middles, k);
        while first.is_none() {
            let Some((piece, _)) = pieces.next() else {
                break;
            };
            first = unsafe { self.kick_spheres(piece) };
        }
        first
    }

    /// The kick of spheres `range`.
    ///
    /// # Safety
    /// Called in the kick phase with `range` disjoint from every other call's: the loads, kin and spin
    /// are written only in these parts, and the springs' flags and the outputs only read.
    unsafe fn kick_spheres(&self, range: Range<usize>) -> Option<(usize, &'static str)> {
        // SAFETY: the caller's promise.
        let (force, torque, kin, spin, in_contact, wall_in_contact, out, wall_out) = unsafe {
            (
                self.force.part(range.clone()),
                self.torque.part(range.clone()),
                self.kin.part(range.clone()),
                self.spin.part(range.clone()),
                self.in_contact.whole(),
                self.wall_in_contact.whole(),
                self.out.whole(),
                self.wall_out.whole(),
            )
        };
        let kick = Kick {
            rows: Rows {
                row_start: self.row_start,
                as_b_start: self.as_b_start,
                as_b: self.as_b,
                wall_start: self.wall_start,
                in_contact,
                wall_in_contact,
            },
            out,
            wall_out,
            gathered: &self.blocks.gathered,
            scattered: true,
            props: self.props,
            gravity: self.gravity,
            dt: self.dt,
            v3: self.v3,
        };
        let part = KickPart {
            force,
            torque,
            kin,
            spin,
        };
        kick.run(range.start, part)
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
