//! The Markdown summary for a pull-request comment: per machine class, the steps found since
//! a base commit (with their sizes and intervals), and the latest gate run's regressions and
//! improvements; "no change since BASE" when there is none.

use super::chart::{percent, value};
use super::html::gate_commits;
use super::{Chart, ClassView, Page, short};
use crate::gate::Verdict;
use crate::git::Rev;
use crate::history::steps::{Drift, Step};
use crate::render::tables::{Align, Table};
use nbody_engine::output::neutral::markdown::{cell_code, code, text};
use std::fmt::Write;
use std::path::{Path, PathBuf};
use std::process::Stdio;

/// The commit the summary counts from.
#[derive(Clone, Debug)]
pub struct Base {
    /// As the summary names it.
    pub name: String,
    /// The commit git resolved it to (None: git does not know it, or there is no base).
    pub commit: Option<String>,
    /// Where git runs, for the ancestry of the steps' commits.
    pub repo: PathBuf,
    /// No base could be found: every step of the history is listed, and this says why.
    pub none: Option<String>,
}

/// The base: `given` (a revision), else the merge base of `HEAD` and `origin/main` (what a
/// pull request's diff starts from), else `HEAD`'s first parent. `Err` when `given` names
/// nothing git or the history knows; with no `given` and no git, a base of `none`.
pub fn resolve(repo: &Path, given: Option<&str>, page: &Page) -> Result<Base, String> {
    let base = |name: String, commit: Option<String>| Base {
        name,
        commit,
        repo: repo.to_path_buf(),
        none: None,
    };
    if let Some(given) = given {
        let rev = Rev::given(given).map_err(|why| format!("--base {why}"))?;
        if let Some(full) = git(
            repo,
            &["rev-parse", "--verify", "--quiet"],
            &[&rev.commit()],
        ) {
            return Ok(base(short(&full).to_string(), Some(full)));
        }
        let held = page
            .charts()
            .any(|c| c.series.points.iter().any(|p| p.commit.starts_with(given)));
        if held && !given.is_empty() {
            return Ok(base(given.to_string(), None));
        }
        return Err(format!(
            "--base {given}: neither git nor any series of the history knows that commit; give \
             a commit of the history or a revision of this repository"
        ));
    }
    let head = Rev::given("HEAD").expect("HEAD is a revision");
    let main = Rev::given("origin/main").expect("origin/main is a revision");
    if let Some(full) = git(repo, &["merge-base"], &[&head, &main]) {
        return Ok(base(short(&full).to_string(), Some(full)));
    }
    if let Some(full) = git(
        repo,
        &["rev-parse", "--verify", "--quiet"],
        &[&head.parent()],
    ) {
        return Ok(base(short(&full).to_string(), Some(full)));
    }
    Ok(Base {
        name: "the start of the history".to_string(),
        commit: None,
        repo: repo.to_path_buf(),
        none: Some(
            "git found neither a merge base with origin/main nor a parent of HEAD (no git, or \
             not a repository): every step of the history is listed; --base names a commit"
                .to_string(),
        ),
    })
}

fn git(repo: &Path, args: &[&str], revs: &[&Rev]) -> Option<String> {
    let out = crate::git::command(repo, args, revs)
        .stderr(Stdio::null())
        .output()
        .ok()?;
    let text = String::from_utf8(out.stdout).ok()?;
    (out.status.success() && !text.trim().is_empty()).then(|| text.trim().to_string())
}

impl Base {
    /// Whether `step` of `chart` came after the base: when the base is a point of the series,
    /// by the order of the series; else when git knows both commits, by ancestry (the first
    /// commit of the new level is not in the base's past); a commit git does not know is
    /// listed.
    pub fn precedes(&self, chart: &Chart, step: &Step) -> bool {
        self.precedes_at(chart, step.index, &step.between[1])
    }

    /// Whether `drift` of `chart` reached past the base: its last commit came after it, as
    /// [`Base::precedes`] tells for a step's first commit of the new level.
    pub fn precedes_drift(&self, chart: &Chart, drift: &Drift) -> bool {
        self.precedes_at(chart, drift.end, &drift.range[1])
    }

