//! The rockfill case's time-step convergence check, posed against the result's own variability.
//!
//! The penetration of a granular layer is a many-contact process whose result moves with the initial
//! state: displacing the projectile's aim by 1 % of a rock size moves the quick variant's residual
//! velocity over about 1 m/s and its axis deflection over about 2°. A time step is converged when halving
//! it changes the result by much less than that spread: here, by at most a quarter of it (the
//! discretisation error then adds at most 3 % to the spread in quadrature). The spread at a time step is
//! the range of the result over the unperturbed run and `perturbations` runs whose aim is displaced by
//! `perturbation_size_fraction` rock sizes in directions evenly spaced around the flight axis.
//!
//! The same measure is applied to a coarse time step (`coarse_dt_divisor` < 1) where it must find the
//! change too large: the check shown to fail where it should.

use std::path::Path;

use polydem::math::{Real, Vector};
use polydem_rockfill::config::ExperimentConfig;
use polydem_rockfill::convergence::ConvergenceRow;
use polydem_rockfill::experiment::{run_experiment_with, BedSource};
use polydem_rockfill::penetration::PenetrationOptions;

use crate::case::Target;
use crate::context::CaseContext;
use crate::error::SuiteError;

/// How the spread is measured, from the case's parameters.
pub(super) struct SpreadParams {
    /// The aim's displacement, in mean rock sizes.
    pub(super) size_fraction: Real,
    /// Number of displaced runs.
    pub(super) count: usize,
    /// Largest change over spread of a converged time step.
    pub(super) tolerance: Real,
}

/// The quantities judged: residual speed (m/s) and axis deflection (°).
const QUANTITIES: [(&str, &str); 2] = [("residual", "m/s"), ("axis_deflection", "°")];

fn judged(row: &ConvergenceRow) -> [Real; 2] {
    [row.residual_speed, row.axis_deflection]
}

/// The range of each judged quantity over `unperturbed` and the runs at the same Δt/k with the aim
/// displaced.
fn spread(
    config: &ExperimentConfig,
    bed: &Path,
    unperturbed: &ConvergenceRow,
    params: &SpreadParams,
) -> Result<[Real; 2], SuiteError> {
    let delta = params.size_fraction * config.rock.mean_size;
    let (mut low, mut high) = (judged(unperturbed), judged(unperturbed));
    for j in 0..params.count {
        let angle = std::f64::consts::TAU * j as Real / params.count as Real;
        let options = PenetrationOptions {
            dt_divisor: unperturbed.parameter,
            start_offset: Vector::new(0.0, angle.cos(), angle.sin()) * delta,
            ..PenetrationOptions::default()
        };
        let r = run_experiment_with(config, BedSource::Load(bed), &options, &mut |_, _| {})
            .map_err(|e| SuiteError::case("rockfill", format!("perturbed run {j}: {e}")))?;
        let p = &r.penetration;
        for (q, v) in [p.residual_speed, p.final_axis_deflection]
            .into_iter()
            .enumerate()
        {
            low[q] = low[q].min(v);
            high[q] = high[q].max(v);
        }
    }
    Ok([high[0] - low[0], high[1] - low[1]])
}

/// Δt/k as the report writes it: `Δt`, `Δt/2`, `8 Δt`.
fn step_label(k: Real) -> String {
    if k == 1.0 {
        "Δt".into()
    } else if k < 1.0 {
        format!("{} Δt", 1.0 / k)
    } else {
        format!("Δt/{k}")
    }
}

/// The row of Δt/k in the sequence.
fn row_at(seq: &[&ConvergenceRow], k: Real) -> Result<ConvergenceRow, SuiteError> {
    seq.iter()
        .find(|r| r.parameter == k)
        .map(|r| (*r).clone())
        .ok_or_else(|| {
            SuiteError::case(
                "rockfill",
                format!(
                    "the time-step sequence has no run at Δt/{k} (dt_divisors must include it)"
                ),
            )
        })
}

/// Checks the change from Δt/`coarse` to Δt/`fine` against the spread at Δt/`coarse`: at most the
/// tolerance when `converged`, above it otherwise. Returns the table rows.
#[allow(clippy::too_many_arguments)] // the pair, its expectation, and where to run and report
pub(super) fn check_pair(
    ctx: &mut CaseContext,
    config: &ExperimentConfig,
    bed: &Path,
    seq: &[&ConvergenceRow],
    (coarse, fine): (Real, Real),
    converged: bool,
    params: &SpreadParams,
    rows: &mut Vec<Vec<String>>,
) -> Result<(), SuiteError> {
    let (a, b) = (row_at(seq, coarse)?, row_at(seq, fine)?);
    let spreads = spread(config, bed, &a, params)?;
    let (va, vb) = (judged(&a), judged(&b));
    let tag = if converged { "dt" } else { "coarse_dt" };
    let (from, to) = (step_label(coarse), step_label(fine));
    for (q, (name, unit)) in QUANTITIES.iter().enumerate() {
        let change = (va[q] - vb[q]).abs();
        let ratio = change / spreads[q];
        let (target, meaning) = if converged {
            (Target::at_most(params.tolerance), "converged")
        } else {
            (
                Target::at_least(params.tolerance),
                "flagged as not converged",
            )
        };
        ctx.check(
            &format!("{tag}_{name}_change_over_spread"),
            ratio,
            target,
            &format!(
                "1 (|r({from}) − r({to})| over the range of r at {from} under aim displacements of {} \
                 rock sizes; {meaning})",
                params.size_fraction
            ),
        );
        rows.push(vec![
            format!("{from} → {to}"),
            format!("{name} ({unit})"),
            format!("{change:.4}"),
            format!("{:.4}", spreads[q]),
            format!("{ratio:.3}"),
            if ratio <= params.tolerance {
                "converged".into()
            } else {
                "not converged".into()
            },
        ]);
    }
    Ok(())
}
