//! Wall-time figures against a peer measured in the same run: our contact query and parry3d-f64's on the
//! same seeded pairs, per shape class, with the machine's load average before and after and the CPU time
//! the measurement took beside each ratio. Wall times on a shared machine move from run to run; the ratio
//! of two codes timed in alternation moves much less, and the load says whether the run was quiet.

use std::time::Duration;

use polydem::contact::ContactTolerances;

use super::benches::{CONTACT_CLASSES, CONTACT_SEED};
use super::history::Row;
use super::key::MachineKey;
use crate::cases::contact::eval::{build, Built};
use crate::cases::contact::{random_set, timing};
use crate::pairsets::{Intent, RandomSetSpec};

/// The peer's name and version, as recorded in the history.
pub const PARRY: &str = "parry3d-f64 0.31";

/// Sizes of a wall-time run: quick (`cargo perf record`) or full (`--full`).
#[derive(Clone, Copy, Debug)]
pub struct PeerSizes {
    pub pairs_per_class: usize,
    pub repeats: usize,
}

pub const QUICK: PeerSizes = PeerSizes {
    pairs_per_class: 60,
    repeats: 30,
};
pub const FULL: PeerSizes = PeerSizes {
    pairs_per_class: 200,
    repeats: 60,
};

/// The 1-minute load average (`/proc/loadavg`), if readable.
pub fn load_average() -> Option<f64> {
    std::fs::read_to_string("/proc/loadavg")
        .ok()?
        .split_whitespace()
        .next()?
        .parse()
        .ok()
}

/// CPU time (user + system) of this process so far.
pub fn cpu_time() -> Duration {
    let mut usage = std::mem::MaybeUninit::<libc::rusage>::zeroed();
    // SAFETY: getrusage writes a whole rusage into the pointer it is given.
    let usage = unsafe {
        libc::getrusage(libc::RUSAGE_SELF, usage.as_mut_ptr());
        usage.assume_init()
    };
    let tv = |t: libc::timeval| Duration::new(t.tv_sec as u64, (t.tv_usec as u32) * 1000);
    tv(usage.ru_utime) + tv(usage.ru_stime)
}

fn pairs(class: &str, sizes: PeerSizes) -> Result<(Vec<Built>, Vec<Built>), String> {
    let spec = RandomSetSpec {
        classes: vec![class.to_string()],
        sizes: vec![1.0],
        pairs_per_class_and_size: 2 * sizes.pairs_per_class,
        seed: CONTACT_SEED,
        touching_fraction: 0.0,
        separated_fraction: 0.5,
        overlap_min_rel: 1e-6,
        overlap_max_rel: 0.3,
    };
    let all = random_set(&spec, || {}).map_err(|e| e.to_string())?;
    let of = |want: fn(&Intent) -> bool| -> Result<Vec<Built>, String> {
        all.iter().filter(|p| want(&p.intent)).map(build).collect()
    };
    Ok((
        of(|i| matches!(i, Intent::Overlap(_)))?,
        of(|i| matches!(i, Intent::Separated(_)))?,
    ))
}

/// Times ours and parry's contact query (overlapping pairs) and intersection test (separated pairs) per
/// shape class, and returns one history row per figure.
pub fn contact_vs_parry(
    sizes: PeerSizes,
    commit: &str,
    date: &str,
    key: &MachineKey,
) -> Result<Vec<Row>, String> {
    let mut rows = Vec::new();
    for class in CONTACT_CLASSES {
        let (overlapping, separated) = pairs(class, sizes)?;
        type Timer = fn(&[Built], usize) -> f64;
        let figures: [(&str, &[Built], Timer, Timer); 2] = [
            (
                "wall_contact_overlap",
                &overlapping,
                |p, r| timing::ours_query_ns(p, ContactTolerances::default(), r),
                timing::parry_query_ns,
            ),
            (
                "wall_contact_separated",
                &separated,
                timing::ours_intersects_ns,
                timing::parry_intersects_ns,
            ),
        ];
        for (name, set, ours, peer) in figures {
            let (load0, cpu0) = (load_average(), cpu_time());
            let ours_ns = ours(set, sizes.repeats);
            let peer_ns = peer(set, sizes.repeats);
            let (load1, cpu1) = (load_average(), cpu_time());
            let load = match (load0, load1) {
                (Some(a), Some(b)) => format!("{a:.2}/{b:.2}"),
                _ => "unknown".to_string(),
            };
            rows.push(Row {
                commit: commit.to_string(),
                date: date.to_string(),
                key: key.clone(),
                figure: format!("{name}/{class}"),
                value: ours_ns,
                unit: "ns".to_string(),
                work: set.len().to_string(),
                peer: PARRY.to_string(),
                peer_value: format!("{peer_ns:.1}"),
                ratio: format!("{:.4}", ours_ns / peer_ns),
                load_avg: load,
                cpu_s: format!("{:.2}", (cpu1 - cpu0).as_secs_f64()),
            });
        }
    }
    Ok(rows)
}
