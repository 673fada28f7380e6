//! Broad phase: candidate pairs from bounding spheres in a uniform grid, with a Verlet skin.
//!
//! Every body is enclosed by a sphere about its centre of mass (rotation-invariant, so only translation can
//! invalidate the list). Two bodies are a candidate pair when their spheres, each inflated by half the skin,
//! overlap: `|x_i − x_j| < r_i + r_j + skin`. The list stays valid — it contains every pair that can touch —
//! until some body has moved more than `skin / 2` from where it was at the last rebuild, so the grid is rebuilt
//! only then (`BroadPhase::needs_rebuild`). The step uses the sharper test of the two largest moves
//! (`BroadPhase::pairs_may_be_stale`: valid while d₁ + d₂ < skin), which lets one fast body travel nearly
//! the whole skin.
//!
//! The grid's cell size is the median inflated diameter, so a typical body covers one to eight cells; a body
//! much larger than its neighbours (a 0.8 m projectile among 0.1 m rocks) is simply entered in every cell
//! its box covers (the grid, its binning and its cell walk are `world::grid`'s, shared with the flat
//! sphere layout's neighbour list). A pair is reported once, from the first cell (lowest x, y, z) of the overlap of the two
//! bodies' cell ranges, which makes the result exactly the set the O(N²) definition gives — no duplicates
//! and no misses — and [`brute_force_pairs`] is that definition, kept as the test oracle.
//!
//! Output: pairs `(i, j)` with `i < j`, sorted, so every later stage sees the same order on every run and
//! for any thread count.
//!
//! # Walls
//! Body–wall candidates use the same skin ([`BroadPhase::update_with_walls`]): a body is a candidate of a
//! wall when its signed distance from the plane is below its radius plus the skin, and the list stays valid
//! while no body and no wall moved half the skin since it was built (a pair left out had a distance of at
//! least r + skin, so after the moves it still has more than r: it cannot touch). A wall that moved half the
//! skin rebuilds the whole broad phase, so that bodies and walls share one build time. Without this list the
//! step tested every body against every wall at every step, and the candidate list — hence the contact
//! store — changed whenever one body crossed its wall distance, which forced the store's merge.

use crate::math::{Point, Real, Vector};

use super::grid::{CellRange, Grid, Oversize};
use super::region_profile::{self, Section};
use super::timing::StageClock;
use super::wall::Wall;

/// A candidate pair of body indices, `i < j`.
pub type Pair = (u32, u32);

/// The broad-phase state kept between steps.
#[derive(Clone, Debug, Default, serde::Serialize, serde::Deserialize)]
pub struct BroadPhase {
    /// Extra margin (m) added to the sum of the radii; the list is valid while no body moved `skin / 2`.
    skin: Real,
    /// Body centres at the last rebuild.
    centres_at_build: Vec<Point>,
    /// The candidate pairs, sorted.
    pairs: Vec<Pair>,
    /// How many times the grid has been rebuilt.
    rebuilds: u64,
    /// Body–wall candidates `(body, wall)`, sorted, built with the bodies by
    /// [`update_with_walls`](BroadPhase::update_with_walls) (empty when only the bodies were rebuilt).
    wall_pairs: Vec<Pair>,
    /// Wall translations at the last build with walls.
    walls_at_build: Vec<Vector>,
    // Scratch, reused between rebuilds (not part of the state: a checkpoint skips it).
    #[serde(skip)]
    grid: Grid,
    #[serde(skip)]
    body_cells: Vec<CellRange>,
    /// A number that identifies the content of `pairs` and `wall_pairs`: a fresh one at every build (unique
    /// in the process), 0 until the first call of [`generation`](BroadPhase::generation) after a
    /// deserialisation or a default construction. A clone keeps it, as it keeps the lists (not part of the
    /// state).
    #[serde(skip)]
    generation: u64,
}

/// The last generation handed out (see [`BroadPhase::generation`]).
static GENERATIONS: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(0);

/// A number never handed out before in this process (nonzero): the generations of the broad phase and the
/// tags of the lists derived from its pairs.
pub(crate) fn fresh_generation() -> u64 {
    GENERATIONS.fetch_add(1, std::sync::atomic::Ordering::Relaxed) + 1
}

/// From this many bodies the pair search of a rebuild runs on rayon's current pool (the result is the same
/// sorted list either way). Below it the search takes less than ~0.1 ms, comparable to spawning the work.
pub const PARALLEL_SEARCH_MIN_BODIES: usize = 4096;

/// The largest number of cells the grid may have; beyond it the cell size grows (a sparse, spread-out scene
/// must not allocate a huge empty grid).
const MAX_CELLS: usize = 1 << 22;

impl BroadPhase {
    /// A broad phase with the given skin (m). A skin of zero is allowed: the list is then rebuilt whenever
    /// any body moves at all.
    pub fn new(skin: Real) -> Self {
        Self {
            skin: skin.max(0.0),
            ..Self::default()
        }
    }

    /// The Verlet skin (m): how far bounding spheres may be apart and still be listed as candidates.
    pub fn skin(&self) -> Real {
        self.skin
    }

    /// The candidate pairs of the last rebuild, sorted, `i < j`.
    pub fn pairs(&self) -> &[Pair] {
        &self.pairs
    }

