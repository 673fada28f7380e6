//! Every contact library on the case's pair sets, side by side: polydem, parry3d-f64 and the C/C++
//! libraries ([`crate::peers::native`]: libccd, Bullet, coal, when compiled in). Per method: wrong statuses
//! against the SAT oracle, depth and distance errors and the normal excess relative to the pair's size
//! ([`score`]), ns per query over the timing pools and per vertex-count class ([`speed`]), all in the same
//! run; a plot of time against worst error; and where each method fails, by pair id ([`failures`]).

mod failures;
mod score;
mod speed;

use polydem::contact::ContactKind;

use super::eval::{build, Built, Eval};
use crate::context::CaseContext;
use crate::error::SuiteError;
use crate::pairsets::Pair;
use crate::peers::native::{availability, NativePair, NativePeer};
use crate::perf::peers::load_average;
use crate::plot::{Plot, Series, SeriesStyle};
use score::Column;
use speed::{time_method, Pool, Times};

/// The pair sets, in the order of the report's per-set counts.
pub const SET_NAMES: [&str; 3] = ["random", "degenerate", "pebble–boulder"];
/// Errors below this (relative to size) are drawn at this value on the log axis.
const PLOT_FLOOR: f64 = 1e-18;

/// A method of the comparison.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum Method {
    Ours,
    Parry,
    Native(NativePeer),
}

impl Method {
    fn label(self) -> String {
        match self {
            Method::Ours => "polydem (default tolerances)".into(),
            Method::Parry => "parry3d-f64 0.31".into(),
            Method::Native(p) => p.label(),
        }
    }
}

/// Scores every method on every pair of `sets` (one pass over the pairs; the C/C++ peers' shapes are
/// built per pair and dropped after it).
fn score_all(
    sets: &[(&[Pair], &[Eval])],
    methods: &[Method],
    ctx: &mut CaseContext,
) -> Result<Vec<Column>, SuiteError> {
    let mut cols: Vec<Column> = methods
        .iter()
        .map(|m| Column::new(m.label(), sets.len()))
        .collect();
    let natives = methods.iter().any(|m| matches!(m, Method::Native(_)));
    let n: usize = sets.iter().map(|(p, _)| p.len()).sum();
    ctx.progress().stage("libraries: answers", n as u64);
    for (set, (pairs, evals)) in sets.iter().enumerate() {
        for (pair, e) in pairs.iter().zip(evals.iter()) {
            let native = if natives {
                let b = build(pair).map_err(|msg| SuiteError::case("contact", msg))?;
                Some(NativePair::new(&b.a, &b.pos1, &b.b, &b.pos2, e.size))
            } else {
                None
            };
            for (m, col) in methods.iter().zip(cols.iter_mut()) {
                let s = match (m, &native) {
                    (Method::Ours, _) => score::from_errors(&e.ours, Some(e.ours_kind), e),
                    (Method::Parry, _) => score::from_errors(&e.parry, e.parry_kind, e),
                    (Method::Native(p), Some(np)) => score::native(&np.answer(*p), pair, e),
                    (Method::Native(_), None) => {
                        unreachable!("native pairs are built when peers run")
                    }
                };
                col.record(set, e, s);
            }
            ctx.progress().inc(1);
        }
    }
    Ok(cols)
}

/// "median / max" of values, "–" when there are none.
fn median_max(v: &mut [f64]) -> String {
    if v.is_empty() {
        return "–".into();
    }
    v.sort_by(f64::total_cmp);
    format!("{:.1e} / {:.1e}", v[v.len() / 2], v[v.len() - 1])
}

fn ns(v: f64) -> String {
    if v.is_nan() {
        "–".into()
    } else {
        format!("{v:.0}")
    }
}

/// The answers table: statuses, errors, normal excess and ns per query over the pools.
fn answers_table(
    cols: &mut [Column],
    timings: &[(Times, Times)],
    ctx: &mut CaseContext,
) -> Result<(), SuiteError> {
    let rows: Vec<Vec<String>> = cols
        .iter_mut()
        .zip(timings)
        .map(|(c, (ov, sep))| {
            vec![
                c.label.clone(),
                format!("{} / {}", c.wrong, c.pairs),
                c.failed.to_string(),
                median_max(&mut c.overlap_errors),
                median_max(&mut c.distance_errors),
                median_max(&mut c.overlap_normal),
                median_max(&mut c.separated_normal),
                ns(ov.all),
                ns(sep.all),
            ]
        })
        .collect();
    ctx.table(
        Some("libraries"),
        &[
            "method",
            "wrong statuses",
            "of which failed calls",
            "depth error / size (median / max)",
            "distance error / size (median / max)",
            "normal excess / size, overlapping (median / max)",
            "normal excess / size, separated (median / max)",
            "overlapping ns",
            "separated ns",
        ],
        &rows,
    )
}

