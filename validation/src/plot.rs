//! Plots of the report: a small description ([`Plot`]) rendered to SVG with plotters, and the CSV behind it.
//!
//! Rendering uses plotters' SVG backend without any font feature: text is written as SVG `<text>`
//! elements (sized by plotters' built-in estimate), so no system font or fontconfig is needed and the
//! output is byte-for-byte deterministic. Logarithmic axes are drawn by plotting log10 of the data on a
//! linear axis labelled with powers of ten; points that cannot be shown on a log axis (≤ 0) are counted in
//! the caption, never silently dropped.

use std::io::Write;
use std::path::Path;

use plotters::prelude::*;

use crate::error::SuiteError;

/// How a series is drawn.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum SeriesStyle {
    /// Markers only (scatter).
    Points,
    /// Markers joined by a line.
    LinePoints,
    /// A line without markers (CDFs, histories).
    Line,
    /// Large markers without a line, their shape (circle, triangle, square, cross) changing with the
    /// series' index as well as their colour: one marker per method in a comparison of many.
    Marker,
}

/// One named data series.
#[derive(Clone, Debug)]
pub struct Series {
    pub label: String,
    pub style: SeriesStyle,
    pub points: Vec<(f64, f64)>,
}

/// A plot: title, axis labels (with units), axis scales and series.
#[derive(Clone, Debug)]
pub struct Plot {
    /// File stem: `reports/<case>/<name>.svg` and `.csv`.
    pub name: String,
    pub title: String,
    pub x_label: String,
    pub y_label: String,
    pub x_log: bool,
    pub y_log: bool,
    pub series: Vec<Series>,
    /// Markdown text shown under the plot.
    pub caption: String,
}

const COLORS: [RGBColor; 8] = [
    RGBColor(31, 119, 180),
    RGBColor(214, 39, 40),
    RGBColor(44, 160, 44),
    RGBColor(255, 127, 14),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
    RGBColor(227, 119, 194),
    RGBColor(23, 190, 207),
];

fn transform(v: f64, log: bool) -> Option<f64> {
    if !v.is_finite() {
        return None;
    }
    if log {
        (v > 0.0).then(|| v.log10())
    } else {
        Some(v)
    }
}

fn axis_label(v: f64, log: bool) -> String {
    if log {
        let p = 10f64.powf(v);
        if (v - v.round()).abs() < 1e-9 {
            format!("1e{}", v.round() as i64)
        } else {
            format!("{p:.1e}")
        }
    } else if v != 0.0 && (v.abs() >= 1e4 || v.abs() < 1e-2) {
        format!("{v:.1e}")
    } else {
        format!("{}", (v * 1e6).round() / 1e6)
    }
}

fn padded_range(lo: f64, hi: f64, log: bool) -> (f64, f64) {
    if !(lo.is_finite() && hi.is_finite()) {
        return (0.0, 1.0);
    }
    if log {
        (
            lo.floor(),
            if hi.ceil() > lo.floor() {
                hi.ceil()
            } else {
                lo.floor() + 1.0
            },
        )
    } else if hi > lo {
        let pad = 0.05 * (hi - lo);
        (lo - pad, hi + pad)
    } else {
        let pad = if lo == 0.0 { 1.0 } else { 0.1 * lo.abs() };
        (lo - pad, hi + pad)
    }
}

