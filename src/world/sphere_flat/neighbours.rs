//! The half neighbour list of the flat sphere path, with a Verlet skin, and its body–wall list.
//!
//! # What is listed
//! - Body pairs (a, b), a < b, whose spheres were closer than r_a + r_b + skin at the build, sorted by
//!   (a, b): the pairs of body a are one contiguous run (`row_start`). This is the order of the general
//!   step's contact keys, so every sum the step takes over pairs runs in the general step's order.
//! - For every body, the pairs in which it is side B, in increasing a (`as_b`): with its own run, the
//!   pairs of body i in the order (a, i) for a < i, then (i, b) for b > i — the key order, which the
//!   per-body gather follows.
//! - Body–wall pairs (body, wall) whose sphere came within the skin of the plane at the build, sorted by
//!   body then wall (`wall_start`).
//!
//! # Validity
//! A pair left out had a gap of at least `skin` at the build; it cannot overlap before the two largest
//! displacements since the build (bodies, or a body and a moving wall) sum to the skin. The step rebuilds
//! when they do ([`NeighbourList::is_stale`], the rule of the general broad phase). A large body (see
//! below: a projectile) is listed with [`LARGE_SKIN_FACTOR`] times the skin against every body and wall,
//! and its pairs stay valid while its displacement and the largest other one sum to that wider skin: a
//! fast projectile alone does not force a rebuild every few steps (at 200 m/s it crosses the common skin of
//! sphere bed b in 8 steps).
//!
//! # Build
//! Bodies are binned in the engine's uniform grid (`world::grid`, shared with the broad phase) with cells
//! `2 r_grid + skin` wide, r_grid the largest radius of the
//! grid's bodies; a body more than [`LARGE_RADIUS_FACTOR`] times the median radius (a projectile) is kept
//! out of the grid and tested against every body, so that one large sphere does not coarsen the grid for
//! all. The grid spans the box of the centres with at most [`MAX_CELLS_PER_BODY`] cells per body; a body
//! beyond it is binned into the nearest edge cell (clamping keeps neighbouring cells neighbours, so the
//! search stays complete, only slower for far outliers). A body's candidates are the grid's bodies in the
//! 3 × 3 × 3 cells about its own (the cell is at least the reach of a pair of grid bodies). Each body's row is searched independently (in
//! parallel on several threads, rows in body order, so the list is the same for any number of threads).
//!
//! # Contact history across rebuilds
//! The tangential spring of a pair lives beside the pair (`histories`, aligned with the pairs); a rebuild
//! carries the spring of every pair that stays listed to its new slot (a merge of the old and new rows of
//! its first body, both sorted), and a new pair starts with no spring, as the general contact store does.
//! The merge's result is kept (`carried_from`): the pair's constants (√R*, m*, and the owner's prepared
//! law) are functions of its two bodies, so they are carried by it too instead of formed again — the
//! same bits. A build fills the vectors of the build before the last (`spare`) instead of fresh ones,
//! which spares page faults (`docs/tuning.md`). Each chunk of the search also merges its bodies' rows and copies their springs and constants (in parallel on several
//! threads), and the build only joins the chunks' vectors; the walls' springs likewise.

use rayon::prelude::*;

use crate::law::pair::effective_contact_radius;
use crate::law::TangentialHistory;
use crate::math::{Point, Real, Vector};

use super::super::grid::{CellRange, Grid, Oversize};
use super::pair::{Props, WallPlane};

/// A body whose radius exceeds this many times the median radius is searched against every body
/// instead of being binned in the grid (see the module docs).
pub const LARGE_RADIUS_FACTOR: Real = 2.0;

/// The skin of a large body's pairs, in skins (see the module docs): 4, so that a projectile four times
/// faster than the fastest bed sphere triggers no more rebuilds than the bed; its list then holds the
/// bed spheres within ~4 skins of its surface (a few tens more candidates for one projectile).
pub const LARGE_SKIN_FACTOR: Real = 4.0;

