//! How the threads of the team share a flat step's work: the pair loop's blocks and the middles between
//! them, and the ranges of spheres of the kick and of the drift ([`Blocks`]).

use std::ops::Range;

use super::NeighbourList;

/// The split of the pair loop into one block of consecutive spheres per thread, with a middle between
/// each two neighbouring blocks, each with the pairs of its spheres' rows and their walls; and the split
/// of the per-sphere passes ([`Blocks::kick`], [`Blocks::drift`]). Made for each build of the lists.
///
/// **Blocks.** Thread k always runs block k, so that a block's records stay in one core's cache from
/// step to step ([`super::team`]). A block's pairs come in pair order, so a sphere all of whose pairs
/// lie in its own block receives its loads in the order of the stage-6 gather (pairs (a, i) by
/// increasing a, its row, its walls): the block sums them as it goes, the same bits as the gather. A
/// sphere that a pair of an earlier block or middle reaches (`gathered`) is left to the gather, whose
/// order the blocks cannot keep.
///
/// **Middles.** The spheres of the middle between blocks k and k + 1 are shared out at run time: when
/// thread k has run its block it takes pieces of the middle from the front, thread k + 1 from the back,
/// until they meet ([`super::team::TwoEnded`]). So a thread that its core runs slower for a while (a
/// shared host) does less of the middle instead of holding the other at the barrier (with blocks only,
/// the slower thread changes from run to run: `docs/tuning.md`). Every sphere of a middle is
/// gathered, since either thread may run its row: that costs its kick about two kicks' time more
/// (below), the price of the middle's size ([`TeamSplit::middle_share`]).
///
/// **Weights.** Blocks and middles are cut at equal sums of a per-sphere weight: its row's pairs and
/// its walls, a pair in contact counting [`CONTACT_WEIGHT`], plus one for the sphere itself (equal numbers of
/// pairs balance worse).
///
/// One block per thread, no more: on the settled bed of the sphere-bed scenes, whose spheres are
/// numbered by height, about 5 % of the spheres are gathered with 2 blocks, 15 % with 4, 35 % with 8
/// (counted on its initial list).
#[derive(Clone, Debug, Default)]
pub(super) struct Blocks {
    /// The lists' build and the number of blocks wanted that these blocks were made for.
    pub(super) built_for: (u64, usize),
    /// Thread k's block of the pair loop, and its weight (below).
    pub(super) bodies: Vec<Range<usize>>,
    pub(super) block_weights: Vec<f64>,
    /// The middle between blocks k and k + 1 (one fewer than the blocks; possibly empty).
    pub(super) middles: Vec<Range<usize>>,
    /// Per sphere, whether its loads are gathered in stage 6: it lies in a middle, or a pair of an
    /// earlier block or middle reaches it.
    pub(super) gathered: Vec<bool>,
    /// The spheres of each thread in the second half kick (balanced with the gathered spheres' sums),
    /// and the kick's middles, shared out as the pair loop's are.
    pub(super) kick: Vec<Range<usize>>,
    pub(super) kick_middles: Vec<Range<usize>>,
    /// The spheres of each thread in the drift (numbers in proportion to the threads' speeds), and the
    /// drift's middles.
    pub(super) drift: Vec<Range<usize>>,
    pub(super) drift_middles: Vec<Range<usize>>,
}

impl Blocks {
    /// Whether the per-sphere passes run on the team (several blocks).
    pub(super) fn team(&self) -> bool {
        self.bodies.len() > 1
    }

