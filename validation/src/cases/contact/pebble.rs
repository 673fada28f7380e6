//! The pebble–boulder pair set: a small hull on a large box, size ratios 1e2 to 1e5, overlaps and gaps of
//! 1e-9 to 1e-3 of the pebble's size.
//!
//! A pair's tolerances follow its smaller body ([`polydem::contact::tolerances::pair_length_scale`]); a
//! band taken from the boulder would swallow these overlaps and gaps (1e-11 of a boulder 1e5 times larger is
//! 1e-6 of the pebble). The pebble (a `box`, `hull16` or `voronoi` cloud of the random sets, randomly
//! rotated) rests on the top face of a randomly rotated and placed cuboid boulder of size 1 m, its lowest
//! vertex along the face normal placed `s` inside the face (overlap) or `s` outside it (gap), at a point of
//! the face far from its edges. The face is then the Minkowski facet of the exact answer, so the
//! constructed value is the exact overlap or gap up to the round-off of coordinates of the boulder's size
//! (~1e-16 m), well below the smallest s (1e-9 × 1e-5 m). Each configuration is given in both pair orders.

use polydem::math::{Point, Vector};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use crate::pairsets::shapes::{random_rotation, random_shape, random_unit};
use crate::pairsets::{pair_seed, Intent, Pair};

/// Size ratios boulder : pebble.
pub const RATIOS: [f64; 4] = [1e2, 1e3, 1e4, 1e5];
/// Overlaps and gaps, × the pebble's size: 1e-9 … 1e-3, one per decade.
pub const DECADES: std::ops::RangeInclusive<i32> = 3..=9;
/// Pebble shape classes.
pub const PEBBLES: [&str; 3] = ["box", "hull16", "voronoi"];

/// The boulder's half-extents (m): a cuboid of bounding diameter ≈ 1.3 m.
const BOULDER_HALF: [f64; 3] = [0.5, 0.35, 0.2];

/// The set, seeded by `seed` (each configuration its own stream, as in the random sets).
pub fn pebble_set(seed: u64) -> Vec<Pair> {
    let mut pairs = Vec::new();
    for (ri, &ratio) in RATIOS.iter().enumerate() {
        for (ci, class) in PEBBLES.iter().enumerate() {
            let mut rng = ChaCha8Rng::seed_from_u64(pair_seed(seed ^ 0x0000_5EBB_1E00, ci, ri, 0));
            let pebble_size = 1.0 / ratio;
            let Some(cloud) = (0..100).find_map(|_| random_shape(class, &mut rng)) else {
                continue;
            };
            let pebble: Vec<Vector> = cloud.iter().map(|p| p.coords * pebble_size).collect();
            for decade in DECADES {
                for sign in [1.0, -1.0] {
                    let s = sign * pebble_size * 10f64.powi(-decade);
                    let (boulder, placed) = place(&mut rng, &pebble, s);
                    let intent = if s > 0.0 {
                        Intent::Overlap(s)
                    } else {
                        Intent::Separated(-s)
                    };
                    let name = format!(
                        "pebble/r{ri}/{class}/{}{decade}",
                        if s > 0.0 { "o" } else { "g" }
                    );
                    for (order, (a, b)) in [(&placed, &boulder), (&boulder, &placed)]
                        .into_iter()
                        .enumerate()
                    {
                        pairs.push(Pair {
                            id: format!("{name}/{}", ["pb", "bp"][order]),
                            class: "pebble".to_string(),
                            size: pebble_size,
                            intent,
                            a: a.clone(),
                            b: b.clone(),
                        });
                    }
                }
            }
        }
    }
    pairs
}

/// A randomly rotated and placed boulder, and the pebble (points relative to its centre) placed on its
/// top face with signed overlap `s`: (boulder cloud, pebble cloud), world coordinates.
fn place(rng: &mut ChaCha8Rng, pebble: &[Vector], s: f64) -> (Vec<Point>, Vec<Point>) {
    let rot_b = random_rotation(rng);
    let centre_b = random_unit(rng) * rng.random_range(0.0..2.0);
    let [hx, hy, hz] = BOULDER_HALF;
    let boulder: Vec<Point> = (0..8)
        .map(|i| {
            let c = |bit: usize, h: f64| if i & bit == 0 { -h } else { h };
            Point::from(rot_b * Vector::new(c(1, hx), c(2, hy), c(4, hz)) + centre_b)
        })
        .collect();
    let n = rot_b * Vector::z();
    // A point of the top face at least half its half-widths from the edges: far from them for any pebble.
    let local = Vector::new(
        rng.random_range(-0.5..0.5) * hx,
        rng.random_range(-0.5..0.5) * hy,
        hz,
    );
    let on_face = rot_b * local + centre_b;
    let rot_p = random_rotation(rng);
    let turned: Vec<Vector> = pebble.iter().map(|p| rot_p * p).collect();
    let lowest = turned
        .iter()
        .map(|p| n.dot(p))
        .fold(f64::INFINITY, f64::min);
    let centre_p = on_face + n * (-s - lowest);
    (
        boulder,
        turned.iter().map(|p| Point::from(p + centre_p)).collect(),
    )
}
