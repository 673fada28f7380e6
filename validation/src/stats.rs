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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn slope_of_an_exact_power_law_is_its_exponent() {
        let x = [0.1, 0.05, 0.02, 0.01];
        let y: Vec<Real> = x.iter().map(|h: &Real| 3.0 * h.powf(2.5)).collect();
        let order = fitted_order(&x, &y);
        assert!((order - 2.5).abs() < 1e-12, "fitted {order}, exact 2.5");
    }
}
