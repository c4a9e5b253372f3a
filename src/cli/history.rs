//! `nbody-bench history`: the performance history of this machine class (or another), case by
//! case, with the steps found in each series; `history record` appends a sweep's results.

use anyhow::{Context, bail};
use clap::{Args, Subcommand};
use nbody_engine::output::neutral::control::visible;
use nbody_harness::gate::baselines::check_class_name;
use nbody_harness::history::series::{Metric, Point, Series, series};
use nbody_harness::history::steps::{Drift, Step, changes};
use nbody_harness::history::store::{self, CommitFacts, History};
use nbody_harness::history::verdicts::{self, GateRun};
use nbody_harness::units::Duration;
use nbody_records::results::{ResultsError, ResultsFile};
use std::path::{Path, PathBuf};

/// Where the committed history lives.
pub const DEFAULT_DIR: &str = "results/history";

#[derive(Debug, Args)]
#[command(
    after_help = "Examples:\n  nbody-bench history                          # this machine class's cases and their steps\n  \
    nbody-bench history --case 'lj-box/verlet/*'  # the cases whose key matches\n  \
    nbody-bench history record runs/ci/2026-12-05T10-00-00Z/results.json\n\n\
    A series is one case of one config on one machine class, one point per commit in commit \
    order (by committer date read to UTC, then file order): the median time per step over the \
    reference workload timed before each sample when every record has it, else in seconds. \
    Records of a build with uncommitted changes are kept but left out of the series; records of \
    a sweep outside git (no commit) are one point per measurement. A line of the file that is \
    not a sound record of its class is named and left out (docs/reference/outputs.md)."
)]
pub struct HistoryArgs {
    #[command(subcommand)]
    pub action: Option<HistoryAction>,
    /// The folder of history files, one per machine class.
    #[arg(long, value_name = "DIR", default_value = DEFAULT_DIR, global = true)]
    pub dir: PathBuf,
    /// The machine class to show (a file name under --dir without `.jsonl`: letters, digits
    /// and `-`); default: this machine's.
    #[arg(long, value_name = "CLASS")]
    pub class: Option<String>,
    /// Only the cases whose key matches this pattern (`*` any text, `?` one character).
    #[arg(long, value_name = "GLOB")]
    pub case: Option<String>,
    /// Print the series as JSON instead of text.
    #[arg(long)]
    pub json: bool,
}

#[derive(Debug, Subcommand)]
pub enum HistoryAction {
    /// Append every measured case of results files to the history of their machine class; a
    /// gate report (a kept gate run's gate.json) appends its verdicts to <class>.gate.jsonl.
    Record(RecordArgs),
    /// Measure older commits into the history: every K-th commit of A..B along the first
    /// parents, each built in the gate's cached worktree and measured side by side with this
    /// build (the gate's interleaved A/B run); both sides are recorded, this build's as the
    /// control of the machine's own drift. A commit that does not build or read the config is
    /// skipped with its reason. Run it on a quiet machine.
    Backfill(BackfillArgs),
}

#[derive(Debug, Args)]
pub struct BackfillArgs {
    /// The commits after A up to B (`A..B`, as git rev-list reads it).
    #[arg(value_name = "A..B")]
    pub range: String,
    /// Measure every K-th commit, counted back from B (B always measured); at least 1.
    #[arg(long, value_name = "K", default_value_t = 1, value_parser = crate::cli::values::parse_count)]
    pub every: usize,
    /// The config both sides sweep: one every commit of the range reads (configs/backfill.toml
    /// holds kernels and keys the project has had since the CI config began).
    #[arg(long, value_name = "FILE|NAME", default_value = "backfill")]
    pub config: PathBuf,
    /// Interleaved rounds per case and side: even (each side goes first as often), from 2 to
    /// 100, as the gate's --rounds.
    #[arg(long, default_value_t = 4, value_parser = crate::cli::values::parse_ab_rounds)]
    pub rounds: usize,
    /// Where each commit's A/B run is kept.
    #[arg(long, value_name = "DIR", default_value = "results/runs/backfill")]
    pub runs: PathBuf,
    /// Only build (or find cached) every commit's binary: the builds need no quiet machine,
    /// the measurements of a later run do.
    #[arg(long)]
    pub build_only: bool,
}

#[derive(Debug, Args)]
pub struct RecordArgs {
    /// Results files (a sweep's results.json, or its run directory), or gate reports
    /// (gate.json).
    #[arg(required = true, value_name = "RESULTS")]
    pub results: Vec<PathBuf>,
    /// What made the measurement, kept in each record.
    #[arg(long, default_value = "sweep", value_parser = ["sweep", "gate", "backfill"])]
    pub source: String,
}

