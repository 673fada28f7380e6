//! The CSV of the scaling runs: one row per rank of each run (`reports/mpi/runs.csv`), and the figures of
//! a run drawn from its rows (the slowest rank's wall time, the traffic summed over the ranks).

use std::fmt::Write;

/// What one rank measured in one run.
#[derive(Clone, Debug, PartialEq)]
pub struct RankRow {
    /// The run's number in the set.
    pub run: u32,
    /// The scene's kind (`spheres`, `polyhedra`).
    pub scene: String,
    /// Ranks of the run.
    pub ranks: usize,
    /// This rank.
    pub rank: usize,
    /// Bodies of the whole world.
    pub bodies: usize,
    /// Steps timed.
    pub steps: u64,
    /// Wall time of the steps (s).
    pub wall_s: f64,
    /// CPU time of this process over the steps (s; MPICH's waits spin, so they count).
    pub cpu_s: f64,
    /// Steps that ended in a cut (new subdomains).
    pub cut_steps: u64,
    /// Wall time of those steps (s).
    pub cut_wall_s: f64,
    /// Bodies owned and ghosts held at the first cut.
    pub owned: usize,
    /// Ghosts held at the first cut.
    pub ghosts: usize,
    /// Bytes and messages this rank sent: ghost exchange, rebuild agreements, cuts.
    pub ghost_bytes: u64,
    /// Ghost-exchange messages.
    pub ghost_messages: u64,
    /// Agreement bytes.
    pub agreement_bytes: u64,
    /// Agreement messages.
    pub agreement_messages: u64,
    /// Cut bytes.
    pub cut_bytes: u64,
    /// Cut messages.
    pub cut_messages: u64,
    /// Mean runnable threads on the machine during the steps, sampled on rank 0 (`/proc/loadavg`).
    pub runnable: f64,
    /// One-minute load average before and after the steps.
    pub load_before: f64,
    /// One-minute load average after the steps.
    pub load_after: f64,
    /// The ghost layer's width over the lattice spacing.
    pub ghost_width_spacings: f64,
}

/// The CSV header, in field order.
pub const HEADER: &str = "run,scene,ranks,rank,bodies,steps,wall_s,cpu_s,cut_steps,cut_wall_s,owned,ghosts,\
ghost_bytes,ghost_messages,agreement_bytes,agreement_messages,cut_bytes,cut_messages,runnable,load_before,\
load_after,ghost_width_spacings";

impl RankRow {
    /// The row as CSV (no newline); floats written so that they read back to the same value.
    pub fn to_csv(&self) -> String {
        let mut s = String::new();
        let _ = write!(
            s,
            "{},{},{},{},{},{},{:e},{:e},{},{:e},{},{},{},{},{},{},{},{},{:e},{:e},{:e},{:e}",
            self.run,
            self.scene,
            self.ranks,
            self.rank,
            self.bodies,
            self.steps,
            self.wall_s,
            self.cpu_s,
            self.cut_steps,
            self.cut_wall_s,
            self.owned,
            self.ghosts,
            self.ghost_bytes,
            self.ghost_messages,
            self.agreement_bytes,
            self.agreement_messages,
            self.cut_bytes,
            self.cut_messages,
            self.runnable,
            self.load_before,
            self.load_after,
            self.ghost_width_spacings
        );
        s
    }

    /// The row of a CSV line, or why not.
    pub fn parse(line: &str) -> Result<Self, String> {
        let f: Vec<&str> = line.trim().split(',').collect();
        let count = HEADER.split(',').count();
        if f.len() != count {
            return Err(format!("{} fields, expected {count}: {line}", f.len()));
        }
        let num = |k: usize| -> Result<f64, String> {
            f[k].parse::<f64>()
                .map_err(|e| format!("field {k} `{}`: {e}", f[k]))
        };
        let int = |k: usize| -> Result<u64, String> {
            f[k].parse::<u64>()
                .map_err(|e| format!("field {k} `{}`: {e}", f[k]))
        };
        Ok(Self {
            run: int(0)? as u32,
            scene: f[1].to_owned(),
            ranks: int(2)? as usize,
            rank: int(3)? as usize,
            bodies: int(4)? as usize,
            steps: int(5)?,
            wall_s: num(6)?,
            cpu_s: num(7)?,
            cut_steps: int(8)?,
            cut_wall_s: num(9)?,
            owned: int(10)? as usize,
            ghosts: int(11)? as usize,
            ghost_bytes: int(12)?,
            ghost_messages: int(13)?,
            agreement_bytes: int(14)?,
            agreement_messages: int(15)?,
            cut_bytes: int(16)?,
            cut_messages: int(17)?,
            runnable: num(18)?,
            load_before: num(19)?,
            load_after: num(20)?,
            ghost_width_spacings: num(21)?,
        })
    }
}