/// The corner of the plot area with the fewest data points (ties: upper left, upper right, lower left,
/// lower right), so the legend hides as little as possible. A corner is the 40 % × 40 % box of the
/// (transformed) axis ranges.
fn legend_corner(data: &[Vec<(f64, f64)>], xr: (f64, f64), yr: (f64, f64)) -> SeriesLabelPosition {
    let (wx, wy) = (0.4 * (xr.1 - xr.0), 0.4 * (yr.1 - yr.0));
    let corners = [
        (
            SeriesLabelPosition::UpperLeft,
            xr.0,
            xr.0 + wx,
            yr.1 - wy,
            yr.1,
        ),
        (
            SeriesLabelPosition::UpperRight,
            xr.1 - wx,
            xr.1,
            yr.1 - wy,
            yr.1,
        ),
        (
            SeriesLabelPosition::LowerLeft,
            xr.0,
            xr.0 + wx,
            yr.0,
            yr.0 + wy,
        ),
        (
            SeriesLabelPosition::LowerRight,
            xr.1 - wx,
            xr.1,
            yr.0,
            yr.0 + wy,
        ),
    ];
    let mut best = (usize::MAX, SeriesLabelPosition::UpperLeft);
    for (pos, xa, xb, ya, yb) in corners {
        let n = data
            .iter()
            .flatten()
            .filter(|(x, y)| *x >= xa && *x <= xb && *y >= ya && *y <= yb)
            .count();
        if n < best.0 {
            best = (n, pos);
        }
    }
    best.1
}

type Chart<'a, 'b> = ChartContext<
    'a,
    SVGBackend<'b>,
    Cartesian2d<plotters::coord::types::RangedCoordf64, plotters::coord::types::RangedCoordf64>,
>;

/// Draws one [`SeriesStyle::Marker`] series and its legend entry: series `i` gets the shape
/// `(i + i / 8) % 4`, so that no two of the first 32 series share both shape and colour.
fn draw_markers(
    chart: &mut Chart,
    i: usize,
    color: RGBColor,
    pts: &[(f64, f64)],
    label: &str,
) -> Result<(), String> {
    const SIZE: i32 = 7;
    let style = color.filled();
    let stroke = color.stroke_width(3);
    let err = |e: DrawingAreaErrorKind<_>| e.to_string();
    match (i + i / 8) % 4 {
        0 => chart
            .draw_series(pts.iter().map(|p| Circle::new(*p, SIZE, style)))
            .map_err(err)?
            .label(label)
            .legend(move |(x, y)| Circle::new((x + 8, y), SIZE, style)),
        1 => chart
            .draw_series(pts.iter().map(|p| TriangleMarker::new(*p, SIZE + 2, style)))
            .map_err(err)?
            .label(label)
            .legend(move |(x, y)| TriangleMarker::new((x + 8, y), SIZE + 2, style)),
        2 => chart
            .draw_series(pts.iter().map(|p| {
                EmptyElement::at(*p) + Rectangle::new([(-SIZE, -SIZE), (SIZE, SIZE)], style)
            }))
            .map_err(err)?
            .label(label)
            .legend(move |(x, y)| Rectangle::new([(x + 2, y - 6), (x + 14, y + 6)], style)),
        _ => chart
            .draw_series(pts.iter().map(|p| Cross::new(*p, SIZE + 1, stroke)))
            .map_err(err)?
            .label(label)
            .legend(move |(x, y)| Cross::new((x + 8, y), SIZE + 1, stroke)),
    };
    Ok(())
}

impl Plot {
    /// Number of points per series that a log axis cannot show (value ≤ 0 or non-finite).
    pub fn hidden_points(&self) -> Vec<(String, usize)> {
        self.series
            .iter()
            .map(|s| {
                let n = s
                    .points
                    .iter()
                    .filter(|(x, y)| {
                        transform(*x, self.x_log).is_none() || transform(*y, self.y_log).is_none()
                    })
                    .count();
                (s.label.clone(), n)
            })
            .collect()
    }

    /// Writes the data as CSV in long form: `series,x,y` (full precision, round-trip exact).
    pub fn write_csv(&self, path: &Path) -> Result<(), SuiteError> {
        let mut w = csv::Writer::from_path(path).map_err(SuiteError::csv(path))?;
        let head = ["series", self.x_label.as_str(), self.y_label.as_str()];
        w.write_record(head).map_err(SuiteError::csv(path))?;
        for s in &self.series {
            for (x, y) in &s.points {
                w.write_record([s.label.clone(), format!("{x:e}"), format!("{y:e}")])
                    .map_err(SuiteError::csv(path))?;
            }
        }
        w.flush().map_err(SuiteError::io(path))
    }

