//! Geometric pre-collapse of the loose sample: a packing-procedure choice, not part of the paper's method.
//!
//! The paper drops the loose Voronoi sample under gravity and compacts it with the top wall (section 4.1) but
//! does not fix how the drop is done. A drop from the generation region (2.6 H tall, see
//! `packing.generation_height_factor`) spends most of the packing's steps in free fall and in damping the
//! chaos of the impacts. Here every rock keeps its shape and its orientation and is only **translated**, one
//! after the other, lowest first: down until it comes within `gap` of a rock, the floor or a side wall, then
//! sliding down the blocker's tangent plane, then down the crease between two blockers, until three blockers
//! hold it or the way down no longer descends (a translation-only, frictionless "drop and roll" sequential
//! deposition). The dynamic deposition then starts from a dense, nearly supported, non-overlapping state.
//!
//! # Algorithm
//! A move of rock A along a unit direction v is limited by every body it could meet: the floor and side walls
//! (closed form from A's vertex box) and the rocks whose boxes meet A's box swept along the move, found in a
//! uniform (x, y) grid. For a rock B the first contact is found by **conservative advancement**: with the gap
//! d between A and B and the unit normal n from A to B of their closest points (GJK distance query,
//! [`polydem::contact::query_polyhedra`]), the plane normal to n through the gap separates the two bodies as long
//! as A has moved by less than d / (v·n); if v·n ≤ 0 that plane separates A from B along the whole move, so B
//! never blocks it. Advancing by (d − gap_AB) / (v·n) at a time leaves the pair at least gap_AB apart after
//! every advance, so no state the collapse produces overlaps (`tests/rockfill_collapse.rs` checks every pair
//! with the exact SAT oracle). gap_AB = `gap` when the move starts at least that far from B, else half the
//! starting gap d₀ (shrunk cells of neighbouring seeds can start closer than `gap`): a pair generated at least
//! `gap` apart ends at least `gap` apart. An advance ends within
//! `tolerance` of the gap, after [`MAX_ADVANCES`] advances (then A stops short of the contact: safe), or
//! beyond the move already allowed by another body.
//!
//! Moves: (1) straight down (−ẑ) to the first blocker, normal n₁; (2) along −ẑ projected on the plane normal
//! to n₁ (the gap to the first blocker along n₁ stays constant, so it cannot be met again), at most one mean
//! size, to a second blocker n₂ — or, if none is met, straight down again; (3) along the crease n₁ × n₂
//! pointing down (or along n₂'s plane alone when that leaves the first blocker); a third blocker ends the
//! rock's moves, as does a direction that no longer descends ([`MIN_DESCENT`]: a flat face or a horizontal
//! crease) or [`MAX_MOVES`] moves. The slides are frictionless (geometry only).
//!
//! # Limits
//! The rocks do not rotate, so a rock does not topple off an edge: the collapsed state is looser than a
//! settled bed. The dynamic deposition that follows (gravity, Table 1's laws, the packing damping) lets the
//! rocks roll and settle, and the top wall's compaction does the rest (see [`super::packing`]).

use std::time::{Duration, Instant};

use super::grading::Rock;
use polydem::contact::{query_polyhedra, ContactKind};
use polydem::math::{Pose, Real, Vector};
use polydem::shape::Aabb;

/// Largest number of conservative-advancement steps for one pair and move. Each step removes the part of the
/// gap that lies along the move; a pair passing each other at a grazing angle converges slowest. A capped pair
/// stops short of contact, which is safe (the report counts them).
pub const MAX_ADVANCES: usize = 64;

/// A move whose direction descends less than this per unit length ends the rock's moves (a flat face, or a
/// horizontal crease, holds it). The slides are frictionless: with Table 1's μ = 0.2 as the stopping slope
/// (tan θ < μ) the quick sample ended with 155 of 351 rocks held by three blockers against 308 without, for
/// the same top, and the dynamic deposition has more to settle.
pub const MIN_DESCENT: Real = 1e-3;

/// Largest number of moves of one rock (see the module docs): enough for a drop, a few slides and re-drops.
pub const MAX_MOVES: usize = 16;

/// How to collapse.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CollapseParams {
    /// Container: floor z = `floor`, side walls x = 0, x = `length`, y = 0, y = `width` (m).
    pub floor: Real,
    pub length: Real,
    pub width: Real,
    /// Gap left between a rock and whatever stops it (m).
    pub gap: Real,
    /// An advance ends when the gap is within this of the pair's gap (m).
    pub tolerance: Real,
    /// Longest slide of one move (m).
    pub max_slide: Real,
}

