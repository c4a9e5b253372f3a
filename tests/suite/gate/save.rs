//! `gate --save-baseline` over a baseline of the same machine class: this build is measured A/B
//! against the commit the old baseline records, and a regression refuses the save unless
//! accepted by name with a reason, which the history's gate verdicts then keep. The base side
//! is this very binary, cached for the test repository's HEAD (as in the A/B tests of
//! `gate.rs`), and the slower build is the test-only slowdown knob on the current side only.

use super::{bin, git, same_tree_repo, serial, text};
use std::path::{Path, PathBuf};
use std::process::Output;

/// Two cases, the fewest samples a CI is judged on: each A/B run takes seconds.
const SAVE_TINY: &str = r#"
name = "save-tiny"
study = "cartesian"
scenarios = ["lj-box"]
kernels = ["naive", "symmetric"]
n = [1000]
threads = [1]

[measure]
warmup_s = 0.01
samples = 6
rounds = 2
min_sample_s = 0.02
reference_s = 0.02
"#;

const NAIVE: &str = "lj-box/naive/n=1000/p=1/r=1/seed=1";
const SYMMETRIC: &str = "lj-box/symmetric/n=1000/p=1/r=1/seed=1";

/// SAVE_TINY swept without calibration (its 20 s are not what is tested), then given a
/// calibration of this machine's class taken from the committed baseline, so that the file is a
/// baseline of this class. Returns (its JSON, its class's file name in a baseline folder).
fn swept_as_this_class(dir: &Path) -> (serde_json::Value, String) {
    let config = dir.join("save-tiny.toml");
    std::fs::write(&config, SAVE_TINY).unwrap();
    let o = bin()
        .args(["sweep", "--no-calibration", "--config"])
        .arg(&config)
        .arg("--out")
        .arg(dir.join("swept"))
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", text(&o.stderr));
    let results = dir.join("swept/save-tiny/results.json");
    let mut v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(results).unwrap()).unwrap();
    let committed: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(crate::committed_baseline()).unwrap())
            .unwrap();
    v["calibration"] = committed["calibration"].clone();
    for side in ["start", "end"] {
        let c = &mut v["calibration"][side];
        c["cpu_model"] = nbody_calibrate::cpu_model().into();
        c["cpu_signature"] = nbody_calibrate::cpu_signature().into();
        c["logical_cpus"] = nbody_engine::run::logical_cpus().into();
    }
    let info = nbody_harness::gate::RunInfo::from_json(&v).unwrap();
    (v, nbody_harness::gate::baselines::file_name(&info))
}

/// Writes `v` to `path` as results measured at `commit`.
fn write_with_commit(v: &serde_json::Value, commit: &str, path: &Path) -> PathBuf {
    let mut v = v.clone();
    v["metadata"]["git_commit"] = commit.into();
    std::fs::write(path, serde_json::to_string_pretty(&v).unwrap()).unwrap();
    path.to_path_buf()
}

/// `gate --save-baseline new.json` in the repository, the symmetric kernel 5x slower in this
/// build (a ratio near 5: a threshold of 0.75 cannot be crossed by the noise of the others).
fn save(repo: &Path, target: &Path, out: &str, extra: &[&str]) -> Output {
    bin()
        .current_dir(repo)
        .env("CARGO_TARGET_DIR", target)
        .env("NBODY_BENCH_TEST_SLOWDOWN", "symmetric:5")
        .args([
            "gate",
            "--baseline",
            "baseline",
            "--save-baseline",
            "new.json",
        ])
        .args(["--rounds", "2", "--threshold", "0.75", "--out", out])
        .args(extra)
        .output()
        .unwrap()
}

fn assert_exit(o: &Output, code: i32, message: &str) -> String {
    let err = text(&o.stderr);
    assert_eq!(o.status.code(), Some(code), "{err}");
    assert!(err.contains(message), "expected `{message}` in: {err}");
    assert!(!err.contains("panicked"), "{err}");
    err
}

