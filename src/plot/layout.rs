//! The page around a plot: white background, title on top, caption at the bottom, legend panel
//! on the right, and the space left for the plot itself. Also the pixel box that tick labels
//! and axis descriptions need, measured with the embedded font.

use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, VPos};

use super::axis::ResolvedAxis;
use super::legend::{self, Entry};
use super::shapes::DrawResult;
use super::text::{self, AXIS_LABEL_SIZE, CAPTION_SIZE, TICK_SIZE, TITLE_SIZE};

const SIDE: i32 = 20;
const TOP: i32 = 12;
const BOTTOM: i32 = 8;
const TITLE_LINE: i32 = 28;
const CAPTION_LINE: i32 = 17;

pub struct Frame<'a, DB: DrawingBackend> {
    pub plot: DrawingArea<DB, Shift>,
    pub legend: Option<DrawingArea<DB, Shift>>,
    pub entries: &'a [Entry],
}

/// Clears `root`, writes the title and the caption, and splits the rest into plot and legend.
pub fn frame<'a, DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    title: &str,
    caption: &str,
    entries: &'a [Entry],
) -> Result<Frame<'a, DB>, String> {
    root.fill(&WHITE).map_err(|e| e.to_string())?;
    let (width, height) = root.dim_in_pixel();
    let max_text = width.saturating_sub(2 * SIDE as u32);

    let title_style = text::anchored(text::bold(TITLE_SIZE), HPos::Center, VPos::Top);
    let mut top = TOP;
    if !title.trim().is_empty() {
        // Measured in the regular face: viewers draw the SVG title in a real bold, up to ~15% wider.
        let title_width = (f64::from(max_text) * 0.85) as u32;
        for line in text::wrap(root, title, &title_style, title_width, 2) {
            root.draw_text(&line, &title_style, (width as i32 / 2, top))
                .map_err(|e| e.to_string())?;
            top += TITLE_LINE;
        }
    }

    let caption_style = text::anchored(
        text::style(CAPTION_SIZE).color(&text::MUTED_COLOR),
        HPos::Center,
        VPos::Bottom,
    );
    let mut bottom = height as i32 - BOTTOM;
    if !caption.trim().is_empty() {
        let lines = text::wrap(root, caption, &caption_style, max_text, 2);
        for line in lines.iter().rev() {
            root.draw_text(line, &caption_style, (width as i32 / 2, bottom))
                .map_err(|e| e.to_string())?;
            bottom -= CAPTION_LINE;
        }
        bottom -= 6;
    }

    let middle_height = (bottom - top).max(1) as u32;
    let middle = root.clone().shrink((0, top), (width, middle_height));
    let legend_width = legend::panel_width(root, entries);
    let (plot, legend) = if legend_width > 0 {
        let (plot, panel) = middle.split_horizontally(width - legend_width - SIDE as u32 / 2);
        (plot, Some(panel))
    } else {
        (middle, None)
    };
    Ok(Frame {
        plot,
        legend,
        entries,
    })
}

impl<DB: DrawingBackend> Frame<'_, DB> {
    /// Draws the legend with its top aligned `top` pixels into the middle area.
    pub fn draw_legend(&self, top: i32) -> DrawResult {
        match &self.legend {
            Some(panel) => legend::draw(panel, self.entries, top),
            None => Ok(()),
        }
    }
}

/// Room below the plot for x tick labels and the x description.
pub fn x_label_area() -> u32 {
    (TICK_SIZE + AXIS_LABEL_SIZE) as u32 + 16
}

/// Room left of the plot for the widest y tick label (at `size`) and the rotated y description.
pub fn y_label_area<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    axis: &ResolvedAxis,
    size: f64,
) -> u32 {
    let style = text::style(size);
    let widest = axis
        .major
        .iter()
        .map(|(_, label)| text::width(root, label, &style))
        .max()
        .unwrap_or(0);
    widest + AXIS_LABEL_SIZE as u32 + 26
}
