//! The inside of a chart's plot area: everything drawn in data coordinates, mapped to pixels
//! and clipped to the axes, in back-to-front order.

use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, VPos};

use super::axis::ResolvedAxis;
use super::chart::{BAND_ALPHA, Plot, REGION_ALPHA, series_color};
use super::palette::{self, REFERENCE};
use super::shapes::{self, DrawResult, LINE_WIDTH, Px, rgb};
use super::spec::{Chart, Point, SeriesStyle};
use super::text::{self, NOTE_SIZE};

pub struct Canvas<'c, 'p, DB: DrawingBackend> {
    pub root: &'c DrawingArea<DB, Shift>,
    pub plot: &'c Plot<'p, DB>,
    pub x: &'c ResolvedAxis,
    pub y: &'c ResolvedAxis,
}

impl<DB: DrawingBackend> Canvas<'_, '_, DB> {
    /// Pixel position of a point, if it lies on both axes.
    fn at(&self, x: f64, y: f64) -> Option<Px> {
        (self.x.contains(x) && self.y.contains(y)).then(|| self.plot.backend_coord(&(x, y)))
    }

    /// Pixel position with y pulled into the axis range (for bands and error bars).
    fn at_clamped(&self, x: f64, y: f64) -> Option<Px> {
        if !self.x.contains(x) || !y.is_finite() || (self.y.fraction(y).is_nan()) {
            return None;
        }
        let y = if self.y.fraction(y) < 0.0 {
            self.y.lo
        } else if self.y.fraction(y) > 1.0 {
            self.y.hi
        } else {
            y
        };
        Some(self.plot.backend_coord(&(x, y)))
    }

    fn pixel_box(&self) -> (std::ops::Range<i32>, std::ops::Range<i32>) {
        self.plot.plotting_area().get_pixel_range()
    }

    /// Draws everything in the plot area; returns whether any data point or band was drawn.
    pub fn draw_contents(&self, chart: &Chart) -> Result<bool, String> {
        self.draw_regions(chart)?;
        let mut drew = self.draw_bands(chart)?;
        self.draw_hlines(chart)?;
        for (i, s) in chart.series.iter().enumerate() {
            if matches!(
                s.style,
                SeriesStyle::Line | SeriesStyle::LineMarkers | SeriesStyle::Dashed
            ) {
                let style = series_color(i, s.color).stroke_width(LINE_WIDTH);
                for run in self.runs(&s.points) {
                    shapes::polyline(self.root, &run, style, s.style == SeriesStyle::Dashed)?;
                    drew = true;
                }
            }
        }
        for (i, s) in chart.series.iter().enumerate() {
            self.draw_error_bars(&s.points, series_color(i, s.color))?;
        }
        for (i, s) in chart.series.iter().enumerate() {
            if matches!(s.style, SeriesStyle::Markers | SeriesStyle::LineMarkers) {
                let (color, marker) = (
                    series_color(i, s.color),
                    palette::marker(s.color.unwrap_or(i)),
                );
                for p in &s.points {
                    if let Some(px) = self.at(p.x, p.y) {
                        shapes::marker(self.root, px, marker, color, p.hollow)?;
                        drew = true;
                    }
                }
            }
        }
        self.draw_point_labels(chart)?;
        Ok(drew)
    }

    /// Consecutive drawable points as pixel runs; a skipped point breaks the line.
    fn runs(&self, points: &[Point]) -> Vec<Vec<Px>> {
        let mut runs = vec![Vec::new()];
        for p in points {
            match self.at(p.x, p.y) {
                Some(px) => runs.last_mut().expect("never empty").push(px),
                None => runs.push(Vec::new()),
            }
        }
        runs.retain(|r| r.len() >= 2);
        runs
    }

    fn draw_regions(&self, chart: &Chart) -> DrawResult {
        let (xs, ys) = self.pixel_box();
        let style = text::anchored(
            text::style(NOTE_SIZE).color(&text::MUTED_COLOR),
            HPos::Left,
            VPos::Top,
        );
        for r in &chart.regions {
            let (from, to) = (r.x_from.min(r.x_to), r.x_from.max(r.x_to));
            let clamp = |v: f64| {
                let f = self.x.fraction(v);
                if !f.is_finite() {
                    None
                } else {
                    Some(xs.start + (f.clamp(0.0, 1.0) * (xs.end - xs.start) as f64).round() as i32)
                }
            };
            let (Some(left), Some(right)) = (clamp(from), clamp(to)) else {
                continue;
            };
            if right <= left {
                continue;
            }
            let rect = vec![
                (left, ys.start),
                (right, ys.start),
                (right, ys.end),
                (left, ys.end),
            ];
            shapes::fill(self.root, rect, rgb(REFERENCE), REGION_ALPHA)?;
            let label = text::shorten(
                self.root,
                &r.label,
                &style,
                (right - left - 8).max(0) as u32,
            );
            if label != "…" {
                self.root
                    .draw_text(&label, &style, (left + 4, ys.start + 4))
                    .map_err(|e| e.to_string())?;
            }
        }
        Ok(())
    }

