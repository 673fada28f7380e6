//! Elliptic integrals and Jacobi elliptic functions (see the module docs of `special_functions`).

use crate::math::Real;
use std::f64::consts::PI;

/// A parameter outside the domain where these functions are implemented.
#[derive(Debug, Clone, Copy, PartialEq, thiserror::Error)]
pub enum EllipticError {
    /// The parameter m must satisfy 0 ≤ m ≤ 1 (and m < 1 for K and F, which diverge at m = 1).
    #[error("elliptic parameter m = {m} is outside the supported range {range}")]
    ParameterOutOfRange {
        /// The parameter given.
        m: Real,
        /// The range allowed, as text.
        range: &'static str,
    },
    /// An argument was not finite.
    #[error("non-finite argument {name} = {value}")]
    NonFinite {
        /// Name of the argument.
        name: &'static str,
        /// Its value.
        value: Real,
    },
}

/// The values of the three Jacobi elliptic functions at one argument, with the amplitude φ = am(u | m)
/// (sn = sin φ, cn = cos φ).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct JacobiElliptic {
    /// sn(u | m) = sin φ.
    pub sn: Real,
    /// cn(u | m) = cos φ.
    pub cn: Real,
    /// dn(u | m) = √(1 − m sin²φ).
    pub dn: Real,
    /// The amplitude φ = am(u | m) (rad).
    pub am: Real,
}

/// Maximum number of AGM iterations. The AGM converges quadratically; 1 − m = 1e-300 needs about 12.
const MAX_AGM_ITERATIONS: usize = 40;

fn check_parameter(m: Real, allow_one: bool) -> Result<(), EllipticError> {
    if !m.is_finite() {
        return Err(EllipticError::NonFinite {
            name: "m",
            value: m,
        });
    }
    let in_range = if allow_one {
        (0.0..=1.0).contains(&m)
    } else {
        (0.0..1.0).contains(&m)
    };
    if in_range {
        Ok(())
    } else {
        Err(EllipticError::ParameterOutOfRange {
            m,
            range: if allow_one { "[0, 1]" } else { "[0, 1)" },
        })
    }
}

/// The complete elliptic integral of the first kind, K(m) = ∫₀^{π/2} dθ / √(1 − m sin²θ), for 0 ≤ m < 1.
///
/// Computed as π / (2 AGM(1, √(1 − m))) (A&S 17.6.1).
pub fn complete_elliptic_k(m: Real) -> Result<Real, EllipticError> {
    check_parameter(m, false)?;
    let mut a: Real = 1.0;
    let mut b: Real = (1.0 - m).sqrt();
    for _ in 0..MAX_AGM_ITERATIONS {
        if (a - b).abs() <= 1e-16 * a {
            break;
        }
        let a_next = 0.5 * (a + b);
        b = (a * b).sqrt();
        a = a_next;
    }
    Ok(PI / (2.0 * a))
}

