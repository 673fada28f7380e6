//! A run of one world split over the ranks of `MPI_COMM_WORLD`, the same bits as one process.
//!
//! Each step: the part's step (the engine's, with the rebuild decision agreed by every rank), then either
//! the ghost exchange (each owner sends its ghosts' states and loads) or, after a rebuild, a cut. A cut
//! migrates bodies between near ranks within the subdomains of the last bisection (`migrate`);
//! when the owned counts have drifted apart (above [`REBALANCE_ABOVE`]) every rank instead gathers the
//! owned bodies' centres, bisects them again, and the bodies migrate to the new subdomains.

use std::sync::Arc;

use mpi::collective::SystemOperation;
use mpi::topology::SimpleCommunicator;
use mpi::traits::*;
use polydem::dynamics::RigidBody;
use polydem::math::{Point, Real, Vector};
use polydem::world::{
    evaluate_initial_loads, step, ContactKey, ContactState, EnergyShare, PartBroadPhase,
    StepParams, StepReport, StepScratch, TimeStepCheck, Wall, World,
};

use crate::consensus::Consensus;
use crate::error::DistributedError;
use crate::exchange::{
    all_gather, exchange_ghost_states, pack_ghost, unpack_ghost, RunTraffic, GHOST_WORDS,
};
use crate::plan::{Holding, Plan, MOVE_ALLOWANCE_IN_SKINS};
use crate::wall_sums::{touching_walls, wall_forces};

/// This rank's part: the world it steps and what it exchanges.
pub(crate) struct Part {
    pub(crate) world: World,
    pub(crate) scratch: StepScratch,
    /// Global index of each local body (increasing).
    pub(crate) ids: Vec<usize>,
    /// Per rank, the local indices of the owned bodies it holds as ghosts.
    pub(crate) sends: Vec<Vec<usize>>,
    /// Per rank, the local indices of the ghosts it owns.
    pub(crate) receives: Vec<Vec<usize>>,
    pub(crate) consensus: Arc<Consensus>,
    /// Positions of the owned bodies at the cut.
    pub(crate) at_cut: Vec<Point>,
    /// The walls at the cut (the whole world's list is built at them and at the bodies' `at_cut`).
    pub(crate) walls_at_cut: Vec<Wall>,
    /// Which ranks hold a body: every rank's subdomain as of the last bisection (kept by the migrations
    /// since), and the largest body each rank owns since this cut.
    pub(crate) holding: Holding,
}

impl Part {
    /// Takes the present positions and walls as those of the last cut (one rank, which keeps its part).
    fn mark_cut(&mut self) {
        let bodies = self.world.bodies();
        self.at_cut = bodies.iter().map(|b| b.position).collect();
        self.walls_at_cut = self.world.walls().to_vec();
    }

    /// Whether local body `i` is owned here (the bodies the part's world counts as its own).
    pub(crate) fn owns(&self, i: usize) -> bool {
        self.world.counts_body(i)
    }

    /// The part holding the bodies `ids` (renumbered in `world`), of which `owned` are this rank's, with
    /// the ghost lists, the subdomains it was cut by, and the owned bodies' positions at the cut.
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn new(
        mut world: World,
        ids: Vec<usize>,
        owned: Vec<bool>,
        sends: Vec<Vec<usize>>,
        receives: Vec<Vec<usize>>,
        holding: Holding,
        at_cut: Vec<Point>,
    ) -> Self {
        let consensus = Arc::new(Consensus::default());
        let mut scratch = StepScratch::default();
        scratch.set_rebuild_consensus(Some(consensus.clone()));
        world.count_only(owned);
        let walls_at_cut = world.walls().to_vec();
        Self {
            world,
            scratch,
            ids,
            sends,
            receives,
            consensus,
            at_cut,
            walls_at_cut,
            holding,
        }
    }
}

/// How the next cut is made.
enum NextCut {
    /// Bisect the whole world again.
    Bisect,
    /// Migrate bodies within the present subdomains: the largest bounding radius each rank owns after,
    /// and the new owner of each body this rank owns, in local order.
    Migrate {
        largest_owned: Vec<Real>,
        owners: Vec<u32>,
    },
}

