//! The public face of [`World`]: read access to every part of its state, and the edits a user makes
//! between steps, each of which keeps what the step relies on.
//!
//! The fields stay private so that the state the step keeps between steps stays consistent:
//! - The loads ([`Loads::current`]) belong to the positions they were evaluated at: moving a body or a
//!   wall marks them stale, and the next step evaluates them again before its first kick.
//! - A sleeping body is frozen (see [`super::sleeping`]): changing its velocity or its pose wakes it.
//! - The broad phase measures every body's and wall's displacement since its last build, so a moved body
//!   or wall is picked up by its own test; nothing needs resetting there.
//!
//! What is not kept: the energy ledger does not see an edit (a velocity set by hand changes the kinetic
//! energy outside the balance); book it with [`World::record_external_work`] or restart the ledger with
//! [`World::reset_ledger`].

use crate::dynamics::{Motion, RigidBody};
use crate::math::{Point, Real, Vector};
use crate::shape::Shape;

use super::broad_phase::BroadPhase;
use super::contact_store::ContactStore;
use super::energy::EnergyLedger;
use super::sleep_state::SleepState;
use super::wall::Wall;
use super::world::{Loads, MaterialTable, World, WorldError};

/// Read access.
impl World {
    /// The shapes the bodies refer to (by index).
    pub fn shapes(&self) -> &[Shape] {
        &self.shapes
    }

    /// State of each body (pose, velocities, mass properties, motion), in body order.
    pub fn bodies(&self) -> &[RigidBody] {
        &self.bodies
    }

    /// Body `i`. Panics if `i` is not a body (see [`World::bodies`] for a checked look-up).
    pub fn body(&self, i: usize) -> &RigidBody {
        &self.bodies[i]
    }

    /// Number of bodies.
    pub fn body_count(&self) -> usize {
        self.bodies.len()
    }

    /// Index into [`World::shapes`] of the shape of each body.
    pub fn shape_indices(&self) -> &[u32] {
        &self.shape_of
    }

    /// Material id of each body.
    pub fn body_materials(&self) -> &[u32] {
        &self.material_of
    }

    /// Bounding-sphere radius of each body about its centre of mass (m).
    pub fn radii(&self) -> &[Real] {
        &self.radii
    }

    /// Name of each body.
    pub fn names(&self) -> &[String] {
        &self.names
    }

    /// Name of body `i`. Panics if `i` is not a body.
    pub fn name(&self, i: usize) -> &str {
        &self.names[i]
    }

    /// The index of the first body named `name`.
    pub fn body_index(&self, name: &str) -> Option<usize> {
        self.names.iter().position(|n| n == name)
    }

    /// The walls (planes).
    pub fn walls(&self) -> &[Wall] {
        &self.walls
    }

    /// The index of the first wall named `name`.
    pub fn wall_index(&self, name: &str) -> Option<usize> {
        self.walls.iter().position(|w| w.name == name)
    }

    /// Materials and the contact law of each pair.
    pub fn materials(&self) -> &MaterialTable {
        &self.materials
    }

    /// Gravitational acceleration (m/s²).
    pub fn gravity(&self) -> Vector {
        self.gravity
    }

    /// Persistent contacts with their history (tangential springs, solver caches).
    pub fn contacts(&self) -> &ContactStore {
        &self.contacts
    }

    /// Broad phase: grid, candidate pairs and Verlet skin.
    pub fn broad_phase(&self) -> &BroadPhase {
        &self.broad_phase
    }

    /// Resultant loads of the last force evaluation.
    pub fn loads(&self) -> &Loads {
        &self.loads
    }

    /// Energy dissipated and work done so far.
    pub fn ledger(&self) -> &EnergyLedger {
        &self.ledger
    }

    /// Which bodies are asleep (see [`super::sleeping`]); empty until the first step.
    pub fn sleep(&self) -> &SleepState {
        &self.sleep
    }

    /// Simulated time (s).
    pub fn time(&self) -> Real {
        self.time
    }

    /// Completed steps.
    pub fn step_index(&self) -> u64 {
        self.step_index
    }
}

/// Checked edits.
impl World {
    fn check_body(&self, i: usize) -> Result<(), WorldError> {
        if i < self.bodies.len() {
            Ok(())
        } else {
            Err(WorldError::UnknownBody {
                body: i,
                count: self.bodies.len(),
            })
        }
    }

