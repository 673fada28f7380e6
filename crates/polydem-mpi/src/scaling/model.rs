//! The cost of one distributed step, T(P, N), from measured per-body costs and a network's latency and
//! bandwidth (the α–β model: a message of b bytes takes α + b/β).
//!
//! With n = N/P bodies per rank in a cube of side a = n^{1/3} lattice spacings (recursive bisection of a
//! compact scene gives near-cubic subdomains), an interior rank holds g = (a + 2w)³ − a³ ghosts for a
//! ghost layer of w spacings and exchanges with the 26 neighbours of a cube (more when the layer is wider
//! than a subdomain). The slowest rank sets the step's pace, so the interior rank is the one modelled.
//!
//! T = t_c (n + g)                                   compute: ghosts are stepped with the owned bodies
//!   + m α + 152 g / β                               ghost exchange: 19 f64 per ghost, m neighbours
//!   + ⌈log₂P⌉ (α + 32 / β)                          rebuild agreement: an all-reduce of 4 f64, ⌈log₂P⌉ rounds
//!   + C / k                                         a cut every k steps, costing C:
//!
//! - [`Migration::Neighbours`], what the crate does: bodies and contact entries move to the near ranks
//!   only (one message each way), each rank assembles its own part, and one all-reduce checks the moves
//!   and the balance: C = m α + b g / β + ⌈log₂P⌉ α + (t_cut + t_plan)(n + g).
//! - [`Migration::WholeWorld`], a whole-world cut at every rebuild (the crate's first design): every rank
//!   gathers the whole state and cuts it again, C = ⌈log₂P⌉ α + b N (P − 1)/P / β + t_cut N + t_plan N P. The last term is the plan: every
//!   rank computes every rank's part (P regions × N centres).

use crate::scaling::record::RunFigures;

/// Bytes per ghost in the exchange after each step (19 f64: `exchange::GHOST_WORDS`).
pub const GHOST_BYTES: f64 = 152.0;
/// Bytes each rank hands to a rebuild agreement's all-reduce (four f64).
pub const AGREEMENT_BYTES: f64 = 32.0;

/// A network in the α–β model.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Network {
    /// Time of an empty message, α (s).
    pub latency_s: f64,
    /// Bytes per second for long messages, β.
    pub bandwidth: f64,
}

impl Network {
    /// The time of one message of `bytes`.
    pub fn message(&self, bytes: f64) -> f64 {
        self.latency_s + bytes / self.bandwidth
    }
}

/// The measured per-body costs of one scene.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Calibration {
    /// Wall time of a step without a cut per body (s), on one rank.
    pub compute_s_per_body_step: f64,
    /// The ghost layer's width in lattice spacings.
    pub ghost_width_spacings: f64,
    /// Steps between cuts (list rebuilds).
    pub steps_per_cut: f64,
    /// The extra wall time of a step with a cut, per body of the world (s), on one rank.
    pub cut_s_per_body: f64,
    /// Bytes per body in the state gathered at a cut (bodies and contact entries, encoded).
    pub cut_bytes_per_body: f64,
    /// Time of the plan per body and rank (s).
    pub plan_s_per_body_rank: f64,
}

/// How bodies change ranks at a cut.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Migration {
    /// Every rank gathers the whole world at every cut (the first design).
    WholeWorld,
    /// Bodies move to neighbouring ranks only (today's cut).
    Neighbours,
}

/// What one rank holds and talks to.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Subdomain {
    /// Bodies owned.
    pub owned: f64,
    /// Ghosts held (and, by symmetry, owned bodies sent).
    pub ghosts: f64,
    /// Ranks it exchanges ghosts with.
    pub neighbours: f64,
}

/// The interior subdomain of `bodies` on `ranks` with a ghost layer of `width` spacings.
pub fn interior_subdomain(bodies: f64, ranks: usize, width: f64) -> Subdomain {
    let owned = bodies / ranks as f64;
    if ranks == 1 {
        return Subdomain {
            owned,
            ghosts: 0.0,
            neighbours: 0.0,
        };
    }
    let side = owned.cbrt();
    let ghosts = (side + 2.0 * width).powi(3) - owned;
    let layers = (width / side).ceil();
    let around = (2.0 * layers + 1.0).powi(3) - 1.0;
    Subdomain {
        owned,
        ghosts,
        neighbours: around.min(ranks as f64 - 1.0),
    }
}

