//! Simple line charts written as SVG files, for result histories (moments
//! along a deployment, driver loads, joint angles).
//!
//! The charts are drawn with `plotters` (SVG backend only) and an embedded
//! font (DejaVu Sans, `assets/fonts/`, Bitstream Vera licence), so no system
//! font library is needed:
//!
//! ```no_run
//! use unfold::io::plot::{line_chart_svg, Series};
//!
//! let s = Series::new("sin", (0..=100).map(|i| {
//!     let x = i as f64 * 0.1;
//!     (x, x.sin())
//! }));
//! line_chart_svg("sin.svg".as_ref(), "A sine", "x", "sin x", &[s]).unwrap();
//! ```

use std::path::Path;
use std::sync::OnceLock;

use plotters::prelude::*;
use plotters::style::{register_font, FontStyle};

/// The embedded font, registered as the `sans-serif` family.
const FONT: &[u8] = include_bytes!("../../assets/fonts/DejaVuSans.ttf");

/// Width and height of a chart, pixels.
pub const SIZE: (u32, u32) = (900, 560);

/// Line colours, in order of the series (cycled).
const COLOURS: [RGBColor; 8] = [
    RGBColor(31, 119, 180),
    RGBColor(214, 39, 40),
    RGBColor(44, 160, 44),
    RGBColor(255, 127, 14),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
    RGBColor(227, 119, 194),
    RGBColor(23, 190, 207),
];

/// One curve of a chart: a label for the legend and its points `(x, y)`,
/// drawn in the given order.
#[derive(Clone, Debug, PartialEq)]
pub struct Series {
    /// Legend text.
    pub label: String,
    /// Points `(x, y)`.
    pub points: Vec<(f64, f64)>,
}

impl Series {
    /// A series from a label and points.
    pub fn new(label: impl Into<String>, points: impl IntoIterator<Item = (f64, f64)>) -> Self {
        Self {
            label: label.into(),
            points: points.into_iter().collect(),
        }
    }
}