    /// Whether the point `index` of `chart`, of commit `commit`, came after the base.
    fn precedes_at(&self, chart: &Chart, index: usize, commit: &str) -> bool {
        if self.none.is_some() {
            return true;
        }
        let mine = |commit: &str| match &self.commit {
            Some(full) => commit == full || full.starts_with(commit) && commit.len() >= 7,
            None => commit.starts_with(&self.name),
        };
        if let Some(at) = chart.series.points.iter().position(|p| mine(&p.commit)) {
            return index > at;
        }
        let Some(full) = self.commit.as_deref().and_then(Rev::recorded) else {
            return true;
        };
        // The step's commit comes from a history file: git hears of it only as a hash.
        let Some(after) = Rev::recorded(commit) else {
            return true;
        };
        let status = crate::git::command(
            &self.repo,
            &["merge-base", "--is-ancestor"],
            &[&after, &full],
        )
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .status();
        // 0: an ancestor of the base (before it); 1: not; anything else: git does not know it.
        !matches!(status.map(|s| s.code()), Ok(Some(0)))
    }
}

/// The summary of `page` since `base`.
pub fn summary(page: &Page, base: &Base) -> String {
    let mut o = String::new();
    let found: Vec<(&Chart, Vec<&Step>)> = page
        .charts()
        .map(|c| (c, c.steps.iter().filter(|s| base.precedes(c, s)).collect()))
        .collect();
    let drifts: Vec<(&Chart, Vec<&Drift>)> = page
        .charts()
        .map(|c| {
            let mine = c.drifts.iter().filter(|d| base.precedes_drift(c, d));
            (c, mine.collect())
        })
        .collect();
    let total: usize = found.iter().map(|(_, s)| s.len()).sum::<usize>()
        + drifts.iter().map(|(_, d)| d.len()).sum::<usize>();
    let _ = writeln!(o, "### Performance history since {}\n", code(&base.name));
    if let Some(why) = &base.none {
        let _ = writeln!(o, "_{why}._\n");
    }
    if total == 0 {
        let _ = writeln!(
            o,
            "No change since {} in any of {} cases on {} machine class{}.\n",
            code(&base.name),
            page.cases.len(),
            page.classes.len(),
            if page.classes.len() == 1 { "" } else { "es" }
        );
    }
    for class in &page.classes {
        let mine: Vec<&(&Chart, Vec<&Step>)> = found
            .iter()
            .filter(|(c, _)| c.series.class == class.class)
            .collect();
        let mine_drifts: Vec<&(&Chart, Vec<&Drift>)> = drifts
            .iter()
            .filter(|(c, d)| c.series.class == class.class && !d.is_empty())
            .collect();
        let count: usize = mine.iter().map(|(_, s)| s.len()).sum::<usize>()
            + mine_drifts.iter().map(|(_, d)| d.len()).sum::<usize>();
        let _ = writeln!(
            o,
            "**{}** ({} commits, newest measurement {})",
            text(&class.class),
            class.commits,
            text(class.newest.as_deref().unwrap_or("unknown"))
        );
        o.push('\n');
        if count == 0 {
            let _ = writeln!(o, "No change since {}.\n", code(&base.name));
        } else {
            if mine.iter().any(|(_, s)| !s.is_empty()) {
                o.push_str(&steps_table(&mine).markdown());
                o.push('\n');
            }
            if !mine_drifts.is_empty() {
                o.push_str(&drifts_table(&mine_drifts).markdown());
                o.push('\n');
            }
        }
        latest_gate(&mut o, class);
    }
    o
}

