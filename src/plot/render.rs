//! Writing figures: each is drawn twice, to an SVG string and to a PNG under a temporary name,
//! and only when both drawings succeeded are the files moved into place, so a failure never
//! leaves a half-written or mismatched pair behind.

use plotters::coord::Shift;
use plotters::prelude::*;
use std::fs;
use std::path::Path;

use super::raster::GlyphText;
use super::shapes::DrawResult;
use super::spec::{Chart, Rendered, StackedBars};
use super::{PlotError, bars, chart, font};
use crate::output::write_atomic;

/// Pixel size of both the SVG and the PNG.
pub const SIZE: (u32, u32) = (1000, 650);

/// Something that can draw itself on any plotters backend.
pub trait Figure {
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> DrawResult;
}

impl Figure for Chart {
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> DrawResult {
        chart::draw(root, self)
    }
}

impl Figure for StackedBars {
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> DrawResult {
        bars::draw(root, self)
    }
}

/// Draws `figure` into `dir/stem.svg` and `dir/stem.png`, creating `dir` if needed.
pub fn render_figure(figure: &impl Figure, dir: &Path, stem: &str) -> Result<Rendered, PlotError> {
    super::check_stem(stem)?;
    font::register();
    fs::create_dir_all(dir).map_err(|source| PlotError::Dir {
        path: dir.to_path_buf(),
        source,
    })?;
    let svg_path = dir.join(format!("{stem}.svg"));
    let png_path = dir.join(format!("{stem}.png"));

    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, SIZE).into_drawing_area();
        let drawn = figure
            .draw(&root)
            .and_then(|()| root.present().map_err(|e| e.to_string()));
        drawn.map_err(|message| PlotError::Draw {
            path: svg_path.clone(),
            message,
        })?;
    }

    // The bitmap backend picks the image format from the extension, so the temporary name
    // must end in `.png` too.
    let png_tmp = dir.join(format!(".{stem}.{}.tmp.png", std::process::id()));
    let drawn = draw_png(figure, &png_tmp);
    let finished = drawn
        .map_err(|message| PlotError::Draw {
            path: png_path.clone(),
            message,
        })
        .and_then(|()| Ok(write_atomic(&svg_path, svg.as_bytes())?))
        .and_then(|()| {
            fs::rename(&png_tmp, &png_path).map_err(|source| {
                PlotError::Write(crate::output::WriteError {
                    path: png_path.clone(),
                    source,
                })
            })
        });
    if finished.is_err() {
        let _ = fs::remove_file(&png_tmp);
    }
    finished.map(|()| Rendered {
        svg: svg_path,
        png: png_path,
    })
}

fn draw_png(figure: &impl Figure, path: &Path) -> DrawResult {
    let root = GlyphText(BitMapBackend::new(path, SIZE)).into_drawing_area();
    figure.draw(&root)?;
    root.present().map_err(|e| e.to_string())
}
