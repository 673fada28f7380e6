//! The core-to-core round trip of a two-thread pool (`polydem::host::core_round_trip_ns`), as the
//! sphere_bed report prints it beside each two-thread run: which state the host's cores are in now.
//!
//! ```text
//! cargo run --release --example core_round_trip -- [READINGS]
//! ```
//! Prints READINGS readings (default 1) on one line, separated by spaces ("n/a" where a reading timed
//! out). Used by `reference/liggghts/scaling.sh`.

use polydem::host::core_round_trip_text;

fn main() -> anyhow::Result<()> {
    let readings: usize = match std::env::args().nth(1) {
        Some(a) => a
            .parse()
            .map_err(|e| anyhow::anyhow!("READINGS must be a whole number, not '{a}': {e}"))?,
        None => 1,
    };
    let pool = rayon::ThreadPoolBuilder::new().num_threads(2).build()?;
    let texts: Vec<String> = (0..readings)
        .map(|_| pool.install(core_round_trip_text))
        .collect();
    println!("{}", texts.join(" "));
    Ok(())
}
