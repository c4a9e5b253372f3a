//! Text for the PNG. plotters' own `ab_glyph` rasterizer places each glyph by its ink box and
//! drops side bearings, so full stops float at mid-height and letters space unevenly. This
//! wrapper around the bitmap backend lays glyphs out on a common baseline at their advance
//! positions instead; everything else passes straight through. Text measurement is left to
//! plotters so that the PNG and the SVG are laid out alike.

use ab_glyph::{Font, FontRef, PxScale, ScaleFont, point};
use plotters_backend::text_anchor::{HPos, VPos};
use plotters_backend::{
    BackendColor, BackendCoord, BackendStyle, BackendTextStyle, DrawingBackend, DrawingErrorKind,
    FontStyle,
};
use std::sync::LazyLock;

use super::font::DEJAVU_SANS;

static FONT: LazyLock<Option<FontRef<'static>>> =
    LazyLock::new(|| FontRef::try_from_slice(DEJAVU_SANS).ok());

/// Baseline position below the top of plotters' text box, as a fraction of the font size;
/// centres capital letters in the box plotters measures (`size / 1.24` high).
const BASELINE: f32 = 0.716;

pub struct GlyphText<B>(pub B);

type Result<E> = std::result::Result<(), DrawingErrorKind<E>>;

impl<B: DrawingBackend> DrawingBackend for GlyphText<B> {
    type ErrorType = B::ErrorType;

    fn get_size(&self) -> (u32, u32) {
        self.0.get_size()
    }

    fn ensure_prepared(&mut self) -> Result<B::ErrorType> {
        self.0.ensure_prepared()
    }

    fn present(&mut self) -> Result<B::ErrorType> {
        self.0.present()
    }

    fn draw_pixel(&mut self, point: BackendCoord, color: BackendColor) -> Result<B::ErrorType> {
        self.0.draw_pixel(point, color)
    }

    fn draw_line<S: BackendStyle>(
        &mut self,
        from: BackendCoord,
        to: BackendCoord,
        style: &S,
    ) -> Result<B::ErrorType> {
        self.0.draw_line(from, to, style)
    }

    fn draw_rect<S: BackendStyle>(
        &mut self,
        a: BackendCoord,
        b: BackendCoord,
        style: &S,
        fill: bool,
    ) -> Result<B::ErrorType> {
        self.0.draw_rect(a, b, style, fill)
    }

    fn draw_path<S: BackendStyle, I: IntoIterator<Item = BackendCoord>>(
        &mut self,
        path: I,
        style: &S,
    ) -> Result<B::ErrorType> {
        self.0.draw_path(path, style)
    }

    fn draw_circle<S: BackendStyle>(
        &mut self,
        c: BackendCoord,
        r: u32,
        style: &S,
        fill: bool,
    ) -> Result<B::ErrorType> {
        self.0.draw_circle(c, r, style, fill)
    }

    fn fill_polygon<S: BackendStyle, I: IntoIterator<Item = BackendCoord>>(
        &mut self,
        vert: I,
        style: &S,
    ) -> Result<B::ErrorType> {
        self.0.fill_polygon(vert, style)
    }

    fn blit_bitmap(
        &mut self,
        pos: BackendCoord,
        size: (u32, u32),
        src: &[u8],
    ) -> Result<B::ErrorType> {
        self.0.blit_bitmap(pos, size, src)
    }

