//! The overlap a wall contact hands to the law: a smoothed maximum of the vertex depths that makes a face or
//! an edge landing flat on a wall energy-consistent.
//!
//! # Why the deepest vertex is not enough
//! The exact overlap of a polyhedron with a plane is δ = max_i d_i, d_i the depth of vertex i below the
//! plane. A force k δ^n applied at the deepest vertex is the gradient of U = k δ^(n+1)/(n+1), but δ has a
//! kink wherever two vertices are equally deep: when an edge or a face lands (nearly) flat and rocks, the
//! force point jumps from one end to the other, the force on the body is discontinuous in its pose, and
//! velocity Verlet loses its second order (measured: 2.5e-3 of the energy at Δt = t_c/200, first order).
//! The paper defines its law for two polyhedra only (eqs. 2–5); for a wall we are free to choose the
//! scalar the law sees, provided the law stays a potential force.
//!
//! # The smoothed depth
//! For a band h > 0 let S_h(d) be the smooth maximum defined implicitly by
//!
//! ```text
//! Σ_i ψ((d_i − S_h)/h) = 1,   ψ(x) = max(0, 1 + x)^q,   q = 3
//! ```
//!
//! S_h is translation-equivariant (S_h(d + c) = S_h(d) + c), equals max_i d_i when every other vertex lies
//! more than h below the deepest one, is C^(q−1) = C² in d (implicit function theorem: Σ ψ' > 0), and its
//! gradient w_i = ∂S_h/∂d_i = ψ'_i / Σ_j ψ'_j is a set of non-negative weights summing to 1. But S_h ≥ max:
//! at a tie of m vertices it exceeds the true depth by h (1 − m^(−1/q)), so a law acting on S_h would
//! push before the shapes touch, and cutting it off at the geometric contact would make the force jump at
//! the onset — the first-order error again. Any smooth, translation-equivariant D that never exceeds the
//! true depth (so that D > 0 implies a true overlap and the contact status stays the exact geometric one)
//! must give some vertex a negative weight: for two vertices, D = d₁ + g(d₂ − d₁) with g(s) − g(−s) = s,
//! g ≤ max(0, s) and g = max(0, s) for |s| ≥ h; weights in [0, 1] mean |g' − ½| ≤ ½, which with
//! g(h) = h forces g(s) ≥ s on [0, h], hence g = max(0, s), the kink. We therefore use the Richardson
//! combination of two bands,
//!
//! ```text
//! D = 2 S_h − S_2h
//! ```
//!
//! which writes D − max = 2h [e(g/h) − e(g/2h)] with g the gaps below the deepest vertex and e ≥ 0 the
//! (decreasing) excess of the smooth maximum, so:
//! - D ≤ max_i d_i everywhere (the law never acts on separated shapes), D = max_i d_i when the next vertex
//!   lies 2h or more below the deepest one (the paper's single-point law) and also at exact ties (a face
//!   resting flat feels k δ^n at its centroid, as before);
//! - in between D falls short of the true depth by at most 0.133 h for two vertices (0.22 h for a square face
//!   tilted about a diagonal; q = 3, see the tests);
//! - D is C² and translation-equivariant: Σ_i ∂D/∂d_i = 2 − 1 = 1, so the total normal force is exactly
//!   k D^n and the force is the gradient of U = k D^(n+1)/(n+1), applied at the weighted mean of the
//!   vertices c = Σ_i w_i x_i, w_i = 2 ∂S_h/∂d_i − ∂S_2h/∂d_i (a normal force has the same torque at any
//!   point of its line, so c is projected onto the level of the overlap). The weights may be negative
//!   (down to −0.20 for two vertices), so c may lie outside the contact face while a flat face tilts by
//!   about h/L; it is back at the deepest vertex once the tilt exceeds 2h/L.
//!
//! # The band
//! h = `band` × the polyhedron's length scale L (bounding diameter). The smoothing replaces the kink by a
//! rocking stiffness of order F L²/h (F the normal force), so h sets how stiffly a face resists tilting:
//! - h far below the overlaps of the scene makes rocking much stiffer than the normal contact, and a time
//!   step derived from t_c resolves it poorly: energy error at t_c/200 of a face landing flat, 3.9e-5 with
//!   h = its peak overlap, 1.9e-4 with h = 0.1 × the peak overlap (still second order);
//! - h far above them makes a resting face soft in rocking, and a face rocking about its centroid barely
//!   changes D, so the normal dashpot hardly damps it: a cube on an incline at tan θ = 0.9 μ (static
//!   overlap 2.9e-5 L) creeps 9× the sticking bound with h = 2e-3 L but sticks (0.6 of the bound) with
//!   h = its static overlap; in `scenes/settling_box.toml` (static overlaps ~1e-4 L) the slowest body
//!   after 1.5 s moves at 0.86, 1.1 and 1.3 of the at-rest threshold with h = 1e-4, 3e-4 and 1e-3 L
//!   (deepest-vertex law: 0.90).
//!
//! Rule: h ≈ the characteristic overlap of the scene (the static overlap under the load, or the peak
//! overlap of the impacts that matter). The default, 1e-4 L, is the static overlap of a gravity-loaded bed
//! (the settling box above; a few 1e-5–1e-4 L for the rockfill's rocks and stiffness); a scene with other
//! overlaps sets [`WallDepth::Smoothed`] through `ContactTolerances::wall_depth`. Measured sensitivity in
//! the `single_contact_energy` and `friction` reports.
//!
//! Cost: one pass over the vertices, then Newton on the few vertices within 2h of the deepest (none but
//! the deepest when one vertex clearly leads: then no iteration runs).

