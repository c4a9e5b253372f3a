//! Where configs and results are found.
//!
//! - A config is named by a path, or by a bare name (`strong`, `strong.toml`) looked up in
//!   `configs/` when no such file exists where the user stands.
//! - A user's sweep writes to a run directory of its own, `<out>/runs/<name>/<UTC time>/`, so
//!   that running the same config twice never collides with an earlier run or with the
//!   committed reference results in `<out>/<name>/` (which change only when a sweep is given
//!   `--out` explicitly, as `scripts/report.sh` does).
//! - `analyze`, `gate` and `sweep --resume` name results by a file, a run directory or a config
//!   name (its latest run).

use super::results::ResultsFile;
use std::path::{Path, PathBuf};
use thiserror::Error;

/// The sub-directory of the results root that holds user runs.
pub(crate) const RUNS_DIR: &str = "runs";

/// Where configs named without a path are looked up: `configs/` where the user stands.
fn config_dirs() -> Vec<PathBuf> {
    vec![PathBuf::from("configs")]
}

/// Why a config, a results file or a run directory could not be found or made.
#[derive(Debug, Error)]
pub enum LocateError {
    /// A `--config` that is neither a readable file nor a name found in `configs/`.
    #[error(
        "no config `{given}`: looked for {looked}; configs available: {available}; pass a path \
         or one of these names"
    )]
    NoConfig {
        /// The path or name as the user gave it.
        given: String,
        /// The paths tried, comma-separated.
        looked: String,
        /// The config names in `configs/`, comma-separated.
        available: String,
    },
    /// Results named by a path, directory or config name where no `results.json` exists.
    #[error(
        "no results for `{given}`: looked for {looked}; pass a results.json, a run directory, or \
         the name of a config that has been swept"
    )]
    NoResults {
        /// The path or name as the user gave it.
        given: String,
        /// The paths tried, comma-separated.
        looked: String,
    },
    /// `sweep --resume` without a directory, when every run of the config is complete.
    #[error(
        "no unfinished run of `{name}` under {dir}: every run there is complete, so resuming \
         would measure nothing; start a new run without --resume, or pass the run to resume: \
         --resume DIR"
    )]
    NothingToResume {
        /// The config's name.
        name: String,
        /// The directory of its runs, `<out>/runs/<name>/`.
        dir: PathBuf,
    },
    /// A run newer than any unfinished one has a results file that cannot be loaded (it may be
    /// the run the user means, so it is not skipped).
    #[error(
        "the run {dir} cannot be read ({source}); pass the run to resume (--resume DIR), or \
         move the broken one aside"
    )]
    Unreadable {
        /// The run directory.
        dir: PathBuf,
        /// Why its `results.json` could not be loaded.
        source: Box<super::results::ResultsError>,
    },
    /// A new run directory (or its parent) could not be created.
    #[error("cannot create the run directory {path}: {source}")]
    CreateRun {
        /// The directory that could not be created.
        path: PathBuf,
        /// The I/O error creating it.
        source: std::io::Error,
    },
}

/// The config file `given` names: the path itself if it is a file or a pipe, else `configs/NAME` and
/// `configs/NAME.toml` for a bare name.
pub fn find_config(given: &Path) -> Result<PathBuf, LocateError> {
    // A pipe (`--config <(...)`) is read like a file.
    if nbody_engine::input::is_readable(given) {
        return Ok(given.to_path_buf());
    }
    let mut looked = vec![given.display().to_string()];
    let bare = given.components().count() == 1;
    if bare {
        for dir in config_dirs() {
            let mut candidates = vec![dir.join(given)];
            if given.extension().is_none() {
                candidates.push(dir.join(given).with_extension("toml"));
            }
            for candidate in candidates {
                if candidate.is_file() {
                    return Ok(candidate);
                }
                looked.push(candidate.display().to_string());
            }
        }
    }
    Err(LocateError::NoConfig {
        given: given.display().to_string(),
        looked: looked.join(", "),
        available: available_configs(),
    })
}

/// The names of the configs in the lookup directories, e.g. "ci, quick, strong".
fn available_configs() -> String {
    let mut names: Vec<String> = config_dirs()
        .iter()
        .filter_map(|d| std::fs::read_dir(d).ok())
        .flatten()
        .flatten()
        .filter_map(|e| {
            let path = e.path();
            (path.extension()? == "toml").then(|| path.file_stem()?.to_str().map(String::from))?
        })
        .collect();
    names.sort();
    names.dedup();
    if names.is_empty() {
        "none found (no configs/ directory here)".to_string()
    } else {
        names.join(", ")
    }
}

