//! One step of the flat sphere path, stage by stage (the stages of `super::super::sphere_step`):
//!
//! ```text
//!  1–2. first half kick, drift, turn; ω = L/J and the displacement since the build   (per sphere)
//!       walls moved by Δt times their velocity
//!  3.   lists rebuilt if the two largest displacements sum to the skin                (rows per sphere)
//!  4–5. pair loop: geometry and law of every listed pair and body–wall pair            (per pair)
//!  6–8. per-sphere sums in key order, second half kick, finiteness check               (per sphere)
//!  9.   wall forces and the walls' power (serial, pair order), ledger, time
//! ```
//! Every per-sphere and per-pair pass writes only its own items' slots, so it runs on rayon's current
//! pool with the same bits for any number of threads: each thread always takes the same part of each
//! pass ([`super::team`]), so that a block's records stay in one core's cache from pass to pass. The pair
//! loop runs in blocks of consecutive spheres ([`Blocks`]: one when serial, one per thread otherwise)
//! and adds each overlapping
//! pair's loads to its spheres as it goes, for every sphere that only its own block's pairs reach: in
//! pair order such a sphere i receives its pairs (a, i) by increasing a (rows of a < i come first), then
//! its own row (i, b) by increasing b, then its walls — the gather's order, so the same sums, bit for
//! bit. Stage 6 gathers the loads of the other spheres (reached by a pair of an earlier block).

use std::time::Instant;

use crate::dynamics::rotation::drift_isotropic;
use crate::law::TangentialHistory;
use crate::math::{Point, Real, Vector};

use super::super::step::{
    first_non_finite, maybe_non_finite, OverlapWarning, StepError, StepReport,
};
use super::super::ContactKey;
use super::neighbours::TopTwo;
use super::pair::{Kinematic, PairContext, PairOut, WallPlane};
use super::team::{for_each_part, split_at_ranges};
use super::{SphereSim, Spin, MIN_PARALLEL_PAIRS};

/// What the pair loop found, summed over its blocks in pair order.
#[derive(Default)]
pub(super) struct Found {
    /// Whether the pair loop summed the loads of the spheres it could (see [`Blocks`]).
    pub(super) scattered: bool,
    contacts: usize,
    max_overlap_ratio: Real,
    /// Warnings of body pairs, then of wall pairs (each in pair order).
    warnings: Vec<OverlapWarning>,
    wall_warnings: Vec<OverlapWarning>,
    /// The first error of a body pair, and of a wall pair.
    error: Option<StepError>,
    wall_error: Option<StepError>,
}

impl Found {
    /// The error to report (a body pair's before a wall pair's), else what was found, with the warnings
    /// of body pairs then of wall pairs as one list (the general step's key order).
    fn finish(mut self) -> Result<Found, StepError> {
        if let Some(e) = self.error.take().or(self.wall_error.take()) {
            return Err(e);
        }
        let wall_warnings = std::mem::take(&mut self.wall_warnings);
        self.warnings.extend(wall_warnings);
        Ok(self)
    }

    fn merge(mut self, other: Found) -> Found {
        self.scattered |= other.scattered;
        self.contacts += other.contacts;
        self.max_overlap_ratio = self.max_overlap_ratio.max(other.max_overlap_ratio);
        self.warnings.extend(other.warnings);
        self.wall_warnings.extend(other.wall_warnings);
        if self.error.is_none() {
            self.error = other.error;
        }
        if self.wall_error.is_none() {
            self.wall_error = other.wall_error;
        }
        self
    }
}