    /// The blocks and middles in sphere order: block 0, middle 0, block 1, …, the last block. They
    /// tile the spheres.
    pub(super) fn segments(&self) -> impl Iterator<Item = Range<usize>> + '_ {
        self.bodies.iter().enumerate().flat_map(|(k, block)| {
            std::iter::once(block.clone()).chain(self.middles.get(k).cloned())
        })
    }

    /// Per thread, its range of the kick and the kick's middle after it, as one range: what it kicks
    /// when the kick runs on its own (no sharing out).
    pub(super) fn kick_by_thread(&self) -> Vec<Range<usize>> {
        joined(&self.kick, &self.kick_middles)
    }

    /// Per thread, its range of the drift and the drift's middle after it, as one range.
    pub(super) fn drift_by_thread(&self) -> Vec<Range<usize>> {
        joined(&self.drift, &self.drift_middles)
    }

    /// The blocks of `list` for `wanted` threads, split as `split` says: each thread's share of every
    /// pass in proportion to its entry of `speeds` if the split follows them (equal shares where it
    /// does not hold `wanted` positive entries).
    pub(super) fn new(
        list: &NeighbourList,
        wanted: usize,
        split: &TeamSplit,
        speeds: &[f64],
    ) -> Self {
        let n = list.row_start.len().saturating_sub(1);
        if wanted <= 1 {
            // One block of every sphere (the serial loop): no weights to form, no sphere gathered.
            return Self {
                built_for: (list.builds(), wanted),
                bodies: std::iter::once(0..n).collect(),
                middles: Vec::new(),
                block_weights: vec![0.0],
                gathered: vec![false; n],
                kick: std::iter::once(0..n).collect(),
                kick_middles: Vec::new(),
                drift: std::iter::once(0..n).collect(),
                drift_middles: Vec::new(),
            };
        }
        // In contact: the pair's flag, which a build sets when the pair holds a spring and an
        // evaluation when it overlaps (blocks made for a new pool between builds); one byte per pair,
        // where reading the springs would cost most of a build.
        let cost = |in_contact: &[bool]| -> usize {
            in_contact
                .iter()
                .map(|&c| if c { CONTACT_WEIGHT } else { 1 })
                .sum()
        };
        let weights: Vec<usize> = (0..n)
            .map(|i| {
                let (r0, r1) = (list.row_start[i] as usize, list.row_start[i + 1] as usize);
                let (w0, w1) = (list.wall_start[i] as usize, list.wall_start[i + 1] as usize);
                cost(&list.in_contact[r0..r1]) + cost(&list.wall_in_contact[w0..w1]) + 1
            })
            .collect();
        let shares = shares_of(if split.follow_speeds { speeds } else { &[] }, wanted);
        let (bodies, middles) = blocks_and_middles(&weights, &shares, split.middle_share);
        let block_weights = bodies
            .iter()
            .map(|r| weights[r.clone()].iter().sum::<usize>() as f64)
            .collect();
        let mut gathered = vec![false; n];
        for range in &bodies {
            for j in range.clone() {
                let (s, e) = (list.as_b_start[j] as usize, list.as_b_start[j + 1] as usize);
                // Side-B pairs come by increasing a: the first has the smallest.
                gathered[j] = s < e && (list.a[list.as_b[s] as usize] as usize) < range.start;
            }
        }
        for range in &middles {
            gathered[range.clone()].fill(true);
        }
        // The kick: a gathered sphere also sums its pairs, about two kicks' more work. The last thread
        // also forms the walls' sums in the kick phase (`super::fused`): counted as one more item of a
        // third of a kick per body–wall pair (both weights measured: `docs/tuning.md`).
        let mut kick_weights: Vec<usize> =
            gathered.iter().map(|&g| 1 + 2 * usize::from(g)).collect();
        kick_weights.push(list.wall_pairs() / 3);
        let (mut kick, mut kick_middles) =
            blocks_and_middles(&kick_weights, &shares, split.pass_middle_share);
        // The weight item of the walls is not a sphere.
        for range in kick.iter_mut().chain(&mut kick_middles) {
            *range = range.start.min(n)..range.end.min(n);
        }
        let (drift, drift_middles) =
            blocks_and_middles(&vec![1; n], &shares, split.pass_middle_share);
        Self {
            built_for: (list.builds(), wanted),
            bodies,
            block_weights,
            middles,
            gathered,
            kick,
            kick_middles,
            drift,
            drift_middles,
        }
    }
}

/// Each of `ranges` joined with the middle after it (if any).
fn joined(ranges: &[Range<usize>], middles: &[Range<usize>]) -> Vec<Range<usize>> {
    ranges
        .iter()
        .enumerate()
        .map(|(k, range)| range.start..middles.get(k).map_or(range.end, |m| m.end))
        .collect()
}