pub fn history(args: HistoryArgs) -> anyhow::Result<i32> {
    match &args.action {
        Some(HistoryAction::Record(r)) => record(&args.dir, r),
        Some(HistoryAction::Backfill(b)) => backfill(&args.dir, b),
        None => show(&args),
    }
}

fn backfill(dir: &Path, args: &BackfillArgs) -> anyhow::Result<i32> {
    use nbody_harness::history::backfill::{self, Backfill, Done};
    let config = nbody_records::locate::find_config(&args.config)?;
    check_record_dir("--dir", dir)?;
    let job = Backfill {
        range: args.range.clone(),
        every: args.every,
        config,
        rounds: args.rounds,
        dir: dir.to_path_buf(),
        runs: args.runs.clone(),
        build_only: args.build_only,
    };
    let done = backfill::backfill(&job, &mut |line| eprintln!("backfill: {line}"))?;
    let mut skipped = 0;
    for d in &done {
        match d {
            Done::Recorded { commit, records } => {
                outln!(
                    "{} {records} records",
                    nbody_harness::gate::prefix(commit, 12)
                )
            }
            Done::Built { commit } => outln!("{} built", nbody_harness::gate::prefix(commit, 12)),
            Done::Skipped { commit, why } => {
                skipped += 1;
                outln!("{} skipped: {why}", nbody_harness::gate::prefix(commit, 12))
            }
        }
    }
    if skipped == done.len() {
        anyhow::bail!("no commit of {} was measured", args.range);
    }
    Ok(0)
}

fn record(dir: &Path, args: &RecordArgs) -> anyhow::Result<i32> {
    check_record_dir("--dir", dir)?;
    for path in &args.results {
        let path = if path.is_dir() {
            path.join("results.json")
        } else {
            path.clone()
        };
        // Read once, through the bounded reader: a pipe is read within the pipe wait, a device
        // refused, and a gate report and a results file are told apart by their text.
        let text = nbody_engine::input::read_text(&path).map_err(|source| ResultsError::Read {
            path: path.clone(),
            source,
        })?;
        if let Some(run) = gate_report(&path, &text)? {
            for (to, count) in verdicts::append(dir, &[run])? {
                eprintln!(
                    "{}: the verdicts of {count} gate run(s) appended to {}",
                    path.display(),
                    to.display()
                );
            }
            continue;
        }
        let value = serde_json::from_str(&text).map_err(|e| ResultsError::Corrupt {
            path: path.clone(),
            detail: e.to_string(),
        })?;
        let file = ResultsFile::from_value(&path, value)?;
        for line in file.taken_out() {
            eprintln!("warning: {}: {}", path.display(), visible(&line));
        }
        let written = append_results(dir, &file, &args.source)?;
        for (to, count) in written {
            eprintln!(
                "{}: {count} records appended to {}",
                path.display(),
                to.display()
            );
        }
    }
    Ok(0)
}

/// The verdicts of `path` (its `text`) when it is a gate report (schema
/// `nbody-bench/gate/v1`, a kept gate run's `gate.json`); `None` for any other file.
fn gate_report(path: &Path, text: &str) -> anyhow::Result<Option<GateRun>> {
    let schema = serde_json::from_str::<serde_json::Value>(text)
        .ok()
        .and_then(|v| v["schema"].as_str().map(str::to_string));
    if schema.as_deref() != Some(verdicts::GATE_REPORT_SCHEMA) {
        return Ok(None);
    }
    let machine = nbody_harness::gate::route::this_machine();
    GateRun::from_report_json(text, &machine)
        .map(Some)
        .map_err(|why| anyhow::anyhow!("{}: a gate report, but {why}", path.display()))
}

/// Checks, before anything is measured or read, that a history can be appended under `dir`
/// (named by `flag`): a directory, or one that can be made, in which this machine class's
/// files can be written. A sweep or a gate that measured for an hour must not fail at the end
/// on a destination it could have refused at the start.
pub fn check_record_dir(flag: &str, dir: &Path) -> anyhow::Result<()> {
    if let Some(part) = nbody_engine::output::not_a_directory(dir) {
        bail!(
            "{flag} {}: {} is {}, where a directory is expected (the history is kept as \
             DIR/<machine class>.jsonl): pass a directory, new or existing",
            dir.display(),
            part.display(),
            if part.is_file() {
                "a file"
            } else {
                "not a directory"
            }
        );
    }
    // The nearest part of the path that exists: the directory itself, or the one it would be
    // made in.
    let existing = dir
        .ancestors()
        .find(|a| !a.as_os_str().is_empty() && a.is_dir())
        .unwrap_or(Path::new("."));
    let probe = if existing == dir {
        let m = nbody_harness::gate::route::this_machine();
        let class =
            nbody_harness::gate::baselines::class_name(m.cpu_signature.as_deref(), m.logical_cpus);
        store::file_of(dir, &class)
    } else {
        // The directory is made when the first record is appended; that it can be is checked
        // by writing (and removing) a file where it would go.
        let first_missing = dir
            .ancestors()
            .take_while(|a| *a != existing && !a.as_os_str().is_empty())
            .last()
            .unwrap_or(dir);
        first_missing.to_path_buf()
    };
    nbody_engine::output::check_writable(&probe).map_err(|e| {
        anyhow::anyhow!(
            "{flag} {}: the history cannot be written there ({}): pass a directory you can \
             write to",
            dir.display(),
            crate::cli::error_chain(&e.into())
        )
    })
}

