//! Which bodies each rank holds: the ones it owns and the ghosts within reach of its subdomain.
//!
//! A candidate pair (i, j) is within `r_i + r_j + skin` at the list build. The parts are cut at a build (the
//! state the whole world's list was built at), and the next build happens before any body has moved more
//! than about the skin (`polydem::world::broad_phase`); the step that builds it may add one step's move.
//! With an allowance `a` = 1.5 skin per body between two cuts, a rank whose owned bodies have bounding
//! radii up to `R` therefore needs, at every step until the next cut, every body j whose centre lies within
//! `r_j + R + skin + 2a` of its subdomain ([`Holding`]); the run checks the allowance at each cut
//! ([`crate::error::DistributedError::HaloExceeded`]). The layer follows each rank's own bodies: one large
//! body (a projectile) widens the layer of the rank that owns it and its own reach, not every rank's.

use polydem::math::{Point, Real};

use crate::decomposition::{bisect, Cuts, Decomposition, Region};
use crate::error::DistributedError;

/// The move (in skins) a body may make between two cuts of the subdomains.
pub const MOVE_ALLOWANCE_IN_SKINS: Real = 1.5;

/// The widest ghost layer (m) around a subdomain for bodies of bounding radius up to `r_max` (m): the reach
/// of a pair of the largest bodies ([`Holding::reach`] at its widest).
pub fn ghost_width(r_max: Real, skin: Real) -> Real {
    2.0 * r_max + margin(skin)
}

/// What a pair's reach adds to its two bounding radii (m): the skin and both bodies' allowances.
fn margin(skin: Real) -> Real {
    skin + 2.0 * MOVE_ALLOWANCE_IN_SKINS * skin
}

/// The rule of which ranks hold a body: its owner, and every rank whose subdomain lies within reach of the
/// body for the largest body that rank owns.
#[derive(Clone, Debug, PartialEq)]
pub struct Holding {
    /// Every rank's subdomain.
    pub regions: Vec<Region>,
    /// The cuts that made them: the owner of a point in O(log P).
    pub cuts: Cuts,
    /// Per rank, the largest bounding radius (m) of the bodies it owns (0 when it owns none).
    pub largest_owned: Vec<Real>,
    /// The skin (m) of the world's list.
    pub skin: Real,
}

impl Holding {
    /// The rule for the subdomains of `decomposition`, with its owners of bodies of bounding radii
    /// `radii`.
    pub fn new(decomposition: &Decomposition, radii: &[Real], skin: Real) -> Self {
        let Decomposition {
            regions,
            cuts,
            owner,
        } = decomposition;
        let mut largest_owned = vec![0.0; regions.len()];
        for (&o, &r) in owner.iter().zip(radii) {
            let largest = &mut largest_owned[o as usize];
            *largest = Real::max(*largest, r);
        }
        Self {
            regions: regions.clone(),
            cuts: cuts.clone(),
            largest_owned,
            skin,
        }
    }

    /// How far (m) from rank `q`'s subdomain a body of bounding radius `r` is held there as a ghost.
    pub fn reach(&self, q: usize, r: Real) -> Real {
        r + self.largest_owned[q] + margin(self.skin)
    }

    /// Whether rank `q` holds a body of bounding radius `r` at `x` owned by rank `owner`.
    pub fn holds(&self, q: usize, owner: usize, x: &Point, r: Real) -> bool {
        q == owner || self.regions[q].distance(x) < self.reach(q, r)
    }
}

/// The bodies of each rank's part.
#[derive(Clone, Debug, PartialEq)]
pub struct Plan {
    /// The subdomains and owners.
    pub decomposition: Decomposition,
    /// Global indices of the bodies of each rank's part (owned and ghosts), increasing.
    pub parts: Vec<Vec<usize>>,
    /// Which ranks hold a body.
    pub holding: Holding,
}

