//! Line charts of result histories (moments along a deployment, driver
//! loads, joint angles) and line drawings of configurations, written as
//! SVG or PNG files.
//!
//! Every chart says what it shows: each axis is a quantity with its unit
//! ([`Axis`]), and each series has its own colour, line pattern (solid,
//! dashed, dotted, long dashes) and marker (circle, triangle, cross,
//! square), so that curves that coincide stay visible — the later ones
//! are drawn with gaps, their markers shifted along the curve. Events
//! such as a change of stage are vertical lines with a label
//! ([`Chart::event`]); dense minor events (a spring latch rattling across
//! its dead band) are short ticks in a row at the top of the plot area,
//! a cluster of them labelled once ([`Chart::tick`]). Labels are placed
//! in rows so that no two of them overlap ([`Chart::label_boxes`]).
//!
//! Line drawings of configurations ([`Wireframe`]): the members of a
//! structure as lines in a parallel projection (isometric by default),
//! several configurations side by side at one scale.
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

/// Font size of the event labels, and the height of a row of them, pixels.
const EVENT_FONT: u32 = 13;
const EVENT_ROW: i32 = 16;

/// Rows of event labels at the top of a chart, at most: a label that
/// finds no free room in them is left out (its line or tick stays), so
/// that no label covers another.
const EVENT_ROWS: usize = 4;

/// Height of the ticks of minor events, pixels, and of their row with
/// its margin.
const TICK: i32 = 8;
const TICK_ROW: i32 = 12;

/// Free space kept between two labels of a row, pixels.
const LABEL_GAP: i32 = 4;

/// Width of the plotting area of a chart (its size less the margins and
/// the label area of the vertical axis), pixels, to place event labels
/// before the axes are drawn.
const PLOT_WIDTH: i32 = SIZE.0 as i32 - 2 * 15 - 80;

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
    /// Vertical lines at `x` with a label (a change of stage); an empty
    /// label draws the line alone.
    pub events: Vec<(f64, String)>,
    /// Minor events at `x`: short ticks in a row at the top of the plot
    /// area; a non-empty label labels a cluster of them (placed after the
    /// labels of `events`).
    pub ticks: Vec<(f64, String)>,
}

/// Where an event label is drawn: its row at the top of the chart (0 the
/// highest), its left end from the left of the plot area and its width,
/// pixels; `event` its index in [`Chart::events`], or in [`Chart::ticks`]
/// for a tick's label.
#[derive(Clone, Debug, PartialEq)]
pub struct LabelBox {
    /// Index of the event (or tick) labelled.
    pub event: usize,
    /// Whether it labels a tick (a cluster of minor events).
    pub tick: bool,
    /// Row, from the top.
    pub row: usize,
    /// Left end, pixels from the left of the plot area.
    pub left: i32,
    /// Width, pixels (with a space on either side of the text).
    pub width: i32,
}

