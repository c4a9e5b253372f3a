//! The performance history through the binary: `history record` appends a results file's
//! cases to its machine class's file (two at once keep both), `history` reads the series back,
//! a damaged line is named by its number and the rest read, and `sweep --record` appends.

use super::{bin, refused, text};
use std::path::Path;

const CLASS: &str = "AuthenticAMD-26-2-1-2cpu";

/// A copy of a committed baseline (20 cases of the ci config, with reference timings).
fn results(dir: &Path) -> std::path::PathBuf {
    let from =
        Path::new(env!("CARGO_MANIFEST_DIR")).join(format!("results/baseline/ci-{CLASS}.json"));
    let to = dir.join("results.json");
    std::fs::copy(from, &to).unwrap();
    to
}

fn history(dir: &Path, args: &[&str]) -> std::process::Output {
    bin()
        .current_dir(dir)
        .arg("history")
        .args(args)
        .args(["--dir", "hist"])
        .output()
        .unwrap()
}

#[test]
fn records_appended_at_once_are_all_kept_and_read_back_as_series() {
    let dir = tempfile::tempdir().unwrap();
    let file = results(dir.path());
    // Two appenders at once.
    let appenders: Vec<_> = (0..2)
        .map(|_| {
            bin()
                .current_dir(dir.path())
                .args(["history", "record", file.to_str().unwrap(), "--dir", "hist"])
                .spawn()
                .unwrap()
        })
        .collect();
    for mut a in appenders {
        assert!(a.wait().unwrap().success());
    }
    let jsonl = dir.path().join(format!("hist/{CLASS}.jsonl"));
    let lines: Vec<serde_json::Value> = std::fs::read_to_string(&jsonl)
        .unwrap()
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    assert_eq!(lines.len(), 40);
    let first = &lines[0];
    assert_eq!(first["class"], CLASS);
    assert_eq!(first["config"], "ci");
    // The commit the baseline was measured at (it changes whenever the baseline is refreshed).
    let baseline: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&file).unwrap()).unwrap();
    let measured_at = baseline["metadata"]["git_commit"].as_str().unwrap();
    assert!(!measured_at.is_empty());
    assert!(measured_at.starts_with(first["commit"].as_str().unwrap()));
    assert!(first["normalized"]["median"].as_f64().unwrap() > 0.0);
    // The series: one point for the one commit measured twice.
    let o = history(dir.path(), &["--class", CLASS, "--json"]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let series: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let series = series.as_array().unwrap();
    assert_eq!(series.len(), 20);
    assert!(
        series
            .iter()
            .all(|s| s["points"].as_array().unwrap().len() == 1
                && s["points"][0]["records"] == 2
                && s["metric"] == "normalized")
    );
    // A pattern picks cases; a damaged line is named and the rest still read.
    let mut damaged = std::fs::read_to_string(&jsonl).unwrap();
    damaged.insert_str(0, "{not json\n");
    std::fs::write(&jsonl, damaged).unwrap();
    let o = history(dir.path(), &["--class", CLASS, "--case", "*/verlet/*"]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    assert!(text(&o.stderr).contains("line 1: not a history record"));
    let shown = text(&o.stdout);
    assert!(
        shown.contains("40 records") && shown.contains("/verlet/"),
        "{shown}"
    );
    assert!(!shown.contains("/naive/"), "{shown}");
}

#[test]
fn what_cannot_be_shown_or_recorded_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    refused(
        &history(dir.path(), &["--class", "Nope-1cpu"]),
        "Nope-1cpu.jsonl does not exist",
    );
    refused(
        &history(dir.path(), &["record", "missing.json"]),
        "missing.json",
    );
    let file = results(dir.path());
    let o = history(dir.path(), &["record", file.to_str().unwrap()]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    refused(
        &history(dir.path(), &["--class", CLASS, "--case", "nothing/*"]),
        "no case",
    );
}

#[test]
fn a_sweep_with_record_appends_its_cases() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(
        dir.path().join("tiny.toml"),
        "name = \"tiny\"\nstudy = \"cartesian\"\nscenarios = [\"lj-box\"]\n\
         kernels = [\"naive\", \"cell-list\"]\nn = [100]\nthreads = [1]\n[measure]\n\
         warmup_s = 0.001\nsamples = 2\nrounds = 1\nmin_sample_s = 0.001\nreference_s = 0.001\n",
    )
    .unwrap();
    let o = bin()
        .current_dir(dir.path())
        .args([
            "sweep",
            "--config",
            "tiny.toml",
            "--out",
            "out",
            "--no-calibration",
        ])
        .args(["--yes", "--record", "hist"])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", text(&o.stderr));
    assert!(
        text(&o.stderr).contains("2 records appended"),
        "{}",
        text(&o.stderr)
    );
    let files: Vec<_> = std::fs::read_dir(dir.path().join("hist"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    assert_eq!(files.len(), 1);
    let text = std::fs::read_to_string(&files[0]).unwrap();
    assert_eq!(text.lines().count(), 2);
    assert!(text.contains("\"source\":\"sweep\"") && text.contains("\"config\":\"tiny\""));
}

/// A series that steps 10% slower at its 13th commit: the step is shown between the 12th and
/// the 13th commit, with its size; the one spike in it is not a step.
#[test]
fn a_step_is_named_between_its_two_commits() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::create_dir(dir.path().join("hist")).unwrap();
    let mut lines = String::new();
    for i in 0..24 {
        // ±0.5% of alternating noise, a 30% spike at commit 5, a 10% step from commit 12.
        let mut t = 1e-3 * if i % 2 == 0 { 1.005 } else { 0.995 };
        if i == 5 {
            t *= 1.3;
        }
        if i >= 12 {
            t *= 1.1;
        }
        lines.push_str(&format!(
            "{{\"schema\":\"nbody-bench-history/1\",\"commit\":\"c{i:02}\",\"parent\":null,\
             \"commit_date\":\"2026-11-{:02}T00:00:00Z\",\"dirty\":false,\
             \"measured\":\"2026-12-05T00:00:00Z\",\"class\":\"X-2cpu\",\"build\":{{\
             \"tool_version\":\"0.1.0\",\"profile\":\"release\",\"simd\":\"avx2\",\
             \"features\":[]}},\"config\":\"ci\",\"source\":\"backfill\",\"case\":\"k\",\
             \"n\":1000,\"median_s\":{t},\"ci95_s\":[{t},{t}],\"normalized\":null,\
             \"samples\":16,\"work\":null}}\n",
            i + 1
        ));
    }
    std::fs::write(dir.path().join("hist/X-2cpu.jsonl"), lines).unwrap();
    let o = history(dir.path(), &["--class", "X-2cpu", "--json"]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let found: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let changes = found[0]["changes"].as_array().unwrap();
    assert_eq!(changes.len(), 1, "{changes:?}");
    assert_eq!(changes[0]["between"], serde_json::json!(["c11", "c12"]));
    let ratio = changes[0]["ratio"].as_f64().unwrap();
    assert!((ratio - 1.1).abs() < 0.01, "{ratio}");
    let o = history(dir.path(), &["--class", "X-2cpu"]);
    assert!(
        text(&o.stdout).contains("step between c11 and c12"),
        "{}",
        text(&o.stdout)
    );
}

/// A commit field of any text (a hand-edited file) is shown, never cut inside a character.
#[test]
fn a_commit_of_any_text_is_shown_whole_characters() {
    let dir = tempfile::tempdir().unwrap();
    let file = results(dir.path());
    let o = history(dir.path(), &["record", file.to_str().unwrap()]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let jsonl = dir.path().join(format!("hist/{CLASS}.jsonl"));
    let edited = std::fs::read_to_string(&jsonl)
        .unwrap()
        .replace("0c85c98d046a77b9086f3179e7e47a98609f2842", "ééééééééééééé");
    std::fs::write(&jsonl, edited).unwrap();
    let o = history(dir.path(), &["--class", CLASS]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    assert!(!text(&o.stderr).contains("panicked"));
}
