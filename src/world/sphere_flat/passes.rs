//! The three passes of a flat step as functions of one part's inputs: the drift of a range of spheres,
//! the pair loop of a block, the kick of a range of spheres. The step that starts each pass on its own
//! ([`super::step`]) and the step that runs all three in one job of the team ([`super::fused`]) call
//! the same functions, so both give the same bits.

use crate::dynamics::rotation::{drift_isotropic, SubRotation};
use crate::dynamics::translation::{
    drifted_position, first_half_kick_velocity, second_half_kick_velocity,
};
use crate::law::TangentialHistory;
use crate::math::{Point, Real, Vector};

use super::super::energy::ContactWork;
use super::super::step::{first_non_finite, OverlapWarning, StepError};
use super::super::world::Wall;
use super::super::ContactKey;
use super::ledger::{LastContact, PairLedger};
use super::neighbours::TopTwo;
use super::pair::{
    Kinematic, LedgerSlot, PairConstants, PairContext, PairOut, Props, WallConstants,
};
use super::Spin;

/// The first sphere a kick left with a non-finite state, and which quantity (`None`: all finite).
pub(super) type NonFinite = Option<(usize, &'static str)>;

/// What the pair loop found, summed over its blocks in pair order.
#[derive(Default)]
pub(super) struct Found {
    /// Whether the pair loop summed the loads of the spheres it could (see [`super::blocks::Blocks`]).
    pub(super) scattered: bool,
    pub(super) contacts: usize,
    pub(super) max_overlap_ratio: Real,
    /// Warnings of body pairs, then of wall pairs (each in pair order).
    pub(super) warnings: Vec<OverlapWarning>,
    wall_warnings: Vec<OverlapWarning>,
    /// The first error of a body pair, and of a wall pair.
    pub(super) error: Option<StepError>,
    pub(super) wall_error: Option<StepError>,
    /// The ledger's terms summed in pair order by a block whose slots are `in_order`
    /// ([`LedgerPart::in_order`]; not merged: only the one block of a serial pair loop sums them).
    pub(super) work: ContactWork,
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

    /// Adds a pair's ledger terms to the sums in pair order.
    #[inline(always)]
    fn add_work(&mut self, w: &ContactWork) {
        self.work.damping += w.damping;
        self.work.friction += w.friction;
        self.work.stiffness += w.stiffness;
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
    /// Whether to run the x86-64-v3 build ([`super::isa`]; the caller checked the CPU).
    pub(super) v3: bool,
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
        #[cfg(target_arch = "x86_64")]
        if self.v3 {
            // SAFETY: `v3` is set only where the CPU has the features (`super::isa::v3`).
            return unsafe { self.run_v3(start, kin, spin) };
        }
        self.run_here(start, kin, spin)
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,bmi1,bmi2,lzcnt,popcnt")]
    fn run_v3(&self, start: usize, kin: &mut [Kinematic], spin: &mut [Spin]) -> (TopTwo, TopTwo) {
        self.run_here(start, kin, spin)
    }

    #[inline(always)]
    fn run_here(&self, start: usize, kin: &mut [Kinematic], spin: &mut [Spin]) -> (TopTwo, TopTwo) {
        let (dt, h) = (self.dt, 0.5 * self.dt);
        let (mut top, mut large) = (TopTwo::default(), TopTwo::default());
        for (k, (kin, spin)) in kin.iter_mut().zip(spin.iter_mut()).enumerate() {
            let i = start + k;
            let p = &self.props[i];
            kin.velocity = first_half_kick_velocity(
                &kin.velocity,
                &self.force[i],
                p.mass,
                &self.gravity,
                None,
                h,
            );
            spin.angular_momentum += h * self.torque[i];
            kin.position = drifted_position(&kin.position, &kin.velocity, dt);
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
    /// Per sphere, whether its loads are gathered here (see [`super::blocks::Blocks`]).
    pub(super) gathered: &'a [bool],
    /// Whether the pair loop summed the loads of the other spheres.
    pub(super) scattered: bool,
    pub(super) props: &'a [Props],
    pub(super) gravity: Vector,
    pub(super) dt: Real,
    /// Whether to run the x86-64-v3 build ([`super::isa`]; the caller checked the CPU).
    pub(super) v3: bool,
}

/// The per-sphere arrays the kick writes, for the spheres of one part.
pub(super) struct KickPart<'a> {
    pub(super) force: &'a mut [Vector],
    pub(super) torque: &'a mut [Vector],
    pub(super) kin: &'a mut [Kinematic],
    pub(super) spin: &'a mut [Spin],
}

impl Kick<'_> {
    /// Spheres `start..start + part.force.len()`: their loads (gathered where the pair loop did not sum
    /// them), second half kick and finiteness check; the first non-finite quantity, if any.
    pub(super) fn run(&self, start: usize, part: KickPart<'_>) -> Option<(usize, &'static str)> {
        #[cfg(target_arch = "x86_64")]
        if self.v3 {
            // SAFETY: `v3` is set only where the CPU has the features (`super::isa::v3`).
            return unsafe { self.run_v3(start, part) };
        }
        self.run_here(start, part)
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,bmi1,bmi2,lzcnt,popcnt")]
    fn run_v3(&self, start: usize, part: KickPart<'_>) -> Option<(usize, &'static str)> {
        self.run_here(start, part)
    }

    #[inline(always)]
    fn run_here(&self, start: usize, part: KickPart<'_>) -> Option<(usize, &'static str)> {
        let KickPart {
            force,
            torque,
            kin,
            spin,
        } = part;
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
            kin.velocity =
                second_half_kick_velocity(&kin.velocity, &f, p.mass, &self.gravity, None, h);
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
    /// The ledger's slots of the block's pairs (empty when the ledger is off).
    pub(super) ledger: LedgerPart<'a>,
}

impl<'a> BlockPart<'a> {
    /// The arrays of the first `pairs` pairs, `walls` body–wall pairs and `bodies` spheres, split off the
    /// front.
    pub(super) fn split_front(
        &mut self,
        pairs: usize,
        walls: usize,
        bodies: usize,
    ) -> BlockPart<'a> {
        fn front<'a, T>(slots: &mut &'a mut [T], n: usize) -> &'a mut [T] {
            let (head, tail) = std::mem::take(slots).split_at_mut(n);
            *slots = tail;
            head
        }
        BlockPart {
            histories: front(&mut self.histories, pairs),
            in_contact: front(&mut self.in_contact, pairs),
            outs: front(&mut self.outs, pairs),
            wall_histories: front(&mut self.wall_histories, walls),
            wall_in_contact: front(&mut self.wall_in_contact, walls),
            wall_outs: front(&mut self.wall_outs, walls),
            force: front(&mut self.force, bodies),
            torque: front(&mut self.torque, bodies),
            ledger: self.ledger.split_front(pairs, walls),
        }
    }
}

/// The ledger's slots of a run of pairs and of body–wall pairs ([`super::ledger::PairLedger`]).
#[derive(Default)]
pub(super) struct LedgerPart<'a> {
    /// Whether the pair loop sums the terms itself as it goes (the one block of a serial pair loop: it
    /// visits every pair in pair order), into [`Found::work`]; the work slots are then empty.
    pub(super) in_order: bool,
    pub(super) last: &'a mut [LastContact],
    pub(super) work: &'a mut [ContactWork],
    pub(super) wall_last: &'a mut [LastContact],
    pub(super) wall_work: &'a mut [ContactWork],
}

