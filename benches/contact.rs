//! Contact queries, ours and parry3d-f64 side by side in the same criterion group, on the same seeded pairs
//! (size-1 pairs of the validation suite's pair sets, one pool per shape class):
//! - `overlap/<class>`: our full contact query (cold pair cache: GJK + EPA) vs parry's `query::contact`;
//! - `separated/<class>`: our boolean intersection test vs parry's `query::intersection_test`.
//!
//! Throughput is one element per pair, so criterion reports time per query. Quick defaults (1 s warm-up,
//! 2 s measurement, 20 samples) keep `cargo bench --bench contact` to about a minute and a half; pass
//! `-- --measurement-time 10` for a careful run.

use std::hint::black_box;
use std::time::Duration;

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use polydem::contact::ContactTolerances;
use polydem_validation::cases::contact::eval::{build, Built};
use polydem_validation::cases::contact::ours::Ours;
use polydem_validation::cases::contact::random_set;
use polydem_validation::pairsets::{Intent, RandomSetSpec};
use polydem_validation::peers::parry::ParryPair;

const CLASSES: [&str; 7] = [
    "tet", "box", "hull8", "hull16", "hull32", "hull64", "voronoi",
];
const PAIRS_PER_KIND: usize = 64;

fn pools() -> Vec<(&'static str, Vec<Built>, Vec<Built>)> {
    let spec = RandomSetSpec {
        classes: CLASSES.iter().map(|s| s.to_string()).collect(),
        sizes: vec![1.0],
        pairs_per_class_and_size: 2 * PAIRS_PER_KIND,
        seed: 4242,
        touching_fraction: 0.0,
        separated_fraction: 0.5,
        overlap_min_rel: 1e-6,
        overlap_max_rel: 0.3,
    };
    let pairs = random_set(&spec, || {}).expect("seeded pair generation");
    CLASSES
        .iter()
        .map(|class| {
            let of = |want: fn(&Intent) -> bool| -> Vec<Built> {
                pairs
                    .iter()
                    .filter(|p| p.class == *class && want(&p.intent))
                    .map(|p| build(p).expect("hull of a generated pair"))
                    .collect()
            };
            (
                *class,
                of(|i| matches!(i, Intent::Overlap(_))),
                of(|i| matches!(i, Intent::Separated(_))),
            )
        })
        .collect()
}

fn contact(c: &mut Criterion) {
    for (class, overlap, separated) in pools() {
        let mut g = c.benchmark_group(format!("overlap/{class}"));
        g.throughput(Throughput::Elements(overlap.len() as u64));
        let mut ours = Ours::new(ContactTolerances::default());
        g.bench_function("polydem", |b| {
            b.iter(|| {
                for p in &overlap {
                    black_box(ours.query(&p.pos1, &p.a, &p.pos2, &p.b));
                }
            })
        });
        g.bench_function("parry", |b| {
            b.iter(|| {
                for p in &overlap {
                    let peer = ParryPair {
                        a: &p.parry_a,
                        b: &p.parry_b,
                    };
                    let _ = black_box(peer.contact(&p.pos1, &p.pos2, 0.0));
                }
            })
        });
        g.finish();

        let mut g = c.benchmark_group(format!("separated/{class}"));
        g.throughput(Throughput::Elements(separated.len() as u64));
        g.bench_function("polydem", |b| {
            b.iter(|| {
                for p in &separated {
                    black_box(ours.intersects(&p.pos1, &p.a, &p.pos2, &p.b));
                }
            })
        });
        g.bench_function("parry", |b| {
            b.iter(|| {
                for p in &separated {
                    let peer = ParryPair {
                        a: &p.parry_a,
                        b: &p.parry_b,
                    };
                    black_box(peer.intersects(&p.pos1, &p.pos2));
                }
            })
        });
        g.finish();
    }
}

criterion_group! {
    name = benches;
    config = Criterion::default()
        .warm_up_time(Duration::from_secs(1))
        .measurement_time(Duration::from_secs(2))
        .sample_size(20);
    targets = contact
}
criterion_main!(benches);
