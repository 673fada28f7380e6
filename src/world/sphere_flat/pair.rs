//! The pair loop of the flat sphere path: one sphere–sphere or wall–sphere candidate from the compact
//! per-body records to its force, torques and elastic potential.
//!
//! A candidate first takes the cheap test that needs no square root: two spheres whose centres are at
//! least r_A + r_B apart, or a sphere whose centre is at least r above a wall, cannot overlap by more than
//! the touching band, so the pair is separated (its spring is released, as the law does for a pair that
//! does not overlap; see [`separated`] for what a pair that stays apart costs). Any other candidate takes
//! the general narrow phase's closed forms: a sphere pair calls the kernels of [`contact_sphere_sphere`]
//! ([`sphere_sphere_normal`] with the squared distance of the cheap test, [`sphere_sphere_points`]), a
//! wall pair the one of [`contact_plane_sphere`] ([`plane_sphere_points`]); then the law of the pair's model scaled by its √R*
//! ([`ContactModel::for_contact_radii`]) with the constants of the pair formed once per list build
//! ([`PairConstants`], [`WallConstants`]: radii, touching band, [`ContactModel::prepared`] with the
//! pair's m*), then [`PreparedModel::respond`] — what [`ContactModel::evaluate`] does in one call — so an
//! overlapping pair gives the same bits as the sphere kernel of the general step
//! (`super::super::sphere_kernel`). Nothing is written for a separated pair but its flag and its cleared
//! spring: no geometry is kept.

use crate::contact::contact_sphere_plane::plane_sphere_points;
use crate::contact::contact_sphere_sphere::{sphere_sphere_normal, sphere_sphere_points};
use crate::contact::tolerances::pair_length_scale;
use crate::contact::ContactTolerances;
#[cfg(doc)]
use crate::contact::{contact_plane_sphere, contact_sphere_sphere};
use crate::law::{ContactModel, ContactResponse, PreparedModel, TangentialHistory};
use crate::math::{Point, Real, Vector};

use super::super::energy::{ContactWork, LastForces};
use super::super::step::StepError;
use super::ledger::LastContact;

/// What the pair loop reads of one sphere (written by the drift pass).
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct Kinematic {
    pub(crate) position: Point,
    pub(crate) velocity: Vector,
    /// World angular velocity L/J (rad/s).
    pub(crate) omega: Vector,
}

impl Kinematic {
    /// Velocity (m/s) of the material point at `point` (world).
    #[inline(always)]
    fn velocity_at(&self, point: &Point) -> Vector {
        self.velocity + self.omega.cross(&(point - self.position))
    }

    /// Velocity (m/s) at `point` with the lever arm from the centre one step `dt` earlier (x − dt·v):
    /// the lever arm the last forces were applied with (the general step's `velocity_back_at`).
    #[inline(always)]
    fn velocity_back_at(&self, point: &Point, dt: Real) -> Vector {
        self.velocity_at(&(point + dt * self.velocity))
    }
}

/// The ledger's slots of one pair (see [`super::ledger`]): its last contact, read and rewritten, and
/// this step's terms, written when the pair is evaluated.
pub(crate) struct LedgerSlot<'s> {
    pub(crate) last: &'s mut LastContact,
    pub(crate) work: &'s mut ContactWork,
}

