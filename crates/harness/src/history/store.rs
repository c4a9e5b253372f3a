//! The history store: one JSON Lines file per machine class under `results/history/`, one
//! record per case and measurement, only ever appended to. Plain text, so that it diffs and
//! merges like the code it describes; a line is a whole record, so that two appenders at once
//! keep both (each writes its lines in one call under an exclusive lock of the file) and a
//! damaged line costs that line only: a reader names it by its number and reads the rest.

use super::lines::{Line, parse_lines, read_lines};
use crate::gate::RunInfo;
use crate::gate::baselines::class_name;
use nbody_engine::kernels::WorkCounters;
use nbody_records::results::{CaseRecord, ResultsFile};
use serde::{Deserialize, Serialize};
use std::io::Write;
use std::path::{Path, PathBuf};
use thiserror::Error;

/// The schema tag every record carries.
pub const HISTORY_SCHEMA: &str = "nbody-bench-history/1";

/// Bootstrap resamples of a normalised median's interval (a fixed seed: the same file gives
/// the same records).
const RESAMPLES: usize = 2000;
const SEED: u64 = 0x5eed;

/// One case of one measurement (a sweep, a gate run, a backfilled commit).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Record {
    /// Schema tag, [`HISTORY_SCHEMA`]; a line with another is not read as a record.
    pub schema: String,
    /// The commit measured (empty when the results name none), its first parent and its
    /// committer date (ISO 8601), when git knows them.
    pub commit: String,
    /// Full hash of the commit's first parent; `None` when git does not know the commit.
    pub parent: Option<String>,
    /// Committer date of the commit, ISO 8601; `None` when git does not know the commit.
    pub commit_date: Option<String>,
    /// Uncommitted changes were in the build.
    pub dirty: bool,
    /// UTC, when the measurement started.
    pub measured: String,
    /// The machine class (CPU signature and logical CPUs), as the gate's baselines name it.
    pub class: String,
    /// How the measured binary was built.
    pub build: Build,
    /// The sweep config's name and what made the record (`sweep`, `gate`, `backfill`).
    pub config: String,
    /// What made the record: `sweep`, `gate` or `backfill`.
    pub source: String,
    /// The case key, and its particle count.
    pub case: String,
    /// Particles of the case.
    pub n: usize,
    /// Median time per step with its bootstrap 95% interval, seconds.
    pub median_s: f64,
    /// Bootstrap 95% interval of that median, seconds per step ([low, high]).
    pub ci95_s: [f64; 2],
    /// The same over the reference workload timed before each sample (dimensionless), when
    /// every sample has one: comparable across machines of a class whose speed drifts.
    pub normalized: Option<Normalized>,
    /// Samples the median is over, all rounds, the rejected ones left out.
    pub samples: usize,
    /// The work of one force computation on the initial state (the same for the same code).
    pub work: Option<WorkCounters>,
}

/// How the measured binary was built.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Build {
    /// Version of nbody-bench that measured (`CARGO_PKG_VERSION`).
    pub tool_version: String,
    /// Cargo profile of the build: "release" or "debug".
    pub profile: String,
    /// The SIMD level the kernels ran with.
    pub simd: String,
    /// Cargo features compiled in.
    pub features: Vec<String>,
}

/// A case's median over the reference workload timed before each sample (dimensionless).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Normalized {
    /// Median of each sample over its reference time.
    pub median: f64,
    /// Bootstrap 95% interval of that median ([low, high]).
    pub ci95: [f64; 2],
}

pub use super::lines::BadLine;

/// A history file's records, and the lines that were not records.
#[derive(Clone, Debug, Default)]
pub struct History {
    /// The readable records, in file order.
    pub records: Vec<Record>,
    /// The lines that were not records, left out.
    pub bad: Vec<BadLine>,
    /// Lines that carry the history's schema, read or left out: a file with one is a history
    /// file, however damaged.
    pub tagged: usize,
}

/// Why a history file cannot be read or appended to.
#[derive(Debug, Error)]
pub enum HistoryError {
    /// The history file exists but cannot be read.
    #[error("cannot read {path}: {source}")]
    Read {
        /// The file.
        path: PathBuf,
        /// The underlying error.
        source: std::io::Error,
    },
    /// A record to append holds a value no measurement gives: nothing is appended.
    #[error(
        "not recording case {case}: {problem}; nothing was appended to the history (a record \
         no reader could use would only be left out when read)"
    )]
    Invalid {
        /// The case key.
        case: String,
        /// What is wrong with the record.
        problem: String,
    },
    /// The history folder or a file in it cannot be created, locked or written.
    #[error("cannot append to {path}: {source}")]
    Append {
        /// The file.
        path: PathBuf,
        /// The underlying error.
        source: std::io::Error,
    },
}