/// The figures of one run (all its ranks' rows).
#[derive(Clone, Debug, PartialEq)]
pub struct RunFigures {
    /// The scene's kind.
    pub scene: String,
    /// Ranks.
    pub ranks: usize,
    /// Bodies of the whole world.
    pub bodies: usize,
    /// Steps timed.
    pub steps: u64,
    /// The slowest rank's wall time (s): the run's time.
    pub wall_s: f64,
    /// CPU time summed over the ranks (s).
    pub cpu_s: f64,
    /// Cuts over the steps (rank 0's count; every rank cuts together).
    pub cut_steps: u64,
    /// The slowest rank's time in steps that cut (s).
    pub cut_wall_s: f64,
    /// Ghosts summed over the ranks at the first cut, over the bodies.
    pub ghost_fraction: f64,
    /// Sent per step, summed over the ranks: (bytes, messages) of ghosts, agreements, cuts.
    pub per_step: [(f64, f64); 3],
    /// Runnable threads during the steps beyond the run's own ranks.
    pub foreign_load: f64,
    /// One-minute load averages before and after.
    pub load_before: f64,
    /// One-minute load average after.
    pub load_after: f64,
    /// The ghost layer's width over the lattice spacing.
    pub ghost_width_spacings: f64,
}

/// The load beyond a run's own ranks above which its times are "not measured quietly".
pub const QUIET_FOREIGN_LOAD: f64 = 0.5;

impl RunFigures {
    /// The figures of the rows of one run (every rank's, any order); `None` when a rank is missing.
    pub fn of(rows: &[&RankRow]) -> Option<Self> {
        let first = rows.first()?;
        let ranks = first.ranks;
        let mut seen = vec![false; ranks];
        for r in rows {
            *seen.get_mut(r.rank)? = true;
        }
        if seen.contains(&false) || rows.len() != ranks {
            return None;
        }
        let rank0 = rows.iter().find(|r| r.rank == 0)?;
        let max = |f: fn(&RankRow) -> f64| rows.iter().map(|r| f(r)).fold(0.0, f64::max);
        let sum = |f: fn(&RankRow) -> f64| rows.iter().map(|r| f(r)).sum::<f64>();
        let steps = first.steps as f64;
        let per_step =
            |b: fn(&RankRow) -> f64, m: fn(&RankRow) -> f64| (sum(b) / steps, sum(m) / steps);
        Some(Self {
            scene: first.scene.clone(),
            ranks,
            bodies: first.bodies,
            steps: first.steps,
            wall_s: max(|r| r.wall_s),
            cpu_s: sum(|r| r.cpu_s),
            cut_steps: rank0.cut_steps,
            cut_wall_s: max(|r| r.cut_wall_s),
            ghost_fraction: sum(|r| r.ghosts as f64) / first.bodies as f64,
            per_step: [
                per_step(|r| r.ghost_bytes as f64, |r| r.ghost_messages as f64),
                per_step(
                    |r| r.agreement_bytes as f64,
                    |r| r.agreement_messages as f64,
                ),
                per_step(|r| r.cut_bytes as f64, |r| r.cut_messages as f64),
            ],
            foreign_load: rank0.runnable - ranks as f64,
            load_before: rank0.load_before,
            load_after: rank0.load_after,
            ghost_width_spacings: first.ghost_width_spacings,
        })
    }

