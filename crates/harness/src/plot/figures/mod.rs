//! The figures this project reports, built from plain numbers. Each constructor returns a
//! [`Chart`] or [`StackedBars`] with a default title that the caller may replace, ready for
//! [`super::draw`] or [`super::draw_stacked`].
//!
//! Measurements come in as [`KernelSeries`]: per kernel, (x, median, CI) triples as the
//! analysis computes them, plus an optional fitted [`Curve`] sampled at a few x values.

mod detail;
mod scaling;

pub use detail::{
    CommTimes, Percentiles, PhaseTimes, ThetaPoint, ThetaSweep, comm_time, octree_accuracy,
    phase_breakdown, phase_shares, step_percentiles,
};
pub use scaling::{efficiency, karp_flatt, speedup, time_per_step, weak_efficiency};

use super::spec::{Axis, Band, Chart, Point, Scale, Series, SeriesStyle};

/// One measured value at `x`: the median over repetitions and its confidence interval.
#[derive(Clone, Debug, PartialEq)]
pub struct Measured {
    /// Where it was measured, in the figure's x unit (threads, particles, bytes…).
    pub x: f64,
    /// The median over repetitions, in the figure's y unit (seconds, speedup…).
    pub median: f64,
    /// The confidence interval `(lo, hi)` drawn as an error bar; `None` draws none.
    pub ci: Option<(f64, f64)>,
    /// Drawn hollow: the case ran more threads × ranks than the machine has logical CPUs.
    pub oversubscribed: bool,
    /// Drawn crossed: the case ran on one thread although given several (the kernel's choice).
    pub one_thread: bool,
}

impl Measured {
    /// A median at `x` without an interval, not oversubscribed.
    pub fn new(x: f64, median: f64) -> Self {
        Measured {
            x,
            median,
            ci: None,
            oversubscribed: false,
            one_thread: false,
        }
    }

    /// A median at `x` with its confidence interval `[ci_lo, ci_hi]`.
    pub fn with_ci(x: f64, median: f64, ci_lo: f64, ci_hi: f64) -> Self {
        Measured {
            ci: Some((ci_lo, ci_hi)),
            ..Measured::new(x, median)
        }
    }

    /// The value marked (drawn hollow) when `oversubscribed` is true.
    pub fn oversubscribed(mut self, oversubscribed: bool) -> Self {
        self.oversubscribed = oversubscribed;
        self
    }

    /// The value marked (drawn crossed) when it ran on one thread although given several.
    pub fn one_thread(mut self, one_thread: bool) -> Self {
        self.one_thread = one_thread;
        self
    }

    fn point(&self) -> Point {
        let point = Point::new(self.x, self.median)
            .hollow(self.oversubscribed)
            .crossed(self.one_thread);
        match self.ci {
            Some((lo, hi)) => point.err(lo, hi),
            None => point,
        }
    }
}

/// A model curve sampled at some x values, with an optional confidence band `(x, lo, hi)`.
#[derive(Clone, Debug, PartialEq)]
pub struct Curve {
    /// Legend text, e.g. `naive: T ∝ n^1.98` or `Amdahl f = 0.031`.
    pub(crate) label: String,
    /// `(x, y)` samples of the curve in increasing x, joined by a dashed line.
    pub points: Vec<(f64, f64)>,
    /// `(x, lo, hi)` of the curve's confidence band, shaded; empty draws no band.
    pub band: Vec<(f64, f64, f64)>,
}

impl Curve {
    /// A curve through `points` with legend text `label` and no band.
    pub fn new(label: impl Into<String>, points: Vec<(f64, f64)>) -> Self {
        Curve {
            label: label.into(),
            points,
            band: Vec::new(),
        }
    }

    /// The curve `f` sampled at `xs` (see [`grid`]).
    pub fn from_fn(label: impl Into<String>, xs: &[f64], f: impl Fn(f64) -> f64) -> Self {
        Curve::new(label, xs.iter().map(|&x| (x, f(x))).collect())
    }

    /// The curve with the confidence band `(x, lo, hi)` shaded around it.
    pub fn with_band(mut self, band: Vec<(f64, f64, f64)>) -> Self {
        self.band = band;
        self
    }
}

/// `count` x values from `lo` to `hi`, evenly spaced on the given scale (for sampling curves).
pub fn grid(lo: f64, hi: f64, count: usize, scale: Scale) -> Vec<f64> {
    let count = count.max(2);
    let log = scale == Scale::Log && lo > 0.0 && hi > 0.0;
    (0..count)
        .map(|i| {
            let t = i as f64 / (count - 1) as f64;
            if log {
                lo * (hi / lo).powf(t)
            } else {
                lo + t * (hi - lo)
            }
        })
        .collect()
}

