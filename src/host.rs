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
