//! Exact solutions of the torque-free rigid body, used as references by the rotation tests and the
//! precession validation case (kept in the engine so that both the unit gates and the validation suite use
//! one implementation).
//!
//! - [`SymmetricTop`] (J̄₁ = J̄₂): closed form. With Ω = ω̄₃ (J̄₃ − J̄₁)/J̄₁, the body components
//!   ω̄₁ + iω̄₂ turn as e^{iΩt}, ω̄₃ is constant, and the orientation is
//!   q(t) = exp(L̂ |L| t / J̄₁) ⊗ q₀ ⊗ exp(−Ω t e₃) (a steady precession about the fixed world L).
//! - [`AsymmetricTop`] (J̄₁ < J̄₂ < J̄₃): ω̄(t) in Jacobi elliptic functions (Landau & Lifshitz, Mechanics,
//!   §37). With energy E and |L| = M, if M² > 2EJ̄₂ (motion about axis 3)
//!   ω̄ = (A₁ cn τ, s A₂ sn τ, s A₃ dn τ), A₁² = (2EJ̄₃ − M²)/(J̄₁(J̄₃ − J̄₁)),
//!   A₂² = (2EJ̄₃ − M²)/(J̄₂(J̄₃ − J̄₂)), A₃² = (M² − 2EJ̄₁)/(J̄₃(J̄₃ − J̄₁)),
//!   τ = λt + τ₀, λ² = (J̄₃ − J̄₂)(M² − 2EJ̄₁)/(J̄₁J̄₂J̄₃), m = (J̄₂ − J̄₁)(2EJ̄₃ − M²)/((J̄₃ − J̄₂)(M² − 2EJ̄₁)),
//!   s = sign ω̄₃(0); if M² < 2EJ̄₂ (motion about axis 1) the roles of axes 1 and 3 are exchanged:
//!   ω̄ = (s A₁ dn τ, s A₂ sn τ, A₃ cn τ), A₁² = (2EJ̄₃ − M²)/(J̄₁(J̄₃ − J̄₁)),
//!   A₂² = (M² − 2EJ̄₁)/(J̄₂(J̄₂ − J̄₁)), A₃² = (M² − 2EJ̄₁)/(J̄₃(J̄₃ − J̄₁)),
//!   λ² = (J̄₂ − J̄₁)(2EJ̄₃ − M²)/(J̄₁J̄₂J̄₃), m = (J̄₃ − J̄₂)(M² − 2EJ̄₁)/((J̄₂ − J̄₁)(2EJ̄₃ − M²)),
//!   s = sign ω̄₁(0). The phase τ₀ = F(am₀ | m) matches the initial condition. The signs were checked
//!   against Euler's equations (test `asymmetric_solution_satisfies_euler_equations`).
//!   The period of ω̄(t) is 4K(m)/λ; near the intermediate axis (m → 1) this is the period of the
//!   Dzhanibekov flip cycle (ω̄₂ changes sign every 2K(m)/λ).
//!   The orientation: in a frame whose z axis is L, the Euler angles (z–x–z, body → L frame) are
//!   cos θ = L̄₃/M, φ = atan2(L̄₁, L̄₂), and the precession angle ψ obeys
//!   ψ̇ = M (J̄₁ω̄₁² + J̄₂ω̄₂²)/(J̄₁²ω̄₁² + J̄₂²ω̄₂²) (Landau & Lifshitz §37), integrated here by composite
//!   Gauss–Legendre quadrature (relative accuracy ~1e-13 for the panel widths used).

use crate::math::{Real, Rotation, Vector};
use crate::special_functions::gauss_legendre;
use crate::special_functions::{
    complete_elliptic_k, incomplete_elliptic_f, jacobi_elliptic, EllipticError,
};

