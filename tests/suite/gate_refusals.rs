//! The gate never judges vacuously and never waits forever: a check that could compare nothing
//! is exit 2 with the reason, a file that cannot be a baseline is refused with the folder left
//! byte for byte as it was, every A/B refusal comes before the base build, and a base binary
//! that hangs is stopped at its time limit. Nothing here times a kernel: the A/B runs meet a
//! fake base binary (a shell script) before anything is measured.

use crate::{bin, refused, text};
use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::time::Duration;
use wait_timeout::ChildExt;

/// Runs `cmd` to its end, failing the test (and killing it) if it takes more than `limit`: a
/// guard against a hang, not a timing assertion.
fn run_guarded(cmd: &mut Command, limit: Duration) -> Output {
    let dir = tempfile::tempdir().unwrap();
    let (out, err) = (dir.path().join("out"), dir.path().join("err"));
    let mut child = cmd
        .stdout(std::fs::File::create(&out).unwrap())
        .stderr(std::fs::File::create(&err).unwrap())
        .spawn()
        .unwrap();
    let Some(status) = child.wait_timeout(limit).unwrap() else {
        let _ = child.kill();
        let _ = child.wait();
        panic!(
            "still running after {limit:?}: {}",
            std::fs::read_to_string(&err).unwrap_or_default()
        );
    };
    Output {
        status,
        stdout: std::fs::read(&out).unwrap(),
        stderr: std::fs::read(&err).unwrap(),
    }
}

const GUARD: Duration = Duration::from_secs(120);

/// A copy of the committed baseline with `edit` applied, written to `dir/name`.
fn edited(dir: &Path, name: &str, edit: impl FnOnce(&mut serde_json::Value)) -> PathBuf {
    let mut v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(crate::committed_baseline()).unwrap())
            .unwrap();
    edit(&mut v);
    let path = dir.join(name);
    std::fs::write(&path, serde_json::to_string(&v).unwrap()).unwrap();
    path
}

/// Every round of every case, for editing.
fn rounds(v: &mut serde_json::Value) -> impl Iterator<Item = &mut serde_json::Value> {
    v["cases"]
        .as_array_mut()
        .unwrap()
        .iter_mut()
        .flat_map(|c| c["rounds"].as_array_mut().unwrap().iter_mut())
}

fn gate_files(baseline: &Path, current: &Path, extra: &[&str]) -> Output {
    let mut cmd = bin();
    cmd.arg("gate")
        .arg("--baseline")
        .arg(baseline)
        .arg("--current")
        .arg(current)
        .args(extra);
    run_guarded(&mut cmd, GUARD)
}

#[test]
fn fail_on_work_change_with_no_counter_to_compare_is_an_error() {
    let dir = tempfile::tempdir().unwrap();
    let base = crate::committed_baseline();
    let no_counters = edited(dir.path(), "old.json", |v| {
        for round in rounds(v) {
            round["initial_work"] = serde_json::Value::Null;
        }
    });
    // Without the flag the counters are only a note, and the same samples pass.
    let o = gate_files(&base, &no_counters, &[]);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o.stderr));
    let o = gate_files(&base, &no_counters, &["--fail-on-work-change"]);
    refused(&o, "--fail-on-work-change asks for them");
    refused(&o, "could not be compared, which is not a pass");
    // With counters on both sides the flag passes unchanged code.
    let o = gate_files(&base, &base, &["--fail-on-work-change"]);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o.stderr));
}

#[test]
fn a_ci_the_samples_cannot_support_is_not_judged() {
    let dir = tempfile::tempdir().unwrap();
    // One sample per side of the first case, the current one 1.5x slower: "95% CI [1.500,
    // 1.500]" would be a regression judged on nothing.
    let one = |factor: f64| {
        move |v: &mut serde_json::Value| {
            let case = &mut v["cases"][0];
            let key = case["key"].as_str().unwrap().to_string();
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
                        .map(|x| (x.as_f64().unwrap() * factor).into())
                        .collect();
                    round[list] = kept.into();
                }
            }
            key
        }
    };
    let mut key = String::new();
    let base = edited(dir.path(), "base.json", |v| key = one(1.0)(v));
    let slow = edited(dir.path(), "slow.json", |v| {
        one(1.5)(v);
        // The reference stays: only the case got slower.
        for (i, round) in v["cases"][0]["rounds"]
            .as_array_mut()
            .unwrap()
            .iter_mut()
            .enumerate()
        {
            if i == 0 {
                let r = round["reference_s"][0].as_f64().unwrap() / 1.5;
                round["reference_s"][0] = r.into();
            }
        }
    });
    let o = gate_files(&base, &slow, &["--format", "json"]);
    refused(&o, &key);
    refused(&o, "a 95% CI of the ratio needs at least 6 per side");
    let report: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert!(
        report["cases"]
            .as_array()
            .unwrap()
            .iter()
            .all(|c| c["key"] != key.as_str() && c["verdict"] != "regressed"),
        "{report}"
    );
}