/// ns per query per vertex-count class, overlapping and separated.
fn class_table(
    cols: &[Column],
    timings: &[(Times, Times)],
    pools: (&Pool, &Pool),
    ctx: &mut CaseContext,
) -> Result<(), SuiteError> {
    ctx.section("ns per query by vertex count");
    ctx.text(
        "Classes by nA + nB, the hull vertices of both bodies; the same pairs as the table above, each \
         class timed on its own (minimum over the passes).",
    );
    let mut headers = vec!["method".to_string()];
    headers.extend(pools.0.class_headers("overlapping"));
    headers.extend(pools.1.class_headers("separated"));
    let rows: Vec<Vec<String>> = cols
        .iter()
        .zip(timings)
        .map(|(c, (ov, sep))| {
            let mut row = vec![c.label.clone()];
            row.extend(ov.by_class.iter().map(|v| ns(*v)));
            row.extend(sep.by_class.iter().map(|v| ns(*v)));
            row
        })
        .collect();
    let headers: Vec<&str> = headers.iter().map(String::as_str).collect();
    ctx.table(Some("libraries_ns_by_class"), &headers, &rows)
}

/// Time against worst value error, one marker per method and setting.
fn time_error_plot(
    cols: &[Column],
    timings: &[(Times, Times)],
    ctx: &mut CaseContext,
) -> Result<(), SuiteError> {
    let series = cols
        .iter()
        .zip(timings)
        .filter_map(|(c, (ov, _))| {
            let err = c.worst_value_error()?;
            Some(Series {
                label: c.label.clone(),
                style: SeriesStyle::Marker,
                points: vec![(ov.all, err.max(PLOT_FLOOR))],
            })
        })
        .collect();
    ctx.plot(&Plot {
        name: "time_vs_error".into(),
        title: "Contact libraries: worst value error against time per query".into(),
        x_label: "ns per overlapping query".into(),
        y_label: "worst depth or distance error / size".into(),
        x_log: true,
        y_log: true,
        series,
        caption: format!(
            "x: ns per query on the overlapping timing pool (the table's column); y: the largest depth or \
             distance error over the pairs each method classifies right, all sets. Wrong statuses are not \
             in y: see the table. Errors below {PLOT_FLOOR:e} × size are drawn at {PLOT_FLOOR:e}."
        ),
    })
}

/// The section: availability, the answers and timing tables of every method (ours first), the plot, and
/// where each fails.
pub fn report(
    sets: &[(&[Pair], &[Eval])],
    timing_overlap: &[Built],
    timing_separated: &[Built],
    repeats: usize,
    ctx: &mut CaseContext,
) -> Result<(), SuiteError> {
    ctx.section("The contact libraries side by side");
    ctx.text(&availability());
    let mut methods = vec![Method::Ours, Method::Parry];
    methods.extend(
        NativePeer::ALL
            .into_iter()
            .filter(|p| p.available())
            .map(Method::Native),
    );
    let load_before = load_average();
    let mut cols = score_all(sets, &methods, ctx)?;
    let natives = methods.len() > 2;
    let pools = (
        Pool::new(timing_overlap, natives),
        Pool::new(timing_separated, natives),
    );
    ctx.progress()
        .stage("libraries: timing", methods.len() as u64);
    let mut timings = Vec::new();
    for m in &methods {
        timings.push(time_method(*m, &pools.0, &pools.1, repeats));
        ctx.progress().inc(1);
    }
    let load_after = load_average();
    let n: usize = sets.iter().map(|(p, _)| p.len()).sum();
    let over = sets
        .iter()
        .flat_map(|(_, e)| e.iter())
        .filter(|e| e.reference.kind == ContactKind::Overlap)
        .count();
    ctx.text(&format!(
        "{n} pairs ({over} overlapping; the random, degenerate and pebble–boulder sets), the same hulls and \
         poses for every library. Errors: |signed gap − SAT oracle| / size (size: the pair's length scale, \
         the smaller body's), over the pairs each method classifies right. Normal excess: the overlap of \
         the two hulls along the returned normal minus the exact overlap (separated pairs: the exact \
         distance minus the separation along it), / size; ≥ 0 up to round-off, 0 when the normal is \
         optimal; ∞ when a method claims an overlap without a direction. Timing: ns per query, minimum over \
         {repeats} passes, on {} overlapping and {} separated size-1 pairs of the random set (overlapping: \
         the call that returns the depth; separated: the call that returns the distance, none for libccd, \
         which answers only whether the shapes intersect). Load average {} before, {} after.",
        pools.0.built.len(),
        pools.1.built.len(),
        load_before.map_or("–".into(), |l| format!("{l:.2}")),
        load_after.map_or("–".into(), |l| format!("{l:.2}")),
    ));
    answers_table(&mut cols, &timings, ctx)?;
    class_table(&cols, &timings, (&pools.0, &pools.1), ctx)?;
    ctx.section("Time against error");
    time_error_plot(&cols, &timings, ctx)?;
    failures::report(&cols, ctx)
}
