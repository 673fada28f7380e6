//! One step of the flat sphere path, stage by stage (the stages of `super::super::sphere_step`):
//!
//! ```text
//!       walls moved by Δt times their velocity
//!  1–2. first half kick, drift, turn; ω = L/J and the displacement since the build   (per sphere)
//!  3.   lists rebuilt if the two largest displacements sum to the skin                (rows per sphere)
//!  4–5. pair loop: geometry and law of every listed pair and body–wall pair            (per pair)
//!  6–8. per-sphere sums in key order, second half kick, finiteness check               (per sphere)
//!  9.   wall forces and the walls' power (serial, pair order), ledger, time
//! ```
//! Every per-sphere and per-pair pass writes only its own items' slots, so it runs on rayon's current
//! pool with the same bits for any number of threads: each thread takes mostly the same part of each
//! pass ([`super::team`]), so that a block's records stay in one core's cache from pass to pass; when
//! the lists hold, the three passes run as one job of the team ([`super::fused`]). The pair loop runs
//! in blocks of consecutive spheres, with middles between them ([`Blocks`]: one block when serial, one
//! per thread otherwise), and adds each overlapping pair's loads to its spheres as it goes, for every
//! sphere that only its own block's pairs reach: in pair order such a sphere i receives its pairs
//! (a, i) by increasing a (rows of a < i come first), then its own row (i, b) by increasing b, then its
//! walls — the gather's order, so the same sums, bit for bit. Stage 6 gathers the loads of the other
//! spheres (in a middle, or reached by a pair of an earlier block or middle).
//! The passes themselves are in [`super::passes`].

use std::time::Instant;

use crate::math::{Point, Real, Vector};

use super::super::step::{guard, TimeStepCheck};
use super::super::step::{StepError, StepReport};
use super::super::ContactKey;
use super::blocks::Blocks;
use super::crew::Crew;
use super::fused::Fused;
use super::ledger::OldWalls;
use super::neighbours::TopTwo;
use super::pair::{PairContext, PairOut, WallPlane};
use super::passes::{
    wall_sums, BlockPart, Drift, Found, Kick, KickPart, LedgerPart, NonFinite, PairBlocks, Rows,
};
use super::team::{for_each_part, split_at_ranges};
use super::{SphereSim, MIN_PARALLEL_PAIRS};

impl SphereSim {
    /// Advances the simulation by one step (see the module docs).
    pub fn step(&mut self) -> Result<StepReport, StepError> {
        self.step_on(None)
    }

    /// One step, its team job handed to `crew` when the run holds one ([`SphereSim::run_steps`]).
    pub(super) fn step_on(&mut self, crew: Option<&Crew>) -> Result<StepReport, StepError> {
        let dt = self.params.dt;
        if !(dt.is_finite() && dt > 0.0) {
            return Err(StepError::InvalidTimeStep {
                step: self.step_index,
                dt,
            });
        }
        let mut report = StepReport::default();
        let external_start = self.external_power;
        // No global viscous damping on this path (`SphereSim::from_world` refuses it), so the kicks leave
        // out the general step's damping terms: with c = 0 they are exact no-ops here (x − (0/m)·v = x
        // because a force summed from +0.0 is never −0.0, and x / (1 + h·0/m) = x), and they cost five of
        // the fourteen divisions per sphere and step.
        debug_assert_eq!(self.params.damping, crate::dynamics::ViscousDamping::None);

        // The walls move first: their moves do not depend on the spheres (the drift is the same either
        // way).
        let t = Instant::now();
        for (wall, plane) in self.walls.iter_mut().zip(&mut self.planes) {
            wall.pose.translation.vector += dt * wall.velocity;
            *plane = WallPlane::of(wall);
        }
        report.counters.integrate += t.elapsed();

        // 1–8 as one job of the team while the lists hold, else pass by pass.
        let (found, non_finite, walls) = match self.fused_step(dt, &mut report, crew) {
            Some(Fused::Stepped {
                found,
                non_finite,
                walls,
            }) => (found.finish()?, non_finite, walls),
            drifted_or_not_run => {
                let (found, non_finite) = self.by_passes(dt, drifted_or_not_run, &mut report)?;
                (found, non_finite, None)
            }
        };
        report.counters.body_pairs_tested += self.list.body_pairs() as u64;
        report.counters.wall_pairs_tested += self.list.wall_pairs() as u64;
        report.contacts = found.contacts;
        report.max_overlap_ratio = found.max_overlap_ratio;
        report.overlap_warnings = found.warnings;
        report.counters.contacts += found.contacts as u64;
        if let Some((body, quantity)) = non_finite {
            return Err(StepError::NonFinite {
                step: self.step_index + 1,
                body,
                name: self.names[body].clone(),
                quantity,
            });
        }
        self.finish_step(dt, walls, external_start, &mut report);
        self.check_time_step(&mut report)?;
        Ok(report)
    }

