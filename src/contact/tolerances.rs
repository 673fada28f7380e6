//! Tolerances of the contact queries, all relative to the pair's length scale.
//!
//! Every tolerance here is a dimensionless factor multiplied by the length scale `L` of the pair
//! ([`pair_length_scale`]: the length scale of the *smaller* body), so that a pair of 1 mm grains and a pair
//! of 1 km blocks are decided alike, and a pebble on a boulder is measured to the pebble's size. Iteration caps are counts. A harness may sweep [`ContactTolerances::epa_gap`] to draw a
//! work-precision curve; the defaults are what the engine uses.

use crate::math::Real;

/// Tolerances and caps of GJK, EPA and the classification of a pair (dimensionless, times `L`).
#[derive(Copy, Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct ContactTolerances {
    /// Touching band: a pair whose overlap or gap is at most `touching · L` is [`Touching`].
    /// Default 1e-11: far below the smallest overlap a DEM step produces (≳ 1e-9 L) and far above the
    /// round-off of coordinates of size `L` (≈ 1e-16 L), so exact face-on-face contacts built in floating
    /// point are classified as touching and not as a spurious overlap or gap.
    ///
    /// [`Touching`]: super::ContactKind::Touching
    pub touching: Real,
    /// GJK stops when the duality gap |v| − v̂·w (an upper bound of the distance error) is at most
    /// `gjk_gap · L`. Default 1e-13: on polytopes GJK terminates exactly, this only guards round-off.
    pub gjk_gap: Real,
    /// EPA stops when the support point along the normal of the closest face lies within `epa_gap · L` of
    /// that face's plane; the reported depth then exceeds the exact one by at most this much. Default 1e-13:
    /// on polytopes EPA reaches a facet of the Minkowski difference exactly, so the gap only absorbs round-off.
    pub epa_gap: Real,
    /// Pairs with a curved shape (the generic support-map arm, [`super::contact_support_map`]): GJK and EPA
    /// stop when their upper and lower bounds on the signed overlap agree within `curved_gap · ℓ`, with ℓ
    /// the length scale of the *smaller* body (a small grain on a large one is measured to its own size).
    /// On a curved surface neither terminates exactly: the bounds close like the square of the local facet
    /// size of EPA's polytope, about a factor 3 per refinement of the closest face. Default 1e-10: the depth
    /// error is then far below the smallest overlap a DEM step produces (≳ 1e-9 ℓ), and the normal, whose
    /// error grows like the square root of the depth's, is good to about 1e-5 rad.
    ///
    /// Not serialised (a checkpoint restores the default), so that checkpoints keep their format.
    #[serde(skip, default = "default_curved_gap")]
    pub curved_gap: Real,
    /// Iteration cap of GJK (default 128; polytope pairs converge in fewer than 30). Reaching it triggers the
    /// exact fallback.
    pub gjk_max_iterations: u32,
    /// Iteration cap of EPA (default 256; each iteration adds one vertex). Reaching it triggers the exact
    /// fallback.
    pub epa_max_iterations: u32,
    /// The overlap a polyhedron–wall contact hands to the law (default: the smoothed depth with a band of
    /// 1e-4 L; see [`super::wall_depth`]). Not a tolerance of the status, which is always exact.
    pub wall_depth: super::wall_depth::WallDepth,
    /// The overlap a polyhedron–polyhedron contact hands to the law through [`super::query_with`]
    /// (default: smoothed with a band of 1e-4 L; see [`super::pair_smoothing`]). The geometric queries
    /// (`query_polytopes_cached`, `query_polyhedra*`, the oracles) always answer the exact overlap.
    pub pair_smoothing: super::pair_smoothing::PairSmoothing,
}

impl Default for ContactTolerances {
    fn default() -> Self {
        Self {
            touching: 1e-11,
            gjk_gap: 1e-13,
            epa_gap: 1e-13,
            curved_gap: default_curved_gap(),
            gjk_max_iterations: 128,
            epa_max_iterations: 256,
            wall_depth: Default::default(),
            pair_smoothing: Default::default(),
        }
    }
}

fn default_curved_gap() -> Real {
    1e-10
}

/// The floor of [`pair_length_scale`] as a fraction of the larger body's length scale. Coordinates of the
/// larger body's size carry round-off of a few ε·L_max ≈ 1e-15 L_max; the touching band, `touching` times
/// the pair's scale, is kept at 1e-11 · 1e-4 = 1e-15 L_max or more, so that it never falls below the
/// round-off of the coordinates it is compared with. Only pairs of size ratio above 1e4 reach the floor.
pub const PAIR_SCALE_FLOOR: Real = 1e-4;

/// The length scale of a pair of bodies of length scales `la` and `lb` (m): the smaller one, since a pair's
/// force and energy error live at the scale of its smaller body (a tolerance taken from the larger body of a
/// pebble–boulder pair of size ratio 1e5 would be 1e-6 of the pebble), floored at [`PAIR_SCALE_FLOOR`] times
/// the larger one. Symmetric in its arguments; equal to either for a pair of equal sizes.
#[inline]
pub fn pair_length_scale(la: Real, lb: Real) -> Real {
    // Plain comparisons rather than f64::min/max (whose NaN rules cost instructions on the hot path);
    // length scales are finite and positive.
    let (small, large) = if la < lb { (la, lb) } else { (lb, la) };
    let floor = PAIR_SCALE_FLOOR * large;
    if small > floor {
        small
    } else {
        floor
    }
}
