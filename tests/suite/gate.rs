//! The `gate` command end to end: real tiny sweeps of the same code pass, a kernel made
//! genuinely slower (the test-only slowdown knob) is flagged alone with exit 1, and bad input
//! (truncated or wrong-schema JSON, another machine, missing cases) exits 2 with a message.

mod save;

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn bin() -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_nbody-bench"));
    c.env_remove("NBODY_BENCH_TEST_SLOWDOWN");
    c
}

fn text(bytes: &[u8]) -> String {
    String::from_utf8_lossy(bytes).into_owned()
}

/// About 0.5 s per case: one thread, three rounds, the reference before every sample. Samples
/// (and their references) last 20 ms, several scheduler slices, so that on a busy machine both
/// see about the same share of the CPU; much shorter ones see all or nothing of it.
const TINY: &str = r#"
name = "gate-tiny"
study = "cartesian"
scenarios = ["lj-box"]
kernels = ["naive", "symmetric", "cell-list"]
n = [1000]
threads = [1]

[measure]
warmup_s = 0.01
samples = 12
rounds = 3
min_sample_s = 0.02
reference_s = 0.02
"#;

/// The tests of this file run one at a time: a sweep must not share the CPUs with another
/// test's gate runs.
static SERIAL: std::sync::Mutex<()> = std::sync::Mutex::new(());

fn serial() -> std::sync::MutexGuard<'static, ()> {
    SERIAL.lock().unwrap_or_else(|e| e.into_inner())
}

/// Sweeps TINY into `dir/<out>` (with the slowdown knob if given); returns the results path.
#[cfg(feature = "test-slowdown")]
fn sweep(dir: &Path, out: &str, slowdown: Option<&str>) -> PathBuf {
    let config = dir.join("gate-tiny.toml");
    std::fs::write(&config, TINY).unwrap();
    let mut cmd = bin();
    cmd.args(["sweep", "--config"])
        .arg(&config)
        .arg("--out")
        .arg(dir.join(out));
    if let Some(knob) = slowdown {
        cmd.env("NBODY_BENCH_TEST_SLOWDOWN", knob);
    }
    let o = cmd.output().unwrap();
    assert!(o.status.success(), "{}", text(&o.stderr));
    dir.join(out).join("gate-tiny/results.json")
}

fn gate(baseline: &Path, current: &Path, extra: &[&str]) -> Output {
    bin()
        .arg("gate")
        .arg("--baseline")
        .arg(baseline)
        .arg("--current")
        .arg(current)
        .args(extra)
        .output()
        .unwrap()
}

/// (case key, verdict) from the JSON report.
fn verdicts(o: &Output) -> Vec<(String, String)> {
    let report: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    report["cases"]
        .as_array()
        .unwrap()
        .iter()
        .map(|c| {
            (
                c["key"].as_str().unwrap().to_string(),
                c["verdict"].as_str().unwrap().to_string(),
            )
        })
        .collect()
}

