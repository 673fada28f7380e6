//! The three passes of a flat step as functions of one part's inputs: the drift of a range of spheres,
//! the pair loop of a block, the kick of a range of spheres. The step that starts each pass on its own
//! ([`super::step`]) and the step that runs all three in one job of the team ([`super::fused`]) call
//! the same functions, so both give the same bits.

use crate::dynamics::rotation::{drift_isotropic, SubRotation};
use crate::law::TangentialHistory;
use crate::math::{Point, Real, Vector};

use super::super::step::{first_non_finite, OverlapWarning, StepError};
use super::super::ContactKey;
use super::neighbours::TopTwo;
use super::pair::{Kinematic, PairConstants, PairContext, PairOut, Props, WallConstants};
use super::Spin;

/// What the pair loop found, summed over its blocks in pair order.
#[derive(Default)]
pub(super) struct Found {
    /// Whether the pair loop summed the loads of the spheres it could (see [`super::step::Blocks`]).
    pub(super) scattered: bool,
    pub(super) contacts: usize,
    pub(super) max_overlap_ratio: Real,
    /// Warnings of body pairs, then of wall pairs (each in pair order).
    pub(super) warnings: Vec<OverlapWarning>,
    wall_warnings: Vec<OverlapWarning>,
    /// The first error of a body pair, and of a wall pair.
    pub(super) error: Option<StepError>,
    pub(super) wall_error: Option<StepError>,
}

impl Found {
    /// Nothing found yet by a pair loop that sums the loads it can.
    pub(super) fn scattered() -> Found {
        Found {
            scattered: true,
            ..Found::default()
        }
    }

    /// The error to report (a body pair's before a wall pair's), else what was found, with the warnings
    /// of body pairs then of wall pairs as one list (the general step's key order).
    pub(super) fn finish(mut self) -> Result<Found, StepError> {
        if let Some(e) = self.error.take().or(self.wall_error.take()) {
            return Err(e);
        }
        let wall_warnings = std::mem::take(&mut self.wall_warnings);
        self.warnings.extend(wall_warnings);
        Ok(self)
    }

    pub(super) fn merge(mut self, other: Found) -> Found {
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

    pub(super) fn failed(&self) -> bool {
        self.error.is_some() || self.wall_error.is_some()
    }

    /// Counts an overlapping pair with overlap `depth` (m) and `ratio` (over the smaller diameter), and
    /// warns when the ratio passes `fraction`.
    #[inline(always)]
    pub(super) fn note(&mut self, depth: Real, ratio: Real, key: ContactKey, fraction: Real) {
        self.contacts += 1;
        self.max_overlap_ratio = self.max_overlap_ratio.max(ratio);
        if ratio > fraction {
            let warning = OverlapWarning { key, depth, ratio };
            match key {
                ContactKey::Wall { .. } => self.wall_warnings.push(warning),
                ContactKey::Body { .. } => self.warnings.push(warning),
            }
        }
    }
}

/// What the drift reads (the first half kick, the drift and the turn of each sphere).
pub(super) struct Drift<'a> {
    pub(super) props: &'a [Props],
    pub(super) force: &'a [Vector],
    pub(super) torque: &'a [Vector],
    pub(super) at_build: &'a [Point],
    pub(super) large_flags: &'a [bool],
    pub(super) gravity: Vector,
    pub(super) form: SubRotation,
    pub(super) dt: Real,
    pub(super) track_orientation: bool,
}

