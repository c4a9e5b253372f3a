//! `publish`: the history as one self-contained HTML page (inline SVG, a small inline script
//! that only adds a filter box and tooltips; no network) and as a Markdown summary for a
//! pull-request comment. Both are made from one [`Page`], built from every history file of a
//! folder with the same series ([`super::series`]) and steps and drifts ([`super::steps`]) the `history`
//! command shows, and from the gate verdicts kept beside them ([`super::verdicts`]). Nothing
//! in the page depends on when or where it was made: the same files give the same bytes.

mod chart;
mod html;
pub mod markdown;
pub mod report_figures;

use super::changes::ChangeError;
use super::series::{Series, series};
use super::steps::{Drift, Step, changes};
use super::store::{self, HistoryError, Record};
use super::verdicts::{self, CaseVerdict, GateRun, Verdicts};
use report_figures::Figure;
use std::path::{Path, PathBuf};
use thiserror::Error;

pub use html::html;

/// The page's file name inside the output folder.
pub const PAGE_FILE: &str = "index.html";

/// Why the history page cannot be made or written.
#[derive(Debug, Error)]
pub enum PublishError {
    /// The history folder does not exist.
    #[error(
        "{0} does not exist: there is no history to publish (record one with `nbody-bench \
         history record RESULTS`, `sweep --record` or `gate --record`, or name the folder \
         that holds it with --dir)"
    )]
    NoDir(PathBuf),
    /// The history folder cannot be listed.
    #[error("cannot list {path}: {source}")]
    List {
        /// The folder.
        path: PathBuf,
        /// The underlying error.
        source: std::io::Error,
    },
    /// The folder holds no `<class>.jsonl` with a readable record.
    #[error(
        "{0} holds no history record (no <class>.jsonl with a readable line): record one with \
         `nbody-bench history record RESULTS`, or name another folder with --dir"
    )]
    Empty(PathBuf),
    /// A history or verdict file exists but cannot be read.
    #[error(transparent)]
    History(#[from] HistoryError),
    /// A series holds a value that is not a time, so its steps cannot be found.
    #[error("the series of {case} on {class}: {source}")]
    Series {
        /// The case key.
        case: String,
        /// The machine class.
        class: String,
        /// What is wrong with the series.
        source: ChangeError,
    },
    /// The report whose figures the page links exists but cannot be read.
    #[error(
        "cannot read --report {path}: {source} (the page links the figures of REPORT.md, a \
         file beside them)"
    )]
    Report {
        /// The report.
        path: PathBuf,
        /// Why it cannot be read.
        source: std::io::Error,
    },
    /// The page, or its folder, cannot be written.
    #[error("cannot write the page: {0}; choose a folder you can write to with --out")]
    Write(#[from] nbody_engine::output::WriteError),
}

/// The history files of one machine class, read.
#[derive(Clone, Debug)]
pub struct ClassFiles {
    /// The machine class, as its file names are (`<class>.jsonl`).
    pub class: String,
    /// Its readable history records, in file order.
    pub records: Vec<Record>,
    /// Its gate runs, from `<class>.gate.jsonl` (none when that file is missing).
    pub verdicts: Verdicts,
}

/// Every class of a history folder, and a warning for each line that was left out.
#[derive(Clone, Debug)]
pub struct Loaded {
    /// Every class with at least one readable record, in the order of their names.
    pub classes: Vec<ClassFiles>,
    /// One for each line left out of a file, naming the file, the line and what is wrong.
    pub warnings: Vec<String>,
}

/// Reads every `<class>.jsonl` of `dir` (in the order of their names) and the
/// `<class>.gate.jsonl` beside each.
pub fn load(dir: &Path) -> Result<Loaded, PublishError> {
    if !dir.is_dir() {
        return Err(PublishError::NoDir(dir.to_path_buf()));
    }
    let list = |source| PublishError::List {
        path: dir.to_path_buf(),
        source,
    };
    let mut names: Vec<String> = Vec::new();
    for entry in std::fs::read_dir(dir).map_err(list)? {
        let name = entry.map_err(list)?.file_name();
        let Some(name) = name.to_str() else { continue };
        if let Some(class) = name.strip_suffix(".jsonl")
            && !class.ends_with(".gate")
            && !class.is_empty()
        {
            names.push(class.to_string());
        }
    }
    names.sort();
    let mut warnings = Vec::new();
    let mut warn = |path: &Path, bad: &[store::BadLine]| {
        warnings.extend(bad.iter().map(|b| b.warning(path)));
    };
    let mut classes = Vec::new();
    for class in names {
        let path = store::file_of(dir, &class);
        let history = store::read(&path)?;
        warn(&path, &history.bad);
        let vpath = verdicts::file_of(dir, &class);
        let v = verdicts::read(&vpath)?;
        warn(&vpath, &v.bad);
        if history.records.is_empty() {
            continue;
        }
        classes.push(ClassFiles {
            class,
            records: history.records,
            verdicts: v,
        });
    }
    if classes.is_empty() {
        return Err(PublishError::Empty(dir.to_path_buf()));
    }
    Ok(Loaded { classes, warnings })
}

/// One chart: a case's series on one class, its steps, and the latest gate verdict on it.
#[derive(Clone, Debug)]
pub struct Chart {
    /// The case's series on one class and config.
    pub series: Series,
    /// The steps found in it, oldest first.
    pub steps: Vec<Step>,
    /// The drifts found in it, oldest first.
    pub drifts: Vec<Drift>,
    /// The case's verdict in the class's latest gate run; `None` without one, or not judged there.
    pub verdict: Option<CaseVerdict>,
}

