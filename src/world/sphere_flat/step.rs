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
//! pool in chunks with the same bits for any number of threads. When the pair loop runs serially (one
//! thread, or a small list), it adds each overlapping pair's loads to its two spheres as it goes
//! instead of the gather of stage 6: in pair order, body i receives its pairs (a, i) by increasing a
//! (rows of a < i come first), then its own row (i, b) by increasing b, then its walls — the gather's
//! order, so the same sums, bit for bit.

use std::time::Instant;

use rayon::prelude::*;

use crate::dynamics::rotation::drift_isotropic;
use crate::law::TangentialHistory;
use crate::math::{Point, Real, Vector};

use super::super::step::{first_non_finite, OverlapWarning, StepError, StepReport};
use super::super::ContactKey;
use super::neighbours::{chunk_len, TopTwo};
use super::pair::{Kinematic, PairContext, PairOut, WallPlane};
use super::{SphereSim, Spin, MIN_PARALLEL_PAIRS};

/// What the pair loop found, summed over its chunks in pair order.
#[derive(Default)]
pub(super) struct Found {
    /// Whether the loads of every sphere were summed by the pair loop itself (serial pass).
    pub(super) scattered: bool,
    contacts: usize,
    max_overlap_ratio: Real,
    warnings: Vec<OverlapWarning>,
    error: Option<StepError>,
}

impl Found {
    fn merge(mut self, other: Found) -> Found {
        self.scattered |= other.scattered;
        self.contacts += other.contacts;
        self.max_overlap_ratio = self.max_overlap_ratio.max(other.max_overlap_ratio);
        self.warnings.extend(other.warnings);
        if self.error.is_none() {
            self.error = other.error;
        }
        self
    }
}

