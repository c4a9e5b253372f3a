//! Drawing [`StackedBars`] as horizontal bars: one row per category (first on top, names on the
//! left where long case names have room), segments stacked left to right, the total at the end.

use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, VPos};

use super::axis::ResolvedAxis;
use super::format;
use super::legend::{Swatch, rgb};
use super::page::{self, Area, NOTE_SIZE, Page, TICK_SIZE, anchored};
use super::palette;
use super::save::{DrawResult, err};
use super::spec::{Axis, StackedBars};

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

pub(crate) fn draw(root: &Area, bars: &StackedBars) -> DrawResult {
    let count = bars.categories.len();
    // Only parts that show somewhere get a legend entry.
    let shown = |k: &usize| (0..count).any(|i| size(bars, *k, i) > 0.0);
    let legend = (0..bars.segments.len()).filter(shown);
    let legend = legend.map(|k| (bars.segments[k].0.clone(), Swatch::Fill(color(k), 1.0)));
    let page = Page::new(root, &bars.title, &bars.caption, legend.collect())?;

    let totals: Vec<f64> = (0..count)
        .map(|i| (0..bars.segments.len()).map(|k| size(bars, k, i)).sum())
        .collect();
    let largest = totals.iter().copied().fold(0.0, f64::max);
    let value_axis = Axis::linear("").unit(bars.value_unit).starting_at_zero();
    let value_axis = if largest > 0.0 {
        value_axis.range(0.0, largest * TOTAL_ROOM)
    } else {
        value_axis
    };
    let x = ResolvedAxis::resolve(&value_axis, [0.0, largest]);

    // Row i sits at position count-1-i so the first category is drawn on top. Many rows get
    // smaller names so that neighbours do not touch.
    let row_height = f64::from(page.plot.dim_in_pixel().1) / count.max(1) as f64;
    let name_size = TICK_SIZE.min((row_height * 0.75).floor()).max(8.0);
    let max_name = (f64::from(root.dim_in_pixel().0) * MAX_NAME_SHARE) as u32;
    let name_style = page::style(name_size);
    let names = bars.categories.iter().rev();
    let names = names
        .map(|c| page::shorten(root, c, &name_style, max_name))
        .collect();
    let y = ResolvedAxis::resolve(&Axis::categorical("", names), []);
    let axes = (x, y);
    let mut plot = page.plot(axes, (&bars.value_label, ""), name_size, false)?;

    let total_style = anchored(NOTE_SIZE.min(name_size), HPos::Left, VPos::Center);
    for (i, &total) in totals.iter().enumerate() {
        let row = (count - 1 - i) as f64;
        let (top, bottom) = (row + BAR_HALF_HEIGHT, row - BAR_HALF_HEIGHT);
        let mut start = 0.0;
        for k in 0..bars.segments.len() {
            let end = start + size(bars, k, i);
            if end > start {
                let segment = Rectangle::new([(start, top), (end, bottom)], color(k).filled());
                // A white edge between segments, where the segment is wide enough to spare it.
                let wide =
                    plot.backend_coord(&(end, row)).0 - plot.backend_coord(&(start, row)).0 >= 2;
                plot.draw_series([segment]).map_err(err)?;
                if wide {
                    let edge = PathElement::new(vec![(end, top), (end, bottom)], WHITE);
                    plot.draw_series([edge]).map_err(err)?;
                }
            }
            start = end;
        }
        if total > 0.0 {
            let (px, py) = plot.backend_coord(&(total, row));
            let label = format::value_label(total, bars.value_unit);
            root.draw_text(&label, &total_style, (px + 6, py))
                .map_err(err)?;
        }
    }
    if largest <= 0.0 {
        page::note_no_data(root, &plot)?;
    }
    Ok(())
}

fn color(k: usize) -> RGBColor {
    rgb(palette::color(k))
}
