//! `report` on a fixture results directory: numbers from the files, idempotent, kept regions
//! survive, bad input is refused with exit 2.

use std::path::Path;
use std::process::Command;

fn report(dir: &Path) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_nbody-bench"))
        .current_dir(dir)
        .args(["report", "--results", "results", "--out", "REPORT.md"])
        .output()
        .unwrap()
}

fn fixture() -> tempfile::TempDir {
    let dir = tempfile::tempdir().unwrap();
    let sweep = dir.path().join("results/quick");
    std::fs::create_dir_all(&sweep).unwrap();
    // The committed quick sweep, read as a complexity study (its cases are kernels over n).
    let text = std::fs::read_to_string("results/quick/results.json").unwrap();
    let mut results: serde_json::Value = serde_json::from_str(&text).unwrap();
    results["config"]["study"] = "complexity".into();
    std::fs::write(
        sweep.join("results.json"),
        serde_json::to_string(&results).unwrap(),
    )
    .unwrap();
    dir
}

#[test]
fn report_numbers_come_from_the_results_and_regeneration_is_idempotent() {
    let dir = fixture();
    let out = report(dir.path());
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = std::fs::read_to_string(dir.path().join("REPORT.md")).unwrap();
    // The fixture's own numbers: the commit, and a case's median time per step.
    let results: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(dir.path().join("results/quick/results.json")).unwrap(),
    )
    .unwrap();
    let commit = &results["metadata"]["git_commit"].as_str().unwrap()[..7];
    assert!(text.contains(commit));
    let case = results["cases"]
        .as_array()
        .unwrap()
        .iter()
        .find(|c| c["key"] == "lj-box/naive/n=2000/p=1/r=1/seed=1")
        .unwrap();
    let median = case["summary"]["median_s"].as_f64().unwrap();
    assert!(text.contains(&nbody_harness::units::Duration(median).to_string()));
    assert!(text.contains("(results/quick/analysis/time-vs-n-lj-box-f32-p1-r1.svg)"));
    assert!(
        dir.path()
            .join("results/quick/analysis/time-vs-n-lj-box-f32-p1-r1.svg")
            .is_file()
    );

    // Hand-written interpretation survives regeneration; the rest is unchanged.
    let edited = text.replace(
        "<!-- keep:complexity -->\n",
        "<!-- keep:complexity -->\nThe symmetric kernel is serial.\n",
    );
    let edited = edited.replacen(
        "_No interpretation written yet: write it here; `nbody-bench report` keeps this region._\n<!-- /keep:complexity -->",
        "<!-- /keep:complexity -->",
        1,
    );
    std::fs::write(dir.path().join("REPORT.md"), &edited).unwrap();
    assert!(report(dir.path()).status.success());
    let again = std::fs::read_to_string(dir.path().join("REPORT.md")).unwrap();
    assert!(again.contains("The symmetric kernel is serial."));
    assert_eq!(
        again, edited,
        "regeneration from the same files changes nothing else"
    );
}

#[test]
fn missing_or_foreign_results_are_refused_with_exit_2() {
    let empty = tempfile::tempdir().unwrap();
    let out = report(empty.path());
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("results"));

    let none = tempfile::tempdir().unwrap();
    std::fs::create_dir_all(none.path().join("results/x")).unwrap();
    let out = report(none.path());
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("no results files"));

    let foreign = fixture();
    std::fs::write(
        foreign.path().join("results/quick/results.json"),
        r#"{"schema": "nbody-bench/results/v0"}"#,
    )
    .unwrap();
    let out = report(foreign.path());
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("schema"));
    assert!(!foreign.path().join("REPORT.md").exists());
}

/// Snapshot: the committed results give exactly the committed REPORT.md, every table and
/// sentence of it (a copy is regenerated, so the repository's figures are not rewritten). A
/// change of the renderer or the analysis shows here as a diff to review, then to commit with
/// `nbody-bench report --results results --out REPORT.md`.
#[test]
fn committed_results_give_the_committed_report_byte_for_byte() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let dir = tempfile::tempdir().unwrap();
    crate::copy_tree(&root.join("results"), &dir.path().join("results"));
    std::fs::copy(root.join("REPORT.md"), dir.path().join("REPORT.md")).unwrap();
    let out = report(dir.path());
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let want = std::fs::read_to_string(root.join("REPORT.md")).unwrap();
    let got = std::fs::read_to_string(dir.path().join("REPORT.md")).unwrap();
    if got != want {
        let line = want
            .lines()
            .zip(got.lines())
            .position(|(a, b)| a != b)
            .unwrap_or(want.lines().count().min(got.lines().count()));
        panic!(
            "REPORT.md differs from what the committed results give, from line {}:\ncommitted: {:?}\ngenerated: {:?}",
            line + 1,
            want.lines().nth(line),
            got.lines().nth(line)
        );
    }
}
