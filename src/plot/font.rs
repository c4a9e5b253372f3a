//! The embedded font. plotters' `ab_glyph` backend measures and draws text only with fonts
//! registered at run time, so DejaVu Sans (Bitstream Vera licence, `assets/DejaVuSans-LICENSE.txt`)
//! is compiled into the binary and registered once; no system font is needed.

use plotters::style::{FontStyle, register_font};
use std::sync::Once;

pub static DEJAVU_SANS: &[u8] = include_bytes!("../../assets/DejaVuSans.ttf");

/// The family name every text style of this module uses.
pub const FAMILY: &str = "sans-serif";

/// Registers the font for the normal and bold styles; later calls do nothing.
pub fn register() {
    static ONCE: Once = Once::new();
    ONCE.call_once(|| {
        for style in [FontStyle::Normal, FontStyle::Bold] {
            // The bytes are a fixed, known-good TTF; a failure here is a broken build.
            let registered = register_font(FAMILY, style, DEJAVU_SANS);
            assert!(registered.is_ok(), "embedded DejaVu Sans did not parse");
        }
    });
}
