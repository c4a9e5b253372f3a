//! A refusal names its real cause: a gate that could judge no case says why each was left out
//! (too few samples), a results file looked for is named once (not joined to itself), and a
//! directory that cannot be made because a file is in the way says that a directory was
//! expected there, not "File exists".

use crate::{bin, refused, text};
use std::path::Path;

/// The committed baseline with every round of every case cut to its first sample.
fn one_sample_each(dir: &Path) -> std::path::PathBuf {
    let mut v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(crate::committed_baseline()).unwrap())
            .unwrap();
    for case in v["cases"].as_array_mut().unwrap() {
        for (i, round) in case["rounds"]
            .as_array_mut()
            .unwrap()
            .iter_mut()
            .enumerate()
        {
            for list in ["samples_s", "reference_s"] {
                let kept: Vec<serde_json::Value> = round[list]
                    .as_array()
                    .unwrap()
                    .iter()
                    .take(usize::from(i == 0))
                    .cloned()
                    .collect();
                round[list] = kept.into();
            }
        }
    }
    let path = dir.join("few.json");
    std::fs::write(&path, serde_json::to_string(&v).unwrap()).unwrap();
    path
}

#[test]
fn a_gate_that_judged_nothing_says_the_samples_were_too_few() {
    let dir = tempfile::tempdir().unwrap();
    let few = one_sample_each(dir.path());
    let o = bin()
        .current_dir(dir.path())
        .arg("gate")
        .arg("--baseline")
        .arg(&few)
        .arg("--current")
        .arg(&few)
        .output()
        .unwrap();
    refused(&o, "could judge none of its");
    refused(&o, "a 95% CI of the ratio needs at least 6 per side");
    assert!(
        !text(&o.stderr).contains("nothing was judged"),
        "{}",
        text(&o.stderr)
    );
}

#[test]
fn a_missing_results_file_is_named_once() {
    let dir = tempfile::tempdir().unwrap();
    let o = bin()
        .current_dir(dir.path())
        .args(["analyze", "results.json"])
        .output()
        .unwrap();
    refused(&o, "looked for results.json");
    assert!(
        !text(&o.stderr).contains("results.json/results.json"),
        "{}",
        text(&o.stderr)
    );
}

#[test]
fn a_file_where_a_directory_is_expected_is_named_as_such() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("a-file"), "").unwrap();
    std::fs::write(
        dir.path().join("tiny.toml"),
        "name = \"tiny\"\nstudy = \"cartesian\"\nscenarios = [\"lj-box\"]\n\
         kernels = [\"naive\"]\nn = [60]\n[measure]\nsamples = 2\nrounds = 1\n",
    )
    .unwrap();
    let expected = "a-file is a file, where a directory is expected";
    let swept = bin()
        .current_dir(dir.path())
        .args(["sweep", "--config", "tiny.toml", "--out", "a-file"])
        .args(["--no-calibration", "--yes"])
        .output()
        .unwrap();
    refused(&swept, expected);
    let quick = Path::new(env!("CARGO_MANIFEST_DIR")).join("results/quick/results.json");
    let analyzed = bin()
        .current_dir(dir.path())
        .arg("analyze")
        .arg(&quick)
        .args(["--out", "a-file/analysis"])
        .output()
        .unwrap();
    refused(&analyzed, expected);
    for o in [&swept, &analyzed] {
        assert!(!text(&o.stderr).contains("os error"), "{}", text(&o.stderr));
    }
}