/// Why an analytic solution cannot be built for these inputs.
#[derive(Debug, Clone, Copy, PartialEq, thiserror::Error)]
pub enum AnalyticError {
    /// The principal moments (kg·m²) are not finite and positive, or not in the order the solution needs.
    #[error("principal moments {moments:?} must be finite, positive and {requirement}")]
    InertiaOrder {
        /// The principal moments J̄₁, J̄₂, J̄₃ given (kg·m²).
        moments: Vector,
        /// The order the solution needs (e.g. J̄₁ < J̄₂ < J̄₃).
        requirement: &'static str,
    },
    /// The initial state gives a motion without a regular periodic solution.
    #[error("degenerate motion (steady rotation about a principal axis or the separatrix M² = 2EJ₂): {reason}")]
    Degenerate {
        /// Which degenerate case was met.
        reason: &'static str,
    },
    /// An elliptic function could not be evaluated.
    #[error(transparent)]
    Elliptic(#[from] EllipticError),
}

/// The torque-free symmetric top J̄₁ = J̄₂ (closed form).
#[derive(Debug, Clone, Copy)]
pub struct SymmetricTop {
    inertia: Vector,
    omega_body0: Vector,
    orientation0: Rotation,
    /// Body-frame precession rate Ω = ω̄₃ (J̄₃ − J̄₁)/J̄₁ (rad/s).
    pub body_precession_rate: Real,
    /// World angular momentum (constant).
    pub angular_momentum: Vector,
}

impl SymmetricTop {
    /// `inertia` must have J̄₁ = J̄₂ (to 1e-12 relative).
    pub fn new(
        inertia: Vector,
        omega_body0: Vector,
        orientation0: Rotation,
    ) -> Result<Self, AnalyticError> {
        let valid = inertia.iter().all(|j| j.is_finite() && *j > 0.0)
            && (inertia[0] - inertia[1]).abs() <= 1e-12 * inertia[0];
        if !valid {
            return Err(AnalyticError::InertiaOrder {
                moments: inertia,
                requirement: "J1 = J2 for a symmetric top",
            });
        }
        Ok(Self {
            inertia,
            omega_body0,
            orientation0,
            body_precession_rate: omega_body0[2] * (inertia[2] - inertia[0]) / inertia[0],
            angular_momentum: orientation0.transform_vector(&omega_body0.component_mul(&inertia)),
        })
    }

    /// Body-frame angular velocity ω̄(t).
    pub fn omega_body(&self, t: Real) -> Vector {
        let (s, c) = (self.body_precession_rate * t).sin_cos();
        let w = self.omega_body0;
        Vector::new(c * w[0] - s * w[1], s * w[0] + c * w[1], w[2])
    }

    /// Orientation q(t) = exp(L̂ |L| t/J̄₁) ⊗ q₀ ⊗ exp(−Ω t e₃).
    pub fn orientation(&self, t: Real) -> Rotation {
        let space = Rotation::from_scaled_axis(self.angular_momentum * (t / self.inertia[0]));
        let body =
            Rotation::from_scaled_axis(Vector::new(0.0, 0.0, -self.body_precession_rate * t));
        space * self.orientation0 * body
    }
}

/// Which axis the asymmetric top's angular momentum circulates about in the body.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Regime {
    /// M² > 2EJ̄₂: L̄ circulates about body axis 3.
    AboutAxis3,
    /// M² < 2EJ̄₂: L̄ circulates about body axis 1.
    AboutAxis1,
}

/// The torque-free asymmetric top J̄₁ < J̄₂ < J̄₃ (Jacobi elliptic functions).
#[derive(Debug, Clone, Copy)]
pub struct AsymmetricTop {
    inertia: Vector,
    /// Which body axis the angular momentum circulates about.
    pub regime: Regime,
    amplitudes: Vector,
    sign: Real,
    /// Frequency λ (1/s) of the elliptic argument τ = λ t + τ₀.
    pub frequency: Real,
    /// Elliptic parameter m.
    pub parameter: Real,
    phase: Real,
    /// |L| (kg·m²/s).
    pub angular_momentum_norm: Real,
    /// Kinetic energy E (J).
    pub energy: Real,
    /// Constant rotation from the "L along z" frame to the world.
    frame: Rotation,
}

/// One regime's solution of Euler's equations: ω̄ = (a₁ cn, s a₂ sn, s a₃ dn) about axis 3, or
/// (s a₁ dn, s a₂ sn, a₃ cn) about axis 1, of τ = λ t + τ₀ with parameter m; `phase_sn`, `phase_cn` give
/// the initial amplitude of τ₀.
struct Circulation {
    regime: Regime,
    amplitudes: Vector,
    frequency: Real,
    parameter: Real,
    sign: Real,
    phase_sn: Real,
    phase_cn: Real,
}

