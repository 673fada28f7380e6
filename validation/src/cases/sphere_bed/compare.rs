//! The comparison of polydem's run with the reference codes' on one variant: the metrics table, the checks
//! against the nearer code (recorded runs, and fresh runs where the codes were re-run), and the plots.

use polydem::math::Real;

use super::polydem_run::Run;
use super::recorded::Recorded;
use super::{fail, Limits};
use crate::case::Target;
use crate::cases::projectile_history::{self, History, Metrics, Quantity, QUANTITIES};
use crate::context::CaseContext;
use crate::error::SuiteError;
use crate::plot::{Plot, Series, SeriesStyle};
use crate::stats::relative_difference;

/// One metric of a run.
type MetricOf = fn(&Metrics) -> Real;
/// A plotted value of sample i of a history, given the projectile's start height z0.
type Pick = fn(&History, usize, Real) -> Real;

/// What one variant compares: polydem's run, the recorded reference runs, the fresh ones (where re-run),
/// over the window t ≤ `t_end`.
pub(super) struct Comparison<'a> {
    pub(super) variant: &'a str,
    pub(super) ours: &'a Run,
    pub(super) yade: &'a Recorded,
    pub(super) liggghts: &'a Recorded,
    pub(super) fresh_yade: Option<&'a Recorded>,
    pub(super) fresh_liggghts: Option<&'a Recorded>,
    pub(super) t_end: Real,
}

/// The metrics of `code`'s history up to `t_end` (an error names the code when it has no samples).
fn metrics(
    code: &str,
    h: &History,
    z0: Real,
    v0: Real,
    t_end: Real,
) -> Result<Metrics, SuiteError> {
    projectile_history::metrics(h, z0, v0, t_end)
        .ok_or_else(|| fail(format!("{code}: no sample at or before t = {t_end} s")))
}

/// Largest |z_a − z_b| over the common samples with t ≤ t_end (same sampling steps in every code).
fn max_gap(a: &History, b: &History, t_end: Real) -> Result<Real, SuiteError> {
    let mut gap: Real = 0.0;
    for i in 0..a.t.len().min(b.t.len()) {
        if a.t[i] > t_end * (1.0 + 1e-9) {
            break;
        }
        if (a.t[i] - b.t[i]).abs() > 1e-6 * a.t[i].max(1e-12) {
            return Err(fail(format!(
                "sample {i}: times differ ({} s vs {} s); the codes must sample the same steps",
                a.t[i], b.t[i]
            )));
        }
        gap = gap.max((a.z[i] - b.z[i]).abs());
    }
    Ok(gap)
}