impl LabelBox {
    /// Whether the two boxes share a row and overlap along it.
    pub fn overlaps(&self, other: &LabelBox) -> bool {
        self.row == other.row
            && self.left < other.left + other.width
            && other.left < self.left + self.width
    }
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
            ticks: Vec::new(),
        }
    }

    /// Adds a series.
    pub fn series(mut self, series: Series) -> Self {
        self.series.push(series);
        self
    }

    /// Adds a vertical line at `x` labelled `label` (an event: a change of
    /// stage, a lock); an empty label draws the line alone (one of a group
    /// of events labelled once).
    pub fn event(mut self, x: f64, label: impl Into<String>) -> Self {
        self.events.push((x, label.into()));
        self
    }

    /// Adds a tick at `x` in the row of minor events at the top of the
    /// plot area (a spring latch's spring engaging); a non-empty `label`
    /// labels the cluster of ticks it starts, an empty one draws the tick
    /// alone.
    pub fn tick(mut self, x: f64, label: impl Into<String>) -> Self {
        self.ticks.push((x, label.into()));
        self
    }

    /// The horizontal range of the chart: that of the curves, widened to
    /// the events and ticks outside it.
    fn x_range(&self) -> Option<(f64, f64)> {
        let xs = self
            .series
            .iter()
            .flat_map(|s| s.points.iter().filter(finite).map(|p| p.0));
        let lo = xs.clone().fold(f64::INFINITY, f64::min);
        let hi = xs.fold(f64::NEG_INFINITY, f64::max);
        if lo > hi {
            return None;
        }
        let (mut x0, mut x1) = padded(lo, hi);
        // an event outside the curves' range is still drawn
        for x in self.events.iter().chain(&self.ticks).map(|e| e.0) {
            if x.is_finite() && (x < x0 || x > x1) {
                (x0, x1) = padded(x0.min(x), x1.max(x));
            }
        }
        Some((x0, x1))
    }

    /// Where the event labels go on a plot area `plot_width` pixels wide
    /// (the charts' is about [`SIZE`]`.0 − 110`): in rows at the top, each
    /// at its event's line (to the left of it at the right edge), in the
    /// first row where it keeps [`LABEL_GAP`] from every other label; the
    /// labels of events first, in order of time, then those of clusters
    /// of ticks. A label that finds no room in [`EVENT_ROWS`] rows is left
    /// out. No two boxes overlap, whatever the width.
    pub fn label_boxes(&self, plot_width: u32) -> Result<Vec<LabelBox>, PlotError> {
        register()?;
        let mut svg = String::new();
        let root = SVGBackend::with_string(&mut svg, (1, 1)).into_drawing_area();
        let range = self.x_range().ok_or(PlotError::Empty)?;
        self.place_labels(&root, range, plot_width as i32)
    }

    /// [`Chart::label_boxes`] with the text measured on `root`, over the
    /// horizontal range `x_range`.
    fn place_labels<DB: DrawingBackend>(
        &self,
        root: &DrawingArea<DB, Shift>,
        x_range: (f64, f64),
        plot_width: i32,
    ) -> Result<Vec<LabelBox>, PlotError> {
        let font: TextStyle = ("sans-serif", EVENT_FONT).into();
        let span = (x_range.1 - x_range.0).max(f64::MIN_POSITIVE);
        let labelled = |list: &[(f64, String)], tick: bool| {
            let mut order: Vec<(usize, bool)> = (0..list.len())
                .filter(|&k| !list[k].1.is_empty() && list[k].0.is_finite())
                .map(|k| (k, tick))
                .collect();
            order.sort_by(|a, b| list[a.0].0.total_cmp(&list[b.0].0));
            order
        };
        let mut order = labelled(&self.events, false);
        order.extend(labelled(&self.ticks, true));
        let mut placed: Vec<LabelBox> = Vec::with_capacity(order.len());
        for (k, tick) in order {
            let (x, label) = if tick {
                &self.ticks[k]
            } else {
                &self.events[k]
            };
            let (w, _) = root
                .estimate_text_size(&format!(" {label} "), &font)
                .map_err(|e| drawing_error(&e))?;
            let width = w as i32;
            let px = ((x - x_range.0) / span * f64::from(plot_width)).round() as i32;
            // to the right of its line, or to the left at the right edge
            let left = if px + width > plot_width {
                (px - width).max(0)
            } else {
                px
            };
            let mut candidate = LabelBox {
                event: k,
                tick,
                row: 0,
                left,
                width: width + LABEL_GAP,
            };
            let free = (0..EVENT_ROWS).find(|&row| {
                candidate.row = row;
                placed.iter().all(|b| !b.overlaps(&candidate))
            });
            if let Some(row) = free {
                candidate.row = row;
                candidate.width = width;
                placed.push(candidate);
            }
        }
        Ok(placed)
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
        let (x0, x1) = self.x_range().ok_or(PlotError::Empty)?;
        let (y0, mut y1) = range(|p| p.1);
        register()?;
        let labels = self.place_labels(root, (x0, x1), PLOT_WIDTH)?;
        let label_rows = labels.iter().map(|l| l.row + 1).max().unwrap_or(0);
        let tick_row = if self.ticks.is_empty() { 0 } else { TICK_ROW };
        // headroom for the legend in the upper right corner, about 22 px
        // per line of a plot area about 450 px high, and for the rows of
        // event labels, so that they cover no curve
        let labelled = self.series.iter().any(|s| !s.label.is_empty());
        let legend = if labelled {
            22 * self.series.len() + 15
        } else {
            0
        };
        let headroom = legend + EVENT_ROW as usize * label_rows + tick_row as usize;
        if headroom > 0 {
            let f = (headroom as f64 / 450.0).min(0.6);
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

        // events: grey vertical lines, labelled in rows below the
        // legend so that no label covers another
        let grey = RGBColor(110, 110, 110);
        for (x, _) in &self.events {
            chart
                .draw_series(std::iter::once(DashedPathElement::new(
                    [(*x, y0), (*x, y1)],
                    6,
                    4,
                    grey.stroke_width(1),
                )))
                .map_err(|e| drawing_error(&e))?;
        }
        // labels placed on PLOT_WIDTH from the left of the plot area
        let left = chart.backend_coord(&(x0, y1));
        let font = ("sans-serif", EVENT_FONT).into_font().color(&grey);
        let top = left.1 + legend as i32 + 2;
        for b in &labels {
            let label = if b.tick {
                &self.ticks[b.event].1
            } else {
                &self.events[b.event].1
            };
            root.draw(&Text::new(
                format!(" {label} "),
                (left.0 + b.left, top + EVENT_ROW * b.row as i32),
                font.clone(),
            ))
            .map_err(|e| drawing_error(&e))?;
        }
        // minor events: ticks in a row below the labels
        let tick_top = top + EVENT_ROW * label_rows as i32;
        for (x, _) in self.ticks.iter().filter(|t| t.0.is_finite()) {
            let (px, _) = chart.backend_coord(&(*x, y1));
            root.draw(&PathElement::new(
                vec![(px, tick_top), (px, tick_top + TICK)],
                grey.stroke_width(1),
            ))
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
        write_text(path, &self.to_svg()?)
    }

    /// Writes the chart as a PNG file.
    pub fn write_png(&self, path: &Path) -> Result<(), PlotError> {
        write_png(path, &self.to_rgb()?, SIZE)
    }
}

/// Writes `pixels` (RGB, row by row) as a PNG file of `size`.
fn write_png(path: &Path, pixels: &[u8], size: (u32, u32)) -> Result<(), PlotError> {
    let io = |source| PlotError::Io {
        path: path.display().to_string(),
        source,
    };
    let file = std::fs::File::create(path).map_err(io)?;
    let mut encoder = png::Encoder::new(std::io::BufWriter::new(file), size.0, size.1);
    encoder.set_color(png::ColorType::Rgb);
    encoder.set_depth(png::BitDepth::Eight);
    let encoded = encoder
        .write_header()
        .and_then(|mut w| w.write_image_data(pixels).and_then(|()| w.finish()));
    encoded.map_err(|e| match e {
        png::EncodingError::IoError(source) => io(source),
        other => drawing_error(&other),
    })
}

/// Writes `svg` to `path`.
fn write_text(path: &Path, svg: &str) -> Result<(), PlotError> {
    std::fs::write(path, svg).map_err(|source| PlotError::Io {
        path: path.display().to_string(),
        source,
    })
}

// ---------- line drawings of configurations ----------

/// A parallel projection seen from the direction of azimuth `azimuth`
/// (from `x` towards `y`) and elevation `elevation` above the `x`–`y`
/// plane, `z` up on the page.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct View {
    /// Azimuth of the direction towards the viewer (rad).
    pub azimuth: f64,
    /// Elevation of the direction towards the viewer (rad).
    pub elevation: f64,
}