    /// Stages 1–8 pass by pass, when the fused job drifted and found the lists stale (`Fused::Stale`) or
    /// did not run (`None`): the drift unless done, the lists, the pair loop, the kick. Returns what the
    /// pair loop found and the first sphere the kick left non-finite.
    fn by_passes(
        &mut self,
        dt: Real,
        drifted_or_not_run: Option<Fused>,
        report: &mut StepReport,
    ) -> Result<(Found, NonFinite), StepError> {
        let moved = match drifted_or_not_run {
            Some(Fused::Stale { top, large }) => (top, large),
            _ => self.drift(dt, report),
        };
        self.lists(moved, report);
        let t = Instant::now();
        let found = self.evaluate(dt)?;
        report.counters.narrow += t.elapsed();
        let t = Instant::now();
        let non_finite = self.kick(dt, found.scattered);
        report.counters.integrate += t.elapsed();
        Ok((found, non_finite))
    }

    /// 9. The wall forces and power (the fused job's, else summed here), the ledger, the time.
    fn finish_step(
        &mut self,
        dt: Real,
        walls: Option<(Vec<Vector>, Real)>,
        external_start: Real,
        report: &mut StepReport,
    ) {
        let t = Instant::now();
        match walls {
            Some((forces, power)) => {
                self.wall_forces = forces;
                self.external_power = power;
            }
            None => self.sum_walls(),
        }
        if self.params.energy_ledger {
            // The contact terms in pair order, added as the general step's stage 9 adds them.
            self.step_work = self.pair_ledger.take_sums();
            self.ledger.dissipated_damping += self.step_work.damping;
            self.ledger.dissipated_friction += self.step_work.friction;
            self.ledger.tangential_stiffness_work += self.step_work.stiffness;
        }
        report.counters.accumulate += t.elapsed();
        self.ledger.external_work += 0.5 * (external_start + self.external_power) * dt;
        self.time += dt;
        self.step_index += 1;
        report.counters.steps = 1;
    }

    /// The check of the time step after the step (`super::super::step::guard`; reads the state only).
    fn check_time_step(&self, report: &mut StepReport) -> Result<(), StepError> {
        let mode = self.params.time_step_check;
        if mode == TimeStepCheck::Off {
            return Ok(());
        }
        let (kin, props) = (&self.kin, &self.props);
        let bodies = guard::Bodies {
            len: kin.len(),
            state: |i: usize| (kin[i].position, kin[i].velocity, props[i].radius),
            names: &self.names,
            walls: &self.walls,
            margin: 0.5 * self.list.skin(),
        };
        let pairs = || {
            let body = self.body_pairs().map(|(a, b)| ContactKey::Body { a, b });
            body.chain(
                self.wall_pairs()
                    .map(|(body, wall)| ContactKey::Wall { body, wall }),
            )
        };
        guard::check(
            mode,
            &self.guard,
            self.params.dt,
            self.step_index,
            &bodies,
            pairs,
            &mut report.counters,
            &mut report.time_step_findings,
        )
    }

