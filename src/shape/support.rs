//! The support mapping, the only view of a convex shape that GJK and EPA need.

use crate::math::{Point, Vector};

/// A convex shape described by its support function h(d) = max over x in the shape of d·x.
///
/// `local_support` returns a point of the shape (in the shape's local frame) that attains the maximum along
/// `dir_local`; `dir_local` need not be normalised and is never zero. `hint` is a warm start: implementations
/// that hill-climb over vertex adjacency start from vertex `*hint` and leave the arg-max vertex index in it;
/// others ignore it. Any value of `hint` (even out of range) must be accepted.
pub trait SupportMap {
    /// A point of the shape (local frame, m) extreme along `dir_local`; `hint` is read and updated as in the trait docs.
    fn local_support(&self, dir_local: &Vector, hint: &mut u32) -> Point;
}
