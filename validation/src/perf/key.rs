//! What an instruction count depends on besides the code: the toolchain, valgrind, glibc, the CPU's
//! instruction set and the thread count. Two counts are comparable only under the same [`MachineKey`].

use std::process::Command;

use crate::provenance::Provenance;

/// The CPU flags that change which code runs: glibc's string functions choose by them (through the
/// features valgrind passes on), and so do crates that dispatch on AVX at run time.
const CODE_PATH_FLAGS: [&str; 11] = [
    "sse4_2", "avx", "avx2", "fma", "bmi1", "bmi2", "erms", "fsrm", "avx512f", "avx512bw",
    "avx512vl",
];

/// The facts a count is keyed by (each a column of `history.csv`).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct MachineKey {
    /// Cores and CPU model (`2 cores, AMD EPYC ...`).
    pub machine: String,
    /// The [`CODE_PATH_FLAGS`] this CPU has, space-separated, in that order.
    pub cpu_flags: String,
    /// `rustc -V`.
    pub rustc: String,
    /// `valgrind --version` (empty for wall-time figures).
    pub valgrind: String,
    /// glibc's version.
    pub glibc: String,
    /// Threads the figure ran on.
    pub threads: usize,
}

impl MachineKey {
    /// The key of this machine for figures run on `threads` threads, with `valgrind` as found.
    pub fn here(prov: &Provenance, valgrind: Option<String>, threads: usize) -> Self {
        Self {
            machine: prov.machine(),
            cpu_flags: cpu_flags(),
            rustc: command_line("rustc", &["-V"]).unwrap_or_else(|| "unknown".into()),
            valgrind: valgrind.unwrap_or_default(),
            glibc: glibc_version(),
            threads,
        }
    }

    /// The fields that differ from `other`, as `name: this / other` (empty when the keys are equal).
    pub fn differences(&self, other: &MachineKey) -> Vec<String> {
        let mut out = Vec::new();
        let mut cmp = |name: &str, a: &str, b: &str| {
            if a != b {
                out.push(format!("{name}: `{a}` / `{b}`"));
            }
        };
        cmp("machine", &self.machine, &other.machine);
        cmp("cpu_flags", &self.cpu_flags, &other.cpu_flags);
        cmp("rustc", &self.rustc, &other.rustc);
        cmp("valgrind", &self.valgrind, &other.valgrind);
        cmp("glibc", &self.glibc, &other.glibc);
        cmp(
            "threads",
            &self.threads.to_string(),
            &other.threads.to_string(),
        );
        out
    }
}

fn command_line(program: &str, args: &[&str]) -> Option<String> {
    let out = Command::new(program).args(args).output().ok()?;
    out.status.success().then(|| {
        String::from_utf8_lossy(&out.stdout)
            .lines()
            .next()
            .unwrap_or("")
            .trim()
            .to_string()
    })
}

fn cpu_flags() -> String {
    let text = std::fs::read_to_string("/proc/cpuinfo").unwrap_or_default();
    let flags: Vec<&str> = text
        .lines()
        .find(|l| l.starts_with("flags"))
        .and_then(|l| l.split_once(':'))
        .map(|(_, v)| v.split_whitespace().collect())
        .unwrap_or_default();
    CODE_PATH_FLAGS
        .iter()
        .filter(|f| flags.contains(f))
        .copied()
        .collect::<Vec<_>>()
        .join(" ")
}

fn glibc_version() -> String {
    // SAFETY: gnu_get_libc_version returns a pointer to a static NUL-terminated string.
    let version = unsafe { std::ffi::CStr::from_ptr(libc::gnu_get_libc_version()) };
    version.to_string_lossy().into_owned()
}