/// The fractions of the work to give each of `wanted` threads: in proportion to `speeds` when it holds
/// `wanted` finite positive entries, else equal.
fn shares_of(speeds: &[f64], wanted: usize) -> Vec<f64> {
    let usable = speeds.len() == wanted && speeds.iter().all(|s| s.is_finite() && *s > 0.0);
    let total: f64 = speeds.iter().sum();
    match usable {
        true => speeds.iter().map(|s| s / total).collect(),
        false => vec![1.0 / wanted as f64; wanted],
    }
}

/// One block of consecutive indices of `weights` per entry of `shares` (fractions of the total weight,
/// summing to 1) and the middles between them, which tile the indices: each boundary between the
/// shares lies in a middle that holds `middle_share` of a mean share (half on each side; blocks only
/// when 0).
fn blocks_and_middles(
    weights: &[usize],
    shares: &[f64],
    middle_share: f64,
) -> (Vec<Range<usize>>, Vec<Range<usize>>) {
    let (n, wanted) = (weights.len(), shares.len().max(1));
    let mut prefix = Vec::with_capacity(n + 1);
    prefix.push(0usize);
    for w in weights {
        prefix.push(prefix[prefix.len() - 1] + w);
    }
    let total = prefix[n] as f64;
    let half = 0.5 * middle_share.clamp(0.0, 1.0) * total / wanted as f64;
    // The first index whose spheres before it weigh at least `x`.
    let at = |x: f64| prefix.partition_point(|&p| (p as f64) < x).min(n);
    let (mut bodies, mut middles) = (Vec::with_capacity(wanted), Vec::with_capacity(wanted));
    let (mut start, mut before) = (0, 0.0);
    for share in shares.iter().take(wanted - 1) {
        before += share;
        let centre = before * total;
        let lo = at(centre - half).max(start);
        let hi = at(centre + half).max(lo);
        bodies.push(start..lo);
        middles.push(lo..hi);
        start = hi;
    }
    bodies.push(start..n);
    (bodies, middles)
}

/// Each thread's speed as the split into blocks assumes it: measured on the pair loop, as the weight of
/// the thread's block over the time the thread took for it, the median over the steps since the blocks
/// were made (a step in which the host left the thread unrun for a while does not count), blended half
/// and half with the previous estimate.
///
/// Why: on a shared host one core can run a fifth to two fifths slower than the other for seconds at a
/// time, in every pass alike, and which one changes from run to run (`docs/tuning.md`): blocks of equal
/// weight then leave the faster thread waiting at each barrier. The
/// blocks are made anew at each build of the lists (every ~40–80 steps on the sphere beds), soon enough
/// to follow such a change. The bits do not depend on the split.
#[derive(Clone, Debug, Default)]
pub(super) struct ThreadSpeeds {
    /// Per thread, since the last estimate: the rate (weight per second) of each step's block.
    rates: Vec<Vec<f64>>,
    /// The last estimate, relative to the mean (empty: none).
    estimate: Vec<f64>,
}

/// The least number of steps measured on every thread for an estimate to be updated.
const MIN_MEASURED_STEPS: usize = 5;

/// The widest ratio of the speeds an estimate admits: beyond it, a measurement is taken for a thread
/// that the host did not run for a while, not for a slower core.
const MAX_SPEED_RATIO: f64 = 2.0;

impl ThreadSpeeds {
    /// Thread `k` ran a block of `weight` in `seconds`.
    pub(super) fn add(&mut self, k: usize, weight: f64, seconds: f64) {
        if self.rates.len() <= k {
            self.rates.resize_with(k + 1, Vec::new);
        }
        if weight > 0.0 && seconds > 0.0 {
            self.rates[k].push(weight / seconds);
        }
    }

    /// The estimate for `threads` threads (relative speeds, mean 1; empty when there is none), updated
    /// with what was measured since the last call, which starts a new measurement.
    pub(super) fn estimate(&mut self, threads: usize) -> Vec<f64> {
        let measured =
            self.rates.len() == threads && self.rates.iter().all(|r| r.len() >= MIN_MEASURED_STEPS);
        if measured {
            let medians: Vec<f64> = self
                .rates
                .iter_mut()
                .map(|r| {
                    r.sort_unstable_by(f64::total_cmp);
                    r[r.len() / 2]
                })
                .collect();
            let fresh = relative(&medians);
            self.estimate = match self.estimate.len() == threads {
                true => relative(
                    &self
                        .estimate
                        .iter()
                        .zip(&fresh)
                        .map(|(old, new)| 0.5 * (old + new))
                        .collect::<Vec<_>>(),
                ),
                false => fresh,
            };
        } else if self.estimate.len() != threads {
            self.estimate.clear();
        }
        self.rates.iter_mut().for_each(Vec::clear);
        self.estimate.clone()
    }
}

