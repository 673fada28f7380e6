//! The C/C++ collision libraries (libccd, Bullet; [`crate::peers::native`]) on the case's pair sets: a
//! column per peer with wrong statuses against the SAT oracle, depth and distance errors relative to the
//! pair's size and ns per query, all in the same run as ours; and where each peer fails, by pair id.
//!
//! A peer's answer is classified with the core's touching band, like ours and parry's; a pair whose
//! reference lies within the pair tolerance of the band's edge is right either way ([`super::eval`]). A
//! peer that only says "no intersection" (libccd) is right on a separated or touching pair and has no
//! distance error. A failed call (an error status, the support-call cap) counts as a wrong status.

use std::hint::black_box;

use polydem::contact::tolerances::pair_length_scale;
use polydem::contact::{ContactKind, ContactTolerances};

use super::eval::{build, classify, Built, Eval};
use super::ours::Ours;
use super::timing::ns_per_item;
use crate::context::CaseContext;
use crate::error::SuiteError;
use crate::pairsets::Pair;
use crate::peers::native::{availability, NativeAnswer, NativePair, NativePeer};
use crate::perf::peers::load_average;

/// Failing pairs listed per peer.
const LISTED_FAILURES: usize = 6;

/// One peer's results over all pairs.
struct Column {
    label: String,
    wrong: usize,
    /// Wrong statuses per set (random, degenerate, pebble–boulder).
    wrong_by_set: Vec<usize>,
    failed: usize,
    overlap_errors: Vec<f64>,
    distance_errors: Vec<f64>,
    failures: Vec<String>,
    ns_overlap: f64,
    ns_separated: f64,
}

fn describe(a: &NativeAnswer, size: f64) -> String {
    match a {
        NativeAnswer::Overlap { depth, .. } => format!("overlap {:.3e}", depth / size),
        NativeAnswer::Separated {
            distance: Some(d), ..
        } => format!("gap {:.3e}", d / size),
        NativeAnswer::Separated { distance: None, .. } => "no intersection".into(),
        NativeAnswer::Failed => "failed".into(),
    }
}

fn kind_name(k: ContactKind) -> &'static str {
    match k {
        ContactKind::Overlap => "overlap",
        ContactKind::Touching => "touching",
        ContactKind::Separated => "separated",
    }
}

/// Scores one answer against the pair's evaluation: (wrong status, failed, value error × size if measured).
fn score(a: &NativeAnswer, e: &Eval, band: f64) -> (bool, bool, Option<f64>) {
    let reference = e.reference.signed_gap;
    let (kind, signed) = match *a {
        NativeAnswer::Overlap { depth, .. } => (classify(-depth, band), Some(-depth)),
        NativeAnswer::Separated {
            distance: Some(d), ..
        } => (classify(d, band), Some(d)),
        NativeAnswer::Separated { distance: None, .. } => (ContactKind::Separated, None),
        NativeAnswer::Failed => return (true, true, None),
    };
    let ambiguous = (reference.abs() - band).abs() <= e.tol;
    let boolean_ok = signed.is_none() && e.reference.kind != ContactKind::Overlap;
    let wrong = kind != e.reference.kind && !ambiguous && !boolean_ok;
    let error = if wrong {
        None
    } else {
        signed.map(|s| (s - reference).abs() / e.size)
    };
    (wrong, false, error)
}

