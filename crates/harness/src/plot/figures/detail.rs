//! Figures that look inside a run: where a step's time goes, how its time is spread, how the
//! octree trades accuracy for cost, and how measured communication compares with a model.

use super::{Curve, Measured, extent};
use crate::plot::spec::{
    Axis, Band, Chart, Point, Region, Scale, Series, SeriesStyle, StackedBars, Unit,
};

/// Seconds per step spent in each phase of one case, phases named.
#[derive(Clone, Debug, PartialEq)]
pub struct PhaseTimes {
    /// The case's label, the bar's name.
    pub case: String,
    /// `(phase name, seconds per step)` in the order the bar's segments are stacked.
    pub phases: Vec<(String, f64)>,
}

/// One horizontal bar per case, split into phases: every phase name any case spent time in, in
/// order of first appearance (a case without it has none of that time).
pub fn phase_breakdown(cases: &[PhaseTimes], caption: &str) -> StackedBars {
    let mut names: Vec<&str> = Vec::new();
    for (name, _) in cases.iter().flat_map(|c| &c.phases) {
        if !names.contains(&name.as_str()) {
            names.push(name);
        }
    }
    let column = |name: &str| -> Vec<f64> {
        cases
            .iter()
            .map(|c| {
                c.phases
                    .iter()
                    .find(|(n, _)| n == name)
                    .map_or(0.0, |(_, v)| *v)
            })
            .collect()
    };
    StackedBars {
        title: "Where a step's time goes".into(),
        caption: caption.into(),
        value_label: "time per step".into(),
        value_unit: Unit::Seconds,
        categories: cases.iter().map(|c| c.case.clone()).collect(),
        // A phase no case spent time in takes no colour: the others keep distinct ones.
        segments: names
            .iter()
            .map(|n| (n.to_string(), column(n)))
            .filter(|(_, values)| values.iter().any(|v| v.is_finite() && *v > 0.0))
            .collect(),
    }
}

/// The same bars as [`phase_breakdown`] with each case scaled to its own total, to compare
/// where the time goes in cases of very different cost.
pub fn phase_shares(cases: &[PhaseTimes], caption: &str) -> StackedBars {
    let mut bars = phase_breakdown(cases, caption);
    let totals: Vec<f64> = (0..cases.len())
        .map(|i| {
            bars.segments
                .iter()
                .map(|(_, v)| v[i])
                .filter(|v| v.is_finite() && *v > 0.0)
                .sum()
        })
        .collect();
    for (_, values) in &mut bars.segments {
        for (v, total) in values.iter_mut().zip(&totals) {
            *v = if *total > 0.0 { *v / total } else { 0.0 };
        }
    }
    bars.title = "Share of a step's time per phase".into();
    bars.value_label = "share of time per step".into();
    bars.value_unit = Unit::Percent;
    bars
}

/// Step-time percentiles of one kernel, in seconds.
#[derive(Clone, Debug, PartialEq)]
pub struct Percentiles {
    /// The row's label: the case (kernel and its settings).
    pub kernel: String,
    /// The median step time, seconds.
    pub p50: f64,
    /// The 90th-percentile step time, seconds.
    pub p90: f64,
    /// The 99th-percentile step time, seconds.
    pub p99: f64,
    /// The slowest step, seconds.
    pub max: f64,
}

/// p50, p90, p99 and max step time per case on a log time axis, one row per case (the first on
/// top, its whole name on the left); the four markers of a case sit one above the other around
/// its row so that close values stay visible.
pub fn step_percentiles(rows: &[Percentiles], caption: &str) -> Chart {
    let names = rows.iter().rev().map(|r| r.kernel.clone()).collect();
    let x = Axis::log("time per step").unit(Unit::Seconds);
    let y = Axis::categorical("", names);
    let mut chart = Chart::new("Step-time percentiles per case", x, y).caption(caption);
    let last = rows.len().saturating_sub(1);
    for (k, name) in ["p50", "p90", "p99", "max"].into_iter().enumerate() {
        let offset = (1.5 - k as f64) * 0.1;
        let points = rows
            .iter()
            .enumerate()
            .map(|(i, r)| Point::new([r.p50, r.p90, r.p99, r.max][k], (last - i) as f64 + offset))
            .collect();
        chart
            .series
            .push(Series::new(name, points, SeriesStyle::Markers).color(k));
    }
    chart
}