/// The parts of one step's time (s).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StepCost {
    /// Stepping the owned bodies and the ghosts.
    pub compute: f64,
    /// The ghost exchange.
    pub halo: f64,
    /// The rebuild agreement.
    pub agreement: f64,
    /// The cut, spread over the steps between cuts.
    pub cut: f64,
}

impl StepCost {
    /// The whole step.
    pub fn total(&self) -> f64 {
        self.compute + self.halo + self.agreement + self.cut
    }
}

fn rounds(ranks: usize) -> f64 {
    (ranks as f64).log2().ceil()
}

/// The step's time for `bodies` on `ranks` with the subdomain `sub`.
pub fn step_cost_of(
    cal: &Calibration,
    net: &Network,
    bodies: f64,
    ranks: usize,
    sub: Subdomain,
    migration: Migration,
) -> StepCost {
    let compute = cal.compute_s_per_body_step * (sub.owned + sub.ghosts);
    if ranks == 1 {
        let cut = (cal.cut_s_per_body + cal.plan_s_per_body_rank) * bodies;
        return StepCost {
            compute,
            halo: 0.0,
            agreement: 0.0,
            cut: cut / cal.steps_per_cut,
        };
    }
    let (alpha, beta, p) = (net.latency_s, net.bandwidth, ranks as f64);
    let halo = sub.neighbours * alpha + GHOST_BYTES * sub.ghosts / beta;
    let agreement = rounds(ranks) * (alpha + AGREEMENT_BYTES / beta);
    let cut = match migration {
        Migration::WholeWorld => {
            rounds(ranks) * alpha
                + cal.cut_bytes_per_body * bodies * (p - 1.0) / p / beta
                + cal.cut_s_per_body * bodies
                + cal.plan_s_per_body_rank * bodies * p
        }
        Migration::Neighbours => {
            sub.neighbours * alpha
                + cal.cut_bytes_per_body * sub.ghosts / beta
                + rounds(ranks) * alpha
                + (cal.cut_s_per_body + cal.plan_s_per_body_rank) * (sub.owned + sub.ghosts)
        }
    };
    StepCost {
        compute,
        halo,
        agreement,
        cut: cut / cal.steps_per_cut,
    }
}

/// The step's time for `bodies` on `ranks`, the interior subdomain of a compact scene.
pub fn step_cost(
    cal: &Calibration,
    net: &Network,
    bodies: f64,
    ranks: usize,
    migration: Migration,
) -> StepCost {
    let sub = interior_subdomain(bodies, ranks, cal.ghost_width_spacings);
    step_cost_of(cal, net, bodies, ranks, sub, migration)
}

/// The strong-scaling efficiency from `base` to `ranks` ranks: T(base)·base / (T(ranks)·ranks).
pub fn strong_efficiency(
    cal: &Calibration,
    net: &Network,
    bodies: f64,
    base: usize,
    ranks: usize,
    migration: Migration,
) -> f64 {
    let t = |p: usize| step_cost(cal, net, bodies, p, migration).total() * p as f64;
    t(base) / t(ranks)
}

/// The wall time of a step without a cut, and the extra time of a step with one (s).
pub fn step_times(run: &RunFigures) -> Option<(f64, f64)> {
    let plain_steps = run.steps.checked_sub(run.cut_steps).filter(|&s| s > 0)?;
    let plain = (run.wall_s - run.cut_wall_s) / plain_steps as f64;
    let cut = (run.cut_steps > 0).then(|| run.cut_wall_s / run.cut_steps as f64 - plain)?;
    Some((plain, cut))
}