/// One test, so that the sweeps never run at the same time as each other. The slower build is
/// the test-only slowdown knob (the `test-slowdown` feature).
#[cfg(feature = "test-slowdown")]
#[test]
fn same_code_passes_and_a_slower_kernel_is_flagged_alone() {
    let _serial = serial();
    let dir = tempfile::tempdir().unwrap();
    let base = sweep(dir.path(), "a", None);
    let same = sweep(dir.path(), "b", None);
    let slow = sweep(dir.path(), "c", Some("symmetric:5"));
    // A large slowdown and a moderate threshold, so that the test cannot be flaky on a busy
    // 2-core machine: the 5x slowdown gives a ratio near 5, and the noise of unchanged code,
    // normalised by the reference, stays well below 1.75 there.
    let json = ["--threshold", "0.75", "--format", "json"];

    let o = gate(&base, &same, &json);
    assert_eq!(
        o.status.code(),
        Some(0),
        "{}{}",
        text(&o.stdout),
        text(&o.stderr)
    );
    let v = verdicts(&o);
    assert_eq!(v.len(), 3);
    assert!(v.iter().all(|(_, verdict)| verdict != "regressed"), "{v:?}");

    let o = gate(&base, &slow, &json);
    assert_eq!(
        o.status.code(),
        Some(1),
        "{}{}",
        text(&o.stdout),
        text(&o.stderr)
    );
    for (key, verdict) in verdicts(&o) {
        let expected = key.starts_with("lj-box/symmetric/");
        assert_eq!(verdict == "regressed", expected, "{key}: {verdict}");
    }
    let report: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    // The slowdown repeats the computation: the work of one computation is unchanged.
    assert!(
        report["cases"]
            .as_array()
            .unwrap()
            .iter()
            .all(|c| c["work_changes"].as_array().unwrap().is_empty())
    );

    let o = gate(
        &base,
        &slow,
        &["--threshold", "0.75", "--format", "markdown"],
    );
    let md = text(&o.stdout);
    assert_eq!(o.status.code(), Some(1), "markdown: {md}");
    assert!(
        md.starts_with("### Performance gate: regression found"),
        "{md}"
    );
    assert!(
        md.contains("| `lj-box/symmetric/n=1000/p=1/r=1/seed=1` |"),
        "{md}"
    );
    let o = gate(&base, &slow, &["--threshold", "0.75"]);
    assert_eq!(o.status.code(), Some(1), "text: {}", text(&o.stdout));

    // Through the CI script too, with and without a job summary to append to.
    let summary = dir.path().join("summary.md");
    for job_summary in [false, true] {
        let mut cmd =
            Command::new(Path::new(env!("CARGO_MANIFEST_DIR")).join("scripts/ci-gate.sh"));
        cmd.env("NBODY_BENCH_BIN", env!("CARGO_BIN_EXE_nbody-bench"))
            .env("NBODY_BENCH_GATE_BASELINE", &base)
            .env("NBODY_BENCH_GATE_CURRENT", &slow)
            .env("NBODY_BENCH_GATE_THRESHOLD", "0.75")
            .env_remove("NBODY_BENCH_GATE_AGAINST")
            .env_remove("GITHUB_STEP_SUMMARY");
        if job_summary {
            cmd.env("GITHUB_STEP_SUMMARY", &summary);
        }
        let o = cmd.output().unwrap();
        assert_eq!(o.status.code(), Some(1), "{}", text(&o.stderr));
    }
    let appended = std::fs::read_to_string(&summary).unwrap();
    assert!(appended.contains("regression found"), "{appended}");
}

/// A committed baseline: a real results file of some machine class.
fn committed_baseline() -> PathBuf {
    crate::committed_baseline()
}

fn edited(dir: &Path, name: &str, edit: impl FnOnce(&mut serde_json::Value)) -> PathBuf {
    let mut v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(committed_baseline()).unwrap()).unwrap();
    edit(&mut v);
    let path = dir.join(name);
    std::fs::write(&path, serde_json::to_string(&v).unwrap()).unwrap();
    path
}

fn assert_bad_input(o: &Output, message: &str) {
    let err = text(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(err.contains(message), "expected `{message}` in: {err}");
    assert!(!err.contains("panicked"), "{err}");
}

/// A case the measurements cannot settle: its ratio within the threshold, its interval too wide
/// to show it unchanged. It is reported unknown, named with how to settle it, and fails nothing.
#[test]
fn an_undecided_case_is_reported_unknown_and_named() {
    let dir = tempfile::tempdir().unwrap();
    let base = committed_baseline();
    let mut first = String::new();
    let current = edited(dir.path(), "current.json", |v| {
        let case = &mut v["cases"][0];
        first = case["key"].as_str().unwrap().to_string();
        // Every other sample 0.8x, the rest 1.5x: a geometric mean near 1.095 (below 1.10),
        // spread far beyond ±20%.
        for round in case["rounds"].as_array_mut().unwrap() {
            for (k, s) in round["samples_s"]
                .as_array_mut()
                .unwrap()
                .iter_mut()
                .enumerate()
            {
                let factor = if k % 2 == 0 { 0.8 } else { 1.5 };
                *s = (s.as_f64().unwrap() * factor).into();
            }
        }
    });
    let o = gate(&base, &current, &["--format", "json"]);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o.stderr));
    for (key, verdict) in verdicts(&o) {
        if key == first {
            assert_eq!(verdict, "unknown", "{key}");
        } else {
            assert!(
                verdict != "regressed" && verdict != "improved",
                "{key}: {verdict}"
            );
        }
    }
    let o = gate(&base, &current, &[]);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o.stderr));
    let out = text(&o.stdout);
    let named = out
        .lines()
        .find(|l| l.starts_with("unknown: "))
        .unwrap_or_default();
    assert!(named.contains(&first), "{out}");
    assert!(named.contains("gate --against"), "{out}");
}

#[test]
fn the_committed_baseline_passes_against_itself() {
    let _serial = serial();
    let base = committed_baseline();
    let o = gate(&base, &base, &[]);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o.stderr));
    let out = text(&o.stdout);
    assert!(out.starts_with("gate ok: "), "{out}");
    assert!(out.contains(" 0 regressed, 0 improved"), "{out}");
}