/// The split of the pair loop into blocks of consecutive spheres, one per thread, each with the pairs of
/// its spheres' rows and their walls, of about equal work: pairs weighted by whether they are in contact
/// ([`CONTACT_WEIGHT`]; before 2026-11-22 (night), equal numbers of pairs). With the split of the
/// per-sphere passes ([`Blocks::kick`], [`Blocks::drift`]) it is what each thread of the team takes
/// ([`super::team`]).
///
/// One block per thread, no more: a sphere reached by a pair of another block has its loads gathered
/// in stage 6 instead of summed by the pair loop (on the settled bed of the sphere-bed scenes, whose
/// spheres are numbered by height, about 5 % of the spheres with 2 blocks, 15 % with 4, 35 % with 8;
/// counted on its initial list), and the team gives each thread its parts statically, so more blocks
/// would not balance the threads (until 2026-11-22 (late) rayon shared two blocks per thread by work
/// stealing).
///
/// A block's pairs come in pair order, so a sphere all of whose pairs lie in its own block receives
/// its loads in the order of the stage-6 gather (pairs (a, i) by increasing a, its row, its walls): the
/// block sums them as it goes, the same bits as the gather. A sphere that a pair of an earlier block
/// reaches (`gathered`) is left to the gather, whose order the blocks cannot keep.
#[derive(Clone, Debug, Default)]
pub(super) struct Blocks {
    /// The lists' build and the number of blocks wanted that these blocks were made for.
    pub(super) built_for: (u64, usize),
    pub(super) bodies: Vec<std::ops::Range<usize>>,
    /// Per sphere, whether a pair of another block reaches it.
    pub(super) gathered: Vec<bool>,
    /// The spheres of each thread in the second half kick (balanced with the gathered spheres' sums)
    /// and in the drift (equal numbers).
    pub(super) kick: Vec<std::ops::Range<usize>>,
    pub(super) drift: Vec<std::ops::Range<usize>>,
}

impl Blocks {
    /// Whether the per-sphere passes run on the team (several blocks).
    pub(super) fn team(&self) -> bool {
        self.bodies.len() > 1
    }

    pub(super) fn new(list: &super::NeighbourList, wanted: usize) -> Self {
        let n = list.row_start.len().saturating_sub(1);
        if wanted <= 1 {
            // One block of every sphere (the serial loop): no weights to form, no sphere gathered.
            return Self {
                built_for: (list.builds(), wanted),
                bodies: std::iter::once(0..n).collect(),
                gathered: vec![false; n],
                kick: std::iter::once(0..n).collect(),
                drift: std::iter::once(0..n).collect(),
            };
        }
        // Per sphere: its row's pairs and its walls, a pair in contact counting CONTACT_WEIGHT, plus
        // one for the sphere itself.
        let cost = |histories: &[TangentialHistory]| -> usize {
            histories
                .iter()
                .map(|h| if h.is_cleared() { 1 } else { CONTACT_WEIGHT })
                .sum()
        };
        let weights: Vec<usize> = (0..n)
            .map(|i| {
                let (r0, r1) = (list.row_start[i] as usize, list.row_start[i + 1] as usize);
                let (w0, w1) = (list.wall_start[i] as usize, list.wall_start[i + 1] as usize);
                cost(&list.histories[r0..r1]) + cost(&list.wall_histories[w0..w1]) + 1
            })
            .collect();
        let bodies = ranges_of_equal_weight(&weights, wanted);
        let mut gathered = vec![false; n];
        if bodies.len() > 1 {
            for range in &bodies {
                for j in range.clone() {
                    let (s, e) = (list.as_b_start[j] as usize, list.as_b_start[j + 1] as usize);
                    // Side-B pairs come by increasing a: the first has the smallest.
                    gathered[j] = s < e && (list.a[list.as_b[s] as usize] as usize) < range.start;
                }
            }
        }
        // The kick: a gathered sphere also sums its pairs, which took about two kicks' time (per-thread
        // timestamps on bed c, 2026-11-22 (late): with the pair blocks' split the thread of the second
        // block, ~1700 spheres of which ~160 gathered, kicked in ~21 µs against ~13 µs for ~1300).
        let kick_weights: Vec<usize> = gathered.iter().map(|&g| 1 + 2 * usize::from(g)).collect();
        let kick = ranges_of_equal_weight(&kick_weights, bodies.len());
        let parts = bodies.len();
        let drift = (0..parts)
            .map(|k| k * n / parts..(k + 1) * n / parts)
            .collect();
        Self {
            built_for: (list.builds(), wanted),
            bodies,
            gathered,
            kick,
            drift,
        }
    }
}