impl LedgerSlot<'_> {
    /// The forces of the last evaluation, with `history` the spring it left.
    #[inline(always)]
    fn previous(&self, history: &TangentialHistory) -> LastForces {
        LastForces {
            damping_force: self.last.damping_force,
            history: *history,
        }
    }

    /// An overlapping pair's terms ([`ContactWork::of_new_contact`] or [`ContactWork::of_evaluation`],
    /// as the general step's stage 5 chooses) with the forces `previous` of its last evaluation; then
    /// this evaluation kept as the last. `velocity_back` gives v_B − v_A at a point with the last lever
    /// arms.
    #[allow(clippy::too_many_arguments)]
    #[inline(always)]
    fn book(
        self,
        previous: &LastForces,
        velocity_back: impl FnOnce(&Point) -> Vector,
        normal: &Vector,
        point: Point,
        response: &ContactResponse,
        relative_velocity: &Vector,
        dt: Real,
    ) {
        *self.work = if previous.is_zero() {
            ContactWork::of_new_contact(response, relative_velocity, dt)
        } else {
            ContactWork::of_evaluation(
                previous,
                &velocity_back(&self.last.point),
                normal,
                response,
                relative_velocity,
                dt,
            )
        };
        *self.last = LastContact {
            damping_force: response.damping_force,
            point,
        };
    }

    /// A pair that does not overlap and overlapped at the last evaluation (`history` its spring): the
    /// release of its last forces ([`ContactWork::of_release`]), and no last contact any more.
    #[inline(always)]
    fn release(
        self,
        history: &TangentialHistory,
        law: Option<&PreparedModel>,
        velocity_back: impl FnOnce(&Point) -> Vector,
        dt: Real,
    ) {
        let previous = self.previous(history);
        if let (false, Some(law)) = (previous.is_zero(), law) {
            let v = velocity_back(&self.last.point);
            *self.work = ContactWork::of_release(&law.tangential, &previous, &v, dt);
        }
        *self.last = LastContact::default();
    }
}

/// The constant properties of one sphere.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct Props {
    /// Radius (m).
    pub(crate) radius: Real,
    /// Mass (kg).
    pub(crate) mass: Real,
    /// Principal moment of inertia J (kg·m², equal about every axis).
    pub(crate) moment: Real,
    pub(crate) material: u32,
}

/// A wall as the pair loop sees it in one step: the world normal and offset of the plane (the values
/// [`contact_plane_sphere`] forms from the pose), with the pose.
#[derive(Clone, Copy, Debug)]
pub(crate) struct WallPlane {
    pub(crate) pose: crate::math::Pose,
    /// World normal n and offset o: the signed height of a point x is n·x − o.
    pub(crate) normal: Vector,
    pub(crate) offset: Real,
    pub(crate) velocity: Vector,
    pub(crate) material: u32,
}

impl WallPlane {
    /// The plane of `wall` at its current pose.
    pub(crate) fn of(wall: &super::super::Wall) -> Self {
        let pose = wall.pose;
        // The same operations as `contact_plane_sphere`.
        let normal = pose.rotation * wall.plane.normal();
        let offset = wall.plane.offset() + normal.dot(&pose.translation.vector);
        Self {
            pose,
            normal,
            offset,
            velocity: wall.velocity,
            material: wall.material,
        }
    }

    /// Signed height (m) of `x` above the plane (positive on the free side).
    #[inline(always)]
    pub(crate) fn height(&self, x: &Point) -> Real {
        self.normal.dot(&x.coords) - self.offset
    }
}

/// The result of one overlapping candidate in one step: the loads the gather reads, then what only the
/// write-back and the elastic potential read. Whether a pair overlaps is kept apart, in a dense flag per
/// pair (the pair loop's `in_contact`): a separated pair writes nothing here, and the pair loop reads
/// nothing here of a pair that stays apart. The elastic potential is not kept: it is formed on request
/// from the overlap and the spring ([`super::SphereSim::elastic_potential`]), with the law's own
/// functions.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct PairOut {
    pub(crate) force_on_b: Vector,
    pub(crate) torque_on_a: Vector,
    pub(crate) torque_on_b: Vector,
    /// The velocity-dependent part of the force (N), as the contact store keeps it.
    pub(crate) damping_force: Vector,
    /// Overlap (m).
    pub(crate) depth: Real,
}

impl PairOut {
    /// The output of an overlapping pair: the law's `response` at overlap `depth` (m).
    #[inline(always)]
    fn overlapping(response: &ContactResponse, depth: Real) -> Self {
        PairOut {
            force_on_b: response.force_on_b,
            torque_on_a: response.torque_on_a,
            torque_on_b: response.torque_on_b,
            damping_force: response.damping_force,
            depth,
        }
    }
}

