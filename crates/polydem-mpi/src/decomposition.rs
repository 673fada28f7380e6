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
    /// Owning rank of each body (by global index).
    pub owner: Vec<u32>,
}

/// The rank whose subdomain owns body `gid` with its centre at `x` ([`Region::owns`]; a non-finite
/// centre lies in none).
pub fn owner_of(regions: &[Region], x: &Point, gid: usize) -> Result<usize, DistributedError> {
    let inside = regions.iter().position(|r| r.owns(x, gid as u32));
    inside.ok_or(DistributedError::NotFinite { body: gid })
}

/// Cuts the bodies at `centres` into `ranks` subdomains of nearly equal body counts.
pub fn bisect(centres: &[Point], ranks: usize) -> Result<Decomposition, DistributedError> {
    if ranks == 0 || ranks > centres.len().max(1) {
        return Err(DistributedError::TooManyRanks {
            ranks,
            bodies: centres.len(),
        });
    }
    let mut regions = vec![Region::everything(); ranks];
    let mut owner = vec![0u32; centres.len()];
    let mut ids: Vec<usize> = (0..centres.len()).collect();
    cut(
        centres,
        &mut ids,
        0,
        ranks,
        Region::everything(),
        &mut regions,
        &mut owner,
    );
    Ok(Decomposition { regions, owner })
}

/// Cuts the bodies `ids` inside `region` among ranks `first..first + count`.
fn cut(
    centres: &[Point],
    ids: &mut [usize],
    first: usize,
    count: usize,
    region: Region,
    regions: &mut [Region],
    owner: &mut [u32],
) {
    if count == 1 {
        regions[first] = region;
        for &i in ids.iter() {
            owner[i] = first as u32;
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
    let (mut lower, mut upper) = (region, region);
    lower.max[axis] = plane;
    lower.max_first[axis] = first_above;
    upper.min[axis] = plane;
    upper.min_first[axis] = first_above;
    let (below, above) = ids.split_at_mut(split);
    cut(centres, below, first, lower_ranks, lower, regions, owner);
    cut(
        centres,
        above,
        first + lower_ranks,
        count - lower_ranks,
        upper,
        regions,
        owner,
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
                let by_rule = owner_of(&d.regions, &centres[i], i).expect("finite centre");
                assert_eq!(
                    by_rule, r as usize,
                    "P {ranks}: body {i} at {:?} (on a plane of {:?}) owned by {r} after the bisection, \
                     by {by_rule} under the regions' rule",
                    centres[i], d.regions[r as usize]
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