    /// What the drift reads.
    pub(super) fn drift_inputs(&self, dt: Real) -> Drift<'_> {
        Drift {
            props: &self.props,
            force: &self.force,
            torque: &self.torque,
            at_build: &self.list.centres_at_build,
            large_flags: &self.list.large_flags,
            gravity: self.gravity,
            form: self.form,
            dt,
            track_orientation: self.track_orientation,
            v3: self.v3,
        }
    }

    /// Stages 1–2 (on the team when the pair loop runs on it, in its blocks of the last build): the
    /// two largest squared displacements since the build, of the small and of the large spheres.
    fn drift(&mut self, dt: Real, report: &mut StepReport) -> (TopTwo, TopTwo) {
        let t = Instant::now();
        let team = self.parallel_bodies() && self.blocks.team();
        let mut kin = std::mem::take(&mut self.kin);
        let mut spin = std::mem::take(&mut self.spin);
        let drift = self.drift_inputs(dt);
        let moved = if team {
            // About the spheres of the thread that pairs and kicks them ([`super::team`]).
            let ranges = &self.blocks.drift_by_thread();
            let parts: Vec<_> = split_at_ranges(&mut kin, ranges)
                .into_iter()
                .zip(split_at_ranges(&mut spin, ranges))
                .collect();
            for_each_part(parts, |k, (kin, spin)| {
                drift.run(ranges[k].start, kin, spin)
            })
            .into_iter()
            .fold((TopTwo::default(), TopTwo::default()), |(a, b), (c, d)| {
                (a.merge(c), b.merge(d))
            })
        } else {
            drift.run(0, &mut kin, &mut spin)
        };
        (self.kin, self.spin) = (kin, spin);
        report.counters.integrate += t.elapsed();
        moved
    }

    /// Stage 3: the lists rebuilt if the displacements `moved` since the build may have let a pair in.
    pub(super) fn lists(&mut self, moved: (TopTwo, TopTwo), report: &mut StepReport) {
        let t = Instant::now();
        if self.list.is_stale(moved.0, moved.1, &self.planes) {
            let parallel = self.parallel_bodies();
            let old_walls = self.params.energy_ledger.then(|| OldWalls::of(&self.list));
            let centres: Vec<Point> = self.kin.iter().map(|k| k.position).collect();
            self.list.rebuild(
                &centres,
                &self.props,
                &self.planes,
                parallel,
                self.step_index,
                &|_, _| None,
            );
            if let Some(old) = &old_walls {
                self.pair_ledger.carry(&mut self.list, Some(old), None);
            }
            self.prepare_pairs(parallel);
            report.counters.broad_rebuilds += 1;
        }
        report.counters.broad += t.elapsed();
    }

    /// What the stage-6 sums read of the lists.
    pub(super) fn rows(&self) -> Rows<'_> {
        let list = &self.list;
        Rows {
            row_start: &list.row_start,
            as_b_start: &list.as_b_start,
            as_b: &list.as_b,
            wall_start: &list.wall_start,
            in_contact: &list.in_contact,
            wall_in_contact: &list.wall_in_contact,
        }
    }

    /// Stages 6–8 (on the team when the pair loop ran on it): every sphere's loads not summed by the
    /// pair loop (all of them unless `scattered`), second half kick, checks; the first non-finite
    /// quantity, if any.
    fn kick(&mut self, dt: Real, scattered: bool) -> Option<(usize, &'static str)> {
        let team = self.parallel_bodies() && self.blocks.team();
        let (mut force, mut torque) = (
            std::mem::take(&mut self.force),
            std::mem::take(&mut self.torque),
        );
        let (mut kin, mut spin) = (
            std::mem::take(&mut self.kin),
            std::mem::take(&mut self.spin),
        );
        let kick = Kick {
            rows: self.rows(),
            out: &self.out,
            wall_out: &self.wall_out,
            gathered: &self.blocks.gathered,
            scattered,
            props: &self.props,
            gravity: self.gravity,
            dt,
            v3: self.v3,
        };
        let non_finite = if team {
            let ranges = &self.blocks.kick_by_thread();
            let parts: Vec<_> = split_at_ranges(&mut force, ranges)
                .into_iter()
                .zip(split_at_ranges(&mut torque, ranges))
                .zip(split_at_ranges(&mut kin, ranges))
                .zip(split_at_ranges(&mut spin, ranges))
                .collect();
            for_each_part(parts, |k, (((force, torque), kin), spin)| {
                let part = KickPart {
                    force,
                    torque,
                    kin,
                    spin,
                };
                kick.run(ranges[k].start, part)
            })
            .into_iter()
            .flatten()
            .next()
        } else {
            let part = KickPart {
                force: &mut force,
                torque: &mut torque,
                kin: &mut kin,
                spin: &mut spin,
            };
            kick.run(0, part)
        };
        (self.force, self.torque, self.kin, self.spin) = (force, torque, kin, spin);
        non_finite
    }

    /// The blocks of the pair loop for the current lists and pool (made anew after a build of the lists
    /// or a change of the pool), and the outputs sized for the lists.
    pub(super) fn ready_blocks(&mut self) {
        let n_pairs = self.list.body_pairs() + self.list.wall_pairs();
        let parallel = rayon::current_num_threads() > 1 && n_pairs >= MIN_PARALLEL_PAIRS;
        let wanted = if parallel {
            rayon::current_num_threads()
        } else {
            1
        };
        if self.blocks.built_for != (self.list.builds(), wanted) {
            let speeds = self.speeds.estimate(wanted);
            self.blocks = Blocks::new(&self.list, wanted, &self.split, &speeds);
        }
        self.out.resize(self.list.body_pairs(), PairOut::default());
        self.wall_out
            .resize(self.list.wall_pairs(), PairOut::default());
    }

    /// Stages 4–5 at the current positions with the tangential increment's time `dt`: every listed pair's
    /// output and spring, and the loads of every sphere the pair loop can sum itself (see
    /// [`Blocks`]): the others' are gathered by stage 6.
    pub(super) fn evaluate(&mut self, dt: Real) -> Result<Found, StepError> {
        self.ready_blocks();
        let fraction = self.params.overlap_warning_fraction;
        let ctx = PairContext {
            kin: &self.kin,
            props: &self.props,
            walls: &self.planes,
            dt,
            step_index: self.step_index,
        };
        let blocks = &self.blocks;
        let list = &mut self.list;
        let pass = PairBlocks {
            ctx,
            a: &list.a,
            b: &list.b,
            row_start: &list.row_start,
            wall_start: &list.wall_start,
            wall_body: &list.wall_body,
            wall_of: &list.wall_of,
            reach: &self.reach,
            constants: &self.pair_constants,
            wall_constants: &self.wall_constants,
            gathered: &blocks.gathered,
            fraction,
            v3: self.v3,
            ledger: self.params.energy_ledger,
        };
        let pl = &mut self.pair_ledger;
        let one_block = blocks.bodies.len() == 1;
        // One block visits the pairs in pair order, so it sums the ledger's terms itself.
        let ledger = LedgerPart::whole(pl, one_block);
        let whole = BlockPart {
            histories: &mut list.histories,
            in_contact: &mut list.in_contact,
            outs: &mut self.out,
            wall_histories: &mut list.wall_histories,
            wall_in_contact: &mut list.wall_in_contact,
            wall_outs: &mut self.wall_out,
            force: &mut self.force,
            torque: &mut self.torque,
            ledger,
        };
        if one_block {
            // One block of every sphere: the same pass without the test of which spheres it sums.
            let found = pass.run_all(whole);
            pl.summed = Some(found.work);
            self.outs_valid = true;
            // The wall warnings join the list here too: a step on one block reports its overlap
            // warnings against walls like any other.
            return found.finish();
        }
        let found = run_blocks(&pass, blocks, whole);
        self.outs_valid = true;
        found.finish()
    }

    /// Stage 6 alone (the evaluation of an initial state): every sphere's sums (unless the pair loop
    /// `scattered` them), the walls'.
    pub(super) fn gather_only(&mut self, scattered: bool) {
        for i in 0..self.kin.len() {
            if !scattered || self.blocks.gathered.get(i).copied().unwrap_or(false) {
                let (f, t) = self.rows().sum_body(&self.out, &self.wall_out, i);
                self.force[i] = f;
                self.torque[i] = t;
            }
        }
        self.sum_walls();
    }

    /// The force on each wall, in pair order (bodies by increasing index), and the power the walls
    /// deliver.
    fn sum_walls(&mut self) {
        let list = &self.list;
        self.external_power = wall_sums(
            &self.wall_out,
            &list.wall_in_contact,
            &list.wall_of,
            &self.walls,
            &mut self.wall_forces,
        );
    }
}

