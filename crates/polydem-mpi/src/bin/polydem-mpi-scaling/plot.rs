//! A line plot with a base-2 logarithmic x axis (rank counts), rendered to SVG with plotters (no font feature: text is written
//! as SVG `<text>`, so the output does not depend on the system's fonts), and the CSV behind it.

use std::path::Path;

use plotters::prelude::*;

use crate::Error;

/// One series: a label, its points, and whether to draw it as markers only.
pub struct Series {
    pub label: String,
    pub points: Vec<(f64, f64)>,
    pub markers_only: bool,
}

const COLORS: [RGBColor; 6] = [
    RGBColor(31, 119, 180),
    RGBColor(214, 39, 40),
    RGBColor(44, 160, 44),
    RGBColor(255, 127, 14),
    RGBColor(148, 103, 189),
    RGBColor(0, 0, 0),
];

/// Writes `stem.svg` and `stem.csv` (series,x,y) for `series` against log2 x.
pub fn write(
    stem: &Path,
    title: &str,
    x_label: &str,
    y_label: &str,
    series: &[Series],
) -> Result<(), Error> {
    let xs = series
        .iter()
        .flat_map(|s| s.points.iter().map(|p| p.0.log2()));
    let (x_lo, x_hi) = xs.fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), x| {
        (lo.min(x), hi.max(x))
    });
    let y_hi = series
        .iter()
        .flat_map(|s| s.points.iter().map(|p| p.1))
        .fold(0.0, f64::max);
    let svg = stem.with_extension("svg");
    {
        let root = SVGBackend::new(&svg, (800, 500)).into_drawing_area();
        root.fill(&WHITE)?;
        let mut chart = ChartBuilder::on(&root)
            .caption(title, ("sans-serif", 20))
            .margin(15)
            .x_label_area_size(45)
            .y_label_area_size(60)
            .build_cartesian_2d(x_lo - 0.1..x_hi + 0.1, 0.0..1.1 * y_hi)?;
        chart
            .configure_mesh()
            .x_desc(x_label)
            .y_desc(y_label)
            .x_labels((x_hi - x_lo).round() as usize + 1)
            .x_label_formatter(&|v| {
                // Labels at the powers of two only.
                if (v - v.round()).abs() < 1e-6 {
                    format!("{:.0}", 2f64.powf(v.round()))
                } else {
                    String::new()
                }
            })
            .draw()?;
        for (k, s) in series.iter().enumerate() {
            let color = COLORS[k % COLORS.len()];
            let points: Vec<(f64, f64)> = s.points.iter().map(|&(x, y)| (x.log2(), y)).collect();
            let drawn = if s.markers_only {
                chart.draw_series(
                    points
                        .iter()
                        .map(|&p| Cross::new(p, 8, color.stroke_width(3))),
                )?
            } else {
                chart.draw_series(LineSeries::new(points.clone(), color.stroke_width(2)))?;
                chart.draw_series(points.iter().map(|&p| Circle::new(p, 3, color.filled())))?
            };
            drawn
                .label(s.label.clone())
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 18, y)], color));
        }
        chart
            .configure_series_labels()
            .position(SeriesLabelPosition::LowerLeft)
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK)
            .draw()?;
        root.present()?;
    }
    let mut csv = String::from("series,x,y\n");
    for s in series {
        for (x, y) in &s.points {
            csv.push_str(&format!("{},{x:e},{y:e}\n", s.label.replace(',', ";")));
        }
    }
    let path = stem.with_extension("csv");
    std::fs::write(&path, csv).map_err(|e| format!("{}: {e}", path.display()).into())
}