    /// How many times the grid has been rebuilt.
    pub fn rebuilds(&self) -> u64 {
        self.rebuilds
    }

    /// An identifier of the current pair lists: equal generations (of this broad phase or a clone of it)
    /// mean equal [`pairs`](Self::pairs) and [`wall_pairs`](Self::wall_pairs); every build takes a new one.
    /// What is derived from the lists can be kept while the generation stays.
    pub fn generation(&mut self) -> u64 {
        if self.generation == 0 {
            self.generation = fresh_generation();
        }
        self.generation
    }

    /// The body centres at the last build (empty before the first).
    pub fn centres_at_build(&self) -> &[Point] {
        &self.centres_at_build
    }

    /// (skin / 2)²: a body whose centre is this far (squared) from where it was at the last build makes
    /// [`needs_rebuild`](Self::needs_rebuild) true.
    pub(crate) fn rebuild_limit_sq(&self) -> Real {
        0.25 * self.skin * self.skin
    }

    /// Whether the pair list may have become incomplete: the body count changed, or some body moved more than
    /// half the skin since the last rebuild.
    pub(crate) fn needs_rebuild(&self, centres: &[Point]) -> bool {
        if centres.len() != self.centres_at_build.len() || self.rebuilds == 0 {
            return true;
        }
        let limit_sq = self.rebuild_limit_sq();
        centres
            .iter()
            .zip(&self.centres_at_build)
            .any(|(now, then)| (now - then).norm_squared() >= limit_sq)
    }

    /// Whether the pair lists may miss a pair that touches now, by the sharper test of two movers: a pair
    /// left out at the build had its spheres at least `skin` apart (a body and a wall: the body's sphere at
    /// least `skin` from the plane), and that gap shrinks by at most the sum of the two displacements, so
    /// the lists hold every touching pair while the two largest body displacements d₁ ≥ d₂ and the largest
    /// wall translation w₁ since the build give d₁ + max(d₂, w₁) < skin (taken with a relative margin of
    /// 1e-9 against rounding). [`needs_rebuild`](Self::needs_rebuild) asks every body to stay within half
    /// the skin, which implies it; this test lets one fast body (a projectile among resting rocks) travel
    /// nearly the whole skin between builds, so the grid is rebuilt about half as often. `centres` must hold
    /// one centre per body of the last build.
    pub(crate) fn pairs_may_be_stale(&self, centres: &[Point], walls: &[Wall]) -> bool {
        if centres.len() != self.centres_at_build.len()
            || walls.len() != self.walls_at_build.len()
            || self.rebuilds == 0
        {
            return true;
        }
        let (d1, d2) = self.largest_moves_sq(centres, |_| true);
        self.moves_reach_skin(d1, d2, walls)
    }

    /// The two largest squared moves (m²) since the last build among the bodies `counted` (the largest
    /// first; equal moves count twice, as in a multiset).
    pub fn largest_moves_sq(
        &self,
        centres: &[Point],
        counted: impl Fn(usize) -> bool,
    ) -> (Real, Real) {
        let (mut d1, mut d2) = (0.0, 0.0);
        let moves = centres.iter().zip(&self.centres_at_build).enumerate();
        for (_, (now, then)) in moves.filter(|(i, _)| counted(*i)) {
            let d_sq: Real = (now - then).norm_squared();
            if d_sq > d2 {
                if d_sq > d1 {
                    d2 = d1;
                    d1 = d_sq;
                } else {
                    d2 = d_sq;
                }
            }
        }
        (d1, d2)
    }

    /// Whether two bodies that moved `d1_sq`, `d2_sq` (m², the largest moves) and the walls' moves since
    /// the last build may have brought a pair within reach that the list lacks.
    pub fn moves_reach_skin(&self, d1_sq: Real, d2_sq: Real, walls: &[Wall]) -> bool {
        let (d1, d2) = (d1_sq, d2_sq);
        let w1 = walls
            .iter()
            .zip(&self.walls_at_build)
            .map(|(w, then)| (w.pose.translation.vector - then).norm_squared())
            .fold(0.0, Real::max);
        d1.sqrt() + d2.max(w1).sqrt() >= self.skin * (1.0 - 1e-9)
    }

    /// This list restricted to the bodies `ids` (strictly increasing), renumbered 0, 1, … in that order:
    /// the pairs and body–wall pairs among kept bodies, their centres at the build, the walls' build
    /// translations and the build count. Every pair among kept bodies keeps its place in the order, so the
    /// result is the list a build at the kept centres would give (a part of a world split over processes,
    /// cut from a restored world whose list was built elsewhere).
    pub fn restricted(&self, ids: &[usize]) -> BroadPhase {
        debug_assert!(ids.windows(2).all(|w| w[0] < w[1]));
        let mut local = vec![u32::MAX; self.centres_at_build.len()];
        for (k, &i) in ids.iter().enumerate() {
            local[i] = k as u32;
        }
        let kept = |&(i, j): &Pair| {
            let (a, b) = (local[i as usize], local[j as usize]);
            (a != u32::MAX && b != u32::MAX).then_some((a, b))
        };
        let kept_wall = |&(i, w): &Pair| {
            let a = local[i as usize];
            (a != u32::MAX).then_some((a, w))
        };
        BroadPhase {
            skin: self.skin,
            centres_at_build: ids.iter().map(|&i| self.centres_at_build[i]).collect(),
            pairs: self.pairs.iter().filter_map(kept).collect(),
            rebuilds: self.rebuilds,
            wall_pairs: self.wall_pairs.iter().filter_map(kept_wall).collect(),
            walls_at_build: self.walls_at_build.clone(),
            ..BroadPhase::default()
        }
    }