/// The grid holds at most this many cells per body (plus 27).
pub const MAX_CELLS_PER_BODY: usize = 4;

/// The lists and the state they were built from (see the module docs).
#[derive(Clone, Debug, Default)]
pub struct NeighbourList {
    pub(crate) skin: Real,
    /// Body pairs: first and second body (a < b), sorted by (a, b).
    pub(crate) a: Vec<u32>,
    pub(crate) b: Vec<u32>,
    /// The pairs of body i as side A: `row_start[i]..row_start[i + 1]`.
    pub(crate) row_start: Vec<u32>,
    /// Pair indices with body i as side B, increasing a: `as_b[as_b_start[i]..as_b_start[i + 1]]`.
    pub(crate) as_b_start: Vec<u32>,
    pub(crate) as_b: Vec<u32>,
    /// Per body pair, √R* (R* = r_a r_b/(r_a + r_b), m^½) and the effective mass m_a m_b/(m_a + m_b) (kg):
    /// constants of the pair, formed once per build with the operations of the general step.
    pub(crate) root_radius: Vec<Real>,
    pub(crate) effective_mass: Vec<Real>,
    /// The tangential spring of each body pair, and the step it entered the list.
    pub(crate) histories: Vec<TangentialHistory>,
    pub(crate) since: Vec<u64>,
    /// Per body pair, whether the pair loop's last evaluation found it overlapping (its output then
    /// holds its loads); false means its spring is cleared, so a pair that stays apart reads nothing
    /// else ([`super::pair`]). A build sets it for the springs it holds (the outputs are formed by the
    /// next evaluation).
    pub(crate) in_contact: Vec<bool>,
    /// Body–wall pairs sorted by (body, wall): the walls of body i are
    /// `wall_of[wall_start[i]..wall_start[i + 1]]`.
    pub(crate) wall_start: Vec<u32>,
    pub(crate) wall_of: Vec<u32>,
    /// The body of each body–wall pair.
    pub(crate) wall_body: Vec<u32>,
    pub(crate) wall_histories: Vec<TangentialHistory>,
    pub(crate) wall_since: Vec<u64>,
    pub(crate) wall_in_contact: Vec<bool>,
    /// Centres of the bodies and translations of the walls at the build.
    pub(crate) centres_at_build: Vec<Point>,
    pub(crate) walls_at_build: Vec<Vector>,
    /// Builds so far.
    pub(crate) builds: u64,
    /// Which bodies the grid holds (found once: the radii do not change).
    layout: Option<Layout>,
    /// Per body, whether it is large (listed with the wider skin).
    pub(crate) large_flags: Vec<bool>,
    /// Per body pair, its index in the lists of the build before ([`NOT_CARRIED`] for a pair that was
    /// not listed then): what the owner of per-pair constants carries them by.
    pub(crate) carried_from: Vec<u32>,
    /// The vectors of the build before the last, emptied and refilled by the next build.
    spare: Spare,
    /// Per chunk of bodies of the search, what it found (kept for the capacity; a clone holds none).
    chunks: SpareVec<ChunkRows>,
    /// The grid of the last build (kept for its capacity).
    grid: Grid,
}

/// [`NeighbourList::carried_from`] of a pair new to the lists.
pub(crate) const NOT_CARRIED: u32 = u32::MAX;

/// Vectors kept for reuse by the next build (see [`NeighbourList::rebuild`]); a clone holds none.
#[derive(Clone, Debug, Default)]
struct Spare {
    a: SpareVec<u32>,
    b: SpareVec<u32>,
    row_start: SpareVec<u32>,
    as_b_start: SpareVec<u32>,
    as_b: SpareVec<u32>,
    root_radius: SpareVec<Real>,
    effective_mass: SpareVec<Real>,
    histories: SpareVec<TangentialHistory>,
    since: SpareVec<u64>,
    in_contact: SpareVec<bool>,
    wall_start: SpareVec<u32>,
    wall_of: SpareVec<u32>,
    wall_body: SpareVec<u32>,
    wall_histories: SpareVec<TangentialHistory>,
    wall_since: SpareVec<u64>,
    wall_in_contact: SpareVec<bool>,
    centres_at_build: SpareVec<Point>,
    carried_from: SpareVec<u32>,
}

