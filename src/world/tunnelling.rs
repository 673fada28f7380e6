//! Tunnelling detection: an observer that, after every step, finds bodies whose path during the step
//! went through another body or through a wall.
//!
//! This is the exact test, O(N²) per step, for verification runs. Every run takes its cheap form, the
//! check of the time step (`world::step::guard`): when two bodies can close by more than the smallest
//! particle radius in one step, which a crossing of kind [`CrossingKind::Missed`] needs, it is a
//! finding there (the run stops by default).
//!
//! # Definition
//! Let step n → n+1 move every body's centre of mass from x_i(n) to x_i(n+1) and turn it from R_i(n) to
//! R_i(n+1). For a dynamic body i and an obstacle:
//!
//! - **another body j** (i ≠ j, any motion): the *relative path* of i's centre in j's own frame is the
//!   segment from r(0) = R_j(n)ᵀ (x_i(n) − x_j(n)) to r(1) = R_j(n+1)ᵀ (x_i(n+1) − x_j(n+1)) (a straight
//!   line in j's frame: the rotation of j within one step is taken as the chord). The path **crosses** j
//!   when this segment meets j's solid (the convex hull of a polyhedron, the ball of a sphere), with r(0)
//!   outside the solid: the centre of i entered j during the step.
//! - **a wall** (the half-space behind a plane): the path crosses the wall when i's centre is on the free
//!   side at the start of the step (signed distance ≥ 0 to the plane at the wall's pose then) and behind
//!   it at the end (signed distance < 0 at the wall's pose now).
//!
//! A centre can only reach the inside of the other solid by overlapping it by more than the smaller
//! inradius, so a crossing is always a failure; the report says which kind:
//!
//! - [`CrossingKind::Missed`] — *tunnelling* proper: no overlapping contact of the pair was registered at
//!   the start of the step (by the query at the positions x(n)), so no contact force acted on the pair
//!   before its centre went through. The bodies passed through each other between two contact queries
//!   (the step is too coarse for the speed, or the broad phase lost the pair). A contact first found at
//!   the end of the step does not count: its force acts only from x(n+1) on, after the crossing.
//! - [`CrossingKind::PassThrough`] — the contact was registered at the start of the step, its force was
//!   acting, and the centre still went through: the stiffness is too soft for the impact speed (the
//!   step's overlap warning reports such runs earlier, at 5 % of the particle size).
//!
//! # Limits
//! The test is on centres: a body that grazes another, overlapping it by less than the depth of the
//! other's centre, is not a crossing (the step's overlap warning covers deep grazes). A body already inside
//! another at the first observation is not reported (nothing crossed). The cost is O(N²) segment tests per
//! step with a bounding-sphere reject; it is a verification tool, not part of the step.

use crate::fixed_hash::FixedHashSet;

use crate::contact::ContactKind;
use crate::math::{Point, Pose, Real};
use crate::shape::convex::segment_distance_to_origin;
use crate::shape::Shape;

use super::contact_store::ContactKey;
use super::world::World;

/// What the centre of a body went through.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Obstacle {
    /// Another body (its index).
    Body(usize),
    /// A wall (its index).
    Wall(usize),
}

/// Whether the pair's contact was registered during the crossing step (see the module docs).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CrossingKind {
    /// No overlapping contact at the start of the step: tunnelling.
    Missed,
    /// An overlapping contact was registered at the start of the step, but the centre still went through.
    PassThrough,
}

/// One crossing found after a step.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Crossing {
    /// The step index at its end (`world.step_index` after the step).
    pub step: u64,
    /// The dynamic body whose centre crossed.
    pub body: usize,
    /// What the centre went through.
    pub obstacle: Obstacle,
    /// Whether the pair's contact was registered during the step.
    pub kind: CrossingKind,
    /// Length of the centre's path during the step relative to the obstacle (m).
    pub path_length: Real,
}

/// Counts of crossings over a run.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct CrossingCounts {
    /// Bodies that tunnelled through another body.
    pub missed_body: u64,
    /// Bodies that tunnelled through a wall.
    pub missed_wall: u64,
    /// Bodies whose centre passed through another body despite a registered contact.
    pub pass_through_body: u64,
    /// Bodies whose centre passed through a wall despite a registered contact.
    pub pass_through_wall: u64,
}

impl CrossingCounts {
    /// Adds one crossing.
    pub fn add(&mut self, c: &Crossing) {
        match (c.kind, c.obstacle) {
            (CrossingKind::Missed, Obstacle::Body(_)) => self.missed_body += 1,
            (CrossingKind::Missed, Obstacle::Wall(_)) => self.missed_wall += 1,
            (CrossingKind::PassThrough, Obstacle::Body(_)) => self.pass_through_body += 1,
            (CrossingKind::PassThrough, Obstacle::Wall(_)) => self.pass_through_wall += 1,
        }
    }