/// A world stepped on every rank of `MPI_COMM_WORLD`.
pub struct DistributedRun {
    pub(crate) comm: SimpleCommunicator,
    pub(crate) rank: usize,
    /// The whole world as of the last cut (bodies, contacts); walls and clock taken from the part.
    pub(crate) whole: World,
    pub(crate) params: StepParams,
    pub(crate) part: Part,
    /// What this rank sent so far (the agreements of the current part not yet added).
    pub(crate) traffic: RunTraffic,
    /// Cuts so far (the first included).
    pub cuts: u64,
    /// Cuts so far that bisected the whole world (the first included); the others migrated bodies.
    pub bisections: u64,
    /// Migrations so far whose part took its list over from the old part (the others built it again).
    pub lists_carried: u64,
    /// Whether `whole`'s broad phase is the whole world's list (a restored world until its first rebuild);
    /// else the list is the one built at the positions and walls of the last cut.
    pub(crate) whole_list_held: bool,
    /// Above which imbalance (the largest owned count over the mean) a cut bisects the whole world again
    /// instead of migrating bodies between neighbours.
    pub(crate) rebalance_above: Real,
    /// Whether the run started from a fresh world (loads not evaluated) and has not stepped yet: the whole
    /// state is then that world, whose stale loads are what one process shows before its first step.
    pub(crate) fresh: bool,
}

/// The imbalance above which a cut bisects again by default: a rank with 10 % more bodies than the
/// mean makes every rank wait about 10 % of a step.
pub const REBALANCE_ABOVE: Real = 1.1;

impl DistributedRun {
    /// Splits `world` over the ranks: a fresh one (its loads not yet evaluated, as a scene builds it) or
    /// one restored from a checkpoint (its loads and broad phase those one process had). Every rank passes
    /// the same world and parameters. The time-step check is not run on the parts (it reads the state
    /// only, so one process's bits do not depend on it).
    ///
    /// A restored world is cut at the centres its broad phase was built at, as if the cut had happened at
    /// that build, and each part takes the whole list restricted to its bodies: the parts then rebuild
    /// when one process would, and the ghost allowance counts the moves since that build. A restored world
    /// without a list (saved from the flat sphere layout, which keeps lists of its own) is cut at its
    /// positions, and its first step builds the lists, as one process's does.
    pub fn new(world: World, params: StepParams) -> Result<Self, DistributedError> {
        let comm = SimpleCommunicator::world();
        let rank = comm.rank() as usize;
        let params = StepParams {
            time_step_check: TimeStepCheck::Off,
            ..params
        };
        if params.sleeping.enabled {
            return Err(DistributedError::Sleeping);
        }
        let restored = world.loads().is_current();
        let list = world.broad_phase();
        let built = list.rebuilds() > 0 && list.centres_at_build().len() == world.body_count();
        let mut part = if restored && built {
            cut(
                &comm,
                &world,
                list.centres_at_build(),
                PartBroadPhase::Restrict,
            )?
        } else {
            // A fresh world, or a restored one without a list (saved from a layout with lists of its
            // own): the next step builds the list, in one process as in every part.
            let centres: Vec<Point> = world.bodies().iter().map(|b| b.position).collect();
            cut(&comm, &world, &centres, PartBroadPhase::Unbuilt)?
        };
        if rank == 0 {
            // The ledger so far (a restored world's) is counted once, on rank 0's part.
            part.world.replace_ledger(*world.ledger());
        }
        let fresh = !world.loads().is_current();
        Ok(Self {
            comm,
            rank,
            whole: world,
            params,
            part,
            traffic: RunTraffic::default(),
            cuts: 1,
            bisections: 1,
            lists_carried: 0,
            whole_list_held: restored,
            rebalance_above: REBALANCE_ABOVE,
            fresh,
        })
    }