/// The calibration of a scene from its one-rank run `one` (the larger world), a run `many` on several
/// ranks (for the bytes of a cut) and the measured plan cost per body and rank.
pub fn calibrate(
    one: &RunFigures,
    many: &RunFigures,
    plan_s_per_body_rank: f64,
) -> Option<Calibration> {
    let (plain, cut) = step_times(one)?;
    if many.cut_steps == 0 || many.ranks < 2 {
        return None;
    }
    let n = one.bodies as f64;
    // Each rank sends its share (about b N / P) to the P − 1 others at every cut.
    let cut_bytes_total = many.per_step[2].0 * many.steps as f64;
    let cut_bytes_per_body =
        cut_bytes_total / (many.cut_steps as f64 * many.bodies as f64 * (many.ranks as f64 - 1.0));
    Some(Calibration {
        compute_s_per_body_step: plain / n,
        ghost_width_spacings: one.ghost_width_spacings,
        steps_per_cut: one.steps as f64 / one.cut_steps as f64,
        cut_s_per_body: (cut / n).max(0.0),
        cut_bytes_per_body,
        plan_s_per_body_rank,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::plan::{ghost_width, Plan};
    use polydem::math::Point;

    #[test]
    fn an_interior_cube_of_8000_bodies_with_a_layer_of_one_spacing_has_the_shell_of_side_22() {
        // 64 ranks of 20³ bodies: the shell between the cubes of side 20 and 20 + 2·1 spacings.
        let sub = interior_subdomain(64.0 * 8000.0, 64, 1.0);
        let shell = 22.0_f64 * 22.0 * 22.0 - 20.0 * 20.0 * 20.0;
        assert!(
            (sub.ghosts - shell).abs() < 1e-9 * shell,
            "ghosts {} for 8000 bodies per rank, width 1: expected {shell}",
            sub.ghosts
        );
        assert_eq!(
            sub.neighbours, 26.0,
            "a cube's face, edge and corner neighbours"
        );
        let two = interior_subdomain(16.0, 2, 5.0);
        assert_eq!(two.neighbours, 1.0, "two ranks: one neighbour at most");
        let one = interior_subdomain(1000.0, 1, 1.0);
        assert_eq!(
            (one.ghosts, one.neighbours),
            (0.0, 0.0),
            "one rank: no halo"
        );
    }

    /// Two ranks on a lattice 2m × m × m of unit spacing are cut halfway between the lattice planes
    /// x = m − 1 and x = m; the ghosts one rank sends are the m² sites of each plane nearer the cut than
    /// the ghost width. The slab estimate m² w of the model is within one plane of that count.
    #[test]
    fn the_ghosts_of_a_two_rank_lattice_are_the_planes_within_the_ghost_width_of_the_cut() {
        let m = 6;
        let centres: Vec<Point> = (0..2 * m * m * m)
            .map(|k| {
                Point::new(
                    (k % (2 * m)) as f64,
                    ((k / (2 * m)) % m) as f64,
                    (k / (2 * m * m)) as f64,
                )
            })
            .collect();
        let (radius, skin) = (0.45, 0.2);
        let width = ghost_width(radius, skin);
        let plan = Plan::new(&centres, &vec![radius; centres.len()], skin, 2).expect("plan");
        let sent = plan.sends(0)[1].len();
        let planes = (0..m).filter(|&j| j as f64 + 0.5 < width).count();
        assert_eq!(
            sent,
            planes * m * m,
            "ghost width {width}: {sent} sent, expected {planes} planes of {} sites",
            m * m
        );
        let slab = (m * m) as f64 * width;
        assert!(
            (slab - sent as f64).abs() <= (m * m) as f64,
            "slab estimate {slab} against {sent} sent: more than one plane ({}) apart",
            m * m
        );
        let bytes = GHOST_BYTES * sent as f64;
        assert_eq!(
            bytes,
            152.0 * (planes * m * m) as f64,
            "bytes per step of rank 0's ghosts"
        );
    }

    #[test]
    fn one_rank_pays_no_communication_and_the_whole_world_cut_grows_with_the_ranks() {
        let cal = Calibration {
            compute_s_per_body_step: 1e-7,
            ghost_width_spacings: 1.3,
            steps_per_cut: 20.0,
            cut_s_per_body: 1e-7,
            cut_bytes_per_body: 300.0,
            plan_s_per_body_rank: 1e-9,
        };
        let net = Network {
            latency_s: 2e-6,
            bandwidth: 1e10,
        };
        let one = step_cost(&cal, &net, 1e6, 1, Migration::WholeWorld);
        assert_eq!((one.halo, one.agreement), (0.0, 0.0), "one rank: {one:?}");
        let expected = 1e-7 * 1e6 + (1e-7 + 1e-9) * 1e6 / 20.0;
        assert!(
            (one.total() - expected).abs() < 1e-12 * expected,
            "{one:?}, expected total {expected}"
        );
        let whole = step_cost(&cal, &net, 1e6, 1024, Migration::WholeWorld);
        let local = step_cost(&cal, &net, 1e6, 1024, Migration::Neighbours);
        assert_eq!(whole.compute, local.compute, "the same compute");
        assert!(
            whole.cut > 100.0 * local.cut,
            "whole-world cut {} s per step against neighbour-only {} s",
            whole.cut,
            local.cut
        );
    }
}
