//! Rock generation (paper section 4.1): the Voronoi tessellation tiles the box, the cells are convex
//! and the shrunk rocks disjoint (exact SAT oracle), and the realised sizes follow the requested distribution.

use polydem::contact::{sat_polyhedra, ContactKind};
use polydem::math::Point;
use polydem::shape::ConvexPolyhedron;
use polydem_rockfill::grading::{equivalent_diameter, grade_cells, SizeDistribution};
use polydem_rockfill::seeds::{random_seeds, Region};
use polydem_rockfill::spatial_order::morton_key;
use polydem_rockfill::statistics::sample_statistics;
use polydem_rockfill::voronoi::tessellate;
use polydem_rockfill::{generate, GenerationParams};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

fn region() -> Region {
    Region::new(Point::new(0.0, -0.5, 1.0), Point::new(1.2, 0.4, 2.0)).unwrap()
}

#[test]
fn unshrunk_cells_tile_the_box_and_are_convex() {
    let region = region();
    let seeds = random_seeds(&region, 300, &mut ChaCha8Rng::seed_from_u64(11));
    let cells = tessellate(&region, &seeds).unwrap();
    assert_eq!(cells.len(), seeds.len());
    let mut sum_voro = 0.0;
    let mut sum_hull = 0.0;
    for cell in &cells {
        // Convex: the hull of the cell's vertices keeps every vertex (none is interior or on a face or an
        // edge) and has the cell's volume.
        let (hull, _) = ConvexPolyhedron::from_points(&cell.vertices).unwrap();
        assert_eq!(
            hull.vertices().len(),
            cell.vertices.len(),
            "cell {}: hull has {} vertices, the cell {}",
            cell.seed_index,
            hull.vertices().len(),
            cell.vertices.len()
        );
        let v = hull.mass_properties().volume;
        assert!(
            (v - cell.volume).abs() <= 1e-10 * cell.volume,
            "cell {}: hull volume {v}, voro++ volume {}, rel tol 1e-10",
            cell.seed_index,
            cell.volume
        );
        sum_voro += cell.volume;
        sum_hull += v;
    }
    let box_volume = region.volume();
    for (what, sum) in [("voro++", sum_voro), ("hull", sum_hull)] {
        let rel = (sum - box_volume).abs() / box_volume;
        assert!(
            rel <= 1e-10,
            "{what} cell volumes sum to {sum}, box volume {box_volume}: relative error {rel:e} > 1e-10"
        );
    }
}

#[test]
fn neighbouring_cells_touch_and_shrunk_rocks_are_disjoint() {
    let region = region();
    let seeds = random_seeds(&region, 120, &mut ChaCha8Rng::seed_from_u64(5));
    let cells = tessellate(&region, &seeds).unwrap();
    let hulls: Vec<_> = cells
        .iter()
        .map(|c| ConvexPolyhedron::from_points(&c.vertices).unwrap())
        .collect();
    let sizes = SizeDistribution::truncated_normal(0.12, 0.05, 0.1, 10).unwrap();
    let (rocks, report) = grade_cells(&cells, &sizes, &mut ChaCha8Rng::seed_from_u64(6)).unwrap();
    let rock_of: std::collections::HashMap<usize, usize> =
        rocks.iter().enumerate().map(|(k, r)| (r.cell, k)).collect();
    let mut pairs = 0;
    for (i, cell) in cells.iter().enumerate() {
        for &j in cell
            .neighbours
            .iter()
            .filter(|&&j| j >= 0 && (j as usize) > i)
        {
            let j = j as usize;
            // Unshrunk neighbours share a face: the oracle reports zero overlap (touching, or an overlap at
            // round-off depth).
            let ((a, pa), (b, pb)) = (&hulls[i], &hulls[j]);
            let g = sat_polyhedra(pa, a, pb, b);
            let scale = a.length_scale().max(b.length_scale());
            assert!(
                g.kind != ContactKind::Separated && g.depth <= 1e-9 * scale,
                "cells {i}, {j}: {:?} depth {} distance {}, expected touching (tol 1e-9 × {scale})",
                g.kind,
                g.depth,
                g.distance
            );
            if let (Some(&ri), Some(&rj)) = (rock_of.get(&i), rock_of.get(&j)) {
                let (ra, rb) = (&rocks[ri], &rocks[rj]);
                let g = sat_polyhedra(&ra.pose, &ra.shape, &rb.pose, &rb.shape);
                assert_eq!(
                    g.kind,
                    ContactKind::Separated,
                    "rocks of cells {i}, {j} (q = {}, {}): {:?}, depth {}",
                    ra.shrink_factor,
                    rb.shrink_factor,
                    g.kind,
                    g.depth
                );
                pairs += 1;
            }
        }
    }
    assert!(pairs > 300, "only {pairs} neighbour pairs checked");
    assert!(report.rocks + report.dropped_small_cells == cells.len());
}

