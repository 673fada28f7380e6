//! The geometric pre-collapse of the loose rockfill sample (`crates/rockfill/src/collapse.rs`): rocks are only
//! translated (shapes and orientations untouched), end inside the container, never move up, and no two rocks
//! overlap afterwards under the exact SAT oracle; a pair generated at least the requested gap apart ends at
//! least that gap apart.

use polydem::contact::{sat_polyhedra, ContactKind};
use polydem::math::Point;
use polydem_rockfill::collapse::{collapse, CollapseParams};
use polydem_rockfill::seeds::Region;
use polydem_rockfill::{generate, GenerationParams};

#[test]
fn collapse_translates_rocks_down_without_any_overlap() {
    // A small container: 1.2 m × 0.8 m, rocks of 0.2 m generated in a region 2.4 m tall.
    let (length, width, mean) = (1.2, 0.8, 0.2);
    let region = Region::new(Point::origin(), Point::new(length, width, 2.4)).unwrap();
    let sample = generate(&GenerationParams::new(region, mean, 5)).unwrap();
    let before = sample.rocks.clone();
    let mut rocks = sample.rocks;
    let params = CollapseParams::new(length, width, mean, 0.02);
    let report = collapse(&mut rocks, &params);
    assert_eq!(report.rocks, before.len());
    assert!(
        report.top_after < report.top_before - 0.5,
        "{} rocks: top {} m -> {} m, expected a collapse of more than 0.5 m",
        report.rocks,
        report.top_before,
        report.top_after
    );
    let scale = mean;
    for (k, (r, r0)) in rocks.iter().zip(&before).enumerate() {
        assert!(
            std::sync::Arc::ptr_eq(&r.shape, &r0.shape) && r.pose.rotation == r0.pose.rotation,
            "rock {k}: shape or orientation changed"
        );
        let dz = r.pose.translation.vector.z - r0.pose.translation.vector.z;
        assert!(dz <= 0.0, "rock {k} moved up by {dz} m");
        let b = r.shape.aabb(&r.pose);
        let tol = 1e-12 * scale;
        assert!(
            b.mins.x >= -tol
                && b.mins.y >= -tol
                && b.mins.z >= -tol
                && b.maxs.x <= length + tol
                && b.maxs.y <= width + tol,
            "rock {k}: box {:?}–{:?} leaves the container {length} × {width} (tolerance {tol})",
            b.mins,
            b.maxs
        );
    }
    let mut touching_pairs = 0;
    for i in 0..rocks.len() {
        for j in i + 1..rocks.len() {
            let g = sat_polyhedra(
                &rocks[i].pose,
                &rocks[i].shape,
                &rocks[j].pose,
                &rocks[j].shape,
            );
            assert_eq!(
                g.kind,
                ContactKind::Separated,
                "rocks {i}, {j} after the collapse: {:?} (depth {}, distance {})",
                g.kind,
                g.depth,
                g.distance
            );
            let g0 = sat_polyhedra(
                &before[i].pose,
                &before[i].shape,
                &before[j].pose,
                &before[j].shape,
            );
            // A pair generated at least a gap apart stays at least a gap apart (to the advance's rounding).
            let floor = if g0.distance >= params.gap {
                params.gap * (1.0 - 1e-9)
            } else {
                0.0
            };
            assert!(
                g.distance >= floor,
                "rocks {i}, {j}: gap {} m after the collapse, initial gap {} m, requested {} m: below {floor} m",
                g.distance,
                g0.distance,
                params.gap
            );
            if g.distance < 2.0 * params.gap {
                touching_pairs += 1;
            }
        }
    }
    // The collapse brings rocks into near contact: most rocks have a neighbour within two gaps.
    assert!(
        touching_pairs >= rocks.len(),
        "{touching_pairs} pairs within 2 gaps for {} rocks: expected at least one per rock",
        rocks.len()
    );
}