    /// The loads of a fresh world's initial state, which one process evaluates at the start of its first
    /// step (outputs before it show the stale loads, as one process's do). A ghost's loads need its
    /// neighbours beyond the ghost layer, so each part evaluates its own and then takes its ghosts' loads
    /// from their owners: every owned body's first step then reads one process's loads for its neighbours
    /// too.
    fn evaluate_initial_loads(&mut self) -> Result<(), DistributedError> {
        let part = &mut self.part;
        evaluate_initial_loads(&self.params, &mut part.world, &mut part.scratch).map_err(
            |source| DistributedError::Step {
                rank: self.rank,
                source,
            },
        )?;
        self.exchange_ghosts();
        Ok(())
    }

    /// Sets the imbalance (largest owned count over the mean) above which a cut bisects the whole world
    /// again ([`REBALANCE_ABOVE`] by default); at most 1, every cut bisects. The bits do not depend on it.
    pub fn set_rebalance_above(&mut self, imbalance: Real) {
        self.rebalance_above = imbalance;
    }

    /// This rank.
    pub fn rank(&self) -> usize {
        self.rank
    }

    /// Bodies in this rank's part (owned, ghosts).
    pub fn part_size(&self) -> (usize, usize) {
        let owned = (0..self.part.ids.len())
            .filter(|&i| self.part.owns(i))
            .count();
        (owned, self.part.ids.len() - owned)
    }

    /// The communicator the run steps on.
    pub fn communicator(&self) -> &SimpleCommunicator {
        &self.comm
    }

    /// This rank's part of the world (owned bodies and ghosts, numbered in global order).
    pub fn part_world(&self) -> &World {
        &self.part.world
    }

    /// The bodies this rank owns, as a VTK piece labelled by their global indices.
    pub fn owned_piece(&self) -> polydem::io::vtk::BodyPiece {
        let owned = (0..self.part.ids.len()).filter(|&i| self.part.owns(i));
        let bodies: Vec<usize> = owned.collect();
        let labels = bodies.iter().map(|&i| self.part.ids[i]).collect();
        polydem::io::vtk::BodyPiece { bodies, labels }
    }

    /// What this rank sent so far, by kind.
    pub fn traffic(&self) -> RunTraffic {
        let mut traffic = self.traffic;
        traffic.agreements += self.part.consensus.traffic();
        traffic
    }

    /// One step of the whole world; the report is that of this rank's part (its counters count the part's
    /// work, ghosts included).
    pub fn step(&mut self) -> Result<StepReport, DistributedError> {
        if self.fresh {
            self.evaluate_initial_loads()?;
            self.fresh = false;
        }
        let part = &mut self.part;
        let report = step(&self.params, &mut part.world, &mut part.scratch).map_err(|source| {
            DistributedError::Step {
                rank: self.rank,
                source,
            }
        })?;
        if part.consensus.last_rebuilt() && self.comm.size() == 1 {
            // One rank's part is the whole world: a cut would rebuild the same part.
            self.part.mark_cut();
            self.whole_list_held = false;
            self.cuts += 1;
        } else if part.consensus.last_rebuilt() {
            match self.check_before_cut()? {
                NextCut::Bisect => self.rebisect()?,
                NextCut::Migrate {
                    largest_owned,
                    owners,
                } => self.migrate(largest_owned, owners)?,
            }
        } else {
            self.exchange_ghosts();
        }
        Ok(report)
    }

    /// Every body of the whole world in global order (on every rank).
    pub fn gather_bodies(&mut self) -> Result<Vec<RigidBody>, DistributedError> {
        let mine = owned_bodies(&self.part);
        let all = all_gather(&self.comm, &mine, &mut self.traffic.gathers)?;
        let mut bodies = vec![None; self.whole.body_count()];
        for (gid, body, _, _) in all.into_iter().flatten() {
            bodies[gid] = Some(body);
        }
        Ok(bodies
            .into_iter()
            .map(|b| b.expect("every body is owned once"))
            .collect())
    }