    /// The list a build at `centres` with `walls` would give for another set of bodies, taken over from
    /// this one where it can: `old_of_new[k]` is new body `k`'s index in this list (increasing where
    /// given), or `None` for a body this list does not hold. Pairs among held bodies are this list's
    /// (renumbered, in the same order); pairs and wall pairs of the others are tested one by one with the
    /// build's criterion. Valid when every held body's centre and radius are those of this list's build and
    /// the walls are those of its build (a part of a world split over processes, cut again right after the
    /// step that built this list: its bodies mostly stay).
    pub fn carried_over(
        &self,
        old_of_new: &[Option<u32>],
        centres: &[Point],
        radii: &[Real],
        walls: &[Wall],
    ) -> BroadPhase {
        debug_assert_eq!(old_of_new.len(), centres.len());
        debug_assert!(old_of_new.iter().enumerate().all(|(k, old)| {
            old.is_none_or(|i| self.centres_at_build[i as usize] == centres[k])
        }));
        let mut new_of_old = vec![u32::MAX; self.centres_at_build.len()];
        let mut newcomers = Vec::new();
        for (k, old) in old_of_new.iter().enumerate() {
            match old {
                Some(i) => new_of_old[*i as usize] = k as u32,
                None => newcomers.push(k),
            }
        }
        let held = |&(i, j): &Pair| {
            let (a, b) = (new_of_old[i as usize], new_of_old[j as usize]);
            (a != u32::MAX && b != u32::MAX).then_some((a, b))
        };
        let mut found = Vec::new();
        for &k in &newcomers {
            // A pair of two newcomers is found from the later one.
            let partners = (0..centres.len()).filter(|&j| j < k || old_of_new[j].is_some());
            for j in partners.filter(|&j| j != k) {
                if spheres_within(centres[k], radii[k], centres[j], radii[j], self.skin) {
                    found.push((k.min(j) as u32, k.max(j) as u32));
                }
            }
        }
        found.sort_unstable();
        let pairs = merge_sorted(self.pairs.iter().filter_map(held), found);
        let newcomer_walls = newcomers.iter().flat_map(|&k| {
            let one = brute_force_wall_pairs(&centres[k..=k], &radii[k..=k], walls, self.skin);
            one.into_iter().map(move |(_, w)| (k as u32, w))
        });
        let kept_walls = self.wall_pairs.iter().filter_map(|&(i, w)| {
            let a = new_of_old[i as usize];
            (a != u32::MAX).then_some((a, w))
        });
        let wall_pairs = merge_sorted(kept_walls, newcomer_walls.collect());
        BroadPhase {
            skin: self.skin,
            centres_at_build: centres.to_vec(),
            pairs,
            rebuilds: self.rebuilds,
            wall_pairs,
            walls_at_build: walls.iter().map(|w| w.pose.translation.vector).collect(),
            generation: fresh_generation(),
            ..BroadPhase::default()
        }
    }

    /// Drops the pairs and body–wall pairs that hold no body for which `counts` is true (a part of a world
    /// split over processes: a pair of two ghosts only moves ghosts, whose states come from their owners).
    /// The build's centres and count stay, so the next rebuild happens when it would have.
    pub fn keep_pairs_of(&mut self, counts: impl Fn(u32) -> bool) {
        self.pairs.retain(|&(i, j)| counts(i) || counts(j));
        self.wall_pairs.retain(|&(i, _)| counts(i));
        self.generation = fresh_generation();
    }

    /// Sets the build count, for a list built in step with another that counts the builds (a part of a
    /// world split over processes, whose list is built anew at each cut).
    pub fn set_rebuilds(&mut self, rebuilds: u64) {
        self.rebuilds = rebuilds;
    }

    /// The body–wall candidates `(body, wall)` of the last [`update_with_walls`](Self::update_with_walls),
    /// sorted; every body whose bounding sphere can reach a wall before the next rebuild is listed.
    pub fn wall_pairs(&self) -> &[Pair] {
        &self.wall_pairs
    }

    /// Whether a wall was added or removed, or moved half the skin, since the last build with walls.
    pub(crate) fn walls_moved(&self, walls: &[Wall]) -> bool {
        if walls.len() != self.walls_at_build.len() {
            return true;
        }
        let limit_sq = 0.25 * self.skin * self.skin;
        walls
            .iter()
            .zip(&self.walls_at_build)
            .any(|(w, then)| (w.pose.translation.vector - then).norm_squared() >= limit_sq)
    }

    /// Rebuilds the body pairs and the body–wall pairs if a body or a wall moved half the skin (or the
    /// counts changed); returns whether it did.
    pub fn update_with_walls(&mut self, centres: &[Point], radii: &[Real], walls: &[Wall]) -> bool {
        if self.needs_rebuild(centres) || self.walls_moved(walls) {
            self.rebuild_with_walls(centres, radii, walls);
            true
        } else {
            false
        }
    }