use crate::math::Real;

/// The largest band (a fraction of the particle size L) the scene accepts for this smoothing and for the
/// pair smoothing of [`super::pair_smoothing`]: 0.05.
///
/// The derivation above holds for h ≈ the characteristic overlap of the scene (its rule), and a sound DEM
/// scene has no overlap near 0.05 L: the step reports a contact that deep as a deep overlap
/// (`world::DEFAULT_OVERLAP_WARNING_FRACTION`), its stiffness or step being wrong for the scene. Beyond
/// that no overlap the rule could match exists, and what the band does instead is let the law's depth
/// fall short of the true one by up to 0.22 h — at h = L a body rests with most of its volume in the
/// wall, the law seeing a small overlap. At 0.05 the shortfall stays below 0.011 L, and a tilt of 2h/L
/// = 0.1 rad already returns a face to the exact deepest-vertex depth.
pub const MAX_BAND: Real = 0.05;

/// How the polyhedron–plane contact turns the vertex depths into the overlap the law sees.
#[derive(Copy, Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub enum WallDepth {
    /// The exact overlap max_i d_i at the deepest vertex (the centroid of vertices tied within 1e-12 L):
    /// the paper's single-point rule, with a kink where vertices tie (first-order energy error when a face
    /// or an edge rocks flat on the wall). Kept for comparison.
    DeepestVertex,
    /// The smoothed depth D = 2 S_h − S_2h of the module docs, with h = `band` × L.
    Smoothed {
        /// Smoothing width as a fraction of the body's length scale L (dimensionless).
        band: Real,
    },
}

impl Default for WallDepth {
    /// `Smoothed { band: 1e-4 }` (see the module docs for the choice).
    fn default() -> Self {
        WallDepth::Smoothed { band: 1e-4 }
    }
}

/// Exponent q of ψ(x) = max(0, 1 + x)^q (q = 3: D is C²).
const Q: i32 = 3;

/// The smooth maximum S_h of `depths` (implicit equation of the module docs) and its gradient written into
/// `weights` (same length; non-negative, summing to 1). `deepest` is max_i d_i. Vertices more than h below
/// the deepest get weight 0.
pub fn smooth_max(depths: &[Real], deepest: Real, h: Real, weights: &mut [Real]) -> Real {
    debug_assert_eq!(depths.len(), weights.len());
    let psi = |x: Real| (1.0 + x).max(0.0).powi(Q);
    let dpsi = |x: Real| Q as Real * (1.0 + x).max(0.0).powi(Q - 1);
    // F(S) = Σ ψ((d_i − S)/h) − 1 is convex and decreasing in S with F(deepest) ≥ 0: Newton from the
    // deepest depth climbs monotonically to the root without overshooting.
    let mut s = deepest;
    for _ in 0..64 {
        let (mut f, mut df) = (-1.0, 0.0);
        for &d in depths {
            let x = (d - s) / h;
            f += psi(x);
            df += dpsi(x);
        }
        // df ≥ q > 0: the deepest vertex has x ≥ −(1 − m^(−1/q)) > −1 along the iteration.
        let step = h * f / df;
        s += step;
        if step <= 1e-15 * h {
            break;
        }
    }
    let mut total = 0.0;
    for (w, &d) in weights.iter_mut().zip(depths) {
        *w = dpsi((d - s) / h);
        total += *w;
    }
    for w in weights.iter_mut() {
        *w /= total;
    }
    s
}

