//! Line charts of result histories (moments along a deployment, driver
//! loads, joint angles), written as SVG or PNG files.
//!
//! Every chart says what it shows: each axis is a quantity with its unit
//! ([`Axis`]), and each series has its own colour, line pattern (solid,
//! dashed, dotted, long dashes) and marker (circle, triangle, cross,
//! square), so that curves that coincide stay visible — the later ones
//! are drawn with gaps, their markers shifted along the curve. Events
//! such as a change of stage are vertical lines with a label
//! ([`Chart::event`]).
//!
//! The charts are drawn with `plotters` and an embedded font (DejaVu
//! Sans, `assets/fonts/`, Bitstream Vera licence), so no system font
//! library is needed; PNG files are encoded with the `png` crate.
//!
//! ```no_run
//! use unfold::io::plot::{Axis, Chart, Series};
//!
//! let s = Series::new("sin", (0..=100).map(|i| {
//!     let x = i as f64 * 0.1;
//!     (x, x.sin())
//! }));
//! Chart::new("A sine", Axis::new("angle", "rad"), Axis::dimensionless("sin"))
//!     .series(s)
//!     .event(std::f64::consts::PI, "half turn")
//!     .write_svg("sin.svg".as_ref())
//!     .unwrap();
//! ```

use std::path::Path;
use std::sync::OnceLock;

use plotters::coord::Shift;
use plotters::element::{DashedPathElement, Drawable, PointCollection};
use plotters::prelude::*;
use plotters::style::{register_font, FontStyle};
use plotters_backend::{BackendCoord, DrawingErrorKind};

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

/// Line patterns, in order of the series (cycled): dash and gap lengths
/// in pixels, `None` for a solid line.
const PATTERNS: [Option<(u32, u32)>; 4] = [None, Some((10, 6)), Some((2, 5)), Some((20, 8))];

/// Markers, in order of the series (cycled).
#[derive(Clone, Copy, Debug)]
enum Mark {
    Circle,
    Triangle,
    Cross,
    Square,
}

const MARKS: [Mark; 4] = [Mark::Circle, Mark::Triangle, Mark::Cross, Mark::Square];

/// Markers drawn along each series (about).
const MARKERS_PER_SERIES: usize = 12;

/// Size of a marker, pixels.
const MARK_SIZE: i32 = 5;

/// An axis: the quantity shown and its unit, written `quantity (unit)`.
#[derive(Clone, Debug, PartialEq)]
pub struct Axis {
    /// What is measured along the axis ("load parameter t", "moment").
    pub quantity: String,
    /// Its unit ("N·m", "m"); "–" for a pure number.
    pub unit: String,
}

impl Axis {
    /// An axis for `quantity` in `unit`.
    pub fn new(quantity: impl Into<String>, unit: impl Into<String>) -> Self {
        Self {
            quantity: quantity.into(),
            unit: unit.into(),
        }
    }

    /// An axis for a pure number (unit "–").
    pub fn dimensionless(quantity: impl Into<String>) -> Self {
        Self::new(quantity, "–")
    }

    /// The label: `quantity (unit)`.
    pub fn label(&self) -> String {
        format!("{} ({})", self.quantity, self.unit)
    }
}

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

/// A line chart: title, axes, series and events.
#[derive(Clone, Debug, PartialEq)]
pub struct Chart {
    /// Title above the chart.
    pub title: String,
    /// Horizontal axis.
    pub x: Axis,
    /// Vertical axis.
    pub y: Axis,
    /// The curves.
    pub series: Vec<Series>,
    /// Vertical lines at `x` with a label (a change of stage).
    pub events: Vec<(f64, String)>,
}