/// Appends the records of `file` (measured by `source`) to the history under `dir`; the files
/// written and their record counts. `sweep --record` and `gate --record` come here too.
pub fn append_results(
    dir: &Path,
    file: &ResultsFile,
    source: &str,
) -> anyhow::Result<Vec<(PathBuf, usize)>> {
    let commit = &file.metadata.git_commit;
    if nbody_harness::git::Rev::recorded(commit).is_none() && commit != "unknown" {
        eprintln!(
            "warning: the results' git_commit `{}` is not a commit hash: git is not asked \
             about it, and its records are kept with no parent and no commit date",
            visible(commit)
        );
    }
    let facts = CommitFacts::of(Path::new("."), commit);
    let machine = nbody_harness::gate::route::this_machine();
    let records = store::records_of(file, source, &facts, &machine);
    if records.is_empty() {
        bail!("no case of the results has a successful sample: nothing to record");
    }
    Ok(store::append(dir, &records)?)
}

fn show(args: &HistoryArgs) -> anyhow::Result<i32> {
    let class = match &args.class {
        Some(c) => check_class_name(c)
            .map_err(|why| anyhow::anyhow!("--class {why}"))?
            .to_string(),
        None => {
            let m = nbody_harness::gate::route::this_machine();
            nbody_harness::gate::baselines::class_name(m.cpu_signature.as_deref(), m.logical_cpus)
        }
    };
    let path = store::file_of(&args.dir, &class);
    if !path.exists() {
        bail!(
            "{} does not exist: no history of machine class {class} yet (record one with \
             `nbody-bench history record RESULTS` or `sweep --record`; --class names another)",
            path.display()
        );
    }
    let History { records, bad, .. } = store::read(&path)?;
    for b in &bad {
        eprintln!("warning: {}", visible(&b.warning(&path)));
    }
    let pattern = args.case.as_deref().map(glob).transpose()?;
    let all: Vec<Series> = series(&records)
        .into_iter()
        .filter(|s| pattern.as_ref().is_none_or(|p| p.is_match(&s.case)))
        .collect();
    if all.is_empty() {
        bail!(
            "no case of {} matches{}",
            path.display(),
            args.case
                .as_deref()
                .map(|c| format!(" `{c}`"))
                .unwrap_or_default()
        );
    }
    let found: Vec<Found> = all.iter().map(found).collect::<anyhow::Result<_>>()?;
    if args.json {
        println!(
            "{}",
            serde_json::to_string_pretty(&found).context("the series as JSON")?
        );
        return Ok(0);
    }
    println!(
        "{}: {} records, {} series",
        path.display(),
        records.len(),
        all.len()
    );
    for f in &found {
        print_series(f);
    }
    Ok(0)
}

/// A series and the steps and drifts found in it. The steps keep the key `changes` they have
/// always had; `drifts` is beside them.
#[derive(serde::Serialize)]
struct Found<'a> {
    #[serde(flatten)]
    series: &'a Series,
    changes: Vec<Step>,
    drifts: Vec<Drift>,
}

fn found(s: &Series) -> anyhow::Result<Found<'_>> {
    let found = changes(s).with_context(|| format!("the series of {}", s.case))?;
    Ok(Found {
        series: s,
        changes: found.steps,
        drifts: found.drifts,
    })
}

