//! Stage 5 for one candidate: the pair's contact model on the geometry of stage 4, the ledger terms and the
//! stored forces; what stage 6 reads of the result.

use crate::contact::ContactKind;
use crate::law::{ContactKinematics, ContactModel};
use crate::math::{Point, Real, Vector};

use super::super::body_inputs;
use super::super::contact_store::{ContactKey, ContactState};
use super::super::energy::{ContactWork, LastForces};
use super::super::skips::Skips;
use super::super::world::{MaterialTable, World};
#[cfg(doc)]
use super::params::StepParams;
use super::report::StepError;

impl Evaluated {
    /// The slot of a candidate that does not overlap and books no ledger term (what [`contact_law`] writes
    /// for it).
    #[inline(always)]
    pub(super) fn clear_separated(&mut self) {
        self.frozen = false;
        self.work = ContactWork::default();
        self.overlapping = false;
    }

    /// The slot of an overlapping candidate without ledger terms (what [`overlap_law`] writes for it with
    /// the ledger off): the response's loads and potential, the overlap and its ratio to the size.
    #[inline(always)]
    pub(super) fn set_overlapping(
        &mut self,
        response: &crate::law::ContactResponse,
        depth: Real,
        overlap_ratio: Real,
    ) {
        self.frozen = false;
        self.work = ContactWork::default();
        self.force_on_b = response.force_on_b;
        self.torque_on_a = response.torque_on_a;
        self.torque_on_b = response.torque_on_b;
        self.potential = response.normal_potential + response.tangential_potential;
        self.overlapping = true;
        self.depth = depth;
        self.overlap_ratio = overlap_ratio;
    }

    /// Whether stage 6 has something to sum for this candidate: a force, or a nonzero ledger term.
    #[inline]
    pub(super) fn contributes(&self) -> bool {
        self.overlapping
            || self.work.damping != 0.0
            || self.work.friction != 0.0
            || self.work.stiffness != 0.0
    }
}

/// The result of stage 5 for one candidate. The flags and `work` are written for every candidate; the
/// other fields only when `overlapping` (a separated pair contributes no force, and no stage reads them).
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct Evaluated {
    /// What stage 6 reads of the law's [`crate::law::ContactResponse`]: the force on B, the torques on A
    /// and B, and the elastic potential (normal + tangential, J).
    pub(super) force_on_b: Vector,
    pub(super) torque_on_a: Vector,
    pub(super) torque_on_b: Vector,
    pub(super) potential: Real,
    /// The ledger terms of this step (nonzero for a separated pair only in the step it opens).
    pub(super) work: ContactWork,
    /// Whether the shapes overlap (the law produced a force).
    pub(super) overlapping: bool,
    /// Whether the pair is frozen (kept from its last evaluation; see [`super::sleeping`]).
    pub(super) frozen: bool,
    /// Overlap δ_M (m) and δ_M divided by the smaller particle's length scale: the exact overlap, also
    /// for a polyhedron on a wall whose law sees the smoothed depth (stage 4 measures it).
    pub(super) depth: Real,
    pub(super) overlap_ratio: Real,
}

/// What stages 4–5 read for every candidate, gathered once per step.
pub(super) struct PairInputs<'a> {
    pub(super) world: &'a World,
    /// Whether ω of a body with equal principal moments is taken as L/J (the `isotropic_rotation` skip).
    pub(super) isotropic: bool,
    /// Every body's ω as [`body_inputs::omega_of`] gives it, when the drift pass wrote them this step.
    pub(super) omegas: Option<&'a [Vector]>,
    /// The contact model of each material pair (row-major `n_materials²`), with the skips applied.
    pub(super) models: &'a [Option<ContactModel>],
    pub(super) n_materials: usize,
    pub(super) dt: Real,
    pub(super) step_index: u64,
    /// Whether the ledger terms are booked ([`StepParams::energy_ledger`]).
    pub(super) ledger: bool,
}