/// What the search found for one chunk of bodies, in body order: their rows (partners and row lengths),
/// their walls, and per pair and body–wall pair what the new lists carry (see `NeighbourList::rebuild`).
#[derive(Debug, Default)]
struct ChunkRows {
    partners: Vec<u32>,
    lengths: Vec<u32>,
    walls: Vec<u32>,
    wall_lengths: Vec<u32>,
    carried: Vec<u32>,
    histories: Vec<TangentialHistory>,
    in_contact: Vec<bool>,
    since: Vec<u64>,
    root_radius: Vec<Real>,
    effective_mass: Vec<Real>,
    wall_histories: Vec<TangentialHistory>,
    wall_since: Vec<u64>,
}

impl ChunkRows {
    /// Emptied, the capacity kept.
    fn clear(&mut self) {
        self.partners.clear();
        self.lengths.clear();
        self.walls.clear();
        self.wall_lengths.clear();
        self.carried.clear();
        self.histories.clear();
        self.in_contact.clear();
        self.since.clear();
        self.root_radius.clear();
        self.effective_mass.clear();
        self.wall_histories.clear();
        self.wall_since.clear();
    }
}

/// A vector kept only for its capacity (refilled by its owner's next use); a clone holds none.
#[derive(Debug)]
pub(crate) struct SpareVec<T>(pub(crate) Vec<T>);

impl<T> Default for SpareVec<T> {
    fn default() -> Self {
        SpareVec(Vec::new())
    }
}

impl<T> Clone for SpareVec<T> {
    fn clone(&self) -> Self {
        SpareVec(Vec::new())
    }
}

/// `v` taken and emptied, its capacity kept.
pub(crate) fn recycled<T>(v: &mut Vec<T>) -> Vec<T> {
    let mut v = std::mem::take(v);
    v.clear();
    v
}

/// The split of the bodies between the grid and the large ones (see the module docs).
#[derive(Clone, Debug)]
struct Layout {
    bodies: usize,
    median: Real,
    /// Bodies above [`LARGE_RADIUS_FACTOR`] times the median radius, and the others.
    large: Vec<u32>,
    members: Vec<u32>,
    /// The largest radius of the grid's bodies.
    r_grid: Real,
}

impl Layout {
    fn of(props: &[Props]) -> Self {
        let n = props.len();
        let mut sorted: Vec<Real> = props.iter().map(|p| p.radius).collect();
        sorted.sort_by(|x, y| x.total_cmp(y));
        let median = sorted.get(n / 2).copied().unwrap_or(0.0);
        let is_large = |i: &u32| props[*i as usize].radius > LARGE_RADIUS_FACTOR * median;
        let (large, members): (Vec<u32>, Vec<u32>) = (0..n as u32).partition(is_large);
        let r_grid = members
            .iter()
            .map(|&i| props[i as usize].radius)
            .fold(0.0, Real::max);
        Self {
            bodies: n,
            median,
            large,
            members,
            r_grid,
        }
    }
}

/// The spring and entry step of a pair given as a body pair `(a, b)` or a body–wall pair `(body, wall)`,
/// if known (see [`NeighbourList::rebuild`]).
pub(crate) type ImportHistory<'a> =
    dyn Fn(Option<(u32, u32)>, Option<(u32, u32)>) -> Option<(TangentialHistory, u64)> + Sync + 'a;

