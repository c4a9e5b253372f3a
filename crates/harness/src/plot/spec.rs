//! What a figure shows, as plain data: axes, series, bands, reference lines and shaded regions
//! for an x-y chart, and categories with named segments for a stacked bar chart. Nothing here
//! depends on plotters, so analysis code can build figures whether or not drawing is compiled in.

use std::path::PathBuf;

/// An x-y chart: series of points and lines over two axes, with optional shaded bands,
/// horizontal reference lines and shaded x-ranges. The legend lists every labelled item.
#[derive(Clone, Debug, PartialEq)]
pub struct Chart {
    /// The heading drawn above the plot.
    pub title: String,
    /// One line under the plot, typically the machine and commit the data came from.
    pub caption: String,
    /// The horizontal axis.
    pub x: Axis,
    /// The vertical axis.
    pub y: Axis,
    /// The data and fitted curves, drawn in order (later ones on top).
    pub series: Vec<Series>,
    /// Shaded bands (confidence bands of fits), drawn beneath the series.
    pub bands: Vec<Band>,
    pub(crate) hlines: Vec<RefLine>,
    /// Shaded vertical strips (e.g. where a curve is extrapolated), drawn beneath everything else.
    pub regions: Vec<Region>,
    /// Legend text explaining hollow markers; shown only when some point is hollow.
    pub(crate) hollow_label: String,
    /// Legend text explaining crossed markers; shown only when some point is crossed.
    pub crossed_label: String,
}

impl Chart {
    /// An empty chart titled `title` over the axes `x` and `y`, with no caption.
    pub fn new(title: impl Into<String>, x: Axis, y: Axis) -> Self {
        Chart {
            title: title.into(),
            caption: String::new(),
            x,
            y,
            series: Vec::new(),
            bands: Vec::new(),
            hlines: Vec::new(),
            regions: Vec::new(),
            hollow_label: "hollow: oversubscribed".into(),
            crossed_label: "crossed: ran on 1 thread".into(),
        }
    }

    /// The chart with `caption` as the line under the plot.
    pub fn caption(mut self, caption: impl Into<String>) -> Self {
        self.caption = caption.into();
        self
    }
}

/// How values are spaced along an axis.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Scale {
    /// Equal steps for equal differences.
    Linear,
    /// Base-10 logarithmic. Falls back to linear when any value on the axis is not positive.
    Log,
}

/// What the numbers on an axis measure; decides how tick labels are written.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Unit {
    /// Plain numbers: `0.5`, `12`, `1e-4`.
    Plain,
    /// Seconds, written with the prefix that suits each tick: `250 ns`, `10 µs`, `1.5 ms`, `2 s`.
    Seconds,
    /// Counts such as particles or threads: `500`, `10k`, `2.5M`; linear ticks are whole numbers.
    Count,
    /// Fractions shown as percentages: 0.25 is written `25%`.
    Percent,
    /// Bytes with decimal prefixes: `512 B`, `64 kB`, `8 MB`.
    Bytes,
}

/// One axis of a [`Chart`]: its title, scale, unit of the tick labels and range.
#[derive(Clone, Debug, PartialEq)]
pub struct Axis {
    pub(crate) label: String,
    /// Linear or logarithmic spacing.
    pub scale: Scale,
    /// How tick labels are written (plain, seconds, counts, percent, bytes).
    pub unit: Unit,
    /// Fixed bounds; `None` fits the data. Points outside a fixed range are not drawn.
    pub range: Option<(f64, f64)>,
    /// Extend the fitted range to include zero (linear axes only).
    pub(crate) include_zero: bool,
    /// Names for the positions 0, 1, 2, ... ; when non-empty the axis is categorical and linear.
    pub(crate) categories: Vec<String>,
}

impl Axis {
    /// A linear axis titled `label`, plain numbers, fitted to the data.
    pub fn linear(label: impl Into<String>) -> Self {
        Axis {
            label: label.into(),
            scale: Scale::Linear,
            unit: Unit::Plain,
            range: None,
            include_zero: false,
            categories: Vec::new(),
        }
    }

    /// A base-10 logarithmic axis titled `label`, plain numbers, fitted to the data.
    pub fn log(label: impl Into<String>) -> Self {
        Axis {
            scale: Scale::Log,
            ..Axis::linear(label)
        }
    }

    pub(crate) fn categorical(label: impl Into<String>, categories: Vec<String>) -> Self {
        Axis {
            categories,
            ..Axis::linear(label)
        }
    }

    /// The axis with its tick labels written in `unit`.
    pub fn unit(mut self, unit: Unit) -> Self {
        self.unit = unit;
        self
    }

    /// The axis fixed to `[lo, hi]` instead of fitted to the data.
    pub fn range(mut self, lo: f64, hi: f64) -> Self {
        self.range = Some((lo, hi));
        self
    }