/// The smoothed depth D = 2 S_h − S_2h of `depths` and its gradient ∂D/∂d_i in `weights` (summing to 1,
/// possibly negative). `scratch` has the length of `depths`.
pub fn smoothed_depth(
    depths: &[Real],
    h: Real,
    weights: &mut [Real],
    scratch: &mut [Real],
) -> Real {
    let deepest = depths.iter().copied().fold(Real::NEG_INFINITY, Real::max);
    let fine = smooth_max(depths, deepest, h, weights);
    let coarse = smooth_max(depths, deepest, 2.0 * h, scratch);
    for (w, c) in weights.iter_mut().zip(scratch.iter()) {
        *w = 2.0 * *w - c;
    }
    // Rounding may leave D a few ulps above the deepest depth at exact ties; the bound D ≤ max is exact.
    (2.0 * fine - coarse).min(deepest)
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};

    fn depth(d: &[Real], h: Real) -> (Real, Vec<Real>) {
        let mut w = vec![0.0; d.len()];
        let mut s = vec![0.0; d.len()];
        (smoothed_depth(d, h, &mut w, &mut s), w)
    }

    /// D never exceeds the deepest depth, equals it at exact ties and when the next vertex is 2h below,
    /// and falls short by at most 0.134 h for two vertices; the weights sum to 1 and stay above −0.201 (bounds
    /// computed independently by a scan of the two-vertex case).
    #[test]
    fn smoothed_depth_is_bounded_by_the_true_depth() {
        let h = 1e-3;
        for m in 1..=8 {
            let d = vec![0.5e-3; m];
            let (dd, w) = depth(&d, h);
            assert!((dd - 0.5e-3).abs() <= 1e-15, "tie of {m}: D = {dd}");
            for wi in &w {
                assert!(
                    (wi - 1.0 / m as Real).abs() < 1e-12,
                    "tie of {m}: weights {w:?}"
                );
            }
        }
        let (mut short, mut lowest): (Real, Real) = (0.0, 1.0);
        for k in 0..=400 {
            let s = 2.5 * h * k as Real / 400.0;
            let (dd, w) = depth(&[0.0, -s], h);
            assert!(dd <= 0.0, "gap {s}: D = {dd} above the deepest depth 0");
            if s >= 2.0 * h {
                assert_eq!(dd, 0.0, "gap {s} ≥ 2h: D = {dd}");
                assert_eq!(w, vec![1.0, 0.0], "gap {s} ≥ 2h: weights {w:?}");
            }
            assert!((w[0] + w[1] - 1.0).abs() < 1e-14, "weights {w:?}");
            short = short.max(-dd / h);
            lowest = lowest.min(w[1]);
        }
        assert!(short < 0.134, "largest shortfall {short} h, bound 0.134 h");
        assert!(lowest > -0.201, "lowest weight {lowest}, bound −0.201");
    }

    /// The weights are the gradient of D (central differences on random depth sets, several vertices in
    /// the band), and D is translation-equivariant.
    #[test]
    fn weights_are_the_gradient_of_the_smoothed_depth() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(3);
        let h = 1.0;
        for _ in 0..300 {
            let m = rng.random_range(1..7);
            let d: Vec<Real> = (0..m).map(|_| rng.random_range(-2.5..0.0)).collect();
            let (dd, w) = depth(&d, h);
            let shift = rng.random_range(-3.0..3.0);
            let moved: Vec<Real> = d.iter().map(|x| x + shift).collect();
            let (dm, _) = depth(&moved, h);
            assert!(
                (dm - dd - shift).abs() < 1e-12,
                "equivariance: {dm} vs {dd} + {shift}"
            );
            for i in 0..m {
                let e = 1e-6;
                let mut up = d.clone();
                up[i] += e;
                let mut down = d.clone();
                down[i] -= e;
                let fd = (depth(&up, h).0 - depth(&down, h).0) / (2.0 * e);
                assert!(
                    (fd - w[i]).abs() < 1e-7,
                    "depths {d:?}: ∂D/∂d_{i} by differences {fd}, weight {}",
                    w[i]
                );
            }
        }
    }
}
