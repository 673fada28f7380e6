//! A checked value: its target (a comparison against a bound) and the row of `reports/summary.csv` it
//! becomes, with the deterministic number format of the reports. A leaf the case trait and the case
//! context both use.

/// How a checked value is compared with its bound.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum Comparison {
    /// value ≤ bound
    AtMost,
    /// value ≥ bound
    AtLeast,
    /// value == bound (counts, exact identities)
    Equal,
}

/// The target of a check: a comparison against a bound. A NaN value never passes.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct Target {
    pub comparison: Comparison,
    pub bound: f64,
}

impl Target {
    pub fn at_most(bound: f64) -> Self {
        Target {
            comparison: Comparison::AtMost,
            bound,
        }
    }
    pub fn at_least(bound: f64) -> Self {
        Target {
            comparison: Comparison::AtLeast,
            bound,
        }
    }
    pub fn equal(bound: f64) -> Self {
        Target {
            comparison: Comparison::Equal,
            bound,
        }
    }

    /// Whether `value` meets the target (false for NaN).
    pub fn holds(&self, value: f64) -> bool {
        match self.comparison {
            Comparison::AtMost => value <= self.bound,
            Comparison::AtLeast => value >= self.bound,
            Comparison::Equal => value == self.bound,
        }
    }

    /// The target as written in `summary.csv`, e.g. `<= 1.000000e-10`.
    pub fn render(&self) -> String {
        let op = match self.comparison {
            Comparison::AtMost => "<=",
            Comparison::AtLeast => ">=",
            Comparison::Equal => "==",
        };
        format!("{op} {}", format_value(self.bound))
    }
}

/// Formats a number deterministically for the report: integers (up to 2^53) as integers, everything else
/// in scientific notation with 6 decimals.
pub fn format_value(value: f64) -> String {
    if value.is_finite() && value == value.trunc() && value.abs() < 9.007_199_254_740_992e15 {
        format!("{}", value as i64)
    } else {
        format!("{value:.6e}")
    }
}

/// One checked quantity: a row of `reports/summary.csv`.
#[derive(Clone, Debug, PartialEq)]
pub struct Check {
    pub case: String,
    pub metric: String,
    pub value: f64,
    pub target: Target,
    pub unit: String,
    pub pass: bool,
}
