//! Readings of the host that speed reports print beside their figures: the calling thread's CPU time,
//! the load average, the hypervisor's steal and the core-to-core round trip (one place for the example
//! programs, the validation suite and the region profile).

use std::sync::atomic::{AtomicU64, Ordering};
use std::time::{Duration, Instant};

/// CPU time of the calling thread (ns); `None` where the clock is unavailable.
pub fn thread_cpu_ns() -> Option<u64> {
    let mut ts = libc::timespec {
        tv_sec: 0,
        tv_nsec: 0,
    };
    // SAFETY: clock_gettime only writes into the timespec we pass.
    let rc = unsafe { libc::clock_gettime(libc::CLOCK_THREAD_CPUTIME_ID, &mut ts) };
    (rc == 0).then(|| ts.tv_sec as u64 * 1_000_000_000 + ts.tv_nsec as u64)
}

/// CPU time of the calling thread (s); `None` where the clock is unavailable.
pub fn thread_cpu_time() -> Option<f64> {
    thread_cpu_ns().map(|ns| ns as f64 * 1e-9)
}

/// The 1, 5 and 15 minute load averages as the kernel prints them, or "n/a" off Linux.
pub fn load_average() -> String {
    std::fs::read_to_string("/proc/loadavg")
        .map(|s| s.split_whitespace().take(3).collect::<Vec<_>>().join(" "))
        .unwrap_or_else(|_| "n/a".into())
}

/// The machine's CPU time by kind since boot, summed over its CPUs, in the kernel's clock ticks
/// (`/proc/stat`): what a run's share of stolen time is measured from ([`CpuTicks::steal_since`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct CpuTicks {
    /// Every kind together.
    pub total: u64,
    /// Time a virtual machine's CPUs were ready to run but the hypervisor ran something else.
    pub steal: u64,
}

impl CpuTicks {
    /// The current ticks; `None` off Linux or where `/proc/stat` cannot be read.
    pub fn now() -> Option<CpuTicks> {
        std::fs::read_to_string("/proc/stat")
            .ok()
            .and_then(|s| CpuTicks::parse(&s))
    }

    /// The ticks of the `cpu` line of a `/proc/stat` text (user, nice, system, idle, iowait, irq,
    /// softirq, steal, …; steal is the eighth field, and counts as 0 on kernels that lack it).
    pub fn parse(stat: &str) -> Option<CpuTicks> {
        let line = stat.lines().find(|l| l.starts_with("cpu "))?;
        let fields: Vec<u64> = line
            .split_whitespace()
            .skip(1)
            .map(str::parse)
            .collect::<Result<_, _>>()
            .ok()?;
        // guest and guest_nice (fields 9–10) are already counted in user and nice.
        let total = fields.iter().take(8).sum();
        Some(CpuTicks {
            total,
            steal: fields.get(7).copied().unwrap_or(0),
        })
    }

    /// The share of the machine's CPU time stolen by the hypervisor since `earlier` (0 to 1); `None`
    /// when no tick passed.
    pub fn steal_since(&self, earlier: &CpuTicks) -> Option<f64> {
        let total = self.total.checked_sub(earlier.total)?;
        let steal = self.steal.checked_sub(earlier.steal)?;
        (total > 0).then(|| steal as f64 / total as f64)
    }
}

/// A counter alone on its cache lines (two: the adjacent-line prefetcher pairs them), so that the round
/// trip measures one line passed between two cores and nothing that shares it.
#[repr(align(128))]
struct PaddedCounter(AtomicU64);

/// How long a wait of [`core_round_trip_ns`] spins before it also yields its core at each check.
const YIELD_AFTER: Duration = Duration::from_micros(20);