/// One row per step found since the base in a class's charts: the case, the two commits, the
/// levels either side, the change and its interval.
fn steps_table(mine: &[&(&Chart, Vec<&Step>)]) -> Table {
    let mut t = Table::new([
        "case",
        "between",
        "level before → after",
        "change",
        "95% interval",
    ])
    .aligned([
        Align::Default,
        Align::Default,
        Align::Default,
        Align::Right,
        Align::Right,
    ]);
    for (c, steps) in mine {
        let s = &c.series;
        for st in steps {
            t.row([
                cell_code(&s.case),
                cell_code(&format!(
                    "{}..{}",
                    short(&st.between[0]),
                    short(&st.between[1])
                )),
                format!(
                    "{} → {}",
                    value(s.metric, st.before),
                    value(s.metric, st.after)
                ),
                format!(
                    "{} {}",
                    percent(st.ratio),
                    if st.ratio > 1.0 { "slower" } else { "faster" }
                ),
                format!(
                    "[{}, {}]",
                    percent(st.ratio_ci95[0]),
                    percent(st.ratio_ci95[1])
                ),
            ]);
        }
    }
    t
}

/// One row per drift reaching past the base in a class's charts: the case, its first and last
/// commits, its size with its interval, and its rate per commit.
fn drifts_table(mine: &[&(&Chart, Vec<&Drift>)]) -> Table {
    let mut t = Table::new([
        "case",
        "drift from..to",
        "change",
        "95% interval",
        "per commit",
    ])
    .aligned([
        Align::Default,
        Align::Default,
        Align::Right,
        Align::Right,
        Align::Right,
    ]);
    for (c, drifts) in mine {
        for d in drifts {
            t.row([
                cell_code(&c.series.case),
                cell_code(&format!("{}..{}", short(&d.range[0]), short(&d.range[1]))),
                format!(
                    "{} {}",
                    percent(d.ratio),
                    if d.ratio > 1.0 { "slower" } else { "faster" }
                ),
                format!(
                    "[{}, {}]",
                    percent(d.ratio_ci95[0]),
                    percent(d.ratio_ci95[1])
                ),
                format!("{:+.2}%", 100.0 * (d.per_commit - 1.0)),
            ]);
        }
    }
    t
}

/// A class's latest gate run: its counts of verdicts, then the cases it did not find
/// unchanged; or that the class has none.
fn latest_gate(o: &mut String, class: &ClassView) {
    let Some(g) = &class.latest_gate else {
        o.push_str("No gate run recorded for this class.\n\n");
        return;
    };
    let count = |v: Verdict| g.cases.iter().filter(|c| c.verdict == v).count();
    let _ = writeln!(
        o,
        "Latest gate run ({}, {}, threshold ±{}%): {} regressed, {} improved, {} unchanged{}.\n",
        text(&g.measured),
        code(&gate_commits(g)),
        100.0 * g.threshold,
        count(Verdict::Regressed),
        count(Verdict::Improved),
        count(Verdict::Unchanged),
        if g.missing.is_empty() {
            String::new()
        } else {
            format!(", {} missing", g.missing.len())
        }
    );
    if let Some(a) = &g.acceptance {
        // A regression let into the baseline on purpose is shown as such, with why. The
        // reason and keys come from a history file: they stay text in the summary.
        let keys: Vec<String> = a.cases.iter().map(|c| code(&c.key)).collect();
        let reason = a.reason.split_whitespace().collect::<Vec<_>>().join(" ");
        let _ = writeln!(
            o,
            "Accepted into the baseline when it was saved ({}): {}, because: {}\n",
            text(&a.accepted),
            keys.join(", "),
            text(&reason)
        );
    }
    let judged: Vec<_> = g
        .cases
        .iter()
        .filter(|c| c.verdict != Verdict::Unchanged)
        .collect();
    if !judged.is_empty() {
        let mut t = Table::new(["case", "verdict", "ratio", "95% interval"]).aligned([
            Align::Default,
            Align::Default,
            Align::Right,
            Align::Right,
        ]);
        for c in judged {
            t.row([
                cell_code(&c.key),
                c.verdict.name().to_string(),
                format!("{:.3}", c.ratio),
                format!("[{:.3}, {:.3}]", c.ci95[0], c.ci95[1]),
            ]);
        }
        o.push_str(&t.markdown());
        o.push('\n');
    }
}