/// Why a chart could not be drawn.
#[derive(Debug, thiserror::Error)]
pub enum PlotError {
    /// No series has a finite point.
    #[error("nothing to plot: no series has a finite point")]
    Empty,
    /// The embedded font could not be read.
    #[error("the embedded font could not be loaded")]
    Font,
    /// The drawing library failed.
    #[error("drawing the chart: {0}")]
    Drawing(String),
    /// The file could not be written.
    #[error("writing the chart: {0}")]
    Io(#[from] std::io::Error),
}

/// Registers the embedded font once per process.
fn register() -> Result<(), PlotError> {
    static REGISTERED: OnceLock<bool> = OnceLock::new();
    let ok =
        *REGISTERED.get_or_init(|| register_font("sans-serif", FontStyle::Normal, FONT).is_ok());
    if ok {
        Ok(())
    } else {
        Err(PlotError::Font)
    }
}

/// Range `[lo, hi]` of the values with a 5 % margin; a single value gets a
/// range of ±1 (or ±5 % of itself).
fn padded(lo: f64, hi: f64) -> (f64, f64) {
    let span = hi - lo;
    if span > 0.0 {
        (lo - 0.05 * span, hi + 0.05 * span)
    } else {
        let d = if lo == 0.0 { 1.0 } else { 0.05 * lo.abs() };
        (lo - d, hi + d)
    }
}

/// Draws the series as lines on one pair of linear axes, with a title,
/// axis labels and a legend (upper right, above the curves), and returns
/// the SVG text. Non-finite points are skipped.
pub fn line_chart_svg_string(
    title: &str,
    x_label: &str,
    y_label: &str,
    series: &[Series],
) -> Result<String, PlotError> {
    register()?;
    let finite = |p: &&(f64, f64)| p.0.is_finite() && p.1.is_finite();
    let all: Vec<(f64, f64)> = series
        .iter()
        .flat_map(|s| s.points.iter().filter(finite).copied())
        .collect();
    if all.is_empty() {
        return Err(PlotError::Empty);
    }
    let range = |f: fn(&(f64, f64)) -> f64| {
        let lo = all.iter().map(f).fold(f64::INFINITY, f64::min);
        let hi = all.iter().map(f).fold(f64::NEG_INFINITY, f64::max);
        padded(lo, hi)
    };
    let (x0, x1) = range(|p| p.0);
    let (y0, mut y1) = range(|p| p.1);
    // headroom for the legend in the upper right corner, about 20 px per
    // line of a plot area about 450 px high, so that it covers no curve
    let labelled = series.iter().any(|s| !s.label.is_empty());
    if labelled {
        let f = ((20 * series.len() + 15) as f64 / 450.0).min(0.6);
        y1 += (y1 - y0) * f / (1.0 - f);
    }

    let mut svg = String::new();
    {
        let err = |e: &dyn std::fmt::Display| PlotError::Drawing(e.to_string());
        let root = SVGBackend::with_string(&mut svg, SIZE).into_drawing_area();
        root.fill(&WHITE).map_err(|e| err(&e))?;
        let mut chart = ChartBuilder::on(&root)
            .caption(title, ("sans-serif", 22))
            .margin(15)
            .x_label_area_size(45)
            .y_label_area_size(70)
            .build_cartesian_2d(x0..x1, y0..y1)
            .map_err(|e| err(&e))?;
        chart
            .configure_mesh()
            .x_desc(x_label)
            .y_desc(y_label)
            .label_style(("sans-serif", 14))
            .axis_desc_style(("sans-serif", 16))
            .light_line_style(RGBColor(235, 235, 235))
            .draw()
            .map_err(|e| err(&e))?;
        for (k, s) in series.iter().enumerate() {
            let colour = COLOURS[k % COLOURS.len()];
            let points: Vec<(f64, f64)> = s.points.iter().filter(finite).copied().collect();
            chart
                .draw_series(LineSeries::new(points, colour.stroke_width(2)))
                .map_err(|e| err(&e))?
                .label(s.label.clone())
                .legend(move |(x, y)| {
                    PathElement::new(vec![(x, y), (x + 20, y)], colour.stroke_width(2))
                });
        }
        if labelled {
            chart
                .configure_series_labels()
                .label_font(("sans-serif", 14))
                .background_style(WHITE.mix(0.85))
                .border_style(BLACK)
                .position(SeriesLabelPosition::UpperRight)
                .draw()
                .map_err(|e| err(&e))?;
        }
        root.present().map_err(|e| err(&e))?;
    }
    Ok(svg)
}

/// Draws the series as in [`line_chart_svg_string`] and writes the SVG
/// file `path`.
pub fn line_chart_svg(
    path: &Path,
    title: &str,
    x_label: &str,
    y_label: &str,
    series: &[Series],
) -> Result<(), PlotError> {
    let svg = line_chart_svg_string(title, x_label, y_label, series)?;
    std::fs::write(path, svg)?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample() -> Vec<Series> {
        vec![
            Series::new(
                "sin",
                (0..=50).map(|i| (0.1 * i as f64, (0.1 * i as f64).sin())),
            ),
            Series::new(
                "cos",
                (0..=50).map(|i| (0.1 * i as f64, (0.1 * i as f64).cos())),
            ),
        ]
    }

    #[test]
    fn writes_an_svg_with_text_and_lines() {
        let path = std::env::temp_dir().join(format!("unfold-plot-{}.svg", std::process::id()));
        line_chart_svg(&path, "Two curves", "x (m)", "y (N·m)", &sample()).unwrap();
        let svg = std::fs::read_to_string(&path).unwrap();
        let _ = std::fs::remove_file(&path);
        assert!(svg.starts_with("<svg"), "{}", &svg[..80.min(svg.len())]);
        // title, axis descriptions, tick labels and legend are text elements
        let texts = svg.matches("<text").count();
        assert!(texts >= 10, "{texts} text elements");
        for s in ["Two curves", "x (m)", "y (N·m)", "sin", "cos"] {
            assert!(svg.contains(s), "missing {s:?}");
        }
        // each series is one polyline (or path)
        let lines = svg.matches("<polyline").count() + svg.matches("<path").count();
        assert!(lines >= 2, "{lines} lines");
    }

    #[test]
    fn skips_non_finite_points_and_rejects_empty_charts() {
        let s = Series::new("gap", [(0.0, 1.0), (1.0, f64::NAN), (2.0, 3.0)]);
        let svg = line_chart_svg_string("t", "x", "y", &[s]).unwrap();
        assert!(!svg.contains("NaN"));
        let empty = Series::new("none", [(f64::NAN, 0.0)]);
        assert!(matches!(
            line_chart_svg_string("t", "x", "y", &[empty]),
            Err(PlotError::Empty)
        ));
        // a constant series still gets a valid range
        let flat = Series::new("flat", [(0.0, 2.0), (1.0, 2.0)]);
        assert!(line_chart_svg_string("t", "x", "y", &[flat]).is_ok());
    }
}