/// One run of a tree code: its setting (e.g. "θ=0.5", or an external code's requested
/// precision), cost (seconds per step) and median relative force error.
#[derive(Clone, Debug, PartialEq)]
pub struct ThetaPoint {
    /// The label written next to the point, e.g. `θ=0.5`.
    pub setting: String,
    /// The cost, seconds per step (the x of the figure).
    pub seconds: f64,
    /// The median relative force error (the y), dimensionless.
    pub error: f64,
}

/// Runs of one code over its accuracy settings, in the order to join them (usually by θ).
#[derive(Clone, Debug, PartialEq)]
pub struct ThetaSweep {
    /// The code's name, its legend text.
    pub name: String,
    /// Its runs, joined by a line in this order.
    pub points: Vec<ThetaPoint>,
}

/// Force error against cost over each code's settings on log-log axes, each point labelled
/// with its setting.
pub fn octree_accuracy(sweeps: &[ThetaSweep], caption: &str) -> Chart {
    let x = Axis::log("time per step").unit(Unit::Seconds);
    let y = Axis::log("median relative force error");
    let mut chart = Chart::new("Long-range codes: force error vs cost", x, y).caption(caption);
    for (k, sweep) in sweeps.iter().enumerate() {
        let points = sweep
            .points
            .iter()
            .map(|p| Point::new(p.seconds, p.error).label(p.setting.clone()))
            .collect();
        chart
            .series
            .push(Series::new(sweep.name.as_str(), points, SeriesStyle::LineMarkers).color(k));
    }
    chart
}

/// Palette indices of the communication figure: the model in blue, measurements in vermillion.
const PREDICTED: usize = 0;
const MEASURED: usize = 1;

/// Measured communication time per step and the model's prediction over an x (ranks, bytes).
#[derive(Clone, Debug, PartialEq)]
pub struct CommTimes {
    /// The x axis, e.g. `Axis::linear("ranks")` or `Axis::log("message size").unit(Unit::Bytes)`;
    /// the time axis uses the same scale.
    pub x: Axis,
    /// The measured communication times per step, seconds, with their intervals.
    pub measured: Vec<Measured>,
    /// The model's prediction, seconds per step, with its uncertainty band.
    pub predicted: Curve,
}