    fn draw_bands(&self, chart: &Chart) -> Result<bool, String> {
        let mut drew = false;
        for (i, band) in chart.bands.iter().enumerate() {
            let color = series_color(i, band.color);
            let mut run: Vec<(Px, Px)> = Vec::new();
            let triples = band
                .x
                .iter()
                .zip(&band.lo)
                .zip(&band.hi)
                .map(|((&x, &lo), &hi)| (x, lo, hi));
            for triple in triples.map(Some).chain([None]) {
                let edge = triple.and_then(|(x, lo, hi)| {
                    Some((self.at_clamped(x, hi)?, self.at_clamped(x, lo)?))
                });
                match edge {
                    Some(e) => run.push(e),
                    None => {
                        if run.len() >= 2 {
                            let mut outline: Vec<Px> = run.iter().map(|e| e.0).collect();
                            outline.extend(run.iter().rev().map(|e| e.1));
                            shapes::fill(self.root, outline, color, BAND_ALPHA)?;
                            drew = true;
                        }
                        run.clear();
                    }
                }
            }
        }
        Ok(drew)
    }

    fn draw_hlines(&self, chart: &Chart) -> DrawResult {
        let (xs, _) = self.pixel_box();
        for h in chart.hlines.iter().filter(|h| self.y.contains(h.y)) {
            let y = self.plot.backend_coord(&(self.x.lo, h.y)).1;
            let color = h.color.map_or(rgb(REFERENCE), |c| rgb(palette::color(c)));
            shapes::polyline(
                self.root,
                &[(xs.start, y), (xs.end, y)],
                color.stroke_width(LINE_WIDTH),
                h.dashed,
            )?;
        }
        Ok(())
    }

    fn draw_error_bars(&self, points: &[Point], color: RGBColor) -> DrawResult {
        let style = color.stroke_width(1);
        for p in points {
            let Some((lo, hi)) = p.y_err else { continue };
            let (Some(top), Some(bottom)) = (self.at_clamped(p.x, hi), self.at_clamped(p.x, lo))
            else {
                continue;
            };
            let x = top.0;
            shapes::polyline(self.root, &[top, bottom], style, false)?;
            for y in [top.1, bottom.1] {
                shapes::polyline(self.root, &[(x - 4, y), (x + 4, y)], style, false)?;
            }
        }
        Ok(())
    }

    /// Point labels go above right of the marker, or above left where they would leave the plot.
    fn draw_point_labels(&self, chart: &Chart) -> DrawResult {
        let (xs, _) = self.pixel_box();
        let right = text::anchored(text::style(NOTE_SIZE), HPos::Left, VPos::Bottom);
        let left = text::anchored(text::style(NOTE_SIZE), HPos::Right, VPos::Bottom);
        for p in chart.series.iter().flat_map(|s| &s.points) {
            let (Some(label), Some(px)) = (&p.label, self.at(p.x, p.y)) else {
                continue;
            };
            let fits_right = px.0 + 7 + text::width(self.root, label, &right) as i32 <= xs.end;
            let (style, x) = if fits_right {
                (&right, px.0 + 7)
            } else {
                (&left, px.0 - 7)
            };
            self.root
                .draw_text(label, style, (x, px.1 - 5))
                .map_err(|e| e.to_string())?;
        }
        Ok(())
    }

    pub fn note_no_data(&self) -> DrawResult {
        let (xs, ys) = self.pixel_box();
        let style = text::anchored(
            text::style(text::LEGEND_SIZE).color(&text::MUTED_COLOR),
            HPos::Center,
            VPos::Center,
        );
        let centre = ((xs.start + xs.end) / 2, (ys.start + ys.end) / 2);
        self.root
            .draw_text("no data to show", &style, centre)
            .map_err(|e| e.to_string())
    }
}