/// The mean time (ns) for one cache line to go from thread 0 of rayon's current pool to thread 1 and
/// back: thread 0 writes an odd count, thread 1 waits for it and writes the next even one, `trips`
/// times. `None` on a pool of one thread, or when one wait outlasts `timeout` (a busy host left a
/// thread unrun).
///
/// Why: on a virtual machine the reading can take different levels for minutes at a time (two vCPUs
/// placed on one die or on two), and two-thread runs of the sphere beds slow down with it while
/// one-thread runs do not (figures: `docs/tuning.md`). A run on two threads passes cache lines between the cores every
/// step (its barriers, the spheres at the split, the gathered loads), so its speed-up depends on the
/// state the host is in; speed reports print this reading beside it.
pub fn core_round_trip_ns(trips: u32, timeout: Duration) -> Option<f64> {
    if rayon::current_num_threads() < 2 || trips == 0 {
        return None;
    }
    let counter = PaddedCounter(AtomicU64::new(0));
    // Either thread gives up when the other has not answered within `timeout`, and says so here, so
    // that the other stops waiting too.
    let abandoned = PaddedCounter(AtomicU64::new(0));
    let wait_for = |value: u64| -> bool {
        let start = Instant::now();
        let mut spins = 0u32;
        while counter.0.load(Ordering::Acquire) != value {
            std::hint::spin_loop();
            spins = spins.wrapping_add(1);
            if spins.is_multiple_of(1024) {
                let waited = start.elapsed();
                if abandoned.0.load(Ordering::Relaxed) != 0 || waited > timeout {
                    abandoned.0.store(1, Ordering::Relaxed);
                    return false;
                }
                // A wait this long is for the scheduler, not for a cache line (more runnable threads
                // than cores): give the core to the other thread instead of spinning out the time slice.
                if waited > YIELD_AFTER {
                    std::thread::yield_now();
                }
            }
        }
        true
    };
    let times = rayon::broadcast(|ctx| match ctx.index() {
        0 => {
            // Both threads running before the clock starts.
            if !wait_for(1) {
                return None;
            }
            let start = Instant::now();
            for trip in 0..u64::from(trips) {
                counter.0.store(2 * trip + 2, Ordering::Release);
                if !wait_for(2 * trip + 3) {
                    return None;
                }
            }
            Some(start.elapsed())
        }
        1 => {
            counter.0.store(1, Ordering::Release);
            for trip in 0..u64::from(trips) {
                if !wait_for(2 * trip + 2) {
                    return None;
                }
                counter.0.store(2 * trip + 3, Ordering::Release);
            }
            None
        }
        _ => None,
    });
    // Thread 0 timed every trip only if thread 1 answered every one: no other check is needed.
    let elapsed = times.first().copied().flatten()?;
    Some(elapsed.as_secs_f64() * 1e9 / f64::from(trips))
}

/// [`core_round_trip_ns`] as speed reports print it: 20 000 trips (~2–10 ms), "n/a" where it has no
/// reading.
pub fn core_round_trip_text() -> String {
    match core_round_trip_ns(20_000, Duration::from_millis(200)) {
        Some(ns) => format!("{ns:.0} ns"),
        None => "n/a".into(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// One thread has no partner; two threads pass the line back and forth: a positive, finite mean
    /// time per trip. No bound on it: the tests of this binary run beside it on the same cores, and a
    /// trip then waits for the scheduler, hundreds of µs on a loaded 2-core machine.
    #[test]
    fn core_round_trip_needs_two_threads_and_gives_a_time() {
        let pool = |threads: usize| {
            rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .expect("pool")
        };
        let one = pool(1).install(|| core_round_trip_ns(200, Duration::from_secs(5)));
        assert_eq!(one, None, "one thread: {one:?}, expected no reading");
        let two = pool(2).install(|| core_round_trip_ns(200, Duration::from_secs(5)));
        let ns = two.expect("two threads: a reading, no wait of 5 s");
        assert!(
            ns.is_finite() && ns > 0.0,
            "round trip {ns} ns over 200 trips, expected a positive finite time"
        );
        let none = pool(2).install(|| core_round_trip_ns(0, Duration::from_secs(5)));
        assert_eq!(none, None, "no trips: {none:?}, expected no reading");
    }

    #[test]
    fn steal_is_the_eighth_field_of_the_cpu_line() {
        let before =
            CpuTicks::parse("cpu  100 0 10 500 2 0 1 7 0 0\ncpu0 50 0 5 250 1 0 0 3 0 0\n");
        let after = CpuTicks::parse("cpu  160 0 20 520 2 0 1 17 0 0\n");
        let (before, after) = (before.expect("parsed"), after.expect("parsed"));
        assert_eq!(
            before,
            CpuTicks {
                total: 620,
                steal: 7
            }
        );
        let steal = after.steal_since(&before).expect("ticks passed");
        assert!(
            (steal - 10.0 / 100.0).abs() < 1e-12,
            "steal share {steal}, expected 0.1"
        );
        assert_eq!(after.steal_since(&after), None);
        assert_eq!(CpuTicks::parse("intr 1 2 3\n"), None);
    }
}
