//! The support mapping of the Minkowski difference A ⊖ B = {a − b}, expressed in the frame of A.
//!
//! GJK and EPA see a pair of shapes only through this map. With `pos12` the pose of B relative to A, the
//! support of A ⊖ B along `d` (frame 1) is s_A(d) − pos12·s_B(−pos12⁻¹ d), and its support function is
//! h_A(d) + h_B(−d): the overlap of the pair along `d` (van den Bergen 2001, ch. 4). Each support point keeps
//! the two points it came from so that contact points can be read back as barycentric combinations.

use crate::math::{Matrix, Pose, Real, Vector};
use crate::shape::{SupportMap, VertexColumns};

/// A vertex of A ⊖ B with its parents: `w = a − b`, `a` on A and `b` on B, all in frame 1, and the
/// support hints the two maps left (vertex indices for polyhedra), so that the point can be rebuilt at
/// another pose.
#[derive(Copy, Clone, Debug, Default, PartialEq)]
pub struct SupportPoint {
    pub w: Vector,
    pub a: Vector,
    pub b: Vector,
    pub ia: u32,
    pub ib: u32,
}

/// A pair of support maps placed relative to each other, with warm-start hints for both.
pub struct MinkowskiPair<'s, A: ?Sized, B: ?Sized> {
    pub a: &'s A,
    pub b: &'s B,
    /// Rotation of B's frame into frame 1 (as a matrix: cheaper to apply many times).
    rot12: Matrix,
    /// Position of B's origin in frame 1.
    tra12: Vector,
    /// Warm-start hints of the two support maps (see [`SupportMap::local_support`]).
    pub hint_a: u32,
    pub hint_b: u32,
}

impl<'s, A: SupportMap + ?Sized, B: SupportMap + ?Sized> MinkowskiPair<'s, A, B> {
    /// The pair with B placed at `pos12` in A's frame.
    pub fn new(a: &'s A, b: &'s B, pos12: &Pose, hint_a: u32, hint_b: u32) -> Self {
        Self {
            a,
            b,
            rot12: pos12.rotation.to_rotation_matrix().into_inner(),
            tra12: pos12.translation.vector,
            hint_a,
            hint_b,
        }
    }

    /// Position of B's origin in frame 1.
    pub fn translation12(&self) -> Vector {
        self.tra12
    }

    /// Support point of A ⊖ B along `dir1` (frame 1, any length, not zero).
    #[inline]
    pub fn support(&mut self, dir1: &Vector) -> SupportPoint {
        let a = self.a.local_support(dir1, &mut self.hint_a).coords;
        let dir2 = -self.rot12.tr_mul(dir1);
        let b_local = self.b.local_support(&dir2, &mut self.hint_b).coords;
        let b = self.rot12 * b_local + self.tra12;
        SupportPoint {
            w: a - b,
            a,
            b,
            ia: self.hint_a,
            ib: self.hint_b,
        }
    }

    /// The support function h_A(n) + h_B(−n) of A ⊖ B along the unit vector `n` (frame 1): the overlap of
    /// the pair along `n` (negative when `n` separates them), with the support point attaining it.
    #[inline]
    pub fn overlap_along(&mut self, n: &Vector) -> (Real, SupportPoint) {
        let s = self.support(n);
        (n.dot(&s.a) - n.dot(&s.b), s)
    }
}

/// A polytope's vertex set seen as a support map by a full scan of its vertex columns (the caller's hint
/// is set to the arg-max index, the first vertex attaining the maximum). For the vertex counts of DEM
/// particles (≤ 64) a vectorised linear scan over contiguous columns beats hill-climbing and has no
/// data-dependent walk.
pub struct VertexScan<'s>(pub &'s VertexColumns);

impl SupportMap for VertexScan<'_> {
    #[inline(always)]
    fn local_support(&self, dir: &Vector, hint: &mut u32) -> crate::math::Point {
        let (i, p) = self.0.support_point(dir);
        *hint = i as u32;
        p
    }
}
