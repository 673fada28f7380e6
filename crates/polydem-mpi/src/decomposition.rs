//! Spatial subdomains by recursive coordinate bisection, balanced by body count.
//!
//! The set of body centres is cut at the median along the axis of its largest extent, the ranks are split in
//! proportion (⌈P/2⌉ on the lower side), and each half is cut again until one rank is left. Ties are broken
//! by global index, so every process that cuts the same positions gets the same subdomains. Each rank's
//! region is a box bounded by its cuts and open to infinity on the sides no cut bounds, so every point of
//! space belongs to one region (bodies leaving the scene's bounds stay owned).
//!
//! A body on a cutting plane (a lattice's layer, or a centre the midpoint rounds onto) belongs to the side
//! its key (coordinate, global index) sorts into, against the key of the first body above the cut: the
//! rule the bisection splits by, kept with the region ([`Region::owns`]), so a later migration within the
//! same subdomains leaves such a body where the bisection put it.

use polydem::math::{Point, Real};

use crate::error::DistributedError;

/// A body's key along one axis: its coordinate (m), then its global index.
pub type Key = (Real, u32);

/// An axis-aligned box, possibly unbounded (infinite bounds).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Region {
    /// Lower corner (m).
    pub min: [Real; 3],
    /// Upper corner (m).
    pub max: [Real; 3],
    /// Per axis, the key of the first body above the cut at `min` (a body on that plane is inside when
    /// its key is not below it).
    pub min_first: [Key; 3],
    /// Per axis, the key of the first body above the cut at `max` (a body on that plane is inside when
    /// its key is below it).
    pub max_first: [Key; 3],
}

impl Region {
    /// All of space.
    pub fn everything() -> Self {
        Self {
            min: [Real::NEG_INFINITY; 3],
            max: [Real::INFINITY; 3],
            min_first: [(Real::NEG_INFINITY, 0); 3],
            max_first: [(Real::INFINITY, 0); 3],
        }
    }

    /// Whether body `gid` with its centre at `x` belongs to the region (false for a non-finite centre).
    pub fn owns(&self, x: &Point, gid: u32) -> bool {
        let below = |x: Real, plane: Real, first: Key| x < plane || x == plane && (x, gid) < first;
        (0..3).all(|axis| {
            let x = x[axis];
            x.is_finite()
                && !below(x, self.min[axis], self.min_first[axis])
                && below(x, self.max[axis], self.max_first[axis])
        })
    }

    /// The distance (m) from `p` to the region (0 inside).
    pub fn distance(&self, p: &Point) -> Real {
        let mut sq = 0.0;
        for axis in 0..3 {
            let x = p[axis];
            let gap = (self.min[axis] - x).max(x - self.max[axis]).max(0.0);
            sq += gap * gap;
        }
        sq.sqrt()
    }
}

/// The subdomain of each rank and the owner of each body.
#[derive(Clone, Debug, PartialEq)]
pub struct Decomposition {
    /// Region of each rank.
    pub regions: Vec<Region>,
    /// The cuts that made the regions, to find a point's owner in O(log P).
    pub cuts: Cuts,
    /// Owning rank of each body (by global index).
    pub owner: Vec<u32>,
}

/// One cut of the bisection: the bodies whose key along `axis` sorts below `first_above` go to the
/// lower ⌈count/2⌉ of the node's ranks.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Cut {
    axis: usize,
    plane: Real,
    first_above: Key,
}

/// The bisection's cuts in pre-order (a node, its lower subtree, its upper subtree): P − 1 cuts for P
/// ranks. The owner of a point is found by walking down them, the same rule as [`Region::owns`] asked
/// of every region, in O(log P) instead of O(P).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Cuts {
    nodes: Vec<Cut>,
}

impl Cuts {
    /// The rank that owns body `gid` with its centre at `x` (a non-finite centre lies in no region).
    pub fn owner_of(&self, x: &Point, gid: usize) -> Result<usize, DistributedError> {
        if !(0..3).all(|axis| x[axis].is_finite()) {
            return Err(DistributedError::NotFinite { body: gid });
        }
        let (mut node, mut first, mut count) = (0, 0, self.nodes.len() + 1);
        while count > 1 {
            let cut = &self.nodes[node];
            let lower_ranks = count.div_ceil(2);
            let coordinate = x[cut.axis];
            let below = coordinate < cut.plane
                || coordinate == cut.plane && (coordinate, gid as u32) < cut.first_above;
            if below {
                node += 1;
                count = lower_ranks;
            } else {
                // The lower subtree has lower_ranks − 1 cuts.
                node += lower_ranks;
                first += lower_ranks;
                count -= lower_ranks;
            }
        }
        Ok(first)
    }
}