impl View {
    /// The isometric view from `(1, 1, 1)`: the three axes are drawn at
    /// 120° to one another, foreshortened alike by `√(2/3)`.
    pub fn isometric() -> Self {
        Self {
            azimuth: std::f64::consts::FRAC_PI_4,
            elevation: (1.0 / 3f64.sqrt()).asin(),
        }
    }

    /// The unit vectors of the page: right, up, and towards the viewer
    /// (`w = (cos e cos a, cos e sin a, sin e)`, `right = z × w / |z × w|`,
    /// `up = w × right`).
    fn axes(&self) -> [[f64; 3]; 3] {
        let (ca, sa) = (self.azimuth.cos(), self.azimuth.sin());
        let (ce, se) = (self.elevation.cos(), self.elevation.sin());
        let w = [ce * ca, ce * sa, se];
        let right = [-sa, ca, 0.0];
        let up = [
            w[1] * right[2] - w[2] * right[1],
            w[2] * right[0] - w[0] * right[2],
            w[0] * right[1] - w[1] * right[0],
        ];
        [right, up, w]
    }

    /// The point `p` on the page: `(right, up)` coordinates, in the units
    /// of `p`, and its depth towards the viewer.
    pub fn project(&self, p: [f64; 3]) -> (f64, f64, f64) {
        let [r, u, w] = self.axes();
        let dot = |a: [f64; 3]| a[0] * p[0] + a[1] * p[1] + a[2] * p[2];
        (dot(r), dot(u), dot(w))
    }
}