impl<'a> LedgerPart<'a> {
    /// The slots of every pair of `ledger`; `in_order` when one block visits all the pairs in pair order
    /// and sums their terms itself (then it has no work slots).
    pub(super) fn whole(ledger: &'a mut PairLedger, in_order: bool) -> Self {
        let (work, wall_work): (&mut [ContactWork], &mut [ContactWork]) = match in_order {
            true => (&mut [], &mut []),
            false => (&mut ledger.work, &mut ledger.wall_work),
        };
        LedgerPart {
            in_order,
            last: &mut ledger.last,
            work,
            wall_last: &mut ledger.wall_last,
            wall_work,
        }
    }

    /// The slots of the first `pairs` pairs and `walls` wall pairs, split off the front (the slots are
    /// empty when the ledger is off: then nothing is split off).
    pub(super) fn split_front(&mut self, pairs: usize, walls: usize) -> LedgerPart<'a> {
        let split = |slots: &mut &'a mut [LastContact], n: usize| {
            let n = n.min(slots.len());
            let (front, back) = std::mem::take(slots).split_at_mut(n);
            *slots = back;
            front
        };
        let split_work = |slots: &mut &'a mut [ContactWork], n: usize| {
            let n = n.min(slots.len());
            let (front, back) = std::mem::take(slots).split_at_mut(n);
            *slots = back;
            front
        };
        LedgerPart {
            in_order: false,
            last: split(&mut self.last, pairs),
            work: split_work(&mut self.work, pairs),
            wall_last: split(&mut self.wall_last, walls),
            wall_work: split_work(&mut self.wall_work, walls),
        }
    }
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
    /// Whether to run the x86-64-v3 build ([`super::isa`]; the caller checked the CPU).
    pub(super) v3: bool,
    /// Whether the pairs book the energy ledger's terms (the parts then hold the ledger's slots).
    pub(super) ledger: bool,
}

