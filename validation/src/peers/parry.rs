//! The parry3d-f64 peer: its GJK/EPA contact, intersection test and distance on the same polyhedra.
//!
//! parry's `ConvexPolyhedron` is built from the vertices of our polyhedron in its principal frame, so both
//! codes see the same solid at the same pose. Queries:
//! - `parry3d_f64::query::contact` in [`ParryPair::contact`], with a prediction large enough to also
//!   return the gap of separated pairs (contact points then are the closest points);
//! - `query::intersection_test` in [`ParryPair::intersects`] (the boolean rejection test);
//! - `query::distance` in [`ParryPair::distance`].
//!
//! A panic inside parry is caught and reported as `None`, never as "no contact".

use std::panic::{catch_unwind, AssertUnwindSafe};

use parry3d_f64::query;
use parry3d_f64::shape::ConvexPolyhedron as ParryPolyhedron;
use polydem::math::{Point, Pose, Vector};
use polydem::shape::ConvexPolyhedron;

use polydem::math::glam::{glam_to_point, glam_to_vector, point_to_glam, pose_to_glam};

/// A contact answer from parry, in polydem's conventions (world frame, normal from A to B).
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct ParryContact {
    /// Signed gap: distance when separated (> 0), minus the penetration depth when overlapping (< 0).
    pub signed_gap: f64,
    pub normal: Vector,
    pub point_a: Point,
    pub point_b: Point,
}

/// A polyhedron converted to parry's shape.
pub struct ParryShape {
    shape: ParryPolyhedron,
}

impl ParryShape {
    /// parry's convex polyhedron with the same vertices (principal frame). `None` when parry's hull fails.
    pub fn new(poly: &ConvexPolyhedron) -> Option<Self> {
        let pts: Vec<_> = poly.vertices().iter().map(point_to_glam).collect();
        ParryPolyhedron::from_convex_hull(&pts).map(|shape| ParryShape { shape })
    }
}

/// Two parry shapes at their poses.
pub struct ParryPair<'a> {
    pub a: &'a ParryShape,
    pub b: &'a ParryShape,
}

impl ParryPair<'_> {
    /// parry's contact with `prediction` (m): `Ok(None)` when parry reports no contact within the prediction,
    /// `Err(())` when parry panicked or reported the pair unsupported.
    #[allow(clippy::result_unit_err)]
    pub fn contact(
        &self,
        pos1: &Pose,
        pos2: &Pose,
        prediction: f64,
    ) -> Result<Option<ParryContact>, ()> {
        let (p1, p2) = (pose_to_glam(pos1), pose_to_glam(pos2));
        let r = catch_unwind(AssertUnwindSafe(|| {
            query::contact(&p1, &self.a.shape, &p2, &self.b.shape, prediction)
        }));
        match r {
            Ok(Ok(Some(c))) => Ok(Some(ParryContact {
                signed_gap: c.dist,
                normal: glam_to_vector(c.normal1),
                point_a: glam_to_point(c.point1),
                point_b: glam_to_point(c.point2),
            })),
            Ok(Ok(None)) => Ok(None),
            _ => Err(()),
        }
    }

    /// parry's boolean intersection test (`None` when parry panicked or reported the pair unsupported).
    pub fn intersects(&self, pos1: &Pose, pos2: &Pose) -> Option<bool> {
        let (p1, p2) = (pose_to_glam(pos1), pose_to_glam(pos2));
        catch_unwind(AssertUnwindSafe(|| {
            query::intersection_test(&p1, &self.a.shape, &p2, &self.b.shape)
        }))
        .ok()?
        .ok()
        .map(|r| r.intersecting)
    }

    /// parry's distance (0 when intersecting; `None` on panic or unsupported).
    pub fn distance(&self, pos1: &Pose, pos2: &Pose) -> Option<f64> {
        let (p1, p2) = (pose_to_glam(pos1), pose_to_glam(pos2));
        catch_unwind(AssertUnwindSafe(|| {
            query::distance(&p1, &self.a.shape, &p2, &self.b.shape)
        }))
        .ok()?
        .ok()
        .map(|r| r.distance)
    }
}
