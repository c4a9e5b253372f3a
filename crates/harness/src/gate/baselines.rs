//! A folder of gate baselines, one file per machine class. The gate takes the file measured on
//! the class it runs on (the fast path); a machine class with no file of its own gets A/B
//! against the newest file's commit. Each class CI has run on thus keeps its fast path, and a
//! new class costs one A/B run until its baseline is committed next to the others.
//!
//! A baseline is swept again from the config it stores, resolved when it was measured (every
//! key written out, defaults included, by the build its metadata names), never from its TOML
//! text read under today's defaults: a default that changes later does not change what the
//! gate measures. A baseline this build cannot reproduce (a key, kernel or schema it no
//! longer has, or cases it would plan differently) is [`Fitness::Stale`]: the gate then says
//! why and measures A/B against the baseline's commit; `tests/suite/gate_baselines.rs` keeps
//! every committed baseline reproducible.

use super::RunInfo;
use nbody_records::config::SweepConfig;
use nbody_records::results::{RESULTS_SCHEMA, ResultsError, ResultsFile, read_json};
use std::path::{Path, PathBuf};
use thiserror::Error;

/// The baseline the gate judges against.
#[derive(Debug)]
pub struct Chosen {
    /// The baseline results file, in the baseline folder.
    pub path: PathBuf,
    /// Where it comes from (read even from a file this build can no longer load).
    pub info: RunInfo,
    /// Whether this build can sweep its config again; if not, the gate runs A/B against its
    /// commit.
    pub fitness: Fitness,
}

/// Whether this build can sweep a baseline's config again and get the baseline's cases.
#[derive(Debug)]
pub enum Fitness {
    /// This build parses the stored config and plans exactly the baseline's cases.
    Reproducible(Box<Reproducible>),
    /// Why not, in one line.
    Stale(String),
}

/// A baseline this build reproduces.
#[derive(Debug)]
pub struct Reproducible {
    /// The baseline results as this build loaded them.
    pub file: ResultsFile,
    /// Its stored config, as this build parsed it.
    pub config: SweepConfig,
    /// The stored config as TOML text: what the gate sweeps and what an A/B run gives both
    /// builds (the base build resolved it itself, so it knows every key).
    pub text: String,
}

impl Fitness {
    /// The reproducible baseline, if it is one.
    pub fn reproducible(&self) -> Option<&Reproducible> {
        match self {
            Fitness::Reproducible(r) => Some(r),
            Fitness::Stale(_) => None,
        }
    }
}

/// Reads one baseline and judges whether this build reproduces it. Only a file that is not a
/// results file at all (unreadable, not JSON, no commit or machine recorded) is an error: that
/// needs the user, while a stale one only needs the A/B route.
pub fn examine(path: &Path) -> Result<Chosen, BaselinesError> {
    let value = read_json(path)?;
    let info = RunInfo::from_json(&value).ok_or_else(|| ResultsError::Corrupt {
        path: path.into(),
        detail: "no metadata.git_commit or machine calibration: not a baseline".into(),
    })?;
    let fitness = match ResultsFile::from_value(path, value.clone()) {
        Err(ResultsError::Schema { found, .. }) => Fitness::Stale(format!(
            "its schema `{found}` is not this build's `{RESULTS_SCHEMA}`"
        )),
        Err(e) => Fitness::Stale(format!("this build cannot read it ({e})")),
        Ok(file) => match reproduce(path, &value, file) {
            Ok(r) => Fitness::Reproducible(Box::new(r)),
            Err(why) => Fitness::Stale(why),
        },
    };
    Ok(Chosen {
        path: path.to_path_buf(),
        info,
        fitness,
    })
}

/// The baseline's stored config (the raw JSON `value["config"]`, as the build that measured it
/// resolved it) parsed and planned by this build: the cases must be the baseline's, key for key.
fn reproduce(
    path: &Path,
    value: &serde_json::Value,
    file: ResultsFile,
) -> Result<Reproducible, String> {
    let text = resolved_text(&value["config"])
        .map_err(|e| format!("its stored config has no TOML form ({e})"))?;
    let config = SweepConfig::parse(&text, path)
        .map_err(|e| format!("this build refuses its stored config: {e}"))?;
    let planned: Vec<String> = nbody_records::plan::cases(&config)
        .iter()
        .map(|c| c.key())
        .collect();
    let stored: Vec<String> = file.cases.iter().map(|c| c.key.clone()).collect();
    if planned != stored {
        let only = |a: &[String], b: &[String]| {
            a.iter()
                .filter(|k| !b.contains(k))
                .cloned()
                .collect::<Vec<_>>()
        };
        let (new, gone) = (only(&planned, &stored), only(&stored, &planned));
        return Err(format!(
            "this build plans other cases from its stored config (would measure [{}], which it              does not have; has [{}], which this build would not measure)",
            new.join(", "),
            gone.join(", ")
        ));
    }
    Ok(Reproducible { file, config, text })
}

