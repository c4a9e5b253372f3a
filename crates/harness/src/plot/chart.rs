//! Drawing a [`Chart`]: axes fitted to what can be drawn, the page around the plot, then the
//! contents back to front. plotters does not clip what it draws in data coordinates, so points
//! off the axes are left out (breaking a line there) and bands and error bars are cut at them.

use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, VPos};

use super::axis::ResolvedAxis;
use super::legend::{DASH, Glyph, LINE_WIDTH, Swatch, rgb};
use super::page::{self, Area, MUTED_COLOR, NOTE_SIZE, Page, Plot, TICK_SIZE, anchored};
use super::palette::{self, Marker, REFERENCE, REFERENCE_INDEX};
use super::save::{DrawResult, err};
use super::spec::{Chart, Point, Scale, SeriesStyle};

const BAND_ALPHA: f64 = 0.18;
const REGION_ALPHA: f64 = 0.09;
/// Category names down the y axis never take more than this share of the figure width.
const MAX_NAME_SHARE: f64 = 0.32;

pub(crate) fn draw(root: &Area, chart: &Chart) -> DrawResult {
    let mut x = ResolvedAxis::resolve(&chart.x, x_values(chart));
    let mut y = ResolvedAxis::resolve(&chart.y, y_values(chart));
    let page = Page::new(root, &chart.title, &chart.caption, legend(chart))?;
    // Category names are cut to the width of their slot so that neighbours never overlap;
    // names down the y axis (one row each) keep up to a third of the figure's width.
    let slot = page.plot.dim_in_pixel().0.saturating_sub(120) / x.major.len().max(1) as u32;
    for (_, label) in &mut x.major {
        *label = page::shorten(root, label, &page::style(TICK_SIZE), slot.saturating_sub(8));
    }
    if !chart.y.categories.is_empty() {
        let room = (f64::from(root.dim_in_pixel().0) * MAX_NAME_SHARE) as u32;
        for (_, label) in &mut y.major {
            *label = page::shorten(root, label, &page::style(TICK_SIZE), room);
        }
    }
    let axes = (x.clone(), y.clone());
    let mut plot = page.plot(axes, (&chart.x.label, &chart.y.label), TICK_SIZE, true)?;
    if !draw_contents(root, &mut plot, chart, (&x, &y))? {
        page::note_no_data(root, &plot)?;
    }
    Ok(())
}

/// Draws regions, bands, reference lines, series lines, error bars, markers and point labels;
/// returns whether any data point or band was drawn.
fn draw_contents(
    root: &Area,
    plot: &mut Plot,
    chart: &Chart,
    axes: (&ResolvedAxis, &ResolvedAxis),
) -> Result<bool, String> {
    draw_regions(root, plot, chart, axes)?;
    let mut drew = draw_bands(plot, chart, axes)?;
    drew |= draw_lines(plot, chart, axes)?;
    draw_error_bars(root, plot, chart, axes)?;
    drew |= draw_markers(plot, chart, axes)?;
    draw_point_labels(root, plot, chart, axes)?;
    Ok(drew)
}

/// Whether a point lies on both axes (points off them are not drawn).
fn on_axes(p: &Point, (x, y): (&ResolvedAxis, &ResolvedAxis)) -> bool {
    x.contains(p.x) && y.contains(p.y)
}

/// Shades each region's span of x over the full height, its label at the top left when any
/// of it fits the span.
fn draw_regions(
    root: &Area,
    plot: &mut Plot,
    chart: &Chart,
    (x, y): (&ResolvedAxis, &ResolvedAxis),
) -> DrawResult {
    let (_, ys) = plot.plotting_area().get_pixel_range();
    let note = anchored(NOTE_SIZE, HPos::Left, VPos::Top).color(&MUTED_COLOR);
    for r in &chart.regions {
        let ends = (x.clamp(r.x_from.min(r.x_to)), x.clamp(r.x_from.max(r.x_to)));
        let (Some(from), Some(to)) = ends else {
            continue;
        };
        let (left, right) = (
            plot.backend_coord(&(from, y.lo)).0,
            plot.backend_coord(&(to, y.lo)).0,
        );
        if right <= left {
            continue;
        }
        let shade = rgb(REFERENCE).mix(REGION_ALPHA).filled();
        plot.draw_series([Rectangle::new([(from, y.lo), (to, y.hi)], shade)])
            .map_err(err)?;
        let label = page::shorten(root, &r.label, &note, (right - left - 8).max(0) as u32);
        if label != "…" {
            root.draw_text(&label, &note, (left + 4, ys.start + 4))
                .map_err(err)?;
        }
    }
    Ok(())
}

