//! Drawing [`StackedBars`] as horizontal bars: one row per category (first on top, names on the
//! left where long case names have room), segments stacked left to right, the total at the end.

use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, VPos};

use super::axis::ResolvedAxis;
use super::coord::AxisCoord;
use super::format;
use super::layout;
use super::legend::{Entry, Swatch};
use super::palette;
use super::shapes::{self, DrawResult, rgb};
use super::spec::{Axis, StackedBars};
use super::text::{self, NOTE_SIZE, TICK_SIZE};

const BAR_HALF_HEIGHT: f64 = 0.36;
/// Category names never take more than this share of the figure width.
const MAX_NAME_SHARE: f64 = 0.32;
/// Room right of the longest bar for its total.
const TOTAL_ROOM: f64 = 1.18;

/// The size of segment `k` in category `i`, with anything unusable counted as zero.
fn size(bars: &StackedBars, k: usize, i: usize) -> f64 {
    let v = bars.segments[k].1.get(i).copied().unwrap_or(0.0);
    if v.is_finite() && v > 0.0 { v } else { 0.0 }
}

fn total(bars: &StackedBars, i: usize) -> f64 {
    (0..bars.segments.len()).map(|k| size(bars, k, i)).sum()
}

pub fn draw<DB: DrawingBackend>(root: &DrawingArea<DB, Shift>, bars: &StackedBars) -> DrawResult {
    let entries: Vec<Entry> = bars
        .segments
        .iter()
        .enumerate()
        .filter(|(k, _)| (0..bars.categories.len()).any(|i| size(bars, *k, i) > 0.0))
        .map(|(k, (name, _))| Entry {
            label: name.clone(),
            swatch: Swatch::Fill {
                color: rgb(palette::color(k)),
                alpha: 1.0,
            },
        })
        .collect();
    let frame = layout::frame(root, &bars.title, &bars.caption, &entries)?;

    let count = bars.categories.len();
    let largest = (0..count).map(|i| total(bars, i)).fold(0.0, f64::max);
    let value_axis = Axis::linear(bars.value_label.as_str())
        .unit(bars.value_unit)
        .from_zero();
    let value_axis = if largest > 0.0 {
        value_axis.range(0.0, largest * TOTAL_ROOM)
    } else {
        value_axis
    };
    let x = ResolvedAxis::resolve(&value_axis, [0.0, largest]);

    // Row i sits at position count-1-i so the first category is drawn on top. Many rows get
    // smaller names so that neighbours do not touch.
    let row_height = frame.plot.dim_in_pixel().1 as f64 / count.max(1) as f64;
    let name_size = TICK_SIZE.min((row_height * 0.75).floor()).max(8.0);
    let name_style = text::style(name_size);
    let max_name = (root.dim_in_pixel().0 as f64 * MAX_NAME_SHARE) as u32;
    let names: Vec<String> = bars
        .categories
        .iter()
        .rev()
        .map(|c| text::shorten(root, c, &name_style, max_name))
        .collect();
    let y = ResolvedAxis::resolve(&Axis::categorical("", names), []);

    let mut builder = ChartBuilder::on(&frame.plot);
    builder
        .margin_top(8)
        .margin_left(10)
        .margin_right(if frame.legend.is_some() { 12 } else { 24 })
        .x_label_area_size(layout::x_label_area())
        .y_label_area_size(layout::y_label_area(root, &y, name_size));
    let mut plot = builder
        .build_cartesian_2d(AxisCoord(x.clone()), AxisCoord(y))
        .map_err(|e| e.to_string())?;
    plot.configure_mesh()
        .x_desc(bars.value_label.as_str())
        .disable_y_mesh()
        .x_label_style(text::style(TICK_SIZE))
        .y_label_style(name_style)
        .axis_desc_style(text::style(text::AXIS_LABEL_SIZE))
        .bold_line_style(BLACK.mix(0.14))
        .light_line_style(BLACK.mix(0.05))
        .draw()
        .map_err(|e| e.to_string())?;

    let total_style = text::anchored(
        text::style(NOTE_SIZE.min(name_size)),
        HPos::Left,
        VPos::Center,
    );
    for i in 0..count {
        let row = (count - 1 - i) as f64;
        let (top, bottom) = (row + BAR_HALF_HEIGHT, row - BAR_HALF_HEIGHT);
        let mut start = 0.0;
        for k in 0..bars.segments.len() {
            let end = start + size(bars, k, i);
            if end > start {
                let (a, b) = (
                    plot.backend_coord(&(start, top)),
                    plot.backend_coord(&(end, bottom)),
                );
                let rect = vec![a, (b.0, a.1), b, (a.0, b.1)];
                shapes::fill(root, rect, rgb(palette::color(k)), 1.0)?;
                if b.0 - a.0 >= 2 {
                    root.draw(&PathElement::new(
                        vec![(b.0, a.1), b],
                        WHITE.stroke_width(1),
                    ))
                    .map_err(|e| e.to_string())?;
                }
            }
            start = end;
        }
        if start > 0.0 {
            let at = plot.backend_coord(&(start, row));
            let label = format::value_label(start, bars.value_unit);
            root.draw_text(&label, &total_style, (at.0 + 6, at.1))
                .map_err(|e| e.to_string())?;
        }
    }
    if largest <= 0.0 {
        let (xs, ys) = plot.plotting_area().get_pixel_range();
        let style = text::anchored(
            text::style(text::LEGEND_SIZE).color(&text::MUTED_COLOR),
            HPos::Center,
            VPos::Center,
        );
        let centre = ((xs.start + xs.end) / 2, (ys.start + ys.end) / 2);
        root.draw_text("no data to show", &style, centre)
            .map_err(|e| e.to_string())?;
    }
    frame.draw_legend(8)
}
