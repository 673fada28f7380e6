//! Case `perf`: a short fixed set of timings, ours vs parry3d-f64 in the same run, appended to
//! `reports/perf/history.csv`; fails when a ratio regresses past the threshold against the last figure
//! recorded on the same machine (cores + CPU model). Not part of the default run.

use crate::provenance::workspace_root;
use std::path::Path;

use polydem::contact::ContactTolerances;
use serde::Deserialize;

use crate::case::{Case, CaseData, Profile, Target};
use crate::cases::contact::eval::{build, Built};
use crate::cases::contact::{random_set, timing};
use crate::context::CaseContext;
use crate::error::SuiteError;
use crate::pairsets::{Intent, RandomSetSpec};
use crate::plot::{Plot, Series, SeriesStyle};
use crate::provenance::Provenance;

/// The case (registered in [`crate::cases::registry`]).
pub struct Perf;

#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct Params {
    seed: u64,
    classes: Vec<String>,
    pairs_per_class: usize,
    repeats: usize,
}

const NAME: &str = "perf";
const HISTORY: &str = "history.csv";
const HEADER: [&str; 8] = [
    "commit",
    "date",
    "machine",
    "figure",
    "value",
    "unit",
    "peer_value",
    "ratio",
];

/// How many recorded runs of a figure the regression baseline takes the median of.
const BASELINE_RUNS: usize = 5;

fn case_err(msg: impl Into<String>) -> SuiteError {
    SuiteError::case(NAME, msg)
}

fn read_history(path: &Path) -> Result<Vec<Vec<String>>, SuiteError> {
    if !path.exists() {
        return Ok(Vec::new());
    }
    let mut r = csv::Reader::from_path(path).map_err(SuiteError::csv(path))?;
    let mut rows = Vec::new();
    for rec in r.records() {
        let rec = rec.map_err(SuiteError::csv(path))?;
        rows.push(rec.iter().map(str::to_string).collect::<Vec<_>>());
    }
    Ok(rows)
}