    fn exchange_ghosts(&mut self) {
        let part = &mut self.part;
        let (bodies, loads) = (part.world.bodies(), part.world.loads());
        let blocks: Vec<Vec<Real>> = part
            .sends
            .iter()
            .map(|list| {
                let mut block = Vec::with_capacity(list.len() * GHOST_WORDS);
                for &i in list {
                    pack_ghost(
                        &bodies[i],
                        &loads.forces()[i],
                        &loads.torques()[i],
                        &mut block,
                    );
                }
                block
            })
            .collect();
        let expected: Vec<usize> = part
            .receives
            .iter()
            .map(|l| l.len() * GHOST_WORDS)
            .collect();
        let received =
            exchange_ghost_states(&self.comm, &blocks, &expected, &mut self.traffic.ghosts);
        let ghosts = part.receives.iter().flatten();
        for (&i, w) in ghosts.zip(received.chunks_exact(GHOST_WORDS)) {
            let (body, force, torque) = unpack_ghost(&part.world.bodies()[i], w);
            part.world.copy_body_from_owner(i, &body, &force, &torque);
        }
    }

    /// Before a cut, one all-reduce of maxima: refuses to go on when a body moved beyond the ghost layer's
    /// allowance since the last cut; tells whether the owned counts are too uneven to migrate again (every
    /// rank answers alike), and, for a migration, each rank's largest owned body after it and the new
    /// owners of this rank's bodies (found here once, and sent with the bodies).
    fn check_before_cut(&self) -> Result<NextCut, DistributedError> {
        let part = &self.part;
        let owned = (0..part.ids.len()).filter(|&i| part.owns(i));
        let moved = owned
            .zip(&part.at_cut)
            .map(|(i, then)| (part.world.bodies()[i].position - then).norm())
            .fold(0.0, Real::max);
        let ranks = self.comm.size() as usize;
        let mut mine = vec![0.0; 2 + ranks];
        mine[0] = moved;
        mine[1] = part.at_cut.len() as Real;
        let cuts = &part.holding.cuts;
        let mut owners = Vec::with_capacity(part.at_cut.len());
        let mut unowned = None;
        for i in (0..part.ids.len()).filter(|&i| part.owns(i)) {
            match cuts.owner_of(&part.world.bodies()[i].position, part.ids[i]) {
                Ok(q) => {
                    mine[2 + q] = Real::max(mine[2 + q], part.world.radii()[i]);
                    owners.push(q as u32);
                }
                // Refused after the all-reduce, which every rank must join.
                Err(e) => unowned = unowned.or(Some(e)),
            }
        }
        let mut largest = vec![0.0; mine.len()];
        self.comm
            .all_reduce_into(&mine[..], &mut largest[..], SystemOperation::max());
        if let Some(e) = unowned {
            return Err(e);
        }
        let allowance = MOVE_ALLOWANCE_IN_SKINS * self.whole.broad_phase().skin();
        if largest[0] > allowance {
            return Err(DistributedError::HaloExceeded {
                moved: largest[0],
                allowance,
            });
        }
        let mean = self.whole.body_count() as Real / ranks as Real;
        Ok(match largest[1] > self.rebalance_above * mean {
            true => NextCut::Bisect,
            false => NextCut::Migrate {
                largest_owned: largest.split_off(2),
                owners,
            },
        })
    }
}

type OwnedBody = (usize, RigidBody, Vector, Vector);

fn owned_bodies(part: &Part) -> Vec<OwnedBody> {
    let (bodies, loads) = (part.world.bodies(), part.world.loads());
    (0..part.ids.len())
        .filter(|&i| part.owns(i))
        .map(|i| {
            (
                part.ids[i],
                bodies[i],
                loads.forces()[i],
                loads.torques()[i],
            )
        })
        .collect()
}

/// The part's contact entries this rank answers for, with global keys: a body pair where it owns the body
/// of lower index, a body–wall pair where it owns the body. Every pair of the whole list is computed,
/// with its full history, on the rank that owns its lower body.
pub(crate) fn authoritative_contacts(part: &Part) -> Vec<(ContactKey, ContactState)> {
    let store = part.world.contacts();
    let global = |i: u32| part.ids[i as usize] as u32;
    store
        .keys()
        .iter()
        .zip(store.states())
        .filter_map(|(key, state)| match *key {
            ContactKey::Body { a, b } => part.owns(a as usize).then(|| {
                let key = ContactKey::Body {
                    a: global(a),
                    b: global(b),
                };
                (key, *state)
            }),
            ContactKey::Wall { body, wall } => part.owns(body as usize).then(|| {
                let key = ContactKey::Wall {
                    body: global(body),
                    wall,
                };
                (key, *state)
            }),
        })
        .collect()
}