/// `<root>/runs/<name>/`: the runs of one config.
pub fn runs_dir(root: &Path, name: &str) -> PathBuf {
    root.join(RUNS_DIR).join(name)
}

/// Claims a new run directory `<root>/runs/<name>/<UTC time>/` (with `-2`, `-3`, ... when a run
/// of the same second exists), created empty.
pub fn new_run_dir(root: &Path, name: &str, utc: &str) -> Result<PathBuf, LocateError> {
    let parent = runs_dir(root, name);
    nbody_engine::output::create_dir_all(&parent).map_err(|source| LocateError::CreateRun {
        path: parent.clone(),
        source,
    })?;
    let stamp: String = utc.chars().filter(|c| !matches!(c, ':' | '-')).collect();
    let mut attempt = 1u64;
    loop {
        let dir = if attempt == 1 {
            parent.join(&stamp)
        } else {
            parent.join(format!("{stamp}-{attempt}"))
        };
        match std::fs::create_dir(&dir) {
            Ok(()) => return Ok(dir),
            Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => attempt += 1,
            Err(source) => return Err(LocateError::CreateRun { path: dir, source }),
        }
    }
}

/// The run directories of a config that hold a results file, oldest first (the directory
/// names are UTC times, so their order is the time order).
pub fn runs(root: &Path, name: &str) -> Vec<PathBuf> {
    let Ok(entries) = std::fs::read_dir(runs_dir(root, name)) else {
        return Vec::new();
    };
    let mut dirs: Vec<PathBuf> = entries
        .flatten()
        .map(|e| e.path())
        .filter(|d| d.join("results.json").is_file())
        .collect();
    dirs.sort_by_key(|d| run_order(d));
    dirs
}

/// Sorts `20261201T101500Z-10` after `20261201T101500Z-9`.
fn run_order(dir: &Path) -> (String, u32) {
    let name = dir.file_name().and_then(|n| n.to_str()).unwrap_or("");
    match name.split_once('-') {
        Some((stamp, k)) => (stamp.to_string(), k.parse().unwrap_or(0)),
        None => (name.to_string(), 1),
    }
}

/// The newest run of a config whose results file has a case that is not complete. A run
/// newer than that one whose results cannot be read is an error, not skipped: it may be the
/// very run the user means, and continuing an older one instead would be silent.
pub fn latest_unfinished(root: &Path, name: &str) -> Result<PathBuf, LocateError> {
    for dir in runs(root, name).into_iter().rev() {
        match ResultsFile::load(&dir.join("results.json")) {
            Ok(f) if f.cases.is_empty() || f.cases.iter().any(|c| !c.is_complete()) => {
                return Ok(dir);
            }
            Ok(_) => continue,
            Err(source) => {
                return Err(LocateError::Unreadable {
                    dir,
                    source: Box::new(source),
                });
            }
        }
    }
    Err(LocateError::NothingToResume {
        name: name.to_string(),
        dir: runs_dir(root, name),
    })
}

/// The results file `given` names: a file or a pipe; a directory holding `results.json`; or a config
/// name (`quick`, `quick.toml`, `configs/quick.toml`), meaning its latest run under
/// `<root>/runs/` with a successful case, else its reference results
/// `<root>/<name>/results.json`.
pub fn find_results(given: &Path, root: &Path) -> Result<PathBuf, LocateError> {
    find_results_noting(given, root).map(|found| found.path)
}

/// What [`find_results_noting`] found.
#[derive(Clone, Debug, PartialEq)]
pub struct Found {
    /// The results file.
    pub path: PathBuf,
    /// For a config name: the runs newer than the one taken, passed over because none of their
    /// cases has a successful sample (or their file cannot be read), newest first.
    pub passed_over: Vec<PathBuf>,
}

/// [`find_results`], with the newer runs of a config name it passed over: a run whose every
/// case failed, or that was stopped before any case finished, has nothing to analyse or
/// compare, and taking it silently would hide the run that has.
pub fn find_results_noting(given: &Path, root: &Path) -> Result<Found, LocateError> {
    let found = |path: PathBuf| Found {
        path,
        passed_over: Vec::new(),
    };
    if nbody_engine::input::is_readable(given) {
        return Ok(found(given.to_path_buf()));
    }
    let mut looked = Vec::new();
    if given.is_dir() {
        let inside = given.join("results.json");
        if inside.is_file() {
            return Ok(found(inside));
        }
        looked.push(inside.display().to_string());
    } else {
        // A path that is no directory was looked for as the file itself (`results.json`, not
        // `results.json/results.json`).
        looked.push(given.display().to_string());
    }
    if let Some(name) = config_name(given) {
        let all = runs(root, &name);
        let mut passed_over = Vec::new();
        for run in all.iter().rev() {
            let path = run.join("results.json");
            let measured =
                ResultsFile::load(&path).is_ok_and(|f| f.cases.iter().any(|c| c.summary.is_some()));
            if measured {
                return Ok(Found { path, passed_over });
            }
            passed_over.push(run.clone());
        }
        // No run has a successful case: the newest, whose own errors then say why.
        if let Some(latest) = all.last() {
            return Ok(found(latest.join("results.json")));
        }
        looked.push(format!(
            "{}/*/results.json",
            runs_dir(root, &name).display()
        ));
        let reference = root.join(&name).join("results.json");
        if reference.is_file() {
            return Ok(found(reference));
        }
        looked.push(reference.display().to_string());
    }
    Err(LocateError::NoResults {
        given: given.display().to_string(),
        looked: looked.join(", "),
    })
}

