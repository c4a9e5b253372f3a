//! History files written by other hands, through every reader (`history`, `publish`,
//! `export-results`): a bad line costs that line only (bytes that are not UTF-8, a median that
//! is not a time), a record of another class than its file's is left out, records without a
//! commit date or with the committer's own offset are ordered by when they were committed,
//! and measurements outside git stay apart.

use super::{bin, text};
use serde_json::{Value, json};
use std::path::Path;
use std::process::Output;

const CLASS: &str = "X-1-2-3-2cpu";

/// A record of `case` at `commit` on `CLASS`, committed at `date` (`None`: git did not know).
fn record(case: &str, commit: &str, date: Option<&str>, median_s: f64) -> Value {
    json!({
        "schema": "nbody-bench-history/1", "commit": commit, "parent": null,
        "commit_date": date, "dirty": false, "measured": "2026-12-05T00:00:00Z",
        "class": CLASS,
        "build": {"tool_version": "0.1.0", "profile": "release", "simd": "avx2", "features": []},
        "config": "ci", "source": "backfill", "case": case, "n": 1000, "median_s": median_s,
        "ci95_s": [median_s * 0.99, median_s * 1.01], "normalized": null, "samples": 16,
        "work": null
    })
}

/// `lines` as the history file of `CLASS` under `dir/hist`.
fn write_history(dir: &Path, lines: &[Vec<u8>]) {
    std::fs::create_dir_all(dir.join("hist")).unwrap();
    let mut bytes = Vec::new();
    for l in lines {
        bytes.extend_from_slice(l);
        bytes.push(b'\n');
    }
    std::fs::write(dir.join(format!("hist/{CLASS}.jsonl")), bytes).unwrap();
}

fn line(v: &Value) -> Vec<u8> {
    v.to_string().into_bytes()
}

fn run(dir: &Path, args: &[&str]) -> Output {
    bin().current_dir(dir).args(args).output().unwrap()
}

/// `history --json`, `publish` and `export-results` of the history under `dir/hist`, each
/// checked to succeed: the series, the page and the table.
fn every_reader(dir: &Path) -> (Vec<Value>, String, String, String) {
    let shown = run(
        dir,
        &["history", "--dir", "hist", "--class", CLASS, "--json"],
    );
    assert!(shown.status.success(), "history: {}", text(&shown.stderr));
    let series: Value = serde_json::from_slice(&shown.stdout).unwrap();
    let page = run(dir, &["publish", "--dir", "hist", "--out", "page"]);
    assert!(page.status.success(), "publish: {}", text(&page.stderr));
    let html = std::fs::read_to_string(dir.join("page/index.html")).unwrap();
    let table = run(dir, &["export-results", "hist"]);
    assert!(table.status.success(), "export: {}", text(&table.stderr));
    let warnings = text(&shown.stderr) + &text(&page.stderr) + &text(&table.stderr);
    (
        series.as_array().unwrap().clone(),
        html,
        text(&table.stdout),
        warnings,
    )
}