impl Case for Perf {
    fn name(&self) -> &'static str {
        NAME
    }
    fn data(&self) -> &'static str {
        include_str!("../../cases/perf.toml")
    }
    fn in_default_run(&self) -> bool {
        false
    }
    fn persistent_files(&self) -> &'static [&'static str] {
        &[HISTORY]
    }

    fn run(
        &self,
        data: &CaseData,
        profile: Profile,
        ctx: &mut CaseContext,
    ) -> Result<(), SuiteError> {
        let p: Params = data.params(NAME, profile)?;
        let threshold = data.tolerance(NAME, "ratio_regression")?.value;
        let spec = RandomSetSpec {
            classes: p.classes.clone(),
            sizes: vec![1.0],
            pairs_per_class_and_size: 2 * p.pairs_per_class,
            seed: p.seed,
            touching_fraction: 0.0,
            separated_fraction: 0.5,
            overlap_min_rel: 1e-6,
            overlap_max_rel: 0.3,
        };
        ctx.progress().stage(
            "generating pairs",
            (p.classes.len() * spec.pairs_per_class_and_size) as u64,
        );
        let pairs = random_set(&spec, || ctx.progress().inc(1))?;
        ctx.progress().stage("timing", p.classes.len() as u64);
        // (figure, ours ns, parry ns)
        let mut figures: Vec<(String, f64, f64)> = Vec::new();
        for class in &p.classes {
            let of = |want: fn(&Intent) -> bool| -> Result<Vec<Built>, SuiteError> {
                pairs
                    .iter()
                    .filter(|q| &q.class == class && want(&q.intent))
                    .map(|q| build(q).map_err(case_err))
                    .collect()
            };
            let ov = of(|i| matches!(i, Intent::Overlap(_)))?;
            let sep = of(|i| matches!(i, Intent::Separated(_)))?;
            figures.push((
                format!("contact_overlap_{class}"),
                timing::ours_query_ns(&ov, ContactTolerances::default(), p.repeats),
                timing::parry_query_ns(&ov, p.repeats),
            ));
            figures.push((
                format!("reject_separated_{class}"),
                timing::ours_intersects_ns(&sep, p.repeats),
                timing::parry_intersects_ns(&sep, p.repeats),
            ));
            ctx.progress().inc(1);
        }

        let prov = Provenance::collect(&workspace_root());
        let machine = prov.machine();
        let Some(dir) = ctx.output_dir()? else {
            // In-memory run: no history to compare with or append to, hence no checks.
            return Ok(());
        };
        let path = dir.join(HISTORY);
        let mut history = read_history(&path)?;
        // The baseline is the median of the last BASELINE_RUNS ratios of the figure on this machine: a
        // single earlier run is as noisy as the new one (back-to-back runs here differ by up to ~40 %).
        let baseline = |fig: &str| {
            let recent: Vec<f64> = history
                .iter()
                .rev()
                .filter(|r| r.len() == HEADER.len() && r[2] == machine && r[3] == fig)
                .filter_map(|r| r[7].parse::<f64>().ok())
                .take(BASELINE_RUNS)
                .collect();
            crate::stats::median(recent)
        };
        let mut rows = Vec::new();
        let mut new_rows = Vec::new();
        for (fig, ours, parry) in &figures {
            let ratio = ours / parry;
            match baseline(fig) {
                Some(base) => {
                    ctx.check(
                        &format!("{fig}_ratio_vs_baseline"),
                        ratio / base,
                        Target::at_most(threshold),
                        "1",
                    );
                    rows.push(vec![
                        fig.clone(),
                        format!("{ours:.0}"),
                        format!("{parry:.0}"),
                        format!("{ratio:.3}"),
                        format!("{base:.3}"),
                    ]);
                }
                None => rows.push(vec![
                    fig.clone(),
                    format!("{ours:.0}"),
                    format!("{parry:.0}"),
                    format!("{ratio:.3}"),
                    "none (first run on this machine)".into(),
                ]),
            }
            new_rows.push(vec![
                prov.commit.clone(),
                prov.date.clone(),
                machine.clone(),
                fig.clone(),
                format!("{ours:.1}"),
                "ns".into(),
                format!("{parry:.1}"),
                format!("{ratio:.4}"),
            ]);
        }
        history.extend(new_rows);
        let mut w = csv::Writer::from_path(&path).map_err(SuiteError::csv(&path))?;
        w.write_record(HEADER).map_err(SuiteError::csv(&path))?;
        for r in &history {
            w.write_record(r).map_err(SuiteError::csv(&path))?;
        }
        w.flush().map_err(SuiteError::io(&path))?;

        ctx.text(&format!(
            "Machine: {machine}. Each figure: ns per query (minimum over {} passes over {} pairs), ours and \
             parry3d-f64 measured in this run; ratio = ours / parry. A check fails when a ratio exceeds {threshold} \
             × the median of the last {BASELINE_RUNS} ratios recorded for the same figure on the same machine. History: [perf/{HISTORY}](perf/{HISTORY}).",
            p.repeats, p.pairs_per_class
        ));
        ctx.table(
            None,
            &[
                "figure",
                "ours ns",
                "parry ns",
                "ratio",
                "baseline ratio (median)",
            ],
            &rows,
        )?;
        for (prefix, what) in [
            ("contact_overlap_", "overlapping pairs: contact query"),
            ("reject_separated_", "separated pairs: intersection test"),
        ] {
            let mut series = Vec::new();
            for (fig, _, _) in figures.iter().filter(|(f, _, _)| f.starts_with(prefix)) {
                let pts: Vec<(f64, f64)> = history
                    .iter()
                    .filter(|r| r.len() == HEADER.len() && r[2] == machine && &r[3] == fig)
                    .enumerate()
                    .filter_map(|(i, r)| Some(((i + 1) as f64, r[7].parse::<f64>().ok()?)))
                    .collect();
                series.push(Series {
                    label: fig.trim_start_matches(prefix).to_string(),
                    style: SeriesStyle::LinePoints,
                    points: pts,
                });
            }
            ctx.plot(&Plot {
                name: format!("{}history", prefix),
                title: format!("Time ratio ours / parry3d-f64, {what}"),
                x_label: "run number on this machine".into(),
                y_label: "time ratio ours / parry (lower is faster)".into(),
                x_log: false,
                y_log: false,
                series,
                caption: "One point per `cargo validate perf` run on this machine, one line per shape class.".into(),
            })?;
        }
        Ok(())
    }
}
