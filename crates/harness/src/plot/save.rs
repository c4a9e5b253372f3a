//! Writing figures: each is drawn once, to an SVG string, and the PNG is that SVG rasterized by
//! resvg. Both are finished in memory before either file is written, so a drawing failure
//! never leaves a half-written or mismatched pair behind.

use plotters::prelude::*;
use resvg::{tiny_skia, usvg};
use std::path::Path;

use super::spec::Rendered;
use super::text::Area;
use super::{PlotError, font};
use nbody_engine::output::write_atomic;

/// Pixel size of both the SVG and the PNG.
pub(crate) const SIZE: (u32, u32) = (1000, 650);

/// Only a regular face is embedded, so resvg would draw bold text (the title) regular; a
/// 1 px outline gives it about the weight of a real bold. It applies to the PNG only: SVG
/// viewers use their own bold face.
const FAKE_BOLD: &str = "text[font-weight=bold] { stroke: #222222; stroke-width: 1.0 }";

pub(crate) use super::text::DrawResult;
pub use super::text::err;

/// Draws a figure with `draw` into `dir/stem.svg` and `dir/stem.png`, creating `dir` if needed.
pub(crate) fn save_figure(
    draw: impl Fn(&Area) -> DrawResult,
    dir: &Path,
    stem: &str,
) -> Result<Rendered, PlotError> {
    super::check_stem(stem)?;
    font::register();
    nbody_engine::output::create_dir_all(dir).map_err(|source| PlotError::Dir {
        path: dir.to_path_buf(),
        source,
    })?;
    let svg_path = dir.join(format!("{stem}.svg"));
    let png_path = dir.join(format!("{stem}.png"));
    let failed = |path: &Path| {
        let path = path.to_path_buf();
        move |message| PlotError::Draw { path, message }
    };

    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, SIZE).into_drawing_area();
        draw(&root)
            .and_then(|()| root.present().map_err(|e| e.to_string()))
            .map_err(failed(&svg_path))?;
    }
    let png = rasterize(&svg).map_err(failed(&png_path))?;
    write_atomic(&svg_path, svg.as_bytes())?;
    write_atomic(&png_path, &png)?;
    Ok(Rendered {
        svg: svg_path,
        png: png_path,
    })
}

/// The PNG of `svg`, drawn with the embedded font only.
pub(crate) fn rasterize(svg: &str) -> Result<Vec<u8>, String> {
    let options = usvg::Options {
        fontdb: font::FONTS.clone(),
        style_sheet: Some(FAKE_BOLD.into()),
        ..usvg::Options::default()
    };
    let tree = usvg::Tree::from_str(svg, &options).map_err(|e| e.to_string())?;
    let mut pixmap = tiny_skia::Pixmap::new(SIZE.0, SIZE.1).ok_or("empty image size")?;
    pixmap.fill(tiny_skia::Color::WHITE);
    resvg::render(&tree, tiny_skia::Transform::default(), &mut pixmap.as_mut());
    pixmap.encode_png().map_err(|e| e.to_string())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Dark pixels in the PNG of `svg`.
    fn ink(svg: &str) -> usize {
        let png = rasterize(svg).unwrap();
        let pixmap = tiny_skia::Pixmap::decode_png(&png).unwrap();
        pixmap.pixels().iter().filter(|p| p.red() < 128).count()
    }

    #[test]
    fn text_is_drawn_with_the_embedded_font_and_bold_is_heavier() {
        let svg = |weight: &str| {
            format!(
                r#"<svg xmlns="http://www.w3.org/2000/svg" width="1000" height="650"><text x="10" y="50" font-family="sans-serif" font-size="30" font-weight="{weight}">Heavy text</text></svg>"#
            )
        };
        let (regular, bold) = (ink(&svg("normal")), ink(&svg("bold")));
        assert!(regular > 500, "no text drawn: {regular} dark pixels");
        assert!(
            bold as f64 > 1.2 * regular as f64,
            "bold {bold}, regular {regular}"
        );
    }
}
