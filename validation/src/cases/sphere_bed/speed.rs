//! Speed: particle-steps per second of polydem against the reference codes (recorded wall times, or the
//! codes re-run in the same suite run, over several rounds), and two threads against one.

use polydem::math::Real;

use super::compare::Comparison;
use super::polydem_run::{run_polydem, Run};
use super::recorded::{rerun_reference, Recorded};
use super::{fail, Limits, Params, Variant};
use crate::case::Target;
use crate::context::CaseContext;
use crate::error::SuiteError;

/// Particle-steps per second of a reference run.
fn rate(r: &Recorded) -> Real {
    r.particles * r.steps / r.wall_time_s
}

/// Particle-steps per second of a polydem run.
fn our_rate(r: &Run) -> Real {
    r.particles as Real * r.steps as Real / r.wall_time_s
}

/// A speed-table row of a polydem run.
fn polydem_row(v: &str, code: String, run: &Run) -> Vec<String> {
    vec![
        v.to_owned(),
        code,
        format!("{}", run.steps),
        format!("{:.2}", run.wall_time_s),
        run.cpu_time_s.map_or("n/a".into(), |c| format!("{c:.2}")),
        format!("{:.3e}", our_rate(run)),
        format!(
            "{}; load average {}",
            crate::provenance::utc_now(),
            run.load
        ),
    ]
}

/// A speed-table row of a reference run.
fn reference_row(v: &str, code: String, r: &Recorded) -> Vec<String> {
    vec![
        v.to_owned(),
        code,
        format!("{}", r.steps),
        format!("{:.2}", r.wall_time_s),
        "n/a".into(),
        format!("{:.3e}", rate(r)),
        format!("{}; {}", r.date, r.machine),
    ]
}

/// A row holding a ratio in the rate column.
fn ratio_row(v: &str, what: String, value: String) -> Vec<String> {
    let blank = String::new;
    vec![
        v.to_owned(),
        what,
        blank(),
        blank(),
        blank(),
        value,
        blank(),
    ]
}

fn list(ratios: &[Real]) -> String {
    let texts: Vec<String> = ratios.iter().map(|r| format!("{r:.3}")).collect();
    texts.join(", ")
}

/// The two-thread runs of a variant, each right after a one-thread run of the same trajectory.
#[derive(Default)]
pub(super) struct ThreadRounds {
    speedups: Vec<Real>,
    rows: Vec<Vec<String>>,
}

impl ThreadRounds {
    /// Runs the variant on two threads right after `one`, checks it repeats `one`'s trajectory, and
    /// records the wall-time ratio.
    pub(super) fn round(
        &mut self,
        variant: &Variant,
        one: &Run,
        ctx: &mut CaseContext,
    ) -> Result<(), SuiteError> {
        let two = run_polydem(variant, ctx, 2)?;
        if two.history.z != one.history.z {
            return Err(fail(format!(
                "{}: the two-thread run did not repeat the one-thread trajectory",
                variant.name
            )));
        }
        let round = self.speedups.len() + 1;
        let mut row = polydem_row(
            &variant.name,
            format!("polydem, 2 threads (this run, round {round})"),
            &two,
        );
        row[4] = "n/a".into();
        self.rows.push(row);
        self.speedups.push(one.wall_time_s / two.wall_time_s);
        Ok(())
    }
}

/// What the speed rows of a variant are made of: the runs it compared.
pub(super) struct SpeedRuns<'a> {
    pub(super) variant: &'a Variant,
    pub(super) runs: &'a Comparison<'a>,
}