/// Fills each band between its low and high edges, one polygon per run of x on the axis;
/// returns whether any was drawn.
fn draw_bands(
    plot: &mut Plot,
    chart: &Chart,
    (x, y): (&ResolvedAxis, &ResolvedAxis),
) -> Result<bool, String> {
    let mut drew = false;
    for (i, band) in chart.bands.iter().enumerate() {
        let shade = series_color(i, band.color).mix(BAND_ALPHA).filled();
        let triples = band.x.iter().zip(&band.lo).zip(&band.hi);
        let edges = triples.map(|((&bx, &lo), &hi)| {
            x.contains(bx).then_some(())?;
            Some((bx, y.clamp(lo)?, y.clamp(hi)?))
        });
        for run in runs(edges) {
            let upper = run.iter().map(|&(bx, _, hi)| (bx, hi));
            let outline: Vec<_> = upper
                .chain(run.iter().rev().map(|&(bx, lo, _)| (bx, lo)))
                .collect();
            plot.draw_series([Polygon::new(outline, shade)])
                .map_err(err)?;
            drew = true;
        }
    }
    Ok(drew)
}

/// Draws the reference lines, then every series' line (all but marker-only series) through
/// its runs of points on the axes; returns whether any series line was drawn.
fn draw_lines(
    plot: &mut Plot,
    chart: &Chart,
    axes: (&ResolvedAxis, &ResolvedAxis),
) -> Result<bool, String> {
    let (x, y) = axes;
    for h in chart.hlines.iter().filter(|h| y.contains(h.y)) {
        let color = rgb(palette::color(h.color.unwrap_or(REFERENCE_INDEX)));
        line(plot, vec![(x.lo, h.y), (x.hi, h.y)], color, h.dashed)?;
    }
    let mut drew = false;
    for (i, s) in chart.series.iter().enumerate() {
        if s.style != SeriesStyle::Markers {
            let points = s
                .points
                .iter()
                .map(|p| on_axes(p, axes).then_some((p.x, p.y)));
            for run in runs(points) {
                line(
                    plot,
                    run,
                    series_color(i, s.color),
                    s.style == SeriesStyle::Dashed,
                )?;
                drew = true;
            }
        }
    }
    Ok(drew)
}

/// Draws every point's vertical error bar with caps, cut at the y axis' ends.
fn draw_error_bars(
    root: &Area,
    plot: &mut Plot,
    chart: &Chart,
    (x, y): (&ResolvedAxis, &ResolvedAxis),
) -> DrawResult {
    for (i, s) in chart.series.iter().enumerate() {
        // 2 px: a 1 px line on whole-pixel coordinates is smeared over two pixels at half strength.
        let style = series_color(i, s.color).stroke_width(2);
        for p in s.points.iter().filter(|p| x.contains(p.x)) {
            let Some((lo, hi)) = p.y_err else { continue };
            let (Some(lo), Some(hi)) = (y.clamp(lo), y.clamp(hi)) else {
                continue;
            };
            let ((bx, top), (_, bottom)) = (
                plot.backend_coord(&(p.x, hi)),
                plot.backend_coord(&(p.x, lo)),
            );
            let bar = [
                (bx - 4, top),
                (bx + 4, top),
                (bx, top),
                (bx, bottom),
                (bx - 4, bottom),
                (bx + 4, bottom),
            ];
            root.draw(&PathElement::new(bar, style)).map_err(err)?;
        }
    }
    Ok(())
}

/// Draws the markers of the series that have them at their points on the axes; returns
/// whether any was drawn.
fn draw_markers(
    plot: &mut Plot,
    chart: &Chart,
    axes: (&ResolvedAxis, &ResolvedAxis),
) -> Result<bool, String> {
    let mut drew = false;
    // Crossed markers last, so that no other series' marker hides a cross.
    for crossed in [false, true] {
        for (i, s) in chart.series.iter().enumerate() {
            if !matches!(s.style, SeriesStyle::Markers | SeriesStyle::LineMarkers) {
                continue;
            }
            let color = series_color(i, s.color);
            let marker = palette::marker(s.color.unwrap_or(i));
            let shown: Vec<&Point> = s
                .points
                .iter()
                .filter(|p| on_axes(p, axes) && p.crossed == crossed)
                .collect();
            // The second pass draws nothing where nothing is crossed: a figure without a
            // crossed point is drawn exactly as before.
            if crossed && shown.is_empty() {
                continue;
            }
            let markers = shown.iter().map(|p| {
                Glyph(
                    (p.x, p.y),
                    Swatch::Marker {
                        color,
                        marker,
                        hollow: p.hollow,
                        crossed: p.crossed,
                    },
                )
            });
            plot.draw_series(markers).map_err(err)?;
            drew |= !shown.is_empty();
        }
    }
    Ok(drew)
}