impl PairInputs<'_> {
    pub(super) fn model(&self, mat_a: u32, mat_b: u32) -> Result<&ContactModel, StepError> {
        self.models[mat_a as usize * self.n_materials + mat_b as usize]
            .as_ref()
            .ok_or(StepError::MissingLaw {
                step: self.step_index,
                a: mat_a,
                b: mat_b,
            })
    }

    /// Velocity (m/s) of the material point of body `i` at `point` (world): [`RigidBody::velocity_at`],
    /// with ω = L/J for a body with equal principal moments when the skip is on (ω = R J̄⁻¹ Rᵀ L = L/J
    /// when J̄ = J·I; see `skips`).
    ///
    /// [`RigidBody::velocity_at`]: crate::dynamics::RigidBody::velocity_at
    #[inline]
    fn velocity_at(&self, i: usize, point: &Point) -> Vector {
        let body = &self.world.bodies[i];
        let omega = match self.omegas {
            Some(omegas) => omegas[i],
            None => body_inputs::omega_of(body, self.isotropic),
        };
        body.velocity + omega.cross(&(point - body.position))
    }

    /// v_B − v_A (m/s) at `point` for the pair `key` (A a wall: its prescribed velocity), with each
    /// body's lever arm taken from its centre `back` seconds earlier (x − back·v: the centre before this
    /// step's drift when `back` = Δt, so the lever arm with which the last forces were applied).
    fn relative_velocity(&self, key: ContactKey, point: &Point, back: Real) -> Vector {
        let at = |i: usize| self.velocity_at(i, &(point + back * self.world.bodies[i].velocity));
        match key {
            ContactKey::Body { a, b } => at(b as usize) - at(a as usize),
            ContactKey::Wall { body, wall } => {
                at(body as usize) - self.world.walls[wall as usize].velocity
            }
        }
    }
}

/// Stage 5 for one candidate: the pair's contact model on the geometry of stage 4 (stored in `state`),
/// updating the tangential history and the stored forces; the result goes to `out`. `previous_point` is
/// the contact point of the pair's last evaluation (the ledger of a pair that opens needs it).
#[inline]
pub(super) fn contact_law(
    pair: &PairInputs,
    key: ContactKey,
    state: &mut ContactState,
    previous_point: &Point,
    out: &mut Evaluated,
) -> Result<(), StepError> {
    out.frozen = false;
    let g = &state.geometry;
    if g.kind != ContactKind::Overlap {
        return release(pair, key, state, previous_point, out);
    }
    let world = pair.world;
    let (a_body, a_velocity_at, mat_a, b) = match key {
        ContactKey::Body { a, b } => (Some(a as usize), None, world.material_of[a as usize], b),
        ContactKey::Wall { body, wall } => {
            let w = &world.walls[wall as usize];
            (None, Some(w.velocity), w.material, body)
        }
    };
    let b = b as usize;
    let model = pair.model(mat_a, world.material_of[b])?;
    let body_b = &world.bodies[b];
    let (velocity_a, center_a, effective_mass, scale) = match a_body {
        Some(a) => {
            let body_a = &world.bodies[a];
            let m = match (body_a.is_dynamic(), body_b.is_dynamic()) {
                (true, true) => body_a.mass * body_b.mass / (body_a.mass + body_b.mass),
                (true, false) => body_a.mass,
                _ => body_b.mass,
            };
            let scale = world.length_scale(a).min(world.length_scale(b));
            (pair.velocity_at(a, &g.point), body_a.position, m, scale)
        }
        None => (
            a_velocity_at.unwrap_or_else(Vector::zeros),
            g.point_a,
            body_b.mass,
            world.length_scale(b),
        ),
    };
    let kinematics = ContactKinematics {
        relative_velocity: pair.velocity_at(b, &g.point) - velocity_a,
        effective_mass,
        center_a,
        center_b: body_b.position,
        dt: pair.dt,
    };
    let model = model.for_shapes(a_body.map(|a| world.shape(a)), world.shape(b));
    overlap_law(
        pair,
        state,
        || pair.relative_velocity(key, previous_point, pair.dt),
        &model,
        &kinematics,
        scale,
        out,
    );
    Ok(())
}