/// The pair loop on several blocks: every array split at the boundaries of the blocks and middles
/// ([`Blocks::segments`]); thread k runs block k, then the middle after it (the whole middle: no
/// sharing out when the passes run one by one). What each segment found, merged in segment order.
fn run_blocks(pass: &PairBlocks<'_>, blocks: &Blocks, mut whole: BlockPart<'_>) -> Found {
    let mut parts: Vec<Vec<(usize, BlockPart)>> =
        blocks.bodies.iter().map(|_| Vec::new()).collect();
    let mut thread = 0;
    for (s, range) in blocks.segments().enumerate() {
        let (first, last) = (range.start, range.end);
        let pairs = (pass.row_start[last] - pass.row_start[first]) as usize;
        let walls = (pass.wall_start[last] - pass.wall_start[first]) as usize;
        parts[thread].push((first, whole.split_front(pairs, walls, last - first)));
        // Segments alternate block, middle: a middle closes its thread's list.
        thread += s % 2;
    }
    let run = |segments: Vec<(usize, BlockPart)>| {
        segments
            .into_iter()
            .map(|(first, part)| pass.run(first, part))
            .fold(Found::default(), Found::merge)
    };
    if parts.len() > 1 && rayon::current_num_threads() > 1 {
        for_each_part(parts, |_, segments| run(segments))
            .into_iter()
            .fold(Found::default(), Found::merge)
    } else {
        parts
            .into_iter()
            .map(run)
            .fold(Found::default(), Found::merge)
    }
}