/// [`NeighbourList::is_stale`] with the walls' moves formed: what decides from the bodies' displacements
/// alone whether the lists hold (each thread of the team decides it for itself: `super::fused`).
#[derive(Clone, Copy, Debug)]
pub(crate) struct StaleTest {
    /// The lists must be built whatever the displacements (never built, or other walls).
    always: bool,
    /// The largest squared move of a wall since the build (m²).
    walls_moved: Real,
    skin: Real,
}

impl StaleTest {
    /// Whether a pair left out may overlap, with `top` and `large` the two largest squared displacements
    /// since the build of the small and of the large bodies.
    pub(crate) fn is_stale(&self, top: TopTwo, large: TopTwo) -> bool {
        if self.always {
            return true;
        }
        let w1 = self.walls_moved;
        let margin = 1.0 - 1e-9;
        top.first.sqrt() + top.second.max(w1).sqrt() >= self.skin * margin
            || large.first.sqrt() + large.second.max(top.first).max(w1).sqrt()
                >= self.skin * LARGE_SKIN_FACTOR * margin
    }
}

/// The two largest of a set of squared displacements (order-free: the same for any split of the set).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(crate) struct TopTwo {
    pub(crate) first: Real,
    pub(crate) second: Real,
}

impl TopTwo {
    #[inline(always)]
    pub(crate) fn push(&mut self, d_sq: Real) {
        if d_sq > self.second {
            if d_sq > self.first {
                self.second = self.first;
                self.first = d_sq;
            } else {
                self.second = d_sq;
            }
        }
    }

    pub(crate) fn merge(mut self, other: TopTwo) -> TopTwo {
        self.push(other.first);
        self.push(other.second);
        self
    }
}

/// Shapes `grid` over the centres of the grid's bodies `members`, with cells `cell` wide, at most
/// [`MAX_CELLS_PER_BODY`] per body (plus 27), and bins each member in the cell of its centre.
fn bin_members(grid: &mut Grid, centres: &[Point], members: &[u32], cell: Real) {
    let (mut lo, mut hi) = ([Real::INFINITY; 3], [Real::NEG_INFINITY; 3]);
    for &i in members {
        let x = &centres[i as usize];
        for k in 0..3 {
            lo[k] = lo[k].min(x[k]);
            hi[k] = hi[k].max(x[k]);
        }
    }
    if members.is_empty() {
        (lo, hi) = ([0.0; 3], [0.0; 3]);
    }
    // Cut rather than grow: a far outlier clamps into an edge cell and the bed keeps its resolution.
    let limit = MAX_CELLS_PER_BODY * members.len() + 27;
    grid.shape(lo, hi, cell, limit, Oversize::CutLongestAxis);
    let cells: Vec<CellRange> = members
        .iter()
        .map(|&i| CellRange::cell(grid.cell_of(&centres[i as usize])))
        .collect();
    grid.bin(&cells, |k| members[k]);
}

impl NeighbourList {
    /// An empty list with the given skin (m); the first `rebuild` fills it.
    pub fn new(skin: Real) -> Self {
        Self {
            skin,
            ..Self::default()
        }
    }

    /// Builds so far.
    pub fn builds(&self) -> u64 {
        self.builds
    }

    /// The skin (m).
    pub fn skin(&self) -> Real {
        self.skin
    }

    /// Body pairs listed.
    pub fn body_pairs(&self) -> usize {
        self.a.len()
    }

    /// Body–wall pairs listed.
    pub fn wall_pairs(&self) -> usize {
        self.wall_of.len()
    }

    /// Whether a pair left out may overlap now (see the module docs): the two largest displacements since
    /// the build, `top` (squared, bodies) and the walls' moves, sum to the skin.
    /// `large` holds the two largest of the large bodies.
    pub(crate) fn is_stale(&self, top: TopTwo, large: TopTwo, walls: &[WallPlane]) -> bool {
        self.stale_test(walls).is_stale(top, large)
    }