    fn check_wall(&self, k: usize) -> Result<(), WorldError> {
        if k < self.walls.len() {
            Ok(())
        } else {
            Err(WorldError::UnknownWall {
                wall: k,
                count: self.walls.len(),
            })
        }
    }

    /// Sets the velocity (m/s) of body `i`'s centre of mass; a sleeping body wakes.
    pub fn set_body_velocity(&mut self, i: usize, velocity: Vector) -> Result<(), WorldError> {
        self.check_body(i)?;
        finite_body(&self.names[i], "velocity", &velocity)?;
        self.edit_body(i, |b| b.velocity = velocity)
    }

    /// Sets the angular velocity (rad/s, world frame) of body `i`; a sleeping body wakes.
    pub fn set_body_angular_velocity(
        &mut self,
        i: usize,
        angular_velocity: Vector,
    ) -> Result<(), WorldError> {
        self.check_body(i)?;
        finite_body(&self.names[i], "angular velocity", &angular_velocity)?;
        self.edit_body(i, |b| b.set_angular_velocity(&angular_velocity))
    }

    /// Moves body `i`'s centre of mass to `position` (m); the loads become stale (the next step evaluates
    /// them at the new position) and a sleeping body wakes.
    pub fn set_body_position(&mut self, i: usize, position: Point) -> Result<(), WorldError> {
        self.check_body(i)?;
        finite_body(&self.names[i], "position", &position.coords)?;
        self.edit_body(i, |b| b.position = position)
    }

    /// Sets how body `i` moves (dynamic, fixed, prescribed); a sleeping body wakes.
    pub fn set_body_motion(&mut self, i: usize, motion: Motion) -> Result<(), WorldError> {
        self.check_body(i)?;
        self.edit_body(i, |b| b.motion = motion)?;
        self.wake(i);
        Ok(())
    }

    /// Edits body `i` in place with `edit` and keeps the world's invariants afterwards: a change of position
    /// or orientation marks the loads stale, and a change of pose or velocities wakes a sleeping body. The
    /// new state is not checked: the step's checks report a non-finite body. Prefer the `set_body_*`
    /// methods; this one is for edits they do not cover (a mass change, a scenario of a test).
    pub fn edit_body<R>(
        &mut self,
        i: usize,
        edit: impl FnOnce(&mut RigidBody) -> R,
    ) -> Result<R, WorldError> {
        self.check_body(i)?;
        let before = self.bodies[i];
        let result = edit(&mut self.bodies[i]);
        let after = &self.bodies[i];
        let moved = !same_bits(&before.position.coords, &after.position.coords)
            || before
                .orientation
                .coords
                .iter()
                .map(|c| c.to_bits())
                .ne(after.orientation.coords.iter().map(|c| c.to_bits()));
        let stirred = !same_bits(&before.velocity, &after.velocity)
            || !same_bits(&before.angular_momentum, &after.angular_momentum);
        if moved {
            self.loads.current = false;
        }
        if moved || stirred {
            self.wake(i);
        }
        Ok(result)
    }

    /// Wakes body `i` if it sleeps.
    fn wake(&mut self, i: usize) {
        if self.sleep.is_asleep(i) {
            self.sleep.wake(i);
        }
    }

    /// Sets the prescribed velocity (m/s, world frame) of wall `k`.
    pub fn set_wall_velocity(&mut self, k: usize, velocity: Vector) -> Result<(), WorldError> {
        self.check_wall(k)?;
        if !velocity.iter().all(|v| v.is_finite()) {
            return Err(WorldError::NonFiniteWall {
                wall: self.walls[k].name.clone(),
                what: "velocity",
            });
        }
        self.walls[k].velocity = velocity;
        Ok(())
    }

    /// Moves wall `k` to the translation `translation` (m), keeping its orientation; the loads become stale.
    pub fn set_wall_translation(
        &mut self,
        k: usize,
        translation: Vector,
    ) -> Result<(), WorldError> {
        self.check_wall(k)?;
        if !translation.iter().all(|v| v.is_finite()) {
            return Err(WorldError::NonFiniteWall {
                wall: self.walls[k].name.clone(),
                what: "position",
            });
        }
        self.walls[k].pose.translation.vector = translation;
        self.loads.current = false;
        Ok(())
    }

    /// Keeps the first `len` walls and removes the others; the loads become stale. Contacts with a removed
    /// wall leave the contact store at the next step, and a body they held wakes as its load changes.
    pub fn truncate_walls(&mut self, len: usize) {
        self.walls.truncate(len);
        self.loads.current = false;
    }