/// `rates` over their mean, the slowest raised so that no two differ by more than [`MAX_SPEED_RATIO`].
fn relative(rates: &[f64]) -> Vec<f64> {
    let fastest = rates.iter().copied().fold(0.0, f64::max);
    let clamped: Vec<f64> = rates
        .iter()
        .map(|r| r.max(fastest / MAX_SPEED_RATIO))
        .collect();
    let mean = clamped.iter().sum::<f64>() / clamped.len().max(1) as f64;
    clamped.iter().map(|r| r / mean).collect()
}

/// How the threads of a team share the work of a flat step (`Blocks`); a tuning knob for measurements
/// (`examples/sphere_flat_threads --splits`): the bits are the same for any split.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TeamSplit {
    /// The share of a mean thread's weight of the pair loop in each of its middles (0 to 1; 0: blocks
    /// only).
    pub middle_share: f64,
    /// The same for the middles of the drift and of the kick.
    pub pass_middle_share: f64,
    /// Whether each thread's shares follow its measured speed (`ThreadSpeeds`), or are equal.
    pub follow_speeds: bool,
}

impl Default for TeamSplit {
    /// Middles of 0.1 in the pair loop, 0.3 in the drift and the kick, shares that follow the speeds:
    /// the best of the splits compared with `examples/sphere_flat_threads --splits` on the sphere beds
    /// (`docs/tuning.md`). Larger middles of the pair loop cost more than they balance, since every
    /// sphere of a middle has its loads gathered.
    fn default() -> Self {
        Self {
            middle_share: 0.1,
            pass_middle_share: 0.3,
            follow_speeds: true,
        }
    }
}

impl TeamSplit {
    /// The fixed split: blocks of equal weight, no middles.
    pub fn fixed() -> Self {
        Self {
            middle_share: 0.0,
            pass_middle_share: 0.0,
            follow_speeds: false,
        }
    }

    /// Finite shares in 0..=1 (others as the default's).
    pub(super) fn sanitized(self) -> Self {
        let default = Self::default();
        let share = |s: f64, d: f64| if s.is_finite() { s.clamp(0.0, 1.0) } else { d };
        Self {
            middle_share: share(self.middle_share, default.middle_share),
            pass_middle_share: share(self.pass_middle_share, default.pass_middle_share),
            follow_speeds: self.follow_speeds,
        }
    }
}

/// A listed pair's weight in the split into blocks when its spring holds a contact at the build (such a
/// pair mostly stays in contact until the next build), against 1 for one that does not: the law costs
/// several times the distance test, and the contacts crowd where the projectile strikes and at the
/// floor, so blocks of equal pair counts are not blocks of equal work. The weight is the best measured
/// on the sphere beds on two threads (`examples/sphere_flat_threads`; figures in `docs/tuning.md`). A
/// frictionless law keeps no spring, so its pairs all weigh 1.
const CONTACT_WEIGHT: usize = 8;

#[cfg(test)]
mod tests {
    use super::*;

    fn tiles(ranges: &[Range<usize>], n: usize) -> bool {
        ranges.windows(2).all(|w| w[0].end == w[1].start)
            && ranges.first().is_some_and(|r| r.start == 0)
            && ranges.last().is_some_and(|r| r.end == n)
    }

