//! Scoring each method's answer on a pair against the SAT oracle, and the per-method column it adds to.
//!
//! A peer's answer is classified with the core's touching band, like ours and parry's; a pair whose
//! reference lies within the pair tolerance of the band's edge is right either way ([`super::super::eval`]).
//! A peer that only says "no intersection" (libccd) is right on a separated or touching pair and has no
//! distance error or normal. A failed call (an error status, the support-call cap) counts as a wrong status.
//! Value errors and normal excesses ([`normal_excess`]) are kept over the pairs a method classifies right.

use polydem::contact::{ContactKind, ContactTolerances};

use super::super::eval::{classify, normal_excess, Errors, Eval};
use crate::pairsets::Pair;
use crate::peers::native::NativeAnswer;

/// One method's answer on one pair, scored.
pub struct Scored {
    pub wrong: bool,
    pub failed: bool,
    /// |signed gap − reference| / size, when the status is right and the method gives a value.
    pub value_error: Option<f64>,
    /// Normal excess / size, when the status is right and the method gives a normal (∞ when it claims an
    /// overlap without a usable direction).
    pub normal_excess: Option<f64>,
    /// The answer in words, for the failure lists.
    pub answer: String,
    /// The answer's kind in words ("overlap", "no intersection", "failed", …).
    pub answer_kind: &'static str,
}

pub fn kind_name(k: ContactKind) -> &'static str {
    match k {
        ContactKind::Overlap => "overlap",
        ContactKind::Touching => "touching",
        ContactKind::Separated => "separated",
    }
}

/// Ours or parry's answer, from the errors the case's evaluation already measured.
pub fn from_errors(err: &Errors, kind: Option<ContactKind>, e: &Eval) -> Scored {
    let wrong = err.wrong_status || err.failed;
    let answer_kind = match kind {
        Some(k) if !err.failed => kind_name(k),
        _ => "failed",
    };
    Scored {
        wrong,
        failed: err.failed,
        value_error: (!wrong).then_some(err.gap / e.size),
        normal_excess: (!wrong).then_some(err.normal_excess / e.size),
        answer: answer_kind.to_string(),
        answer_kind,
    }
}

/// A C/C++ peer's answer on `pair` (evaluated as `e`).
pub fn native(a: &NativeAnswer, pair: &Pair, e: &Eval) -> Scored {
    let band = ContactTolerances::default().touching * e.size;
    let reference = e.reference.signed_gap;
    let (kind, signed, normal) = match *a {
        NativeAnswer::Overlap { depth, normal } => {
            (classify(-depth, band), Some(-depth), Some(normal))
        }
        NativeAnswer::Separated {
            distance: Some(d),
            normal,
        } => (classify(d, band), Some(d), Some(normal)),
        NativeAnswer::Separated { distance: None, .. } => (ContactKind::Separated, None, None),
        NativeAnswer::Failed => {
            return Scored {
                wrong: true,
                failed: true,
                value_error: None,
                normal_excess: None,
                answer: "failed".into(),
                answer_kind: "failed",
            }
        }
    };
    let ambiguous = (reference.abs() - band).abs() <= e.tol;
    let boolean_ok = signed.is_none() && e.reference.kind != ContactKind::Overlap;
    let wrong = kind != e.reference.kind && !ambiguous && !boolean_ok;
    let excess = normal.map(|n| match n {
        Some(n) => normal_excess(pair, &n, reference) / e.size,
        None => f64::INFINITY,
    });
    Scored {
        wrong,
        failed: false,
        value_error: signed
            .filter(|_| !wrong)
            .map(|s| (s - reference).abs() / e.size),
        normal_excess: excess.filter(|_| !wrong),
        answer: match *a {
            NativeAnswer::Overlap { depth, .. } => format!("overlap {:.3e}", depth / e.size),
            NativeAnswer::Separated {
                distance: Some(d), ..
            } => format!("gap {:.3e}", d / e.size),
            _ => "no intersection".into(),
        },
        answer_kind: if signed.is_none() {
            "no intersection"
        } else {
            kind_name(kind)
        },
    }
}

/// A wrong answer, for the failure lists.
pub struct Failure {
    pub id: String,
    /// Index of the pair set (random, degenerate, pebble–boulder).
    pub set: usize,
    pub reference_kind: &'static str,
    /// |reference signed gap| / size.
    pub reference_value: f64,
    pub answer: String,
    pub answer_kind: &'static str,
}

/// One method's results over all pairs.
pub struct Column {
    pub label: String,
    pub wrong: usize,
    /// Wrong statuses per set (random, degenerate, pebble–boulder).
    pub wrong_by_set: Vec<usize>,
    pub failed: usize,
    pub pairs: usize,
    pub overlap_errors: Vec<f64>,
    pub distance_errors: Vec<f64>,
    /// Normal excess / size on overlapping and on separated pairs.
    pub overlap_normal: Vec<f64>,
    pub separated_normal: Vec<f64>,
    pub failures: Vec<Failure>,
}

impl Column {
    pub fn new(label: String, sets: usize) -> Self {
        Column {
            label,
            wrong: 0,
            wrong_by_set: vec![0; sets],
            failed: 0,
            pairs: 0,
            overlap_errors: Vec::new(),
            distance_errors: Vec::new(),
            overlap_normal: Vec::new(),
            separated_normal: Vec::new(),
            failures: Vec::new(),
        }
    }

    /// Adds one scored answer on pair `e` of set `set`.
    pub fn record(&mut self, set: usize, e: &Eval, s: Scored) {
        self.pairs += 1;
        if s.wrong {
            self.wrong += 1;
            self.wrong_by_set[set] += 1;
            self.failed += s.failed as usize;
            self.failures.push(Failure {
                id: e.id.clone(),
                set,
                reference_kind: kind_name(e.reference.kind),
                reference_value: e.reference.signed_gap.abs() / e.size,
                answer: s.answer,
                answer_kind: s.answer_kind,
            });
            return;
        }
        let (errors, normals) = match e.reference.kind {
            ContactKind::Overlap => (&mut self.overlap_errors, &mut self.overlap_normal),
            ContactKind::Separated => (&mut self.distance_errors, &mut self.separated_normal),
            ContactKind::Touching => return,
        };
        errors.extend(s.value_error);
        normals.extend(s.normal_excess);
    }

    /// The largest value error (depth or distance) / size over the pairs classified right.
    pub fn worst_value_error(&self) -> Option<f64> {
        self.overlap_errors
            .iter()
            .chain(&self.distance_errors)
            .copied()
            .reduce(f64::max)
    }
}