/// The inputs shared by every candidate of a step.
pub(crate) struct PairContext<'a> {
    pub(crate) kin: &'a [Kinematic],
    pub(crate) props: &'a [Props],
    pub(crate) walls: &'a [WallPlane],
    /// The tangential increment's time (s; 0 for the evaluation of an initial state).
    pub(crate) dt: Real,
    pub(crate) step_index: u64,
}

/// The constants of one listed sphere pair, formed at the list build ([`PairConstants::of`]).
#[derive(Clone, Copy, Debug)]
pub(crate) struct PairConstants {
    pub(crate) radius_a: Real,
    pub(crate) radius_b: Real,
    /// The touching band of [`contact_sphere_sphere`]: tolerance × the pair's length scale, the smaller
    /// diameter floored at a fraction of the larger ([`pair_length_scale`]) (m).
    pub(crate) touch: Real,
    /// The smaller diameter (m): the overlap ratio's scale.
    pub(crate) scale: Real,
    /// The pair's model scaled by its √R* and prepared with its m*; `None` when its materials have no
    /// law (an error if the pair overlaps).
    pub(crate) law: Option<PreparedModel>,
}

impl PairConstants {
    /// The constants of the pair (A, B) with √R* `root_radius` and m* `effective_mass` (formed with the
    /// operations of the general step), for the material pair's `model`.
    pub(crate) fn of(
        pa: &Props,
        pb: &Props,
        root_radius: Real,
        effective_mass: Real,
        model: Option<&ContactModel>,
        tolerances: &ContactTolerances,
    ) -> Self {
        Self {
            radius_a: pa.radius,
            radius_b: pb.radius,
            touch: tolerances.touching * pair_length_scale(2.0 * pa.radius, 2.0 * pb.radius),
            scale: (2.0 * pa.radius).min(2.0 * pb.radius),
            law: model.map(|m| scaled(m, root_radius).prepared(effective_mass)),
        }
    }
}

/// The constants of one listed wall–sphere pair, formed at the list build.
#[derive(Clone, Copy, Debug)]
pub(crate) struct WallConstants {
    /// The touching band of [`contact_plane_sphere`]: tolerance × the diameter (m).
    pub(crate) touch: Real,
    pub(crate) law: Option<PreparedModel>,
}

impl WallConstants {
    pub(crate) fn of(
        p: &Props,
        model: Option<&ContactModel>,
        tolerances: &ContactTolerances,
    ) -> Self {
        Self {
            touch: tolerances.touching * 2.0 * p.radius,
            law: model.map(|m| m.for_contact_radii(None, Some(p.radius)).prepared(p.mass)),
        }
    }
}

