//! What every drawing shares: the drawing area, text sizes, colours and styles, measuring,
//! shortening and wrapping text, and the result type of a drawing step.

use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use super::font::FAMILY;

pub(crate) type Area<'a> = DrawingArea<SVGBackend<'a>, Shift>;

/// The result of a drawing step; the error is plotters' message.
pub(crate) type DrawResult = Result<(), String>;

pub fn err(e: impl std::fmt::Display) -> String {
    e.to_string()
}

pub(crate) const TITLE_SIZE: f64 = 22.0;
pub(crate) const TICK_SIZE: f64 = 14.0;
pub(crate) const AXIS_LABEL_SIZE: f64 = 16.0;
pub(crate) const LEGEND_SIZE: f64 = 14.0;
pub(crate) const CAPTION_SIZE: f64 = 13.0;
pub(crate) const NOTE_SIZE: f64 = 12.0;
pub(crate) const TEXT_COLOR: RGBColor = RGBColor(0x22, 0x22, 0x22);
pub(crate) const MUTED_COLOR: RGBColor = RGBColor(0x55, 0x55, 0x55);

pub fn style(size: f64) -> TextStyle<'static> {
    (FAMILY, size).into_font().color(&TEXT_COLOR)
}

pub fn anchored(size: f64, h: HPos, v: VPos) -> TextStyle<'static> {
    style(size).pos(Pos::new(h, v))
}

/// Width in pixels of `text` drawn in `style` (0 if the font cannot measure it).
pub fn width(area: &Area, text: &str, style: &TextStyle) -> u32 {
    area.estimate_text_size(text, style).map_or(0, |(w, _)| w)
}

/// `text` cut short with `…` so that it is no wider than `max_width`.
pub(crate) fn shorten(area: &Area, text: &str, style: &TextStyle, max_width: u32) -> String {
    let chars: Vec<char> = text.chars().collect();
    let fits = |s: &str| width(area, s, style) <= max_width;
    if fits(text) {
        return text.to_string();
    }
    (1..chars.len())
        .rev()
        .map(|keep| chars[..keep].iter().collect::<String>() + "…")
        .find(|s| fits(s))
        .unwrap_or_else(|| "…".into())
}

/// Splits `text` after spaces or `/` (so case names such as `lj-box/cell-list/n=1000` break
/// between parts) into at most `max_lines` lines no wider than `max_width`, shortening the last.
pub fn wrap(
    area: &Area,
    text: &str,
    style: &TextStyle,
    max_width: u32,
    max_lines: usize,
) -> Vec<String> {
    let mut lines = vec![String::new()];
    for word in text.split_inclusive([' ', '/']) {
        let full = lines.len() >= max_lines;
        let current = lines.last_mut().expect("never empty");
        let candidate = format!("{current}{word}");
        if full || current.is_empty() || width(area, candidate.trim_end(), style) <= max_width {
            *current = candidate;
        } else {
            lines.push(word.to_string());
        }
    }
    let lines = lines
        .iter()
        .map(|l| shorten(area, l.trim(), style, max_width));
    lines.collect()
}