/// Consecutive ranges of `weights`' indices, at most `wanted`, each of about the same total weight (the
/// last takes the rest).
fn ranges_of_equal_weight(weights: &[usize], wanted: usize) -> Vec<std::ops::Range<usize>> {
    let n = weights.len();
    let total: usize = weights.iter().sum();
    let target = total.div_ceil(wanted.max(1)).max(1);
    let mut ranges = Vec::with_capacity(wanted);
    let (mut first, mut weight) = (0, 0);
    for (i, w) in weights.iter().enumerate() {
        weight += w;
        if weight >= target && i + 1 < n {
            ranges.push(first..i + 1);
            (first, weight) = (i + 1, 0);
        }
    }
    ranges.push(first..n);
    ranges
}

/// A listed pair's weight in the split into blocks when its spring holds a contact at the build (such a
/// pair mostly stays in contact until the next build), against 1 for one that does not: the law costs
/// several times the distance test, and the contacts crowd where the projectile strikes and at the
/// floor, so blocks of equal pair counts are not blocks of equal work. 8 is the best of 1, 4, 6, 8, 12
/// and 16 measured on the sphere beds a–c on two threads (`examples/sphere_flat_threads`, medians of 4–5
/// runs, 2026-11-22: 1.43 / 1.67 / 1.43× over one thread with 1, 1.79 / 1.79 / 1.63× with 8); the
/// 10^4-sphere settling scene came out slightly slower (medians 1.39–1.51× against 1.51–1.57×, not
/// understood). A frictionless law keeps no spring, so its pairs all weigh 1, as before.
const CONTACT_WEIGHT: usize = 8;

/// The slices of one block.
struct BlockPart<'a> {
    histories: &'a mut [TangentialHistory],
    in_contact: &'a mut [bool],
    outs: &'a mut [PairOut],
    wall_histories: &'a mut [TangentialHistory],
    wall_in_contact: &'a mut [bool],
    wall_outs: &'a mut [PairOut],
    force: &'a mut [Vector],
    torque: &'a mut [Vector],
}