    /// Recomputes the body pairs and the body–wall pairs from scratch.
    pub fn rebuild_with_walls(&mut self, centres: &[Point], radii: &[Real], walls: &[Wall]) {
        self.rebuild_with_walls_timed(centres, radii, walls, &mut StageClock::start());
    }

    /// [`BroadPhase::rebuild_with_walls`] within the stage timed by `clock` (the parallel pair search is
    /// not serial time).
    pub(crate) fn rebuild_with_walls_timed(
        &mut self,
        centres: &[Point],
        radii: &[Real],
        walls: &[Wall],
        clock: &mut StageClock,
    ) {
        self.rebuild_timed(centres, radii, clock);
        self.walls_at_build.clear();
        self.walls_at_build
            .extend(walls.iter().map(|w| w.pose.translation.vector));
        let skin = self.skin;
        self.wall_pairs = clock.serial(Section::SerialGrid, || {
            if centres.len() >= PARALLEL_SEARCH_MIN_BODIES && rayon::current_num_threads() > 1 {
                // The same test per body, bodies in parallel chunks concatenated in body order: the
                // list of the serial definition.
                use rayon::prelude::*;
                let chunk = centres
                    .len()
                    .div_ceil(rayon::current_num_threads() * super::parallel::CHUNKS_PER_THREAD);
                let found: Vec<Vec<Pair>> = centres
                    .par_chunks(chunk)
                    .zip(radii.par_chunks(chunk))
                    .with_max_len(1)
                    .enumerate()
                    .map(|(k, (c, r))| {
                        let mut out = brute_force_wall_pairs(c, r, walls, skin);
                        for pair in &mut out {
                            pair.0 += (k * chunk) as u32;
                        }
                        out
                    })
                    .collect();
                found.concat()
            } else {
                brute_force_wall_pairs(centres, radii, walls, skin)
            }
        });
        self.generation = fresh_generation();
    }

    /// Rebuilds the pair list if `needs_rebuild`; returns whether it did.
    pub fn update(&mut self, centres: &[Point], radii: &[Real]) -> bool {
        if self.needs_rebuild(centres) {
            self.rebuild(centres, radii);
            true
        } else {
            false
        }
    }

    /// Recomputes the candidate pairs from scratch.
    ///
    /// `centres` and `radii` are the bounding spheres of the bodies (world frame, m), one per body; the radii
    /// must be finite and non-negative (the world checks bodies before they get here).
    pub fn rebuild(&mut self, centres: &[Point], radii: &[Real]) {
        self.rebuild_timed(centres, radii, &mut StageClock::start());
    }

    /// [`BroadPhase::rebuild`] within the stage timed by `clock`.
    fn rebuild_timed(&mut self, centres: &[Point], radii: &[Real], clock: &mut StageClock) {
        assert_eq!(
            centres.len(),
            radii.len(),
            "broad phase: one radius per centre"
        );
        self.rebuilds += 1;
        self.generation = fresh_generation();
        // The body–wall list belongs to a build with walls: a plain rebuild forgets it (the next
        // `update_with_walls` then rebuilds when there are walls).
        self.wall_pairs.clear();
        self.walls_at_build.clear();
        self.centres_at_build.clear();
        self.centres_at_build.extend_from_slice(centres);
        self.pairs.clear();
        if centres.len() < 2 {
            return;
        }
        let profile_grid = clock.serial_start();
        let mut grid = std::mem::take(&mut self.grid);
        self.bin_bodies(&mut grid, centres, radii);
        clock.serial_end(Section::SerialGrid, profile_grid);
        let mut pairs = std::mem::take(&mut self.pairs);
        let search = PairSearch {
            grid: &grid,
            body_cells: &self.body_cells,
            centres,
            radii,
            skin: self.skin,
        };
        search.run(&mut pairs, clock);
        self.pairs = pairs;
        self.grid = grid;
        debug_assert!(self.pairs.windows(2).all(|w| w[0] < w[1]));
    }

    /// Shapes `grid` over the bodies and enters each body in the cells of its box inflated by half the skin.
    fn bin_bodies(&mut self, grid: &mut Grid, centres: &[Point], radii: &[Real]) {
        let half_skin = 0.5 * self.skin;
        self.shape_grid(grid, centres, radii);
        self.body_cells.clear();
        let cells_of = |(c, &r): (&Point, &Real)| {
            // Widened by a relative 1e-9 so that rounding can never drop a pair the sphere test would keep:
            // extra cells only cost a test, a missing cell would lose a contact.
            grid.cells_of_box(c, (r + half_skin) * (1.0 + 1e-9))
        };
        if centres.len() >= PARALLEL_SEARCH_MIN_BODIES && rayon::current_num_threads() > 1 {
            // One range per body, in body order (an indexed parallel extend).
            use rayon::prelude::*;
            self.body_cells
                .par_extend(centres.par_iter().zip(radii.par_iter()).map(cells_of));
        } else {
            self.body_cells
                .extend(centres.iter().zip(radii).map(cells_of));
        }
        grid.bin(&self.body_cells, |body| body as u32);
    }

