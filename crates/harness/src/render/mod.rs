//! The presentation layer: an [`Analysis`] as Markdown tables ([`tables`]), how its external
//! programs ran ([`runs`]), the per-sweep summary ([`summary`]), figures ([`analysis_figures`]) and the
//! files of an analysis directory. Every table of `summary.md` and REPORT.md comes from [`tables`], so the two never disagree; every
//! quantity is formatted by `crate::units`.

pub mod analysis_figures;
pub mod family_tables;
pub mod fit_tables;
pub mod runs;
pub mod summary;
pub mod sweep_tables;
pub mod tables;

use crate::analysis::Analysis;
use std::path::{Path, PathBuf};

/// What `write` produced.
pub struct Written {
    /// The analysis as JSON, `<dir>/fits.json`.
    pub fits: PathBuf,
    /// The Markdown summary, `<dir>/summary.md`.
    pub summary: PathBuf,
    /// The figures drawn, each as `<dir>/<stem>.svg` and `.png`.
    pub figures: Vec<analysis_figures::Figure>,
    /// Figures that could not be drawn (the fits and summary are written regardless).
    pub figure_errors: Vec<String>,
}

/// Writes `fits.json`, `summary.md` and the figures into `dir` (atomically, file by file).
pub fn write(analysis: &Analysis, dir: &Path) -> Result<Written, nbody_engine::output::WriteError> {
    let fits = dir.join("fits.json");
    let summary = dir.join("summary.md");
    // Checked before any figure is drawn, so that a refusal writes nothing.
    nbody_engine::output::create_dir_all(dir).map_err(|source| {
        nbody_engine::output::WriteError {
            path: dir.to_path_buf(),
            source,
        }
    })?;
    if let Err(e) =
        nbody_engine::output::check_outputs(&[("analysis", &fits), ("analysis", &summary)], &[])
    {
        return Err(nbody_engine::output::WriteError {
            path: dir.to_path_buf(),
            source: std::io::Error::other(e.to_string()),
        });
    }
    let (figures, figure_errors) = analysis_figures::render_all(analysis, dir);
    let text = serde_json::to_string_pretty(analysis).expect("analysis serializes");
    nbody_engine::output::write_atomic(&fits, text.as_bytes())?;
    let md = summary::markdown(analysis, &figures);
    nbody_engine::output::write_atomic(&summary, md.as_bytes())?;
    Ok(Written {
        fits,
        summary,
        figures,
        figure_errors,
    })
}