#[test]
fn realised_sizes_follow_the_requested_distribution() {
    // 4 m³ at a mean size of 0.1 m: about 2000 rocks.
    let region = Region::new(Point::origin(), Point::new(2.0, 1.0, 2.0)).unwrap();
    let params = GenerationParams::new(region, 0.1, 2021);
    let sample = generate(&params).unwrap();
    let stats = sample_statistics(&sample.rocks);
    let n = sample.rocks.len() as f64;
    // Every rock's volume-equivalent diameter is its drawn size (the shrink is a homothety).
    for r in &sample.rocks {
        let d = equivalent_diameter(r.shape.mass_properties().volume);
        assert!(
            (d - r.diameter).abs() <= 1e-9 * r.diameter,
            "cell {}: realised d_eq {d}, drawn {}, rel tol 1e-9",
            r.cell,
            r.diameter
        );
    }
    // The sample against the distribution eq. 29 samples (piecewise uniform over the bins of the truncated
    // normal): mean within 4 standard errors, standard deviation within 4 of its standard errors (for a
    // near-normal law SE(s) ≈ s/√(2(n − 1))).
    let (mean, var) = sample.sizes.bin_mean_and_variance();
    let sd = var.sqrt();
    let se_mean = sd / n.sqrt();
    assert!(
        (stats.diameter.mean - mean).abs() <= 4.0 * se_mean,
        "n = {n}: sample mean {} vs {mean}, tol 4 SE = {}",
        stats.diameter.mean,
        4.0 * se_mean
    );
    let se_sd = sd / (2.0 * (n - 1.0)).sqrt();
    assert!(
        (stats.diameter.std - sd).abs() <= 4.0 * se_sd,
        "n = {n}: sample std {} vs {sd}, tol 4 SE = {}",
        stats.diameter.std,
        4.0 * se_sd
    );
    // The binned law against the requested normal truncated at ±2σ: the same mean (symmetric), and σ_t =
    // σ √(1 − 2·2φ(2)/(2Φ(2) − 1)) = 0.879586 σ, plus the within-bin variance w²/12 (w the bin width).
    let requested_sd: f64 = 0.05 * 0.1;
    let w = sample.sizes.edges[1] - sample.sizes.edges[0];
    let truncated = requested_sd * 0.879_586;
    let expected_sd = (truncated.powi(2) + w * w / 12.0).sqrt();
    assert!(
        (mean - 0.1).abs() < 1e-12 * 0.1,
        "binned mean {mean}, requested 0.1"
    );
    assert!(
        (sd - expected_sd).abs() <= 0.02 * expected_sd,
        "binned sd {sd}, truncated normal with bin width {w}: {expected_sd}, rel tol 0.02"
    );
    assert!(stats.diameter.min >= 0.09 - 1e-12 && stats.diameter.max <= 0.11 + 1e-12);
    let dropped = sample.grading.dropped_small_cells as f64 / sample.seeds as f64;
    assert!(
        dropped < 0.05,
        "{} of {} cells dropped as too small ({dropped})",
        sample.grading.dropped_small_cells,
        sample.seeds
    );
    eprintln!(
        "seeds {}, rocks {}, dropped {}, tessellation {:?}, grading {:?}\n{stats}",
        sample.seeds,
        sample.rocks.len(),
        sample.grading.dropped_small_cells,
        sample.tessellation_time,
        sample.grading_time
    );
}

#[test]
fn generated_rocks_are_numbered_along_the_z_order_curve() {
    // generate() numbers the rocks along the Z-order curve of their centres on a grid of the largest rock
    // size from the region's corner (crates/rockfill/src/spatial_order.rs): the keys never decrease.
    let region = region();
    let params = GenerationParams::new(region, 0.1, 5);
    let sample = generate(&params).unwrap();
    let cell = sample.sizes.max_size();
    let keys: Vec<u64> = sample
        .rocks
        .iter()
        .map(|rock| {
            let c = rock.pose.translation.vector;
            let [i, j, k] =
                [0, 1, 2].map(|a| ((c[a] - region.min[a]) / cell).floor().max(0.0) as u64);
            morton_key(i, j, k)
        })
        .collect();
    assert!(sample.rocks.len() > 100, "{} rocks", sample.rocks.len());
    for (n, pair) in keys.windows(2).enumerate() {
        assert!(
            pair[0] <= pair[1],
            "rocks {n} and {}: Z-order keys {} then {} (cell {cell} m)",
            n + 1,
            pair[0],
            pair[1]
        );
    }
}
