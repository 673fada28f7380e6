//! Placing B relative to A along a direction to reach a target overlap, touching, or a target gap.
//!
//! B starts with its reference point on A's (the two solids then overlap) and is translated by t·u along a
//! unit direction u. The signed gap g(t) (distance when separated, minus the Minkowski overlap when
//! overlapping) is convex in t wherever it is negative and increasing once the pair separates, so:
//! 1. the touching translation t₀ (g = 0) is found by bisection between 0 and the bounding-sphere distance;
//! 2. a target overlap δ by bisection on [0, t₀] (requires g(0) ≤ −δ; else the draw is rejected);
//! 3. a target gap d by doubling past t₀, then bisection.
//!
//! `coarse` (a fast peer query) drives the bisections; the achieved overlap or gap is then measured by the
//! exact oracle by the caller, so an occasional wrong coarse answer only moves the pair elsewhere on the
//! overlap axis. Touching pairs are refined by Newton steps on the exact oracle (`refine`), since a coarse
//! solver's absolute tolerances would otherwise leave a gap above the touching band for small particles.

use polydem::math::Vector;

/// What a pair is meant to show.
#[derive(Copy, Clone, Debug, PartialEq)]
pub enum Intent {
    /// Overlap δ (m).
    Overlap(f64),
    /// Boundaries touching.
    Touching,
    /// Gap d (m).
    Separated(f64),
}

impl Intent {
    pub fn name(&self) -> &'static str {
        match self {
            Intent::Overlap(_) => "overlap",
            Intent::Touching => "touching",
            Intent::Separated(_) => "separated",
        }
    }
}

/// Finds the translation t along `u` at which the pair realises `intent`. `gap(t, exact)` returns the signed
/// gap and the unit normal (A → B) at translation t, from the coarse solver (`exact == false`) or the exact
/// oracle (`exact == true`); `t_max` separates the bounding spheres. Returns `None` when the draw cannot
/// realise the intent (reject and redraw).
pub fn place(
    mut gap: impl FnMut(f64, bool) -> Option<(f64, Vector)>,
    u: &Vector,
    t_max: f64,
    intent: Intent,
) -> Option<f64> {
    let mut coarse = |t: f64| gap(t, false);
    let g0 = coarse(0.0)?.0;
    if g0 >= 0.0 || coarse(t_max)?.0 <= 0.0 {
        return None;
    }
    let bisect = |f: &mut dyn FnMut(f64) -> Option<(f64, Vector)>,
                  mut lo: f64,
                  mut hi: f64,
                  target: f64,
                  rel: f64| {
        for _ in 0..200 {
            let mid = 0.5 * (lo + hi);
            if mid <= lo || mid >= hi {
                break;
            }
            let g = f(mid)?.0;
            if rel > 0.0 && (g - target).abs() <= rel * target.abs() {
                return Some(mid);
            }
            if g < target {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        Some(0.5 * (lo + hi))
    };
    let t0 = bisect(&mut coarse, 0.0, t_max, 0.0, 0.0)?;
    match intent {
        Intent::Touching => {
            let mut t = t0;
            for _ in 0..6 {
                let (g, n) = gap(t, true)?;
                let slope = n.dot(u);
                if g == 0.0 || slope < 0.05 {
                    break;
                }
                t -= g / slope;
            }
            Some(t)
        }
        Intent::Overlap(delta) => {
            if g0 > -delta {
                return None;
            }
            bisect(&mut coarse, 0.0, t0, -delta, 1e-3)
        }
        Intent::Separated(d) => {
            let mut hi = t0 + d;
            let mut k = 0;
            while coarse(hi)?.0 < d {
                hi = t0 + 2.0 * (hi - t0);
                k += 1;
                if k > 60 {
                    return None;
                }
            }
            bisect(&mut coarse, t0, hi, d, 1e-3)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Two unit cubes (half-width 0.5), axis-aligned, B moved along x: g(t) = t − 1 exactly.
    #[test]
    fn places_cubes_at_the_intended_gap() {
        let gap = |t: f64, _exact: bool| Some((t - 1.0, Vector::x()));
        let u = Vector::x();
        let t = place(gap, &u, 3.0, Intent::Touching).unwrap();
        assert!((t - 1.0).abs() < 1e-15, "touching at t = {t}, expected 1");
        let t = place(gap, &u, 3.0, Intent::Overlap(0.25)).unwrap();
        assert!(
            (t - 0.75).abs() <= 0.25e-3,
            "overlap 0.25 at t = {t}, expected 0.75 ± 2.5e-4"
        );
        let t = place(gap, &u, 3.0, Intent::Separated(1e-6)).unwrap();
        assert!(
            (t - 1.0 - 1e-6).abs() <= 1e-9,
            "gap 1e-6 at t = {t}, expected 1 + 1e-6 ± 1e-9"
        );
        assert!(
            place(gap, &u, 3.0, Intent::Overlap(1.5)).is_none(),
            "overlap deeper than g(0) must be rejected"
        );
    }
}
