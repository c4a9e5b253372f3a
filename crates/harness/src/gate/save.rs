//! `gate --save-baseline`: a sweep of the baseline's config kept as its machine class's
//! baseline, once it is fit to be one.

use super::{BUSY_BASELINE_CPUS, GateOptions, RunInfo, background_cpus, baselines, compare};
use nbody_records::locate;
use nbody_records::results::ResultsFile;
use std::path::{Path, PathBuf};

/// Keeps `results` in `folder` under its machine class's name, replacing that class's earlier
/// file, once it compares cleanly with itself (schema, calibration, config, every case
/// judgeable), was measured on a quiet machine, and plans again to its own cases with this
/// build; the other classes' files stay. Every refusal leaves the folder as it was. Returns
/// the file written and the class it was kept for.
pub fn save_baseline(folder: &Path, results: &Path) -> anyhow::Result<(PathBuf, RunInfo)> {
    let source = locate::find_results(results, Path::new("results"))?;
    if nbody_engine::input::is_pipe(&source) {
        // It is read twice: checked, then copied byte for byte.
        anyhow::bail!(
            "--save-baseline {}: is a pipe; a baseline is checked and then copied, so it must \
             be a file: write it to one first",
            source.display()
        );
    }
    let file = ResultsFile::load(&source)?;
    if file.calibration.start.is_none() && file.calibration.end.is_none() {
        anyhow::bail!(
            "{} was swept without calibration, so its machine class is unknown; sweep \
             configs/ci.toml again with calibration",
            source.display()
        );
    }
    if let Some(busy) = background_cpus(&file).filter(|&b| b >= BUSY_BASELINE_CPUS) {
        // The reference workload slows down more than the kernels under load: every later
        // run on a quiet machine would read as a regression.
        anyhow::bail!(
            "{} was measured while other processes used {busy:.2} CPUs (at most \
             {BUSY_BASELINE_CPUS} for a baseline): every later run would be judged against a \
             slowed reference; wait for the other work to end and run \
             scripts/refresh-baseline.sh again",
            source.display(),
        );
    }
    compare(&file, &file, &GateOptions::default())?;
    if let Some(why) = unfit_as_baseline(&file) {
        anyhow::bail!(
            "{} cannot be a baseline, since a gate could not judge against it: {why}; sweep \
             the config to completion (sweep --resume) and save that run",
            source.display()
        );
    }
    if let baselines::Fitness::Stale(why) = baselines::examine(&source)?.fitness {
        anyhow::bail!(
            "{} cannot be a baseline: {why}; sweep the config again with this build",
            source.display()
        );
    }
    if folder.is_file() {
        anyhow::bail!(
            "--baseline {} is a file; --save-baseline needs the folder of baselines \
             (results/baseline)",
            folder.display()
        );
    }
    std::fs::create_dir_all(folder)
        .map_err(|e| anyhow::anyhow!("cannot create {}: {e}", folder.display()))?;
    let info = RunInfo::of(&file);
    let target = folder.join(baselines::file_name(&info));
    let text = nbody_engine::input::read_text(&source)
        .map_err(|e| anyhow::anyhow!("cannot read {}: {e}", source.display()))?;
    nbody_engine::output::write_atomic(&target, text.as_bytes())?;
    Ok((target, info))
}

/// Why a results file cannot be a baseline: every check the gate makes against it must be
/// able to compare something, so a file with no case, a case with no measured round, an
/// unfinished case, or fewer successful samples than a CI needs is refused.
pub fn unfit_as_baseline(file: &ResultsFile) -> Option<String> {
    if file.cases.is_empty() {
        return Some("it holds no case".to_string());
    }
    let mut why: Vec<String> = file
        .cases
        .iter()
        .filter(|c| !c.is_complete())
        .map(|c| {
            format!(
                "{}: {}/{} rounds measured",
                c.key, c.rounds_done, c.rounds_planned
            )
        })
        .collect();
    // The file against itself: every case it could not judge is one a gate could not either.
    if let Ok(report) = compare(file, file, &GateOptions::default()) {
        for m in &report.missing {
            if !why.iter().any(|w| w.starts_with(&format!("{}:", m.key))) {
                why.push(format!("{}: {}", m.key, m.reason));
            }
        }
    }
    (!why.is_empty()).then(|| listed(&why))
}

/// The first few of `items`, "; "-separated, with how many more there are.
pub fn listed(items: &[String]) -> String {
    const SHOWN: usize = 5;
    let mut text = items
        .iter()
        .take(SHOWN)
        .cloned()
        .collect::<Vec<_>>()
        .join("; ");
    if items.len() > SHOWN {
        text += &format!("; and {} more", items.len() - SHOWN);
    }
    text
}