    /// The test of [`NeighbourList::is_stale`] for the walls at `walls` (their part of it formed).
    pub(crate) fn stale_test(&self, walls: &[WallPlane]) -> StaleTest {
        let always = self.builds == 0 || walls.len() != self.walls_at_build.len();
        let walls_moved = walls
            .iter()
            .zip(&self.walls_at_build)
            .map(|(w, then)| (w.pose.translation.vector - then).norm_squared())
            .fold(0.0, Real::max);
        StaleTest {
            always,
            walls_moved,
            skin: self.skin,
        }
    }

    /// Whether body `i` is a large body (listed with the wider skin; see the module docs).
    pub(crate) fn is_large(&self, i: usize) -> bool {
        self.large_flags.get(i).copied().unwrap_or(false)
    }

    /// The skin (m) of body `i`'s pairs with small bodies and walls.
    pub fn skin_of(&self, i: usize) -> Real {
        if self.is_large(i) {
            self.skin * LARGE_SKIN_FACTOR
        } else {
            self.skin
        }
    }

    /// Rebuilds the lists at `centres`, carrying every listed pair's spring (see the module docs).
    /// `history_of` gives the spring and entry step of a new pair the old lists do not hold, as a body
    /// pair `(a, b)` or a body–wall pair `(body, wall)` (the import from a world's contact store on the
    /// first build; `None`: no spring, entering at `step`).
    pub(crate) fn rebuild(
        &mut self,
        centres: &[Point],
        props: &[Props],
        walls: &[WallPlane],
        parallel: bool,
        step: u64,
        history_of: &ImportHistory<'_>,
    ) {
        let n = centres.len();
        let skin = self.skin;
        // Large bodies out of the grid (the radii do not change: found on the first build).
        if self.layout.is_none() || self.layout.as_ref().is_some_and(|l| l.bodies != n) {
            self.layout = Some(Layout::of(props));
        }
        let layout = self.layout.take().unwrap_or_else(|| Layout::of(props));
        let cell = (2.0 * layout.r_grid + skin).max(Real::MIN_POSITIVE);
        let mut grid = std::mem::take(&mut self.grid);
        bin_members(&mut grid, centres, &layout.members, cell);
        let mut chunks = std::mem::take(&mut self.chunks.0);
        let search = Search {
            centres,
            props,
            walls,
            layout: &layout,
            grid: &grid,
            skin,
        };
        self.search_chunks(&search, parallel, step, history_of, &mut chunks);
        let large_flags = (0..n).map(|i| search.is_large(i)).collect();
        // The chunks joined in the vectors of the build before the last (their capacity kept: fresh
        // vectors of a few hundred kB per build came back as page faults on every build).
        let mut old = std::mem::take(self);
        let mut spare = std::mem::take(&mut old.spare);
        self.skin = skin;
        self.builds = old.builds + 1;
        self.join_chunks(&chunks, &mut spare);
        self.chunks = SpareVec(chunks);
        self.grid = grid;
        self.index_side_b(n, &mut spare);
        self.wall_in_contact = recycled(&mut spare.wall_in_contact.0);
        self.wall_in_contact
            .extend(self.wall_histories.iter().map(|h| !h.is_cleared()));
        self.centres_at_build = recycled(&mut spare.centres_at_build.0);
        self.centres_at_build.extend_from_slice(centres);
        self.large_flags = large_flags;
        self.layout = Some(layout);
        self.walls_at_build = walls.iter().map(|w| w.pose.translation.vector).collect();
        // The old lists' vectors are the next build's.
        self.spare = Spare::of(old);
    }

