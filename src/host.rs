//! Readings of the host that speed reports print beside their figures: the calling thread's CPU time and
//! the load average (one place for the example programs, the validation suite and the region profile).

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

#[cfg(test)]
mod tests {
    use super::*;

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