    pub(crate) fn starting_at_zero(mut self) -> Self {
        self.include_zero = true;
        self
    }
}

/// How a series is drawn.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SeriesStyle {
    /// A solid line through the points, no markers.
    Line,
    /// Markers only, no line (measurements that are not a curve).
    Markers,
    /// A solid line with a marker at each point.
    LineMarkers,
    /// A dashed line, no markers (ideals and models, e.g. `S = p`).
    Dashed,
}

/// One labelled sequence of points on a [`Chart`].
#[derive(Clone, Debug, PartialEq)]
pub struct Series {
    /// Legend text; an empty label keeps the series out of the legend.
    pub(crate) label: String,
    /// The points in drawing order; lines join them in this order.
    pub points: Vec<Point>,
    /// Line, markers, both, or dashed line.
    pub style: SeriesStyle,
    /// Index into the palette ([`super::palette::PALETTE`], wrapping); `None` uses the
    /// series' position in the chart. Give a kernel's points and its fit the same index.
    pub color: Option<usize>,
}

impl Series {
    /// A series labelled `label` (empty: not in the legend) coloured by its position.
    pub fn new(label: impl Into<String>, points: Vec<Point>, style: SeriesStyle) -> Self {
        Series {
            label: label.into(),
            points,
            style,
            color: None,
        }
    }

    /// A series from bare (x, y) pairs.
    pub fn from_xy(
        label: impl Into<String>,
        xy: impl IntoIterator<Item = (f64, f64)>,
        style: SeriesStyle,
    ) -> Self {
        let points = xy.into_iter().map(|(x, y)| Point::new(x, y)).collect();
        Series::new(label, points, style)
    }

    /// The series drawn with palette colour (and marker) `index` instead of its position's.
    pub fn color(mut self, index: usize) -> Self {
        self.color = Some(index);
        self
    }
}

/// One data point. Non-finite coordinates are skipped when drawing (a line breaks there).
#[derive(Clone, Debug, PartialEq)]
pub struct Point {
    pub x: f64,
    pub y: f64,
    /// Error bar from `lo` to `hi` in y (e.g. a 95% confidence interval).
    pub(crate) y_err: Option<(f64, f64)>,
    /// Drawn as an outline marker, e.g. for an oversubscribed measurement.
    pub(crate) hollow: bool,
    /// Drawn with a cross over the marker, e.g. for a case that ran on one thread although
    /// given several.
    pub(crate) crossed: bool,
    /// Text written next to the marker, e.g. `θ=0.5`.
    pub(crate) label: Option<String>,
}

impl Point {
    pub fn new(x: f64, y: f64) -> Self {
        Point {
            x,
            y,
            y_err: None,
            hollow: false,
            crossed: false,
            label: None,
        }
    }

    pub fn err(mut self, lo: f64, hi: f64) -> Self {
        self.y_err = Some((lo, hi));
        self
    }

    pub(crate) fn hollow(mut self, hollow: bool) -> Self {
        self.hollow = hollow;
        self
    }

    pub(crate) fn crossed(mut self, crossed: bool) -> Self {
        self.crossed = crossed;
        self
    }

    pub(crate) fn label(mut self, label: impl Into<String>) -> Self {
        self.label = Some(label.into());
        self
    }
}

/// A shaded band between `lo` and `hi` along `x` (e.g. the confidence band of a fit).
/// The three vectors are read in step; extra entries of a longer one are ignored.
#[derive(Clone, Debug, PartialEq)]
pub struct Band {
    pub(crate) label: String,
    pub x: Vec<f64>,
    pub lo: Vec<f64>,
    pub hi: Vec<f64>,
    pub color: Option<usize>,
}

/// A horizontal line across the whole plot at `y` (e.g. ideal efficiency 1).
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct RefLine {
    pub(crate) label: String,
    pub y: f64,
    /// Palette index; `None` draws it dark grey.
    pub color: Option<usize>,
    pub(crate) dashed: bool,
}

/// A shaded vertical strip from `x_from` to `x_to`, labelled inside the plot and in the
/// legend (e.g. where a curve is a prediction with no measurement behind it).
#[derive(Clone, Debug, PartialEq)]
pub struct Region {
    pub(crate) label: String,
    pub(crate) x_from: f64,
    pub(crate) x_to: f64,
}

/// Horizontal stacked bars: one bar per category, one coloured segment per named part.
/// `segments[k].1[i]` is the size of part k in category i; missing, negative or non-finite
/// sizes count as zero.
#[derive(Clone, Debug, PartialEq)]
pub struct StackedBars {
    pub title: String,
    pub caption: String,
    pub(crate) value_label: String,
    pub(crate) value_unit: Unit,
    pub(crate) categories: Vec<String>,
    pub(crate) segments: Vec<(String, Vec<f64>)>,
}

/// The files a render wrote.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Rendered {
    pub svg: PathBuf,
    pub png: PathBuf,
}