    /// Renders the plot to an SVG file.
    pub fn write_svg(&self, path: &Path) -> Result<(), SuiteError> {
        let mut svg = String::new();
        self.render(&mut svg).map_err(|msg| SuiteError::Plot {
            name: self.name.clone(),
            msg,
        })?;
        let mut f = std::fs::File::create(path).map_err(SuiteError::io(path))?;
        f.write_all(svg.as_bytes()).map_err(SuiteError::io(path))
    }

    fn render(&self, out: &mut String) -> Result<(), String> {
        let data = self.transformed();
        let (x0, x1, y0, y1) = bounds(&data);
        // A run index or a count on x: one tick per whole number (up to 20), none in between.
        let whole_x = !self.x_log && data.iter().flatten().all(|(x, _)| x.fract() == 0.0);
        let x_ticks = if whole_x && x1 - x0 <= 20.0 {
            (x1 - x0) as usize + 1
        } else {
            10
        };
        let (x0, x1) = padded_range(x0, x1, self.x_log);
        let (y0, y1) = padded_range(y0, y1, self.y_log);
        let root = SVGBackend::with_string(out, (900, 600)).into_drawing_area();
        root.fill(&WHITE).map_err(|e| e.to_string())?;
        let mut chart = ChartBuilder::on(&root)
            .caption(&self.title, ("sans-serif", 22))
            .margin(16)
            .x_label_area_size(50)
            .y_label_area_size(80)
            .build_cartesian_2d(x0..x1, y0..y1)
            .map_err(|e| e.to_string())?;
        let (xl, yl) = (self.x_log, self.y_log);
        let x_fmt = move |v: &f64| axis_label(*v, xl);
        let y_fmt = move |v: &f64| axis_label(*v, yl);
        chart
            .configure_mesh()
            .x_desc(self.x_label.as_str())
            .y_desc(self.y_label.as_str())
            .axis_desc_style(("sans-serif", 16))
            .label_style(("sans-serif", 13))
            .x_labels(x_ticks)
            .x_label_formatter(&x_fmt)
            .y_label_formatter(&y_fmt)
            .light_line_style(RGBColor(235, 235, 235))
            .draw()
            .map_err(|e| e.to_string())?;
        for (i, (s, pts)) in self.series.iter().zip(&data).enumerate() {
            draw_series(&mut chart, i, s, pts)?;
        }
        chart
            .configure_series_labels()
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK)
            .label_font(("sans-serif", 14))
            .position(legend_corner(&data, (x0, x1), (y0, y1)))
            .draw()
            .map_err(|e| e.to_string())?;
        root.present().map_err(|e| e.to_string())
    }

    /// Each series' points on the axes' scales (log10 where an axis is logarithmic); points a log axis
    /// cannot show are left out.
    fn transformed(&self) -> Vec<Vec<(f64, f64)>> {
        self.series
            .iter()
            .map(|s| {
                s.points
                    .iter()
                    .filter_map(|(x, y)| {
                        Some((transform(*x, self.x_log)?, transform(*y, self.y_log)?))
                    })
                    .collect()
            })
            .collect()
    }
}

/// The smallest and largest x and y of every point of `data`: (x0, x1, y0, y1).
fn bounds(data: &[Vec<(f64, f64)>]) -> (f64, f64, f64, f64) {
    let (mut x0, mut x1, mut y0, mut y1) = (
        f64::INFINITY,
        f64::NEG_INFINITY,
        f64::INFINITY,
        f64::NEG_INFINITY,
    );
    for (x, y) in data.iter().flatten() {
        x0 = x0.min(*x);
        x1 = x1.max(*x);
        y0 = y0.min(*y);
        y1 = y1.max(*y);
    }
    (x0, x1, y0, y1)
}