/// Writes each labelled point's label above right of its marker, or above left where it would
/// leave the plot.
fn draw_point_labels(
    root: &Area,
    plot: &mut Plot,
    chart: &Chart,
    axes: (&ResolvedAxis, &ResolvedAxis),
) -> DrawResult {
    let (xs, _) = plot.plotting_area().get_pixel_range();
    let right = anchored(NOTE_SIZE, HPos::Left, VPos::Bottom);
    let left = anchored(NOTE_SIZE, HPos::Right, VPos::Bottom);
    let points = chart.series.iter().flat_map(|s| &s.points);
    for p in points.filter(|p| on_axes(p, axes)) {
        let Some(label) = &p.label else { continue };
        let (px, py) = plot.backend_coord(&(p.x, p.y));
        let fits = px + 7 + page::width(root, label, &right) as i32 <= xs.end;
        let (style, at) = if fits {
            (&right, px + 7)
        } else {
            (&left, px - 7)
        };
        root.draw_text(label, style, (at, py - 5)).map_err(err)?;
    }
    Ok(())
}

/// A solid or dashed line through `points`.
fn line(plot: &mut Plot, points: Vec<(f64, f64)>, color: RGBColor, dashed: bool) -> DrawResult {
    let style = color.stroke_width(LINE_WIDTH);
    let drawn = if dashed {
        plot.draw_series(DashedLineSeries::new(points, DASH.0, DASH.1, style))
    } else {
        plot.draw_series(LineSeries::new(points, style))
    };
    drawn.map(|_| ()).map_err(err)
}

/// Runs of consecutive `Some` items that are long enough to draw; a `None` ends a run.
fn runs<T>(items: impl IntoIterator<Item = Option<T>>) -> Vec<Vec<T>> {
    let mut runs = vec![Vec::new()];
    for item in items {
        match item {
            Some(t) => runs.last_mut().expect("never empty").push(t),
            None => runs.push(Vec::new()),
        }
    }
    runs.retain(|r| r.len() >= 2);
    runs
}

fn series_color(index: usize, color: Option<usize>) -> RGBColor {
    rgb(palette::color(color.unwrap_or(index)))
}

/// Every labelled item in legend order: series, bands, reference lines, regions, and what a
/// hollow marker means when some point is hollow.
fn legend(chart: &Chart) -> Vec<(String, Swatch)> {
    let mut entries = Vec::new();
    for (i, s) in chart.series.iter().enumerate() {
        let (color, shape) = (
            series_color(i, s.color),
            palette::marker(s.color.unwrap_or(i)),
        );
        let swatch = match s.style {
            SeriesStyle::Markers => Swatch::Marker {
                color,
                marker: shape,
                hollow: false,
                crossed: false,
            },
            style => Swatch::Line {
                color,
                dashed: style == SeriesStyle::Dashed,
                marker: (style == SeriesStyle::LineMarkers).then_some(shape),
            },
        };
        entries.push((s.label.clone(), swatch));
    }
    for (i, b) in chart.bands.iter().enumerate() {
        let swatch = Swatch::Fill(series_color(i, b.color), BAND_ALPHA * 1.5);
        entries.push((b.label.clone(), swatch));
    }
    for h in &chart.hlines {
        let color = rgb(palette::color(h.color.unwrap_or(REFERENCE_INDEX)));
        let swatch = Swatch::Line {
            color,
            dashed: h.dashed,
            marker: None,
        };
        entries.push((h.label.clone(), swatch));
    }
    for r in &chart.regions {
        entries.push((
            r.label.clone(),
            Swatch::Fill(rgb(REFERENCE), REGION_ALPHA * 2.0),
        ));
    }
    if chart
        .series
        .iter()
        .flat_map(|s| &s.points)
        .any(|p| p.hollow)
    {
        let color = rgb(REFERENCE);
        let hollow = Swatch::Marker {
            color,
            marker: Marker::Circle,
            hollow: true,
            crossed: false,
        };
        entries.push((chart.hollow_label.clone(), hollow));
    }
    if chart
        .series
        .iter()
        .flat_map(|s| &s.points)
        .any(|p| p.crossed)
    {
        let crossed = Swatch::Marker {
            color: rgb(REFERENCE),
            marker: Marker::Circle,
            hollow: false,
            crossed: true,
        };
        entries.push((chart.crossed_label.clone(), crossed));
    }
    entries
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
    let lo = values.iter().copied().reduce(f64::min);
    let hi = values.iter().copied().reduce(f64::max);
    if let (true, Some(lo), Some(hi)) = (labelled, lo, hi)
        && hi > lo
    {
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

    #[test]
    fn lines_break_where_a_point_is_missing() {
        let items = [
            Some(1),
            Some(2),
            None,
            Some(3),
            None,
            Some(4),
            Some(5),
            Some(6),
        ];
        assert_eq!(runs(items), [vec![1, 2], vec![4, 5, 6]]);
    }
}