/// The commit facts git gives for a record: first parent and committer date.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct CommitFacts {
    /// Full hash of the commit's first parent; `None` when git does not know the commit.
    pub parent: Option<String>,
    /// Committer date, ISO 8601 (`git show --format=%cI`); `None` when git does not know it.
    pub date: Option<String>,
}

impl CommitFacts {
    /// What `git` in `repo` knows of `commit` (nothing when git or the commit is missing,
    /// or when `commit` is not a commit hash: git is never asked about other text).
    pub fn of(repo: &Path, commit: &str) -> CommitFacts {
        let Some(commit) = crate::git::Rev::recorded(commit) else {
            return CommitFacts::default();
        };
        let git = |args: &[&str], rev: &crate::git::Rev| -> Option<String> {
            let out = crate::git::command(repo, args, &[rev])
                .stderr(std::process::Stdio::null())
                .output()
                .ok()?;
            let text = String::from_utf8(out.stdout).ok()?;
            (out.status.success() && !text.trim().is_empty()).then(|| text.trim().to_string())
        };
        CommitFacts {
            parent: git(&["rev-parse", "--verify", "--quiet"], &commit.parent()),
            date: git(&["show", "-s", "--format=%cI"], &commit),
        }
    }
}

/// The records of every measured case of `file`: `source` says what made it, `facts` the
/// commit's parent and date, `machine` the class when the file has no calibration (it was
/// measured on this machine just before). A case without a successful sample is left out.
pub fn records_of(
    file: &ResultsFile,
    source: &str,
    facts: &CommitFacts,
    machine: &RunInfo,
) -> Vec<Record> {
    let info = RunInfo::of(file);
    let class = match info.cpu_signature {
        Some(_) => class_name(info.cpu_signature.as_deref(), info.logical_cpus),
        None => class_name(machine.cpu_signature.as_deref(), machine.logical_cpus),
    };
    let m = &file.metadata;
    let build = Build {
        tool_version: m.tool_version.clone(),
        profile: m.profile.clone(),
        simd: m.simd.clone(),
        features: m.cargo_features.clone(),
    };
    file.cases
        .iter()
        .filter_map(|c| {
            let s = c.summary.as_ref()?;
            Some(Record {
                schema: HISTORY_SCHEMA.to_string(),
                commit: m.git_commit.clone(),
                parent: facts.parent.clone(),
                commit_date: facts.date.clone(),
                dirty: m.git_dirty,
                measured: m.started.clone(),
                class: class.clone(),
                build: build.clone(),
                config: file.config.name.clone(),
                source: source.to_string(),
                case: c.key.clone(),
                n: c.n,
                median_s: s.median_s,
                ci95_s: s.ci95_s,
                normalized: normalized(c),
                samples: s.samples,
                work: c.rounds.iter().find_map(|r| r.initial_work),
            })
        })
        .collect()
}

/// The median of each sample over the reference timed right before it, with its interval;
/// `None` unless every sample has its reference.
fn normalized(c: &CaseRecord) -> Option<Normalized> {
    let mut ratios = Vec::new();
    for r in &c.rounds {
        if r.reference_s.len() != r.samples_s.len() {
            return None;
        }
        ratios.extend(r.samples_s.iter().zip(&r.reference_s).map(|(s, t)| s / t));
    }
    if !ratios.iter().all(|x| x.is_finite() && *x > 0.0) {
        return None;
    }
    let median = nbody_engine::stats::median(&ratios)?;
    let ci95 = nbody_engine::stats::bootstrap_median_ci(&ratios, RESAMPLES, SEED)?;
    Some(Normalized { median, ci95 })
}

/// `dir/<class>.jsonl`, the history of one machine class.
pub fn file_of(dir: &Path, class: &str) -> PathBuf {
    dir.join(format!("{class}.jsonl"))
}

/// Appends `records` to the history files under `dir` (one per class, created as needed):
/// each file's lines in one write under an exclusive lock, through no link. Returns the files
/// written, with the number of records each.
pub fn append(dir: &Path, records: &[Record]) -> Result<Vec<(PathBuf, usize)>, HistoryError> {
    // Checked as every reader checks a line, before anything is written.
    if let Some((r, problem)) = records.iter().find_map(|r| Some((r, r.problem()?))) {
        return Err(HistoryError::Invalid {
            case: r.case.clone(),
            problem,
        });
    }
    let mut classes: Vec<&str> = records.iter().map(|r| r.class.as_str()).collect();
    classes.sort_unstable();
    classes.dedup();
    let mut written = Vec::new();
    for class in classes {
        let path = file_of(dir, class);
        let fail = |source| HistoryError::Append {
            path: path.clone(),
            source,
        };
        let mut text = String::new();
        let mut count = 0;
        for r in records.iter().filter(|r| r.class == class) {
            // A record serialises: its numbers were checked above.
            let line = serde_json::to_string(r).map_err(|e| fail(std::io::Error::other(e)))?;
            text.push_str(&line);
            text.push('\n');
            count += 1;
        }
        nbody_engine::output::create_dir_all(dir).map_err(fail)?;
        append_text(&path, &text).map_err(fail)?;
        written.push((path.clone(), count));
    }
    Ok(written)
}