impl Plan {
    /// Cuts the bodies at `centres` with bounding radii `radii` into `ranks` parts.
    pub fn new(
        centres: &[Point],
        radii: &[Real],
        skin: Real,
        ranks: usize,
    ) -> Result<Self, DistributedError> {
        let decomposition = bisect(centres, ranks)?;
        let owner = &decomposition.owner;
        let holding = Holding::new(&decomposition, radii, skin);
        let parts = (0..ranks)
            .map(|rank| {
                let held =
                    |&i: &usize| holding.holds(rank, owner[i] as usize, &centres[i], radii[i]);
                (0..centres.len()).filter(held).collect()
            })
            .collect();
        Ok(Self {
            decomposition,
            parts,
            holding,
        })
    }

    /// For rank `me`: per other rank, the global indices it holds that `me` owns (what `me` sends after each
    /// step), in increasing order.
    pub fn sends(&self, me: usize) -> Vec<Vec<usize>> {
        let owner = &self.decomposition.owner;
        (0..self.parts.len())
            .map(|q| {
                let mine = |i: &&usize| q != me && owner[**i] as usize == me;
                self.parts[q].iter().filter(mine).copied().collect()
            })
            .collect()
    }

    /// For rank `me`: per other rank, the global indices of `me`'s ghosts it owns (what `me` receives),
    /// in increasing order.
    pub fn receives(&self, me: usize) -> Vec<Vec<usize>> {
        let owner = &self.decomposition.owner;
        (0..self.parts.len())
            .map(|q| {
                let theirs = |i: &&usize| q != me && owner[**i] as usize == q;
                self.parts[me].iter().filter(theirs).copied().collect()
            })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Bodies on a twisted curve, radii of 0.05–0.15 m and one of 1 m (a projectile among rocks).
    fn bodies() -> (Vec<Point>, Vec<Real>) {
        let centres: Vec<Point> = (0..200)
            .map(|k| {
                let t = k as Real;
                Point::new((t * 0.37).sin() * 3.0, (t * 0.11).cos() * 2.0, t * 0.01)
            })
            .collect();
        let mut radii: Vec<Real> = (0..centres.len())
            .map(|k| 0.05 + 0.1 * ((k * 7919) % 101) as Real / 100.0)
            .collect();
        radii[57] = 1.0;
        (centres, radii)
    }

    #[test]
    fn what_one_rank_sends_another_is_what_that_rank_receives_and_every_part_holds_all_near_pairs()
    {
        let (centres, radii) = bodies();
        let skin = 0.02;
        for ranks in 1..=4 {
            let plan = Plan::new(&centres, &radii, skin, ranks).expect("plan");
            for me in 0..ranks {
                for q in 0..ranks {
                    assert_eq!(
                        plan.sends(me)[q],
                        plan.receives(q)[me],
                        "P {ranks}: {me} → {q}"
                    );
                }
                // Every pair within reach of an owned body is held.
                for &i in &plan.parts[me] {
                    if plan.decomposition.owner[i] as usize != me {
                        continue;
                    }
                    for j in 0..centres.len() {
                        let reach = radii[i] + radii[j] + skin;
                        if (centres[i] - centres[j]).norm() < reach {
                            assert!(
                                plan.parts[me].contains(&j),
                                "P {ranks}: rank {me} owns {i} but lacks {j} within {reach} m"
                            );
                        }
                    }
                }
            }
        }
    }

    /// The large body widens the layer of the rank that owns it only: the other ranks hold fewer ghosts
    /// than a layer sized by the largest body everywhere would give them.
    #[test]
    fn a_large_body_widens_only_its_owners_layer() {
        let (centres, radii) = bodies();
        let skin = 0.02;
        let plan = Plan::new(&centres, &radii, skin, 4).expect("plan");
        let owner_of_large = plan.decomposition.owner[57] as usize;
        let widest = ghost_width(1.0, skin);
        for q in (0..4).filter(|&q| q != owner_of_large) {
            let region = &plan.holding.regions[q];
            let held_by_widest = (0..centres.len())
                .filter(|&i| {
                    plan.decomposition.owner[i] as usize == q
                        || region.distance(&centres[i]) < widest
                })
                .count();
            let held = plan.parts[q].len();
            assert!(
                held < held_by_widest,
                "rank {q}: {held} bodies held, {held_by_widest} with the layer of the large body"
            );
            assert!(
                plan.holding.largest_owned[q] < 0.16,
                "rank {q} does not own the large body: largest owned {}",
                plan.holding.largest_owned[q]
            );
        }
    }
}
