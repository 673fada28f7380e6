//! Errors of shape construction: every way a point cloud, a mesh or a shape parameter can be unusable.

use crate::math::Real;

/// Why a shape could not be built. Construction never panics on user input: it returns one of these.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum ShapeError {
    /// Fewer than four points (or vertices) were given; a solid needs at least four.
    #[error("too few points: {count} given, a convex polyhedron needs at least 4")]
    TooFewPoints { count: usize },

    /// A coordinate is NaN or infinite.
    #[error("point {index} has a non-finite coordinate: [{x}, {y}, {z}]")]
    NonFinite {
        index: usize,
        x: Real,
        y: Real,
        z: Real,
    },

    /// All points coincide (within the tolerance).
    #[error("all points coincide (extent {extent:e})")]
    Coincident { extent: Real },

    /// The cloud's extent is outside the sizes whose mass properties f64 represents.
    #[error("extent {extent:e} is outside the sizes this hull builder handles, {min:e} to {max:e} (the mass properties scale as the fifth power of the size and must stay within f64's normal range); express the coordinates in another unit")]
    ExtentOutOfRange { extent: Real, min: Real, max: Real },

    /// The cloud is too small for its distance from the origin: its coordinates' round-off blurs its shape.
    #[error("extent {extent:e} is too small for coordinates as large as {largest:e}: their round-off allowance there is {rounding:e} (64 ε × the largest coordinate), and a shape must be at least {min_extent:e} across (1000 times that); give the points relative to a nearby origin")]
    BelowRoundOff {
        extent: Real,
        largest: Real,
        rounding: Real,
        min_extent: Real,
    },

    /// All points lie on one line (within the tolerance relative to the cloud's extent).
    #[error("all points are collinear: largest distance from a line is {distance:e}, tolerance {tolerance:e}")]
    Collinear { distance: Real, tolerance: Real },

    /// All points lie in one plane (within the tolerance relative to the cloud's extent).
    #[error("all points are coplanar: largest distance from a plane is {distance:e}, tolerance {tolerance:e}")]
    Coplanar { distance: Real, tolerance: Real },

    /// The solid's volume is zero or negligible relative to its extent cubed.
    #[error("zero volume: volume {volume:e} is below the tolerance {tolerance:e}")]
    ZeroVolume { volume: Real, tolerance: Real },

    /// The convex-hull library failed, or its output did not pass our checks.
    #[error("convex hull computation failed: {reason}")]
    HullFailed { reason: String },

    /// A face references a vertex index that does not exist.
    #[error("face {face} references vertex {index}, but there are only {num_vertices} vertices")]
    IndexOutOfRange {
        face: usize,
        index: u32,
        num_vertices: usize,
    },

    /// A face has fewer than three vertices or repeats a vertex.
    #[error("face {face} is malformed: {reason}")]
    MalformedFace { face: usize, reason: String },

    /// The faces do not close up into a consistently oriented 2-manifold surface.
    #[error("the faces do not form a closed, consistently oriented surface: {reason}")]
    NotClosed { reason: String },

    /// A vertex is not used by any face.
    #[error("vertex {index} is not used by any face")]
    UnusedVertex { index: usize },

    /// The faces are oriented clockwise seen from outside (the enclosed signed volume is negative).
    #[error("faces are oriented inward (signed volume {signed_volume:e}); list each face counter-clockwise seen from outside")]
    InwardOrientation { signed_volume: Real },

    /// A face's vertices do not lie in one plane.
    #[error("face {face} is not planar: vertex {vertex} is {distance:e} off its plane (tolerance {tolerance:e})")]
    NonPlanarFace {
        face: usize,
        vertex: u32,
        distance: Real,
        tolerance: Real,
    },

    /// The solid is not convex: a vertex lies outside the plane of a face.
    #[error("not convex: vertex {vertex} lies {distance:e} outside the plane of face {face} (tolerance {tolerance:e})")]
    NotConvex {
        face: usize,
        vertex: u32,
        distance: Real,
        tolerance: Real,
    },

    /// A shape parameter (radius, normal) is out of its valid range.
    #[error("invalid parameter {name} = {value}: {reason}")]
    InvalidParameter {
        name: &'static str,
        value: String,
        reason: &'static str,
    },
}