impl PairContext<'_> {
    #[cold]
    fn missing_law(&self, a: u32, b: u32) -> StepError {
        StepError::MissingLaw {
            step: self.step_index,
            a,
            b,
        }
    }

    /// Whether the centres of spheres a and b are at least `reach` (r_a + r_b) apart: the first test of
    /// [`PairContext::body_pair`], asked ahead of it (false for NaN positions, as there).
    ///
    /// Why ahead: whether a listed pair overlaps follows no pattern along the list, so the branch on it
    /// was mispredicted for about 4 pairs in 10 (`valgrind --tool=cachegrind --branch-sim=yes`, bed c:
    /// 5.1 of 11.3 million). The pair loop asks this of a chunk of pairs and notes the
    /// others without a branch ([`super::passes::PairChunks`]), then runs `body_pair` on those (and on
    /// those apart that were in contact: their springs are released there).
    #[inline(always)]
    pub(crate) fn centres_apart(&self, a: usize, b: usize, reach: Real) -> bool {
        let d_squared = (self.kin[b].position - self.kin[a].position).norm_squared();
        d_squared >= reach * reach
    }

    /// The sphere pair (a, b), a < b (A = a): its output, flag and updated spring; `Some(overlap /
    /// the smaller diameter)` when it overlaps. `reach` is r_a + r_b and `c` the pair's constants;
    /// `in_contact` says whether it overlapped at the last evaluation (false: its spring is cleared).
    ///
    /// The geometry is [`contact_sphere_sphere`]'s, through its kernels (the distance's square root taken
    /// from the squared distance of the cheap test), and the law is the model's
    /// ([`PreparedModel::respond`]), so the pair gives the bits of the general step's sphere kernel.
    /// With `ledger` (the energy ledger on), the pair's terms are booked there as the general step's
    /// stage 5 books them.
    #[allow(clippy::too_many_arguments)]
    #[inline(always)]
    pub(crate) fn body_pair(
        &self,
        a: usize,
        b: usize,
        reach: Real,
        c: &PairConstants,
        history: &mut TangentialHistory,
        in_contact: &mut bool,
        out: &mut PairOut,
        ledger: Option<LedgerSlot<'_>>,
    ) -> Result<Option<Real>, StepError> {
        let (ka, kb) = (&self.kin[a], &self.kin[b]);
        let dt = self.dt;
        let velocity_back = |p: &Point| kb.velocity_back_at(p, dt) - ka.velocity_back_at(p, dt);
        let d_vec = kb.position - ka.position;
        let d_squared = d_vec.norm_squared();
        // d ≥ r_A + r_B, or an overlap within the touching band: separated.
        let overlap = (d_squared < reach * reach)
            .then(|| sphere_sphere_normal(&d_vec, d_squared, reach))
            .filter(|&(_, depth)| depth > c.touch && depth > 0.0);
        let Some((normal, depth)) = overlap else {
            separated(
                history,
                in_contact,
                ledger,
                c.law.as_ref(),
                velocity_back,
                dt,
            );
            return Ok(None);
        };
        let Some(law) = &c.law else {
            return Err(self.missing_law(self.props[a].material, self.props[b].material));
        };
        let (point_a, point_b) =
            sphere_sphere_points(&ka.position, c.radius_a, &kb.position, c.radius_b, &normal);
        let point = nalgebra::center(&point_a, &point_b);
        let overlapping = Overlapping {
            depth,
            normal,
            point,
            relative_velocity: kb.velocity_at(&point) - ka.velocity_at(&point),
            center_a: ka.position,
            center_b: kb.position,
        };
        overlapping.respond(law, dt, history, in_contact, out, ledger, velocity_back);
        Ok(Some(depth / c.scale))
    }

    /// Whether the centre of sphere `i` is at least its radius above wall `w`: a pair that
    /// [`PairContext::wall_pair`] finds separated, asked ahead of it as [`PairContext::centres_apart`].
    #[inline(always)]
    pub(crate) fn wall_apart(&self, w: usize, i: usize) -> bool {
        self.walls[w].height(&self.kin[i].position) >= self.props[i].radius
    }

    /// The wall–sphere pair (A = wall `w`, B = sphere `i`) with its constants `c`: the geometry of
    /// [`contact_plane_sphere`] through its kernel, then the model (returns and flags as
    /// [`PairContext::body_pair`], the ratio over the sphere's diameter).
    #[allow(clippy::too_many_arguments)]
    #[inline(always)]
    pub(crate) fn wall_pair(
        &self,
        w: usize,
        i: usize,
        c: &WallConstants,
        history: &mut TangentialHistory,
        in_contact: &mut bool,
        out: &mut PairOut,
        ledger: Option<LedgerSlot<'_>>,
    ) -> Result<Option<Real>, StepError> {
        let (k, p, wall) = (&self.kin[i], &self.props[i], &self.walls[w]);
        let dt = self.dt;
        let velocity_back = |x: &Point| k.velocity_back_at(x, dt) - wall.velocity;
        let height = wall.height(&k.position);
        let depth = p.radius - height;
        // At or above the radius (depth ≤ 0), or an overlap within the touching band: separated.
        if !(depth > c.touch && depth > 0.0) {
            separated(
                history,
                in_contact,
                ledger,
                c.law.as_ref(),
                velocity_back,
                dt,
            );
            return Ok(None);
        }
        let Some(law) = &c.law else {
            return Err(self.missing_law(wall.material, p.material));
        };
        let n = wall.normal;
        let (point_a, point_b) = plane_sphere_points(&k.position, p.radius, &n, height);
        let point = nalgebra::center(&point_a, &point_b);
        let overlapping = Overlapping {
            depth,
            normal: n,
            point,
            relative_velocity: k.velocity_at(&point) - wall.velocity,
            center_a: point_a,
            center_b: k.position,
        };
        overlapping.respond(law, dt, history, in_contact, out, ledger, velocity_back);
        Ok(Some(depth / (2.0 * p.radius)))
    }
}