#[test]
fn a_line_that_is_not_utf8_or_not_a_time_costs_that_line_only_in_every_reader() {
    let dir = tempfile::tempdir().unwrap();
    let mut lines = Vec::new();
    for i in 0..6 {
        let date = format!("2026-11-{:02}T10:00:00Z", i + 1);
        lines.push(line(&record("a", &format!("c{i}"), Some(&date), 1e-3)));
        lines.push(line(&record("b", &format!("c{i}"), Some(&date), 2e-3)));
    }
    // Line 13: one byte that is no UTF-8, inside a record of case a.
    let mut broken = line(&record("a", "c9", Some("2026-11-20"), 1e-3));
    let at = broken.len() - 10;
    broken[at] = 0xff;
    lines.push(broken);
    // Lines 14-16: medians no measurement gives, in case b.
    for (i, median) in [-1.0, 0.0, -1e-9].into_iter().enumerate() {
        let commit = format!("bad{i}");
        lines.push(line(&record("b", &commit, Some("2026-11-21"), median)));
    }
    write_history(dir.path(), &lines);
    let (series, html, table, warnings) = every_reader(dir.path());
    // Both cases keep their six commits.
    assert_eq!(series.len(), 2);
    for s in &series {
        assert_eq!(s["points"].as_array().unwrap().len(), 6, "{s}");
    }
    assert!(html.contains(r#"data-case="a""#) && html.contains(r#"data-case="b""#));
    assert_eq!(table.lines().count(), 1 + 12, "{table}");
    // Each of the three readers names each bad line and why.
    let file = format!("{CLASS}.jsonl");
    assert_eq!(
        warnings
            .matches(&format!("{file} line 13: not UTF-8 text"))
            .count(),
        3,
        "{warnings}"
    );
    for (line, value) in [(14, "-1"), (15, "0"), (16, "-0.000000001")] {
        let said = format!(
            "{file} line {line}: a history record, but median_s = {value} is not a time > 0"
        );
        assert_eq!(warnings.matches(&said).count(), 3, "{said}: {warnings}");
    }
    assert!(!warnings.contains("panicked"), "{warnings}");
}

#[test]
fn commits_are_ordered_by_when_they_were_committed_with_or_without_a_date() {
    let dir = tempfile::tempdir().unwrap();
    // 30 records of one case measured newest commit first, every third without a date:
    // sorting them panicked once.
    let mut lines: Vec<Vec<u8>> = (0..30)
        .map(|i| {
            let date = format!("2026-10-{:02}T10:00:00Z", 30 - i);
            let date = (i % 3 != 1).then_some(date.as_str());
            line(&record("a", &format!("c{i:02}"), date, 1e-3))
        })
        .collect();
    // git's %cI keeps the committer's offset: 23:00 at -05:00 is 04:00 UTC on the 2nd, after
    // 02:00 UTC on the 2nd, although its text sorts first.
    lines.push(line(&record(
        "b",
        "late",
        Some("2026-12-01T23:00-05:00"),
        1e-3,
    )));
    lines.push(line(&record("b", "early", Some("2026-12-02T02:00Z"), 1e-3)));
    write_history(dir.path(), &lines);
    let (series, _, _, warnings) = every_reader(dir.path());
    assert!(!warnings.contains("panicked"), "{warnings}");
    let commits = |s: &Value| -> Vec<String> {
        s["points"]
            .as_array()
            .unwrap()
            .iter()
            .map(|p| p["commit"].as_str().unwrap().to_string())
            .collect()
    };
    // Oldest date first; a record without one right after the record measured before it.
    let mut want = Vec::new();
    for i in (0..30).rev().filter(|i| i % 3 != 1) {
        want.push(format!("c{i:02}"));
        if i % 3 == 0 {
            want.push(format!("c{:02}", i + 1));
        }
    }
    assert_eq!(commits(&series[0]), want);
    assert_eq!(commits(&series[1]), ["early", "late"]);
}

#[test]
fn a_record_of_another_class_is_left_out_of_its_file() {
    let dir = tempfile::tempdir().unwrap();
    let mut lines: Vec<Vec<u8>> = (0..4)
        .map(|i| line(&record("a", &format!("c{i}"), Some("2026-11-01"), 1e-3)))
        .collect();
    let mut stray = record("a", "c9", Some("2026-11-02"), 5e-3);
    stray["class"] = json!("Other-9-9-9-8cpu");
    lines.push(line(&stray));
    write_history(dir.path(), &lines);
    let (series, html, table, warnings) = every_reader(dir.path());
    let said = format!(
        "{CLASS}.jsonl line 5: a history record of machine class `Other-9-9-9-8cpu` in the \
         file of class `{CLASS}`"
    );
    assert_eq!(warnings.matches(&said).count(), 3, "{warnings}");
    assert_eq!(series[0]["points"].as_array().unwrap().len(), 4);
    assert!(!html.contains("Other-9-9-9-8cpu"), "the page draws it");
    assert!(!table.contains("Other-9-9-9-8cpu"), "{table}");
}

#[test]
fn sweeps_outside_git_are_one_point_per_measurement_and_said_so() {
    let dir = tempfile::tempdir().unwrap();
    let mut lines = Vec::new();
    for (measured, median) in [
        ("2026-12-05T10:00:00Z", 1e-3),
        ("2026-12-06T10:00:00Z", 2e-3),
        ("2026-12-05T10:00:00Z", 1.2e-3),
    ] {
        let mut r = record("a", "unknown", None, median);
        r["measured"] = json!(measured);
        lines.push(line(&r));
    }
    write_history(dir.path(), &lines);
    let (series, _, _, _) = every_reader(dir.path());
    let points = series[0]["points"].as_array().unwrap();
    let got: Vec<(&str, u64)> = points
        .iter()
        .map(|p| {
            (
                p["measured"].as_str().unwrap(),
                p["records"].as_u64().unwrap(),
            )
        })
        .collect();
    assert_eq!(
        got,
        [("2026-12-05T10:00:00Z", 2), ("2026-12-06T10:00:00Z", 1)]
    );
    let o = run(dir.path(), &["history", "--dir", "hist", "--class", CLASS]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    assert!(
        text(&o.stdout).contains(
            "2 of the points are of sweeps outside git (no commit): one point per measurement"
        ),
        "{}",
        text(&o.stdout)
    );
}