    /// Shapes `grid` over the inflated boxes of all bodies, with the median inflated diameter as cell size
    /// (a body then covers one to eight cells; a large one is entered in every cell its box covers).
    fn shape_grid(&self, grid: &mut Grid, centres: &[Point], radii: &[Real]) {
        let half_skin = 0.5 * self.skin;
        let mut lo = [Real::INFINITY; 3];
        let mut hi = [Real::NEG_INFINITY; 3];
        for (c, &r) in centres.iter().zip(radii) {
            for axis in 0..3 {
                lo[axis] = lo[axis].min(c[axis] - r - half_skin);
                hi[axis] = hi[axis].max(c[axis] + r + half_skin);
            }
        }
        let mut diameters: Vec<Real> = radii.iter().map(|&r| 2.0 * (r + half_skin)).collect();
        let mid = diameters.len() / 2;
        let (_, median, _) = diameters.select_nth_unstable_by(mid, |a, b| a.total_cmp(b));
        let largest_extent = (0..3).map(|k| hi[k] - lo[k]).fold(0.0, Real::max);
        // A zero median (point bodies, no skin) would make a degenerate grid: fall back to the scene size.
        let cell = if *median > 0.0 {
            *median
        } else {
            largest_extent.max(1.0)
        };
        // A sparse, spread-out scene grows its cells rather than allocating a huge empty grid.
        grid.shape(lo, hi, cell, MAX_CELLS, Oversize::GrowCells);
    }
}

/// The pair search of a rebuild over bodies binned in `grid`.
struct PairSearch<'a> {
    grid: &'a Grid,
    body_cells: &'a [CellRange],
    centres: &'a [Point],
    radii: &'a [Real],
    skin: Real,
}

impl PairSearch<'_> {
    /// Appends every pair within the skin to `pairs`, sorted. Bodies are independent here: large scenes
    /// search in parallel chunks of bodies, concatenated in body order (the same list for any chunking).
    fn run(&self, pairs: &mut Vec<Pair>, clock: &mut StageClock) {
        let n = self.centres.len();
        if n >= PARALLEL_SEARCH_MIN_BODIES && rayon::current_num_threads() > 1 {
            use rayon::prelude::*;
            // Chunks of bodies handed out one at a time (see `parallel::for_each_chunked`): the bodies
            // of a dense region have more pairs to test.
            let chunk =
                n.div_ceil(rayon::current_num_threads() * super::parallel::CHUNKS_PER_THREAD);
            let found: Vec<Vec<Pair>> = clock.region(Section::BroadSearch, true, || {
                (0..n.div_ceil(chunk))
                    .into_par_iter()
                    .with_max_len(1)
                    .map(|k| {
                        let _timer = region_profile::chunk();
                        let mut out = Vec::new();
                        for i in k * chunk..((k + 1) * chunk).min(n) {
                            self.body(i, &mut out);
                        }
                        out
                    })
                    .collect()
            });
            for part in found {
                pairs.extend_from_slice(&part);
            }
        } else {
            // Parallel from PARALLEL_SEARCH_MIN_BODIES on a pool of several threads: not serial time.
            let on_pool = n >= PARALLEL_SEARCH_MIN_BODIES;
            clock.region(Section::BroadSearch, on_pool, || {
                let _timer = region_profile::chunk();
                for i in 0..n {
                    self.body(i, pairs);
                }
            });
        }
    }

    /// Body `i`'s pairs (i, j > i), each examined in the first cell of the overlap of both cell ranges
    /// only, and sorted as found (a few per body): the lists concatenated in body order are sorted, with
    /// no sort of the whole list.
    #[inline]
    fn body(&self, i: usize, out: &mut Vec<Pair>) {
        let found_before = out.len();
        let range_i = &self.body_cells[i];
        self.grid.for_each_cell(range_i, |c, bodies| {
            for &j in bodies {
                let j_usize = j as usize;
                if j_usize <= i {
                    continue;
                }
                let range_j = &self.body_cells[j_usize];
                let first_common = [
                    range_i.lo[0].max(range_j.lo[0]),
                    range_i.lo[1].max(range_j.lo[1]),
                    range_i.lo[2].max(range_j.lo[2]),
                ];
                if first_common != c {
                    continue;
                }
                if spheres_within(
                    self.centres[i],
                    self.radii[i],
                    self.centres[j_usize],
                    self.radii[j_usize],
                    self.skin,
                ) {
                    out.push((i as u32, j));
                }
            }
        });
        out[found_before..].sort_unstable();
    }
}

/// The pairs of `a` and of `b` (each sorted, no pair in both) in one sorted list.
fn merge_sorted(a: impl Iterator<Item = Pair>, b: Vec<Pair>) -> Vec<Pair> {
    let mut out = Vec::with_capacity(b.len());
    let mut b = b.into_iter().peekable();
    for pair in a {
        while let Some(next) = b.next_if(|next| *next < pair) {
            out.push(next);
        }
        out.push(pair);
    }
    out.extend(b);
    out
}

/// The pair criterion: spheres closer than the sum of their radii plus the skin.
fn spheres_within(c1: Point, r1: Real, c2: Point, r2: Real, skin: Real) -> bool {
    let reach = r1 + r2 + skin;
    (c2 - c1).norm_squared() < reach * reach
}