fn evaluate_peer(
    peer: NativePeer,
    sets: &[(&[Pair], &[Eval])],
    prepared: &[(Built, NativePair)],
) -> Column {
    let mut col = Column {
        label: peer.label(),
        wrong: 0,
        wrong_by_set: Vec::new(),
        failed: 0,
        overlap_errors: Vec::new(),
        distance_errors: Vec::new(),
        failures: Vec::new(),
        ns_overlap: f64::NAN,
        ns_separated: f64::NAN,
    };
    col.wrong_by_set = vec![0; sets.len()];
    let evals = sets
        .iter()
        .enumerate()
        .flat_map(|(k, (_, e))| e.iter().map(move |e| (k, e)));
    for ((set, e), (built, native)) in evals.zip(prepared) {
        let band = ContactTolerances::default().touching
            * pair_length_scale(built.a.length_scale(), built.b.length_scale());
        let a = native.answer(peer);
        let (wrong, failed, error) = score(&a, e, band);
        col.wrong += wrong as usize;
        col.wrong_by_set[set] += wrong as usize;
        col.failed += failed as usize;
        if let Some(err) = error {
            if e.reference.kind == ContactKind::Overlap {
                col.overlap_errors.push(err);
            } else if e.reference.kind == ContactKind::Separated {
                col.distance_errors.push(err);
            }
        }
        if wrong && col.failures.len() < LISTED_FAILURES {
            col.failures.push(format!(
                "`{}`: {} {:.3e} → {}",
                e.id,
                kind_name(e.reference.kind),
                e.reference.signed_gap.abs() / e.size,
                describe(&a, e.size)
            ));
        }
    }
    col
}

fn stats(v: &mut [f64]) -> (String, String) {
    if v.is_empty() {
        return ("–".into(), "–".into());
    }
    v.sort_by(f64::total_cmp);
    (
        format!("{:.1e}", v[v.len() / 2]),
        format!("{:.1e}", v[v.len() - 1]),
    )
}

/// ns per query of `peer` on the overlapping and the separated timing pools.
fn time_peer(
    peer: NativePeer,
    overlap: &[NativePair],
    separated: &[NativePair],
    repeats: usize,
) -> (f64, f64) {
    let ov = ns_per_item(overlap.len(), repeats, |i| {
        black_box(overlap[i].answer_overlap_only(peer));
    });
    let sep = ns_per_item(separated.len(), repeats, |i| {
        black_box(separated[i].answer_separated_only(peer));
    });
    (ov, sep)
}

fn native(b: &Built) -> NativePair {
    let size = pair_length_scale(b.a.length_scale(), b.b.length_scale());
    NativePair::new(&b.a, &b.pos1, &b.b, &b.pos2, size)
}