/// An overlapping candidate as its law takes it: overlap (m), normal (A to B), contact point, the
/// velocity of B relative to A there, and the points the torques on A and B are taken about.
struct Overlapping {
    depth: Real,
    normal: Vector,
    point: Point,
    relative_velocity: Vector,
    center_a: Point,
    center_b: Point,
}

impl Overlapping {
    /// The law's response written to `out` ([`PreparedModel::respond`], the spring `history` advanced
    /// over `dt`), the pair flagged in contact; with `ledger`, its terms booked ([`LedgerSlot::book`],
    /// `velocity_back` as there).
    #[allow(clippy::too_many_arguments)]
    #[inline(always)]
    fn respond(
        &self,
        law: &PreparedModel,
        dt: Real,
        history: &mut TangentialHistory,
        in_contact: &mut bool,
        out: &mut PairOut,
        ledger: Option<LedgerSlot<'_>>,
        velocity_back: impl FnOnce(&Point) -> Vector,
    ) {
        let previous = ledger.as_ref().map(|slot| slot.previous(history));
        let (normal, v) = (&self.normal, &self.relative_velocity);
        let response = law.respond(
            self.depth,
            normal,
            &self.point,
            v,
            &self.center_a,
            &self.center_b,
            dt,
            history,
        );
        if let (Some(slot), Some(previous)) = (ledger, previous) {
            slot.book(
                &previous,
                velocity_back,
                normal,
                self.point,
                &response,
                v,
                dt,
            );
        }
        *out = PairOut::overlapping(&response, self.depth);
        *in_contact = true;
    }
}

/// The model of a contact from its material pair's model and √R*: [`ContactModel::for_contact_radii`]
/// with the root of the effective radius already formed.
#[inline(always)]
pub(crate) fn scaled(model: &ContactModel, root_radius: Real) -> ContactModel {
    model.for_root_radius(root_radius)
}

/// A candidate that does not overlap: the law resets its spring, and it contributes no force; with the
/// ledger, a pair that overlapped at the last evaluation books the release of its last forces
/// ([`LedgerSlot::release`], `velocity_back` as there).
///
/// A pair that was apart at the last evaluation already holds the cleared spring (`in_contact` false
/// says so; with the ledger, no last contact either), so it reads and writes nothing but its flag:
/// neither its spring nor its output, whose records are ~15 times the flag's size (most listed pairs are
/// apart: ~82 % on bed c).
#[inline(always)]
fn separated(
    history: &mut TangentialHistory,
    in_contact: &mut bool,
    ledger: Option<LedgerSlot<'_>>,
    law: Option<&PreparedModel>,
    velocity_back: impl FnOnce(&Point) -> Vector,
    dt: Real,
) {
    if *in_contact {
        if let Some(slot) = ledger {
            slot.release(history, law, velocity_back, dt);
        }
        if !history.is_cleared() {
            *history = TangentialHistory::default();
        }
        *in_contact = false;
    }
}