/// The body–wall candidates: `(body, wall)` for every body whose signed distance from the wall's plane is
/// below its radius plus `skin`, sorted by body then wall. O(bodies × walls) — the handful of walls of a box.
pub(crate) fn brute_force_wall_pairs(
    centres: &[Point],
    radii: &[Real],
    walls: &[Wall],
    skin: Real,
) -> Vec<Pair> {
    let mut pairs = Vec::new();
    for (i, (c, &r)) in centres.iter().zip(radii).enumerate() {
        for (w, wall) in walls.iter().enumerate() {
            if wall.signed_distance(c) < r + skin {
                pairs.push((i as u32, w as u32));
            }
        }
    }
    pairs
}

/// The O(N²) definition of the candidate pairs: the oracle the grid must match exactly.
pub fn brute_force_pairs(centres: &[Point], radii: &[Real], skin: Real) -> Vec<Pair> {
    let mut pairs = Vec::new();
    for i in 0..centres.len() {
        for j in i + 1..centres.len() {
            if spheres_within(centres[i], radii[i], centres[j], radii[j], skin) {
                pairs.push((i as u32, j as u32));
            }
        }
    }
    pairs
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A small deterministic generator (SplitMix64), so these tests need no extra crate.
    struct SplitMix(u64);
    impl SplitMix {
        fn next_f64(&mut self) -> f64 {
            self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
            let mut z = self.0;
            z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
            z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
            ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
        }
        fn uniform(&mut self, lo: f64, hi: f64) -> f64 {
            lo + (hi - lo) * self.next_f64()
        }
    }

    fn random_scene(
        seed: u64,
        n: usize,
        box_size: f64,
        r_min: f64,
        r_max: f64,
    ) -> (Vec<Point>, Vec<Real>) {
        let mut rng = SplitMix(seed);
        let centres = (0..n)
            .map(|_| {
                Point::new(
                    rng.uniform(0.0, box_size),
                    rng.uniform(0.0, box_size),
                    rng.uniform(0.0, box_size),
                )
            })
            .collect();
        let radii = (0..n).map(|_| rng.uniform(r_min, r_max)).collect();
        (centres, radii)
    }

    fn assert_matches_oracle(label: &str, centres: &[Point], radii: &[Real], skin: Real) {
        let mut broad = BroadPhase::new(skin);
        broad.rebuild(centres, radii);
        let expected = brute_force_pairs(centres, radii, skin);
        let missing: Vec<_> = expected
            .iter()
            .filter(|p| broad.pairs().binary_search(p).is_err())
            .take(5)
            .collect();
        let extra: Vec<_> = broad
            .pairs()
            .iter()
            .filter(|p| expected.binary_search(p).is_err())
            .take(5)
            .collect();
        assert!(
            broad.pairs() == expected.as_slice(),
            "{label}: grid found {} pairs, O(N²) oracle {} (n = {}, skin = {skin}); first missing {missing:?}, \
             first extra {extra:?}",
            broad.pairs().len(),
            expected.len(),
            centres.len(),
        );
    }

    #[test]
    fn grid_pairs_equal_brute_force_for_uniform_sizes() {
        for seed in 0..5 {
            let (centres, radii) = random_scene(seed, 800, 2.0, 0.045, 0.055);
            assert_matches_oracle(&format!("uniform seed {seed}"), &centres, &radii, 0.01);
        }
    }

    #[test]
    fn parallel_pair_search_equals_brute_force() {
        // Above PARALLEL_SEARCH_MIN_BODIES, in a pool of 2 threads (the parallel path) and of 1.
        let (centres, radii) = random_scene(3, PARALLEL_SEARCH_MIN_BODIES + 900, 4.0, 0.04, 0.06);
        for threads in [1, 2, 4] {
            rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .expect("pool")
                .install(|| {
                    assert_matches_oracle(&format!("{threads} threads"), &centres, &radii, 0.01);
                    // The body–wall list of a build with walls (bodies in parallel chunks above the
                    // threshold) is the serial definition's.
                    let walls: Vec<Wall> = [
                        (Vector::z(), 0.3),
                        (-Vector::x(), -3.7),
                        (Vector::new(1.0, 1.0, 0.0).normalize(), 0.9),
                    ]
                    .iter()
                    .map(|&(normal, offset)| Wall {
                        name: "w".to_owned(),
                        plane: crate::shape::Plane::new(normal, offset).expect("plane"),
                        pose: crate::math::Pose::identity(),
                        velocity: Vector::zeros(),
                        material: 0,
                    })
                    .collect();
                    let mut broad = BroadPhase::new(0.01);
                    broad.rebuild_with_walls(&centres, &radii, &walls);
                    let expected = brute_force_wall_pairs(&centres, &radii, &walls, 0.01);
                    assert!(
                        expected.len() > 100,
                        "only {} body-wall pairs: the walls test nothing",
                        expected.len()
                    );
                    assert!(
                        broad.wall_pairs() == expected.as_slice(),
                        "{threads} threads: {} body-wall pairs against {} of the serial definition",
                        broad.wall_pairs().len(),
                        expected.len()
                    );
                });
        }
    }

    #[test]
    fn grid_pairs_equal_brute_force_with_a_projectile_among_small_rocks() {
        // A 0.8 m body among 0.1 m ones: the large body covers many cells.
        let (mut centres, mut radii) = random_scene(7, 1500, 3.0, 0.04, 0.06);
        centres.push(Point::new(1.5, 1.5, 1.5));
        radii.push(0.4);
        centres.push(Point::new(0.1, 2.9, 1.0));
        radii.push(0.45);
        assert_matches_oracle("projectile among rocks", &centres, &radii, 0.005);
    }

    #[test]
    fn grid_pairs_equal_brute_force_for_sizes_spanning_four_decades() {
        let mut rng = SplitMix(11);
        let n = 600;
        let centres: Vec<Point> = (0..n)
            .map(|_| {
                Point::new(
                    rng.uniform(0.0, 5.0),
                    rng.uniform(0.0, 5.0),
                    rng.uniform(0.0, 5.0),
                )
            })
            .collect();
        let radii: Vec<Real> = (0..n).map(|_| 10f64.powf(rng.uniform(-3.0, 0.0))).collect();
        assert_matches_oracle("log-uniform radii 1e-3..1", &centres, &radii, 0.0);
        assert_matches_oracle("log-uniform radii 1e-3..1, skin", &centres, &radii, 0.02);
    }

    #[test]
    fn a_list_carried_over_to_another_set_of_bodies_is_the_list_built_for_that_set() {
        // The old set holds bodies 0..1200 but every seventh; the new one drops every fifth of those and
        // takes in the seventh ones (newcomers) and bodies 1200..1300, with a wall cutting through both.
        let (centres, radii) = random_scene(21, 1300, 1.0, 0.04, 0.06);
        let walls = vec![Wall {
            name: "w".to_owned(),
            plane: crate::shape::Plane::new(Vector::z(), 0.2).expect("plane"),
            pose: crate::math::Pose::identity(),
            velocity: Vector::zeros(),
            material: 0,
        }];
        let skin = 0.01;
        let old_ids: Vec<usize> = (0..1200).filter(|i| i % 7 != 0).collect();
        let new_ids: Vec<usize> = (0..1300)
            .filter(|i| *i >= 1200 || i % 7 == 0 || i % 5 != 0)
            .collect();
        let pick = |ids: &[usize]| -> (Vec<Point>, Vec<Real>) {
            (
                ids.iter().map(|&i| centres[i]).collect(),
                ids.iter().map(|&i| radii[i]).collect(),
            )
        };
        let (old_centres, old_radii) = pick(&old_ids);
        let mut old = BroadPhase::new(skin);
        old.rebuild_with_walls(&old_centres, &old_radii, &walls);
        let (new_centres, new_radii) = pick(&new_ids);
        let mut built = BroadPhase::new(skin);
        built.rebuild_with_walls(&new_centres, &new_radii, &walls);
        let old_of_new: Vec<Option<u32>> = new_ids
            .iter()
            .map(|gid| old_ids.binary_search(gid).ok().map(|k| k as u32))
            .collect();
        let newcomers = old_of_new.iter().filter(|o| o.is_none()).count();
        let carried = old.carried_over(&old_of_new, &new_centres, &new_radii, &walls);
        assert!(
            newcomers > 100 && built.pairs().len() > 1000 && built.wall_pairs().len() > 20,
            "{newcomers} newcomers, {} pairs, {} wall pairs: the test tests too little",
            built.pairs().len(),
            built.wall_pairs().len()
        );
        assert!(
            carried.pairs() == built.pairs() && carried.wall_pairs() == built.wall_pairs(),
            "{newcomers} newcomers: carried over {} pairs and {} wall pairs, built {} and {}",
            carried.pairs().len(),
            carried.wall_pairs().len(),
            built.pairs().len(),
            built.wall_pairs().len()
        );
        assert_eq!(carried.centres_at_build(), built.centres_at_build());
    }

    #[test]
    fn spheres_exactly_at_the_reach_are_not_a_pair_and_just_inside_are() {
        let radii = [0.5, 0.5];
        let apart = [Point::origin(), Point::new(1.1, 0.0, 0.0)];
        assert_matches_oracle("at the reach", &apart, &radii, 0.1);
        let inside = [Point::origin(), Point::new(1.1 * (1.0 - 1e-15), 0.0, 0.0)];
        assert_matches_oracle("just inside the reach", &inside, &radii, 0.1);
        assert_eq!(brute_force_pairs(&inside, &radii, 0.1), vec![(0, 1)]);
    }

    #[test]
    fn degenerate_scenes_give_the_oracle_pairs() {
        // All bodies at one point, a flat layer, and a spread-out sparse scene that would need a huge grid.
        let same = vec![Point::new(1.0, 1.0, 1.0); 20];
        assert_matches_oracle("coincident centres", &same, &[0.1; 20], 0.0);
        let flat: Vec<Point> = (0..400)
            .map(|k| Point::new((k % 20) as f64 * 0.09, (k / 20) as f64 * 0.09, 0.0))
            .collect();
        assert_matches_oracle("flat layer", &flat, &[0.05; 400], 0.0);
        let sparse: Vec<Point> = (0..50)
            .map(|k| Point::new(k as f64 * 1e4, 0.0, (k % 3) as f64))
            .collect();
        assert_matches_oracle("sparse huge extent", &sparse, &[0.6; 50], 0.0);
        assert_matches_oracle("no bodies", &[], &[], 0.1);
        assert_matches_oracle("one body", &[Point::origin()], &[1.0], 0.1);
    }

    #[test]
    fn wall_pairs_keep_every_body_that_can_touch_a_wall_until_the_rebuild() {
        use crate::shape::Plane;
        let (mut centres, radii) = random_scene(5, 400, 1.0, 0.04, 0.06);
        let skin = 0.02;
        let wall = |name: &str, normal: Vector, offset: Real, velocity: Vector| Wall {
            name: name.to_owned(),
            plane: Plane::new(normal, offset).expect("plane"),
            pose: crate::math::Pose::identity(),
            velocity,
            material: 0,
        };
        let mut walls = vec![
            wall("floor", Vector::z(), 0.05, Vector::zeros()),
            wall("side", -Vector::x(), -0.95, Vector::zeros()),
            wall("lid", -Vector::z(), -0.9, Vector::new(0.0, 0.0, -1.0)),
        ];
        let mut broad = BroadPhase::new(skin);
        assert!(broad.update_with_walls(&centres, &radii, &walls));
        let built = broad.wall_pairs().to_vec();
        assert!(
            !built.is_empty(),
            "no body near a wall: the scene tests nothing"
        );
        // Every body moves 0.49 skin in a seeded direction, the lid 0.49 skin down: no rebuild, and every
        // body–wall pair whose sphere reaches the plane now is in the kept list.
        let mut rng = SplitMix(9);
        for c in &mut centres {
            let d = Vector::new(
                rng.uniform(-1.0, 1.0),
                rng.uniform(-1.0, 1.0),
                rng.uniform(-1.0, 1.0),
            );
            *c += d.normalize() * 0.49 * skin;
        }
        walls[2].pose.translation.vector.z -= 0.49 * skin;
        assert!(
            !broad.update_with_walls(&centres, &radii, &walls),
            "moves of 0.49 skin must not rebuild"
        );
        let touching_now = brute_force_wall_pairs(&centres, &radii, &walls, 0.0);
        let lost: Vec<_> = touching_now
            .iter()
            .filter(|p| built.binary_search(p).is_err())
            .collect();
        assert!(
            lost.is_empty(),
            "kept wall list ({} pairs) lost pairs that reach a wall now: {lost:?}",
            built.len()
        );
        walls[2].pose.translation.vector.z -= 0.02 * skin;
        assert!(
            broad.update_with_walls(&centres, &radii, &walls),
            "a wall moving 0.51 skin must rebuild"
        );
        assert_eq!(
            broad.wall_pairs(),
            brute_force_wall_pairs(&centres, &radii, &walls, skin).as_slice()
        );
    }

    #[test]
    fn one_fast_body_may_travel_nearly_the_skin_and_the_list_still_holds_every_touching_pair() {
        let (mut centres, radii) = random_scene(4, 600, 1.0, 0.04, 0.06);
        let skin = 0.02;
        let mut broad = BroadPhase::new(skin);
        broad.rebuild_with_walls(&centres, &radii, &[]);
        let mut rng = SplitMix(17);
        // Body 42 moves 0.9 skin, every other body 0.09 skin, each in a seeded direction: 0.99 skin in all.
        for (i, c) in centres.iter_mut().enumerate() {
            let d = Vector::new(
                rng.uniform(-1.0, 1.0),
                rng.uniform(-1.0, 1.0),
                rng.uniform(-1.0, 1.0),
            )
            .normalize();
            *c += d * if i == 42 { 0.9 } else { 0.09 } * skin;
        }
        assert!(
            broad.needs_rebuild(&centres),
            "0.9 skin exceeds the half-skin rule"
        );
        assert!(
            !broad.pairs_may_be_stale(&centres, &[]),
            "moves of 0.9 and 0.09 skin (sum 0.99) must keep the lists"
        );
        // Every pair that can touch now (no skin), also with the shifted spheres inflated by 0.01 skin,
        // is in the kept list.
        for (i, j) in brute_force_pairs(&centres, &radii, 0.01 * skin) {
            assert!(
                broad.pairs().binary_search(&(i, j)).is_ok(),
                "kept list lost pair ({i}, {j}) within 0.01 skin after moves summing to 0.99 skin"
            );
        }
        // A second body at 0.11 skin: the sum reaches the skin.
        centres[7] = broad.centres_at_build()[7] + Vector::new(0.11 * skin, 0.0, 0.0);
        assert!(
            broad.pairs_may_be_stale(&centres, &[]),
            "moves of 0.9 and 0.11 skin (sum 1.01) must rebuild"
        );
    }

    #[test]
    fn list_is_rebuilt_only_after_a_body_moves_half_the_skin() {
        let (mut centres, radii) = random_scene(3, 200, 1.0, 0.04, 0.06);
        let skin = 0.02;
        let mut broad = BroadPhase::new(skin);
        assert!(broad.update(&centres, &radii), "first update must build");
        centres[17].x += 0.49 * skin;
        assert!(
            !broad.update(&centres, &radii),
            "a move of 0.49 skin must not trigger a rebuild"
        );
        // Every pair that can touch (sum of radii, no skin) is still in the stale list.
        for (i, j) in brute_force_pairs(&centres, &radii, 0.0) {
            assert!(
                broad.pairs().binary_search(&(i, j)).is_ok(),
                "stale list lost touching pair ({i}, {j})"
            );
        }
        centres[17].x += 0.02 * skin;
        assert!(
            broad.update(&centres, &radii),
            "a move of 0.51 skin must trigger a rebuild"
        );
        assert_eq!(broad.rebuilds(), 2);
    }
}