    #[test]
    fn blocks_and_middles_tile_the_indices_around_equal_shares() {
        let weights: Vec<usize> = (0..1000).map(|i| 1 + (i * 7919) % 13).collect();
        let total: usize = weights.iter().sum();
        for wanted in [2, 3, 5] {
            for share in [0.0, 0.2, 0.5] {
                let equal = vec![1.0 / wanted as f64; wanted];
                let (bodies, middles) = blocks_and_middles(&weights, &equal, share);
                assert_eq!(
                    (bodies.len(), middles.len()),
                    (wanted, wanted - 1),
                    "{wanted} blocks, middle share {share}"
                );
                let order: Vec<Range<usize>> = bodies
                    .iter()
                    .enumerate()
                    .flat_map(|(k, b)| std::iter::once(b.clone()).chain(middles.get(k).cloned()))
                    .collect();
                assert!(tiles(&order, 1000), "{order:?}: not a tiling of 0..1000");
                for (k, middle) in middles.iter().enumerate() {
                    let weight = |r: Range<usize>| weights[r].iter().sum::<usize>() as f64;
                    let (before, inside) = (weight(0..middle.start), weight(middle.clone()));
                    let centre = (k + 1) as f64 * total as f64 / wanted as f64;
                    let expected = share * total as f64 / wanted as f64;
                    // Cut at whole spheres: each end within one sphere's weight (at most 13).
                    assert!(
                        (inside - expected).abs() <= 26.0
                            && (before + 0.5 * inside - centre).abs() <= 26.0,
                        "{wanted} blocks, share {share}, middle {k} {middle:?}: weight {inside} \
                         (expected {expected} ± 26), centred at {} (expected {centre} ± 26)",
                        before + 0.5 * inside
                    );
                }
            }
        }
    }

    #[test]
    fn few_spheres_give_empty_blocks_not_a_panic() {
        for n in [0, 1, 2] {
            let (bodies, middles) = blocks_and_middles(&vec![5; n], &[0.25; 4], 0.3);
            let order: Vec<_> = bodies.iter().chain(&middles).collect();
            let covered: usize = order.iter().map(|r| r.len()).sum();
            assert_eq!(covered, n, "{n} spheres: {bodies:?} {middles:?}");
        }
    }

    #[test]
    fn shares_follow_the_speeds() {
        let weights = vec![1; 1000];
        let shares = shares_of(&[3.0, 1.0], 2);
        assert_eq!(shares, vec![0.75, 0.25]);
        let (bodies, middles) = blocks_and_middles(&weights, &shares, 0.0);
        assert_eq!(bodies, [0..750, 750..1000]);
        assert_eq!((middles.len(), middles[0].clone()), (1, 750..750));
        for bad in [&[1.0][..], &[1.0, 0.0], &[1.0, f64::NAN], &[]] {
            assert_eq!(shares_of(bad, 2), vec![0.5, 0.5], "speeds {bad:?}");
        }
    }

    #[test]
    fn speeds_are_measured_blended_and_bounded() {
        let mut speeds = ThreadSpeeds::default();
        let steps = |speeds: &mut ThreadSpeeds, k: usize, seconds: &[f64]| {
            for &t in seconds {
                speeds.add(k, 100.0, t);
            }
        };
        assert!(speeds.estimate(2).is_empty(), "no measurement, no estimate");
        // Thread 1 ran its block of the same weight in twice the time: half the speed; one step in
        // which it was left unrun for 50 ms does not count.
        steps(&mut speeds, 0, &[1e-3; 6]);
        steps(&mut speeds, 1, &[2e-3, 2e-3, 50e-3, 2e-3, 2e-3, 2e-3]);
        let first = speeds.estimate(2);
        assert!(
            (first[0] - 4.0 / 3.0).abs() < 1e-12 && (first[1] - 2.0 / 3.0).abs() < 1e-12,
            "{first:?}"
        );
        // Equal speeds next: halfway back.
        steps(&mut speeds, 0, &[1e-3; 5]);
        steps(&mut speeds, 1, &[1e-3; 5]);
        let second = speeds.estimate(2);
        assert!((second[0] - 7.0 / 6.0).abs() < 1e-12, "{second:?}");
        // Too few steps keep the estimate; another thread count drops it.
        steps(&mut speeds, 0, &[1e-3; 4]);
        steps(&mut speeds, 1, &[1e-3; 4]);
        assert_eq!(speeds.estimate(2), second);
        assert!(speeds.estimate(3).is_empty());
        // A thread slower than twice the other counts as twice slower.
        steps(&mut speeds, 0, &[1e-3; 5]);
        steps(&mut speeds, 1, &[5e-3; 5]);
        let bounded = speeds.estimate(2);
        assert!((bounded[0] / bounded[1] - 2.0).abs() < 1e-12, "{bounded:?}");
    }
}