    /// Per chunk of bodies, independently: their rows, walls, and each pair's spring and constants
    /// (see [`Self::search_body`]); in parallel, since this is a third of a build on two threads.
    fn search_chunks(
        &self,
        search: &Search<'_>,
        parallel: bool,
        step: u64,
        history_of: &ImportHistory<'_>,
        chunks: &mut Vec<ChunkRows>,
    ) {
        let n = search.centres.len();
        let chunk = chunk_len(n, parallel);
        let ranges: Vec<std::ops::Range<usize>> = (0..n)
            .step_by(chunk.max(1))
            .map(|s| s..(s + chunk).min(n))
            .collect();
        chunks.resize_with(ranges.len(), ChunkRows::default);
        let search_chunk = |(range, rows): (std::ops::Range<usize>, &mut ChunkRows)| {
            rows.clear();
            for i in range {
                self.search_body(search, i, rows, step, history_of);
            }
        };
        if parallel {
            ranges
                .into_par_iter()
                .zip(chunks.par_iter_mut())
                .with_max_len(1)
                .for_each(search_chunk);
        } else {
            ranges
                .into_iter()
                .zip(chunks.iter_mut())
                .for_each(search_chunk);
        }
    }

    /// Body `i`'s row and walls appended to `rows`, each pair's spring and constants carried over from
    /// the old lists (the constants are functions of the two bodies: the same bits as forming them
    /// again), or imported, or new.
    #[inline]
    fn search_body(
        &self,
        search: &Search<'_>,
        i: usize,
        rows: &mut ChunkRows,
        step: u64,
        history_of: &ImportHistory<'_>,
    ) {
        let (p0, w0) = (rows.partners.len(), rows.walls.len());
        search.row(i, &mut rows.partners);
        search.wall_row(i, &mut rows.walls);
        rows.lengths.push((rows.partners.len() - p0) as u32);
        rows.wall_lengths.push((rows.walls.len() - w0) as u32);
        // Each new pair's slot in the old lists, if it was listed there: a merge of the old and new
        // rows of its first body (both sorted by the second body).
        let (old_first, old_row) = self.old_row(i);
        let mut k = 0;
        for &j in &rows.partners[p0..] {
            while k < old_row.len() && old_row[k] < j {
                k += 1;
            }
            if k < old_row.len() && old_row[k] == j {
                let from = old_first + k;
                rows.carried.push(from as u32);
                rows.histories.push(self.histories[from]);
                rows.in_contact.push(!self.histories[from].is_cleared());
                rows.since.push(self.since[from]);
                rows.root_radius.push(self.root_radius[from]);
                rows.effective_mass.push(self.effective_mass[from]);
                continue;
            }
            let (h, since) =
                history_of(Some((i as u32, j)), None).unwrap_or((Default::default(), step));
            let (pa, pb) = (&search.props[i], &search.props[j as usize]);
            rows.carried.push(NOT_CARRIED);
            rows.histories.push(h);
            rows.in_contact.push(!h.is_cleared());
            rows.since.push(since);
            rows.root_radius
                .push(effective_contact_radius(Some(pa.radius), Some(pb.radius)).sqrt());
            rows.effective_mass
                .push(pa.mass * pb.mass / (pa.mass + pb.mass));
        }
        for &wall in &rows.walls[w0..] {
            let (h, since) = match self.old_wall(i, wall) {
                Some(k) => (self.wall_histories[k], self.wall_since[k]),
                None => {
                    history_of(None, Some((i as u32, wall))).unwrap_or((Default::default(), step))
                }
            };
            rows.wall_histories.push(h);
            rows.wall_since.push(since);
        }
    }

    /// Body `a`'s row in these lists: the index of its first pair and the second bodies.
    #[inline]
    fn old_row(&self, a: usize) -> (usize, &[u32]) {
        match self.row_start.get(a..a + 2) {
            Some(&[s, e]) => (s as usize, &self.b[s as usize..e as usize]),
            _ => (0, &[][..]),
        }
    }

    /// The index of the body–wall pair `(body, wall)` in these lists, if listed.
    #[inline]
    fn old_wall(&self, body: usize, wall: u32) -> Option<usize> {
        let (s, e) = match self.wall_start.get(body..body + 2) {
            Some(&[s, e]) => (s as usize, e as usize),
            _ => return None,
        };
        self.wall_of[s..e]
            .iter()
            .position(|&w| w == wall)
            .map(|k| s + k)
    }

