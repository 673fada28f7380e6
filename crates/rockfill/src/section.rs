//! Section pictures like the paper's Fig. 7: the layer cut by a plane x = const (the ZY plane), at several
//! instants of the penetration run.
//!
//! Every polyhedron the plane cuts is drawn as its section polygon — the points where its edges cross the
//! plane, ordered by angle around their centroid (the section of a convex body is convex) — coloured by the
//! rock's displacement since the start of the run, in mean rock sizes (dark blue 0, yellow at
//! [`SectionPicture::displacement_scale`] and above). The projectile's section is outlined in red; when it
//! does not reach the plane, its outline projected onto the plane is drawn dashed (thin) instead.
//! The picture is an SVG written with plotters.

use std::path::Path;

use plotters::prelude::*;

use super::penetration::Snapshot;
use polydem::math::{Point, Pose, Real};
use polydem::shape::Shape;
use polydem::world::World;

/// Why a picture could not be drawn.
#[derive(Debug, thiserror::Error)]
pub enum SectionError {
    #[error("section picture {path}: {message}")]
    Draw { path: String, message: String },
    #[error("section picture: {0}")]
    Input(String),
}

/// What to draw.
#[derive(Clone, Debug)]
pub struct SectionPicture<'a> {
    /// The plane x = `plane_x` (m).
    pub plane_x: Real,
    /// Extent of the picture: y ∈ [0, width], z ∈ [0, height] (m).
    pub width: Real,
    pub height: Real,
    /// Mean rock size (m): the unit of the colour scale.
    pub mean_size: Real,
    /// Displacement (in mean sizes) at which the colour saturates.
    pub displacement_scale: Real,
    /// The projectile's body index.
    pub projectile: usize,
    pub title: &'a str,
}

/// The section polygon of the polyhedron of body `i` at `pose` by the plane x = `plane_x`, as (y, z) points
/// in order; empty when the plane misses it.
pub fn section_polygon(world: &World, i: usize, pose: &Pose, plane_x: Real) -> Vec<(Real, Real)> {
    let Shape::Polyhedron(p) = world.shape(i) else {
        return Vec::new();
    };
    let v: Vec<Point> = p.vertices().iter().map(|x| pose * x).collect();
    let mut points: Vec<(Real, Real)> = Vec::new();
    for &[a, b] in p.edges() {
        let (pa, pb) = (v[a as usize], v[b as usize]);
        let (da, db) = (pa.x - plane_x, pb.x - plane_x);
        if (da < 0.0) != (db < 0.0) {
            let s = da / (da - db);
            let q = pa + (pb - pa) * s;
            points.push((q.y, q.z));
        }
    }
    order_around_centroid(points)
}

/// The outline of body `i`'s polyhedron projected onto the ZY plane (its 2D convex hull).
fn projected_outline(world: &World, i: usize, pose: &Pose) -> Vec<(Real, Real)> {
    let Shape::Polyhedron(p) = world.shape(i) else {
        return Vec::new();
    };
    let mut pts: Vec<(Real, Real)> = p
        .vertices()
        .iter()
        .map(|x| {
            let q = pose * x;
            (q.y, q.z)
        })
        .collect();
    // Monotone chain convex hull.
    pts.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.total_cmp(&b.1)));
    let cross = |o: (Real, Real), a: (Real, Real), b: (Real, Real)| {
        (a.0 - o.0) * (b.1 - o.1) - (a.1 - o.1) * (b.0 - o.0)
    };
    let mut hull: Vec<(Real, Real)> = Vec::new();
    for pass in 0..2 {
        let start = hull.len();
        let iter: Box<dyn Iterator<Item = &(Real, Real)>> = if pass == 0 {
            Box::new(pts.iter())
        } else {
            Box::new(pts.iter().rev())
        };
        for &p in iter {
            while hull.len() >= start + 2
                && cross(hull[hull.len() - 2], hull[hull.len() - 1], p) <= 0.0
            {
                hull.pop();
            }
            hull.push(p);
        }
        hull.pop();
    }
    hull
}

fn order_around_centroid(mut points: Vec<(Real, Real)>) -> Vec<(Real, Real)> {
    if points.len() < 3 {
        return Vec::new();
    }
    let n = points.len() as Real;
    let cy = points.iter().map(|p| p.0).sum::<Real>() / n;
    let cz = points.iter().map(|p| p.1).sum::<Real>() / n;
    points.sort_by(|a, b| {
        (a.1 - cz)
            .atan2(a.0 - cy)
            .total_cmp(&(b.1 - cz).atan2(b.0 - cy))
    });
    points
}

/// A perceptually ordered colour scale (viridis anchors), `t` ∈ [0, 1].
fn colour(t: Real) -> RGBColor {
    const ANCHORS: [(u8, u8, u8); 5] = [
        (68, 1, 84),
        (59, 82, 139),
        (33, 145, 140),
        (94, 201, 98),
        (253, 231, 37),
    ];
    let t = t.clamp(0.0, 1.0) * (ANCHORS.len() - 1) as Real;
    let k = (t.floor() as usize).min(ANCHORS.len() - 2);
    let f = t - k as Real;
    let mix = |a: u8, b: u8| (a as Real + (b as Real - a as Real) * f).round() as u8;
    let (a, b) = (ANCHORS[k], ANCHORS[k + 1]);
    RGBColor(mix(a.0, b.0), mix(a.1, b.1), mix(a.2, b.2))
}