/// One test, so that its A/B runs never overlap.
#[test]
fn a_regression_is_saved_into_a_baseline_only_when_accepted_by_name() {
    let _serial = serial();
    let (repo, target) = same_tree_repo();
    let repo = repo.path();
    let head = git(repo, &["rev-parse", "HEAD"]);
    let (swept, name) = swept_as_this_class(repo);
    std::fs::create_dir(repo.join("baseline")).unwrap();
    let old = write_with_commit(&swept, &head, &repo.join("baseline").join(&name));
    let new = write_with_commit(&swept, "feedc0de", &repo.join("new.json"));
    let before = std::fs::read(&old).unwrap();

    // Bad input is refused before anything is measured.
    let o = save(repo, &target, "no-reason", &["--accept", SYMMETRIC]);
    assert_exit(&o, 2, "--accept needs --reason");
    let o = save(
        repo,
        &target,
        "typo",
        &["--accept", "lj-box/nave", "--reason", "x"],
    );
    let err = assert_exit(
        &o,
        2,
        "not a case the A/B run against the replaced baseline measures",
    );
    assert!(err.contains(SYMMETRIC) && err.contains(NAIVE), "{err}");
    let o = save(repo, &target, "reason-alone", &["--reason", "x"]);
    assert_exit(&o, 2, "--accept");
    for dir in ["no-reason", "typo", "reason-alone"] {
        assert!(!repo.join(dir).exists(), "{dir}: nothing measured");
    }

    // The regression refuses the save, names the case with its ratio, and says how to accept.
    let o = save(repo, &target, "refused", &[]);
    let err = assert_exit(&o, 1, "the new baseline is refused");
    assert!(err.contains(&format!("{SYMMETRIC}: ")), "{err}");
    assert!(!err.contains(&format!("{NAIVE}: ")), "{err}");
    assert!(
        err.contains(&format!("--accept {SYMMETRIC} --reason")),
        "{err}"
    );
    assert_eq!(
        std::fs::read(&old).unwrap(),
        before,
        "the old baseline is untouched"
    );

    // Accepting a case that did not regress is bad input, naming the one that did.
    let o = save(
        repo,
        &target,
        "wrong-case",
        &["--accept", NAIVE, SYMMETRIC, "--reason", "x"],
    );
    let err = assert_exit(&o, 2, "did not regress in the A/B run");
    assert!(
        err.contains(&format!("the regressed cases are: {SYMMETRIC}: ")),
        "{err}"
    );
    assert_eq!(std::fs::read(&old).unwrap(), before);

    // Accepted by name with a reason: saved, and the history keeps the acceptance.
    let reason = "the symmetric kernel checks every pair twice now";
    let o = save(
        repo,
        &target,
        "accepted",
        &[
            "--accept", SYMMETRIC, "--reason", reason, "--record", "history",
        ],
    );
    assert_exit(&o, 0, "regressions accepted");
    assert_eq!(std::fs::read(&old).unwrap(), std::fs::read(&new).unwrap());
    let class = name.trim_start_matches("ci-").trim_end_matches(".json");
    let path = nbody_harness::history::verdicts::file_of(&repo.join("history"), class);
    let verdicts = nbody_harness::history::verdicts::read(&path).unwrap();
    assert!(verdicts.bad.is_empty(), "{:?}", verdicts.bad);
    let accepted: Vec<_> = verdicts
        .runs
        .iter()
        .filter_map(|r| r.acceptance.as_ref())
        .collect();
    assert_eq!(accepted.len(), 1, "{path:?}");
    let a = accepted[0];
    assert_eq!(a.reason, reason);
    assert_eq!(a.replaced_commit, head);
    assert_eq!(a.new_commit, "feedc0de");
    assert_eq!(a.class, class);
    assert_eq!(a.cases.len(), 1);
    assert_eq!(a.cases[0].key, SYMMETRIC);
    assert!(a.cases[0].ratio > 1.75, "{}", a.cases[0].ratio);
}
