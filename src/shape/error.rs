//! Errors of shape construction: every way a point cloud, a mesh or a shape parameter can be unusable.

use crate::math::Real;

/// Why a shape could not be built. Construction never panics on user input: it returns one of these.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum ShapeError {
    /// Fewer than four points (or vertices) were given; a solid needs at least four.
    #[error("too few points: {count} given, a convex polyhedron needs at least 4")]
    TooFewPoints {
        /// Number of points given.
        count: usize,
    },

    /// A coordinate is NaN or infinite.
    #[error("point {index} has a non-finite coordinate: [{x}, {y}, {z}]")]
    NonFinite {
        /// Index of the point.
        index: usize,
        /// Its x coordinate (m).
        x: Real,
        /// Its y coordinate (m).
        y: Real,
        /// Its z coordinate (m).
        z: Real,
    },

    /// All points coincide (within the tolerance).
    #[error("all points coincide (extent {extent:e})")]
    Coincident {
        /// Largest extent of the cloud (m).
        extent: Real,
    },

    /// The cloud's extent is outside the sizes whose mass properties f64 represents.
    #[error("extent {extent:e} is outside the sizes this hull builder handles, {min:e} to {max:e} (the mass properties scale as the fifth power of the size and must stay within f64's normal range); express the coordinates in another unit")]
    ExtentOutOfRange {
        /// Largest extent of the cloud (m).
        extent: Real,
        /// Smallest extent handled (m).
        min: Real,
        /// Largest extent handled (m).
        max: Real,
    },

    /// The cloud is too small for its distance from the origin: its coordinates' round-off blurs its shape.
    #[error("extent {extent:e} is too small for coordinates as large as {largest:e}: their round-off allowance there is {rounding:e} (64 ε × the largest coordinate), and a shape must be at least {min_extent:e} across (1000 times that); give the points relative to a nearby origin")]
    BelowRoundOff {
        /// Largest extent of the cloud (m).
        extent: Real,
        /// Largest coordinate magnitude (m).
        largest: Real,
        /// Round-off allowance at that magnitude (m).
        rounding: Real,
        /// Smallest extent accepted there (m).
        min_extent: Real,
    },

    /// All points lie on one line (within the tolerance relative to the cloud's extent).
    #[error("all points are collinear: largest distance from a line is {distance:e}, tolerance {tolerance:e}")]
    Collinear {
        /// Largest distance of a point from the line through the two farthest extreme points (m).
        distance: Real,
        /// The tolerance it was compared with (m).
        tolerance: Real,
    },

    /// All points lie in one plane (within the tolerance relative to the cloud's extent).
    #[error("all points are coplanar: largest distance from a plane is {distance:e}, tolerance {tolerance:e}")]
    Coplanar {
        /// Largest distance of a point from the plane through three of the points (m).
        distance: Real,
        /// The tolerance it was compared with (m).
        tolerance: Real,
    },

    /// The solid's volume is zero or negligible relative to its extent cubed.
    #[error("zero volume: volume {volume:e} is below the tolerance {tolerance:e}")]
    ZeroVolume {
        /// The volume found (m³).
        volume: Real,
        /// The tolerance it was compared with (m³).
        tolerance: Real,
    },

    /// The convex-hull library failed, or its output did not pass our checks.
    #[error("convex hull computation failed: {reason}")]
    HullFailed {
        /// What failed.
        reason: String,
    },

    /// A face references a vertex index that does not exist.
    #[error("face {face} references vertex {index}, but there are only {num_vertices} vertices")]
    IndexOutOfRange {
        /// Index of the face.
        face: usize,
        /// The vertex index it references.
        index: u32,
        /// Number of vertices given.
        num_vertices: usize,
    },

    /// A face has fewer than three vertices or repeats a vertex.
    #[error("face {face} is malformed: {reason}")]
    MalformedFace {
        /// Index of the face.
        face: usize,
        /// What is wrong with it.
        reason: String,
    },

    /// The faces do not close up into a consistently oriented 2-manifold surface.
    #[error("the faces do not form a closed, consistently oriented surface: {reason}")]
    NotClosed {
        /// Where the surface is open or inconsistent.
        reason: String,
    },

    /// A vertex is not used by any face.
    #[error("vertex {index} is not used by any face")]
    UnusedVertex {
        /// Index of the vertex.
        index: usize,
    },

    /// The faces are oriented clockwise seen from outside (the enclosed signed volume is negative).
    #[error("faces are oriented inward (signed volume {signed_volume:e}); list each face counter-clockwise seen from outside")]
    InwardOrientation {
        /// The signed volume enclosed by the faces as given (m³).
        signed_volume: Real,
    },

    /// A face's vertices do not lie in one plane.
    #[error("face {face} is not planar: vertex {vertex} is {distance:e} off its plane (tolerance {tolerance:e})")]
    NonPlanarFace {
        /// Index of the face.
        face: usize,
        /// Index of a vertex of the face that lies off its plane.
        vertex: u32,
        /// Its distance from the plane (m).
        distance: Real,
        /// The tolerance it was compared with (m).
        tolerance: Real,
    },

    /// The solid is not convex: a vertex lies outside the plane of a face.
    #[error("not convex: vertex {vertex} lies {distance:e} outside the plane of face {face} (tolerance {tolerance:e})")]
    NotConvex {
        /// Index of the face.
        face: usize,
        /// Index of the vertex outside its plane.
        vertex: u32,
        /// How far outside (m).
        distance: Real,
        /// The tolerance it was compared with (m).
        tolerance: Real,
    },

    /// A shape parameter (radius, normal) is out of its valid range.
    #[error("invalid parameter {name} = {value}: {reason}")]
    InvalidParameter {
        /// Name of the parameter.
        name: &'static str,
        /// The value given, as text.
        value: String,
        /// Why it is invalid.
        reason: &'static str,
    },
}