/// The Jacobi elliptic functions sn, cn, dn and the amplitude am of argument u and parameter m ∈ [0, 1].
///
/// Descending AGM scheme (A&S 16.4): a₀ = 1, b₀ = √(1 − m), c₀ = √m; iterate a, b, c to c_N ≈ 0; then
/// φ_N = 2^N a_N u and φ_{n−1} = (φ_n + asin(c_n sin φ_n / a_n)) / 2; finally sn = sin φ₀, cn = cos φ₀,
/// dn = √(cn² + (1 − m) sn²).
pub fn jacobi_elliptic(u: Real, m: Real) -> Result<JacobiElliptic, EllipticError> {
    check_parameter(m, true)?;
    if !u.is_finite() {
        return Err(EllipticError::NonFinite {
            name: "u",
            value: u,
        });
    }
    if m == 1.0 {
        // Degenerate case (A&S 16.6.1-3): sn = tanh u, cn = dn = sech u, am = gd(u).
        let sech = 1.0 / u.cosh();
        return Ok(JacobiElliptic {
            sn: u.tanh(),
            cn: sech,
            dn: sech,
            am: 2.0 * u.exp().atan() - 0.5 * PI,
        });
    }
    if m == 0.0 {
        return Ok(JacobiElliptic {
            sn: u.sin(),
            cn: u.cos(),
            dn: 1.0,
            am: u,
        });
    }
    let mut a = [0.0; MAX_AGM_ITERATIONS + 1];
    let mut c = [0.0; MAX_AGM_ITERATIONS + 1];
    a[0] = 1.0;
    let mut b = (1.0 - m).sqrt();
    c[0] = m.sqrt();
    let mut n = 0;
    while n < MAX_AGM_ITERATIONS && c[n].abs() > 1e-16 * a[n] {
        a[n + 1] = 0.5 * (a[n] + b);
        c[n + 1] = 0.5 * (a[n] - b);
        b = (a[n] * b).sqrt();
        n += 1;
    }
    let mut phi = (2.0 as Real).powi(n as i32) * a[n] * u;
    for j in (1..=n).rev() {
        let s = (c[j] / a[j] * phi.sin()).clamp(-1.0, 1.0);
        phi = 0.5 * (phi + s.asin());
    }
    let (sn, cn) = phi.sin_cos();
    // dn = √(cn² + (1 − m) sn²): both terms are non-negative (no cancellation), and 1 − m is exact for
    // m ≥ ½. A&S's cos φ₀ / cos(φ₁ − φ₀) is 0/0 near u = K and is not used.
    let dn = (cn * cn + (1.0 - m) * sn * sn).sqrt();
    Ok(JacobiElliptic {
        sn,
        cn,
        dn,
        am: phi,
    })
}

/// The Jacobi amplitude φ = am(u | m), the inverse of u = F(φ | m); continuous and increasing in u.
pub fn jacobi_amplitude(u: Real, m: Real) -> Result<Real, EllipticError> {
    Ok(jacobi_elliptic(u, m)?.am)
}

/// Carlson's symmetric elliptic integral R_F(x, y, z) for x, y, z ≥ 0 with at most one of them zero.
///
/// Duplication algorithm; the loop stops when the relative spread of the arguments is below 1e-3, where the
/// fifth-order series below leaves a relative error under 1e-16 (Carlson 1995, eq. 2.2 and the error bound
/// that follows it).
fn carlson_rf(mut x: Real, mut y: Real, mut z: Real) -> Real {
    for _ in 0..100 {
        let mean = (x + y + z) / 3.0;
        let dx = 1.0 - x / mean;
        let dy = 1.0 - y / mean;
        let dz = 1.0 - z / mean;
        if dx.abs().max(dy.abs()).max(dz.abs()) < 1e-3 {
            let e2 = dx * dy - dz * dz;
            let e3 = dx * dy * dz;
            return (1.0 - e2 / 10.0 + e3 / 14.0 + e2 * e2 / 24.0 - 3.0 * e2 * e3 / 44.0)
                / mean.sqrt();
        }
        let (sx, sy, sz) = (x.sqrt(), y.sqrt(), z.sqrt());
        let lambda = sx * sy + sy * sz + sz * sx;
        x = 0.25 * (x + lambda);
        y = 0.25 * (y + lambda);
        z = 0.25 * (z + lambda);
    }
    // The spread shrinks by a factor 4 per iteration, so 100 iterations are never needed for finite input.
    let mean = (x + y + z) / 3.0;
    1.0 / mean.sqrt()
}