impl SphereSim {
    /// Advances the simulation by one step (see the module docs).
    pub fn step(&mut self) -> Result<StepReport, StepError> {
        let dt = self.params.dt;
        if !(dt.is_finite() && dt > 0.0) {
            return Err(StepError::InvalidTimeStep {
                step: self.step_index,
                dt,
            });
        }
        let mut report = StepReport::default();
        let external_start = self.external_power;
        let parallel = self.parallel_bodies();
        // The per-sphere passes run on the team when the pair loop does (its blocks of the last build).
        let team = parallel && self.blocks.team();

        // 1–2. First half kick, drift, turn.
        let t = Instant::now();
        let h = 0.5 * dt;
        let (props, force, torque) = (&self.props, &self.force, &self.torque);
        // No global viscous damping on this path (`SphereSim::from_world` refuses it), so the kicks leave
        // out the general step's damping terms: with c = 0 they are exact no-ops here (x − (0/m)·v = x
        // because a force summed from +0.0 is never −0.0, and x / (1 + h·0/m) = x), and they cost five of
        // the fourteen divisions per sphere and step.
        debug_assert_eq!(self.params.damping, crate::dynamics::ViscousDamping::None);
        let (gravity, form) = (self.gravity, self.form);
        let track_orientation = self.track_orientation;
        let at_build = &self.list.centres_at_build;
        let large_flags = &self.list.large_flags;
        let (top, large) = {
            let spin = &mut self.spin;
            let drift = |start: usize, kin: &mut [Kinematic], spin: &mut [Spin]| {
                let (mut top, mut large) = (TopTwo::default(), TopTwo::default());
                for (k, (kin, spin)) in kin.iter_mut().zip(spin.iter_mut()).enumerate() {
                    let i = start + k;
                    let p = &props[i];
                    kin.velocity += h * (force[i] / p.mass + gravity);
                    spin.angular_momentum += h * torque[i];
                    kin.position += dt * kin.velocity;
                    if track_orientation && spin.angular_momentum != Vector::zeros() {
                        drift_isotropic(
                            form,
                            &mut spin.orientation,
                            &spin.angular_momentum,
                            p.moment,
                            dt,
                        );
                    }
                    kin.omega = spin.angular_momentum / p.moment;
                    let moved = (kin.position - at_build[i]).norm_squared();
                    if large_flags[i] {
                        large.push(moved);
                    } else {
                        top.push(moved);
                    }
                }
                (top, large)
            };
            if team {
                // About the spheres of the thread that pairs and kicks them ([`super::team`]).
                let ranges = &self.blocks.drift;
                let parts: Vec<_> = split_at_ranges(&mut self.kin, ranges)
                    .into_iter()
                    .zip(split_at_ranges(spin, ranges))
                    .collect();
                for_each_part(parts, |k, (kin, spin)| drift(ranges[k].start, kin, spin))
                    .into_iter()
                    .fold((TopTwo::default(), TopTwo::default()), |(a, b), (c, d)| {
                        (a.merge(c), b.merge(d))
                    })
            } else {
                drift(0, &mut self.kin, spin)
            }
        };
        for (wall, plane) in self.walls.iter_mut().zip(&mut self.planes) {
            wall.pose.translation.vector += dt * wall.velocity;
            *plane = WallPlane::of(wall);
        }
        report.counters.integrate += t.elapsed();

        // 3. Lists.
        let t = Instant::now();
        if self.list.is_stale(top, large, &self.planes) {
            let centres: Vec<Point> = self.kin.iter().map(|k| k.position).collect();
            self.list.rebuild(
                &centres,
                &self.props,
                &self.planes,
                parallel,
                self.step_index,
                &|_, _| None,
            );
            self.prepare_pairs(parallel);
            report.counters.broad_rebuilds += 1;
        }
        report.counters.body_pairs_tested += self.list.body_pairs() as u64;
        report.counters.wall_pairs_tested += self.list.wall_pairs() as u64;
        report.counters.broad += t.elapsed();

        // 4–5. Pair loop.
        let t = Instant::now();
        let found = self.evaluate(dt)?;
        let scattered = found.scattered;
        report.contacts = found.contacts;
        report.max_overlap_ratio = found.max_overlap_ratio;
        report.overlap_warnings = found.warnings;
        report.counters.contacts += found.contacts as u64;
        report.counters.narrow += t.elapsed();

        // 6–8. Per-sphere sums, second half kick, checks.
        let t = Instant::now();
        let team = parallel && self.blocks.team();
        let non_finite = {
            let (list, out, wall_out) = (&self.list, &self.out, &self.wall_out);
            let gathered = &self.blocks.gathered;
            let props = &self.props;
            let kin = &mut self.kin;
            let spin = &mut self.spin;
            let kick = |start: usize,
                        force: &mut [Vector],
                        torque: &mut [Vector],
                        kin: &mut [Kinematic],
                        spin: &mut [Spin]|
             -> Option<(usize, &'static str)> {
                for k in 0..force.len() {
                    let i = start + k;
                    let (f, t) = if scattered && !gathered.get(i).copied().unwrap_or(false) {
                        (force[k], torque[k])
                    } else {
                        let (f, t) = sum_body(list, out, wall_out, i);
                        force[k] = f;
                        torque[k] = t;
                        (f, t)
                    };
                    let p = &props[i];
                    let (kin, spin) = (&mut kin[k], &mut spin[k]);
                    kin.velocity += h * (f / p.mass + gravity);
                    spin.angular_momentum += h * t;
                    let maybe = maybe_non_finite(
                        &f,
                        &t,
                        &kin.position,
                        &kin.velocity,
                        &spin.orientation,
                        &spin.angular_momentum,
                    );
                    if maybe {
                        if let Some(q) = non_finite_quantity(&f, &t, kin, spin) {
                            return Some((i, q));
                        }
                    }
                }
                None
            };
            if team {
                let ranges = &self.blocks.kick;
                let parts: Vec<_> = split_at_ranges(&mut self.force, ranges)
                    .into_iter()
                    .zip(split_at_ranges(&mut self.torque, ranges))
                    .zip(split_at_ranges(kin, ranges))
                    .zip(split_at_ranges(spin, ranges))
                    .collect();
                for_each_part(parts, |k, (((f, t), kin), spin)| {
                    kick(ranges[k].start, f, t, kin, spin)
                })
                .into_iter()
                .flatten()
                .next()
            } else {
                kick(0, &mut self.force, &mut self.torque, kin, spin)
            }
        };
        report.counters.integrate += t.elapsed();
        if let Some((body, quantity)) = non_finite {
            return Err(StepError::NonFinite {
                step: self.step_index + 1,
                body,
                name: self.names[body].clone(),
                quantity,
            });
        }

        // 9. Walls, ledger, time.
        let t = Instant::now();
        self.sum_walls();
        report.counters.accumulate += t.elapsed();
        self.ledger.external_work += 0.5 * (external_start + self.external_power) * dt;
        self.time += dt;
        self.step_index += 1;
        report.counters.steps = 1;
        Ok(report)
    }

