//! Small statistics shared by the cases and the gates.

use polydem::math::Real;

/// Least-squares slope of log y against log x: the observed order of convergence when `x` are step sizes
/// and `y` errors. Every value must be positive (a zero or negative one makes the slope NaN, which fails any
/// check against it); callers that may see exact zeros filter them out first and say so.
pub fn fitted_order(x: &[Real], y: &[Real]) -> Real {
    let lx: Vec<Real> = x.iter().map(|v| v.ln()).collect();
    let ly: Vec<Real> = y.iter().map(|v| v.ln()).collect();
    let n = lx.len() as Real;
    let (mx, my) = (lx.iter().sum::<Real>() / n, ly.iter().sum::<Real>() / n);
    let sxy: Real = lx.iter().zip(&ly).map(|(a, b)| (a - mx) * (b - my)).sum();
    let sxx: Real = lx.iter().map(|a| (a - mx) * (a - mx)).sum();
    sxy / sxx
}

/// Relative difference of two values against their mean magnitude, |a − b| / (½ (|a| + |b|)): symmetric,
/// for comparing two runs where neither is the reference.
pub fn relative_difference(a: Real, b: Real) -> Real {
    (a - b).abs() / (0.5 * (a.abs() + b.abs()))
}

/// The median of `values` (the mean of the middle two for an even count); `None` when empty.
pub fn median(mut values: Vec<Real>) -> Option<Real> {
    if values.is_empty() {
        return None;
    }
    values.sort_by(Real::total_cmp);
    let mid = values.len() / 2;
    Some(if values.len() % 2 == 1 {
        values[mid]
    } else {
        0.5 * (values[mid - 1] + values[mid])
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn median_of_odd_even_and_empty_lists() {
        assert_eq!(median(vec![]), None);
        assert_eq!(median(vec![3.0, 1.0, 2.0]), Some(2.0));
        assert_eq!(median(vec![4.0, 1.0, 3.0, 2.0]), Some(2.5));
    }

    #[test]
    fn slope_of_an_exact_power_law_is_its_exponent() {
        let x = [0.1, 0.05, 0.02, 0.01];
        let y: Vec<Real> = x.iter().map(|h: &Real| 3.0 * h.powf(2.5)).collect();
        let order = fitted_order(&x, &y);
        assert!((order - 2.5).abs() < 1e-12, "fitted {order}, exact 2.5");
    }
}