impl SpeedRuns<'_> {
    /// The further rounds of timed runs (polydem, then each re-run code), so that a ratio is not one
    /// moment of a shared machine; returns the rounds' ratios against LIGGGHTS and YADE, the compared
    /// runs' first.
    fn rounds(
        &self,
        p: &Params,
        threads: &mut ThreadRounds,
        ctx: &mut CaseContext,
        rows: &mut Vec<Vec<String>>,
    ) -> Result<(Vec<Real>, Vec<Real>), SuiteError> {
        let v = &self.variant.name;
        let ours_rate = our_rate(self.runs.ours);
        let mut lig =
            vec![ours_rate / rate(self.runs.fresh_liggghts.unwrap_or(self.runs.liggghts))];
        let mut yade = vec![ours_rate / rate(self.runs.fresh_yade.unwrap_or(self.runs.yade))];
        let codes: Vec<&str> = [
            ("yade", self.runs.fresh_yade),
            ("liggghts", self.runs.fresh_liggghts),
        ]
        .into_iter()
        .filter_map(|(code, fresh)| fresh.map(|_| code))
        .collect();
        if codes.is_empty() {
            return Ok((lig, yade));
        }
        for k in 1..p.speed_rounds {
            eprintln!(
                "sphere_bed: timing round {} of {} ({v}) ...",
                k + 1,
                p.speed_rounds
            );
            let again = run_polydem(self.variant, ctx, 1)?;
            threads.round(self.variant, &again, ctx)?;
            if again.history.z != self.runs.ours.history.z {
                return Err(fail(format!(
                    "{v}: polydem's timing run {} did not repeat the compared run's trajectory",
                    k + 1
                )));
            }
            rows.push(polydem_row(
                v,
                format!("polydem (this run, round {})", k + 1),
                &again,
            ));
            for code in &codes {
                // Timed only: its outputs go to a scratch directory, not to the report.
                let scratch = std::env::temp_dir().join(format!(
                    "polydem-sphere-bed-rounds-{}/{code}{}",
                    std::process::id(),
                    k + 1
                ));
                let timed = rerun_reference(code, v, &scratch)?;
                let (label, ratios) = match *code {
                    "yade" => ("YADE", &mut yade),
                    _ => ("LIGGGHTS", &mut lig),
                };
                ratios.push(our_rate(&again) / rate(&timed));
                rows.push(reference_row(
                    v,
                    format!("{label} (this run, round {})", k + 1),
                    &timed,
                ));
            }
        }
        Ok((lig, yade))
    }

    /// The variant's speed rows (pushed onto `rows`) and, with `check_speed`, its speed checks.
    pub(super) fn report(
        &self,
        p: &Params,
        limits: &Limits,
        mut threads: ThreadRounds,
        ctx: &mut CaseContext,
        rows: &mut Vec<Vec<String>>,
    ) -> Result<(), SuiteError> {
        let v = &self.variant.name;
        let (lig_ratios, yade_ratios) = self.rounds(p, &mut threads, ctx, rows)?;
        let lig_ratio = crate::stats::median(lig_ratios.clone()).unwrap_or(lig_ratios[0]);
        let yade_ratio = crate::stats::median(yade_ratios.clone()).unwrap_or(yade_ratios[0]);
        let source = |fresh: Option<&Recorded>| {
            if fresh.is_some() {
                "this run"
            } else {
                "recorded"
            }
        };
        let (yade_source, lig_source) = (
            source(self.runs.fresh_yade),
            source(self.runs.fresh_liggghts),
        );
        rows.push(polydem_row(v, "polydem (this run)".into(), self.runs.ours));
        let fresh_rows = [
            self.runs.fresh_yade.map(|r| ("YADE (this run)", r)),
            self.runs.fresh_liggghts.map(|r| ("LIGGGHTS (this run)", r)),
        ];
        for (code, r) in [
            ("YADE (recorded)", self.runs.yade),
            ("LIGGGHTS (recorded)", self.runs.liggghts),
        ]
        .into_iter()
        .chain(fresh_rows.into_iter().flatten())
        {
            rows.push(reference_row(v, code.into(), r));
        }
        let rounds_note = if lig_ratios.len() > 1 || yade_ratios.len() > 1 {
            format!(
                " (medians of the rounds; LIGGGHTS {}; YADE {})",
                list(&lig_ratios),
                list(&yade_ratios)
            )
        } else {
            String::new()
        };
        rows.push(ratio_row(
            v,
            format!("ratio polydem / LIGGGHTS ({lig_source}), polydem / YADE ({yade_source}){rounds_note}"),
            format!("{lig_ratio:.3}, {yade_ratio:.3}"),
        ));
        if p.check_speed {
            let unit = |ratios: &[Real], code: &str, source: &str| match ratios.len() {
                1 => format!("1 (particle-steps/s, wall time; {code} {source})"),
                n => format!(
                    "1 (particle-steps/s, wall time; median of {n} rounds of runs, {code} {source})"
                ),
            };
            ctx.check(
                &format!("{v}_speed_over_liggghts"),
                lig_ratio,
                Target::at_least(limits.speed_over_liggghts),
                &unit(&lig_ratios, "LIGGGHTS", lig_source),
            );
            ctx.check(
                &format!("{v}_speed_over_yade"),
                yade_ratio,
                Target::at_least(limits.speed_over_yade),
                &unit(&yade_ratios, "YADE", yade_source),
            );
        }
        threads_report(v, threads, limits, ctx, rows);
        Ok(())
    }
}