/// The config name a path stands for: `quick` for `quick`, `quick.toml`, `configs/quick.toml`.
fn config_name(given: &Path) -> Option<String> {
    let is_toml = given.extension().is_some_and(|e| e == "toml");
    let bare = given.components().count() == 1;
    if !(bare || is_toml) || given.extension().is_some_and(|e| e != "toml") {
        return None;
    }
    let stem = given.file_stem()?.to_str()?;
    (!stem.is_empty() && !stem.starts_with('.')).then(|| stem.to_string())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn run_directories_are_new_and_ordered() {
        let root = tempfile::tempdir().unwrap();
        let a = new_run_dir(root.path(), "quick", "2026-12-01T10:15:00Z").unwrap();
        let b = new_run_dir(root.path(), "quick", "2026-12-01T10:15:00Z").unwrap();
        assert_ne!(a, b);
        assert!(a.ends_with("runs/quick/20261201T101500Z"), "{a:?}");
        assert!(b.ends_with("runs/quick/20261201T101500Z-2"), "{b:?}");
        // Only runs with a results file count.
        assert!(runs(root.path(), "quick").is_empty());
        for _ in 3..=10 {
            new_run_dir(root.path(), "quick", "2026-12-01T10:15:00Z").unwrap();
        }
        let all: Vec<PathBuf> = std::fs::read_dir(runs_dir(root.path(), "quick"))
            .unwrap()
            .flatten()
            .map(|e| e.path())
            .collect();
        for d in &all {
            std::fs::write(d.join("results.json"), "{}").unwrap();
        }
        let ordered = runs(root.path(), "quick");
        assert_eq!(ordered.len(), 10);
        assert!(ordered[0].ends_with("20261201T101500Z"));
        assert!(ordered[9].ends_with("20261201T101500Z-10"), "{ordered:?}");
    }

    #[test]
    fn config_names() {
        assert_eq!(config_name(Path::new("quick")).as_deref(), Some("quick"));
        assert_eq!(
            config_name(Path::new("quick.toml")).as_deref(),
            Some("quick")
        );
        assert_eq!(
            config_name(Path::new("configs/quick.toml")).as_deref(),
            Some("quick")
        );
        assert_eq!(config_name(Path::new("a/b.json")), None);
        assert_eq!(config_name(Path::new("dir/sub")), None);
    }

    #[test]
    fn results_by_name_prefer_the_latest_run() {
        let root = tempfile::tempdir().unwrap();
        let missing = find_results(Path::new("quick"), root.path()).unwrap_err();
        assert!(
            missing.to_string().contains("runs/quick/*/results.json"),
            "{missing}"
        );
        let reference = root.path().join("quick");
        nbody_engine::output::create_dir_all(&reference).unwrap();
        std::fs::write(reference.join("results.json"), "{}").unwrap();
        assert_eq!(
            find_results(Path::new("quick"), root.path()).unwrap(),
            reference.join("results.json")
        );
        let run = new_run_dir(root.path(), "quick", "2026-12-01T10:15:00Z").unwrap();
        std::fs::write(run.join("results.json"), "{}").unwrap();
        assert_eq!(
            find_results(Path::new("quick.toml"), root.path()).unwrap(),
            run.join("results.json")
        );
        assert_eq!(
            find_results(&run, root.path()).unwrap(),
            run.join("results.json")
        );
    }

    #[test]
    fn a_missing_config_lists_the_places_and_the_configs() {
        let e = find_config(Path::new("no-such-config"))
            .unwrap_err()
            .to_string();
        assert!(e.contains("configs/no-such-config.toml"), "{e}");
        // The configs available where the user stands (tests/suite/bad_input.rs lists them
        // from the repository's root).
        assert!(e.contains("configs available: "), "{e}");
    }
}
