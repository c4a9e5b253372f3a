//! Text that fits: sizes and styles used across figures, and wrapping or shortening a string to
//! a pixel width measured with the embedded font.

use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use super::font::FAMILY;

pub const TITLE_SIZE: f64 = 22.0;
pub const TICK_SIZE: f64 = 14.0;
pub const AXIS_LABEL_SIZE: f64 = 16.0;
pub const LEGEND_SIZE: f64 = 14.0;
pub const CAPTION_SIZE: f64 = 13.0;
pub const NOTE_SIZE: f64 = 12.0;

pub const TEXT_COLOR: RGBColor = RGBColor(0x22, 0x22, 0x22);
pub const MUTED_COLOR: RGBColor = RGBColor(0x55, 0x55, 0x55);

pub fn style(size: f64) -> TextStyle<'static> {
    (FAMILY, size).into_font().color(&TEXT_COLOR)
}

pub fn bold(size: f64) -> TextStyle<'static> {
    (FAMILY, size, FontStyle::Bold)
        .into_font()
        .color(&TEXT_COLOR)
}

pub fn anchored(style: TextStyle<'static>, h: HPos, v: VPos) -> TextStyle<'static> {
    style.pos(Pos::new(h, v))
}

/// Width in pixels of `text` drawn in `style` (0 if the font cannot measure it).
pub fn width<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    text: &str,
    style: &TextStyle,
) -> u32 {
    area.estimate_text_size(text, style)
        .map(|(w, _)| w)
        .unwrap_or(0)
}

/// Splits `text` at spaces (or `/`, keeping it) into at most `max_lines` lines no wider than
/// `max_width`; the last line is shortened with an ellipsis if the text still does not fit.
pub fn wrap<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    text: &str,
    style: &TextStyle,
    max_width: u32,
    max_lines: usize,
) -> Vec<String> {
    let fits = |s: &str| width(area, s, style) <= max_width;
    let mut lines: Vec<String> = Vec::new();
    let mut current = String::new();
    for word in words(text) {
        let candidate = format!("{current}{word}");
        if current.is_empty() || fits(candidate.trim_end()) {
            current = candidate;
        } else {
            lines.push(current.trim_end().to_string());
            current = word.trim_start().to_string();
        }
    }
    if !current.trim().is_empty() || lines.is_empty() {
        lines.push(current.trim_end().to_string());
    }
    if lines.len() > max_lines {
        let rest = lines.split_off(max_lines - 1).join(" ");
        lines.push(rest);
    }
    if let Some(last) = lines.last_mut() {
        *last = shorten(area, last, style, max_width);
    }
    lines
}

/// Words of `text` with their trailing separator: spaces, and `/` so that case names such as
/// `lj-box/cell-list/n=1000` can break between parts.
fn words(text: &str) -> Vec<&str> {
    let mut out = Vec::new();
    let mut start = 0;
    for (i, c) in text.char_indices() {
        if c == ' ' || c == '/' {
            out.push(&text[start..i + c.len_utf8()]);
            start = i + c.len_utf8();
        }
    }
    if start < text.len() {
        out.push(&text[start..]);
    }
    out
}

/// `text` cut short with `…` so that it is no wider than `max_width`.
pub fn shorten<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    text: &str,
    style: &TextStyle,
    max_width: u32,
) -> String {
    if width(area, text, style) <= max_width {
        return text.to_string();
    }
    let chars: Vec<char> = text.chars().collect();
    let mut keep = chars.len();
    while keep > 0 {
        keep -= 1;
        let candidate: String = chars[..keep].iter().collect::<String>() + "…";
        if width(area, &candidate, style) <= max_width {
            return candidate;
        }
    }
    "…".into()
}
