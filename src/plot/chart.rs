//! Drawing a [`Chart`]: axes fitted to the data, the page around them, the legend entries,
//! and then the plot area's contents (see [`super::canvas`]).

use plotters::coord::Shift;
use plotters::prelude::*;

use super::axis::ResolvedAxis;
use super::canvas::Canvas;
use super::coord::AxisCoord;
use super::layout::{self, Frame};
use super::legend::{Entry, Swatch};
use super::palette::{self, REFERENCE};
use super::shapes::{DrawResult, rgb};
use super::spec::{Chart, Point, Scale, SeriesStyle};
use super::text::{self, TICK_SIZE};

pub const BAND_ALPHA: f64 = 0.18;
pub const REGION_ALPHA: f64 = 0.09;

pub type Plot<'a, DB> = ChartContext<'a, DB, Cartesian2d<AxisCoord, AxisCoord>>;

pub fn draw<DB: DrawingBackend>(root: &DrawingArea<DB, Shift>, chart: &Chart) -> DrawResult {
    let mut x = ResolvedAxis::resolve(&chart.x, x_values(chart));
    let y = ResolvedAxis::resolve(&chart.y, y_values(chart));
    let entries = legend_entries(chart);
    let frame = layout::frame(root, &chart.title, &chart.caption, &entries)?;
    shorten_categories(root, &frame, &mut x);

    let y_area = layout::y_label_area(root, &y, TICK_SIZE);
    let mut builder = ChartBuilder::on(&frame.plot);
    builder
        .margin_top(8)
        .margin_left(10)
        .margin_right(if frame.legend.is_some() { 12 } else { 24 })
        .x_label_area_size(layout::x_label_area())
        .y_label_area_size(y_area);
    let mut plot = builder
        .build_cartesian_2d(AxisCoord(x.clone()), AxisCoord(y.clone()))
        .map_err(|e| e.to_string())?;
    plot.configure_mesh()
        .x_desc(chart.x.label.as_str())
        .y_desc(chart.y.label.as_str())
        .label_style(text::style(TICK_SIZE))
        .axis_desc_style(text::style(text::AXIS_LABEL_SIZE))
        .bold_line_style(BLACK.mix(0.14))
        .light_line_style(BLACK.mix(0.05))
        .draw()
        .map_err(|e| e.to_string())?;

    let canvas = Canvas {
        root,
        plot: &plot,
        x: &x,
        y: &y,
    };
    let drew_data = canvas.draw_contents(chart)?;
    if !drew_data {
        canvas.note_no_data()?;
    }
    frame.draw_legend(8)
}

/// Every x value the chart shows, for fitting the axis; with labelled points, one more value
/// 12% of the span beyond the largest so that the last label fits right of its marker.
fn x_values(chart: &Chart) -> Vec<f64> {
    let points = shown_points(chart).map(|p| p.x);
    let bands = band_triples(chart).map(|(x, _, _)| x);
    let regions = chart.regions.iter().flat_map(|r| [r.x_from, r.x_to]);
    let mut values: Vec<f64> = points
        .chain(bands)
        .chain(regions)
        .filter(|v| v.is_finite())
        .collect();
    let labelled = chart
        .series
        .iter()
        .flat_map(|s| &s.points)
        .any(|p| p.label.is_some());
    let (Some(lo), Some(hi)) = (
        values.iter().copied().reduce(f64::min),
        values.iter().copied().reduce(f64::max),
    ) else {
        return values;
    };
    if labelled && hi > lo {
        let log = chart.x.scale == Scale::Log && lo > 0.0;
        values.push(if log {
            hi * (hi / lo).powf(0.12)
        } else {
            hi + 0.12 * (hi - lo)
        });
    }
    values
}

/// Every y value the chart shows: points with their error bars, bands and reference lines.
fn y_values(chart: &Chart) -> Vec<f64> {
    let mut values = Vec::new();
    for p in shown_points(chart) {
        values.push(p.y);
        values.extend(p.y_err.map(|(lo, hi)| [lo, hi]).into_iter().flatten());
    }
    values.extend(band_triples(chart).flat_map(|(_, lo, hi)| [lo, hi]));
    values.extend(chart.hlines.iter().map(|h| h.y));
    values
}

/// Points that can be drawn: both coordinates finite. Only these shape the axes.
fn shown_points(chart: &Chart) -> impl Iterator<Item = &Point> {
    let finite = |p: &&Point| p.x.is_finite() && p.y.is_finite();
    chart.series.iter().flat_map(|s| &s.points).filter(finite)
}