impl PairBlocks<'_> {
    /// One block: bodies `first..first + part.force.len()`, their rows of pairs and their walls, in
    /// pair order; the loads of every body of the block that no other block's pair reaches are summed
    /// here.
    pub(super) fn run(&self, first: usize, part: BlockPart<'_>) -> Found {
        #[cfg(target_arch = "x86_64")]
        if self.v3 {
            // SAFETY: `v3` is set only where the CPU has the features (`super::isa::v3`).
            return unsafe { self.run_v3(first, part) };
        }
        self.run_here(first, part)
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,bmi1,bmi2,lzcnt,popcnt")]
    fn run_v3(&self, first: usize, part: BlockPart<'_>) -> Found {
        self.run_here(first, part)
    }

    #[inline(always)]
    fn run_here(&self, first: usize, part: BlockPart<'_>) -> Found {
        let end = first + part.force.len();
        let own = |j: usize| j < end && !self.gathered.get(j).copied().unwrap_or(false);
        if self.ledger {
            self.run_summing::<true>(first, part, own)
        } else {
            self.run_summing::<false>(first, part, own)
        }
    }

    /// The one block of every sphere (the serial pair loop): [`PairBlocks::run`] without the test of
    /// which spheres it sums (all of them).
    pub(super) fn run_all(&self, part: BlockPart<'_>) -> Found {
        #[cfg(target_arch = "x86_64")]
        if self.v3 {
            // SAFETY: `v3` is set only where the CPU has the features (`super::isa::v3`).
            return unsafe { self.run_all_v3(part) };
        }
        self.run_all_here(part)
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,bmi1,bmi2,lzcnt,popcnt")]
    fn run_all_v3(&self, part: BlockPart<'_>) -> Found {
        self.run_all_here(part)
    }

    #[inline(always)]
    fn run_all_here(&self, part: BlockPart<'_>) -> Found {
        if self.ledger {
            self.run_summing::<true>(0, part, |_| true)
        } else {
            self.run_summing::<false>(0, part, |_| true)
        }
    }

    /// The pair loop of one block, summing the loads of the spheres `own` names, in two halves per
    /// chunk of pairs ([`PairChunks`]); with `LEDGER`, booking each evaluated pair's ledger terms in its
    /// slot of `part.ledger` (one build of the loop per value, so that the loop without the ledger has
    /// no test of it). The body pairs first, then the body–wall pairs; a pair without a law ends the loop.
    #[inline(always)]
    fn run_summing<const LEDGER: bool>(
        &self,
        first: usize,
        part: BlockPart<'_>,
        own: impl Fn(usize) -> bool,
    ) -> Found {
        let mut found = Found::scattered();
        let BlockPart {
            histories,
            in_contact,
            outs,
            wall_histories,
            wall_in_contact,
            wall_outs,
            force,
            torque,
            ledger,
        } = part;
        force.fill(Vector::zeros());
        torque.fill(Vector::zeros());
        let mut sums = BlockSums {
            first,
            own,
            force,
            torque,
            fraction: self.fraction,
            found: &mut found,
        };
        let p0 = self.row_start[first] as usize;
        let pairs = p0..p0 + histories.len();
        let bodies = BodyPairs {
            ctx: &self.ctx,
            a: &self.a[pairs.clone()],
            b: &self.b[pairs.clone()],
            reach: &self.reach[pairs.clone()],
            constants: &self.constants[pairs],
        };
        let slots = PairSlots {
            histories,
            in_contact,
            outs,
            last: ledger.last,
            work: ledger.work,
            in_order: ledger.in_order,
        };
        if let Err(e) = sum_pairs::<LEDGER>(&bodies, slots, &mut sums) {
            found.error = Some(e);
            return found;
        }
        let q0 = self.wall_start[first] as usize;
        let walls = q0..q0 + wall_histories.len();
        let walls = WallPairs {
            ctx: &self.ctx,
            body: &self.wall_body[walls.clone()],
            wall: &self.wall_of[walls.clone()],
            constants: &self.wall_constants[walls],
        };
        let slots = PairSlots {
            histories: wall_histories,
            in_contact: wall_in_contact,
            outs: wall_outs,
            last: ledger.wall_last,
            work: ledger.wall_work,
            in_order: ledger.in_order,
        };
        if let Err(e) = sum_pairs::<LEDGER>(&walls, slots, &mut sums) {
            found.wall_error = Some(e);
        }
        found
    }
}

/// The per-pair slots of one kind of listed pair of a block: springs, flags, outputs and the ledger's
/// slots (empty when the ledger is off).
struct PairSlots<'p> {
    histories: &'p mut [TangentialHistory],
    in_contact: &'p mut [bool],
    outs: &'p mut [PairOut],
    last: &'p mut [LastContact],
    work: &'p mut [ContactWork],
    /// Whether the terms are summed in pair order as the loop goes ([`LedgerPart::in_order`]).
    in_order: bool,
}

