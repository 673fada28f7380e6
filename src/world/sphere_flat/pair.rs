//! The pair loop of the flat sphere path: one sphere–sphere or wall–sphere candidate from the compact
//! per-body records to its force, torques and elastic potential.
//!
//! A candidate first takes the cheap test that needs no square root: two spheres whose centres are at
//! least r_A + r_B apart, or a sphere whose centre is at least r above a wall, cannot overlap by more than
//! the touching band, so the pair is separated (its spring is released, as the law does for a pair that
//! does not overlap). Any other candidate goes through the same closed forms as the general narrow phase
//! ([`contact_sphere_sphere`], [`contact_plane_sphere`]), the model scaled by √R* of the two radii
//! ([`ContactModel::for_contact_radii`]) and the law inlined ([`ContactModel::evaluate_inlined`]), with the
//! same arguments and operations as the sphere kernel of the general step (`super::super::sphere_kernel`),
//! so an overlapping pair gives the same bits on both paths. Nothing is written for a separated pair
//! but its flag and its cleared spring: no geometry is kept.

use crate::contact::{contact_plane_sphere, contact_sphere_sphere, ContactKind, ContactTolerances};
use crate::law::{ContactKinematics, ContactModel, RadiusScaling, TangentialHistory};
use crate::math::{Point, Real, Vector};

use super::super::step::StepError;

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
/// [`contact_plane_sphere`] forms from the pose), with the pose itself for that function.
#[derive(Clone, Copy, Debug)]
pub(crate) struct WallPlane {
    pub(crate) pose: crate::math::Pose,
    /// The plane's normal and offset in its own frame (the arguments of [`contact_plane_sphere`]).
    pub(crate) local_normal: Vector,
    pub(crate) local_offset: Real,
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
        let (local_normal, local_offset) = (*wall.plane.normal(), wall.plane.offset());
        // The same operations as `contact_plane_sphere`.
        let normal = pose.rotation * local_normal;
        let offset = local_offset + normal.dot(&pose.translation.vector);
        Self {
            pose,
            local_normal,
            local_offset,
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

/// The result of one candidate in one step: the loads the gather reads, then what only the write-back
/// and the report read. Written in full for an overlapping pair; for a separated one only `overlapping`.
/// The elastic potential is not kept: it is formed on request from the overlap and the spring
/// ([`super::SphereSim::elastic_potential`]), with the law's own functions.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct PairOut {
    pub(crate) force_on_b: Vector,
    pub(crate) torque_on_a: Vector,
    pub(crate) torque_on_b: Vector,
    pub(crate) overlapping: bool,
    /// The velocity-dependent part of the force (N), as the contact store keeps it.
    pub(crate) damping_force: Vector,
    /// Overlap (m) and overlap / the smaller particle's diameter.
    pub(crate) depth: Real,
    pub(crate) overlap_ratio: Real,
}

/// The inputs shared by every candidate of a step.
pub(crate) struct PairContext<'a> {
    pub(crate) kin: &'a [Kinematic],
    pub(crate) props: &'a [Props],
    pub(crate) walls: &'a [WallPlane],
    /// The model of each material pair with the step's skips applied (row-major, `n_materials`²).
    pub(crate) models: &'a [Option<ContactModel>],
    pub(crate) n_materials: usize,
    pub(crate) tolerances: &'a ContactTolerances,
    /// The tangential increment's time (s; 0 for the evaluation of an initial state).
    pub(crate) dt: Real,
    pub(crate) step_index: u64,
}