    fn draw_text<S: BackendTextStyle>(
        &mut self,
        text: &str,
        style: &S,
        pos: BackendCoord,
    ) -> Result<B::ErrorType> {
        let Some(font) = FONT.as_ref() else {
            return self.0.draw_text(text, style, pos);
        };
        let color = style.color();
        if color.alpha == 0.0 {
            return Ok(());
        }
        let size = style.size() as f32;
        let scale = PxScale::from(size);
        let scaled = font.as_scaled(scale);
        let width: f32 = {
            let ids: Vec<_> = text.chars().map(|c| scaled.glyph_id(c)).collect();
            let advances: f32 = ids.iter().map(|&id| scaled.h_advance(id)).sum();
            advances + ids.windows(2).map(|w| scaled.kern(w[0], w[1])).sum::<f32>()
        };
        let height = (style.size() / 1.24) as i32;
        let dx = match style.anchor().h_pos {
            HPos::Left => 0,
            HPos::Center => -(width as i32) / 2,
            HPos::Right => -(width as i32),
        };
        let dy = match style.anchor().v_pos {
            VPos::Top => 0,
            VPos::Center => -height / 2,
            VPos::Bottom => -height,
        };
        let transform = style.transform();
        // Bold is faked by a second pass one pixel to the right: only one weight is embedded.
        let passes = if matches!(style.style(), FontStyle::Bold) {
            2
        } else {
            1
        };

        let mut caret = 0.0f32;
        let mut previous = None;
        let mut coverage: Vec<(i32, i32, f32)> = Vec::new();
        for c in text.chars() {
            let id = scaled.glyph_id(c);
            if let Some(prev) = previous {
                caret += scaled.kern(prev, id);
            }
            previous = Some(id);
            let glyph = id.with_scale_and_position(scale, point(caret, BASELINE * size));
            caret += scaled.h_advance(id);
            let Some(outline) = font.outline_glyph(glyph) else {
                continue;
            };
            let bounds = outline.px_bounds();
            outline.draw(|x, y, c| {
                coverage.push((
                    bounds.min.x as i32 + x as i32,
                    bounds.min.y as i32 + y as i32,
                    c,
                ));
            });
        }
        for pass in 0..passes {
            for &(x, y, c) in &coverage {
                let (x, y) = transform.transform(x + pass + dx, y + dy);
                let pixel = BackendColor {
                    alpha: color.alpha * f64::from(c.min(1.0)),
                    rgb: color.rgb,
                };
                self.0.draw_pixel((pos.0 + x, pos.1 + y), pixel)?;
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use plotters::prelude::*;
    use plotters::style::text_anchor::Pos;

    /// (row, column) of every inked pixel of `text` drawn at (10, 10), top-left anchored.
    fn ink(text: &str, size: f64) -> Vec<(usize, usize)> {
        super::super::font::register();
        let (w, h) = (200usize, 80usize);
        let mut buffer = vec![255u8; w * h * 3];
        {
            let style = ("sans-serif", size)
                .into_font()
                .color(&BLACK)
                .pos(Pos::new(HPos::Left, VPos::Top));
            let root = GlyphText(BitMapBackend::with_buffer(
                &mut buffer,
                (w as u32, h as u32),
            ))
            .into_drawing_area();
            root.draw_text(text, &style, (10, 10)).unwrap();
        }
        (0..h)
            .flat_map(|y| (0..w).map(move |x| (y, x)))
            .filter(|&(y, x)| buffer[(y * w + x) * 3] < 200)
            .collect()
    }

    #[test]
    fn glyphs_keep_their_side_bearings() {
        // plotters' own rasterizer starts every glyph's ink at the caret: 4 px off here.
        let size = 40.0;
        let font = FONT.as_ref().expect("embedded font parses");
        let scaled = font.as_scaled(PxScale::from(size as f32));
        let (x, stop) = (scaled.glyph_id('x'), scaled.glyph_id('.'));
        let expected =
            10.0 + scaled.h_advance(x) + scaled.kern(x, stop) + scaled.h_side_bearing(stop);
        let x_right = ink("x", size).iter().map(|p| p.1).max().unwrap();
        let stop_left = ink("x.", size)
            .iter()
            .map(|p| p.1)
            .filter(|&c| c > x_right)
            .min()
            .unwrap();
        assert!(
            (stop_left as f32 - expected).abs() <= 1.0,
            "full stop at column {stop_left}, expected {expected}"
        );
    }

    #[test]
    fn full_stops_sit_on_the_baseline_at_label_sizes() {
        for size in [12.0, 13.0, 14.0, 16.0, 22.0] {
            let bottom = |text| ink(text, size).iter().map(|p| p.0).max().unwrap();
            assert_eq!(bottom("."), bottom("x"), "size {size}");
        }
    }
}