    /// The pairs and walls of the chunks, in body order, into the spare vectors of the build before the
    /// last.
    fn join_chunks(&mut self, chunks: &[ChunkRows], spare: &mut Spare) {
        self.a = recycled(&mut spare.a.0);
        self.b = recycled(&mut spare.b.0);
        self.row_start = recycled(&mut spare.row_start.0);
        self.wall_start = recycled(&mut spare.wall_start.0);
        self.wall_of = recycled(&mut spare.wall_of.0);
        self.wall_body = recycled(&mut spare.wall_body.0);
        self.carried_from = recycled(&mut spare.carried_from.0);
        self.histories = recycled(&mut spare.histories.0);
        // A held spring is a contact until the pair loop finds it apart (see `in_contact`).
        self.in_contact = recycled(&mut spare.in_contact.0);
        self.since = recycled(&mut spare.since.0);
        self.root_radius = recycled(&mut spare.root_radius.0);
        self.effective_mass = recycled(&mut spare.effective_mass.0);
        self.wall_histories = recycled(&mut spare.wall_histories.0);
        self.wall_since = recycled(&mut spare.wall_since.0);
        self.row_start.push(0);
        self.wall_start.push(0);
        let mut i = 0u32;
        for rows in chunks {
            for (&len, &wall_len) in rows.lengths.iter().zip(&rows.wall_lengths) {
                self.a.extend(std::iter::repeat_n(i, len as usize));
                self.row_start.push(self.a.len() as u32);
                self.wall_body
                    .extend(std::iter::repeat_n(i, wall_len as usize));
                self.wall_start.push(self.wall_body.len() as u32);
                i += 1;
            }
            self.b.extend_from_slice(&rows.partners);
            self.wall_of.extend_from_slice(&rows.walls);
            self.carried_from.extend_from_slice(&rows.carried);
            self.histories.extend_from_slice(&rows.histories);
            self.in_contact.extend_from_slice(&rows.in_contact);
            self.since.extend_from_slice(&rows.since);
            self.root_radius.extend_from_slice(&rows.root_radius);
            self.effective_mass.extend_from_slice(&rows.effective_mass);
            self.wall_histories.extend_from_slice(&rows.wall_histories);
            self.wall_since.extend_from_slice(&rows.wall_since);
        }
    }

    /// Side-B rows: pairs in key order appended to their second body's row (so increasing a).
    fn index_side_b(&mut self, n: usize, spare: &mut Spare) {
        self.as_b_start = recycled(&mut spare.as_b_start.0);
        self.as_b_start.resize(n + 1, 0);
        for &b in &self.b {
            self.as_b_start[b as usize + 1] += 1;
        }
        for k in 0..n {
            self.as_b_start[k + 1] += self.as_b_start[k];
        }
        self.as_b = recycled(&mut spare.as_b.0);
        self.as_b.resize(self.b.len(), 0);
        let mut fill = self.as_b_start.clone();
        for (p, &b) in self.b.iter().enumerate() {
            self.as_b[fill[b as usize] as usize] = p as u32;
            fill[b as usize] += 1;
        }
    }
}

/// What decides at a build which pairs are listed: the centres and radii, the grid of the bodies that
/// are not large, and the skins.
struct Search<'a> {
    centres: &'a [Point],
    props: &'a [Props],
    walls: &'a [WallPlane],
    layout: &'a Layout,
    grid: &'a Grid,
    skin: Real,
}