impl Drift<'_> {
    /// Spheres `start..start + kin.len()`: their half kick, drift and turn; returns the two largest
    /// squared displacements since the build of the small spheres, then of the large ones.
    pub(super) fn run(
        &self,
        start: usize,
        kin: &mut [Kinematic],
        spin: &mut [Spin],
    ) -> (TopTwo, TopTwo) {
        let (dt, h) = (self.dt, 0.5 * self.dt);
        let (mut top, mut large) = (TopTwo::default(), TopTwo::default());
        for (k, (kin, spin)) in kin.iter_mut().zip(spin.iter_mut()).enumerate() {
            let i = start + k;
            let p = &self.props[i];
            kin.velocity += h * (self.force[i] / p.mass + self.gravity);
            spin.angular_momentum += h * self.torque[i];
            kin.position += dt * kin.velocity;
            if self.track_orientation && spin.angular_momentum != Vector::zeros() {
                drift_isotropic(
                    self.form,
                    &mut spin.orientation,
                    &spin.angular_momentum,
                    p.moment,
                    dt,
                );
            }
            kin.omega = spin.angular_momentum / p.moment;
            let moved = (kin.position - self.at_build[i]).norm_squared();
            if self.large_flags[i] {
                large.push(moved);
            } else {
                top.push(moved);
            }
        }
        (top, large)
    }
}

/// The pairs of each sphere in the lists, and which overlapped at the last evaluation: what the
/// stage-6 sum of a sphere reads.
pub(super) struct Rows<'a> {
    pub(super) row_start: &'a [u32],
    pub(super) as_b_start: &'a [u32],
    pub(super) as_b: &'a [u32],
    pub(super) wall_start: &'a [u32],
    pub(super) in_contact: &'a [bool],
    pub(super) wall_in_contact: &'a [bool],
}

impl Rows<'_> {
    /// Stage 6 for sphere `i`: its force and torque summed over its overlapping pairs in key order
    /// (pairs (a, i) by increasing a, (i, b) by increasing b, then its walls), as the general step sums
    /// them.
    #[inline(always)]
    pub(super) fn sum_body(
        &self,
        out: &[PairOut],
        wall_out: &[PairOut],
        i: usize,
    ) -> (Vector, Vector) {
        let (mut f, mut t) = (Vector::zeros(), Vector::zeros());
        for &p in &self.as_b[self.as_b_start[i] as usize..self.as_b_start[i + 1] as usize] {
            if self.in_contact[p as usize] {
                let o = &out[p as usize];
                f += o.force_on_b;
                t += o.torque_on_b;
            }
        }
        let row = self.row_start[i] as usize..self.row_start[i + 1] as usize;
        for (o, &overlapping) in out[row.clone()].iter().zip(&self.in_contact[row]) {
            if overlapping {
                f -= o.force_on_b;
                t += o.torque_on_a;
            }
        }
        let walls = self.wall_start[i] as usize..self.wall_start[i + 1] as usize;
        for (o, &overlapping) in wall_out[walls.clone()]
            .iter()
            .zip(&self.wall_in_contact[walls])
        {
            if overlapping {
                f += o.force_on_b;
                t += o.torque_on_b;
            }
        }
        (f, t)
    }
}

/// What the second half kick reads.
pub(super) struct Kick<'a> {
    pub(super) rows: Rows<'a>,
    pub(super) out: &'a [PairOut],
    pub(super) wall_out: &'a [PairOut],
    /// Per sphere, whether its loads are gathered here (see [`super::step::Blocks`]).
    pub(super) gathered: &'a [bool],
    /// Whether the pair loop summed the loads of the other spheres.
    pub(super) scattered: bool,
    pub(super) props: &'a [Props],
    pub(super) gravity: Vector,
    pub(super) dt: Real,
}