/// A line segment of a drawing and the group it belongs to (which sets
/// its colour and its legend entry).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Segment {
    /// First end.
    pub from: [f64; 3],
    /// Second end.
    pub to: [f64; 3],
    /// Index of its group in [`Wireframe::groups`].
    pub group: usize,
}

/// One configuration of a drawing: its segments and marked points.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Panel {
    /// Caption under the panel.
    pub label: String,
    /// Lines.
    pub segments: Vec<Segment>,
    /// Points marked with a dot, with their group.
    pub points: Vec<([f64; 3], usize)>,
}

/// Configurations of a structure drawn side by side as lines in a
/// parallel projection, all at one scale, with a title, a caption under
/// each and a legend naming the groups of lines.
///
/// ```
/// use unfold::io::plot::{Panel, Segment, Wireframe};
///
/// let edge = |from, to| Segment { from, to, group: 0 };
/// let cube = Panel {
///     label: "unit cube".into(),
///     segments: vec![edge([0.0; 3], [1.0, 0.0, 0.0]), edge([0.0; 3], [0.0, 0.0, 1.0])],
///     points: vec![([0.0; 3], 1)],
/// };
/// let svg = Wireframe::new("A cube", ["edges", "corners"]).panel(cube).to_svg().unwrap();
/// assert!(svg.contains("unit cube"));
/// ```
#[derive(Clone, Debug, PartialEq)]
pub struct Wireframe {
    /// Title above the panels.
    pub title: String,
    /// Legend names of the groups, in order (colours of [`Chart`]'s
    /// series).
    pub groups: Vec<String>,
    /// The configurations, left to right.
    pub panels: Vec<Panel>,
    /// The projection.
    pub view: View,
}

/// Size of one panel of a [`Wireframe`], pixels.
pub const PANEL_SIZE: (u32, u32) = (600, 520);

/// Heights of a [`Wireframe`]'s title band and legend band, pixels.
const WIREFRAME_BANDS: (u32, u32) = (50, 70);

impl Wireframe {
    /// An empty drawing, isometric, with its title and the names of its
    /// groups of lines.
    pub fn new(
        title: impl Into<String>,
        groups: impl IntoIterator<Item = impl Into<String>>,
    ) -> Self {
        Self {
            title: title.into(),
            groups: groups.into_iter().map(Into::into).collect(),
            panels: Vec::new(),
            view: View::isometric(),
        }
    }