/// Band entries `(x, lo, hi)` with all three finite.
fn band_triples(chart: &Chart) -> impl Iterator<Item = (f64, f64, f64)> + '_ {
    let triples = chart
        .bands
        .iter()
        .flat_map(|b| b.x.iter().zip(&b.lo).zip(&b.hi));
    let triples = triples.map(|((&x, &lo), &hi)| (x, lo, hi));
    triples.filter(|(x, lo, hi)| x.is_finite() && lo.is_finite() && hi.is_finite())
}

pub fn series_color(index: usize, color: Option<usize>) -> RGBColor {
    rgb(palette::color(color.unwrap_or(index)))
}

fn legend_entries(chart: &Chart) -> Vec<Entry> {
    let mut entries = Vec::new();
    for (i, s) in chart
        .series
        .iter()
        .enumerate()
        .filter(|(_, s)| !s.label.is_empty())
    {
        let color = series_color(i, s.color);
        let marker = palette::marker(s.color.unwrap_or(i));
        let swatch = match s.style {
            SeriesStyle::Line => Swatch::Line {
                color,
                dashed: false,
                marker: None,
            },
            SeriesStyle::Dashed => Swatch::Line {
                color,
                dashed: true,
                marker: None,
            },
            SeriesStyle::LineMarkers => Swatch::Line {
                color,
                dashed: false,
                marker: Some(marker),
            },
            SeriesStyle::Markers => Swatch::Markers { color, marker },
        };
        entries.push(Entry {
            label: s.label.clone(),
            swatch,
        });
    }
    for (i, b) in chart
        .bands
        .iter()
        .enumerate()
        .filter(|(_, b)| !b.label.is_empty())
    {
        let swatch = Swatch::Fill {
            color: series_color(i, b.color),
            alpha: BAND_ALPHA * 1.5,
        };
        entries.push(Entry {
            label: b.label.clone(),
            swatch,
        });
    }
    for h in chart.hlines.iter().filter(|h| !h.label.is_empty()) {
        let color = h.color.map_or(rgb(REFERENCE), |c| rgb(palette::color(c)));
        let swatch = Swatch::Line {
            color,
            dashed: h.dashed,
            marker: None,
        };
        entries.push(Entry {
            label: h.label.clone(),
            swatch,
        });
    }
    for r in chart.regions.iter().filter(|r| !r.label.is_empty()) {
        let swatch = Swatch::Fill {
            color: rgb(REFERENCE),
            alpha: REGION_ALPHA * 2.0,
        };
        entries.push(Entry {
            label: r.label.clone(),
            swatch,
        });
    }
    let any_hollow = chart
        .series
        .iter()
        .flat_map(|s| &s.points)
        .any(|p| p.hollow);
    if any_hollow && !chart.hollow_label.is_empty() {
        let swatch = Swatch::Hollow {
            color: rgb(REFERENCE),
        };
        entries.push(Entry {
            label: chart.hollow_label.clone(),
            swatch,
        });
    }
    entries
}

/// Category names on the x axis cut to the width of their slot so neighbours never overlap.
fn shorten_categories<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    frame: &Frame<DB>,
    x: &mut ResolvedAxis,
) {
    let count = x.major.len().max(1) as u32;
    let slot = frame.plot.dim_in_pixel().0.saturating_sub(120) / count;
    let style = text::style(TICK_SIZE);
    for (_, label) in &mut x.major {
        *label = text::shorten(root, label, &style, slot.saturating_sub(8));
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::plot::spec::{Axis, Band, Series};

    #[test]
    fn axes_fit_only_what_can_be_drawn() {
        let mut chart = Chart::new("t", Axis::linear("x"), Axis::linear("y"));
        let xy = [
            (1.0, 1.0),
            (100.0, f64::NAN),
            (f64::INFINITY, 50.0),
            (2.0, 2.0),
        ];
        chart
            .series
            .push(Series::from_xy("s", xy, SeriesStyle::Line));
        chart.bands.push(Band {
            label: String::new(),
            x: vec![3.0, 300.0],
            lo: vec![0.5, f64::NAN],
            hi: vec![3.0, 400.0],
            color: None,
        });
        assert_eq!(x_values(&chart), [1.0, 2.0, 3.0]);
        assert_eq!(y_values(&chart), [1.0, 2.0, 0.5, 3.0]);
    }
}