impl PairContext<'_> {
    #[inline(always)]
    fn model(&self, a: u32, b: u32) -> Result<&ContactModel, StepError> {
        self.models[a as usize * self.n_materials + b as usize]
            .as_ref()
            .ok_or(StepError::MissingLaw {
                step: self.step_index,
                a,
                b,
            })
    }

    /// The sphere pair (a, b), a < b (A = a): its output and updated spring.
    /// `root_radius` (√R*) and `effective_mass` are the pair's constants.
    #[allow(clippy::too_many_arguments)]
    #[inline(always)]
    pub(crate) fn body_pair(
        &self,
        a: usize,
        b: usize,
        root_radius: Real,
        effective_mass: Real,
        history: &mut TangentialHistory,
        out: &mut PairOut,
    ) -> Result<(), StepError> {
        let (ka, kb) = (&self.kin[a], &self.kin[b]);
        let (pa, pb) = (&self.props[a], &self.props[b]);
        let reach = pa.radius + pb.radius;
        if (kb.position - ka.position).norm_squared() >= reach * reach {
            // d ≥ r_A + r_B: no overlap beyond the touching band.
            separated(history, out);
            return Ok(());
        }
        let g = contact_sphere_sphere(
            &ka.position,
            pa.radius,
            &kb.position,
            pb.radius,
            self.tolerances,
        );
        if g.kind != ContactKind::Overlap {
            separated(history, out);
            return Ok(());
        }
        // `for_contact_radii(Some(r_a), Some(r_b))` with the pair's √R* formed at the list build.
        let model = scaled(self.model(pa.material, pb.material)?, root_radius);
        let point = &g.point;
        let kinematics = ContactKinematics {
            relative_velocity: kb.velocity_at(point) - ka.velocity_at(point),
            effective_mass,
            center_a: ka.position,
            center_b: kb.position,
            dt: self.dt,
        };
        let response = model.evaluate_inlined(&g, &kinematics, history);
        let scale = (2.0 * pa.radius).min(2.0 * pb.radius);
        *out = PairOut {
            force_on_b: response.force_on_b,
            torque_on_a: response.torque_on_a,
            torque_on_b: response.torque_on_b,
            overlapping: true,
            damping_force: response.damping_force,
            depth: g.depth,
            overlap_ratio: g.depth / scale,
        };
        Ok(())
    }

    /// The wall–sphere pair (A = wall `w`, B = sphere `i`).
    #[inline(always)]
    pub(crate) fn wall_pair(
        &self,
        w: usize,
        i: usize,
        history: &mut TangentialHistory,
        out: &mut PairOut,
    ) -> Result<(), StepError> {
        let (k, p, wall) = (&self.kin[i], &self.props[i], &self.walls[w]);
        if wall.height(&k.position) >= p.radius {
            separated(history, out);
            return Ok(());
        }
        let g = contact_plane_sphere(
            &wall.pose,
            &wall.local_normal,
            wall.local_offset,
            &k.position,
            p.radius,
            self.tolerances,
        );
        if g.kind != ContactKind::Overlap {
            separated(history, out);
            return Ok(());
        }
        let model = self
            .model(wall.material, p.material)?
            .for_contact_radii(None, Some(p.radius));
        let kinematics = ContactKinematics {
            relative_velocity: k.velocity_at(&g.point) - wall.velocity,
            effective_mass: p.mass,
            center_a: g.point_a,
            center_b: k.position,
            dt: self.dt,
        };
        let response = model.evaluate_inlined(&g, &kinematics, history);
        *out = PairOut {
            force_on_b: response.force_on_b,
            torque_on_a: response.torque_on_a,
            torque_on_b: response.torque_on_b,
            overlapping: true,
            damping_force: response.damping_force,
            depth: g.depth,
            overlap_ratio: g.depth / (2.0 * p.radius),
        };
        Ok(())
    }
}

/// The model of a contact from its material pair's model and √R*: [`ContactModel::for_contact_radii`]
/// with the root of the effective radius already formed.
#[inline(always)]
pub(crate) fn scaled(model: &ContactModel, root_radius: Real) -> ContactModel {
    match model.normal.radius_scaling {
        RadiusScaling::Constant => *model,
        RadiusScaling::SqrtEffectiveRadius => model.with_root_radius(root_radius),
    }
}

/// A candidate that does not overlap: the law resets its spring, and it contributes nothing.
#[inline(always)]
fn separated(history: &mut TangentialHistory, out: &mut PairOut) {
    *history = TangentialHistory::default();
    out.overlapping = false;
}
