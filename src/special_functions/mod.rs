//! Special functions the analytical reference solutions need: the complete elliptic integral of the first
//! kind K(m), the incomplete integral F(φ | m), and the Jacobi elliptic functions sn, cn, dn and the
//! amplitude am; and Gauss–Legendre quadrature, which the analytic solutions and the tests use.
//!
//! Conventions follow Abramowitz & Stegun (1964), chapters 16 and 17: the *parameter* m = k² (not the
//! modulus k), with 0 ≤ m ≤ 1.
//!
//! Methods:
//! - K(m) by the arithmetic–geometric mean, K(m) = π / (2 AGM(1, √(1 − m))) (A&S 17.6.1), quadratically
//!   convergent: 5–6 iterations reach machine precision for m ≤ 1 − 1e-12.
//! - sn, cn, dn, am by the descending AGM/Landen scheme of A&S 16.4 (the "method of the arithmetic-geometric
//!   mean") for am, sn = sin am, cn = cos am, and dn = √(cn² + (1 − m) sn²) (free of cancellation; A&S's
//!   cos φ₀ / cos(φ₁ − φ₀) is 0/0 at u = K); accurate to a few ulps for |u| up to a few periods.
//! - F(φ | m) by Carlson's symmetric integral R_F with the duplication algorithm (Carlson 1995, Numer.
//!   Algorithms 10:13), extended beyond |φ| ≤ π/2 by F(φ + jπ | m) = F(φ | m) + 2jK(m).
//!
//! Limits: m outside [0, 1] is refused with [`EllipticError`]; m = 1 is refused by K and F (they diverge),
//! while sn, cn, dn at m = 1 return the degenerate closed forms tanh, sech, sech.

mod elliptic;
mod quadrature;

pub use elliptic::{
    complete_elliptic_k, incomplete_elliptic_f, jacobi_amplitude, jacobi_elliptic, EllipticError,
    JacobiElliptic,
};
pub use quadrature::gauss_legendre;