/// This rank's part of `whole` cut by the plan of `centres` (the positions of the whole world's last list
/// build), with its broad phase as `broad_phase` says.
fn cut(
    comm: &SimpleCommunicator,
    whole: &World,
    centres: &[Point],
    broad_phase: PartBroadPhase,
) -> Result<Part, DistributedError> {
    let (rank, size) = (comm.rank() as usize, comm.size() as usize);
    let plan = Plan::new(centres, whole.radii(), whole.broad_phase().skin(), size)?;
    let ids = plan.parts[rank].clone();
    let local = |gid: &usize| ids.binary_search(gid).expect("held by the plan");
    let to_local = |lists: Vec<Vec<usize>>| -> Vec<Vec<usize>> {
        lists
            .into_iter()
            .map(|l| l.iter().map(local).collect())
            .collect()
    };
    let owned: Vec<bool> = ids
        .iter()
        .map(|&i| plan.decomposition.owner[i] as usize == rank)
        .collect();
    let mut world = whole.part(&ids, broad_phase);
    world.keep_pairs_of_owned(&owned);
    let (sends, receives) = (to_local(plan.sends(rank)), to_local(plan.receives(rank)));
    let at_cut = (0..ids.len()).filter(|&i| owned[i]);
    let at_cut = at_cut.map(|i| centres[ids[i]]).collect();
    Ok(Part::new(
        world,
        ids,
        owned,
        sends,
        receives,
        plan.holding,
        at_cut,
    ))
}

/// What a caller reads of the whole run between steps: one body's facts from its owner, the whole world.
impl DistributedRun {
    /// `read(part, local)` evaluated on the rank that owns global body `gid` (`local`: the body's index in
    /// that rank's part world, whose contact store holds every pair of the body, as one process's does),
    /// handed to every rank bit for bit. One all-gather (counted with the gathers).
    pub fn from_owner<T: serde::Serialize + serde::de::DeserializeOwned>(
        &mut self,
        gid: usize,
        read: impl FnOnce(&World, usize) -> T,
    ) -> Result<T, DistributedError> {
        let part = &self.part;
        let local = part.ids.binary_search(&gid).ok();
        let mine = local
            .filter(|&i| part.owns(i))
            .map(|i| read(&part.world, i));
        let all = all_gather(&self.comm, &mine, &mut self.traffic.gathers)?;
        Ok(all
            .into_iter()
            .flatten()
            .next()
            .expect("every body is owned once"))
    }

    /// The whole world at the current step, on every rank: every body's state and loads from its owner,
    /// every contact entry from the rank that answers for it, the walls and clock, the energy ledger and
    /// sums added over the ranks' shares in rank order. The per-body state and the contact store are one
    /// process's bit for bit, and so are the walls' forces (summed from the touching entries in key
    /// order, as the step sums them); the energy sums are one process's up to rounding (grouped by part).
    pub fn gather_world(&mut self) -> Result<World, DistributedError> {
        if self.fresh {
            return Ok(self.whole.clone());
        }
        let share = self.part.world.energy_share();
        let mine = (
            owned_bodies(&self.part),
            authoritative_contacts(&self.part),
            share,
        );
        let all = all_gather(&self.comm, &mine, &mut self.traffic.gathers)?;
        let mut whole = self.whole.clone();
        whole.copy_walls_and_clock(&self.part.world);
        let mut entries = Vec::new();
        let mut total = EnergyShare::default();
        for (bodies, contacts, share) in all {
            for (gid, body, force, torque) in bodies {
                whole.copy_body_from_owner(gid, &body, &force, &torque);
            }
            entries.extend(contacts);
            total.add(&share);
        }
        entries.sort_by_key(|entry| entry.0);
        let walls = wall_forces(&touching_walls(&entries), whole.walls().len());
        whole.replace_wall_forces(walls);
        whole.replace_contacts(entries, self.part.world.contacts().last_touched());
        whole.replace_energy_share(&total);
        Ok(whole)
    }
}