/// Why a chart could not be drawn.
#[derive(Debug, thiserror::Error)]
pub enum PlotError {
    /// No series has a finite point.
    #[error("nothing to plot: no series has a finite point")]
    Empty,
    /// An axis without a quantity or a unit.
    #[error("axis {0:?}: give the quantity and its unit (\"–\" for a pure number)")]
    Axis(String),
    /// The embedded font could not be read.
    #[error("the embedded font could not be loaded")]
    Font,
    /// The drawing library failed.
    #[error("drawing the chart: {0}")]
    Drawing(String),
    /// The file could not be written.
    #[error("{path}: {source}")]
    Io {
        /// The chart file.
        path: String,
        /// What went wrong.
        source: std::io::Error,
    },
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

fn finite(p: &&(f64, f64)) -> bool {
    p.0.is_finite() && p.1.is_finite()
}

fn drawing_error(e: &dyn std::fmt::Display) -> PlotError {
    PlotError::Drawing(e.to_string())
}

/// A marker of a series at a point, and in the legend the series' line
/// through it: drawn with the backend's primitives so that one type serves
/// every marker and line pattern.
struct Glyph<C> {
    /// Centre of the marker.
    at: C,
    mark: Mark,
    colour: RGBColor,
    /// The legend's line through the marker, with its pattern; `None` on
    /// the curves.
    line: Option<Option<(u32, u32)>>,
}

impl<'a, C> PointCollection<'a, C> for &'a Glyph<C> {
    type Point = &'a C;
    type IntoIter = std::iter::Once<&'a C>;
    fn point_iter(self) -> Self::IntoIter {
        std::iter::once(&self.at)
    }
}

impl<C, DB: DrawingBackend> Drawable<DB> for Glyph<C> {
    fn draw<I: Iterator<Item = BackendCoord>>(
        &self,
        mut points: I,
        backend: &mut DB,
        _: (u32, u32),
    ) -> Result<(), DrawingErrorKind<DB::ErrorType>> {
        let Some((x, y)) = points.next() else {
            return Ok(());
        };
        let stroke = self.colour.stroke_width(2);
        let fill = self.colour.filled();
        if let Some(pattern) = self.line {
            // a 36 px line centred on the marker
            let (dash, gap) = pattern.map_or((36, 0), |(d, g)| (d.min(8) as i32, g.min(4) as i32));
            let mut x0 = x - 18;
            while x0 < x + 18 {
                let x1 = (x0 + dash).min(x + 18);
                backend.draw_line((x0, y), (x1, y), &stroke)?;
                x0 = x1 + gap;
            }
        }
        let r = MARK_SIZE;
        match self.mark {
            Mark::Circle => backend.draw_circle((x, y), r as u32, &stroke, false),
            Mark::Triangle => backend.fill_polygon(
                [(x, y - r - 1), (x - r - 1, y + r), (x + r + 1, y + r)],
                &fill,
            ),
            Mark::Cross => {
                backend.draw_line((x - r, y - r), (x + r, y + r), &stroke)?;
                backend.draw_line((x - r, y + r), (x + r, y - r), &stroke)
            }
            Mark::Square => {
                backend.draw_rect((x - r + 1, y - r + 1), (x + r - 1, y + r - 1), &fill, true)
            }
        }
    }
}

impl Chart {
    /// An empty chart with a title and its axes.
    pub fn new(title: impl Into<String>, x: Axis, y: Axis) -> Self {
        Self {
            title: title.into(),
            x,
            y,
            series: Vec::new(),
            events: Vec::new(),
        }
    }

    /// Adds a series.
    pub fn series(mut self, series: Series) -> Self {
        self.series.push(series);
        self
    }

    /// Adds a vertical line at `x` labelled `label` (an event: a change of
    /// stage, a lock).
    pub fn event(mut self, x: f64, label: impl Into<String>) -> Self {
        self.events.push((x, label.into()));
        self
    }