/// The rows of a comparison table: each quantity for polydem, YADE and LIGGGHTS (in that order in
/// `metrics`) with the three pairwise relative differences, then the depth-history gaps (`gaps`: polydem–YADE,
/// polydem–LIGGGHTS, YADE–LIGGGHTS, in mean bed diameters).
fn comparison_rows(metrics: [&Metrics; 3], gaps: [Real; 3]) -> Vec<Vec<String>> {
    let row = |q: &Quantity| {
        let [o, y, l] = metrics.map(|m| q.of(m));
        vec![
            q.heading(),
            CaseContext::fmt(o),
            CaseContext::fmt(y),
            CaseContext::fmt(l),
            format!("{:.2} %", 100.0 * relative_difference(o, y)),
            format!("{:.2} %", 100.0 * relative_difference(o, l)),
            format!("{:.2} %", 100.0 * relative_difference(y, l)),
        ]
    };
    let mut gap_row = vec![
        "max depth-history gap [mean bed diameters]".to_owned(),
        "-".into(),
        "-".into(),
        "-".into(),
    ];
    gap_row.extend(gaps.map(CaseContext::fmt));
    let mut rows: Vec<Vec<String>> = QUANTITIES.iter().map(row).collect();
    rows.push(gap_row);
    rows
}
impl Comparison<'_> {
    fn metrics(&self, code: &str, h: &History) -> Result<Metrics, SuiteError> {
        metrics(code, h, self.ours.z0, self.ours.v0, self.t_end)
    }

    fn gap(&self, a: &History, b: &History) -> Result<Real, SuiteError> {
        max_gap(a, b, self.t_end)
    }

    /// The table and the checks against the recorded runs; returns the variant's row of the summary table.
    pub(super) fn against_recorded(
        &self,
        ctx: &mut CaseContext,
        limits: &Limits,
    ) -> Result<Vec<String>, SuiteError> {
        let (v, h) = (self.variant, &self.ours.history);
        let m_ours = self.metrics("polydem", h)?;
        let m_yade = self.metrics("YADE (recorded)", &self.yade.history)?;
        let m_lig = self.metrics("LIGGGHTS (recorded)", &self.liggghts.history)?;
        let gap_yl = self.gap(&self.yade.history, &self.liggghts.history)?;
        let gap_py = self.gap(h, &self.yade.history)?;
        let gap_pl = self.gap(h, &self.liggghts.history)?;
        let d = limits.mean_diameter;
        let rows = comparison_rows(
            [&m_ours, &m_yade, &m_lig],
            [gap_py, gap_pl, gap_yl].map(|g| g / d),
        );
        ctx.table(
            Some(&format!("{v}_table")),
            &table_header("YADE", "LIGGGHTS"),
            &rows,
        )?;
        // Checks against the nearer code.
        let nearer = |f: &dyn Fn(&Metrics) -> Real| {
            relative_difference(f(&m_ours), f(&m_yade))
                .min(relative_difference(f(&m_ours), f(&m_lig)))
        };
        ctx.check(
            &format!("{v}_depth_gap_to_nearer_code"),
            gap_py.min(gap_pl) / d,
            Target::at_most(gap_yl / d),
            "mean bed diameters (bound: YADE–LIGGGHTS gap)",
        );
        let impact: [(&str, MetricOf); 3] = [
            ("peak_force", |m| m.peak_force),
            ("contact_impulse", |m| m.impulse),
            ("slow_down_time", |m| m.slow_time),
        ];
        for (metric, f) in impact {
            ctx.check(
                &format!("{v}_{metric}_rel_to_nearer_code"),
                nearer(&f),
                Target::at_most(limits.impact_rel),
                "1",
            );
        }
        ctx.check(
            &format!("{v}_final_depth_rel_to_nearer_code"),
            nearer(&|m| m.final_depth),
            Target::at_most(
                limits
                    .final_depth_rel
                    .max(relative_difference(m_yade.final_depth, m_lig.final_depth)),
            ),
            "1 (bound: max of the tolerance and the YADE–LIGGGHTS spread)",
        );
        let [o, y, l] = [&m_ours, &m_yade, &m_lig];
        let mut row = vec![v.to_owned()];
        row.extend([o, y, l].map(|m| format!("{:.3}", m.final_depth * 1e3)));
        row.extend([o, y, l].map(|m| format!("{:.3}", m.final_vz)));
        row.extend([o, y, l].map(|m| format!("{:.2}", m.peak_force)));
        Ok(row)
    }

    /// The table and the checks against the reference runs of this suite run, where a code was re-run
    /// (the recorded run stands in for a code that was not).
    pub(super) fn against_fresh(
        &self,
        ctx: &mut CaseContext,
        limits: &Limits,
    ) -> Result<(), SuiteError> {
        if self.fresh_yade.is_none() && self.fresh_liggghts.is_none() {
            return Ok(());
        }
        let (v, h, d) = (self.variant, &self.ours.history, limits.mean_diameter);
        let fy = self.fresh_yade.unwrap_or(self.yade);
        let fl = self.fresh_liggghts.unwrap_or(self.liggghts);
        let label = |f: Option<&Recorded>, code: &str| match f {
            Some(_) => format!("{code} (this run)"),
            None => format!("{code} (recorded: not installed)"),
        };
        let m_ours = self.metrics("polydem", h)?;
        let m_fy = self.metrics("YADE", &fy.history)?;
        let m_fl = self.metrics("LIGGGHTS", &fl.history)?;
        let gap_fyl = self.gap(&fy.history, &fl.history)?;
        let gap_pfy = self.gap(h, &fy.history)?;
        let gap_pfl = self.gap(h, &fl.history)?;
        let same = |f: Option<&Recorded>, r: &Recorded| -> Result<String, SuiteError> {
            Ok(match f {
                Some(f) => CaseContext::fmt(self.gap(&f.history, &r.history)? / d),
                None => "-".into(),
            })
        };
        let mut rows = comparison_rows(
            [&m_ours, &m_fy, &m_fl],
            [gap_pfy, gap_pfl, gap_fyl].map(|g| g / d),
        );
        let mut same_row = vec![
            "max gap to the recorded run of the same code [mean bed diameters]".into(),
            "-".into(),
            same(self.fresh_yade, self.yade)?,
            same(self.fresh_liggghts, self.liggghts)?,
        ];
        same_row.extend(["-", "-", "-"].map(String::from));
        rows.push(same_row);
        let (yade, lig) = (
            label(self.fresh_yade, "YADE"),
            label(self.fresh_liggghts, "LIGGGHTS"),
        );
        ctx.text(&format!(
            "Against the reference runs of this suite run ({yade}, {lig}):"
        ));
        ctx.table(
            Some(&format!("{v}_table_this_run")),
            &table_header(&yade, &lig),
            &rows,
        )?;
        ctx.check(
            &format!("{v}_depth_gap_to_nearer_code_this_run"),
            gap_pfy.min(gap_pfl) / d,
            Target::at_most(gap_fyl / d),
            "mean bed diameters (bound: YADE–LIGGGHTS gap; reference codes re-run in this suite run)",
        );
        ctx.check(
            &format!("{v}_final_depth_rel_to_nearer_code_this_run"),
            relative_difference(m_ours.final_depth, m_fy.final_depth)
                .min(relative_difference(m_ours.final_depth, m_fl.final_depth)),
            Target::at_most(
                limits
                    .final_depth_rel
                    .max(relative_difference(m_fy.final_depth, m_fl.final_depth)),
            ),
            "1 (bound: max of the tolerance and the YADE–LIGGGHTS spread; this suite run)",
        );
        Ok(())
    }

    /// Depth, velocity and force against time, every code overlaid.
    pub(super) fn plots(&self, ctx: &mut CaseContext) -> Result<(), SuiteError> {
        let (v, t_end, z0) = (self.variant, self.t_end, self.ours.z0);
        let series =
            |hist: &History, label: &str, pick: fn(&History, usize, Real) -> Real| Series {
                label: label.into(),
                style: SeriesStyle::Line,
                points: (0..hist.t.len())
                    .take_while(|&i| hist.t[i] <= t_end * (1.0 + 1e-9))
                    .map(|i| (hist.t[i] * 1e3, pick(hist, i, z0)))
                    .collect(),
            };
        let quantities: [(&str, &str, Pick); 3] = [
            ("depth", "depth z0 − z (mm)", |h, i, z0| {
                (z0 - h.z[i]) * 1e3
            }),
            ("velocity", "vertical velocity (m/s)", |h, i, _| h.vz[i]),
            ("force", "vertical contact force (N)", |h, i, _| h.fz[i]),
        ];
        for (quantity, y_label, pick) in quantities {
            let mut list = vec![
                series(&self.ours.history, "polydem", pick),
                series(&self.yade.history, "YADE 2023.02a (recorded)", pick),
                series(&self.liggghts.history, "LIGGGHTS 3.8.0 (recorded)", pick),
            ];
            for (f, label) in [
                (self.fresh_yade, "YADE (this run)"),
                (self.fresh_liggghts, "LIGGGHTS (this run)"),
            ] {
                if let Some(f) = f {
                    list.push(series(&f.history, label, pick));
                }
            }
            ctx.plot(&Plot {
                name: format!("{v}_{quantity}"),
                title: format!("{v}: projectile {quantity}"),
                x_label: "t (ms)".into(),
                y_label: y_label.into(),
                x_log: false,
                y_log: false,
                series: list,
                caption: format!(
                    "Projectile {quantity} against time, the three codes overlaid (YADE reports the \
                     velocity at the half step)."
                ),
            })?;
        }
        Ok(())
    }
}

/// The header of a comparison table, with the two reference codes' column labels.
fn table_header<'a>(yade: &'a str, liggghts: &'a str) -> [&'a str; 7] {
    [
        "quantity",
        "polydem",
        yade,
        liggghts,
        "polydem–YADE",
        "polydem–LIGGGHTS",
        "YADE–LIGGGHTS (yardstick)",
    ]
}
