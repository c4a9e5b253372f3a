//! Figures as plain data, drawn to SVG and PNG.
//!
//! [`Chart`] (x-y series, error bars, bands, reference lines, shaded regions) and
//! [`StackedBars`] describe a figure with plain numbers and strings; [`figures`] builds the
//! figures this project reports from per-kernel measurements. [`draw`] and
//! [`draw_stacked`] draw them once, to SVG with plotters, and rasterize that SVG with resvg,
//! both with an embedded font, writing `stem.svg` and `stem.png` (1000×650) atomically.
//! Without the `plot` cargo feature the types and constructors remain, and drawing returns
//! [`PlotError::Disabled`].

#[cfg_attr(not(feature = "plot"), allow(dead_code))]
mod axis;
pub mod figures;
#[cfg_attr(not(feature = "plot"), allow(dead_code))]
mod format;
pub mod palette;
mod spec;

#[cfg(feature = "plot")]
mod bars;
#[cfg(feature = "plot")]
mod chart;
#[cfg(feature = "plot")]
mod font;
#[cfg(feature = "plot")]
mod legend;
#[cfg(feature = "plot")]
mod page;
#[cfg(feature = "plot")]
mod save;
#[cfg(all(test, feature = "plot"))]
mod tests;
#[cfg(feature = "plot")]
mod text;

pub use spec::{Axis, Chart, Scale, Series, SeriesStyle, Unit};
pub(crate) use spec::{Rendered, StackedBars};

use std::path::{Path, PathBuf};
use thiserror::Error;

/// Why a figure was not drawn or written.
#[derive(Debug, Error)]
pub enum PlotError {
    /// This build lacks the `plot` cargo feature, so nothing can be drawn.
    #[error("built without the `plot` feature; rebuild with `--features plot` to draw figures")]
    Disabled,
    /// The figure's stem (given here) is empty, starts with '.' or has characters other than
    /// letters, digits, '-', '_' and '.', so it could land outside its directory.
    #[error("figure name {0:?} is not a plain file name: use letters, digits, '-', '_' or '.'")]
    BadName(String),
    /// The directory the figure goes into could not be created.
    #[error("cannot create the figure directory {path}: {source}")]
    Dir {
        /// The directory.
        path: PathBuf,
        /// The error creating it.
        #[source]
        source: std::io::Error,
    },
    /// plotters failed drawing the SVG, or resvg failed rasterizing it to the PNG.
    #[error("cannot draw {path}: {message}")]
    Draw {
        /// The file being drawn (`stem.svg` or `stem.png`).
        path: PathBuf,
        /// The drawing library's error message.
        message: String,
    },
    /// Writing the drawn SVG or PNG atomically into place failed.
    #[error(transparent)]
    Write(#[from] nbody_engine::output::WriteError),
}

/// Draws `chart` into `dir/stem.svg` and `dir/stem.png` (creating `dir`), replacing any earlier
/// pair only once both are drawn.
pub fn draw(chart: &Chart, dir: &Path, stem: &str) -> Result<Rendered, PlotError> {
    #[cfg(feature = "plot")]
    return save::save_figure(|root| chart::draw(root, chart), dir, stem);
    #[cfg(not(feature = "plot"))]
    return disabled(&chart.title, dir, stem);
}

/// Draws `bars` into `dir/stem.svg` and `dir/stem.png`, like [`draw`].
pub fn draw_stacked(bars: &StackedBars, dir: &Path, stem: &str) -> Result<Rendered, PlotError> {
    #[cfg(feature = "plot")]
    return save::save_figure(|root| bars::draw(root, bars), dir, stem);
    #[cfg(not(feature = "plot"))]
    return disabled(&bars.title, dir, stem);
}

#[cfg(not(feature = "plot"))]
fn disabled(_title: &str, _dir: &Path, stem: &str) -> Result<Rendered, PlotError> {
    check_stem(stem)?;
    Err(PlotError::Disabled)
}

/// A figure name must be a bare file stem, so figures land in the directory they were meant for.
fn check_stem(stem: &str) -> Result<(), PlotError> {
    let plain = |c: char| c.is_ascii_alphanumeric() || matches!(c, '-' | '_' | '.');
    if stem.is_empty() || stem.starts_with('.') || !stem.chars().all(plain) {
        return Err(PlotError::BadName(stem.to_string()));
    }
    Ok(())
}

#[cfg(all(test, not(feature = "plot")))]
mod disabled_tests {
    use super::*;

    #[test]
    fn rendering_without_the_feature_is_a_typed_error_and_writes_nothing() {
        let dir = tempfile::tempdir().unwrap();
        let chart = figures::time_per_step(&[], "");
        let err = draw(&chart, dir.path(), "fig").unwrap_err();
        assert!(matches!(err, PlotError::Disabled));
        assert!(err.to_string().contains("`plot` feature"));
        let bars = figures::phase_breakdown(&[], "");
        assert!(matches!(
            draw_stacked(&bars, dir.path(), "bars"),
            Err(PlotError::Disabled)
        ));
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
    }
}