impl Circulation {
    /// The regime of moments J̄₁ < J̄₂ < J̄₃ and initial body-frame ω̄₀, from 2EJ₃ − M² (`upper`),
    /// M² − 2EJ₁ (`lower`) and whether M² > 2EJ₂ (`about_axis3`).
    fn of(inertia: Vector, omega0: Vector, upper: Real, lower: Real, about_axis3: bool) -> Self {
        let (j1, j2, j3) = (inertia[0], inertia[1], inertia[2]);
        if about_axis3 {
            let a = Vector::new(
                (upper / (j1 * (j3 - j1))).sqrt(),
                (upper / (j2 * (j3 - j2))).sqrt(),
                (lower / (j3 * (j3 - j1))).sqrt(),
            );
            let s = omega0[2].signum();
            Self {
                regime: Regime::AboutAxis3,
                amplitudes: a,
                frequency: ((j3 - j2) * lower / (j1 * j2 * j3)).sqrt(),
                parameter: (j2 - j1) * upper / ((j3 - j2) * lower),
                sign: s,
                phase_sn: s * omega0[1] / a[1],
                phase_cn: omega0[0] / a[0],
            }
        } else {
            let a = Vector::new(
                (upper / (j1 * (j3 - j1))).sqrt(),
                (lower / (j2 * (j2 - j1))).sqrt(),
                (lower / (j3 * (j3 - j1))).sqrt(),
            );
            let s = omega0[0].signum();
            Self {
                regime: Regime::AboutAxis1,
                amplitudes: a,
                frequency: ((j2 - j1) * upper / (j1 * j2 * j3)).sqrt(),
                parameter: (j3 - j2) * lower / ((j2 - j1) * upper),
                sign: s,
                phase_sn: s * omega0[1] / a[1],
                phase_cn: omega0[2] / a[2],
            }
        }
    }
}

impl AsymmetricTop {
    /// The motion from the principal moments `inertia` (kg·m², ordered J̄₁ < J̄₂ < J̄₃), the initial body-frame
    /// angular velocity `omega_body0` (rad/s) and the initial orientation `orientation0` (body to world).
    ///
    /// Errors: [`AnalyticError::InertiaOrder`] if the moments are not strictly increasing, finite and
    /// positive; [`AnalyticError::Degenerate`] on a steady rotation about a principal axis or on the separatrix.
    pub fn new(
        inertia: Vector,
        omega_body0: Vector,
        orientation0: Rotation,
    ) -> Result<Self, AnalyticError> {
        let (j1, j2, j3) = (inertia[0], inertia[1], inertia[2]);
        if !(inertia.iter().all(|j| j.is_finite()) && 0.0 < j1 && j1 < j2 && j2 < j3) {
            return Err(AnalyticError::InertiaOrder {
                moments: inertia,
                requirement: "strictly increasing (J1 < J2 < J3)",
            });
        }
        let l_body = omega_body0.component_mul(&inertia);
        let m2 = l_body.norm_squared();
        let two_e = omega_body0.dot(&l_body);
        let upper = two_e * j3 - m2; // 2EJ₃ − M² ≥ 0
        let lower = m2 - two_e * j1; // M² − 2EJ₁ ≥ 0
        let scale = m2.max(Real::MIN_POSITIVE);
        if upper <= 1e-14 * scale || lower <= 1e-14 * scale {
            return Err(AnalyticError::Degenerate {
                reason: "steady rotation about axis 1 or axis 3",
            });
        }
        let separatrix = m2 - two_e * j2;
        if separatrix.abs() <= 1e-14 * scale {
            return Err(AnalyticError::Degenerate {
                reason: "on the separatrix M² = 2EJ₂",
            });
        }
        let Circulation {
            regime,
            amplitudes,
            frequency,
            parameter,
            sign,
            phase_sn,
            phase_cn,
        } = Circulation::of(inertia, omega_body0, upper, lower, separatrix > 0.0);
        let amplitude0 = phase_sn.atan2(phase_cn);
        let phase = incomplete_elliptic_f(amplitude0, parameter)?;
        let mut top = Self {
            inertia,
            regime,
            amplitudes,
            sign,
            frequency,
            parameter,
            phase,
            angular_momentum_norm: m2.sqrt(),
            energy: 0.5 * two_e,
            frame: Rotation::identity(),
        };
        // frame ⊗ R_L(0) = q₀, with R_L(t) the body → L-frame rotation (ψ(0) = 0).
        top.frame = orientation0 * top.orientation_in_momentum_frame(0.0, 0.0).inverse();
        Ok(top)
    }