    /// Sets the gravitational acceleration (m/s²).
    pub fn set_gravity(&mut self, gravity: Vector) -> Result<(), WorldError> {
        if !gravity.iter().all(|g| g.is_finite()) {
            return Err(WorldError::NonFiniteGravity);
        }
        self.gravity = gravity;
        Ok(())
    }

    /// Replaces the material table (the contact laws) by `materials`. Refused, with the world unchanged, if a
    /// material of a body or wall is not in the new table or two materials that can meet have no law
    /// there. A contact's law is read from the table at each step, so the next step uses the new laws.
    pub fn set_materials(&mut self, materials: MaterialTable) -> Result<(), WorldError> {
        let bodies = self.names.iter().zip(&self.material_of);
        let walls = self.walls.iter().map(|w| (&w.name, &w.material));
        for (owner, &m) in bodies.clone().chain(walls.clone()) {
            if m as usize >= materials.len() {
                return Err(WorldError::UnknownMaterial {
                    owner: owner.clone(),
                    material: m as usize,
                    count: materials.len(),
                });
            }
        }
        // Every body meets every body and wall (walls never meet each other): one look-up per distinct pair.
        let distinct =
            |ids: &mut dyn Iterator<Item = u32>| ids.collect::<std::collections::BTreeSet<u32>>();
        let of_bodies = distinct(&mut self.material_of.iter().copied());
        let of_walls = distinct(&mut self.walls.iter().map(|w| w.material));
        for &a in &of_bodies {
            for &b in of_bodies.iter().chain(&of_walls) {
                if materials.model(a, b).is_none() {
                    let k = self.material_of.iter().position(|&m| m == a).unwrap_or(0);
                    return Err(WorldError::MissingLaw {
                        owner: self.names[k].clone(),
                        a: materials.name(a).to_owned(),
                        b: materials.name(b).to_owned(),
                    });
                }
            }
        }
        self.materials = materials;
        Ok(())
    }

    /// Replaces the broad phase by an empty one with the Verlet skin `skin` (m); it is built at the next
    /// step (the candidate pairs it gives do not depend on the skin, only how often they are rebuilt).
    pub fn set_skin(&mut self, skin: Real) {
        self.broad_phase = BroadPhase::new(skin);
    }

    /// Drops the contact store: every tangential spring and solver cache is forgotten (a restart from the
    /// bodies alone).
    pub fn clear_contacts(&mut self) {
        self.contacts = ContactStore::default();
    }

    /// Marks the loads stale: the next step evaluates them at the current state before its first kick.
    pub fn invalidate_loads(&mut self) {
        self.loads.current = false;
    }

    /// Sets the contact force (N) and torque (N·m) of body `i` in the loads by hand, for a caller that
    /// reads them outside the step (a test of a damping model). The per-body arrays grow to the body count
    /// first (new entries zero); nothing else changes, and the next force evaluation of a step overwrites
    /// them.
    pub fn set_body_load_unchecked(
        &mut self,
        i: usize,
        force: Vector,
        torque: Vector,
    ) -> Result<(), WorldError> {
        self.check_body(i)?;
        let n = self.bodies.len();
        for column in [&mut self.loads.forces, &mut self.loads.torques] {
            if column.len() < n {
                column.resize(n, Vector::zeros());
            }
        }
        self.loads.forces[i] = force;
        self.loads.torques[i] = torque;
        Ok(())
    }

    /// Restarts the energy ledger: the next step records the initial energy again.
    pub fn reset_ledger(&mut self) {
        self.ledger = EnergyLedger::default();
    }

    /// Books work (J) done on the bodies outside the step (a density change, a velocity set by hand), so
    /// that the energy balance still closes.
    pub fn record_external_work(&mut self, work: Real) {
        self.ledger.external_work += work;
    }

    /// Books energy (J) removed by a viscous damping applied outside the step.
    pub fn record_viscous_dissipation(&mut self, energy: Real) {
        self.ledger.dissipated_viscous += energy;
    }
}

fn same_bits(a: &Vector, b: &Vector) -> bool {
    a.iter()
        .map(|x| x.to_bits())
        .eq(b.iter().map(|x| x.to_bits()))
}

fn finite_body(name: &str, what: &'static str, v: &Vector) -> Result<(), WorldError> {
    if v.iter().all(|x| x.is_finite()) {
        Ok(())
    } else {
        Err(WorldError::NonFiniteBody {
            body: name.to_owned(),
            what,
        })
    }
}