/// Draws series `i` (`s`, at the transformed points `pts`) in its style and colour, with its legend entry.
fn draw_series(chart: &mut Chart, i: usize, s: &Series, pts: &[(f64, f64)]) -> Result<(), String> {
    let color = COLORS[i % COLORS.len()];
    let marker_style = color.mix(0.6).filled();
    let line_style = color.stroke_width(2);
    let anno = match s.style {
        SeriesStyle::Marker => return draw_markers(chart, i, color, pts, &s.label),
        SeriesStyle::Points => chart
            .draw_series(pts.iter().map(|p| Circle::new(*p, 2, marker_style)))
            .map_err(|e| e.to_string())?,
        SeriesStyle::Line => chart
            .draw_series(LineSeries::new(pts.iter().copied(), line_style))
            .map_err(|e| e.to_string())?,
        SeriesStyle::LinePoints => {
            chart
                .draw_series(LineSeries::new(pts.iter().copied(), line_style))
                .map_err(|e| e.to_string())?;
            chart
                .draw_series(pts.iter().map(|p| Circle::new(*p, 4, color.filled())))
                .map_err(|e| e.to_string())?
        }
    };
    anno.label(s.label.as_str())
        .legend(move |(x, y)| Rectangle::new([(x, y - 4), (x + 16, y + 4)], color.filled()));
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn svg_has_title_labels_and_legend_text() {
        let plot = Plot {
            name: "t".into(),
            title: "Depth error vs overlap".into(),
            x_label: "overlap / size".into(),
            y_label: "depth error / size".into(),
            x_log: true,
            y_log: true,
            series: vec![
                Series {
                    label: "ours".into(),
                    style: SeriesStyle::Points,
                    points: vec![(1e-9, 1e-17), (1e-3, 2e-16), (0.0, 1.0)],
                },
                Series {
                    label: "parry3d-f64".into(),
                    style: SeriesStyle::LinePoints,
                    points: vec![(1e-8, 1e-12), (1e-2, 3e-3)],
                },
            ],
            caption: String::new(),
        };
        let mut svg = String::new();
        plot.render(&mut svg).unwrap();
        for needle in [
            "Depth error vs overlap",
            "overlap / size",
            "depth error / size",
            "ours",
            "parry3d-f64",
            "1e-9",
        ] {
            assert!(svg.contains(needle), "SVG lacks `{needle}`");
        }
        assert_eq!(
            plot.hidden_points(),
            vec![("ours".to_string(), 1), ("parry3d-f64".to_string(), 0)]
        );
        // Left in the temp directory for a look: `rsvg-convert` it to PNG.
        let path = std::env::temp_dir().join("polydem_plot_test.svg");
        plot.write_svg(&path).unwrap();
    }

    #[test]
    fn marker_series_are_drawn_with_their_legend_entries() {
        let series = (0..10i32)
            .map(|i| Series {
                label: format!("method {i}"),
                style: SeriesStyle::Marker,
                points: vec![(1e3 * (1.0 + f64::from(i)), 10f64.powi(-i))],
            })
            .collect();
        let plot = Plot {
            name: "m".into(),
            title: "Time against error".into(),
            x_label: "ns".into(),
            y_label: "error".into(),
            x_log: true,
            y_log: true,
            series,
            caption: String::new(),
        };
        let mut svg = String::new();
        plot.render(&mut svg).unwrap();
        for i in 0..10 {
            assert!(
                svg.contains(&format!("method {i}")),
                "SVG lacks legend `method {i}`"
            );
        }
        // Circles, triangles (polygons) and squares among the first four markers.
        for needle in ["<circle", "<polygon", "<rect"] {
            assert!(svg.contains(needle), "SVG lacks a `{needle}` marker");
        }
        // Left in the temp directory for a look: `rsvg-convert` it to PNG.
        let path = std::env::temp_dir().join("polydem_plot_markers.svg");
        plot.write_svg(&path).unwrap();
    }
}