    /// Stages 4–5 at the current positions with the tangential increment's time `dt`: every listed pair's
    /// output and spring, and the loads of every sphere the pair loop can sum itself (see
    /// [`Blocks`]): the others' are gathered by stage 6.
    pub(super) fn evaluate(&mut self, dt: Real) -> Result<Found, StepError> {
        let n_pairs = self.list.body_pairs() + self.list.wall_pairs();
        let parallel = rayon::current_num_threads() > 1 && n_pairs >= MIN_PARALLEL_PAIRS;
        let wanted = if parallel {
            rayon::current_num_threads()
        } else {
            1
        };
        if self.blocks.built_for != (self.list.builds(), wanted) {
            self.blocks = Blocks::new(&self.list, wanted);
        }
        self.out.resize(self.list.body_pairs(), PairOut::default());
        self.wall_out
            .resize(self.list.wall_pairs(), PairOut::default());
        let ctx = PairContext {
            kin: &self.kin,
            props: &self.props,
            walls: &self.planes,
            dt,
            step_index: self.step_index,
        };
        let (reach, constants, wall_constants) =
            (&self.reach, &self.pair_constants, &self.wall_constants);
        let fraction = self.params.overlap_warning_fraction;
        let blocks = &self.blocks;
        let gathered = &blocks.gathered;
        let list = &mut self.list;
        let (a, b) = (&list.a, &list.b);
        let (row_start, wall_start) = (&list.row_start, &list.wall_start);
        let (wall_body, wall_of) = (&list.wall_body, &list.wall_of);
        let note = |found: &mut Found, o: &PairOut, ratio: Real, key: ContactKey, wall: bool| {
            found.contacts += 1;
            found.max_overlap_ratio = found.max_overlap_ratio.max(ratio);
            if ratio > fraction {
                let warning = OverlapWarning {
                    key,
                    depth: o.depth,
                    ratio,
                };
                if wall {
                    found.wall_warnings.push(warning);
                } else {
                    found.warnings.push(warning);
                }
            }
        };
        if blocks.bodies.len() == 1 {
            // One block of every sphere: the same pass without the test of which spheres it sums.
            let (force, torque) = (&mut self.force, &mut self.torque);
            force.fill(Vector::zeros());
            torque.fill(Vector::zeros());
            let mut found = Found {
                scattered: true,
                ..Found::default()
            };
            let pairs = list.histories.iter_mut().zip(&mut list.in_contact);
            for (p, ((history, in_contact), out)) in pairs.zip(&mut self.out).enumerate() {
                let (i, j) = (a[p] as usize, b[p] as usize);
                match ctx.body_pair(i, j, reach[p], &constants[p], history, in_contact, out) {
                    Ok(None) => {}
                    Ok(Some(ratio)) => {
                        force[i] -= out.force_on_b;
                        torque[i] += out.torque_on_a;
                        force[j] += out.force_on_b;
                        torque[j] += out.torque_on_b;
                        let key = ContactKey::Body { a: a[p], b: b[p] };
                        note(&mut found, out, ratio, key, false);
                    }
                    Err(e) => {
                        found.error = Some(e);
                        break;
                    }
                }
            }
            if found.error.is_none() {
                let pairs = list
                    .wall_histories
                    .iter_mut()
                    .zip(&mut list.wall_in_contact);
                for (q, ((history, in_contact), out)) in pairs.zip(&mut self.wall_out).enumerate() {
                    let (body, wall) = (wall_body[q], wall_of[q]);
                    let (i, c) = (body as usize, &wall_constants[q]);
                    match ctx.wall_pair(wall as usize, i, c, history, in_contact, out) {
                        Ok(None) => {}
                        Ok(Some(ratio)) => {
                            force[i] += out.force_on_b;
                            torque[i] += out.torque_on_b;
                            let key = ContactKey::Wall { body, wall };
                            note(&mut found, out, ratio, key, true);
                        }
                        Err(e) => {
                            found.error = Some(e);
                            break;
                        }
                    }
                }
            }
            self.outs_valid = true;
            // Before 2026-11-22 (evening) this returned without joining the wall warnings to the list: a step on
            // one block reported no overlap warning against a wall.
            return found.finish();
        }
        // One block: bodies `first..first + force.len()`, their rows of pairs and their walls, in pair
        // order; the loads of every body of the block that no other block's pair reaches are summed here.
        let block = |first: usize, part: BlockPart<'_>| -> Found {
            let BlockPart {
                histories,
                in_contact,
                outs,
                wall_histories,
                wall_in_contact,
                wall_outs,
                force,
                torque,
            } = part;
            let end = first + force.len();
            let (p0, q0) = (row_start[first] as usize, wall_start[first] as usize);
            let mut found = Found {
                scattered: true,
                ..Found::default()
            };
            force.fill(Vector::zeros());
            torque.fill(Vector::zeros());
            let own = |j: usize| j < end && !gathered.get(j).copied().unwrap_or(false);
            let pairs = histories.iter_mut().zip(in_contact.iter_mut());
            for (k, ((history, in_contact), out)) in pairs.zip(outs.iter_mut()).enumerate() {
                let p = p0 + k;
                let (i, j) = (a[p] as usize, b[p] as usize);
                match ctx.body_pair(i, j, reach[p], &constants[p], history, in_contact, out) {
                    Ok(None) => {}
                    Ok(Some(ratio)) => {
                        if own(i) {
                            force[i - first] -= out.force_on_b;
                            torque[i - first] += out.torque_on_a;
                        }
                        if own(j) {
                            force[j - first] += out.force_on_b;
                            torque[j - first] += out.torque_on_b;
                        }
                        let key = ContactKey::Body { a: a[p], b: b[p] };
                        note(&mut found, out, ratio, key, false);
                    }
                    Err(e) => {
                        found.error = Some(e);
                        return found;
                    }
                }
            }
            let pairs = wall_histories.iter_mut().zip(wall_in_contact.iter_mut());
            for (k, ((history, in_contact), out)) in pairs.zip(wall_outs.iter_mut()).enumerate() {
                let q = q0 + k;
                let (body, wall) = (wall_body[q], wall_of[q]);
                let (i, c) = (body as usize, &wall_constants[q]);
                match ctx.wall_pair(wall as usize, i, c, history, in_contact, out) {
                    Ok(None) => {}
                    Ok(Some(ratio)) => {
                        if own(i) {
                            force[i - first] += out.force_on_b;
                            torque[i - first] += out.torque_on_b;
                        }
                        let key = ContactKey::Wall { body, wall };
                        note(&mut found, out, ratio, key, true);
                    }
                    Err(e) => {
                        found.wall_error = Some(e);
                        return found;
                    }
                }
            }
            found
        };
        // Split every array at the blocks' boundaries.
        let mut parts = Vec::with_capacity(blocks.bodies.len());
        {
            let (mut h, mut c, mut o) = (
                &mut list.histories[..],
                &mut list.in_contact[..],
                &mut self.out[..],
            );
            let (mut wh, mut wc, mut wo) = (
                &mut list.wall_histories[..],
                &mut list.wall_in_contact[..],
                &mut self.wall_out[..],
            );
            let (mut f, mut t) = (&mut self.force[..], &mut self.torque[..]);
            for range in &blocks.bodies {
                let (first, last) = (range.start, range.end);
                let pairs = (row_start[last] - row_start[first]) as usize;
                let walls = (wall_start[last] - wall_start[first]) as usize;
                let (h1, h2) = std::mem::take(&mut h).split_at_mut(pairs);
                let (c1, c2) = std::mem::take(&mut c).split_at_mut(pairs);
                let (o1, o2) = std::mem::take(&mut o).split_at_mut(pairs);
                let (wh1, wh2) = std::mem::take(&mut wh).split_at_mut(walls);
                let (wc1, wc2) = std::mem::take(&mut wc).split_at_mut(walls);
                let (wo1, wo2) = std::mem::take(&mut wo).split_at_mut(walls);
                let (f1, f2) = std::mem::take(&mut f).split_at_mut(last - first);
                let (t1, t2) = std::mem::take(&mut t).split_at_mut(last - first);
                (h, c, o, wh, wc, wo, f, t) = (h2, c2, o2, wh2, wc2, wo2, f2, t2);
                parts.push((
                    first,
                    BlockPart {
                        histories: h1,
                        in_contact: c1,
                        outs: o1,
                        wall_histories: wh1,
                        wall_in_contact: wc1,
                        wall_outs: wo1,
                        force: f1,
                        torque: t1,
                    },
                ));
            }
        }
        let found = if parallel && parts.len() > 1 {
            for_each_part(parts, |_, (first, part)| block(first, part))
                .into_iter()
                .fold(Found::default(), Found::merge)
        } else {
            parts
                .into_iter()
                .map(|(first, part)| block(first, part))
                .fold(Found::default(), Found::merge)
        };
        self.outs_valid = true;
        found.finish()
    }

    /// Stage 6 alone (the evaluation of an initial state): every sphere's sums (unless the pair loop
    /// `scattered` them), the walls'.
    pub(super) fn gather_only(&mut self, scattered: bool) {
        let (list, out, wall_out) = (&self.list, &self.out, &self.wall_out);
        for i in 0..self.kin.len() {
            if !scattered || self.blocks.gathered.get(i).copied().unwrap_or(false) {
                let (f, t) = sum_body(list, out, wall_out, i);
                self.force[i] = f;
                self.torque[i] = t;
            }
        }
        self.sum_walls();
    }

    /// The force on each wall, in pair order (bodies by increasing index), and the power the walls
    /// deliver.
    fn sum_walls(&mut self) {
        for f in &mut self.wall_forces {
            *f = Vector::zeros();
        }
        let list = &self.list;
        for (q, o) in self.wall_out.iter().enumerate() {
            if list.wall_in_contact[q] {
                self.wall_forces[list.wall_of[q] as usize] -= o.force_on_b;
            }
        }
        let mut external_power = 0.0;
        for (w, wall) in self.walls.iter().enumerate() {
            external_power -= self.wall_forces[w].dot(&wall.velocity);
        }
        self.external_power = external_power;
    }
}