/// The smallest and largest finite value.
fn extent(values: impl Iterator<Item = f64>) -> Option<(f64, f64)> {
    let finite: Vec<f64> = values.filter(|v| v.is_finite()).collect();
    let lo = finite.iter().copied().reduce(f64::min)?;
    Some((lo, finite.iter().copied().fold(lo, f64::max)))
}

/// One kernel's measurements and, optionally, the model fitted to them.
#[derive(Clone, Debug, PartialEq)]
pub struct KernelSeries {
    /// The kernel's name, the legend text of its measurements.
    pub name: String,
    /// The measured values, one per x.
    pub measured: Vec<Measured>,
    /// The model fitted to them, drawn dashed in the same colour; `None` joins the
    /// measurements with a line instead.
    pub fit: Option<Curve>,
}

impl KernelSeries {
    /// A kernel's measurements without a fitted curve.
    pub fn new(name: impl Into<String>, measured: Vec<Measured>) -> Self {
        KernelSeries {
            name: name.into(),
            measured,
            fit: None,
        }
    }

    #[cfg(test)]
    /// From `(x, median, ci_lo, ci_hi)` rows.
    pub(crate) fn from_rows(name: impl Into<String>, rows: &[(f64, f64, f64, f64)]) -> Self {
        let measured = rows
            .iter()
            .map(|&(x, m, lo, hi)| Measured::with_ci(x, m, lo, hi))
            .collect();
        KernelSeries::new(name, measured)
    }

    /// The series with `fit` drawn through its measurements.
    pub fn with_fit(mut self, fit: Curve) -> Self {
        self.fit = Some(fit);
        self
    }
}

/// A chart with one colour per kernel: measured medians with CI bars (joined by a line unless
/// a fit is drawn through them), the fit dashed in the same colour, its band shaded.
fn kernel_chart(title: &str, x: Axis, y: Axis, kernels: &[KernelSeries], caption: &str) -> Chart {
    let mut chart = Chart::new(title, x, y).caption(caption);
    let mut band_labelled = false;
    for (k, kernel) in kernels.iter().enumerate() {
        let style = if kernel.fit.is_some() {
            SeriesStyle::Markers
        } else {
            SeriesStyle::LineMarkers
        };
        let points = kernel.measured.iter().map(Measured::point).collect();
        chart
            .series
            .push(Series::new(kernel.name.as_str(), points, style).color(k));
        let Some(fit) = &kernel.fit else { continue };
        chart.series.push(
            Series::from_xy(
                fit.label.as_str(),
                fit.points.iter().copied(),
                SeriesStyle::Dashed,
            )
            .color(k),
        );
        if !fit.band.is_empty() {
            let label = if band_labelled {
                ""
            } else {
                "shaded: 95% CI of the fit"
            };
            band_labelled = true;
            chart.bands.push(Band {
                label: label.into(),
                x: fit.band.iter().map(|b| b.0).collect(),
                lo: fit.band.iter().map(|b| b.1).collect(),
                hi: fit.band.iter().map(|b| b.2).collect(),
                color: Some(k),
            });
        }
    }
    chart
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn grids_span_the_range_on_either_scale() {
        let lin = grid(1.0, 3.0, 3, Scale::Linear);
        assert_eq!(lin, [1.0, 2.0, 3.0]);
        let log = grid(1.0, 100.0, 3, Scale::Log);
        assert!((log[1] - 10.0).abs() < 1e-9);
        assert_eq!(grid(0.0, 1.0, 0, Scale::Log).len(), 2);
    }

    #[test]
    fn kernel_charts_give_each_kernel_one_colour_for_points_fit_and_band() {
        let fit = Curve::new("fit", vec![(1.0, 1.0), (2.0, 2.0)])
            .with_band(vec![(1.0, 0.9, 1.1), (2.0, 1.8, 2.2)]);
        let kernels = [
            KernelSeries::from_rows("a", &[(1.0, 1.0, 0.9, 1.1)]),
            KernelSeries::from_rows("b", &[(1.0, 2.0, 1.9, 2.1)]).with_fit(fit),
        ];
        let chart = kernel_chart("t", Axis::linear("x"), Axis::linear("y"), &kernels, "c");
        let colors: Vec<_> = chart
            .series
            .iter()
            .map(|s| (s.label.as_str(), s.color))
            .collect();
        assert_eq!(colors, [("a", Some(0)), ("b", Some(1)), ("fit", Some(1))]);
        assert_eq!(chart.bands[0].color, Some(1));
        assert_eq!(chart.series[0].points[0].y_err, Some((0.9, 1.1)));
    }
}