#[test]
fn the_threshold_is_bounded() {
    let base = crate::committed_baseline();
    for bad in ["1e300", "1.5", "inf"] {
        let o = gate_files(&base, &base, &["--threshold", bad]);
        assert_eq!(o.status.code(), Some(2), "{bad}: {}", text(&o.stderr));
        assert!(!text(&o.stderr).contains("panicked"));
        assert!(
            text(&o.stderr).contains("from 0 to 1") || text(&o.stderr).contains("must be finite"),
            "{bad}: {}",
            text(&o.stderr)
        );
    }
    let o = gate_files(&base, &base, &["--threshold", "1"]);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o.stderr));
}

#[test]
fn a_file_no_gate_could_judge_against_is_not_saved_as_a_baseline() {
    let dir = tempfile::tempdir().unwrap();
    let folder = dir.path().join("baseline");
    std::fs::create_dir(&folder).unwrap();
    let good = crate::committed_baseline();
    let kept = folder.join(good.file_name().unwrap());
    std::fs::copy(&good, &kept).unwrap();
    let before = std::fs::read(&kept).unwrap();
    let no_case = edited(dir.path(), "no-case.json", |v| {
        v["cases"] = serde_json::json!([]);
    });
    let no_round = edited(dir.path(), "no-round.json", |v| {
        let case = &mut v["cases"][1];
        case["rounds"] = serde_json::json!([]);
        case["rounds_done"] = 0.into();
    });
    let zeros = edited(dir.path(), "zeros.json", |v| {
        for round in rounds(v) {
            let n = round["samples_s"].as_array().unwrap().len();
            round["samples_s"] = vec![0.0; n].into();
        }
    });
    for (file, why) in [
        (&no_case, "it holds no case"),
        (&no_round, "0/3 rounds measured"),
        (&zeros, "no samples in the baseline"),
    ] {
        let mut cmd = bin();
        cmd.arg("gate")
            .arg("--baseline")
            .arg(&folder)
            .arg("--save-baseline")
            .arg(file);
        let o = run_guarded(&mut cmd, GUARD);
        refused(&o, "cannot be a baseline");
        refused(&o, why);
        assert_eq!(std::fs::read(&kept).unwrap(), before, "{why}: replaced");
        let names: Vec<_> = std::fs::read_dir(&folder).unwrap().flatten().collect();
        assert_eq!(names.len(), 1, "{why}: nothing else written");
    }
}

fn git(dir: &Path, args: &[&str]) -> String {
    let o = Command::new("git")
        .current_dir(dir)
        .args(["-c", "user.name=test", "-c", "user.email=test@localhost"])
        .args(args)
        .output()
        .unwrap();
    assert!(o.status.success(), "git {args:?}: {}", text(&o.stderr));
    text(&o.stdout).trim().to_string()
}

const TINY: &str = r#"
name = "tiny"
study = "cartesian"
scenarios = ["lj-box"]
kernels = ["naive"]
n = [200]
threads = [1]

[measure]
warmup_s = 0.0
samples = 6
rounds = 2
min_sample_s = 0.001
"#;

/// A git repository holding `configs` (name, text), committed; its HEAD.
fn repo(dir: &Path, configs: &[(&str, &str)]) -> String {
    git(dir, &["init", "-q"]);
    for (name, body) in configs {
        std::fs::write(dir.join(name), body).unwrap();
    }
    git(dir, &["add", "-A"]);
    git(dir, &["commit", "-q", "-m", "configs"]);
    git(dir, &["rev-parse", "HEAD"])
}