impl CollapseParams {
    /// Gap `gap_fraction × mean_size`, tolerance a tenth of the gap, slides of one mean size, floor at z = 0.
    pub fn new(length: Real, width: Real, mean_size: Real, gap_fraction: Real) -> Self {
        let gap = gap_fraction * mean_size;
        Self {
            floor: 0.0,
            length,
            width,
            gap,
            tolerance: 0.1 * gap,
            max_slide: mean_size,
        }
    }
}

/// What the collapse did.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct CollapseReport {
    pub rocks: usize,
    /// Highest rock point before and after (m).
    pub top_before: Real,
    pub top_after: Real,
    /// Mean and largest descent of a rock (m).
    pub mean_descent: Real,
    pub max_descent: Real,
    /// Moves made, and rocks that ended held by three blockers.
    pub moves: u64,
    pub held_by_three: usize,
    /// Pairs examined and distance queries made.
    pub pairs: u64,
    pub queries: u64,
    /// Pair advances that hit [`MAX_ADVANCES`] (stopped short, safe).
    pub capped: u64,
    pub wall_time: Duration,
}

/// The gap a move keeps to a body it starts `start` away from: the requested `gap`, or half the starting gap
/// for a pair that starts closer (then it may still close, by halves, but never to contact).
fn pair_gap(gap: Real, start: Real) -> Real {
    if start >= gap {
        gap
    } else {
        0.5 * start
    }
}

/// Move of `a` (at `pose_a`) along the unit direction `v` before it comes within the pair's gap of `b`, with
/// the blocking normal (from A to B), if shorter than `limit`.
fn move_until_contact(
    a: &Rock,
    pose_a: &Pose,
    v: &Vector,
    b: &Rock,
    params: &CollapseParams,
    limit: Real,
    report: &mut CollapseReport,
) -> Option<(Real, Vector)> {
    let mut s = 0.0;
    let mut target = params.gap;
    for k in 0..MAX_ADVANCES {
        let mut moved = *pose_a;
        moved.translation.vector += v * s;
        let g = query_polyhedra(&moved, &a.shape, &b.pose, &b.shape);
        report.queries += 1;
        if g.kind != ContactKind::Separated {
            // Only at s = 0, for a pair that starts touching: A cannot move towards B at all.
            return (g.normal.dot(v) > 0.0).then_some((s, g.normal));
        }
        if k == 0 {
            target = pair_gap(params.gap, g.distance);
        }
        let approach = g.normal.dot(v);
        if approach <= 0.0 {
            return None;
        }
        let advance = (g.distance - target) / approach;
        if advance <= params.tolerance {
            return Some((s, g.normal));
        }
        s += advance;
        if s >= limit {
            return None;
        }
    }
    report.capped += 1;
    Some((s, Vector::zeros()))
}

/// Uniform (x, y) grid of the rocks' boxes.
struct Grid {
    lo: (Real, Real),
    cell: Real,
    nx: usize,
    ny: usize,
    cells: Vec<Vec<u32>>,
}

impl Grid {
    fn range(&self, b: &Aabb) -> (usize, usize, usize, usize) {
        let ix =
            |x: Real| (((x - self.lo.0) / self.cell).floor().max(0.0) as usize).min(self.nx - 1);
        let iy =
            |y: Real| (((y - self.lo.1) / self.cell).floor().max(0.0) as usize).min(self.ny - 1);
        (ix(b.mins.x), ix(b.maxs.x), iy(b.mins.y), iy(b.maxs.y))
    }

    fn insert(&mut self, i: usize, b: &Aabb) {
        let (x0, x1, y0, y1) = self.range(b);
        for gx in x0..=x1 {
            for gy in y0..=y1 {
                self.cells[gx * self.ny + gy].push(i as u32);
            }
        }
    }

    fn remove(&mut self, i: usize, b: &Aabb) {
        let (x0, x1, y0, y1) = self.range(b);
        for gx in x0..=x1 {
            for gy in y0..=y1 {
                self.cells[gx * self.ny + gy].retain(|&j| j as usize != i);
            }
        }
    }
}

/// The rocks being moved, with their boxes binned in a grid over the container, and the report.
struct Pile<'a> {
    rocks: &'a mut [Rock],
    boxes: Vec<Aabb>,
    grid: Grid,
    params: &'a CollapseParams,
    /// Per rock, the last visit that looked at it (a rock in several cells is tested once per visit).
    stamp: Vec<u64>,
    visit: u64,
    candidates: Vec<usize>,
    report: CollapseReport,
}