/// Measured points with CIs, the predicted line with its uncertainty band, and shaded regions
/// where the prediction goes beyond the measured x range.
pub fn comm_time(comm: &CommTimes, caption: &str) -> Chart {
    let mut y = Axis::log("communication time per step").unit(Unit::Seconds);
    if comm.x.scale == Scale::Linear {
        y = Axis {
            scale: Scale::Linear,
            ..y
        }
        .starting_at_zero();
    }
    let mut chart =
        Chart::new("Communication: measured vs predicted", comm.x.clone(), y).caption(caption);
    let predicted = &comm.predicted;
    if !predicted.band.is_empty() {
        chart.bands.push(Band {
            label: "prediction uncertainty".into(),
            x: predicted.band.iter().map(|b| b.0).collect(),
            lo: predicted.band.iter().map(|b| b.1).collect(),
            hi: predicted.band.iter().map(|b| b.2).collect(),
            color: Some(PREDICTED),
        });
    }
    let line = Series::from_xy(
        predicted.label.as_str(),
        predicted.points.iter().copied(),
        SeriesStyle::Dashed,
    );
    chart.series.push(line.color(PREDICTED));
    let points = comm.measured.iter().map(Measured::point).collect();
    chart.series.push(
        Series::new("measured (median, 95% CI)", points, SeriesStyle::Markers).color(MEASURED),
    );

    let measured = extent(comm.measured.iter().map(|m| m.x));
    let predicted_x = predicted.points.iter().map(|p| p.0);
    let predicted_x = extent(predicted_x.chain(predicted.band.iter().map(|b| b.0)));
    // Shaded: the predicted x range beyond the measured one on either side, or all of it
    // without measurements. Only the first part is named in the legend.
    let spans = match (predicted_x, measured) {
        (None, _) => vec![],
        (Some(predicted), None) => vec![predicted],
        (Some((p_lo, p_hi)), Some((m_lo, m_hi))) => vec![(m_hi, p_hi), (p_lo, m_lo)],
    };
    let spans = spans.into_iter().filter(|(from, to)| to > from);
    for (k, (x_from, x_to)) in spans.enumerate() {
        let label = if k == 0 {
            "prediction only (not measured)"
        } else {
            ""
        };
        let label = label.into();
        chart.regions.push(Region {
            label,
            x_from,
            x_to,
        });
    }
    chart
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn prediction_beyond_measurements_is_marked() {
        let comm = CommTimes {
            x: Axis::linear("ranks"),
            measured: vec![Measured::new(1.0, 1e-4), Measured::new(2.0, 2e-4)],
            predicted: Curve::new("model", vec![(1.0, 1e-4), (8.0, 9e-4)]),
        };
        let chart = comm_time(&comm, "");
        assert_eq!(chart.regions.len(), 1);
        assert_eq!((chart.regions[0].x_from, chart.regions[0].x_to), (2.0, 8.0));
        assert_eq!(chart.y.scale, Scale::Linear);
    }

    #[test]
    fn percentile_markers_of_a_kernel_stay_within_its_slot() {
        let rows = [Percentiles {
            kernel: "naive".into(),
            p50: 1e-3,
            p90: 1.1e-3,
            p99: 2e-3,
            max: 5e-3,
        }];
        let chart = step_percentiles(&rows, "");
        assert_eq!(chart.series.len(), 4);
        assert!(chart.series.iter().all(|s| s.points[0].y.abs() < 0.5));
        assert_eq!(chart.y.categories, ["naive"]);
    }

    #[test]
    fn phases_keep_case_order() {
        let case = |name: &str, interact| PhaseTimes {
            case: name.into(),
            phases: vec![
                ("build".into(), 0.0),
                ("interact".into(), interact),
                ("integrate".into(), 1e-5),
            ],
        };
        let bars = phase_breakdown(&[case("a", 1e-3), case("b", 2e-3)], "");
        assert_eq!(bars.categories, ["a", "b"]);
        // `build` is zero in every case: left out.
        assert_eq!(bars.segments[0].0, "interact");
        assert_eq!(bars.segments[0].1, [1e-3, 2e-3]);
        // A program's own phases join the legend after the others; cases without them get none.
        let own = PhaseTimes {
            case: "c".into(),
            phases: vec![("comm".into(), 3e-3), ("interact".into(), 1e-3)],
        };
        let bars = phase_breakdown(&[case("a", 1e-3), own], "");
        let names: Vec<&str> = bars.segments.iter().map(|(n, _)| n.as_str()).collect();
        assert_eq!(names, ["interact", "integrate", "comm"]);
        assert_eq!(bars.segments[2].1, [0.0, 3e-3]);
        assert_eq!(bars.segments[0].1, [1e-3, 1e-3]);
        let shares = phase_shares(&[case("a", 1e-3), case("b", 0.0)], "");
        let a: f64 = shares.segments.iter().map(|(_, v)| v[0]).sum();
        assert!((a - 1.0).abs() < 1e-12);
        assert!(
            shares
                .segments
                .iter()
                .all(|(_, v)| v[1] == 0.0 || v[1] == 1.0)
        );
    }
}