fn a_b(dir: &Path, config: &str, extra: &[&str]) -> Output {
    let mut cmd = bin();
    cmd.current_dir(dir)
        .env("CARGO_TARGET_DIR", dir.join("target"))
        .args(["gate", "--against", "HEAD", "--config", config])
        .args(extra);
    run_guarded(&mut cmd, GUARD)
}

/// What used to fail only after minutes of building the base revision is refused before it:
/// nothing is built (no base build directory appears) and no run directory is left.
#[test]
fn a_b_refusals_come_before_the_base_build() {
    let dir = tempfile::tempdir().unwrap();
    let mpi = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("configs/weak-mpi.toml"),
    )
    .unwrap();
    let big_seed = TINY.replace(
        "threads = [1]",
        "threads = [1]\nseeds = [18446744073709551615]",
    );
    repo(
        dir.path(),
        &[
            ("tiny.toml", TINY),
            ("mpi.toml", &mpi),
            ("seed.toml", &big_seed),
        ],
    );
    let cases: [(&str, &[&str], &str); 5] = [
        ("tiny.toml", &["--rounds", "3"], "even number from 2 to 100"),
        (
            "tiny.toml",
            &["--rounds", "1000000000"],
            "even number from 2 to 100",
        ),
        ("mpi.toml", &[], "it runs cases under MPI"),
        ("seed.toml", &[], "9223372036854775807"),
        ("tiny.toml", &["--timeout", "1e20"], "more than a week"),
    ];
    for (config, extra, why) in cases {
        let o = a_b(dir.path(), config, extra);
        refused(&o, why);
        let err = text(&o.stderr);
        assert!(!err.contains("building the base revision"), "{err}");
        assert!(
            !dir.path().join("target/gate-base").exists(),
            "{config} {extra:?}: a base build started"
        );
        assert!(
            !dir.path().join("results").exists(),
            "{config}: run dir left"
        );
    }
}

/// A base binary that hangs, in the gate's cache for the repository's HEAD.
fn hanging_base(dir: &Path, head: &str, script: &str) {
    use std::os::unix::fs::PermissionsExt;
    let cached = dir
        .join("target/gate-base")
        .join(nbody_harness::gate::base_build::cache_key(head));
    std::fs::create_dir_all(&cached).unwrap();
    let path = cached.join("nbody-bench");
    std::fs::write(&path, script).unwrap();
    std::fs::set_permissions(&path, std::fs::Permissions::from_mode(0o755)).unwrap();
}

#[test]
fn a_base_binary_that_hangs_is_stopped_at_its_time_limit() {
    // It answers `sweep --help` and hangs in the sweep; its `sleep` is a child of its own,
    // stopped with it (else it would hold the gate's pipe open).
    let dir = tempfile::tempdir().unwrap();
    let head = repo(dir.path(), &[("tiny.toml", TINY)]);
    hanging_base(
        dir.path(),
        &head,
        "#!/bin/sh\nif [ \"$2\" = --help ]; then echo --yes; exit 0; fi\nsleep 300\n",
    );
    let o = a_b(
        dir.path(),
        "tiny.toml",
        &["--rounds", "2", "--timeout", "1", "--out", "ab"],
    );
    refused(&o, "the base build's sweep of lj-box/naive/");
    refused(&o, "did not finish within 1 s and was stopped");
    refused(&o, "pass --timeout SECONDS");
    assert!(text(&o.stderr).contains("estimated"), "{}", text(&o.stderr));
    // No scratch of the stopped sweep is left.
    let left: Vec<_> = std::fs::read_dir(dir.path().join("ab"))
        .map(|d| d.flatten().map(|e| e.file_name()).collect())
        .unwrap_or_default();
    assert!(left.is_empty(), "{left:?}");

    // One that hangs whatever it is asked.
    let dir = tempfile::tempdir().unwrap();
    let head = repo(dir.path(), &[("tiny.toml", TINY)]);
    hanging_base(dir.path(), &head, "#!/bin/sh\nsleep 300\n");
    let o = a_b(dir.path(), "tiny.toml", &["--timeout", "1", "--out", "ab"]);
    refused(&o, "cannot be asked for its options");
    refused(&o, "did not finish within 1 s and was stopped");
}