impl Kick<'_> {
    /// Spheres `start..start + force.len()`: their loads (gathered where the pair loop did not sum
    /// them), second half kick and finiteness check; the first non-finite quantity, if any.
    pub(super) fn run(
        &self,
        start: usize,
        force: &mut [Vector],
        torque: &mut [Vector],
        kin: &mut [Kinematic],
        spin: &mut [Spin],
    ) -> Option<(usize, &'static str)> {
        let h = 0.5 * self.dt;
        for k in 0..force.len() {
            let i = start + k;
            let (f, t) = if self.scattered && !self.gathered.get(i).copied().unwrap_or(false) {
                (force[k], torque[k])
            } else {
                let (f, t) = self.rows.sum_body(self.out, self.wall_out, i);
                force[k] = f;
                torque[k] = t;
                (f, t)
            };
            let p = &self.props[i];
            let (kin, spin) = (&mut kin[k], &mut spin[k]);
            kin.velocity += h * (f / p.mass + self.gravity);
            spin.angular_momentum += h * t;
            let quantity = first_non_finite(
                &f,
                &t,
                &kin.position,
                &kin.velocity,
                &spin.orientation,
                &spin.angular_momentum,
            );
            if let Some(q) = quantity {
                return Some((i, q));
            }
        }
        None
    }
}

/// The slices of one block of the pair loop.
pub(super) struct BlockPart<'a> {
    pub(super) histories: &'a mut [TangentialHistory],
    pub(super) in_contact: &'a mut [bool],
    pub(super) outs: &'a mut [PairOut],
    pub(super) wall_histories: &'a mut [TangentialHistory],
    pub(super) wall_in_contact: &'a mut [bool],
    pub(super) wall_outs: &'a mut [PairOut],
    pub(super) force: &'a mut [Vector],
    pub(super) torque: &'a mut [Vector],
}

/// What a block of the pair loop reads.
pub(super) struct PairBlocks<'a> {
    pub(super) ctx: PairContext<'a>,
    pub(super) a: &'a [u32],
    pub(super) b: &'a [u32],
    pub(super) row_start: &'a [u32],
    pub(super) wall_start: &'a [u32],
    pub(super) wall_body: &'a [u32],
    pub(super) wall_of: &'a [u32],
    pub(super) reach: &'a [Real],
    pub(super) constants: &'a [PairConstants],
    pub(super) wall_constants: &'a [WallConstants],
    pub(super) gathered: &'a [bool],
    /// The overlap ratio above which a contact is warned about.
    pub(super) fraction: Real,
}

impl PairBlocks<'_> {
    /// One block: bodies `first..first + part.force.len()`, their rows of pairs and their walls, in
    /// pair order; the loads of every body of the block that no other block's pair reaches are summed
    /// here.
    pub(super) fn run(&self, first: usize, part: BlockPart<'_>) -> Found {
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
        let (p0, q0) = (
            self.row_start[first] as usize,
            self.wall_start[first] as usize,
        );
        let mut found = Found::scattered();
        force.fill(Vector::zeros());
        torque.fill(Vector::zeros());
        let own = |j: usize| j < end && !self.gathered.get(j).copied().unwrap_or(false);
        let ctx = &self.ctx;
        let pairs = histories.iter_mut().zip(in_contact.iter_mut());
        for (k, ((history, in_contact), out)) in pairs.zip(outs.iter_mut()).enumerate() {
            let p = p0 + k;
            let (i, j) = (self.a[p] as usize, self.b[p] as usize);
            let c = &self.constants[p];
            match ctx.body_pair(i, j, self.reach[p], c, history, in_contact, out) {
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
                    let key = ContactKey::Body {
                        a: self.a[p],
                        b: self.b[p],
                    };
                    found.note(out.depth, ratio, key, self.fraction);
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
            let (body, wall) = (self.wall_body[q], self.wall_of[q]);
            let (i, c) = (body as usize, &self.wall_constants[q]);
            match ctx.wall_pair(wall as usize, i, c, history, in_contact, out) {
                Ok(None) => {}
                Ok(Some(ratio)) => {
                    if own(i) {
                        force[i - first] += out.force_on_b;
                        torque[i - first] += out.torque_on_b;
                    }
                    let key = ContactKey::Wall { body, wall };
                    found.note(out.depth, ratio, key, self.fraction);
                }
                Err(e) => {
                    found.wall_error = Some(e);
                    return found;
                }
            }
        }
        found
    }
}