/// Draws one panel per snapshot (two columns) into `path`.
pub fn draw_sections(
    path: &Path,
    world: &World,
    start_positions: &[Point],
    snapshots: &[Snapshot],
    picture: &SectionPicture,
) -> Result<(), SectionError> {
    if snapshots.is_empty() {
        return Err(SectionError::Input("no snapshots".into()));
    }
    if start_positions.len() != world.bodies().len()
        || snapshots
            .iter()
            .any(|s| s.poses.len() != world.bodies().len())
    {
        return Err(SectionError::Input(format!(
            "{} bodies, {} start positions, snapshots of {:?} poses",
            world.bodies().len(),
            start_positions.len(),
            snapshots.iter().map(|s| s.poses.len()).collect::<Vec<_>>()
        )));
    }
    let err = |e: String| SectionError::Draw {
        path: path.display().to_string(),
        message: e,
    };
    let columns = 2usize;
    let rows = snapshots.len().div_ceil(columns);
    let panel = 460u32;
    let aspect = picture.height / picture.width;
    let panel_h = ((panel as Real - 60.0) * aspect + 70.0).round() as u32;
    let root = SVGBackend::new(path, (panel * columns as u32, panel_h * rows as u32 + 50))
        .into_drawing_area();
    root.fill(&WHITE).map_err(|e| err(e.to_string()))?;
    let (header, body) = root.split_vertically(50);
    header
        .draw(&Text::new(
            format!(
                "{} — section x = {:.2} m; colour: displacement 0 (dark) to ≥ {} mean sizes (yellow); red: projectile",
                picture.title, picture.plane_x, picture.displacement_scale
            ),
            (10, 18),
            ("sans-serif", 14).into_font(),
        ))
        .map_err(|e| err(e.to_string()))?;
    let panels = body.split_evenly((rows, columns));
    for (snap, area) in snapshots.iter().zip(panels.iter()) {
        let mut chart = ChartBuilder::on(area)
            .caption(
                format!("t = {:.2} ms, tip x = {:.2} m", snap.time * 1e3, snap.tip.x),
                ("sans-serif", 14),
            )
            .margin(8)
            .x_label_area_size(28)
            .y_label_area_size(36)
            .build_cartesian_2d(0.0..picture.width, 0.0..picture.height)
            .map_err(|e| err(e.to_string()))?;
        chart
            .configure_mesh()
            .disable_mesh()
            .x_desc("y (m)")
            .y_desc("z (m)")
            .draw()
            .map_err(|e| err(e.to_string()))?;
        for (i, pose) in snap.poses.iter().enumerate() {
            if i == picture.projectile {
                continue;
            }
            let poly = section_polygon(world, i, pose, picture.plane_x);
            if poly.is_empty() {
                continue;
            }
            let d = (Point::from(pose.translation.vector) - start_positions[i]).norm()
                / picture.mean_size;
            let fill = colour(d / picture.displacement_scale);
            chart
                .draw_series(std::iter::once(Polygon::new(poly.clone(), fill.filled())))
                .map_err(|e| err(e.to_string()))?;
            let mut closed = poly;
            closed.push(closed[0]);
            chart
                .draw_series(std::iter::once(PathElement::new(
                    closed,
                    BLACK.mix(0.5).stroke_width(1),
                )))
                .map_err(|e| err(e.to_string()))?;
        }
        let pose = &snap.poses[picture.projectile];
        let cut = section_polygon(world, picture.projectile, pose, picture.plane_x);
        let (outline, width) = if cut.is_empty() {
            (projected_outline(world, picture.projectile, pose), 1)
        } else {
            (cut, 3)
        };
        if !outline.is_empty() {
            let mut closed = outline;
            closed.push(closed[0]);
            chart
                .draw_series(std::iter::once(PathElement::new(
                    closed,
                    RED.stroke_width(width),
                )))
                .map_err(|e| err(e.to_string()))?;
        }
    }
    root.present().map_err(|e| err(e.to_string()))?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn colour_scale_ends() {
        assert_eq!(colour(0.0), RGBColor(68, 1, 84));
        assert_eq!(colour(1.0), RGBColor(253, 231, 37));
        assert_eq!(colour(7.0), RGBColor(253, 231, 37));
    }

    #[test]
    fn points_are_ordered_counter_clockwise() {
        let square = vec![(1.0, 1.0), (0.0, 0.0), (1.0, 0.0), (0.0, 1.0)];
        let ordered = order_around_centroid(square);
        let area: Real = (0..4)
            .map(|k| {
                let (a, b) = (ordered[k], ordered[(k + 1) % 4]);
                a.0 * b.1 - b.0 * a.1
            })
            .sum::<Real>()
            * 0.5;
        assert!((area - 1.0).abs() < 1e-15, "signed area {area}, expected 1");
    }
}
