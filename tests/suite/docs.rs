//! The docs cannot drift from the code: the generated reference pages (`docs/reference/cli.md`
//! and `config.md`, printed by the hidden `nbody-bench reference`) must equal the committed
//! ones, the results page must list exactly the fields a results file of this version holds,
//! and every relative link of the Markdown pages must lead to a file (and heading) that exists.
//!
//! `NBODY_BENCH_UPDATE_DOCS=1 cargo test --test suite docs` rewrites the generated pages.

use crate::{bin, text};
use nbody_records::external::SampleError;
use nbody_records::results::{InitialRecord, ResultsFile};
use nbody_records::scheduler::{JobError, JobRecord};
use nbody_records::vet::Rejected;
use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

const UPDATE: &str = "NBODY_BENCH_UPDATE_DOCS";

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

/// The first line where `a` and `b` differ, 1-based, with both versions.
fn first_difference(have: &str, want: &str) -> String {
    let (mut a, mut b) = (have.lines(), want.lines());
    for line in 1.. {
        match (a.next(), b.next()) {
            (None, None) => return "only in the line endings".into(),
            (x, y) if x != y => {
                return format!(
                    "line {line}: committed {:?}, generated {:?}",
                    x.unwrap_or("(end)"),
                    y.unwrap_or("(end)")
                );
            }
            _ => {}
        }
    }
    unreachable!()
}

/// Compares `docs/reference/<page>` with `generated`, or rewrites it under `UPDATE=1`.
fn check_generated(page: &str, generated: &str) {
    let path = root().join("docs/reference").join(page);
    if std::env::var(UPDATE).as_deref() == Ok("1") {
        std::fs::write(&path, generated).unwrap();
        return;
    }
    let committed = std::fs::read_to_string(&path).unwrap_or_default();
    assert!(
        committed == generated,
        "docs/reference/{page} is stale ({}): regenerate it with \
         `{UPDATE}=1 cargo test --test suite docs`, review the diff and commit it",
        first_difference(&committed, generated)
    );
}

fn reference(page: &str) -> String {
    let out = bin().args(["reference", page]).output().unwrap();
    assert!(out.status.success(), "{}", text(&out.stderr));
    text(&out.stdout)
}

#[test]
fn the_cli_reference_is_the_commands_help() {
    let page = reference("cli");
    for sub in ["run", "sweep", "analyze", "report", "gate", "fit", "export"] {
        assert!(page.contains(&format!("\n## nbody-bench {sub}\n")), "{sub}");
    }
    assert!(
        !page.contains("## nbody-bench reference"),
        "the hidden command is listed"
    );
    assert!(!page.contains('\u{1b}'), "colours in the page");
    check_generated("cli.md", &page);
}

#[test]
fn the_config_reference_has_every_key() {
    let page = reference("config");
    for key in [
        "`measure.samples`",
        "`weak.rule`",
        "`mpi.ranks`",
        "`external.time`",
    ] {
        assert!(page.contains(key), "{key} missing");
    }
    check_generated("config.md", &page);
}

/// `a.{b,c}.d` → `a.b.d`, `a.c.d`.
fn expand(pattern: &str) -> Vec<String> {
    let Some(open) = pattern.find('{') else {
        return vec![pattern.to_string()];
    };
    let close = open + pattern[open..].find('}').expect("a closing brace");
    let (head, tail) = (&pattern[..open], &pattern[close + 1..]);
    pattern[open + 1..close]
        .split(',')
        .flat_map(|alt| expand(&format!("{head}{}{tail}", alt.trim())))
        .collect()
}

/// The key paths the results page documents: the first cell of each table row that is a code
/// span.
fn documented_paths(page: &str) -> BTreeSet<String> {
    let mut paths = BTreeSet::new();
    for line in page.lines() {
        let Some(rest) = line.strip_prefix("| `") else {
            continue;
        };
        let cell = rest.split(" |").next().unwrap();
        for path in cell.split(", ") {
            let path = path.trim_matches('`');
            paths.extend(expand(path));
        }
    }
    paths
}