/// Appends `text` (whole lines) to `path` in one write under an exclusive lock; a file that
/// does not end with a newline (a writer stopped mid-line) gets one first, so that the damage
/// stays on its own line.
pub(crate) fn append_text(path: &Path, text: &str) -> std::io::Result<()> {
    use std::io::{Read, Seek, SeekFrom};
    use std::os::unix::fs::OpenOptionsExt;
    let mut file = std::fs::OpenOptions::new()
        .read(true)
        .append(true)
        .create(true)
        .custom_flags(libc::O_NOFOLLOW)
        .open(path)?;
    if !file.metadata()?.is_file() {
        return Err(std::io::Error::other("not a regular file"));
    }
    file.lock()?;
    let mut out = String::new();
    let len = file.metadata()?.len();
    if len > 0 {
        let mut last = [0u8; 1];
        file.seek(SeekFrom::Start(len - 1))?;
        file.read_exact(&mut last)?;
        if last[0] != b'\n' {
            out.push('\n');
        }
    }
    out.push_str(text);
    file.write_all(out.as_bytes())?;
    file.flush()?;
    file.unlock()
}

impl Line for Record {
    const SCHEMA: &'static str = HISTORY_SCHEMA;
    const WHAT: &'static str = "a history record";
    const SUFFIX: &'static str = ".jsonl";
    fn class(&self) -> &str {
        &self.class
    }
    fn problem(&self) -> Option<String> {
        let interval = |what: &str, [lo, hi]: [f64; 2]| {
            (!(lo.is_finite() && hi.is_finite() && lo > 0.0 && lo <= hi))
                .then(|| format!("{what} = [{lo}, {hi}] is not an interval of times > 0"))
        };
        let time = |what: &str, v: f64| {
            (!(v.is_finite() && v > 0.0)).then(|| format!("{what} = {v} is not a time > 0"))
        };
        let normalized = self.normalized.and_then(|n| {
            time("normalized.median", n.median).or_else(|| interval("normalized.ci95", n.ci95))
        });
        time("median_s", self.median_s)
            .or_else(|| interval("ci95_s", self.ci95_s))
            .or(normalized)
            .or_else(|| (self.samples == 0).then(|| "it is of 0 samples".to_string()))
            .or_else(|| (self.n == 0).then(|| "it is of n = 0 particles".to_string()))
            .or_else(|| {
                self.case
                    .is_empty()
                    .then(|| "its case key is empty".to_string())
            })
            .or_else(|| {
                self.class
                    .is_empty()
                    .then(|| "its machine class is empty".to_string())
            })
    }
}

impl Record {
    /// Whether the record names the commit it measured: a sweep outside a git checkout names
    /// `unknown`, a results file that names none gives an empty commit.
    pub fn commit_known(&self) -> bool {
        !(self.commit.is_empty() || self.commit == "unknown")
    }
}

/// Reads a history file: every record, and every line that is not one with its number (the
/// rest stays readable). A record must name the class the file is named after
/// (`<class>.jsonl`). A missing file is an empty history.
pub fn read(path: &Path) -> Result<History, HistoryError> {
    let lines = read_lines(path).map_err(|source| HistoryError::Read {
        path: path.into(),
        source,
    })?;
    Ok(History {
        records: lines.good,
        bad: lines.bad,
        tagged: lines.tagged,
    })
}