/// The incomplete elliptic integral of the first kind F(φ | m) = ∫₀^φ dθ / √(1 − m sin²θ), any real φ,
/// 0 ≤ m < 1.
pub fn incomplete_elliptic_f(phi: Real, m: Real) -> Result<Real, EllipticError> {
    check_parameter(m, false)?;
    if !phi.is_finite() {
        return Err(EllipticError::NonFinite {
            name: "phi",
            value: phi,
        });
    }
    // Reduce φ to [−π/2, π/2]: F(φ + jπ) = F(φ) + 2jK.
    let j = (phi / PI).round();
    let reduced = phi - j * PI;
    let (s, c) = reduced.sin_cos();
    let f_reduced = s * carlson_rf(c * c, 1.0 - m * s * s, 1.0);
    if j == 0.0 {
        Ok(f_reduced)
    } else {
        Ok(f_reduced + 2.0 * j * complete_elliptic_k(m)?)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::special_functions::gauss_legendre;

    /// K(m) by the trapezoidal rule over a full period of the smooth, π-periodic integrand
    /// 1/√(1 − m sin²θ): K = ½ ∫₀^π …, and the trapezoidal rule converges geometrically for periodic analytic
    /// integrands. Independent of the AGM.
    fn k_by_quadrature(m: Real) -> Real {
        let n = 200_000;
        let h = PI / n as Real;
        let sum: Real = (0..n)
            .map(|i| {
                let s = (i as Real * h).sin();
                1.0 / (1.0 - m * s * s).sqrt()
            })
            .sum();
        0.5 * h * sum
    }

    /// F(φ | m) by composite 8-point Gauss–Legendre quadrature on 400 panels (nodes and weights from the
    /// closed-form Golub–Welsch-free Newton iteration below, so no table is typed in).
    fn f_by_quadrature(phi: Real, m: Real) -> Real {
        let (nodes, weights) = gauss_legendre(8);
        let panels = 400;
        let h = phi / panels as Real;
        let mut sum = 0.0;
        for p in 0..panels {
            let mid = (p as Real + 0.5) * h;
            for (x, w) in nodes.iter().zip(&weights) {
                let theta = mid + 0.5 * h * x;
                let s = theta.sin();
                sum += 0.5 * h * w / (1.0 - m * s * s).sqrt();
            }
        }
        sum
    }

    const PARAMETERS: [Real; 9] = [0.0, 1e-6, 0.1, 0.3, 0.5, 0.7, 0.9, 0.99, 0.999];

    #[test]
    fn complete_integral_matches_quadrature() {
        for m in PARAMETERS {
            let measured = complete_elliptic_k(m).unwrap();
            let expected = k_by_quadrature(m);
            let tolerance = 1e-13 * expected;
            assert!(
                (measured - expected).abs() <= tolerance,
                "K(m = {m}) = {measured}, quadrature {expected}, tolerance {tolerance}"
            );
        }
    }

    #[test]
    fn complete_integral_matches_power_series_for_small_m() {
        // A&S 17.3.11: K = π/2 Σ [(2n)! / (2^{2n} (n!)²)]² mⁿ.
        for m in [1e-3, 0.01, 0.05, 0.2] {
            let mut coefficient: Real = 1.0;
            let mut sum = 0.0;
            let mut power = 1.0;
            for n in 0..200 {
                sum += coefficient * coefficient * power;
                let n = n as Real;
                coefficient *= (2.0 * n + 1.0) / (2.0 * n + 2.0);
                power *= m;
            }
            let expected = 0.5 * PI * sum;
            let measured = complete_elliptic_k(m).unwrap();
            assert!(
                (measured - expected).abs() <= 1e-14 * expected,
                "K({m}) = {measured}, series {expected}, tolerance 1e-14 relative"
            );
        }
    }

    #[test]
    fn amplitude_inverts_the_incomplete_integral_by_quadrature() {
        for m in PARAMETERS {
            for u in [-2.5, -0.3, 0.0, 0.4, 1.0, 1.7, 3.3, 6.0] {
                let phi = jacobi_amplitude(u, m).unwrap();
                let u_back = f_by_quadrature(phi, m);
                assert!(
                    (u_back - u).abs() <= 1e-12 * (1.0 + u.abs()),
                    "m = {m}, u = {u}: am = {phi}, F(am) by quadrature = {u_back}, tolerance 1e-12"
                );
                if m < 1.0 {
                    let u_carlson = incomplete_elliptic_f(phi, m).unwrap();
                    assert!(
                        (u_carlson - u).abs() <= 1e-12 * (1.0 + u.abs()),
                        "m = {m}, u = {u}: F(am(u)) by Carlson = {u_carlson}, tolerance 1e-12"
                    );
                }
            }
        }
    }

    #[test]
    fn incomplete_integral_matches_quadrature_beyond_half_period() {
        for m in [0.2, 0.8, 0.95] {
            for phi in [-4.0, -1.0, 0.7, 1.5, 2.0, 5.0, 9.0] {
                let measured = incomplete_elliptic_f(phi, m).unwrap();
                let expected = f_by_quadrature(phi, m);
                assert!(
                    (measured - expected).abs() <= 1e-12 * (1.0 + expected.abs()),
                    "F({phi} | {m}) = {measured}, quadrature {expected}, tolerance 1e-12"
                );
            }
        }
    }

    #[test]
    fn identities_and_derivatives_hold() {
        // sn² + cn² = 1, dn² + m sn² = 1 (A&S 16.9.1), d sn/du = cn dn, d cn/du = −sn dn,
        // d dn/du = −m sn cn (A&S 16.16), by a central difference of step h (error ~h²/6 · |f'''|).
        let h = 1e-5;
        for m in PARAMETERS {
            for u in [-3.0, -1.1, 0.2, 0.9, 2.2, 4.5] {
                let f = jacobi_elliptic(u, m).unwrap();
                let plus = jacobi_elliptic(u + h, m).unwrap();
                let minus = jacobi_elliptic(u - h, m).unwrap();
                let checks = [
                    ("sn²+cn²−1", f.sn * f.sn + f.cn * f.cn - 1.0, 1e-14),
                    ("dn²+m sn²−1", f.dn * f.dn + m * f.sn * f.sn - 1.0, 1e-14),
                    (
                        "sn' − cn dn",
                        (plus.sn - minus.sn) / (2.0 * h) - f.cn * f.dn,
                        1e-9,
                    ),
                    (
                        "cn' + sn dn",
                        (plus.cn - minus.cn) / (2.0 * h) + f.sn * f.dn,
                        1e-9,
                    ),
                    (
                        "dn' + m sn cn",
                        (plus.dn - minus.dn) / (2.0 * h) + m * f.sn * f.cn,
                        1e-9,
                    ),
                ];
                for (name, residual, tolerance) in checks {
                    assert!(
                        residual.abs() <= tolerance,
                        "m = {m}, u = {u}: {name} = {residual:e}, tolerance {tolerance:e}"
                    );
                }
            }
        }
    }

    #[test]
    fn periods_and_limits_are_right() {
        for m in [0.1, 0.5, 0.9, 0.99] {
            let k = complete_elliptic_k(m).unwrap();
            let at_k = jacobi_elliptic(k, m).unwrap();
            // sn(K) = 1, cn(K) = 0, dn(K) = √(1 − m) (A&S 16.5).
            assert!(
                (at_k.sn - 1.0).abs() < 1e-14,
                "m = {m}: sn(K) = {}",
                at_k.sn
            );
            assert!(at_k.cn.abs() < 1e-13, "m = {m}: cn(K) = {}", at_k.cn);
            assert!(
                (at_k.dn - (1.0 - m).sqrt()).abs() < 1e-14,
                "m = {m}: dn(K) = {}, expected {}",
                at_k.dn,
                (1.0 - m).sqrt()
            );
            let u = 0.37;
            let a = jacobi_elliptic(u, m).unwrap();
            let b = jacobi_elliptic(u + 4.0 * k, m).unwrap();
            assert!(
                (a.sn - b.sn).abs() < 1e-13
                    && (a.cn - b.cn).abs() < 1e-13
                    && (a.dn - b.dn).abs() < 1e-13,
                "m = {m}: functions not 4K-periodic: {a:?} vs {b:?}"
            );
        }
        // m → 0: circular functions; m → 1: hyperbolic (A&S 16.6), approached continuously.
        for u in [-1.3, 0.5, 2.0] {
            let f = jacobi_elliptic(u, 1e-12).unwrap();
            assert!(
                (f.sn - Real::sin(u)).abs() < 1e-11,
                "sn({u}|1e-12) = {}",
                f.sn
            );
            let g = jacobi_elliptic(u, 1.0 - 1e-13).unwrap();
            assert!(
                (g.sn - u.tanh()).abs() < 1e-11,
                "sn({u}|1−1e-13) = {}",
                g.sn
            );
            assert!(
                (g.dn - 1.0 / u.cosh()).abs() < 1e-11,
                "dn({u}|1−1e-13) = {}",
                g.dn
            );
        }
    }

    #[test]
    fn out_of_range_parameters_are_refused() {
        assert!(complete_elliptic_k(1.0).is_err());
        assert!(complete_elliptic_k(-0.1).is_err());
        assert!(jacobi_elliptic(0.3, 1.5).is_err());
        assert!(jacobi_elliptic(Real::NAN, 0.5).is_err());
        assert!(incomplete_elliptic_f(0.3, Real::NAN).is_err());
    }
}