/// The two-thread rows, their median ratio and its check (when the variant ran on two threads).
fn threads_report(
    v: &str,
    threads: ThreadRounds,
    limits: &Limits,
    ctx: &mut CaseContext,
    rows: &mut Vec<Vec<String>>,
) {
    let Some(speedup) = crate::stats::median(threads.speedups.clone()) else {
        return;
    };
    let n = threads.speedups.len();
    rows.extend(threads.rows);
    rows.push(ratio_row(
        v,
        format!(
            "ratio polydem 2 threads / 1 thread (median of {n} rounds: {})",
            list(&threads.speedups)
        ),
        format!("{speedup:.3}"),
    ));
    ctx.check(
        &format!("{v}_two_threads_over_one"),
        speedup,
        Target::at_least(limits.two_threads_over_one),
        &format!(
            "1 (wall time of the one-thread run over the two-thread run right after it; median of {n} \
             rounds)"
        ),
    );
}

/// The speed section: how the rows are measured, and the table.
pub(super) fn section(ctx: &mut CaseContext, rows: &[Vec<String>]) -> Result<(), SuiteError> {
    ctx.section("Speed (single thread)");
    ctx.text(
        "Particle-steps per second = particles × steps / wall time of the stepping loop. Rows marked \
         **recorded** take the wall times in the headers of the committed output files (with the date and \
         the load of the machine then); rows marked **this run** are the reference codes re-run by this \
         suite run right after polydem's run of the same variant (full profile, codes installed), and \
         the speed ratios and checks use them when they exist. polydem's wall time is measured here, \
         with its thread's CPU time beside it; it runs without the per-contact energy ledger \
         (`energy_ledger = false`, the same trajectory bit for bit), as YADE and LIGGGHTS keep none, \
         through the run `polydem run` uses (`Simulation::run_observed`, the state handed out every \
         output interval), which takes the flat sphere layout (per-sphere arrays and a half neighbour \
         list; the same bits as the general step). \
         The machine is shared (2 cores), so wall-time ratios between runs at different moments carry \
         an uncertainty of up to a factor of two or three, and a single ratio within one suite run moves \
         by ±10–20 %: the full profile times `speed_rounds` rounds per variant (polydem, then each re-run \
         code; rows **round k**) and checks the median of each code's ratios. Each one-thread polydem \
         run of the full profile is followed by the same run on two threads (the same trajectory, \
         checked), and the median of the wall-time ratios is checked against the target. Beside each \
         polydem run's load average: the share of the machine's CPU time that the hypervisor gave to \
         other machines during the run (**host steal**, `/proc/stat`); a run on two threads loses more \
         to it than a run on one, since each step waits for both threads. Beside each two-thread run: \
         the time a cache line takes from one of the pool's threads to the other and back, read just \
         before and after the run (**core round trip**, `polydem::host::core_round_trip_ns`). The host \
         may move the machine's two virtual CPUs between cores tens to hundreds of nanoseconds apart; a \
         two-thread step passes cache lines between the cores at each synchronisation, so its time \
         follows the round trip (see `docs/speed.md`), and the two-thread rows hold for the state the \
         run met.",
    );
    ctx.table(
        Some("speed"),
        &[
            "variant",
            "code",
            "steps",
            "wall time [s]",
            "CPU time [s]",
            "particle-steps/s",
            "when, machine",
        ],
        rows,
    )
}
