//! A folder of gate baselines, one file per machine class. The gate takes the file measured on
//! the class it runs on (the fast path); a machine class with no file of its own gets A/B
//! against the newest file's commit. Each class CI has run on thus keeps its fast path, and a
//! new class costs one A/B run until its baseline is committed next to the others.

use super::RunInfo;
use crate::records::results::{ResultsError, ResultsFile};
use std::path::{Path, PathBuf};
use thiserror::Error;

/// The baseline the gate judges against.
#[derive(Debug)]
pub struct Chosen {
    pub path: PathBuf,
    pub file: ResultsFile,
}

#[derive(Debug, Error)]
pub enum BaselinesError {
    #[error("cannot read the baseline folder {path}: {source}")]
    Read {
        path: PathBuf,
        source: std::io::Error,
    },
    #[error(
        "the baseline folder {0} holds no .json results file; measure one with \
         scripts/refresh-baseline.sh, or pass --against REV"
    )]
    Empty(PathBuf),
    #[error(transparent)]
    Results(#[from] ResultsError),
}

/// The file of `dir` measured on `here`'s machine class (the newest, if several are), else the
/// newest file of all, marked as of another class. Every `.json` file in `dir` must be a
/// results file: a corrupt one is an error, not skipped, so that a broken baseline is seen.
pub fn choose(dir: &Path, here: &RunInfo) -> Result<Chosen, BaselinesError> {
    let read_err = |source| BaselinesError::Read {
        path: dir.to_path_buf(),
        source,
    };
    let mut paths: Vec<PathBuf> = std::fs::read_dir(dir)
        .map_err(read_err)?
        .filter_map(|entry| entry.ok().map(|e| e.path()))
        .filter(|p| p.is_file() && p.extension().is_some_and(|e| e == "json"))
        .collect();
    paths.sort();
    let mut files = Vec::with_capacity(paths.len());
    for path in paths {
        let file = ResultsFile::load(&path)?;
        files.push((path, file));
    }
    let newest = |candidates: Vec<(PathBuf, ResultsFile)>| {
        candidates
            .into_iter()
            .max_by(|a, b| a.1.metadata.started.cmp(&b.1.metadata.started))
    };
    let (same, other): (Vec<_>, Vec<_>) = files
        .into_iter()
        .partition(|(_, f)| RunInfo::of(f).machine_class_differs(here).is_none());
    if let Some((path, file)) = newest(same) {
        return Ok(Chosen { path, file });
    }
    match newest(other) {
        Some((path, file)) => Ok(Chosen { path, file }),
        None => Err(BaselinesError::Empty(dir.to_path_buf())),
    }
}

/// A file name for a baseline of `info`'s machine class: `ci-<vendor>-<family>-<model>-
/// <stepping>-<cpus>cpu.json`, e.g. `ci-AuthenticAMD-25-1-1-2cpu.json`.
pub fn file_name(info: &RunInfo) -> String {
    let signature = info.cpu_signature.as_deref().unwrap_or("unknown");
    let slug: String = signature
        .chars()
        .map(|c| if c.is_ascii_alphanumeric() { c } else { '-' })
        .collect();
    let cpus = info
        .logical_cpus
        .map_or("unknown".into(), |n| n.to_string());
    format!("ci-{slug}-{cpus}cpu.json")
}
