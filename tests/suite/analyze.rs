//! `analyze` on the committed quick sweep, and on bad input.

use std::process::Command;

fn bin() -> Command {
    Command::new(env!("CARGO_BIN_EXE_nbody-bench"))
}

#[test]
fn analyze_committed_quick_sweep_writes_fits_summary_and_figures() {
    let dir = tempfile::tempdir().unwrap();
    let out = bin()
        .args(["analyze", "results/quick/results.json", "--out"])
        .arg(dir.path())
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let fits: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.path().join("fits.json")).unwrap())
            .unwrap();
    assert_eq!(fits["schema"], "nbody-bench/fits/v1");
    let strong = fits["strong"].as_array().unwrap();
    assert!(!strong.is_empty());
    let f = &strong[0]["fit"]["fit"]["serial_fraction"];
    assert!(f["estimate"].as_f64().unwrap() >= 0.0 && f["ci95"].as_array().unwrap().len() == 2);
    let summary = std::fs::read_to_string(dir.path().join("summary.md")).unwrap();
    assert!(summary.contains("## Strong scaling") && summary.contains("Amdahl f"));
    for stem in [
        "speedup-galaxy-n2000-f64",
        "phases-lj-box",
        "percentiles-galaxy",
    ] {
        for ext in ["svg", "png"] {
            let path = dir.path().join(format!("{stem}.{ext}"));
            assert!(
                std::fs::metadata(&path)
                    .map(|m| m.len() > 0)
                    .unwrap_or(false),
                "{path:?} missing"
            );
        }
        assert!(summary.contains(&format!("({stem}.svg)")));
    }
    // Deterministic: a second analysis gives the same fits.
    let again = tempfile::tempdir().unwrap();
    let status = bin()
        .args(["analyze", "results/quick/results.json", "--out"])
        .arg(again.path())
        .output()
        .unwrap()
        .status;
    assert!(status.success());
    assert_eq!(
        std::fs::read_to_string(dir.path().join("fits.json")).unwrap(),
        std::fs::read_to_string(again.path().join("fits.json")).unwrap()
    );
}

#[test]
fn analyze_refuses_truncated_and_foreign_files_with_exit_2() {
    let dir = tempfile::tempdir().unwrap();
    let text = std::fs::read_to_string("results/quick/results.json").unwrap();
    let truncated = dir.path().join("truncated.json");
    std::fs::write(&truncated, &text[..text.len() / 2]).unwrap();
    let foreign = dir.path().join("foreign.json");
    std::fs::write(&foreign, r#"{"schema": "other/v9"}"#).unwrap();
    for (file, needle) in [
        (&truncated, "not a valid results file"),
        (&foreign, "schema"),
    ] {
        let out = bin()
            .arg("analyze")
            .arg(file)
            .arg("--out")
            .arg(dir.path().join("out"))
            .output()
            .unwrap();
        assert_eq!(out.status.code(), Some(2));
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(err.contains(needle), "{err}");
        assert!(!dir.path().join("out").join("fits.json").exists());
    }
}

/// Snapshots: the committed sweeps give exactly their committed `summary.md` and `fits.json`
/// (the tables `summary.md` shares with REPORT.md come from one renderer; a change of any table
/// shows here as a diff to review and commit with `nbody-bench report`).
#[test]
fn committed_sweeps_give_their_committed_summaries_byte_for_byte() {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut checked = 0;
    for entry in std::fs::read_dir(root.join("results")).unwrap().flatten() {
        let sweep = entry.path();
        let committed = sweep.join("analysis/summary.md");
        if !sweep.join("results.json").is_file() || !committed.is_file() {
            continue;
        }
        let name = sweep.file_name().unwrap().to_string_lossy().into_owned();
        let dir = tempfile::tempdir().unwrap();
        let out = bin()
            .current_dir(root)
            .args(["analyze", &format!("results/{name}/results.json"), "--out"])
            .arg(dir.path())
            .output()
            .unwrap();
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        for file in ["summary.md", "fits.json"] {
            let want = std::fs::read_to_string(sweep.join("analysis").join(file)).unwrap();
            let got = std::fs::read_to_string(dir.path().join(file)).unwrap();
            assert!(got == want, "{name}/{file} differs from the committed one");
        }
        checked += 1;
    }
    assert!(checked >= 5, "only {checked} committed sweeps found");
}

/// A results file edited to hold times no step takes (a median of -1 s, a sample of 0 s): every
/// reader that analyses it (`analyze`, `report`, `history record`) takes them out and says so,
/// case by case; none uses them.
#[test]
fn times_no_step_takes_are_taken_out_and_named_by_every_analysis() {
    let dir = tempfile::tempdir().unwrap();
    let results = dir.path().join("sweeps/quick/results.json");
    std::fs::create_dir_all(results.parent().unwrap()).unwrap();
    let mut file: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(
            std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("results/quick/results.json"),
        )
        .unwrap(),
    )
    .unwrap();
    let cases = file["cases"].as_array_mut().unwrap();
    // Case 0: every sample -1 s, and a summary that says so; case 1: one sample of 0 s.
    for round in cases[0]["rounds"].as_array_mut().unwrap() {
        for s in round["samples_s"].as_array_mut().unwrap() {
            *s = serde_json::json!(-1.0);
        }
    }
    cases[0]["summary"]["median_s"] = serde_json::json!(-1.0);
    cases[1]["rounds"][0]["samples_s"][0] = serde_json::json!(0.0);
    let keys = [0, 1].map(|i| cases[i]["key"].as_str().unwrap().to_string());
    std::fs::write(&results, file.to_string()).unwrap();
    let analyze = bin()
        .args(["analyze"])
        .arg(&results)
        .arg("--out")
        .arg(dir.path().join("analysis"))
        .output()
        .unwrap();
    let report = bin()
        .current_dir(dir.path())
        .args(["report", "--results", "sweeps", "--out", "R.md"])
        .output()
        .unwrap();
    let record = bin()
        .current_dir(dir.path())
        .args([
            "history",
            "record",
            "sweeps/quick/results.json",
            "--dir",
            "hist",
        ])
        .output()
        .unwrap();
    for (what, o) in [
        ("analyze", analyze),
        ("report", report),
        ("history record", record),
    ] {
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(o.status.success(), "{what}: {err}");
        assert!(
            err.contains(&format!(
                "case {}: round 0 sample 0 = -1e0 s per step: a step takes more than zero time \
                 and 5 more, taken out; it has no sample left, so no figure",
                keys[0]
            )),
            "{what}: {err}"
        );
        assert!(
            err.contains(&format!(
                "case {}: round 0 sample 0 = 0e0 s per step: a step takes more than zero time, \
                 taken out; its median is of the other 5 samples",
                keys[1]
            )),
            "{what}: {err}"
        );
    }
    // The history holds no record of the case without a sample.
    let history = std::fs::read_dir(dir.path().join("hist"))
        .unwrap()
        .map(|e| std::fs::read_to_string(e.unwrap().path()).unwrap())
        .collect::<String>();
    assert!(!history.contains(&format!("\"case\":\"{}\"", keys[0])));
    assert!(history.contains(&format!("\"case\":\"{}\"", keys[1])));
}
