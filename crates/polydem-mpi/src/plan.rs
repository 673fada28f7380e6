//! Which bodies each rank holds: the ones it owns and the ghosts within reach of its subdomain.
//!
//! A candidate pair is within `r_a + r_b + skin ≤ 2 r_max + skin` at the list build. The parts are cut at a
//! build (the state the whole world's list was built at), and the next build happens before any body has
//! moved more than about the skin (`polydem::world::broad_phase`); the step that builds it may add one
//! step's move. A ghost layer of `2 r_max + skin + 2 a` with an allowance `a` = 1.5 skin per body therefore
//! holds, at every step until the next cut, every body that can pair with an owned body; the run checks the
//! allowance at each cut ([`crate::error::DistributedError::HaloExceeded`]).

use polydem::math::{Point, Real};

use crate::decomposition::{bisect, Decomposition};
use crate::error::DistributedError;

/// The move (in skins) a body may make between two cuts of the subdomains.
pub const MOVE_ALLOWANCE_IN_SKINS: Real = 1.5;

/// The width (m) of the ghost layer around each subdomain for bodies of bounding radius up to `r_max` (m).
pub fn ghost_width(r_max: Real, skin: Real) -> Real {
    2.0 * r_max + skin + 2.0 * MOVE_ALLOWANCE_IN_SKINS * skin
}

/// The bodies of each rank's part.
#[derive(Clone, Debug, PartialEq)]
pub struct Plan {
    /// The subdomains and owners.
    pub decomposition: Decomposition,
    /// Global indices of the bodies of each rank's part (owned and ghosts), increasing.
    pub parts: Vec<Vec<usize>>,
    /// The width (m) of the ghost layer around each subdomain ([`ghost_width`]).
    pub ghost_width: Real,
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
        let r_max = radii.iter().copied().fold(0.0, Real::max);
        let width = ghost_width(r_max, skin);
        let parts = decomposition
            .regions
            .iter()
            .enumerate()
            .map(|(rank, region)| {
                let held = |i: &usize| {
                    decomposition.owner[*i] as usize == rank
                        || region.distance(&centres[*i]) < width
                };
                (0..centres.len()).filter(held).collect()
            })
            .collect();
        Ok(Self {
            decomposition,
            parts,
            ghost_width: width,
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

    #[test]
    fn what_one_rank_sends_another_is_what_that_rank_receives_and_every_part_holds_all_near_pairs()
    {
        let centres: Vec<Point> = (0..200)
            .map(|k| {
                let t = k as Real;
                Point::new((t * 0.37).sin() * 3.0, (t * 0.11).cos() * 2.0, t * 0.01)
            })
            .collect();
        let radii = vec![0.1; centres.len()];
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
}