    /// Body-frame angular velocity ω̄(t).
    pub fn omega_body(&self, t: Real) -> Vector {
        // The parameter was validated in `new`, so the elliptic functions cannot fail here.
        let f = jacobi_elliptic(self.frequency * t + self.phase, self.parameter)
            .expect("parameter validated at construction");
        let (a, s) = (self.amplitudes, self.sign);
        match self.regime {
            Regime::AboutAxis3 => Vector::new(a[0] * f.cn, s * a[1] * f.sn, s * a[2] * f.dn),
            Regime::AboutAxis1 => Vector::new(s * a[0] * f.dn, s * a[1] * f.sn, a[2] * f.cn),
        }
    }

    /// Period of ω̄(t), 4K(m)/λ (s): the full Dzhanibekov flip cycle near the intermediate axis.
    pub fn period(&self) -> Real {
        4.0 * complete_elliptic_k(self.parameter).expect("parameter validated at construction")
            / self.frequency
    }

    /// ψ̇ = M (J̄₁ω̄₁² + J̄₂ω̄₂²)/(J̄₁²ω̄₁² + J̄₂²ω̄₂²) (rad/s).
    fn precession_rate(&self, t: Real) -> Real {
        let w = self.omega_body(t);
        let (j1, j2) = (self.inertia[0], self.inertia[1]);
        let (a, b) = (w[0] * w[0], w[1] * w[1]);
        self.angular_momentum_norm * (j1 * a + j2 * b) / (j1 * j1 * a + j2 * j2 * b)
    }

    /// The precession angle ψ(t) = ∫₀ᵗ ψ̇ dt, composite 8-point Gauss–Legendre with panels ≤ period/64.
    pub fn precession_angle(&self, t: Real) -> Real {
        let panels = ((t.abs() / (self.period() / 64.0)).ceil() as usize).max(1);
        let h = t / panels as Real;
        let (nodes, weights) = gauss_legendre(8);
        let mut sum = 0.0;
        for p in 0..panels {
            let mid = (p as Real + 0.5) * h;
            for (x, w) in nodes.iter().zip(weights.iter()) {
                sum += 0.5 * h * w * self.precession_rate(mid + 0.5 * h * x);
            }
        }
        sum
    }

    /// Body → L-frame rotation Rz(ψ) Rx(θ) Rz(φ) at time t for a given ψ.
    fn orientation_in_momentum_frame(&self, t: Real, psi: Real) -> Rotation {
        let l = self.omega_body(t).component_mul(&self.inertia);
        let theta = (l[2] / self.angular_momentum_norm).clamp(-1.0, 1.0).acos();
        let phi = l[0].atan2(l[1]);
        Rotation::from_axis_angle(&Vector::z_axis(), psi)
            * Rotation::from_axis_angle(&Vector::x_axis(), theta)
            * Rotation::from_axis_angle(&Vector::z_axis(), phi)
    }