    /// Draws the chart on `root`: linear axes with their labels, the
    /// series with their styles, the events, and a legend in the upper
    /// right corner above the curves. Non-finite points are skipped.
    fn draw<'d, DB: DrawingBackend + 'd>(
        &self,
        root: &DrawingArea<DB, Shift>,
    ) -> Result<(), PlotError> {
        for axis in [&self.x, &self.y] {
            if axis.quantity.trim().is_empty() || axis.unit.trim().is_empty() {
                return Err(PlotError::Axis(axis.label()));
            }
        }
        register()?;
        let all: Vec<(f64, f64)> = self
            .series
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
        // headroom for the legend in the upper right corner, about 22 px
        // per line of a plot area about 450 px high, so that it covers no
        // curve
        let labelled = self.series.iter().any(|s| !s.label.is_empty());
        if labelled {
            let f = ((22 * self.series.len() + 15) as f64 / 450.0).min(0.6);
            y1 += (y1 - y0) * f / (1.0 - f);
        }

        root.fill(&WHITE).map_err(|e| drawing_error(&e))?;
        let mut chart = ChartBuilder::on(root)
            .caption(&self.title, ("sans-serif", 22))
            .margin(15)
            .x_label_area_size(50)
            .y_label_area_size(80)
            .build_cartesian_2d(x0..x1, y0..y1)
            .map_err(|e| drawing_error(&e))?;
        chart
            .configure_mesh()
            .x_desc(self.x.label())
            .y_desc(self.y.label())
            .label_style(("sans-serif", 14))
            .axis_desc_style(("sans-serif", 16))
            .light_line_style(RGBColor(235, 235, 235))
            .draw()
            .map_err(|e| drawing_error(&e))?;

        // events: grey vertical lines labelled at the top
        let grey = RGBColor(110, 110, 110);
        for (x, label) in &self.events {
            chart
                .draw_series(std::iter::once(DashedPathElement::new(
                    [(*x, y0), (*x, y1)],
                    6,
                    4,
                    grey.stroke_width(1),
                )))
                .map_err(|e| drawing_error(&e))?;
            chart
                .draw_series(std::iter::once(Text::new(
                    format!(" {label}"),
                    (*x, y1),
                    ("sans-serif", 13).into_font().color(&grey),
                )))
                .map_err(|e| drawing_error(&e))?;
        }

        let n_series = self.series.len().max(1);
        for (k, s) in self.series.iter().enumerate() {
            let colour = COLOURS[k % COLOURS.len()];
            let pattern = PATTERNS[k % PATTERNS.len()];
            let mark = MARKS[k % MARKS.len()];
            let points: Vec<(f64, f64)> = s.points.iter().filter(finite).copied().collect();
            let style = colour.stroke_width(2);
            match pattern {
                None => chart.draw_series(LineSeries::new(points.iter().copied(), style)),
                Some((dash, gap)) => chart.draw_series(std::iter::once(DashedPathElement::new(
                    points.iter().copied(),
                    dash,
                    gap,
                    style,
                ))),
            }
            .map_err(|e| drawing_error(&e))?;
            // markers every `every` points, shifted by series so that
            // coinciding curves show each one's markers
            let every = points.len().div_ceil(MARKERS_PER_SERIES).max(1);
            let shift = k * every / n_series;
            chart
                .draw_series(points.iter().skip(shift).step_by(every).map(|p| Glyph {
                    at: *p,
                    mark,
                    colour,
                    line: None,
                }))
                .map_err(|e| drawing_error(&e))?
                .label(s.label.clone())
                .legend(move |at| Glyph {
                    at,
                    mark,
                    colour,
                    line: Some(pattern),
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
                .map_err(|e| drawing_error(&e))?;
        }
        root.present().map_err(|e| drawing_error(&e))?;
        Ok(())
    }

    /// The chart as SVG text.
    pub fn to_svg(&self) -> Result<String, PlotError> {
        let mut svg = String::new();
        {
            let root = SVGBackend::with_string(&mut svg, SIZE).into_drawing_area();
            self.draw(&root)?;
        }
        Ok(svg)
    }

    /// The chart as RGB pixels, `SIZE.0 × SIZE.1`, row by row.
    pub fn to_rgb(&self) -> Result<Vec<u8>, PlotError> {
        let mut pixels = vec![0u8; 3 * SIZE.0 as usize * SIZE.1 as usize];
        {
            let root = BitMapBackend::with_buffer(&mut pixels, SIZE).into_drawing_area();
            self.draw(&root)?;
        }
        Ok(pixels)
    }

    /// Writes the chart as an SVG file.
    pub fn write_svg(&self, path: &Path) -> Result<(), PlotError> {
        let svg = self.to_svg()?;
        std::fs::write(path, svg).map_err(|source| PlotError::Io {
            path: path.display().to_string(),
            source,
        })
    }

    /// Writes the chart as a PNG file.
    pub fn write_png(&self, path: &Path) -> Result<(), PlotError> {
        let pixels = self.to_rgb()?;
        let io = |source| PlotError::Io {
            path: path.display().to_string(),
            source,
        };
        let file = std::fs::File::create(path).map_err(io)?;
        let mut encoder = png::Encoder::new(std::io::BufWriter::new(file), SIZE.0, SIZE.1);
        encoder.set_color(png::ColorType::Rgb);
        encoder.set_depth(png::BitDepth::Eight);
        let encoded = encoder
            .write_header()
            .and_then(|mut w| w.write_image_data(&pixels).and_then(|()| w.finish()));
        encoded.map_err(|e| match e {
            png::EncodingError::IoError(source) => io(source),
            other => drawing_error(&other),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample() -> Chart {
        Chart::new("Two curves", Axis::new("x", "m"), Axis::new("y", "N·m"))
            .series(Series::new(
                "sin",
                (0..=50).map(|i| (0.1 * i as f64, (0.1 * i as f64).sin())),
            ))
            .series(Series::new(
                "cos",
                (0..=50).map(|i| (0.1 * i as f64, (0.1 * i as f64).cos())),
            ))
    }

    #[test]
    fn writes_an_svg_with_text_and_lines() {
        let path = std::env::temp_dir().join(format!("unfold-plot-{}.svg", std::process::id()));
        sample().write_svg(&path).unwrap();
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
        let chart = |s: Series| Chart::new("t", Axis::new("x", "m"), Axis::new("y", "m")).series(s);
        let svg = chart(Series::new(
            "gap",
            [(0.0, 1.0), (1.0, f64::NAN), (2.0, 3.0)],
        ))
        .to_svg()
        .unwrap();
        assert!(!svg.contains("NaN"));
        assert!(matches!(
            chart(Series::new("none", [(f64::NAN, 0.0)])).to_svg(),
            Err(PlotError::Empty)
        ));
        // a constant series still gets a valid range
        assert!(chart(Series::new("flat", [(0.0, 2.0), (1.0, 2.0)]))
            .to_svg()
            .is_ok());
    }

    /// Curves that coincide stay distinguishable: each series has its own
    /// colour, its own line pattern and its own markers.
    #[test]
    fn coinciding_series_are_drawn_distinctly() {
        let same: Vec<(f64, f64)> = (0..=40).map(|i| (i as f64, (i as f64).sqrt())).collect();
        let mut chart = Chart::new(
            "four equal curves",
            Axis::new("x", "m"),
            Axis::new("y", "N"),
        );
        for k in 0..4 {
            chart = chart.series(Series::new(format!("curve {k}"), same.clone()));
        }
        let svg = chart.to_svg().unwrap();
        for c in COLOURS.iter().take(4) {
            let hex = format!("#{:02X}{:02X}{:02X}", c.0, c.1, c.2);
            assert!(svg.contains(&hex), "colour {hex} missing");
        }
        // solid lines are one polyline each; dashed ones many short lines
        assert!(svg.matches("<polyline").count() >= 1);
        assert!(
            svg.matches("<line").count() >= 30,
            "dashes: {}",
            svg.matches("<line").count()
        );
        // markers: circles, triangles (polygons), crosses, squares
        assert!(svg.matches("<circle").count() >= 10);
        assert!(svg.matches("<polygon").count() >= 10);
        assert!(svg.matches("<rect").count() >= 10);
    }

    #[test]
    fn axes_need_a_unit_and_events_are_drawn() {
        let bare = Chart::new("t", Axis::new("t", ""), Axis::new("y", "m"))
            .series(Series::new("a", [(0.0, 0.0), (1.0, 1.0)]));
        assert!(matches!(bare.to_svg(), Err(PlotError::Axis(_))));
        let svg = sample().event(1.0, "stage (b)").to_svg().unwrap();
        assert!(svg.contains("stage (b)"));
    }

    #[test]
    fn writes_a_png() {
        let path = std::env::temp_dir().join(format!("unfold-plot-{}.png", std::process::id()));
        sample().write_png(&path).unwrap();
        let bytes = std::fs::read(&path).unwrap();
        let _ = std::fs::remove_file(&path);
        assert_eq!(&bytes[..8], b"\x89PNG\r\n\x1a\n");
        let decoder = png::Decoder::new(std::io::Cursor::new(bytes));
        let reader = decoder.read_info().unwrap();
        assert_eq!((reader.info().width, reader.info().height), SIZE);
        // not blank: the curves are coloured pixels
        let pixels = sample().to_rgb().unwrap();
        let blue = pixels
            .chunks(3)
            .filter(|p| p[0] == COLOURS[0].0 && p[1] == COLOURS[0].1 && p[2] == COLOURS[0].2)
            .count();
        assert!(blue > 100, "{blue} pixels of the first series");
    }
}