/// A case and its charts, one per class (and config) that measured it.
#[derive(Clone, Debug)]
pub struct CaseView {
    /// The case key.
    pub key: String,
    /// Its charts, by class then config.
    pub charts: Vec<Chart>,
    /// The classes with no record of the case.
    pub absent: Vec<String>,
}

/// What the page says of one machine class.
#[derive(Clone, Debug)]
pub struct ClassView {
    /// The machine class.
    pub class: String,
    /// History records of the class, dirty builds included.
    pub records: usize,
    /// Commits in the class's series (the clean ones), and the newest measurement.
    pub commits: usize,
    /// UTC start of the class's newest measurement; `None` without records.
    pub newest: Option<String>,
    /// The class's latest gate run; `None` when it has no verdicts.
    pub latest_gate: Option<GateRun>,
}

/// What the history page and the pull-request summary show: every class, case and figure.
#[derive(Clone, Debug)]
pub struct Page {
    /// Every machine class with records, in the order of their names.
    pub classes: Vec<ClassView>,
    /// By case key.
    pub cases: Vec<CaseView>,
    /// The figures of REPORT.md linked from the page, in REPORT.md's order.
    pub figures: Vec<Figure>,
}

impl Page {
    /// The newest measurement of any class (the page's date: it has no other).
    pub fn newest(&self) -> Option<&str> {
        self.classes
            .iter()
            .filter_map(|c| c.newest.as_deref())
            .max_by_key(|m| (super::instant::parse(m), *m))
    }

    /// Every chart with its steps, in page order.
    pub fn charts(&self) -> impl Iterator<Item = &Chart> {
        self.cases.iter().flat_map(|c| &c.charts)
    }
}

/// The page of `loaded`, linking `figures`.
pub fn page(loaded: &Loaded, figures: Vec<Figure>) -> Result<Page, PublishError> {
    let mut classes = Vec::new();
    let mut charts: Vec<Chart> = Vec::new();
    for c in &loaded.classes {
        let latest = c.verdicts.latest().cloned();
        let all = series(&c.records);
        let mut commits: Vec<(&str, Option<&str>)> = all
            .iter()
            .flat_map(|s| {
                s.points
                    .iter()
                    .map(|p| (p.commit.as_str(), p.measured.as_deref()))
            })
            .collect();
        commits.sort_unstable();
        commits.dedup();
        classes.push(ClassView {
            class: c.class.clone(),
            records: c.records.len(),
            commits: commits.len(),
            // By instant, not by text: a hand-written time may carry an offset.
            newest: c
                .records
                .iter()
                .enumerate()
                .max_by_key(|(i, r)| (super::instant::parse(&r.measured), *i))
                .map(|(_, r)| r.measured.clone()),
            latest_gate: latest.clone(),
        });
        for s in all {
            // A series of builds with uncommitted changes only has no point to draw.
            if s.points.is_empty() {
                continue;
            }
            let found = changes(&s).map_err(|source| PublishError::Series {
                case: s.case.clone(),
                class: s.class.clone(),
                source,
            })?;
            let verdict = latest.as_ref().and_then(|g| g.case(&s.case)).cloned();
            charts.push(Chart {
                series: s,
                steps: found.steps,
                drifts: found.drifts,
                verdict,
            });
        }
    }
    let mut keys: Vec<String> = charts.iter().map(|c| c.series.case.clone()).collect();
    keys.sort();
    keys.dedup();
    let cases = keys
        .into_iter()
        .map(|key| {
            let mut mine: Vec<Chart> = charts
                .iter()
                .filter(|c| c.series.case == key)
                .cloned()
                .collect();
            mine.sort_by(|a, b| {
                (&a.series.class, &a.series.config).cmp(&(&b.series.class, &b.series.config))
            });
            let absent = classes
                .iter()
                .map(|c| c.class.clone())
                .filter(|class| !mine.iter().any(|m| &m.series.class == class))
                .collect();
            CaseView {
                key,
                charts: mine,
                absent,
            }
        })
        .collect();
    Ok(Page {
        classes,
        cases,
        figures,
    })
}

/// The page of the history under `dir`, linking the figures of `report` from the folder
/// `out` (which must exist), and the warnings of the lines left out: what `publish` writes,
/// and what the test of the committed page compares it with.
pub fn build(dir: &Path, report: &Path, out: &Path) -> Result<(Page, Vec<String>), PublishError> {
    let loaded = load(dir)?;
    let figures = report_figures::figures(report, out).map_err(|source| PublishError::Report {
        path: report.to_path_buf(),
        source,
    })?;
    let page = page(&loaded, figures)?;
    Ok((page, loaded.warnings))
}

/// Writes the page's HTML to `out/index.html` (the folder created as needed), atomically.
pub fn write(page: &Page, out: &Path) -> Result<PathBuf, PublishError> {
    let path = out.join(PAGE_FILE);
    nbody_engine::output::create_dir_all(out).map_err(|source| {
        nbody_engine::output::WriteError {
            path: out.to_path_buf(),
            source,
        }
    })?;
    nbody_engine::output::write_atomic(&path, html(page).as_bytes())?;
    Ok(path)
}

/// `text` safe inside HTML text and attribute values.
pub(crate) fn esc(text: &str) -> String {
    let mut o = String::with_capacity(text.len());
    for c in text.chars() {
        match c {
            '&' => o.push_str("&amp;"),
            '<' => o.push_str("&lt;"),
            '>' => o.push_str("&gt;"),
            '"' => o.push_str("&quot;"),
            '\'' => o.push_str("&#39;"),
            c => o.push(c),
        }
    }
    o
}

/// A commit as the page names it: its first 7 characters (a history file may hold anything,
/// so cut by characters).
pub(crate) fn short(commit: &str) -> &str {
    crate::gate::prefix(commit, 7)
}

#[cfg(test)]
mod tests;
