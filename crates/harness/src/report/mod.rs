//! `report`: the performance characterization (REPORT.md) generated from committed results.
//!
//! Every number and figure comes from a results file under the results directory: each sweep
//! is analysed into `<results>/<name>/analysis/` (fits and figures), and the document links
//! those figures by relative path. Hand-written interpretation lives in kept regions
//! ([`keep`]) that regeneration carries over, so the command never destroys analysis, and the
//! same files always give the same text.

mod comm_section;
mod family_section;
pub mod keep;
mod melt_section;
mod sections;
mod sources_section;
mod tree_section;

use crate::analysis::{self, Analysis};
use nbody_mpi::ranks::bench_file::MpiBenchFile;
use nbody_records::results::{ResultsError, ResultsFile};
use std::path::{Path, PathBuf};
use thiserror::Error;

/// Why `report` wrote nothing; the report already on disk is left as it was.
#[derive(Debug, Error)]
pub enum ReportError {
    /// The results directory (or a sweep directory in it) could not be listed.
    #[error(
        "cannot read the results directory {path}: {source}; pass --results DIR with one sub-directory per sweep"
    )]
    Dir {
        /// The directory that could not be listed.
        path: PathBuf,
        /// The I/O error listing it.
        source: std::io::Error,
    },
    /// No sub-directory of the results directory holds a `results.json`.
    #[error(
        "no results files (<sweep>/results.json) under {path}; run the sweeps first: scripts/report.sh"
    )]
    NoResults {
        /// The results directory searched.
        path: PathBuf,
    },
    /// A results file could not be loaded.
    #[error(transparent)]
    Results(#[from] ResultsError),
    /// A sweep's results could not be analysed.
    #[error(transparent)]
    Analysis(#[from] analysis::AnalysisError),
    /// The existing report's kept-region markers are broken (unclosed or repeated).
    #[error("{path}: {source}; fix or remove the kept-region markers and run again")]
    Keep {
        /// The report file.
        path: PathBuf,
        /// What is wrong with its markers.
        source: keep::KeepError,
    },
    /// The existing report exists but could not be read (its kept regions would be lost).
    #[error("cannot read the existing report {path}: {source}")]
    ReadOld {
        /// The report file.
        path: PathBuf,
        /// The I/O error reading it.
        source: std::io::Error,
    },
    /// An analysis file or the report could not be written.
    #[error(transparent)]
    Write(#[from] nbody_engine::output::WriteError),
    /// An `mpi-bench*.json` file under the results directory could not be loaded (the message).
    #[error("{0}")]
    Bench(String),
}

/// One analysed sweep and where its figures are, relative to the report.
pub struct Sweep {
    /// The sweep's results analysed.
    pub analysis: Analysis,
    /// Directory of the figures relative to the report's directory, with `/` separators.
    pub(crate) figures_dir: String,
    /// The figures drawn for it into its `analysis/` directory.
    pub figures: Vec<crate::render::analysis_figures::Figure>,
}

impl Sweep {
    /// Links to this sweep's figures whose names start with `prefix`.
    pub(crate) fn figure_links(&self, md: &mut String, prefix: &str) {
        use std::fmt::Write;
        for f in self.figures.iter().filter(|f| f.stem.starts_with(prefix)) {
            let _ = writeln!(md, "![{}]({}/{}.svg)\n", f.title, self.figures_dir, f.stem);
        }
    }
}

/// What `generate` wrote.
pub struct Generated {
    /// The report written (the `out` given).
    pub path: PathBuf,
    /// Sweeps analysed, one per results file.
    pub sweeps: usize,
    /// Figures drawn for the sweeps' analyses, all sweeps together.
    pub figures: usize,
    /// Figures that could not be drawn, each "stem: error" (the report is written regardless).
    pub figure_errors: Vec<String>,
    /// Raw values of the results taken out as impossible, one line per case ("FILE: case
    /// KEY: ..."; see `ResultsFile::taken_out`).
    pub taken_out: Vec<String>,
    /// Figures written by hand in a kept region, by region: each belongs in a generated
    /// section (a number in a kept region goes stale when the results change).
    pub kept_figures: Vec<(String, Vec<String>)>,
}

/// The results files under `dir`: `dir/<name>/results.json`, sorted by name.
pub fn find_results(dir: &Path) -> Result<Vec<PathBuf>, ReportError> {
    let entries = std::fs::read_dir(dir).map_err(|source| ReportError::Dir {
        path: dir.into(),
        source,
    })?;
    let mut files: Vec<PathBuf> = entries
        .filter_map(|e| e.ok())
        .map(|e| e.path().join("results.json"))
        .filter(|p| p.is_file())
        .collect();
    files.sort();
    if files.is_empty() {
        return Err(ReportError::NoResults { path: dir.into() });
    }
    Ok(files)
}

/// Analyses every sweep under `results_dir` and writes the report to `out`, keeping the
/// hand-written regions of the report already there.
pub fn generate(results_dir: &Path, out: &Path) -> Result<Generated, ReportError> {
    let files = find_results(results_dir)?;
    // Load everything before writing anything: a bad file must not leave a half-updated report.
    let loaded: Vec<(PathBuf, ResultsFile)> = files
        .into_iter()
        .map(|f| ResultsFile::load(&f).map(|r| (f, r)))
        .collect::<Result<_, _>>()?;
    let taken_out: Vec<String> = loaded
        .iter()
        .flat_map(|(f, r)| {
            r.taken_out()
                .into_iter()
                .map(move |line| format!("{}: {line}", f.display()))
        })
        .collect();
    let analyses: Vec<(PathBuf, Analysis)> = loaded
        .iter()
        .map(|(f, r)| analysis::analyze(r, &relative_source(f)).map(|a| (f.clone(), a)))
        .collect::<Result<_, _>>()?;
    let report_dir = out
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    let mut sweeps = Vec::new();
    let mut figure_errors = Vec::new();
    for (file, a) in analyses {
        let dir = file
            .parent()
            .expect("results files are in a directory")
            .join("analysis");
        let written = crate::render::write(&a, &dir)?;
        figure_errors.extend(written.figure_errors);
        sweeps.push(Sweep {
            figures_dir: relative(&dir, report_dir),
            figures: written.figures,
            analysis: a,
        });
    }
    let benches = bench_files(results_dir)?;
    let comm = comm_model(&benches, &sweeps, report_dir, &mut figure_errors);
    let analyses: Vec<&Analysis> = sweeps.iter().map(|s| &s.analysis).collect();
    let tree = analysis::tree_comm::choose(&benches, &analyses);
    let generated = sections::document(&sweeps, comm.as_ref(), tree.as_ref(), results_dir);
    let old = match nbody_engine::input::read_text(out) {
        Ok(text) => text,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => String::new(),
        Err(source) => {
            return Err(ReportError::ReadOld {
                path: out.into(),
                source,
            });
        }
    };
    let keep_err = |source| ReportError::Keep {
        path: out.into(),
        source,
    };
    let kept = keep::extract(&old).map_err(keep_err)?;
    let text = keep::merge(&generated, &kept).map_err(keep_err)?;
    nbody_engine::output::write_atomic(out, text.as_bytes())?;
    Ok(Generated {
        path: out.into(),
        sweeps: sweeps.len(),
        figures: sweeps.iter().map(|s| s.figures.len()).sum(),
        figure_errors,
        taken_out,
        kept_figures: keep::figures(&kept),
    })
}

/// The communication model ([`analysis::comm_model::choose`]) and its figures, drawn next to the
/// mpi-bench file it was fitted on.
fn comm_model(
    benches: &[(PathBuf, MpiBenchFile)],
    sweeps: &[Sweep],
    report_dir: &Path,
    figure_errors: &mut Vec<String>,
) -> Option<sections::Comm> {
    let analyses: Vec<&Analysis> = sweeps.iter().map(|s| &s.analysis).collect();
    let chosen = analysis::comm_model::choose(benches, &analyses)?;
    let weak_mpi = chosen
        .weak_mpi
        .and_then(|a| sweeps.iter().find(|s| std::ptr::eq(&s.analysis, a)));
    let dir = chosen
        .bench
        .parent()
        .expect("in a directory")
        .join("analysis");
    let (figures, errors) = sections::comm_figures(&chosen.model, weak_mpi, &dir);
    figure_errors.extend(errors);
    Some(sections::Comm {
        model: chosen.model,
        figures_dir: relative(&dir, report_dir),
        figures,
    })
}

/// Every `mpi-bench*.json` file one level under the results directory, sorted by path.
fn bench_files(results_dir: &Path) -> Result<Vec<(PathBuf, MpiBenchFile)>, ReportError> {
    let mut benches: Vec<(PathBuf, MpiBenchFile)> = Vec::new();
    for dir in std::fs::read_dir(results_dir)
        .map_err(|source| ReportError::Dir {
            path: results_dir.into(),
            source,
        })?
        .filter_map(|e| e.ok())
    {
        let Ok(files) = std::fs::read_dir(dir.path()) else {
            continue;
        };
        for f in files.filter_map(|e| e.ok()).map(|e| e.path()) {
            let name = f
                .file_name()
                .map(|n| n.to_string_lossy().into_owned())
                .unwrap_or_default();
            if name.starts_with("mpi-bench") && name.ends_with(".json") {
                let bench =
                    MpiBenchFile::load(&f).map_err(|e| ReportError::Bench(e.to_string()))?;
                benches.push((f, bench));
            }
        }
    }
    benches.sort_by(|a, b| a.0.cmp(&b.0));
    Ok(benches)
}

/// The path as given, with `/` separators, so the report does not depend on the machine.
fn relative_source(path: &Path) -> PathBuf {
    PathBuf::from(path.to_string_lossy().replace('\\', "/"))
}

/// `target` relative to `base` when it lies under it (the usual layout: REPORT.md at the top,
/// results below), else as given.
fn relative(target: &Path, base: &Path) -> String {
    let clean = |p: &Path| -> Vec<String> {
        p.components()
            .filter(|c| !matches!(c, std::path::Component::CurDir))
            .map(|c| c.as_os_str().to_string_lossy().into_owned())
            .collect()
    };
    let (t, b) = (clean(target), clean(base));
    let rel = if t.starts_with(&b) {
        &t[b.len()..]
    } else {
        &t[..]
    };
    rel.join("/")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn figure_paths_are_relative_to_the_report() {
        assert_eq!(
            relative(Path::new("results/strong/analysis"), Path::new(".")),
            "results/strong/analysis"
        );
        assert_eq!(
            relative(Path::new("./results/a/analysis"), Path::new("./")),
            "results/a/analysis"
        );
        assert_eq!(relative(Path::new("/x/r/a"), Path::new("/x")), "r/a");
    }
}