/// Runs `f` on aligned chunks of `a` and `b` (one chunk when not `parallel`), with the index of the
/// chunk's first item, and merges the chunks' results in chunk order.
fn chunked2<A, B, R>(
    parallel: bool,
    a: &mut [A],
    b: &mut [B],
    f: impl Fn(usize, &mut [A], &mut [B]) -> R + Sync + Send,
    merge: impl Fn(R, R) -> R,
    empty: R,
) -> R
where
    A: Send,
    B: Send,
    R: Send,
{
    if !parallel {
        return merge(empty, f(0, a, b));
    }
    let chunk = chunk_len(a.len(), parallel);
    let parts: Vec<R> = a
        .par_chunks_mut(chunk)
        .zip(b.par_chunks_mut(chunk))
        .with_max_len(1)
        .enumerate()
        .map(|(c, (a, b))| f(c * chunk, a, b))
        .collect();
    parts.into_iter().fold(empty, merge)
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

        // 1–2. First half kick, drift, turn.
        let t = Instant::now();
        let h = 0.5 * dt;
        let (props, force, torque) = (&self.props, &self.force, &self.torque);
        let (gravity, damping, form) = (self.gravity, self.params.damping, self.form);
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
                    let c = damping.coefficient(p.mass);
                    kin.velocity += h * (force[i] / p.mass + gravity - (c / p.mass) * kin.velocity);
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
            let chunk = chunk_len(self.kin.len(), parallel);
            if parallel {
                self.kin
                    .par_chunks_mut(chunk)
                    .zip(spin.par_chunks_mut(chunk))
                    .with_max_len(1)
                    .enumerate()
                    .map(|(c, (kin, spin))| drift(c * chunk, kin, spin))
                    .reduce(
                        || (TopTwo::default(), TopTwo::default()),
                        |(a, b), (c, d)| (a.merge(c), b.merge(d)),
                    )
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
        let non_finite = {
            let (list, out, wall_out) = (&self.list, &self.out, &self.wall_out);
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
                    let (f, t) = if scattered {
                        (force[k], torque[k])
                    } else {
                        let (f, t) = sum_body(list, out, wall_out, i);
                        force[k] = f;
                        torque[k] = t;
                        (f, t)
                    };
                    let p = &props[i];
                    let c = damping.coefficient(p.mass);
                    let (kin, spin) = (&mut kin[k], &mut spin[k]);
                    kin.velocity =
                        (kin.velocity + h * (f / p.mass + gravity)) / (1.0 + h * c / p.mass);
                    spin.angular_momentum += h * t;
                    let sum = f.sum()
                        + t.sum()
                        + kin.position.coords.sum()
                        + kin.velocity.sum()
                        + spin.orientation.coords.sum()
                        + spin.angular_momentum.sum();
                    if !sum.is_finite() {
                        if let Some(q) = non_finite_quantity(&f, &t, kin, spin) {
                            return Some((i, q));
                        }
                    }
                }
                None
            };
            let chunk = chunk_len(kin.len(), parallel);
            if parallel {
                self.force
                    .par_chunks_mut(chunk)
                    .zip(self.torque.par_chunks_mut(chunk))
                    .zip(kin.par_chunks_mut(chunk))
                    .zip(spin.par_chunks_mut(chunk))
                    .with_max_len(1)
                    .enumerate()
                    .map(|(c, (((f, t), kin), spin))| kick(c * chunk, f, t, kin, spin))
                    .collect::<Vec<_>>()
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
    /// output and spring.
    pub(super) fn evaluate(&mut self, dt: Real) -> Result<Found, StepError> {
        let n_pairs = self.list.body_pairs() + self.list.wall_pairs();
        let parallel = rayon::current_num_threads() > 1 && n_pairs >= MIN_PARALLEL_PAIRS;
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
        let list = &mut self.list;
        let (a, b) = (&list.a, &list.b);
        let (wall_body, wall_of) = (&list.wall_body, &list.wall_of);
        let note = |found: &mut Found, o: &PairOut, key: ContactKey| {
            if o.overlapping {
                found.contacts += 1;
                found.max_overlap_ratio = found.max_overlap_ratio.max(o.overlap_ratio);
                if o.overlap_ratio > fraction {
                    found.warnings.push(OverlapWarning {
                        key,
                        depth: o.depth,
                        ratio: o.overlap_ratio,
                    });
                }
            }
        };
        let body_pass =
            |start: usize, histories: &mut [TangentialHistory], outs: &mut [PairOut]| {
                let mut found = Found::default();
                for (k, (history, out)) in histories.iter_mut().zip(outs.iter_mut()).enumerate() {
                    let p = start + k;
                    if let Err(e) = ctx.body_pair(
                        a[p] as usize,
                        b[p] as usize,
                        reach[p],
                        &constants[p],
                        history,
                        out,
                    ) {
                        found.error = Some(e);
                        break;
                    }
                    note(&mut found, out, ContactKey::Body { a: a[p], b: b[p] });
                }
                found
            };
        let wall_pass =
            |start: usize, histories: &mut [TangentialHistory], outs: &mut [PairOut]| {
                let mut found = Found::default();
                for (k, (history, out)) in histories.iter_mut().zip(outs.iter_mut()).enumerate() {
                    let q = start + k;
                    let (body, wall) = (wall_body[q], wall_of[q]);
                    if let Err(e) =
                        ctx.wall_pair(wall as usize, body as usize, &wall_constants[q], history, out)
                    {
                        found.error = Some(e);
                        break;
                    }
                    note(&mut found, out, ContactKey::Wall { body, wall });
                }
                found
            };
        if !parallel {
            // One pass in pair order that also sums the loads (see the module docs).
            let (force, torque) = (&mut self.force, &mut self.torque);
            force.fill(Vector::zeros());
            torque.fill(Vector::zeros());
            let mut found = Found {
                scattered: true,
                ..Found::default()
            };
            for (p, (history, out)) in list.histories.iter_mut().zip(&mut self.out).enumerate() {
                let (i, j) = (a[p] as usize, b[p] as usize);
                if let Err(e) = ctx.body_pair(i, j, reach[p], &constants[p], history, out) {
                    found.error = Some(e);
                    break;
                }
                if out.overlapping {
                    force[i] -= out.force_on_b;
                    torque[i] += out.torque_on_a;
                    force[j] += out.force_on_b;
                    torque[j] += out.torque_on_b;
                    note(&mut found, out, ContactKey::Body { a: a[p], b: b[p] });
                }
            }
            if found.error.is_none() {
                for (q, (history, out)) in list
                    .wall_histories
                    .iter_mut()
                    .zip(&mut self.wall_out)
                    .enumerate()
                {
                    let (body, wall) = (wall_body[q], wall_of[q]);
                    let (i, w) = (body as usize, wall as usize);
                    if let Err(e) = ctx.wall_pair(w, i, &wall_constants[q], history, out) {
                        found.error = Some(e);
                        break;
                    }
                    if out.overlapping {
                        force[i] += out.force_on_b;
                        torque[i] += out.torque_on_b;
                        note(&mut found, out, ContactKey::Wall { body, wall });
                    }
                }
            }
            self.outs_valid = true;
            return match found.error {
                Some(e) => Err(e),
                None => Ok(found),
            };
        }
        let found = chunked2(
            parallel,
            &mut list.histories,
            &mut self.out,
            body_pass,
            Found::merge,
            Found::default(),
        );
        let found = found.merge(chunked2(
            parallel,
            &mut list.wall_histories,
            &mut self.wall_out,
            wall_pass,
            Found::merge,
            Found::default(),
        ));
        self.outs_valid = true;
        match found.error {
            Some(e) => Err(e),
            None => Ok(found),
        }
    }

    /// Stage 6 alone (the evaluation of an initial state): every sphere's sums (unless the pair loop
    /// `scattered` them), the walls'.
    pub(super) fn gather_only(&mut self, scattered: bool) {
        if !scattered {
            let (list, out, wall_out) = (&self.list, &self.out, &self.wall_out);
            for i in 0..self.kin.len() {
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
        for (q, o) in self.wall_out.iter().enumerate() {
            if o.overlapping {
                self.wall_forces[self.list.wall_of[q] as usize] -= o.force_on_b;
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
        let o = &out[p as usize];
        if o.overlapping {
            f += o.force_on_b;
            t += o.torque_on_b;
        }
    }
    for o in &out[list.row_start[i] as usize..list.row_start[i + 1] as usize] {
        if o.overlapping {
            f -= o.force_on_b;
            t += o.torque_on_a;
        }
    }
    for o in &wall_out[list.wall_start[i] as usize..list.wall_start[i + 1] as usize] {
        if o.overlapping {
            f += o.force_on_b;
            t += o.torque_on_b;
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