#[test]
fn bad_input_exits_2_with_a_message() {
    let _serial = serial();
    let dir = tempfile::tempdir().unwrap();
    let base = committed_baseline();

    let full = std::fs::read_to_string(&base).unwrap();
    let truncated = dir.path().join("truncated.json");
    std::fs::write(&truncated, &full[..full.len() / 2]).unwrap();
    assert_bad_input(&gate(&base, &truncated, &[]), "may be truncated");

    let schema = edited(dir.path(), "schema.json", |v| {
        v["schema"] = "nbody-bench/results/v0".into()
    });
    assert_bad_input(
        &gate(&schema, &base, &[]),
        "has schema `nbody-bench/results/v0`",
    );

    let other_machine = edited(dir.path(), "machine.json", |v| {
        v["calibration"]["start"]["cpu_model"] = "Some Other CPU".into();
        v["calibration"]["end"]["cpu_model"] = "Some Other CPU".into();
    });
    assert_bad_input(
        &gate(&other_machine, &base, &[]),
        "the baseline comes from another machine: CPU model `Some Other CPU` there",
    );
    let forced = gate(&other_machine, &base, &["--force"]);
    assert_eq!(forced.status.code(), Some(0), "{}", text(&forced.stderr));
    assert!(
        text(&forced.stdout).contains("warning: forced: the baseline comes from another machine")
    );

    let other_cpus = edited(dir.path(), "cpus.json", |v| {
        v["calibration"]["start"]["logical_cpus"] = 64.into();
    });
    assert_bad_input(
        &gate(&other_cpus, &base, &[]),
        "logical CPU count `64` there",
    );

    let other_config = edited(dir.path(), "config.json", |v| {
        v["config"]["measure"]["samples"] = 99.into();
    });
    assert_bad_input(
        &gate(&other_config, &base, &[]),
        "different configs (they differ in measure.samples)",
    );

    let missing = edited(dir.path(), "missing.json", |v| {
        v["cases"].as_array_mut().unwrap().remove(0);
    });
    let o = gate(&base, &missing, &[]);
    assert_bad_input(&o, "1 baseline case(s) could not be compared");
    assert!(
        text(&o.stdout)
            .contains("missing: lj-box/naive/n=2000/p=1/r=1/seed=1 (not in the current results)")
    );

    assert_bad_input(
        &gate(&base, &dir.path().join("nope.json"), &[]),
        "no results for",
    );
    let empty = edited(dir.path(), "empty.json", |v| {
        v["cases"] = serde_json::Value::Array(Vec::new());
    });
    assert_bad_input(&gate(&empty, &empty, &[]), "compared no case");
    assert_bad_input(
        &gate(&base, &base, &["--threshold", "-1"]),
        "must be 0 or greater",
    );
    assert_bad_input(
        &gate(&base, &base, &["--threshold", "x"]),
        "is not a number",
    );
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

/// A git repository whose HEAD's base build is this very binary, put in the gate's cache, so
/// that an A/B run of HEAD measures the same build on both sides without compiling it again.
fn same_tree_repo() -> (tempfile::TempDir, PathBuf) {
    let dir = tempfile::tempdir().unwrap();
    git(dir.path(), &["init", "-q"]);
    std::fs::write(dir.path().join("gate-tiny.toml"), TINY).unwrap();
    git(dir.path(), &["add", "-A"]);
    git(dir.path(), &["commit", "-q", "-m", "tiny"]);
    let head = git(dir.path(), &["rev-parse", "HEAD"]);
    let target = dir.path().join("target");
    let cached = target
        .join("gate-base")
        .join(nbody_harness::gate::base_build::cache_key(&head));
    std::fs::create_dir_all(&cached).unwrap();
    std::fs::copy(
        env!("CARGO_BIN_EXE_nbody-bench"),
        cached.join("nbody-bench"),
    )
    .unwrap();
    (dir, target)
}

fn a_b(
    dir: &Path,
    target: &Path,
    rev: &str,
    out: &str,
    slowdown: Option<&str>,
    extra: &[&str],
) -> Output {
    let mut cmd = bin();
    cmd.current_dir(dir)
        .env("CARGO_TARGET_DIR", target)
        .args([
            "gate",
            "--against",
            rev,
            "--config",
            "gate-tiny.toml",
            "--rounds",
            "2",
        ])
        .args(["--out", out, "--format", "json"])
        .args(extra);
    if let Some(knob) = slowdown {
        cmd.env("NBODY_BENCH_TEST_SLOWDOWN", knob);
    }
    cmd.output().unwrap()
}

/// How the A/B run's builds shared the machine, from its JSON report.
fn sides(out: &Output) -> String {
    let report: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    report["sides"].as_str().unwrap_or_default().to_string()
}

/// One test, so that its A/B runs never overlap.
#[test]
fn a_b_against_the_same_tree_passes_and_a_slower_current_side_fails() {
    let _serial = serial();
    let (repo, target) = same_tree_repo();
    let same = a_b(
        repo.path(),
        &target,
        "HEAD",
        "same",
        None,
        &["--threshold", "0.75", "--sides", "turns"],
    );
    assert_eq!(same.status.code(), Some(0), "{}", text(&same.stderr));
    assert_eq!(sides(&same), "turns");
    assert!(verdicts(&same).iter().all(|(_, v)| v == "unchanged"));
    assert_eq!(verdicts(&same).len(), 3);
    for kept in ["base.json", "current.json", "gate.json"] {
        assert!(repo.path().join("same").join(kept).is_file(), "{kept}");
    }
    let left: Vec<_> = std::fs::read_dir(repo.path().join("same"))
        .unwrap()
        .flatten()
        .filter(|e| e.file_name().to_string_lossy().starts_with(".scratch"))
        .collect();
    assert!(left.is_empty(), "scratch removed");
    // What a gate kept is never overwritten.
    let again = a_b(repo.path(), &target, "HEAD", "same", None, &[]);
    assert_bad_input(&again, "is there from an earlier gate run");

    // The slower current side is the test-only slowdown knob (the `test-slowdown` feature).
    #[cfg(feature = "test-slowdown")]
    {
        let slow = a_b(
            repo.path(),
            &target,
            "HEAD",
            "slow",
            Some("symmetric:5"),
            &["--threshold", "0.75", "--sides", "duet"],
        );
        assert_eq!(slow.status.code(), Some(1), "{}", text(&slow.stderr));
        // Both builds at once wherever this process may use two CPUs.
        let two = nbody_harness::gate::duet::cpus().is_some();
        assert_eq!(sides(&slow), if two { "duet" } else { "turns" });
        for (key, verdict) in verdicts(&slow) {
            let expected = if key.contains("/symmetric/") {
                "regressed"
            } else {
                "unchanged"
            };
            assert_eq!(verdict, expected, "{key}");
        }
    }

    let missing = a_b(
        repo.path(),
        &target,
        "0123456789abcdef0123",
        "missing",
        None,
        &[],
    );
    assert_bad_input(&missing, "is not in this clone");
}

#[test]
fn a_base_revision_is_built_once_and_a_broken_one_is_refused() {
    use nbody_harness::gate::base_build::{base_binary, cache_root};
    let dir = tempfile::tempdir().unwrap();
    let repo = dir.path();
    git(repo, &["init", "-q"]);
    std::fs::create_dir(repo.join("src")).unwrap();
    std::fs::write(
        repo.join("Cargo.toml"),
        "[package]\nname = \"nbody-bench\"\nversion = \"0.0.0\"\nedition = \"2021\"\n",
    )
    .unwrap();
    std::fs::write(repo.join("src/main.rs"), "fn main() {}\n").unwrap();
    git(repo, &["add", "-A"]);
    git(repo, &["commit", "-q", "-m", "builds"]);
    let good = git(repo, &["rev-parse", "HEAD"]);
    std::fs::write(repo.join("src/main.rs"), "fn main() { not rust }\n").unwrap();
    git(repo, &["commit", "-q", "-am", "broken"]);
    let broken = git(repo, &["rev-parse", "HEAD"]);

    let mut quiet = |_: &str| {};
    let first = base_binary(repo, &good, &mut quiet).unwrap();
    assert!(first.built && first.path.is_file());
    assert!(first.path.starts_with(cache_root(repo)));
    let again = base_binary(repo, &good, &mut quiet).unwrap();
    assert!(!again.built, "taken from the cache");
    assert_eq!(again.path, first.path);
    let err = base_binary(repo, &broken, &mut quiet)
        .unwrap_err()
        .to_string();
    assert!(err.contains("does not build"), "{err}");
    assert!(
        err.contains("error"),
        "the compiler's message is shown: {err}"
    );
    // No worktree is left behind either way.
    let worktrees = git(repo, &["worktree", "list"]);
    assert_eq!(worktrees.lines().count(), 1, "{worktrees}");
}

/// A folder of baselines: the gate takes the file of the current run's machine class, whatever
/// its name; `--save-baseline` files a run under its class's name; an empty folder or a corrupt
/// file in it is an error.
#[test]
fn a_folder_of_baselines_gives_each_machine_class_its_own() {
    let _serial = serial();
    let dir = tempfile::tempdir().unwrap();
    let folder = dir.path().join("baseline");
    std::fs::create_dir(&folder).unwrap();
    let base = committed_baseline();
    let signature = |path: &Path| {
        let v: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap();
        v["calibration"]["start"]["cpu_signature"]
            .as_str()
            .unwrap()
            .to_string()
    };
    let here = signature(&base);
    // Another class's baseline, and newer: chosen, the gate would refuse it (another machine).
    let other = edited(dir.path(), "other.json", |v| {
        for side in ["start", "end"] {
            v["calibration"][side]["cpu_signature"] = "OtherVendor 1/2/3".into();
        }
        v["metadata"]["started"] = "2999-01-01T00:00:00Z".into();
    });
    std::fs::copy(&other, folder.join("a-other.json")).unwrap();
    std::fs::copy(&base, folder.join("z-mine.json")).unwrap();
    let o = gate(&folder, &base, &["--format", "json"]);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o.stderr));
    let report: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(report["baseline"]["cpu_signature"], here.as_str());

    // Filed under the class's own name, beside the other class's file.
    let save = |results: &Path| {
        bin()
            .args(["gate", "--baseline"])
            .arg(&folder)
            .arg("--save-baseline")
            .arg(results)
            .output()
            .unwrap()
    };
    let saved = save(&base);
    assert_eq!(saved.status.code(), Some(0), "{}", text(&saved.stderr));
    let slug: String = here
        .chars()
        .map(|c| if c.is_ascii_alphanumeric() { c } else { '-' })
        .collect();
    let filed = std::fs::read_dir(&folder)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .find(|name| name.starts_with(&format!("ci-{slug}-")))
        .unwrap_or_else(|| panic!("no ci-{slug}-*.json in the folder"));
    assert_eq!(signature(&folder.join(&filed)), here);
    assert!(folder.join("a-other.json").is_file());

    // A run measured on a busy machine is not filed, and the class's file stays as it was.
    let before = std::fs::read(folder.join(&filed)).unwrap();
    let busy = edited(dir.path(), "busy.json", |v| {
        v["calibration"]["end"]["background_cpus"] = 0.6.into();
    });
    assert_bad_input(&save(&busy), "other processes used 0.60 CPUs");
    assert_eq!(std::fs::read(folder.join(&filed)).unwrap(), before);

    std::fs::write(folder.join("broken.json"), "{").unwrap();
    assert_bad_input(&gate(&folder, &base, &[]), "broken.json");
    let empty = dir.path().join("empty");
    std::fs::create_dir(&empty).unwrap();
    assert_bad_input(&gate(&empty, &base, &[]), "holds no .json results file");
}