/// Where a block's pair loop sums: the loads of the spheres `own` names (block-local from `first`),
/// and what it found.
struct BlockSums<'s, Own> {
    first: usize,
    own: Own,
    force: &'s mut [Vector],
    torque: &'s mut [Vector],
    /// The overlap ratio above which a contact is warned about.
    fraction: Real,
    found: &'s mut Found,
}

impl<Own: Fn(usize) -> bool> BlockSums<'_, Own> {
    /// Adds `force` and `torque` to sphere `i` if the block sums its loads.
    #[inline(always)]
    fn add(&mut self, i: usize, force: Vector, torque: Vector) {
        if (self.own)(i) {
            self.force[i - self.first] += force;
            self.torque[i - self.first] += torque;
        }
    }

    /// Adds the reaction to `force` (−force) and `torque` to sphere `i` if the block sums its loads.
    #[inline(always)]
    fn add_reaction(&mut self, i: usize, force: Vector, torque: Vector) {
        if (self.own)(i) {
            self.force[i - self.first] -= force;
            self.torque[i - self.first] += torque;
        }
    }
}

/// One kind of listed pair (sphere–sphere, wall–sphere) of a block, as [`sum_pairs`] walks it.
trait ListedPairs {
    /// 1 when pair `k` must be evaluated: its bodies are not apart, or it was in contact until now (its
    /// spring is then released); as an integer, so that no branch is taken on it.
    fn must_evaluate(&self, k: usize, in_contact: bool) -> u64;

    /// Pair `k` with its slots: `Some(overlap ratio)` when it overlaps ([`PairContext::body_pair`]).
    fn evaluate(
        &self,
        k: usize,
        history: &mut TangentialHistory,
        in_contact: &mut bool,
        out: &mut PairOut,
        ledger: Option<LedgerSlot<'_>>,
    ) -> Result<Option<Real>, StepError>;

    /// Adds the loads `out` of overlapping pair `k` to its spheres in `sums`.
    fn add_loads<Own: Fn(usize) -> bool>(&self, k: usize, out: &PairOut, sums: &mut BlockSums<Own>);

    fn key(&self, k: usize) -> ContactKey;
}

/// The sphere pairs of a block.
struct BodyPairs<'a> {
    ctx: &'a PairContext<'a>,
    a: &'a [u32],
    b: &'a [u32],
    reach: &'a [Real],
    constants: &'a [PairConstants],
}