/// Stage 5 for a candidate that does not overlap: the law resets its history and stored forces; a pair
/// that opened in this step books the work of its last forces, which acted for the first half kick.
#[inline]
fn release(
    pair: &PairInputs,
    key: ContactKey,
    state: &mut ContactState,
    previous_point: &Point,
    out: &mut Evaluated,
) -> Result<(), StepError> {
    let ContactState {
        history,
        force_on_b,
        damping_force,
        ..
    } = state;
    out.work = ContactWork::default();
    let previous = LastForces {
        damping_force: *damping_force,
        history: *history,
    };
    if pair.ledger && !previous.is_zero() {
        // The pair opened in this step: its last forces acted for the first half kick.
        let world = pair.world;
        let (shape_a, mat_a, b) = match key {
            ContactKey::Body { a, b } => (
                Some(world.shape(a as usize)),
                world.material_of[a as usize],
                b,
            ),
            ContactKey::Wall { body, wall } => (None, world.walls[wall as usize].material, body),
        };
        let b = b as usize;
        let model = pair
            .model(mat_a, world.material_of[b])?
            .for_shapes(shape_a, world.shape(b));
        let relative_velocity = pair.relative_velocity(key, previous_point, pair.dt);
        out.work =
            ContactWork::of_release(&model.tangential, &previous, &relative_velocity, pair.dt);
    }
    // The law resets the history of a pair that does not overlap.
    *history = Default::default();
    *force_on_b = Vector::zeros();
    *damping_force = Vector::zeros();
    out.overlapping = false;
    Ok(())
}

/// The end of stage 5 for an overlapping candidate whose model (with the pair's stiffnesses), kinematics
/// and length scale (the smaller particle's) are known: the law, the ledger terms, the stored forces.
/// `previous_velocity` gives v_B − v_A at the last contact point with the last lever arms (called only
/// when the ledger books the last forces: [`PairInputs::relative_velocity`] with `back` = Δt).
#[inline]
pub(super) fn overlap_law(
    pair: &PairInputs,
    state: &mut ContactState,
    previous_velocity: impl FnOnce() -> Vector,
    model: &ContactModel,
    kinematics: &ContactKinematics,
    scale: Real,
    out: &mut Evaluated,
) {
    let ContactState {
        geometry: g,
        history,
        force_on_b,
        damping_force,
        ..
    } = state;
    let previous = LastForces {
        damping_force: *damping_force,
        history: *history,
    };
    let response = model.evaluate(g, kinematics, history);
    out.work = if !pair.ledger {
        ContactWork::default()
    } else if previous.is_zero() {
        ContactWork::of_new_contact(&response, &kinematics.relative_velocity, pair.dt)
    } else {
        // The last forces were applied with the lever arms of the last contact point.
        ContactWork::of_evaluation(
            &previous,
            &previous_velocity(),
            &g.normal,
            &response,
            &kinematics.relative_velocity,
            pair.dt,
        )
    };
    *force_on_b = response.force_on_b;
    *damping_force = response.damping_force;
    out.force_on_b = response.force_on_b;
    out.torque_on_a = response.torque_on_a;
    out.torque_on_b = response.torque_on_b;
    out.potential = response.normal_potential + response.tangential_potential;
    out.overlapping = true;
    out.depth = g.depth;
    out.overlap_ratio = g.depth / scale;
}

/// The model with the slots the skips make free: no tangential spring when μ = 0, no damping term when its
/// coefficient is 0 (see [`super::skips`]).
fn effective_model(model: &ContactModel, skips: &Skips) -> ContactModel {
    model.with_skips(skips.frictionless_history, skips.undamped_contacts)
}

/// The contact model of every material pair (row-major `n²`, `None` where no law is set) with the skips
/// applied ([`effective_model`]), into `models`.
pub(crate) fn effective_models(
    materials: &MaterialTable,
    skips: &Skips,
    models: &mut Vec<Option<ContactModel>>,
) {
    let n_materials = materials.len();
    models.clear();
    for a in 0..n_materials as u32 {
        for b in 0..n_materials as u32 {
            let model = materials.model(a, b);
            models.push(model.map(|m| effective_model(m, skips)));
        }
    }
}