/// The section: availability, the table of every peer (ours first), and where each fails.
#[allow(clippy::too_many_arguments)]
pub fn report(
    sets: &[(&[Pair], &[Eval])],
    timing_overlap: &[Built],
    timing_separated: &[Built],
    repeats: usize,
    ctx: &mut CaseContext,
) -> Result<(), SuiteError> {
    ctx.section("The C/C++ collision libraries");
    ctx.text(&availability());
    let peers: Vec<NativePeer> = NativePeer::ALL
        .into_iter()
        .filter(|p| p.available())
        .collect();
    if peers.is_empty() {
        return Ok(());
    }
    let load_before = load_average();
    let mut prepared = Vec::new();
    for (pairs, _) in sets {
        for pair in pairs.iter() {
            let built = build(pair).map_err(|e| SuiteError::case("contact", e))?;
            let n = native(&built);
            prepared.push((built, n));
        }
    }
    let ov: Vec<NativePair> = timing_overlap.iter().map(native).collect();
    let sep: Vec<NativePair> = timing_separated.iter().map(native).collect();
    let mut ours_col = ours_column(sets, timing_overlap, timing_separated, repeats);
    let mut cols = Vec::new();
    for peer in peers {
        let mut c = evaluate_peer(peer, sets, &prepared);
        (c.ns_overlap, c.ns_separated) = time_peer(peer, &ov, &sep, repeats);
        if !peer.gives_distance() {
            c.ns_separated = f64::NAN;
        }
        cols.push(c);
    }
    let load_after = load_average();
    let n: usize = sets.iter().map(|(p, _)| p.len()).sum();
    ctx.text(&format!(
        "{n} pairs (the random, degenerate and pebble–boulder sets), the same hulls and poses for every \
         library; errors are |signed gap − SAT oracle| / size (size: the pair's length scale, the smaller \
         body's), over the pairs each method classifies right. Timing: ns per query, minimum over {repeats} \
         passes, on {} overlapping and {} separated size-1 pairs of the random set (overlapping: the \
         penetration call; separated: the call that returns the distance, none for libccd, which answers \
         only whether the shapes intersect). Load average {} before, {} after.",
        ov.len(),
        sep.len(),
        load_before.map_or("–".into(), |l| format!("{l:.2}")),
        load_after.map_or("–".into(), |l| format!("{l:.2}")),
    ));
    cols.insert(0, std::mem::replace(&mut ours_col, empty_column()));
    let rows: Vec<Vec<String>> = cols
        .iter_mut()
        .map(|c| {
            let (om, ox) = stats(&mut c.overlap_errors);
            let (dm, dx) = stats(&mut c.distance_errors);
            let ns = |v: f64| {
                if v.is_nan() {
                    "–".into()
                } else {
                    format!("{v:.0}")
                }
            };
            vec![
                c.label.clone(),
                format!("{} / {n}", c.wrong),
                c.failed.to_string(),
                om,
                ox,
                dm,
                dx,
                ns(c.ns_overlap),
                ns(c.ns_separated),
            ]
        })
        .collect();
    ctx.table(
        Some("native_peers"),
        &[
            "method",
            "wrong statuses",
            "of which failed calls",
            "depth error median (× size)",
            "depth error max",
            "distance error median",
            "distance error max",
            "overlapping ns",
            "separated ns",
        ],
        &rows,
    )?;
    ctx.section("Where each C/C++ peer fails");
    ctx.text(
        "The first failing pairs of each peer (pair ids as in `cargo validate --export-pairs`; the pebble–boulder \
         ids are `pebble/r<ratio index>/<class>/<o|g><decade>/<order>`): reference status and |value| / size → \
         the peer's answer / size.",
    );
    let rows: Vec<Vec<String>> = cols[1..]
        .iter()
        .map(|c| {
            let list = if c.failures.is_empty() {
                "–".to_string()
            } else {
                c.failures.join("; ")
            };
            let by_set: Vec<String> = c.wrong_by_set.iter().map(|w| w.to_string()).collect();
            vec![c.label.clone(), by_set.join(" / "), list]
        })
        .collect();
    ctx.table(
        Some("native_peer_failures"),
        &[
            "peer",
            "wrong (random / degenerate / pebble–boulder)",
            "first failing pairs",
        ],
        &rows,
    )
}

fn empty_column() -> Column {
    Column {
        label: String::new(),
        wrong: 0,
        wrong_by_set: Vec::new(),
        failed: 0,
        overlap_errors: Vec::new(),
        distance_errors: Vec::new(),
        failures: Vec::new(),
        ns_overlap: f64::NAN,
        ns_separated: f64::NAN,
    }
}

/// Our column from the evaluations already made, timed on the same pools in the same run.
fn ours_column(sets: &[(&[Pair], &[Eval])], ov: &[Built], sep: &[Built], repeats: usize) -> Column {
    let mut col = empty_column();
    col.label = "polydem (default tolerances)".into();
    for (_, evals) in sets {
        for e in evals.iter() {
            col.wrong += e.ours.wrong_status as usize;
            col.failed += e.ours.failed as usize;
            if !e.ours.wrong_status && !e.ours.failed {
                match e.reference.kind {
                    ContactKind::Overlap => col.overlap_errors.push(e.ours.gap / e.size),
                    ContactKind::Separated => col.distance_errors.push(e.ours.gap / e.size),
                    ContactKind::Touching => {}
                }
            }
        }
    }
    let mut ours = Ours::new(ContactTolerances::default());
    col.ns_overlap = ns_per_item(ov.len(), repeats, |i| {
        black_box(ours.query(&ov[i].pos1, &ov[i].a, &ov[i].pos2, &ov[i].b));
    });
    col.ns_separated = ns_per_item(sep.len(), repeats, |i| {
        black_box(ours.query(&sep[i].pos1, &sep[i].a, &sep[i].pos2, &sep[i].b));
    });
    col
}