impl Search<'_> {
    /// Whether body `i` is large (searched against every body, with the wider skin).
    #[inline]
    fn is_large(&self, i: usize) -> bool {
        self.props[i].radius > LARGE_RADIUS_FACTOR * self.layout.median
    }

    /// The skin of body `i`'s pairs with walls and with bodies that are not large.
    #[inline]
    fn own_skin(&self, i: usize) -> Real {
        if self.is_large(i) {
            self.skin * LARGE_SKIN_FACTOR
        } else {
            self.skin
        }
    }

    /// Whether bodies `i` and `j` are within reach: closer than the sum of their radii and the pair's skin.
    #[inline]
    fn reach(&self, i: usize, j: usize) -> bool {
        let pair_skin = if self.is_large(i) || self.is_large(j) {
            self.skin * LARGE_SKIN_FACTOR
        } else {
            self.skin
        };
        let r = self.props[i].radius + self.props[j].radius + pair_skin;
        (self.centres[j] - self.centres[i]).norm_squared() < r * r
    }

    /// Body `i`'s partners j > i within reach, increasing, appended to `out`.
    #[inline]
    fn row(&self, i: usize, out: &mut Vec<u32>) {
        let (centres, props, n) = (self.centres, self.props, self.centres.len());
        let start = out.len();
        if self.is_large(i) {
            out.extend((i as u32 + 1..n as u32).filter(|&j| self.reach(i, j as usize)));
            return;
        }
        let (x_i, r_i, skin) = (centres[i], props[i].radius, self.skin);
        let grid = self.grid;
        // The cells of a row are one run of bodies (the row is sorted below, so the order of the runs
        // does not matter). Neither i nor a body of the grid is large: the plain skin.
        grid.for_each_row(&grid.neighbourhood(grid.cell_of(&x_i)), |bodies| {
            for &j in bodies {
                let ju = j as usize;
                if ju > i {
                    let r = r_i + props[ju].radius + skin;
                    if (centres[ju] - x_i).norm_squared() < r * r {
                        out.push(j);
                    }
                }
            }
        });
        out.extend(
            self.layout
                .large
                .iter()
                .copied()
                .filter(|&j| j as usize > i && self.reach(i, j as usize)),
        );
        out[start..].sort_unstable();
    }

    /// The walls within body `i`'s skin of its sphere, increasing, appended to `out`.
    #[inline]
    fn wall_row(&self, i: usize, out: &mut Vec<u32>) {
        let own_skin = self.own_skin(i);
        for (w, plane) in self.walls.iter().enumerate() {
            if plane.height(&self.centres[i]) - self.props[i].radius < own_skin {
                out.push(w as u32);
            }
        }
    }
}

impl Spare {
    /// The vectors of `old` lists, kept for the next build.
    fn of(old: NeighbourList) -> Self {
        Self {
            a: SpareVec(old.a),
            b: SpareVec(old.b),
            row_start: SpareVec(old.row_start),
            as_b_start: SpareVec(old.as_b_start),
            as_b: SpareVec(old.as_b),
            root_radius: SpareVec(old.root_radius),
            effective_mass: SpareVec(old.effective_mass),
            histories: SpareVec(old.histories),
            since: SpareVec(old.since),
            in_contact: SpareVec(old.in_contact),
            wall_start: SpareVec(old.wall_start),
            wall_of: SpareVec(old.wall_of),
            wall_body: SpareVec(old.wall_body),
            wall_histories: SpareVec(old.wall_histories),
            wall_since: SpareVec(old.wall_since),
            wall_in_contact: SpareVec(old.wall_in_contact),
            centres_at_build: SpareVec(old.centres_at_build),
            carried_from: SpareVec(old.carried_from),
        }
    }
}

/// Items per parallel chunk: a few chunks per thread so that a thread that runs dry takes work from the
/// other (the whole range when serial).
fn chunk_len(n: usize, parallel: bool) -> usize {
    if !parallel {
        return n.max(1);
    }
    let chunks = rayon::current_num_threads() * super::super::parallel::CHUNKS_PER_THREAD / 4;
    n.div_ceil(chunks.max(1)).max(64)
}
