//! The 3D Voronoi tessellation of the seeds in a box (paper eqs. 26–27), computed by voro++ (C. H. Rycroft,
//! Chaos 19, 041111, 2009) through its Rust bindings `voro_rs` (licence BSD-3-Clause-LBNL for voro++,
//! MIT/Apache-2.0 for the bindings; both compile from source with a C++14 compiler, no other system library).
//!
//! Each cell is the set of points of the box closer to its seed than to any other seed: a convex polyhedron,
//! clipped by the box faces. The cells tile the box; a cell's neighbour list names the seeds across its
//! faces (negative ids are the box walls, voro++'s convention: −1…−6 for x−, x+, y−, y+, z−, z+).
//!
//! Limits: a non-periodic box only (the experiment's region is a box); seeds must lie inside it and be
//! distinct (coincident seeds have no bisector plane, and voro++ drops one of the two cells).

use voro_rs::prelude::*;

use super::seeds::Region;
use polydem::math::{Point, Real};

/// Why a tessellation failed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum VoronoiError {
    #[error("seed {index} at {position:?} lies outside the region")]
    SeedOutside { index: usize, position: [Real; 3] },
    #[error("voro++ computed {computed} cells for {seeds} seeds (coincident seeds?)")]
    MissingCells { computed: usize, seeds: usize },
    #[error("no seeds")]
    NoSeeds,
}

/// One Voronoi cell in world coordinates.
#[derive(Clone, Debug, PartialEq)]
pub struct VoronoiCell {
    /// Index of the seed in the input list.
    pub seed_index: usize,
    /// The seed S_i (m).
    pub seed: Point,
    /// Cell vertices (m), world frame.
    pub vertices: Vec<Point>,
    /// Faces as loops of indices into `vertices`, in voro++'s order.
    pub faces: Vec<Vec<u32>>,
    /// For each face, the seed index across it, or a negative wall id (see the module docs).
    pub neighbours: Vec<i32>,
    /// Cell volume as voro++ computes it (m³).
    pub volume: Real,
}

/// Particles per voro++ block: the voro++ documentation recommends about five for a good balance of the
/// block search and the memory per block.
const PARTICLES_PER_BLOCK: Real = 5.0;

/// The Voronoi cells of `seeds` in the box `region`, ordered by seed index.
pub fn tessellate(region: &Region, seeds: &[Point]) -> Result<Vec<VoronoiCell>, VoronoiError> {
    if seeds.is_empty() {
        return Err(VoronoiError::NoSeeds);
    }
    if let Some((index, p)) = seeds.iter().enumerate().find(|(_, p)| !region.contains(p)) {
        return Err(VoronoiError::SeedOutside {
            index,
            position: p.coords.into(),
        });
    }
    let extent = region.extent();
    let block = (region.volume() * PARTICLES_PER_BLOCK / seeds.len() as Real).cbrt();
    let grid = [0, 1, 2].map(|k| ((extent[k] / block).ceil() as i32).max(1));
    let mut container = ContainerStd::new(
        region.min.coords.into(),
        region.max.coords.into(),
        grid,
        [false; 3],
    );
    for (i, p) in seeds.iter().enumerate() {
        container.put(i as i32, p.coords.into(), 0.0);
    }
    let mut cells: Vec<Option<VoronoiCell>> = vec![None; seeds.len()];
    let mut looper = LoopAll::of_container_std(&mut container);
    if looper.start() {
        loop {
            let id = looper.particle_id() as usize;
            let position = looper.position();
            let computed: Option<VoroCellNbr> = container.compute_cell(&mut looper);
            if let Some(mut cell) = computed {
                cells[id] = Some(convert(id, position, &mut cell));
            }
            if !looper.inc() {
                break;
            }
        }
    }
    let computed = cells.iter().filter(|c| c.is_some()).count();
    if computed != seeds.len() {
        return Err(VoronoiError::MissingCells {
            computed,
            seeds: seeds.len(),
        });
    }
    Ok(cells.into_iter().flatten().collect())
}

fn convert(id: usize, position: [Real; 3], cell: &mut VoroCellNbr) -> VoronoiCell {
    let flat = cell.vertices_global(position);
    let vertices: Vec<Point> = flat
        .chunks_exact(3)
        .map(|c| Point::new(c[0], c[1], c[2]))
        .collect();
    let loops = cell.face_vertices();
    let mut faces = Vec::new();
    let mut k = 0;
    while k < loops.len() {
        let n = loops[k] as usize;
        faces.push(loops[k + 1..k + 1 + n].iter().map(|&v| v as u32).collect());
        k += n + 1;
    }
    VoronoiCell {
        seed_index: id,
        seed: Point::from(position),
        vertices,
        faces,
        neighbours: cell.neighbors(),
        volume: cell.volume(),
    }
}