impl<'a> Pile<'a> {
    /// The rocks' boxes in a grid over the container, cells of the largest horizontal box extent.
    fn new(rocks: &'a mut [Rock], params: &'a CollapseParams) -> Self {
        let boxes: Vec<Aabb> = rocks.iter().map(|r| r.shape.aabb(&r.pose)).collect();
        let mut cell: Real = 0.0;
        for b in &boxes {
            cell = cell.max(b.maxs.x - b.mins.x).max(b.maxs.y - b.mins.y);
        }
        let cell = cell.max(params.gap).max(Real::MIN_POSITIVE);
        let nx = ((params.length / cell).floor() as usize + 1).max(1);
        let ny = ((params.width / cell).floor() as usize + 1).max(1);
        let mut grid = Grid {
            lo: (0.0, 0.0),
            cell,
            nx,
            ny,
            cells: vec![Vec::new(); nx * ny],
        };
        for (i, b) in boxes.iter().enumerate() {
            grid.insert(i, b);
        }
        let report = CollapseReport {
            rocks: rocks.len(),
            ..Default::default()
        };
        Self {
            stamp: vec![u64::MAX; rocks.len()],
            rocks,
            boxes,
            grid,
            params,
            visit: 0,
            candidates: Vec::new(),
            report,
        }
    }

    /// Moves rock `i` down, then sliding on up to two blockers, until three hold it, a move is capped
    /// short of a contact, the way down is too flat, or [`MAX_MOVES`] moves are made.
    fn settle(&mut self, i: usize) {
        let box0 = self.boxes[i];
        let mut normals: Vec<Vector> = Vec::with_capacity(3);
        for _ in 0..MAX_MOVES {
            let Some(v) = next_direction(&mut normals) else {
                break;
            };
            let limit = if normals.is_empty() {
                Real::INFINITY
            } else {
                self.params.max_slide
            };
            self.visit += 1;
            self.report.moves += 1;
            let hit = self.first_blocker(i, &v, limit);
            let s = hit.map_or(limit, |(s, _)| s);
            if s.is_finite() && s > 0.0 {
                self.rocks[i].pose.translation.vector += v * s;
                self.boxes[i].mins += v * s;
                self.boxes[i].maxs += v * s;
            }
            match hit {
                Some((_, n)) if n != Vector::zeros() => {
                    normals.push(n);
                    if normals.len() == 3 {
                        self.report.held_by_three += 1;
                        break;
                    }
                }
                // An advance capped short of a contact: stop here (safe).
                Some(_) => break,
                // A free slide: drop straight down again.
                None => normals.clear(),
            }
        }
        if self.boxes[i] != box0 {
            self.grid.remove(i, &box0);
            self.grid.insert(i, &self.boxes[i]);
        }
    }

    /// The first blocker of rock `i` moving along `v` by at most `limit`: (distance, normal from the rock
    /// to the blocker), or `None` if the whole move is free.
    fn first_blocker(&mut self, i: usize, v: &Vector, limit: Real) -> Option<(Real, Vector)> {
        let bi = self.boxes[i];
        let (mut best, mut reach) = wall_blocker(&bi, v, limit, self.params);
        self.gather_candidates(i, &swept_box(&bi, &(v * reach), self.params.gap));
        // Nearest along the move first (by box centre), so that the first blockers shorten the reach.
        let centre = |b: &Aabb| (b.mins.coords + b.maxs.coords) * 0.5;
        let ci = centre(&bi);
        let boxes = &self.boxes;
        self.candidates.sort_by(|&a, &b| {
            let da = (centre(&boxes[a]) - ci).dot(v);
            let db = (centre(&boxes[b]) - ci).dot(v);
            da.total_cmp(&db)
        });
        for &j in &self.candidates {
            // Box test against the move still allowed.
            if !swept_box(&bi, &(v * reach), self.params.gap).intersects(&self.boxes[j]) {
                continue;
            }
            self.report.pairs += 1;
            let rock = &self.rocks[i];
            let hit = move_until_contact(
                rock,
                &rock.pose,
                v,
                &self.rocks[j],
                self.params,
                reach,
                &mut self.report,
            );
            if let Some((s, n)) = hit {
                if s < reach || best.is_none() {
                    reach = s;
                    best = Some((s, n));
                }
            }
        }
        best
    }