/// The records of a history's text, whatever their class (see [`read`]).
pub fn parse(text: &str) -> History {
    let lines = parse_lines(text.as_bytes(), None);
    History {
        records: lines.good,
        bad: lines.bad,
        tagged: lines.tagged,
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// A record of `case` at `commit` (class `Test-1-2-3-2cpu`, config `ci`), for the tests of
    /// the history's modules.
    pub(crate) fn record(case: &str, commit: &str, median_s: f64) -> Record {
        Record {
            schema: HISTORY_SCHEMA.into(),
            commit: commit.into(),
            parent: None,
            commit_date: Some("2026-12-01T10:00:00+00:00".into()),
            dirty: false,
            measured: "2026-12-05T10:00:00Z".into(),
            class: "Test-1-2-3-2cpu".into(),
            build: Build {
                tool_version: "0.1.0".into(),
                profile: "release".into(),
                simd: "avx2".into(),
                features: vec![],
            },
            config: "ci".into(),
            source: "sweep".into(),
            case: case.into(),
            n: 1000,
            median_s,
            ci95_s: [median_s * 0.99, median_s * 1.01],
            normalized: None,
            samples: 16,
            work: None,
        }
    }

    #[test]
    fn a_damaged_line_costs_that_line_only() {
        let dir = tempfile::tempdir().unwrap();
        let a = record("lj-box/naive/n=1000", "abc", 1e-3);
        append(dir.path(), std::slice::from_ref(&a)).unwrap();
        let path = file_of(dir.path(), &a.class);
        // A writer stopped mid-line, then a good append after it.
        let mut f = std::fs::OpenOptions::new()
            .append(true)
            .open(&path)
            .unwrap();
        f.write_all(b"{\"schema\": \"nbody-bench-hist").unwrap();
        drop(f);
        let b = record("lj-box/naive/n=1000", "def", 2e-3);
        append(dir.path(), std::slice::from_ref(&b)).unwrap();
        let h = read(&path).unwrap();
        assert_eq!(h.records, [a, b]);
        assert_eq!(h.bad.len(), 1);
        assert_eq!(h.bad[0].line, 2);
        assert!(h.bad[0].problem.contains("not a history record"));
    }

    #[test]
    fn concurrent_appenders_keep_every_record() {
        let dir = tempfile::tempdir().unwrap();
        let threads: Vec<_> = (0..8)
            .map(|t| {
                let dir = dir.path().to_path_buf();
                std::thread::spawn(move || {
                    for i in 0..50 {
                        let r = record(&format!("case-{t}"), &format!("{i}"), 1e-3);
                        append(&dir, &[r.clone(), r]).unwrap();
                    }
                })
            })
            .collect();
        for t in threads {
            t.join().unwrap();
        }
        let h = read(&file_of(dir.path(), "Test-1-2-3-2cpu")).unwrap();
        assert!(h.bad.is_empty(), "{:?}", h.bad);
        assert_eq!(h.records.len(), 8 * 50 * 2);
        for t in 0..8 {
            let mine: Vec<&str> = h
                .records
                .iter()
                .filter(|r| r.case == format!("case-{t}"))
                .map(|r| r.commit.as_str())
                .collect();
            // Each appender's pair stays together, in its order.
            let want: Vec<String> = (0..50)
                .flat_map(|i| [i.to_string(), i.to_string()])
                .collect();
            assert_eq!(mine, want);
        }
    }

    #[test]
    fn a_link_planted_at_the_history_file_is_not_written_through() {
        let dir = tempfile::tempdir().unwrap();
        let victim = dir.path().join("victim");
        std::fs::write(&victim, "mine\n").unwrap();
        let r = record("c", "abc", 1e-3);
        std::os::unix::fs::symlink(&victim, file_of(dir.path(), &r.class)).unwrap();
        assert!(append(dir.path(), &[r]).is_err());
        assert_eq!(std::fs::read_to_string(&victim).unwrap(), "mine\n");
    }

    #[test]
    fn a_record_no_reader_could_use_is_never_appended() {
        let dir = tempfile::tempdir().unwrap();
        let good = record("a", "abc", 1e-3);
        for median in [-1.0, 0.0, f64::NAN, f64::INFINITY] {
            let bad = record("b", "abc", median);
            let e = append(dir.path(), &[good.clone(), bad]).unwrap_err();
            assert!(
                e.to_string()
                    .starts_with("not recording case b: median_s = "),
                "{e}"
            );
            assert!(e.to_string().contains("is not a time > 0"), "{e}");
        }
        // Nothing of a refused batch was written, the good record included.
        assert!(!file_of(dir.path(), &good.class).exists());
        let mut no_samples = good.clone();
        no_samples.samples = 0;
        assert!(append(dir.path(), &[no_samples]).is_err());
    }

    #[test]
    fn a_record_of_another_schema_is_named_not_read() {
        let line = serde_json::to_string(&record("c", "abc", 1e-3))
            .unwrap()
            .replace(HISTORY_SCHEMA, "nbody-bench-history/9");
        let h = parse(&format!("\n{line}\n"));
        assert!(h.records.is_empty());
        assert_eq!(h.bad[0].line, 2);
        assert!(h.bad[0].problem.contains("history/9"));
    }
}
