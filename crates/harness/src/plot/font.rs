//! The embedded font, DejaVu Sans (Bitstream Vera licence, `assets/DejaVuSans-LICENSE.txt`),
//! compiled into the binary so that no system font is needed. plotters measures text with it
//! while laying a figure out, and resvg draws the SVG's text with it, so the two agree.

use plotters::style::{FontStyle, register_font};
use resvg::usvg::fontdb::Database;
use std::sync::{Arc, LazyLock, Once};

static DEJAVU_SANS: &[u8] = include_bytes!("../../../../assets/DejaVuSans.ttf");

/// The family name every text style of this module uses.
pub(crate) const FAMILY: &str = "sans-serif";

/// Registers the font with plotters for the normal and bold styles; later calls do nothing.
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

/// The only font resvg sees: it stands for every generic family, so the PNG looks the same
/// on every machine.
pub(crate) static FONTS: LazyLock<Arc<Database>> = LazyLock::new(|| {
    let mut db = Database::new();
    db.load_font_data(DEJAVU_SANS.to_vec());
    db.set_sans_serif_family("DejaVu Sans");
    Arc::new(db)
});