    /// The rocks other than `i` whose boxes meet `swept`, into `candidates`.
    fn gather_candidates(&mut self, i: usize, swept: &Aabb) {
        self.candidates.clear();
        let grid = &self.grid;
        let (x0, x1, y0, y1) = grid.range(swept);
        for gx in x0..=x1 {
            for gy in y0..=y1 {
                for &j in &grid.cells[gx * grid.ny + gy] {
                    let j = j as usize;
                    if j != i && self.stamp[j] != self.visit {
                        self.stamp[j] = self.visit;
                        if swept.intersects(&self.boxes[j]) {
                            self.candidates.push(j);
                        }
                    }
                }
            }
        }
    }
}

/// The floor or side wall that box `bi` moving along `v` meets first within `limit` (stopping at the pair
/// gap from it): (Some((distance, normal towards the wall)), distance), or (None, `limit`).
fn wall_blocker(
    bi: &Aabb,
    v: &Vector,
    limit: Real,
    params: &CollapseParams,
) -> (Option<(Real, Vector)>, Real) {
    let mut best: Option<(Real, Vector)> = None;
    let mut reach = limit;
    // Floor and side walls: (gap, rate at which the move closes it, normal towards the wall).
    let walls = [
        (bi.mins.z - params.floor, -v.z, -Vector::z()),
        (bi.mins.x, -v.x, -Vector::x()),
        (params.length - bi.maxs.x, v.x, Vector::x()),
        (bi.mins.y, -v.y, -Vector::y()),
        (params.width - bi.maxs.y, v.y, Vector::y()),
    ];
    for (gap, rate, normal) in walls {
        if rate > 0.0 {
            let target = pair_gap(params.gap, gap.max(0.0));
            let s = ((gap - target) / rate).max(0.0);
            if s < reach {
                reach = s;
                best = Some((s, normal));
            }
        }
    }
    (best, reach)
}

/// Box `bi` swept by `end` and grown by `gap` on every side.
fn swept_box(bi: &Aabb, end: &Vector, gap: Real) -> Aabb {
    let mut swept = *bi;
    for k in 0..3 {
        swept.mins[k] = bi.mins[k].min(bi.mins[k] + end[k]) - gap;
        swept.maxs[k] = bi.maxs[k].max(bi.maxs[k] + end[k]) + gap;
    }
    swept
}

/// The next move's direction for a rock held by `normals` (none: straight down; one: down its face; two:
/// along their crease, or down the second face when that leaves the first), or `None` when the way down
/// is too flat. Drops the first blocker when the rock slides off it.
fn next_direction(normals: &mut Vec<Vector>) -> Option<Vector> {
    let down = -Vector::z();
    let v = match *normals.as_slice() {
        [] => down,
        [n1] => down - n1 * down.dot(&n1),
        [n1, n2] => {
            let along2 = down - n2 * down.dot(&n2);
            if along2.dot(&n1) <= 0.0 {
                // Sliding on the second blocker alone leaves the first one.
                normals.remove(0);
                along2
            } else {
                let c = n1.cross(&n2);
                if c.z > 0.0 {
                    -c
                } else {
                    c
                }
            }
        }
        _ => return None,
    };
    let v = v.try_normalize(1e-12)?;
    if -v.z < MIN_DESCENT {
        None
    } else {
        Some(v)
    }
}

/// Moves the rocks (see the module docs); returns what it did.
pub fn collapse(rocks: &mut [Rock], params: &CollapseParams) -> CollapseReport {
    let start = Instant::now();
    if rocks.is_empty() {
        return CollapseReport::default();
    }
    let z_before: Vec<Real> = rocks.iter().map(|r| r.pose.translation.vector.z).collect();
    let mut pile = Pile::new(rocks, params);
    pile.report.top_before = highest_top(&pile.boxes);
    let mut order: Vec<usize> = (0..pile.rocks.len()).collect();
    let boxes = &pile.boxes;
    order.sort_by(|&i, &j| boxes[i].mins.z.total_cmp(&boxes[j].mins.z).then(i.cmp(&j)));
    for i in order {
        pile.settle(i);
    }
    let Pile {
        rocks,
        boxes,
        mut report,
        ..
    } = pile;
    let mut total_descent = 0.0;
    for (r, z0) in rocks.iter().zip(&z_before) {
        let d = z0 - r.pose.translation.vector.z;
        total_descent += d;
        report.max_descent = report.max_descent.max(d);
    }
    report.mean_descent = total_descent / rocks.len() as Real;
    report.top_after = highest_top(&boxes);
    report.wall_time = start.elapsed();
    report
}

/// The highest top of `boxes` (m).
fn highest_top(boxes: &[Aabb]) -> Real {
    boxes
        .iter()
        .map(|b| b.maxs.z)
        .fold(Real::NEG_INFINITY, Real::max)
}