    /// Adds a panel on the right.
    pub fn panel(mut self, panel: Panel) -> Self {
        self.panels.push(panel);
        self
    }

    /// Sets the projection.
    pub fn view(mut self, view: View) -> Self {
        self.view = view;
        self
    }

    /// Size of the picture, pixels.
    pub fn size(&self) -> (u32, u32) {
        let n = self.panels.len().max(1) as u32;
        (
            n * PANEL_SIZE.0,
            PANEL_SIZE.1 + WIREFRAME_BANDS.0 + WIREFRAME_BANDS.1,
        )
    }

    /// Draws the panels on `root`: the scale is the largest at which every
    /// panel fits its box with a margin, each panel centred in its box;
    /// segments are drawn from the farthest to the nearest.
    fn draw<'d, DB: DrawingBackend + 'd>(
        &self,
        root: &DrawingArea<DB, Shift>,
    ) -> Result<(), PlotError> {
        register()?;
        let finite = |p: &[f64; 3]| p.iter().all(|c| c.is_finite());
        let extents: Vec<Option<[f64; 4]>> = self
            .panels
            .iter()
            .map(|panel| {
                let mut b = [
                    f64::INFINITY,
                    f64::NEG_INFINITY,
                    f64::INFINITY,
                    f64::NEG_INFINITY,
                ];
                let ends = panel.segments.iter().flat_map(|s| [s.from, s.to]);
                for p in ends.chain(panel.points.iter().map(|p| p.0)).filter(finite) {
                    let (u, v, _) = self.view.project(p);
                    b = [b[0].min(u), b[1].max(u), b[2].min(v), b[3].max(v)];
                }
                (b[0] <= b[1]).then_some(b)
            })
            .collect();
        if extents.iter().all(Option::is_none) {
            return Err(PlotError::Empty);
        }
        // one scale for all panels: the largest extent fills 85 % of its box
        let (w, h) = (f64::from(PANEL_SIZE.0), f64::from(PANEL_SIZE.1));
        let scale = extents
            .iter()
            .flatten()
            .map(|b| (0.85 * w / (b[1] - b[0])).min(0.85 * h / (b[3] - b[2])))
            .filter(|s| s.is_finite())
            .fold(f64::INFINITY, f64::min);
        let scale = if scale.is_finite() { scale } else { 1.0 };

        root.fill(&WHITE).map_err(|e| drawing_error(&e))?;
        let (width, _) = self.size();
        let title: TextStyle = ("sans-serif", 22).into();
        let (tw, _) = root
            .estimate_text_size(&self.title, &title)
            .map_err(|e| drawing_error(&e))?;
        root.draw(&Text::new(
            self.title.clone(),
            ((width as i32 - tw as i32) / 2, 14),
            title,
        ))
        .map_err(|e| drawing_error(&e))?;

        let top = WIREFRAME_BANDS.0 as i32;
        for (k, (panel, extent)) in self.panels.iter().zip(&extents).enumerate() {
            let left = k as i32 * PANEL_SIZE.0 as i32;
            if let Some(b) = extent {
                let (cu, cv) = (0.5 * (b[0] + b[1]), 0.5 * (b[2] + b[3]));
                let page = |p: [f64; 3]| {
                    let (u, v, _) = self.view.project(p);
                    (
                        left + (0.5 * w + scale * (u - cu)).round() as i32,
                        top + (0.5 * h - scale * (v - cv)).round() as i32,
                    )
                };
                // far to near
                let mut order: Vec<(f64, &Segment)> = panel
                    .segments
                    .iter()
                    .filter(|s| finite(&s.from) && finite(&s.to))
                    .map(|s| {
                        let mid = [0, 1, 2].map(|i| 0.5 * (s.from[i] + s.to[i]));
                        (self.view.project(mid).2, s)
                    })
                    .collect();
                order.sort_by(|a, b| a.0.total_cmp(&b.0));
                for (_, s) in order {
                    let colour = COLOURS[s.group % COLOURS.len()];
                    root.draw(&PathElement::new(
                        vec![page(s.from), page(s.to)],
                        colour.stroke_width(2),
                    ))
                    .map_err(|e| drawing_error(&e))?;
                }
                for (p, group) in panel.points.iter().filter(|p| finite(&p.0)) {
                    let colour = COLOURS[group % COLOURS.len()];
                    root.draw(&Circle::new(page(*p), 3, colour.filled()))
                        .map_err(|e| drawing_error(&e))?;
                }
            }
            let font: TextStyle = ("sans-serif", 16).into();
            let (lw, _) = root
                .estimate_text_size(&panel.label, &font)
                .map_err(|e| drawing_error(&e))?;
            let x = left + (PANEL_SIZE.0 as i32 - lw as i32) / 2;
            root.draw(&Text::new(
                panel.label.clone(),
                (x, top + PANEL_SIZE.1 as i32),
                font,
            ))
            .map_err(|e| drawing_error(&e))?;
        }

        // legend: a short line of each group's colour and its name
        let font: TextStyle = ("sans-serif", 15).into();
        let y = top + PANEL_SIZE.1 as i32 + 40;
        let mut x = 20;
        for (g, name) in self.groups.iter().enumerate() {
            let colour = COLOURS[g % COLOURS.len()];
            root.draw(&PathElement::new(
                vec![(x, y + 8), (x + 30, y + 8)],
                colour.stroke_width(3),
            ))
            .map_err(|e| drawing_error(&e))?;
            root.draw(&Text::new(name.clone(), (x + 38, y), font.clone()))
                .map_err(|e| drawing_error(&e))?;
            let (nw, _) = root
                .estimate_text_size(name, &font)
                .map_err(|e| drawing_error(&e))?;
            x += 38 + nw as i32 + 30;
        }
        root.present().map_err(|e| drawing_error(&e))?;
        Ok(())
    }