/// A baseline of this machine class that this build cannot reproduce (here: a key it does not
/// know) is never a refusal: the gate says why in one line and measures the baseline's commit
/// and this build side by side, sweeping configs/ci.toml with both.
#[test]
fn a_stale_baseline_of_this_class_takes_a_b_with_a_notice() {
    let _serial = serial();
    let (repo, target) = same_tree_repo();
    let head = git(repo.path(), &["rev-parse", "HEAD"]);
    std::fs::create_dir_all(repo.path().join("configs")).unwrap();
    std::fs::write(repo.path().join("configs/ci.toml"), TINY).unwrap();
    let folder = repo.path().join("baseline");
    std::fs::create_dir(&folder).unwrap();
    let stale = edited(&folder, "stale.json", |v| {
        v["metadata"]["git_commit"] = head.clone().into();
        v["config"]["retired_key"] = 1.into();
        for side in ["start", "end"] {
            let c = &mut v["calibration"][side];
            c["cpu_model"] = nbody_calibrate::cpu_model().into();
            c["cpu_signature"] = nbody_calibrate::cpu_signature().into();
            c["logical_cpus"] = nbody_engine::run::logical_cpus().into();
        }
    });
    assert!(stale.starts_with(&folder));
    let o = bin()
        .current_dir(repo.path())
        .env("CARGO_TARGET_DIR", &target)
        .args(["gate", "--baseline", "baseline", "--rounds", "2"])
        .args(["--out", "stale", "--format", "json", "--threshold", "0.75"])
        .output()
        .unwrap();
    let err = text(&o.stderr);
    assert_eq!(o.status.code(), Some(0), "{err}");
    assert!(err.contains("cannot be reproduced by this build"), "{err}");
    assert!(err.contains("retired_key"), "{err}");
    assert!(err.contains("A/B"), "{err}");
    assert_eq!(verdicts(&o).len(), 3, "TINY's three cases, by both builds");
}