impl ListedPairs for BodyPairs<'_> {
    #[inline(always)]
    fn must_evaluate(&self, k: usize, in_contact: bool) -> u64 {
        let (a, b) = (self.a[k] as usize, self.b[k] as usize);
        u64::from(!self.ctx.centres_apart(a, b, self.reach[k])) | u64::from(in_contact)
    }

    #[inline(always)]
    fn evaluate(
        &self,
        k: usize,
        history: &mut TangentialHistory,
        in_contact: &mut bool,
        out: &mut PairOut,
        ledger: Option<LedgerSlot<'_>>,
    ) -> Result<Option<Real>, StepError> {
        let (a, b) = (self.a[k] as usize, self.b[k] as usize);
        let c = &self.constants[k];
        self.ctx
            .body_pair(a, b, self.reach[k], c, history, in_contact, out, ledger)
    }

    #[inline(always)]
    fn add_loads<Own: Fn(usize) -> bool>(
        &self,
        k: usize,
        out: &PairOut,
        sums: &mut BlockSums<Own>,
    ) {
        sums.add_reaction(self.a[k] as usize, out.force_on_b, out.torque_on_a);
        sums.add(self.b[k] as usize, out.force_on_b, out.torque_on_b);
    }

    #[inline(always)]
    fn key(&self, k: usize) -> ContactKey {
        ContactKey::Body {
            a: self.a[k],
            b: self.b[k],
        }
    }
}

/// The wall–sphere pairs of a block.
struct WallPairs<'a> {
    ctx: &'a PairContext<'a>,
    body: &'a [u32],
    wall: &'a [u32],
    constants: &'a [WallConstants],
}

impl ListedPairs for WallPairs<'_> {
    #[inline(always)]
    fn must_evaluate(&self, k: usize, in_contact: bool) -> u64 {
        let (w, i) = (self.wall[k] as usize, self.body[k] as usize);
        u64::from(!self.ctx.wall_apart(w, i)) | u64::from(in_contact)
    }

    #[inline(always)]
    fn evaluate(
        &self,
        k: usize,
        history: &mut TangentialHistory,
        in_contact: &mut bool,
        out: &mut PairOut,
        ledger: Option<LedgerSlot<'_>>,
    ) -> Result<Option<Real>, StepError> {
        let (w, i) = (self.wall[k] as usize, self.body[k] as usize);
        let c = &self.constants[k];
        self.ctx
            .wall_pair(w, i, c, history, in_contact, out, ledger)
    }

    #[inline(always)]
    fn add_loads<Own: Fn(usize) -> bool>(
        &self,
        k: usize,
        out: &PairOut,
        sums: &mut BlockSums<Own>,
    ) {
        sums.add(self.body[k] as usize, out.force_on_b, out.torque_on_b);
    }

    #[inline(always)]
    fn key(&self, k: usize) -> ContactKey {
        ContactKey::Wall {
            body: self.body[k],
            wall: self.wall[k],
        }
    }
}

/// The pair loop over one kind of listed pair: the pairs each chunk must evaluate ([`PairChunks`]),
/// in pair order, their loads summed and their contacts noted in `sums`; with `LEDGER`, each pair's
/// terms booked in its slot (or summed in pair order). Stops at the first pair without a law.
#[inline(always)]
fn sum_pairs<const LEDGER: bool>(
    pairs: &impl ListedPairs,
    slots: PairSlots<'_>,
    sums: &mut BlockSums<impl Fn(usize) -> bool>,
) -> Result<(), StepError> {
    let PairSlots {
        histories,
        in_contact,
        outs,
        last,
        work: works,
        in_order,
    } = slots;
    // A pair's terms when the loop sums them in pair order (`in_order`).
    let mut work = ContactWork::default();
    let mut chunks = PairChunks::new(histories.len());
    while let Some(listed) = chunks.next(|k| pairs.must_evaluate(k, in_contact[k])) {
        for k in listed {
            let slot = LEDGER.then(|| LedgerSlot {
                last: &mut last[k],
                work: match in_order {
                    true => &mut work,
                    false => &mut works[k],
                },
            });
            let out = &mut outs[k];
            let evaluated = pairs.evaluate(k, &mut histories[k], &mut in_contact[k], out, slot);
            if LEDGER && in_order {
                sums.found.add_work(&std::mem::take(&mut work));
            }
            if let Some(ratio) = evaluated? {
                pairs.add_loads(k, out, sums);
                let fraction = sums.fraction;
                sums.found.note(out.depth, ratio, pairs.key(k), fraction);
            }
        }
    }
    Ok(())
}