    /// The drawing as SVG text.
    pub fn to_svg(&self) -> Result<String, PlotError> {
        let mut svg = String::new();
        {
            let root = SVGBackend::with_string(&mut svg, self.size()).into_drawing_area();
            self.draw(&root)?;
        }
        Ok(svg)
    }

    /// The drawing as RGB pixels, [`Wireframe::size`], row by row.
    pub fn to_rgb(&self) -> Result<Vec<u8>, PlotError> {
        let size = self.size();
        let mut pixels = vec![0u8; 3 * size.0 as usize * size.1 as usize];
        {
            let root = BitMapBackend::with_buffer(&mut pixels, size).into_drawing_area();
            self.draw(&root)?;
        }
        Ok(pixels)
    }

    /// Writes the drawing as an SVG file.
    pub fn write_svg(&self, path: &Path) -> Result<(), PlotError> {
        write_text(path, &self.to_svg()?)
    }

    /// Writes the drawing as a PNG file.
    pub fn write_png(&self, path: &Path) -> Result<(), PlotError> {
        write_png(path, &self.to_rgb()?, self.size())
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

    /// Labels crowded at one instant and spread over the range, of
    /// events and of ticks: whatever the width, no two boxes overlap,
    /// each lies in one of the rows, and those that find no room are left
    /// out rather than drawn over another.
    #[test]
    fn event_labels_never_overlap() {
        let mut chart = sample();
        for k in 0..30 {
            let x = if k < 15 { 2.0 } else { 0.17 * k as f64 - 2.5 };
            chart = chart
                .event(x, format!("latch {k} locks"))
                .tick(x + 0.01, format!("latch {k}: 3 engages, 2 disengages"));
        }
        for width in [60, 200, 790, 3000] {
            let boxes = chart.label_boxes(width).unwrap();
            assert!(!boxes.is_empty());
            assert!(boxes.len() < 60, "{} at {width}", boxes.len());
            for (i, a) in boxes.iter().enumerate() {
                assert!(a.row < EVENT_ROWS && a.left >= 0, "{a:?}");
                for b in &boxes[i + 1..] {
                    assert!(!a.overlaps(b), "at {width} px: {a:?} {b:?}");
                }
            }
        }
        assert!(chart.to_svg().unwrap().contains("latch 0 locks"));
    }

    /// The isometric view draws the three unit axes with the same length
    /// `√(2/3)` at 120° to one another, `z` straight up.
    #[test]
    fn isometric_projection_foreshortens_the_axes_alike() {
        let view = View::isometric();
        let axes = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]].map(|a| {
            let (u, v, _) = view.project(a);
            (u, v)
        });
        for (u, v) in axes {
            assert!((u.hypot(v) - (2.0f64 / 3.0).sqrt()).abs() < 1e-15);
        }
        for k in 0..3 {
            let (a, b) = (axes[k], axes[(k + 1) % 3]);
            let cos = (a.0 * b.0 + a.1 * b.1) / (2.0 / 3.0);
            assert!((cos + 0.5).abs() < 1e-15, "cos {cos}");
        }
        assert!(axes[2].0.abs() < 1e-15 && axes[2].1 > 0.0);
        // the viewer looks from (1, 1, 1): that corner is the nearest
        assert!(view.project([1.0, 1.0, 1.0]).2 > view.project([0.0, 0.0, 0.0]).2);
    }

    fn square(label: &str, size: f64) -> Panel {
        let corners = [[0.0, 0.0], [size, 0.0], [size, size], [0.0, size]];
        Panel {
            label: label.into(),
            segments: (0..4)
                .map(|k| {
                    let (a, b) = (corners[k], corners[(k + 1) % 4]);
                    Segment {
                        from: [a[0], a[1], 0.0],
                        to: [b[0], b[1], 0.0],
                        group: k % 2,
                    }
                })
                .collect(),
            points: vec![([0.0, 0.0, 0.0], 2)],
        }
    }

    #[test]
    fn wireframe_draws_every_panel_at_one_scale() {
        let drawing = Wireframe::new("Two squares", ["sides", "other sides", "corner"])
            .panel(square("small", 1.0))
            .panel(square("large", 2.0));
        assert_eq!(drawing.size(), (2 * PANEL_SIZE.0, PANEL_SIZE.1 + 120));
        let svg = drawing.to_svg().unwrap();
        for s in [
            "Two squares",
            "small",
            "large",
            "sides",
            "other sides",
            "corner",
        ] {
            assert!(svg.contains(s), "missing {s:?}");
        }
        // 8 sides and 3 legend lines, 2 dots
        let lines = svg.matches("<polyline").count() + svg.matches("<line").count();
        assert!(lines >= 11, "{lines} lines");
        assert!(svg.matches("<circle").count() >= 2);
        // one scale: the large square spans twice the pixels of the small
        let pixels = drawing.to_rgb().unwrap();
        let (w, _) = drawing.size();
        let columns = |range: std::ops::Range<u32>| {
            // within the panels' band (the legend below is blue too)
            let band = WIREFRAME_BANDS.0..WIREFRAME_BANDS.0 + PANEL_SIZE.1;
            let blue = |x: u32| {
                pixels.chunks(3).enumerate().any(|(i, p)| {
                    let (px, py) = (i as u32 % w, i as u32 / w);
                    px == x && band.contains(&py) && p == [31, 119, 180]
                })
            };
            let xs: Vec<u32> = range.filter(|&x| blue(x)).collect();
            xs.last().unwrap() - xs.first().unwrap()
        };
        // (to the width of the lines, 2 px, at both ends of both squares)
        let small = columns(0..PANEL_SIZE.0) as f64;
        let large = columns(PANEL_SIZE.0..2 * PANEL_SIZE.0) as f64;
        assert!((large - 2.0 * small).abs() <= 8.0, "{small} {large}");
        // nothing to draw
        let empty = Wireframe::new("none", ["a"]).panel(Panel::default());
        assert!(matches!(empty.to_svg(), Err(PlotError::Empty)));
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