/// Stage 6 for sphere `i`: its force and torque summed over its overlapping pairs in key order (pairs
/// (a, i) by increasing a, (i, b) by increasing b, then its walls), as the general step sums them.
#[inline(always)]
fn sum_body(
    list: &super::NeighbourList,
    out: &[PairOut],
    wall_out: &[PairOut],
    i: usize,
) -> (Vector, Vector) {
    let (mut f, mut t) = (Vector::zeros(), Vector::zeros());
    for &p in &list.as_b[list.as_b_start[i] as usize..list.as_b_start[i + 1] as usize] {
        if list.in_contact[p as usize] {
            let o = &out[p as usize];
            f += o.force_on_b;
            t += o.torque_on_b;
        }
    }
    for p in list.row_start[i] as usize..list.row_start[i + 1] as usize {
        if list.in_contact[p] {
            f -= out[p].force_on_b;
            t += out[p].torque_on_a;
        }
    }
    for q in list.wall_start[i] as usize..list.wall_start[i + 1] as usize {
        if list.wall_in_contact[q] {
            f += wall_out[q].force_on_b;
            t += wall_out[q].torque_on_b;
        }
    }
    (f, t)
}

/// The first non-finite quantity of a sphere's loads and state (the general step's order).
fn non_finite_quantity(
    force: &Vector,
    torque: &Vector,
    kin: &Kinematic,
    spin: &Spin,
) -> Option<&'static str> {
    first_non_finite(
        force,
        torque,
        &kin.position,
        &kin.velocity,
        &spin.orientation,
        &spin.angular_momentum,
    )
}