    /// Orientation q(t) (body → world).
    pub fn orientation(&self, t: Real) -> Rotation {
        self.frame * self.orientation_in_momentum_frame(t, self.precession_angle(t))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn euler_residual(inertia: &Vector, omega: impl Fn(Real) -> Vector, t: Real) -> Real {
        // J̄ ω̄' + ω̄ × J̄ω̄ = 0, ω̄' by a central difference (error ~h²).
        let h = 1e-5;
        let derivative = (omega(t + h) - omega(t - h)) / (2.0 * h);
        let w = omega(t);
        let residual = derivative.component_mul(inertia) + w.cross(&w.component_mul(inertia));
        residual.norm() / (w.component_mul(inertia).norm() * w.norm())
    }

    #[test]
    fn asymmetric_solution_satisfies_euler_equations() {
        let inertia = Vector::new(1.0, 2.0, 3.0);
        let q0 = Rotation::from_scaled_axis(Vector::new(0.1, 0.2, 0.3));
        for omega0 in [
            Vector::new(0.3, 0.5, 1.2),
            Vector::new(0.3, -0.5, -1.2),
            Vector::new(1.5, 0.4, 0.3),
            Vector::new(-1.5, 0.4, -0.3),
            Vector::new(0.01, 1.0, 0.02),
            Vector::new(-0.02, -1.0, 0.01),
        ] {
            let top = AsymmetricTop::new(inertia, omega0, q0).unwrap();
            let start = top.omega_body(0.0);
            assert!(
                (start - omega0).norm() < 1e-12 * omega0.norm(),
                "ω̄(0) = {start:?}, initial {omega0:?} ({:?})",
                top.regime
            );
            for t in [0.3, 1.7, 5.0, 13.0] {
                let r = euler_residual(&inertia, |s| top.omega_body(s), t);
                assert!(
                    r < 1e-8,
                    "ω̄0 = {omega0:?}, t = {t}: relative Euler residual {r:e}, tolerance 1e-8"
                );
                let w = top.omega_body(t);
                let energy = 0.5 * w.dot(&w.component_mul(&inertia));
                assert!(
                    (energy - top.energy).abs() < 1e-13 * top.energy,
                    "energy {energy} vs {} at t = {t}",
                    top.energy
                );
            }
        }
    }

    #[test]
    fn asymmetric_orientation_is_consistent_with_angular_velocity() {
        // dq/dt = ½ q ⊗ ω̄ and R(q) J̄ω̄ = L (constant) along the analytic orientation.
        let inertia = Vector::new(1.0, 2.0, 3.0);
        let q0 = Rotation::from_scaled_axis(Vector::new(-0.4, 0.2, 0.9));
        for omega0 in [Vector::new(0.3, 0.5, 1.2), Vector::new(1.5, 0.4, -0.3)] {
            let top = AsymmetricTop::new(inertia, omega0, q0).unwrap();
            let l0 = q0.transform_vector(&omega0.component_mul(&inertia));
            assert!(top.orientation(0.0).angle_to(&q0) < 1e-14);
            for t in [0.5, 2.5, 7.0] {
                let q = top.orientation(t);
                let l = q.transform_vector(&top.omega_body(t).component_mul(&inertia));
                assert!(
                    (l - l0).norm() < 1e-12 * l0.norm(),
                    "t = {t}: L = {l:?}, L₀ = {l0:?}"
                );
                let h = 1e-5;
                let relative = top.orientation(t).inverse() * top.orientation(t + h);
                let backward = top.orientation(t).inverse() * top.orientation(t - h);
                let omega_fd = (relative.scaled_axis() - backward.scaled_axis()) / (2.0 * h);
                let omega = top.omega_body(t);
                assert!(
                    (omega_fd - omega).norm() < 1e-8 * omega.norm(),
                    "t = {t}: ω̄ from dq/dt = {omega_fd:?}, analytic {omega:?}"
                );
            }
        }
    }

    #[test]
    fn symmetric_top_satisfies_euler_equations_and_kinematics() {
        let inertia = Vector::new(2.0, 2.0, 0.7);
        let q0 = Rotation::from_scaled_axis(Vector::new(0.5, -0.3, 0.2));
        let omega0 = Vector::new(0.8, -0.2, 3.0);
        let top = SymmetricTop::new(inertia, omega0, q0).unwrap();
        for t in [0.0, 0.9, 4.0] {
            let r = euler_residual(&inertia, |s| top.omega_body(s), t);
            assert!(r < 1e-8, "t = {t}: relative Euler residual {r:e}");
            let q = top.orientation(t);
            let l = q.transform_vector(&top.omega_body(t).component_mul(&inertia));
            assert!(
                (l - top.angular_momentum).norm() < 1e-13 * l.norm(),
                "t = {t}: L = {l:?}, expected {:?}",
                top.angular_momentum
            );
            let h = 1e-5;
            let fd = ((q.inverse() * top.orientation(t + h)).scaled_axis()
                - (q.inverse() * top.orientation(t - h)).scaled_axis())
                / (2.0 * h);
            assert!(
                (fd - top.omega_body(t)).norm() < 1e-8 * omega0.norm(),
                "t = {t}: ω̄ fd {fd:?}"
            );
        }
    }

    #[test]
    fn invalid_inputs_are_refused() {
        let q = Rotation::identity();
        assert!(
            AsymmetricTop::new(Vector::new(2.0, 1.0, 3.0), Vector::new(1.0, 1.0, 1.0), q).is_err()
        );
        assert!(
            AsymmetricTop::new(Vector::new(1.0, 2.0, 3.0), Vector::new(0.0, 0.0, 1.0), q).is_err()
        );
        assert!(
            SymmetricTop::new(Vector::new(1.0, 2.0, 3.0), Vector::new(1.0, 1.0, 1.0), q).is_err()
        );
    }
}
