//! `report`: the performance characterization (REPORT.md) generated from committed results.
//!
//! Every number and figure comes from a results file under the results directory: each sweep
//! is analysed into `<results>/<name>/analysis/` (fits and figures), and the document links
//! those figures by relative path. Hand-written interpretation lives in kept regions
//! ([`keep`]) that regeneration carries over, so the command never destroys analysis, and the
//! same files always give the same text.

mod comm_section;
pub mod keep;
mod sections;
mod tree_section;

use crate::analysis::{self, Analysis};
use crate::experiment::results::{ResultsError, ResultsFile};
use std::path::{Path, PathBuf};
use thiserror::Error;

#[derive(Debug, Error)]
pub enum ReportError {
    #[error(
        "cannot read the results directory {path}: {source}; pass --results DIR with one sub-directory per sweep"
    )]
    Dir {
        path: PathBuf,
        source: std::io::Error,
    },
    #[error(
        "no results files (<sweep>/results.json) under {path}; run the sweeps first: scripts/report.sh"
    )]
    NoResults { path: PathBuf },
    #[error(transparent)]
    Results(#[from] ResultsError),
    #[error(transparent)]
    Analysis(#[from] analysis::AnalysisError),
    #[error("{path}: {source}; fix or remove the kept-region markers and run again")]
    Keep {
        path: PathBuf,
        source: keep::KeepError,
    },
    #[error("cannot read the existing report {path}: {source}")]
    ReadOld {
        path: PathBuf,
        source: std::io::Error,
    },
    #[error(transparent)]
    Write(#[from] crate::output::WriteError),
    #[error("{0}")]
    Bench(String),
}

/// One analysed sweep and where its figures are, relative to the report.
pub struct Sweep {
    pub analysis: Analysis,
    /// Directory of the figures relative to the report's directory, with `/` separators.
    pub(crate) figures_dir: String,
    pub figures: Vec<crate::render::figures::Figure>,
}

/// What `generate` wrote.
pub struct Generated {
    pub path: PathBuf,
    pub sweeps: usize,
    pub figures: usize,
    pub figure_errors: Vec<String>,
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
    let comm = comm_model(results_dir, &sweeps, report_dir, &mut figure_errors)?;
    let tree = tree_comm(results_dir, &sweeps)?;
    let generated = sections::document(&sweeps, comm.as_ref(), tree.as_ref(), results_dir);
    let old = match crate::input::read_text(out) {
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
    crate::output::write_atomic(out, text.as_bytes())?;
    Ok(Generated {
        path: out.into(),
        sweeps: sweeps.len(),
        figures: sweeps.iter().map(|s| s.figures.len()).sum(),
        figure_errors,
    })
}

/// The communication model and its figures, from the `mpi-bench-<ranks>.json` files under
/// the results directory: the benchmark with the most ranks that still had a CPU each.
fn comm_model(
    results_dir: &Path,
    sweeps: &[Sweep],
    report_dir: &Path,
    figure_errors: &mut Vec<String>,
) -> Result<Option<sections::Comm>, ReportError> {
    // The LJ model is fitted on the library's own transport; a TCP run is the tree section's.
    let benches: Vec<_> = bench_files(results_dir)?
        .into_iter()
        .filter(|(_, b)| !b.over_tcp())
        .collect();
    let weak_mpi = sweeps.iter().find(|s| {
        s.analysis
            .cases
            .iter()
            .any(|c| c.decomp.is_some() && c.case.scenario != crate::scenario::ScenarioKind::Galaxy)
    });
    // The bench in the LJ sweep's own directory when there is one (the same machine).
    let own: Vec<_> = match weak_mpi {
        Some(s) => benches
            .iter()
            .filter(|(p, _)| in_sweep_dir(p, &[s.analysis.name.as_str()]))
            .collect(),
        None => Vec::new(),
    };
    let pool: Vec<_> = if own.is_empty() {
        benches.iter().collect()
    } else {
        own
    };
    let Some((path, bench)) = pool
        .iter()
        .copied()
        .filter(|(_, b)| !b.oversubscribed)
        .max_by_key(|(_, b)| b.ranks)
        .or(pool.first().copied())
    else {
        return Ok(None);
    };
    let n_per_rank = weak_mpi
        .and_then(|s| s.analysis.cases.iter().find(|c| c.ranks == 1).map(|c| c.n))
        .unwrap_or(20_000);
    let model = crate::analysis::comm::comm_model(
        bench,
        &relative_source(path).to_string_lossy(),
        n_per_rank,
        crate::scenario::LJ_GAS_DENSITY,
        crate::scenario::LJ_CUTOFF,
    );
    let dir = path.parent().expect("in a directory").join("analysis");
    let (figures, errors) = sections::comm_figures(&model, weak_mpi, &dir);
    figure_errors.extend(errors);
    Ok(Some(sections::Comm {
        model,
        figures_dir: relative(&dir, report_dir),
        figures,
    }))
}

/// Whether `path` is a file directly in the results directory of one of the sweeps `names`.
fn in_sweep_dir(path: &Path, names: &[&str]) -> bool {
    path.parent()
        .and_then(|d| d.file_name())
        .is_some_and(|d| names.iter().any(|n| d == *n))
}

/// Every `mpi-bench*.json` file one level under the results directory, sorted by path.
fn bench_files(
    results_dir: &Path,
) -> Result<Vec<(PathBuf, crate::ranks::bench_file::MpiBenchFile)>, ReportError> {
    use crate::ranks::bench_file::MpiBenchFile;
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

/// The distributed-tree model, when a sweep ran the galaxy over MPI: counted bytes, and the
/// α-β prediction of every transport an mpi-bench file was measured on.
fn tree_comm(
    results_dir: &Path,
    sweeps: &[Sweep],
) -> Result<Option<crate::analysis::tree_comm::TreeComm>, ReportError> {
    use crate::scenario::ScenarioKind;
    let galaxy: Vec<&Sweep> = sweeps
        .iter()
        .filter(|s| {
            s.analysis
                .cases
                .iter()
                .any(|c| c.decomp.is_some() && c.case.scenario == ScenarioKind::Galaxy)
        })
        .collect();
    let Some(first) = galaxy.first() else {
        return Ok(None);
    };
    let cases = &first.analysis.cases;
    let n_per_rank = cases
        .iter()
        .filter(|c| c.ranks > 0)
        .map(|c| c.n / c.ranks)
        .min()
        .unwrap_or(10_000);
    let theta = cases.iter().find_map(|c| c.theta).unwrap_or(0.5);
    let leaf = crate::kernels::KernelParams::default().leaf_size;
    // A sweep's α-β comes from the mpi-bench files in its own directory (the same machine).
    let names: Vec<&str> = galaxy.iter().map(|s| s.analysis.name.as_str()).collect();
    let files = bench_files(results_dir)?;
    let benches: Vec<(String, &crate::ranks::bench_file::MpiBenchFile)> = files
        .iter()
        .filter(|(p, _)| in_sweep_dir(p, &names))
        .map(|(p, b)| (relative_source(p).to_string_lossy().into_owned(), b))
        .collect();
    let series: Vec<(String, &[crate::analysis::groups::Point])> = galaxy
        .iter()
        .map(|s| (s.analysis.name.clone(), s.analysis.cases.as_slice()))
        .collect();
    Ok(Some(crate::analysis::tree_comm::tree_comm(
        n_per_rank, theta, leaf, &benches, &series,
    )))
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
