//! Where each method fails: per method, the wrong statuses per pair set and per kind of mistake with the
//! first pairs of each kind on the page, and the failing pairs by id in a CSV (the first
//! [`LISTED_PER_KIND`] of each kind per method). Pair ids reproduce the pairs with the case's seed
//! (`cargo validate --export-pairs`).

use std::collections::BTreeMap;

use super::score::{Column, Failure};
use crate::context::CaseContext;
use crate::error::SuiteError;

/// Failing pairs shown on the page per method and kind of mistake.
const SHOWN_PER_KIND: usize = 2;
/// Failing pairs written to the CSV per method and kind of mistake.
pub const LISTED_PER_KIND: usize = 100;
/// The CSV of failing pairs.
const CSV_NAME: &str = "library_failing_pairs";

fn kind_of(f: &Failure) -> String {
    format!("{} → {}", f.reference_kind, f.answer_kind)
}

/// The failures of a column grouped by kind of mistake, in order of first appearance within each kind.
fn by_kind(c: &Column) -> BTreeMap<String, Vec<&Failure>> {
    let mut map: BTreeMap<String, Vec<&Failure>> = BTreeMap::new();
    for f in &c.failures {
        map.entry(kind_of(f)).or_default().push(f);
    }
    map
}

fn show(f: &Failure) -> String {
    format!("`{}` ({:.3e} → {})", f.id, f.reference_value, f.answer)
}

/// The page table of every method, and the CSV of failing pairs.
pub fn report(cols: &[Column], ctx: &mut CaseContext) -> Result<(), SuiteError> {
    ctx.section("Where each library fails");
    ctx.text(&format!(
        "Wrong statuses per method: per pair set, per kind of mistake (reference status → answer) with \
         the first {SHOWN_PER_KIND} pairs of each kind, as `pair id` (|reference value| / size → the \
         answer, values / size). Pair ids reproduce the pairs with the case's seed (`cargo validate \
         --export-pairs`; pebble–boulder ids are `pebble/r<ratio index>/<class>/<o|g><decade>/<order>`). \
         The CSV lists the first {LISTED_PER_KIND} failing pairs of each kind per method."
    ));
    let mut rows = Vec::new();
    let mut listed = Vec::new();
    for c in cols {
        let kinds = by_kind(c);
        let summary: Vec<String> = kinds
            .iter()
            .map(|(k, fs)| {
                let first: Vec<String> = fs.iter().take(SHOWN_PER_KIND).map(|f| show(f)).collect();
                format!("{k}: {} — {}", fs.len(), first.join(", "))
            })
            .collect();
        let by_set: Vec<String> = c.wrong_by_set.iter().map(|w| w.to_string()).collect();
        rows.push(vec![
            c.label.clone(),
            by_set.join(" / "),
            if summary.is_empty() {
                "–".into()
            } else {
                summary.join("; ")
            },
        ]);
        for fs in kinds.values() {
            for f in fs.iter().take(LISTED_PER_KIND) {
                listed.push(vec![
                    c.label.clone(),
                    super::SET_NAMES[f.set].to_string(),
                    f.id.clone(),
                    kind_of(f),
                    format!("{:e}", f.reference_value),
                    f.answer.clone(),
                ]);
            }
        }
    }
    ctx.table(
        Some("library_failures"),
        &[
            "method",
            "wrong (random / degenerate / pebble–boulder)",
            "kinds of mistake: count — first pairs",
        ],
        &rows,
    )?;
    write_listed(&listed, ctx)
}

fn write_listed(rows: &[Vec<String>], ctx: &mut CaseContext) -> Result<(), SuiteError> {
    let Some(dir) = ctx.output_dir()? else {
        return Ok(());
    };
    let path = dir.join(format!("{CSV_NAME}.csv"));
    let mut w = csv::Writer::from_path(&path).map_err(SuiteError::csv(&path))?;
    w.write_record([
        "method",
        "set",
        "pair",
        "mistake",
        "reference |value| / size",
        "answer",
    ])
    .map_err(SuiteError::csv(&path))?;
    for r in rows {
        w.write_record(r).map_err(SuiteError::csv(&path))?;
    }
    w.flush().map_err(SuiteError::io(&path))?;
    ctx.text(&format!(
        "Failing pairs: [{CSV_NAME}.csv]({}/{CSV_NAME}.csv) ({} rows).",
        ctx.case(),
        rows.len()
    ));
    Ok(())
}