/// A stored config (JSON) as TOML text, nulls left out (TOML has none: an absent key is the
/// same `None`).
pub fn resolved_text(config: &serde_json::Value) -> Result<String, String> {
    fn strip(v: &serde_json::Value) -> serde_json::Value {
        match v {
            serde_json::Value::Object(map) => map
                .iter()
                .filter(|(_, v)| !v.is_null())
                .map(|(k, v)| (k.clone(), strip(v)))
                .collect(),
            serde_json::Value::Array(items) => items.iter().map(strip).collect(),
            other => other.clone(),
        }
    }
    if !config.is_object() {
        return Err("not a table".into());
    }
    let table = toml::Value::try_from(strip(config)).map_err(|e| e.to_string())?;
    let body = toml::to_string(&table).map_err(|e| e.to_string())?;
    Ok(format!(
        "# The sweep's config as it was resolved when measured: every key written out.\n{body}"
    ))
}

/// Every `.json` file of `dir`, sorted, each examined ([`examine`]): what the compatibility
/// test walks.
pub fn examine_all(dir: &Path) -> Result<Vec<Chosen>, BaselinesError> {
    json_files(dir)?.iter().map(|p| examine(p)).collect()
}

pub(crate) fn json_files(dir: &Path) -> Result<Vec<PathBuf>, BaselinesError> {
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
    Ok(paths)
}

/// Why the baseline folder gives no baseline.
#[derive(Debug, Error)]
pub enum BaselinesError {
    /// The folder cannot be listed.
    #[error("cannot read the baseline folder {path}: {source}")]
    Read {
        /// The folder.
        path: PathBuf,
        /// The underlying error.
        source: std::io::Error,
    },
    /// The folder holds no `.json` file.
    #[error(
        "the baseline folder {0} holds no .json results file; measure one with \
         scripts/refresh-baseline.sh, or pass --against REV"
    )]
    Empty(PathBuf),
    /// A `.json` file in the folder is unreadable, not JSON, or records no commit or machine.
    #[error(transparent)]
    Results(#[from] ResultsError),
}

/// The file of `dir` measured on `here`'s machine class (the newest, if several are), else the
/// newest file of all, marked as of another class. Every `.json` file in `dir` must be a
/// results file: a corrupt one is an error, not skipped, so that a broken baseline is seen; a
/// stale one is chosen as any other and marked so.
pub fn choose(dir: &Path, here: &RunInfo) -> Result<Chosen, BaselinesError> {
    let files = examine_all(dir)?;
    let newest = |candidates: Vec<Chosen>| {
        candidates
            .into_iter()
            .max_by(|a, b| a.info.started.cmp(&b.info.started))
    };
    let (same, other): (Vec<_>, Vec<_>) = files
        .into_iter()
        .partition(|c| c.info.machine_class_differs(here).is_none());
    newest(same)
        .or_else(|| newest(other))
        .ok_or_else(|| BaselinesError::Empty(dir.to_path_buf()))
}

/// A file name for a baseline of `info`'s machine class: `ci-<vendor>-<family>-<model>-
/// <stepping>-<cpus>cpu.json`, e.g. `ci-AuthenticAMD-25-1-1-2cpu.json`.
pub fn file_name(info: &RunInfo) -> String {
    format!(
        "ci-{}.json",
        class_name(info.cpu_signature.as_deref(), info.logical_cpus)
    )
}

/// A machine class as file names spell it, e.g. `AuthenticAMD-25-1-1-2cpu`.
pub fn class_name(signature: Option<&str>, logical_cpus: Option<usize>) -> String {
    let slug: String = signature
        .unwrap_or("unknown")
        .chars()
        .map(|c| if c.is_ascii_alphanumeric() { c } else { '-' })
        .collect();
    let cpus = logical_cpus.map_or("unknown".into(), |n| n.to_string());
    format!("{slug}-{cpus}cpu")
}

/// `name` when it can be a machine class as [`class_name`] spells it: ASCII letters, digits
/// and `-`, so one file name and nothing that leads out of the folder (`../x`, `sub/y`);
/// `Err` says why not.
pub fn check_class_name(name: &str) -> Result<&str, String> {
    if !name.is_empty() && name.chars().all(|c| c.is_ascii_alphanumeric() || c == '-') {
        return Ok(name);
    }
    Err(format!(
        "`{}` is not a machine class: a class is a file name made of letters, digits and `-` \
         (such as GenuineIntel-6-167-1-2cpu, as `nbody-bench history` names this machine's); \
         list the folder of the history to see the classes it holds",
        nbody_engine::output::neutral::control::visible(name)
    ))
}
