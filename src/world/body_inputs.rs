//! What stage 3 reads of every body, written by the drift's own pass (stages 1–2, on the thread pool)
//! instead of a serial pass of its own, and the reuse of the candidate list between grid rebuilds.
//!
//! Per body the drift pass writes the centre (the broad phase's input) and a byte of flags: dynamic,
//! anisotropic (unequal principal moments: the integration's cost), prescribed motion (the ledger's
//! external power), and whether the centre moved half the skin since the last grid build (the comparison
//! of [`super::broad_phase::BroadPhase::needs_rebuild`]; only then can the two largest moves reach the
//! skin, and stage 3 runs the exact test [`super::broad_phase::BroadPhase::pairs_may_be_stale`]). Stage 3
//! then folds the bytes serially (a few µs for 10⁴ bodies) instead of reading every rigid body.
//!
//! The candidate list (the broad phase's pairs with a dynamic side, then the body–wall pairs of dynamic
//! bodies) depends only on the broad phase's lists and the dynamic flags: it is rebuilt only when the grid
//! was rebuilt ([`super::broad_phase::BroadPhase::generation`] changed), a body's dynamic flag changed, or
//! the `non_dynamic_pairs` skip changed; otherwise the previous step's list is kept as it is (the same
//! keys, so the same bits).

use crate::dynamics::rotation::is_isotropic;
use crate::dynamics::{Motion, RigidBody};
use crate::math::{Point, Real, Vector};

use super::broad_phase::BroadPhase;
use super::contact_store::ContactKey;

/// The body's motion is dynamic (it responds to forces).
pub(super) const DYNAMIC: u8 = 1;
/// Dynamic with unequal principal moments.
pub(super) const ANISOTROPIC: u8 = 2;
/// Prescribed motion.
pub(super) const PRESCRIBED: u8 = 4;
/// The centre moved half the skin or more since the last grid build.
pub(super) const FAR: u8 = 8;

/// The per-body inputs of stage 3 and the kept candidate list (scratch: nothing in it matters after a
/// step but as a cache that is checked before use).
#[derive(Clone, Debug, Default)]
pub(super) struct BodyInputs {
    pub(super) centres: Vec<Point>,
    pub(super) flags: Vec<u8>,
    /// Whether `centres` and `flags` were written for the current positions by this step's drift pass
    /// (consumed by stage 3 of the same step).
    pub(super) fresh: bool,
    /// The world angular velocity of every body ([`omega_of`]), written by the general step's drift pass
    /// for stages 4–5 (the velocity of a contact point reads it instead of recomputing R J̄⁻¹ Rᵀ L for
    /// every contact, up to four times per pair: the same function of the same state, so the same bits).
    pub(super) omegas: Vec<Vector>,
    /// Whether `omegas` was written for the current state by this step's drift pass (consumed by the
    /// stages 4–5 of the same step; the initial evaluation and the sphere step compute ω per contact).
    pub(super) omegas_fresh: bool,
    /// The fold of the flags ([`BodyInputs::summarise`]).
    pub(super) summary: Summary,
    /// The broad-phase generation and `non_dynamic_pairs` skip the candidate list was built for.
    candidates_of: Option<(u64, bool)>,
    /// The dynamic flag of every body when the candidate list was built.
    candidates_dynamic: Vec<bool>,
    /// A tag of the candidate list's content ([`super::contact_store::ContactStore::sync_tagged`]): a fresh
    /// number at every rebuild of the list.
    pub(super) candidates_tag: u64,
    /// Body pairs and body–wall pairs in the candidate list.
    pub(super) body_candidates: usize,
    pub(super) wall_candidates: usize,
}

/// The flags folded over all bodies.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub(super) struct Summary {
    pub(super) dynamic: usize,
    pub(super) anisotropic: usize,
    pub(super) any_prescribed: bool,
    pub(super) any_far: bool,
}

/// The flags of body `i` at its current position (`at_build`, `limit_sq`: the broad phase's centres at its
/// last build and (skin/2)²).
#[inline]
pub(super) fn flags_of(i: usize, body: &RigidBody, at_build: &[Point], limit_sq: Real) -> u8 {
    let dynamic = body.is_dynamic();
    let mut f = 0;
    if dynamic {
        f |= DYNAMIC;
        if !is_isotropic(&body.inertia.0) {
            f |= ANISOTROPIC;
        }
    }
    if matches!(body.motion, Motion::Prescribed { .. }) {
        f |= PRESCRIBED;
    }
    let far = match at_build.get(i) {
        Some(then) => (body.position - then).norm_squared() >= limit_sq,
        None => true,
    };
    if far {
        f |= FAR;
    }
    f
}