    /// Every crossing, of any kind.
    pub fn total(&self) -> u64 {
        self.missed_body + self.missed_wall + self.pass_through_body + self.pass_through_wall
    }

    /// Tunnelling proper: crossings without a registered contact.
    pub fn missed(&self) -> u64 {
        self.missed_body + self.missed_wall
    }
}

/// The observer: remembers the state at the start of a step and compares it with the state after it.
#[derive(Clone, Debug)]
pub struct TunnellingMonitor {
    poses: Vec<Pose>,
    wall_poses: Vec<Pose>,
    overlapping: FixedHashSet<ContactKey>,
}

fn overlapping_pairs(world: &World) -> FixedHashSet<ContactKey> {
    world
        .contacts
        .keys()
        .iter()
        .zip(world.contacts.states())
        .filter(|(_, s)| s.geometry.kind == ContactKind::Overlap)
        .map(|(k, _)| *k)
        .collect()
}

/// Whether the segment p0 → p1 (in the shape's frame) meets the solid, and p0 is outside it. Public so that
/// monitors with another candidate search (the validation's grid monitor for large beds) share the test.
pub fn segment_enters(shape: &Shape, p0: &Point, p1: &Point) -> bool {
    shape.convex().is_some_and(|c| c.segment_enters(p0, p1))
}

impl TunnellingMonitor {
    /// Starts observing `world` in its current state.
    pub fn new(world: &World) -> Self {
        Self {
            poses: (0..world.bodies.len()).map(|i| world.pose(i)).collect(),
            wall_poses: world.walls.iter().map(|w| w.pose).collect(),
            overlapping: overlapping_pairs(world),
        }
    }

