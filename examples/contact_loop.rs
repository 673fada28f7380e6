//! The Rust side of the Python batch benchmark (`python/examples/contact_batch_speed.py`): the pairs of a
//! JSONL file (the `polydem contact` input) queried in a plain loop on one thread, as `polydem.contact`
//! and `contact_batch` query each pair (the exact Minkowski geometry, a fresh cache per pair).
//!
//! ```text
//! cargo run --release --example contact_loop -- PAIRS.jsonl [REPEATS]
//! ```
//! Prints the best and the mean over REPEATS (default 20) of the loop's nanoseconds per pair; hull
//! building and file reading are outside the timed loop.

use std::time::Instant;

use polydem::contact::{
    query_with, ContactTolerances, EpaScratch, PairCache, PairSmoothing, QueryCounters,
};
use polydem::io::pairs_jsonl::parse_pair;
use polydem::math::Pose;
use polydem::shape::{ConvexPolyhedron, Shape};

fn main() -> anyhow::Result<()> {
    let mut args = std::env::args().skip(1);
    let path = args
        .next()
        .ok_or_else(|| anyhow::anyhow!("usage: contact_loop PAIRS.jsonl [REPEATS]"))?;
    let repeats: usize = args.next().map_or(Ok(20), |a| a.parse())?;
    let text = std::fs::read_to_string(&path)?;
    let mut pairs: Vec<(Pose, Shape, Pose, Shape)> = Vec::new();
    for (k, line) in text
        .lines()
        .enumerate()
        .filter(|(_, l)| !l.trim().is_empty())
    {
        let pair = parse_pair(line).map_err(|(_, e)| anyhow::anyhow!("{path}:{}: {e}", k + 1))?;
        let (a, pose_a) = ConvexPolyhedron::from_points(&pair.a)?;
        let (b, pose_b) = ConvexPolyhedron::from_points(&pair.b)?;
        pairs.push((
            pose_a,
            Shape::Polyhedron(a.into()),
            pose_b,
            Shape::Polyhedron(b.into()),
        ));
    }
    let tolerances = ContactTolerances {
        pair_smoothing: PairSmoothing::Exact,
        ..ContactTolerances::default()
    };
    let mut scratch = EpaScratch::default();
    let (mut best, mut total) = (f64::INFINITY, 0.0);
    for _ in 0..repeats {
        let start = Instant::now();
        for (pos1, s1, pos2, s2) in &pairs {
            let g = query_with(
                pos1,
                s1,
                pos2,
                s2,
                &tolerances,
                &mut PairCache::default(),
                &mut scratch,
                &mut QueryCounters::default(),
            )?;
            std::hint::black_box(g);
        }
        let ns = start.elapsed().as_secs_f64() * 1e9 / pairs.len() as f64;
        best = best.min(ns);
        total += ns;
    }
    let mean = total / repeats as f64;
    println!(
        "{} pairs, best of {repeats}: {best:.1} ns per pair (mean {mean:.1})",
        pairs.len()
    );
    Ok(())
}