/// The pairs of a block in chunks of 64, listing the pairs of each chunk that the pair loop must
/// evaluate: the caller's test (1: evaluate, 0: skip; centres not apart, or in contact until now) is
/// asked of every pair of the chunk and kept as one bit per pair, with no branch on the answer; the
/// caller then evaluates the pairs whose bits are set, in pair order ([`Listed`]), so the loads are
/// summed in the same order, with the same bits, as by one pass over the pairs that branches on the
/// test.
///
/// Why bits and not a list of indices: a list written at a position that depends on the last answer
/// made each pair's loads wait for the previous pair's test (bed c: ~23 cycles per pair,
/// 45 % of the pair loop's samples).
pub(super) struct PairChunks {
    pairs: usize,
    next: usize,
}

impl PairChunks {
    pub(super) fn new(pairs: usize) -> Self {
        Self { pairs, next: 0 }
    }

    /// The pairs of the next chunk (indices into the block's pairs) for which `test` gives 1; `None`
    /// after the last chunk.
    #[inline(always)]
    pub(super) fn next(&mut self, test: impl Fn(usize) -> u64) -> Option<Listed> {
        if self.next >= self.pairs {
            return None;
        }
        let (start, end) = (self.next, (self.next + 64).min(self.pairs));
        let mut bits = 0u64;
        for k in start..end {
            bits |= test(k) << (k - start);
        }
        self.next = end;
        Some(Listed { start, bits })
    }
}

/// The listed pairs of one chunk of [`PairChunks`], in order.
pub(super) struct Listed {
    start: usize,
    bits: u64,
}

impl Iterator for Listed {
    type Item = usize;

    #[inline(always)]
    fn next(&mut self) -> Option<usize> {
        if self.bits == 0 {
            return None;
        }
        let k = self.start + self.bits.trailing_zeros() as usize;
        self.bits &= self.bits - 1;
        Some(k)
    }
}

/// Stage 9's sums, a pure function of the pair loop's wall outputs: the force on each wall, its pairs
/// taken in pair order (bodies by increasing index), and the power the walls deliver.
pub(super) fn wall_sums(
    wall_out: &[PairOut],
    wall_in_contact: &[bool],
    wall_of: &[u32],
    walls: &[Wall],
    forces: &mut [Vector],
) -> Real {
    for f in forces.iter_mut() {
        *f = Vector::zeros();
    }
    for ((o, &overlapping), &w) in wall_out.iter().zip(wall_in_contact).zip(wall_of) {
        if overlapping {
            forces[w as usize] -= o.force_on_b;
        }
    }
    let mut external_power = 0.0;
    for (f, wall) in forces.iter().zip(walls) {
        external_power -= f.dot(&wall.velocity);
    }
    external_power
}

#[cfg(test)]
mod tests {
    use super::PairChunks;
    use rand::{Rng, SeedableRng};

    /// The chunks list exactly the pairs whose test gives 1, in pair order, for lengths around the chunk
    /// size and for dense, sparse and random tests.
    #[test]
    fn chunks_list_the_passing_pairs_in_order() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(7);
        for pairs in [0, 1, 2, 63, 64, 65, 127, 128, 129, 1000] {
            for density in [0.0, 0.05, 0.5, 0.95, 1.0] {
                let pass: Vec<bool> = (0..pairs).map(|_| rng.random_bool(density)).collect();
                let expected: Vec<usize> = (0..pairs).filter(|&k| pass[k]).collect();
                let mut listed = Vec::new();
                let mut chunks = PairChunks::new(pairs);
                let mut count = 0;
                while let Some(chunk) = chunks.next(|k| u64::from(pass[k])) {
                    listed.extend(chunk);
                    count += 1;
                }
                assert_eq!(
                    listed, expected,
                    "{pairs} pairs, density {density}: listed {listed:?}, expected {expected:?}"
                );
                assert_eq!(count, pairs.div_ceil(64), "{pairs} pairs: {count} chunks");
            }
        }
    }
}