    /// Compares the world after a step with the state kept from the previous call (or from
    /// [`TunnellingMonitor::new`]), appends the crossings of this step to `out`, and keeps the new state.
    pub fn observe(&mut self, world: &World, out: &mut Vec<Crossing>) {
        let now: Vec<Pose> = (0..world.bodies.len()).map(|i| world.pose(i)).collect();
        let overlapping_now = overlapping_pairs(world);
        let kind_of = |key: ContactKey| {
            if self.overlapping.contains(&key) {
                CrossingKind::PassThrough
            } else {
                CrossingKind::Missed
            }
        };
        let n = now.len().min(self.poses.len());
        for i in 0..n {
            if !world.bodies[i].is_dynamic() {
                continue;
            }
            let x0 = Point::from(self.poses[i].translation.vector);
            let x1 = Point::from(now[i].translation.vector);
            for (w, wall) in world.walls.iter().enumerate() {
                let Some(pose0) = self.wall_poses.get(w) else {
                    continue;
                };
                let d0 = wall.plane.signed_distance(pose0, &x0);
                let d1 = wall.plane.signed_distance(&wall.pose, &x1);
                if d0 >= 0.0 && d1 < 0.0 {
                    out.push(Crossing {
                        step: world.step_index,
                        body: i,
                        obstacle: Obstacle::Wall(w),
                        kind: kind_of(ContactKey::Wall {
                            body: i as u32,
                            wall: w as u32,
                        }),
                        path_length: (x1 - x0).norm(),
                    });
                }
            }
            // Each unordered pair once: i's centre through j, or (if not) j's centre through i.
            for j in 0..n {
                if j == i || (j < i && world.bodies[j].is_dynamic()) {
                    continue;
                }
                let through = |p: usize, q: usize| {
                    let r0 = self.poses[q]
                        .inverse_transform_point(&Point::from(self.poses[p].translation.vector));
                    let r1 =
                        now[q].inverse_transform_point(&Point::from(now[p].translation.vector));
                    // Bounding-sphere reject, then the exact segment test.
                    (segment_distance_to_origin(&r0, &r1) <= world.radii[q]
                        && segment_enters(world.shape(q), &r0, &r1))
                    .then(|| (r1 - r0).norm())
                };
                let found = through(i, j).map(|l| (i, j, l)).or_else(|| {
                    world.bodies[j]
                        .is_dynamic()
                        .then(|| through(j, i).map(|l| (j, i, l)))
                        .flatten()
                });
                if let Some((p, q, path_length)) = found {
                    let (a, b) = (i.min(j) as u32, i.max(j) as u32);
                    out.push(Crossing {
                        step: world.step_index,
                        body: p,
                        obstacle: Obstacle::Body(q),
                        kind: kind_of(ContactKey::Body { a, b }),
                        path_length,
                    });
                }
            }
        }
        self.poses = now;
        self.wall_poses = world.walls.iter().map(|w| w.pose).collect();
        self.overlapping = overlapping_now;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dynamics::{PrincipalInertia, RigidBody};
    use crate::law::{ContactModel, DampingLaw, NormalLaw, TangentialLaw};
    use crate::math::{Rotation, Vector};
    use crate::shape::{ConvexPolyhedron, Plane};
    use crate::world::{step, MaterialTable, StepParams, StepScratch, TimeStepCheck, Wall};
    use std::sync::Arc;

    fn cube(half: Real) -> Shape {
        let pts: Vec<Point> = (0..8)
            .map(|i| {
                let s = |b: usize| if i & (1 << b) != 0 { half } else { -half };
                Point::new(s(0), s(1), s(2))
            })
            .collect();
        Shape::Polyhedron(Arc::new(ConvexPolyhedron::from_points(&pts).unwrap().0))
    }

    /// Two unit cubes (and a floor) with a linear law of stiffness `k`.
    fn world(k: Real) -> World {
        let mut materials = MaterialTable::default();
        let m = materials.add_material("rock");
        materials.set_model(
            m,
            m,
            ContactModel {
                normal: NormalLaw::linear(k).unwrap(),
                damping: DampingLaw::None,
                tangential: TangentialLaw::None,
            },
        );
        let mut w = World::new(Vector::zeros(), materials, 0.05);
        let s = w.add_shape(cube(0.5));
        let inertia = PrincipalInertia::new(Vector::repeat(1.0 / 6.0)).unwrap();
        let mut a = RigidBody::new_dynamic(Point::new(-2.0, 0.0, 1.0), 1.0, inertia).unwrap();
        a.velocity = Vector::new(10.0, 0.0, 0.0);
        let b = RigidBody::new_dynamic(Point::new(2.0, 0.0, 1.0), 1.0, inertia).unwrap();
        w.add_body("a", s, m, a).unwrap();
        w.add_body("b", s, m, b).unwrap();
        w.add_wall(Wall {
            name: "floor".into(),
            plane: Plane::new(Vector::z(), 0.0).unwrap(),
            pose: Pose::identity(),
            velocity: Vector::zeros(),
            material: m,
        })
        .unwrap();
        w
    }

    fn run(w: &mut World, dt: Real, steps: usize) -> CrossingCounts {
        let mut monitor = TunnellingMonitor::new(w);
        let mut scratch = StepScratch::default();
        let mut out = Vec::new();
        // Steps that tunnel on purpose: the step's own cheap check would stop them before the monitor
        // (the exact test under test here) sees the crossing.
        let mut params = StepParams::new(dt);
        params.time_step_check = TimeStepCheck::Off;
        for _ in 0..steps {
            step(&params, w, &mut scratch).unwrap();
            monitor.observe(w, &mut out);
        }
        let mut counts = CrossingCounts::default();
        out.iter().for_each(|c| counts.add(c));
        counts
    }

    #[test]
    fn a_step_that_jumps_over_a_body_is_missed_tunnelling() {
        // A (x ∈ [-1, 0]) at 10 m/s towards B (x ∈ [1.5, 2.5]); one step of 0.4 s puts A at x ∈ [3, 4]:
        // its centre went through B and the pair never overlapped at a query.
        let mut w = world(1e3);
        w.bodies[0].position.x = -0.5;
        let counts = run(&mut w, 0.4, 1);
        assert_eq!(
            counts.missed_body, 1,
            "A jumped over B in one step: {counts:?}"
        );
    }

    #[test]
    fn a_resolved_collision_has_no_crossing() {
        let mut w = world(1e6);
        // t_c = π √(m*/k) = π √(0.5/1e6) ≈ 2.2e-3 s; Δt = t_c/50; 4 m gap at 10 m/s: 0.4 s.
        let counts = run(&mut w, 4.4e-5, 12_000);
        assert_eq!(counts.total(), 0, "{counts:?}");
        assert!(w.bodies[0].velocity.x < 0.0, "A bounced back");
    }

    #[test]
    fn a_soft_contact_that_cannot_stop_the_body_is_a_pass_through() {
        // k so small that the contact barely slows A: its centre enters B with the contact registered.
        let mut w = world(1e-3);
        let counts = run(&mut w, 1e-3, 600);
        assert!(counts.pass_through_body >= 1, "{counts:?}");
        assert_eq!(counts.missed(), 0, "{counts:?}");
    }

    #[test]
    fn a_centre_that_leaves_through_the_floor_is_a_wall_crossing() {
        let mut w = world(1e6);
        w.bodies[0].velocity = Vector::new(0.0, 0.0, -100.0);
        w.bodies[0].orientation = Rotation::identity();
        // 1 m above the floor, 100 m/s, Δt = 0.02 s: the centre goes from z = 1 to z = -1 in one step.
        let counts = run(&mut w, 0.02, 1);
        assert_eq!(counts.missed_wall, 1, "{counts:?}");
    }
}
