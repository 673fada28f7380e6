//! Statistics of a generated sample: the realised size distribution and the shape statistics the issue asks
//! for (vertex and face counts, aspect ratios).
//!
//! Aspect ratios are given two ways, both in the rock's principal frame:
//! - `ellipsoid`: the ratio of the longest to the shortest semi-axis of the ellipsoid with the same volume
//!   and principal moments (for an ellipsoid of semi-axes a, b, c: J₁ = V(b² + c²)/5 per unit density, so
//!   a² = 5(J₂ + J₃ − J₁)/(2V));
//! - `box`: the ratio of the longest to the shortest edge of the principal-frame bounding box.

use super::grading::Rock;
use polydem::math::Real;

/// min / mean / max / standard deviation of a list of values.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Summary {
    pub count: usize,
    pub min: Real,
    pub mean: Real,
    pub max: Real,
    /// Sample standard deviation (n − 1).
    pub std: Real,
}

impl Summary {
    pub fn of(values: &[Real]) -> Self {
        let n = values.len();
        if n == 0 {
            return Self::default();
        }
        let mean = values.iter().sum::<Real>() / n as Real;
        let var = if n > 1 {
            values.iter().map(|v| (v - mean).powi(2)).sum::<Real>() / (n - 1) as Real
        } else {
            0.0
        };
        Self {
            count: n,
            min: values.iter().copied().fold(Real::INFINITY, Real::min),
            mean,
            max: values.iter().copied().fold(Real::NEG_INFINITY, Real::max),
            std: var.sqrt(),
        }
    }
}

impl std::fmt::Display for Summary {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "n {} min {:.4} mean {:.4} max {:.4} std {:.4}",
            self.count, self.min, self.mean, self.max, self.std
        )
    }
}

/// The statistics of a sample of rocks.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SampleStatistics {
    /// Volume-equivalent diameters (m).
    pub diameter: Summary,
    pub vertices: Summary,
    pub faces: Summary,
    pub aspect_ellipsoid: Summary,
    pub aspect_box: Summary,
    /// Σ rock volumes (m³).
    pub total_volume: Real,
}

/// Longest / shortest semi-axis of the equivalent-inertia ellipsoid of a rock.
pub fn ellipsoid_aspect_ratio(rock: &Rock) -> Real {
    let mp = rock.shape.mass_properties();
    let j = mp.principal_moments;
    let axes = [j[1] + j[2] - j[0], j[0] + j[2] - j[1], j[0] + j[1] - j[2]]
        .map(|s| (2.5 * s / mp.volume).max(0.0).sqrt());
    let max = axes.iter().copied().fold(0.0, Real::max);
    let min = axes.iter().copied().fold(Real::INFINITY, Real::min);
    max / min
}

/// Longest / shortest edge of the principal-frame bounding box of a rock.
pub fn box_aspect_ratio(rock: &Rock) -> Real {
    let aabb = rock.shape.aabb(&polydem::math::Pose::identity());
    let e = aabb.maxs - aabb.mins;
    e.max() / e.min()
}

/// Statistics of `rocks`.
pub fn sample_statistics(rocks: &[Rock]) -> SampleStatistics {
    let collect = |f: &dyn Fn(&Rock) -> Real| rocks.iter().map(f).collect::<Vec<Real>>();
    SampleStatistics {
        diameter: Summary::of(&collect(&|r| {
            super::grading::equivalent_diameter(r.shape.mass_properties().volume)
        })),
        vertices: Summary::of(&collect(&|r| r.shape.vertices().len() as Real)),
        faces: Summary::of(&collect(&|r| r.shape.num_faces() as Real)),
        aspect_ellipsoid: Summary::of(&collect(&ellipsoid_aspect_ratio)),
        aspect_box: Summary::of(&collect(&box_aspect_ratio)),
        total_volume: rocks.iter().map(|r| r.shape.mass_properties().volume).sum(),
    }
}

impl std::fmt::Display for SampleStatistics {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        writeln!(f, "size d_eq (m):        {}", self.diameter)?;
        writeln!(f, "vertices:             {}", self.vertices)?;
        writeln!(f, "faces:                {}", self.faces)?;
        writeln!(f, "aspect (ellipsoid):   {}", self.aspect_ellipsoid)?;
        write!(f, "aspect (box):         {}", self.aspect_box)
    }
}