/// Cuts the bodies at `centres` into `ranks` subdomains of nearly equal body counts.
pub fn bisect(centres: &[Point], ranks: usize) -> Result<Decomposition, DistributedError> {
    if ranks == 0 || ranks > centres.len().max(1) {
        return Err(DistributedError::TooManyRanks {
            ranks,
            bodies: centres.len(),
        });
    }
    let mut ids: Vec<usize> = (0..centres.len()).collect();
    let mut made = Decomposition {
        regions: vec![Region::everything(); ranks],
        cuts: Cuts::default(),
        owner: vec![0u32; centres.len()],
    };
    cut(centres, &mut ids, 0, ranks, Region::everything(), &mut made);
    Ok(made)
}

/// Cuts the bodies `ids` inside `region` among ranks `first..first + count`, adding the regions, cuts
/// and owners to `made`.
fn cut(
    centres: &[Point],
    ids: &mut [usize],
    first: usize,
    count: usize,
    region: Region,
    made: &mut Decomposition,
) {
    if count == 1 {
        made.regions[first] = region;
        for &i in ids.iter() {
            made.owner[i] = first as u32;
        }
        return;
    }
    let axis = widest_axis(centres, ids);
    let lower_ranks = count.div_ceil(2);
    let key = |i: &usize| (centres[*i][axis], *i);
    ids.sort_by(|a, b| key(a).partial_cmp(&key(b)).expect("finite centres"));
    let split = ids.len() * lower_ranks / count;
    // The plane halfway between the last body below and the first above (both exist: each side keeps at
    // least one body per rank since P ≤ bodies).
    let plane = match (split.checked_sub(1).map(|k| ids[k]), ids.get(split)) {
        (Some(lo), Some(&hi)) => 0.5 * (centres[lo][axis] + centres[hi][axis]),
        _ => region.min[axis].max(region.max[axis].min(0.0)),
    };
    // The midpoint lies in [lo, hi], so the bodies below sort below the first above, those above not.
    let first_above = ids
        .get(split)
        .map_or((Real::INFINITY, 0), |&hi| (centres[hi][axis], hi as u32));
    made.cuts.nodes.push(Cut {
        axis,
        plane,
        first_above,
    });
    let (mut lower, mut upper) = (region, region);
    lower.max[axis] = plane;
    lower.max_first[axis] = first_above;
    upper.min[axis] = plane;
    upper.min_first[axis] = first_above;
    let (below, above) = ids.split_at_mut(split);
    cut(centres, below, first, lower_ranks, lower, made);
    let upper_ranks = count - lower_ranks;
    cut(
        centres,
        above,
        first + lower_ranks,
        upper_ranks,
        upper,
        made,
    );
}

/// The axis along which the centres `ids` spread most (the first such axis on a tie).
fn widest_axis(centres: &[Point], ids: &[usize]) -> usize {
    let extent = |axis: usize| {
        let values = ids.iter().map(|&i| centres[i][axis]);
        let lo = values.clone().fold(Real::INFINITY, Real::min);
        let hi = values.fold(Real::NEG_INFINITY, Real::max);
        hi - lo
    };
    let extents = [extent(0), extent(1), extent(2)];
    let mut best = 0;
    for axis in 1..3 {
        if extents[axis] > extents[best] {
            best = axis;
        }
    }
    best
}

#[cfg(test)]
mod tests {
    use super::*;

    fn lattice(n: usize) -> Vec<Point> {
        (0..n * n * n)
            .map(|k| {
                Point::new(
                    (k % n) as Real,
                    ((k / n) % n) as Real,
                    (k / (n * n)) as Real,
                )
            })
            .collect()
    }