    /// Whether the machine ran nothing else worth counting during the steps.
    pub fn quiet(&self) -> bool {
        self.foreign_load <= QUIET_FOREIGN_LOAD
    }
}

/// The runs of a CSV text (header first), in run order; an error names the line.
pub fn read_runs(text: &str) -> Result<Vec<RunFigures>, String> {
    let mut rows = Vec::new();
    for (n, line) in text.lines().enumerate().skip(1) {
        if line.trim().is_empty() {
            continue;
        }
        rows.push(RankRow::parse(line).map_err(|e| format!("line {}: {e}", n + 1))?);
    }
    let mut ids: Vec<u32> = rows.iter().map(|r| r.run).collect();
    ids.sort_unstable();
    ids.dedup();
    ids.into_iter()
        .map(|id| {
            let of_run: Vec<&RankRow> = rows.iter().filter(|r| r.run == id).collect();
            RunFigures::of(&of_run).ok_or_else(|| format!("run {id}: a rank's row is missing"))
        })
        .collect()
}

/// The median of `values` (the mean of the middle two for an even count); `None` when empty.
pub fn median(values: &mut [f64]) -> Option<f64> {
    if values.is_empty() {
        return None;
    }
    values.sort_by(f64::total_cmp);
    let n = values.len();
    Some(if n % 2 == 1 {
        values[n / 2]
    } else {
        0.5 * (values[n / 2 - 1] + values[n / 2])
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn row(rank: usize, wall: f64, ghost_bytes: u64) -> RankRow {
        RankRow {
            run: 3,
            scene: "spheres".into(),
            ranks: 2,
            rank,
            bodies: 100,
            steps: 10,
            wall_s: wall,
            cpu_s: 1.25,
            cut_steps: 2,
            cut_wall_s: 0.1 * wall,
            owned: 50,
            ghosts: 10,
            ghost_bytes,
            ghost_messages: 8,
            agreement_bytes: 320,
            agreement_messages: 10,
            cut_bytes: 4000,
            cut_messages: 2,
            runnable: 2.75,
            load_before: 1.5,
            load_after: 2.25,
            ghost_width_spacings: 1.0 / 3.0,
        }
    }

    #[test]
    fn rows_read_back_and_a_run_takes_the_slowest_rank_and_the_summed_traffic() {
        let rows = [row(0, 2.0, 1520), row(1, 3.0, 3040)];
        let text = format!("{HEADER}\n{}\n{}\n", rows[0].to_csv(), rows[1].to_csv());
        let read_back: Vec<RankRow> = text
            .lines()
            .skip(1)
            .map(|l| RankRow::parse(l).expect("a row written by to_csv"))
            .collect();
        assert_eq!(read_back, rows, "rows written then read");
        let runs = read_runs(&text).expect("two rows of one run");
        assert_eq!(runs.len(), 1, "one run expected: {runs:?}");
        let run = &runs[0];
        assert_eq!(run.wall_s, 3.0, "wall time: the slowest rank's");
        assert_eq!(run.cpu_s, 2.5, "CPU time: summed over the ranks");
        let ghost_bytes_per_step = (1520.0 + 3040.0) / 10.0;
        assert_eq!(
            run.per_step[0],
            (ghost_bytes_per_step, 16.0 / 10.0),
            "ghosts per step"
        );
        assert_eq!(run.ghost_fraction, 20.0 / 100.0, "ghosts over bodies");
        assert_eq!(run.foreign_load, 0.75, "runnable 2.75 beyond 2 ranks");
        assert!(!run.quiet(), "foreign load 0.75 > {QUIET_FOREIGN_LOAD}");
        let missing = format!("{HEADER}\n{}\n", rows[0].to_csv());
        assert!(
            read_runs(&missing).is_err(),
            "a run without rank 1's row is refused"
        );
    }

    #[test]
    fn median_of_odd_and_even_counts() {
        assert_eq!(median(&mut [3.0, 1.0, 2.0]), Some(2.0));
        assert_eq!(median(&mut [4.0, 1.0, 3.0, 2.0]), Some(2.5));
        assert_eq!(median(&mut []), None);
    }
}