fn print_series(f: &Found) {
    let s = f.series;
    let unit = match s.metric {
        Metric::Normalized => "× the reference",
        Metric::Seconds => "per step",
    };
    let value = |v: f64| match s.metric {
        Metric::Normalized => format!("{v:.4}"),
        Metric::Seconds => Duration(v).to_string(),
    };
    // The case key and the config name come from the history file: no control character of
    // theirs reaches the terminal.
    let (case, config) = (visible(&s.case), visible(&s.config));
    let (Some(first), Some(last)) = (s.points.first(), s.points.last()) else {
        println!("\n{case} ({config}): no commit measured");
        return;
    };
    println!(
        "\n{case} ({config}): {} commits, {} → {} {unit}{}",
        s.points.len(),
        value(first.value),
        value(last.value),
        if s.dirty > 0 {
            format!(
                " ({} records of builds with uncommitted changes left out)",
                s.dirty
            )
        } else {
            String::new()
        }
    );
    let outside_git = s.points.iter().filter(|p| p.outside_git()).count();
    if outside_git > 0 {
        println!(
            "  {outside_git} of the points are of sweeps outside git (no commit): one point per \
             measurement, named by when it started, never merged"
        );
    }
    for c in &f.changes {
        let [a, b] = [c.index.saturating_sub(1), c.index].map(|i| name(&s.points[i]));
        println!(
            "  step between {a} and {b}: {} → {} ({:+.1}% [{:+.1}%, {:+.1}%])",
            value(c.before),
            value(c.after),
            100.0 * (c.ratio - 1.0),
            100.0 * (c.ratio_ci95[0] - 1.0),
            100.0 * (c.ratio_ci95[1] - 1.0)
        );
    }
    for d in &f.drifts {
        let [a, b] = [d.start, d.end].map(|i| name(&s.points[i]));
        println!("  {}", d.text(&a, &b));
    }
    if f.changes.is_empty() && f.drifts.is_empty() && s.points.len() > 1 {
        println!("  no step");
    }
}

/// A point as the text names it: its commit as read from a history file, which may hold
/// anything, cut by characters, its control characters shown escaped; a point of a sweep
/// outside git by when it was measured.
fn name(p: &Point) -> String {
    match &p.measured {
        Some(measured) => format!("(no commit, measured {})", visible(measured)),
        None => visible(nbody_harness::gate::prefix(&p.commit, 10)).into_owned(),
    }
}

/// A `*` / `?` pattern as an anchored regular expression.
fn glob(pattern: &str) -> anyhow::Result<regex::Regex> {
    let mut re = String::from("^");
    for c in pattern.chars() {
        match c {
            '*' => re.push_str(".*"),
            '?' => re.push('.'),
            c => re.push_str(&regex::escape(&c.to_string())),
        }
    }
    re.push('$');
    regex::Regex::new(&re).with_context(|| format!("--case `{pattern}`"))
}

/// Appends what the gate measured to the history under `dir`: the A/B run's two sides (the
/// baseline's revision and this build), the fast path's sweep, or the `--current` file; and
/// the run's verdicts to the class's verdict file beside it.
pub fn record_gate_run(
    dir: &std::path::Path,
    outcome: &nbody_harness::gate::drive::Outcome,
    current: Option<&std::path::Path>,
) -> anyhow::Result<()> {
    let duet = outcome.report.sides == Some(nbody_harness::gate::duet::Sides::Duet);
    if duet {
        eprintln!(
            "gate: the builds were measured at the same moment (duet): their times, each with the \
             other CPU busy, are not appended to the history, whose records are one build alone \
             (`--sides turns` measures them so)"
        );
    }
    let files: Vec<std::path::PathBuf> = match (&outcome.kept_in, current) {
        (Some(_), _) if duet => Vec::new(),
        (Some(kept), _) => ["base.json", "current.json", "results.json"]
            .iter()
            .map(|f| kept.join(f))
            .filter(|p| p.is_file())
            .collect(),
        (None, Some(current)) => vec![nbody_records::locate::find_results(
            current,
            std::path::Path::new("results"),
        )?],
        (None, None) => Vec::new(),
    };
    // The verdicts beside the records: the page shows each class's latest gate run.
    let run = nbody_harness::history::verdicts::GateRun::of(
        &outcome.report,
        &nbody_harness::gate::route::this_machine(),
    );
    // A run the file already holds (a save's accepted run, appended just before) is not
    // appended again, and not reported.
    for (to, count) in nbody_harness::history::verdicts::append(dir, &[run])? {
        if count == 0 {
            continue;
        }
        eprintln!(
            "gate: the verdicts of {count} gate run(s) appended to {}",
            to.display()
        );
    }
    for path in files {
        let file = nbody_records::results::ResultsFile::load(&path)?;
        for (to, count) in append_results(dir, &file, "gate")? {
            eprintln!(
                "gate: {count} records of {} appended to {}",
                path.display(),
                to.display()
            );
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::glob;

    #[test]
    fn case_patterns_match_whole_keys() {
        let p = glob("lj-box/verlet/*").unwrap();
        assert!(p.is_match("lj-box/verlet/n=1000/p=1/r=1/seed=1"));
        assert!(!p.is_match("lj-liquid/verlet/n=1000"));
        assert!(glob("*n=1000?p=1*").unwrap().is_match("a/n=1000/p=1/r=1"));
        assert!(!glob("a.b").unwrap().is_match("axb"));
    }
}
