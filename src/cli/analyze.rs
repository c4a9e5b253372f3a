//! `analyze`: refit and re-plot a saved sweep.

use crate::cli::args::AnalyzeArgs;
use nbody_harness::analysis;
use nbody_harness::render::Written;
use nbody_records::locate;
use nbody_records::results::ResultsFile;
use std::path::{Path, PathBuf};

pub fn analyze(args: AnalyzeArgs) -> anyhow::Result<i32> {
    let found = locate::find_results_noting(&args.results, Path::new("results"))?;
    let path = found.path;
    if !found.passed_over.is_empty() {
        let newer: Vec<String> = found
            .passed_over
            .iter()
            .map(|p| p.display().to_string())
            .collect();
        eprintln!(
            "analyzing {}, the newest run with a successful case; newer run(s) without one: {}",
            path.display(),
            newer.join(", ")
        );
    } else if path != args.results {
        eprintln!("analyzing {}", path.display());
    }
    if args.out.is_none() && nbody_engine::input::is_pipe(&path) {
        anyhow::bail!(
            "{} is a pipe: its analysis has no directory to go beside; name one with --out DIR",
            path.display()
        );
    }
    // Whatever the analysis writes, under whatever name, never replaces what it reads.
    nbody_engine::output::protect_inputs(&[("results", &path)]);
    let results = ResultsFile::load(&path)?;
    for line in results.taken_out() {
        eprintln!("warning: {}: {line}", path.display());
    }
    let dir = args.out.unwrap_or_else(|| default_dir(&path));
    let written = run(&results, &path, &dir)?;
    print_written(&written);
    Ok(0)
}

/// `analysis/` beside the results file.
pub fn default_dir(results: &Path) -> PathBuf {
    results.parent().unwrap_or(Path::new(".")).join("analysis")
}

/// Analyses `results` into `dir`; shared with the end of `sweep`.
pub fn run(results: &ResultsFile, source: &Path, dir: &Path) -> anyhow::Result<Written> {
    let analysis = analysis::analyze(results, source)?;
    Ok(nbody_harness::render::write(&analysis, dir)?)
}

pub fn print_written(w: &Written) {
    outln!(
        "analysis: {} and {} with {} figure(s) in {}",
        w.fits.display(),
        w.summary.display(),
        w.figures.len(),
        w.fits.parent().unwrap_or(Path::new(".")).display()
    );
    for e in &w.figure_errors {
        eprintln!("warning: figure not drawn: {e}");
    }
}