/// Every key path of `value`: `.key` into objects, `[]` into arrays of objects; an array of
/// numbers (or of arrays of numbers) and a null are leaves; `config` is one field (its keys are
/// the config page's), and so is an external run's `phases` (keyed by the config's phase names).
fn walk(value: &serde_json::Value, path: &str, out: &mut BTreeSet<String>) {
    let leaf = |out: &mut BTreeSet<String>| {
        out.insert(path.trim_end_matches("[]").to_string());
    };
    if path == "config" || path.ends_with("external.runs[].phases") {
        return leaf(out);
    }
    match value {
        serde_json::Value::Object(map) if !map.is_empty() => {
            for (k, v) in map {
                let p = if path.is_empty() {
                    k.clone()
                } else {
                    format!("{path}.{k}")
                };
                walk(v, &p, out);
            }
        }
        serde_json::Value::Array(items) if !items.is_empty() => {
            for item in items {
                walk(item, &format!("{path}[]"), out);
            }
        }
        _ => leaf(out),
    }
}

/// Drops a path that is the parent of another (`initial_work` is null in some rounds and an
/// object in others: its fields are what is documented).
fn leaves(paths: BTreeSet<String>) -> BTreeSet<String> {
    paths
        .iter()
        .filter(|p| {
            !paths.iter().any(|q| {
                q.len() > p.len()
                    && q.starts_with(p.as_str())
                    && matches!(q.as_bytes()[p.len()], b'.' | b'[')
            })
        })
        .cloned()
        .collect()
}

/// The committed results files: each sweep's and each gate baseline.
fn committed_results() -> Vec<PathBuf> {
    let mut files = Vec::new();
    for entry in std::fs::read_dir(root().join("results")).unwrap().flatten() {
        let dir = entry.path();
        if dir.join("results.json").is_file() {
            files.push(dir.join("results.json"));
        }
    }
    for entry in std::fs::read_dir(root().join("results/baseline"))
        .unwrap()
        .flatten()
    {
        if entry.path().extension().is_some_and(|e| e == "json") {
            files.push(entry.path());
        }
    }
    files.sort();
    files
}

#[test]
fn the_results_reference_lists_exactly_the_fields_written() {
    // Each committed file read by this version and written again (older files gain the
    // fields added since), plus the fields only some sweeps write: a rejected value, an
    // external program's failures and wall-timing overhead, and a batch job's record.
    let mut found = BTreeSet::new();
    let files = committed_results();
    assert!(files.len() > 5, "{files:?}");
    for (i, path) in files.iter().enumerate() {
        let mut file = ResultsFile::load(path).unwrap();
        if i == 0 {
            file.metadata.initial = Some(InitialRecord {
                path: "/data/bodies.txt".into(),
                format: "barnes-hut".into(),
                bodies: 2000,
                fnv1a: "0123456789abcdef".into(),
            });
            file.cases[0].rejected.push(Rejected {
                round: 0,
                what: "sample 0".into(),
                value: "NaN".into(),
                reason: "not a finite number".into(),
            });
            file.cases[0].rounds[0].job = Some(JobRecord {
                id: "17".into(),
                node: Some("node1".into()),
                state: Some("TIMEOUT".into()),
                error: Some(JobError {
                    what: "job 17 ended TIMEOUT without a result".into(),
                    output_tail: vec!["slurmstepd: error: *** JOB 17 CANCELLED".into()],
                }),
            });
        }
        let external = file
            .cases
            .iter_mut()
            .flat_map(|c| c.rounds.iter_mut())
            .find_map(|r| r.external.as_mut());
        if let Some(round) = external {
            let error = SampleError {
                what: "exit status 1".into(),
                command: "program".into(),
                output_tail: vec!["failed".into()],
            };
            round.launch_overhead_s = Some(1e-3);
            round.overhead_share = Some(0.01);
            round.setup_error = Some(error.clone());
            round.warnings.push("a warning".into());
            round.runs[0].error = Some(error);
            round.runs[0].phases.insert("comm".into(), 1e-3);
            round.runs[0].energy_drift = Some(1e-4);
        }
        walk(&serde_json::to_value(&file).unwrap(), "", &mut found);
    }
    let found = leaves(found);
    let page = std::fs::read_to_string(root().join("docs/reference/results.md")).unwrap();
    let documented = documented_paths(&page);
    let undocumented: Vec<_> = found.difference(&documented).collect();
    let gone: Vec<_> = documented.difference(&found).collect();
    assert!(
        undocumented.is_empty() && gone.is_empty(),
        "docs/reference/results.md is stale: fields written but not documented {undocumented:#?}; \
         documented but not written {gone:#?}. Edit the tables of the page (first column: the key \
         path, `{{a,b}}` for alternatives)"
    );
}