/// The world angular velocity ω (rad/s) at which stages 4–5 move the material points of `body`:
/// [`RigidBody::angular_velocity`], or L/J for a body with equal principal moments when `isotropic` (the
/// `isotropic_rotation` skip: ω = R J̄⁻¹ Rᵀ L = L/J when J̄ = J·I).
#[inline]
pub(super) fn omega_of(body: &RigidBody, isotropic: bool) -> Vector {
    if isotropic && is_isotropic(&body.inertia.0) {
        body.angular_momentum / body.inertia.0.x
    } else {
        body.angular_velocity()
    }
}

impl BodyInputs {
    /// Sizes the per-body slots for `n` bodies (their values are written by the drift pass or
    /// [`BodyInputs::write`]).
    pub(super) fn resize(&mut self, n: usize) {
        self.centres.resize(n, Point::origin());
        self.flags.resize(n, 0);
    }

    /// Sizes the per-body angular velocities for `n` bodies (written by the drift pass).
    pub(super) fn resize_omegas(&mut self, n: usize) {
        self.omegas.resize(n, Vector::zeros());
    }

    /// Writes the inputs of every body serially (the initial evaluation, which has no drift pass).
    pub(super) fn write(&mut self, bodies: &[RigidBody], broad: &BroadPhase) {
        self.resize(bodies.len());
        let (at_build, limit_sq) = (broad.centres_at_build(), broad.rebuild_limit_sq());
        for (i, (b, (c, f))) in bodies
            .iter()
            .zip(self.centres.iter_mut().zip(self.flags.iter_mut()))
            .enumerate()
        {
            *c = b.position;
            *f = flags_of(i, b, at_build, limit_sq);
        }
    }

    /// Folds the flags into [`BodyInputs::summary`].
    pub(super) fn summarise(&mut self) {
        let mut s = Summary::default();
        let mut any = 0u8;
        for &f in &self.flags {
            s.dynamic += (f & DYNAMIC) as usize;
            s.anisotropic += ((f & ANISOTROPIC) >> 1) as usize;
            any |= f;
        }
        s.any_prescribed = any & PRESCRIBED != 0;
        s.any_far = any & FAR != 0;
        self.summary = s;
    }

    #[inline]
    pub(super) fn is_dynamic(&self, i: usize) -> bool {
        self.flags[i] & DYNAMIC != 0
    }

    /// Makes `candidates` the candidate list of `broad` (see the module docs): kept when nothing it depends
    /// on changed since it was built, else rebuilt. Returns whether it was rebuilt.
    pub(super) fn update_candidates(
        &mut self,
        broad: &mut BroadPhase,
        skip_non_dynamic: bool,
        candidates: &mut Vec<ContactKey>,
    ) -> bool {
        let key = (broad.generation(), skip_non_dynamic);
        let n = self.flags.len();
        let same_dynamic = self.candidates_dynamic.len() == n
            && self
                .candidates_dynamic
                .iter()
                .zip(&self.flags)
                .all(|(&d, &f)| d == (f & DYNAMIC != 0));
        if self.candidates_of == Some(key)
            && same_dynamic
            && candidates.len() == self.body_candidates + self.wall_candidates
        {
            return false;
        }
        candidates.clear();
        for &(a, b) in broad.pairs() {
            if !skip_non_dynamic || self.is_dynamic(a as usize) || self.is_dynamic(b as usize) {
                candidates.push(ContactKey::Body { a, b });
            }
        }
        self.body_candidates = candidates.len();
        // Body–wall pairs: the broad phase's list (bodies that can reach a wall before its next rebuild).
        for &(body, wall) in broad.wall_pairs() {
            if self.is_dynamic(body as usize) {
                candidates.push(ContactKey::Wall { body, wall });
            }
        }
        self.wall_candidates = candidates.len() - self.body_candidates;
        self.candidates_dynamic.clear();
        self.candidates_dynamic
            .extend(self.flags.iter().map(|&f| f & DYNAMIC != 0));
        self.candidates_of = Some(key);
        self.candidates_tag = super::broad_phase::fresh_generation();
        true
    }
}
