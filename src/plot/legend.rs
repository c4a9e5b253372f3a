//! The legend, drawn in its own panel to the right of the plot so it never covers data.

use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, VPos};

use super::palette::Marker;
use super::shapes::{self, DrawResult, LINE_WIDTH};
use super::text::{self, LEGEND_SIZE};

/// How an entry's sample is drawn.
#[derive(Clone, Copy, Debug)]
pub enum Swatch {
    Line {
        color: RGBColor,
        dashed: bool,
        marker: Option<Marker>,
    },
    Markers {
        color: RGBColor,
        marker: Marker,
    },
    Fill {
        color: RGBColor,
        alpha: f64,
    },
    Hollow {
        color: RGBColor,
    },
}

#[derive(Clone, Debug)]
pub struct Entry {
    pub label: String,
    pub swatch: Swatch,
}

const SWATCH_WIDTH: i32 = 30;
const GAP: i32 = 8;
const PADDING: i32 = 10;
const LINE_HEIGHT: i32 = 18;
const ENTRY_GAP: i32 = 6;
/// The legend never takes more than this share of the figure width.
const MAX_SHARE: f64 = 0.3;

/// Width the legend panel needs for `entries` (0 when there are none).
pub fn panel_width<DB: DrawingBackend>(root: &DrawingArea<DB, Shift>, entries: &[Entry]) -> u32 {
    if entries.is_empty() {
        return 0;
    }
    let style = text::style(LEGEND_SIZE);
    let widest = entries
        .iter()
        .map(|e| text::width(root, &e.label, &style))
        .max()
        .unwrap_or(0);
    let wanted = widest as i32 + SWATCH_WIDTH + GAP + 2 * PADDING + 12;
    let cap = (root.dim_in_pixel().0 as f64 * MAX_SHARE) as i32;
    wanted.min(cap) as u32
}

/// Draws the entries top-down inside `panel`, starting `top` pixels below its top edge, in a
/// light box. Labels wider than the panel wrap onto a second line.
pub fn draw<DB: DrawingBackend>(
    panel: &DrawingArea<DB, Shift>,
    entries: &[Entry],
    top: i32,
) -> DrawResult {
    if entries.is_empty() {
        return Ok(());
    }
    let (width, height) = panel.dim_in_pixel();
    let style = text::anchored(text::style(LEGEND_SIZE), HPos::Left, VPos::Center);
    let text_width = (width as i32 - SWATCH_WIDTH - GAP - 2 * PADDING - 6).max(20) as u32;
    let laid_out: Vec<(Vec<String>, Swatch)> = entries
        .iter()
        .map(|e| (text::wrap(panel, &e.label, &style, text_width, 2), e.swatch))
        .collect();
    let box_height: i32 = laid_out
        .iter()
        .map(|(lines, _)| lines.len() as i32 * LINE_HEIGHT + ENTRY_GAP)
        .sum::<i32>()
        - ENTRY_GAP
        + 2 * PADDING;
    let box_height = box_height.min(height as i32 - top);
    let (left, right) = (2, width as i32 - 4);
    let frame = [(left, top), (right, top + box_height)];
    panel
        .draw(&Rectangle::new(frame, WHITE.filled()))
        .map_err(|e| e.to_string())?;
    panel
        .draw(&Rectangle::new(
            frame,
            RGBColor(0xBB, 0xBB, 0xBB).stroke_width(1),
        ))
        .map_err(|e| e.to_string())?;

    let mut y = top + PADDING;
    for (lines, swatch) in laid_out {
        let centre = y + LINE_HEIGHT / 2;
        if centre > top + box_height {
            break;
        }
        draw_swatch(panel, swatch, (left + PADDING, centre))?;
        for (i, line) in lines.iter().enumerate() {
            let at = (
                left + PADDING + SWATCH_WIDTH + GAP,
                centre + i as i32 * LINE_HEIGHT,
            );
            panel
                .draw_text(line, &style, at)
                .map_err(|e| e.to_string())?;
        }
        y += lines.len() as i32 * LINE_HEIGHT + ENTRY_GAP;
    }
    Ok(())
}

/// The sample for one entry, its left edge at `x` and vertically centred on `y`.
fn draw_swatch<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    swatch: Swatch,
    (x, y): (i32, i32),
) -> DrawResult {
    let middle = (x + SWATCH_WIDTH / 2, y);
    match swatch {
        Swatch::Line {
            color,
            dashed,
            marker,
        } => {
            let line = [(x, y), (x + SWATCH_WIDTH, y)];
            shapes::polyline(area, &line, color.stroke_width(LINE_WIDTH), dashed)?;
            match marker {
                Some(m) => shapes::marker(area, middle, m, color, false),
                None => Ok(()),
            }
        }
        Swatch::Markers { color, marker } => shapes::marker(area, middle, marker, color, false),
        Swatch::Fill { color, alpha } => {
            let rect = vec![
                (x, y - 7),
                (x + SWATCH_WIDTH, y - 7),
                (x + SWATCH_WIDTH, y + 7),
                (x, y + 7),
            ];
            shapes::fill(area, rect, color, alpha)
        }
        Swatch::Hollow { color } => shapes::marker(area, middle, Marker::Circle, color, true),
    }
}