/// The Markdown files of the repository a reader follows links in.
fn markdown_pages() -> Vec<PathBuf> {
    fn under(dir: &Path, out: &mut Vec<PathBuf>) {
        for entry in std::fs::read_dir(dir).unwrap().flatten() {
            let path = entry.path();
            if path.is_dir() {
                under(&path, out);
            } else if path.extension().is_some_and(|e| e == "md") {
                out.push(path);
            }
        }
    }
    let mut pages = vec![root().join("README.md"), root().join("REPORT.md")];
    under(&root().join("docs"), &mut pages);
    pages.sort();
    pages
}

/// GitHub's anchor of a heading: lower case, punctuation but `-` and `_` dropped, spaces to `-`.
fn anchor(heading: &str) -> String {
    heading
        .trim()
        .to_lowercase()
        .chars()
        .filter(|c| c.is_alphanumeric() || matches!(c, ' ' | '-' | '_'))
        .map(|c| if c == ' ' { '-' } else { c })
        .collect()
}

fn anchors(page: &str) -> BTreeSet<String> {
    let mut fenced = false;
    let mut out = BTreeSet::new();
    for line in page.lines() {
        if line.starts_with("```") {
            fenced = !fenced;
        } else if !fenced && line.starts_with('#') {
            out.insert(anchor(line.trim_start_matches('#')));
        }
    }
    out
}

/// The targets of the inline links `[text](target)` of a page, outside code.
fn links(page: &str) -> Vec<String> {
    let mut out = Vec::new();
    let mut fenced = false;
    for line in page.lines() {
        if line.starts_with("```") {
            fenced = !fenced;
            continue;
        }
        if fenced {
            continue;
        }
        let mut rest = line;
        while let Some(at) = rest.find("](") {
            let tail = &rest[at + 2..];
            let Some(end) = tail.find(')') else { break };
            out.push(tail[..end].to_string());
            rest = &tail[end..];
        }
    }
    out
}

#[test]
fn every_relative_link_of_the_docs_leads_somewhere() {
    let mut broken = Vec::new();
    for page in markdown_pages() {
        let body = std::fs::read_to_string(&page).unwrap();
        for link in links(&body) {
            if link.contains("://") || link.starts_with("mailto:") {
                continue;
            }
            let (file, fragment) = link.split_once('#').unwrap_or((&link, ""));
            let target = if file.is_empty() {
                page.clone()
            } else {
                page.parent().unwrap().join(file)
            };
            let shown = page.strip_prefix(root()).unwrap().display().to_string();
            if !target.exists() {
                broken.push(format!("{shown}: {link} (no such file)"));
            } else if !fragment.is_empty() && target.extension().is_some_and(|e| e == "md") {
                let text = std::fs::read_to_string(&target).unwrap();
                if !anchors(&text).contains(fragment) {
                    broken.push(format!("{shown}: {link} (no such heading)"));
                }
            }
        }
    }
    assert!(broken.is_empty(), "broken links: {broken:#?}");
}

/// The gate page's figures are the committed study files', through the generator: its
/// generated region equals `gate-study --docs`'s (rewritten under `UPDATE=1`), and every study
/// file of a committed baseline's machine class reads back.
#[test]
fn the_gate_page_tables_come_from_the_study_files() {
    use nbody_harness::gate::study::{run, table};
    let files = run::study_files(&root().join("results/gate-study")).unwrap();
    let path = root().join("docs/explanation/gate.md");
    let page = std::fs::read_to_string(&path).unwrap();
    let generated = table::splice(&page, &table::markdown(&files))
        .expect("docs/explanation/gate.md keeps its generated region's marks");
    if std::env::var(UPDATE).as_deref() == Ok("1") {
        std::fs::write(&path, &generated).unwrap();
        return;
    }
    assert!(
        page == generated,
        "docs/explanation/gate.md's study tables are stale ({}): `nbody-bench gate-study \
         --docs` regenerates them",
        first_difference(&page, &generated)
    );
}