    #[test]
    fn every_rank_gets_a_near_equal_share_and_owns_the_bodies_inside_its_region() {
        let centres = lattice(7);
        for ranks in 1..=7 {
            let d = bisect(&centres, ranks).expect("P ≤ bodies");
            let mut counts = vec![0usize; ranks];
            for (i, &r) in d.owner.iter().enumerate() {
                counts[r as usize] += 1;
                let inside = d.regions[r as usize].distance(&centres[i]);
                assert_eq!(
                    inside, 0.0,
                    "P {ranks}: body {i} at {:?} is outside its region {:?}",
                    centres[i], d.regions[r as usize]
                );
                // The lattice puts whole layers on the cutting planes: the region rule must split them
                // as the bisection did.
                let by_rule = owner_by_regions(&d.regions, &centres[i], i);
                assert_eq!(
                    by_rule,
                    Some(r as usize),
                    "P {ranks}: body {i} at {:?} (on a plane of {:?}) owned by {r} after the bisection, \
                     by {by_rule:?} under the regions' rule",
                    centres[i], d.regions[r as usize]
                );
                let by_cuts = d.cuts.owner_of(&centres[i], i).expect("finite centre");
                assert_eq!(
                    by_cuts, r as usize,
                    "P {ranks}: body {i} at {:?} owned by {r} after the bisection, by {by_cuts} down \
                     the cuts {:?}",
                    centres[i], d.cuts
                );
            }
            let (lo, hi) = (counts.iter().min().unwrap(), counts.iter().max().unwrap());
            assert!(
                hi - lo <= 1 + centres.len() / 32,
                "P {ranks}: shares {counts:?} of {} bodies differ by more than {}",
                centres.len(),
                1 + centres.len() / 32
            );
        }
    }

    /// The regions' rule asked of every region: the rank of the one region that owns the body.
    fn owner_by_regions(regions: &[Region], x: &Point, gid: usize) -> Option<usize> {
        let owning: Vec<usize> = (0..regions.len())
            .filter(|&q| regions[q].owns(x, gid as u32))
            .collect();
        assert!(
            owning.len() <= 1,
            "body {gid} at {x:?} lies in regions {owning:?}"
        );
        owning.first().copied()
    }

    /// Walking down the cuts gives the rank the regions' rule gives, for any point of space: on the
    /// lattice's planes (any global index), between them, far outside the bodies; and no rank for a
    /// non-finite centre.
    #[test]
    fn the_cuts_find_the_owner_the_regions_give() {
        let centres = lattice(7);
        let probes = [-1e9, -0.5, 0.0, 1.0, 2.5, 3.0, 3.5, 6.0, 1e9];
        for ranks in 1..=7 {
            let d = bisect(&centres, ranks).expect("P ≤ bodies");
            assert_eq!(
                d.cuts.nodes.len(),
                ranks - 1,
                "P {ranks}: cuts {:?}",
                d.cuts
            );
            let mut points = Vec::new();
            for &x in &probes {
                for &y in &probes {
                    points.extend(probes.iter().map(|&z| Point::new(x, y, z)));
                }
            }
            for (k, x) in points.into_iter().enumerate() {
                for gid in [0, k % 343, 171, 342, 1000] {
                    let by_cuts = d.cuts.owner_of(&x, gid).ok();
                    let by_rule = owner_by_regions(&d.regions, &x, gid);
                    assert_eq!(
                        by_cuts, by_rule,
                        "P {ranks}: body {gid} at {x:?}: {by_cuts:?} down the cuts {:?}, {by_rule:?} \
                         under the regions {:?}",
                        d.cuts, d.regions
                    );
                }
            }
            for bad in [Real::NAN, Real::INFINITY] {
                let x = Point::new(1.0, bad, 2.0);
                let err = d.cuts.owner_of(&x, 5).expect_err("non-finite centre");
                assert!(
                    matches!(err, DistributedError::NotFinite { body: 5 }),
                    "{err}"
                );
            }
        }
    }

    #[test]
    fn more_ranks_than_bodies_is_refused() {
        let err = bisect(&lattice(1), 2).expect_err("1 body, 2 ranks");
        assert!(
            matches!(
                err,
                DistributedError::TooManyRanks {
                    ranks: 2,
                    bodies: 1
                }
            ),
            "{err}"
        );
    }
}
