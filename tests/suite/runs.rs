//! Where sweeps write and read: the README's main job in a fresh copy of the repository works
//! twice and leaves every tracked file as it was; configs are found by bare name; a missing
//! config lists where it was looked for.

use std::path::Path;
use std::process::{Command, Output};

fn bin(dir: &Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_nbody-bench"))
        .current_dir(dir)
        .args(args)
        .env_remove("NBODY_BENCH_TEST_SLOWDOWN")
        .stdin(std::process::Stdio::null())
        .output()
        .expect("binary runs")
}

fn text(bytes: &[u8]) -> String {
    String::from_utf8_lossy(bytes).into_owned()
}

fn git(dir: &Path, args: &[&str]) -> String {
    let o = Command::new("git")
        .current_dir(dir)
        .args(args)
        .output()
        .expect("git runs");
    assert!(o.status.success(), "git {args:?}: {}", text(&o.stderr));
    text(&o.stdout)
}

/// A fresh repository holding the tracked files of this checkout as they are now, committed.
fn fresh_copy() -> tempfile::TempDir {
    let here = Path::new(env!("CARGO_MANIFEST_DIR"));
    let copy = tempfile::tempdir().unwrap();
    for file in git(here, &["ls-files", "-z"])
        .split('\0')
        .filter(|f| !f.is_empty())
    {
        let from = here.join(file);
        if !from.is_file() {
            continue; // deleted in the working tree
        }
        let to = copy.path().join(file);
        std::fs::create_dir_all(to.parent().unwrap()).unwrap();
        std::fs::copy(&from, &to).unwrap();
    }
    git(copy.path(), &["init", "-q"]);
    git(copy.path(), &["add", "-A"]);
    git(
        copy.path(),
        &[
            "-c",
            "user.name=test",
            "-c",
            "user.email=test@localhost",
            "commit",
            "-q",
            "-m",
            "copy",
        ],
    );
    copy
}

#[test]
fn the_main_job_runs_twice_and_leaves_tracked_files_alone() {
    let repo = fresh_copy();
    let mut results = Vec::new();
    for attempt in 1..=2 {
        let o = bin(repo.path(), &["sweep", "--config", "configs/quick.toml"]);
        assert!(
            o.status.success(),
            "attempt {attempt}: {}{}",
            text(&o.stdout),
            text(&o.stderr)
        );
        let out = text(&o.stdout);
        let line = out
            .lines()
            .find(|l| l.contains("results in "))
            .expect("the sweep says where its results are");
        let path = line
            .rsplit("results in ")
            .next()
            .unwrap()
            .trim()
            .to_string();
        assert!(path.starts_with("results/runs/quick/"), "{path}");
        assert!(repo.path().join(&path).is_file(), "{path}");
        results.push(path);
    }
    assert_ne!(results[0], results[1], "each run has its own directory");
    let status = git(repo.path(), &["status", "--porcelain"]);
    assert!(status.is_empty(), "tracked files changed:\n{status}");
    // analyze finds the latest run by the config's name.
    let o = bin(repo.path(), &["analyze", "quick"]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    assert!(text(&o.stderr).contains(&results[1]), "{}", text(&o.stderr));
}

const TINY: &str = r#"
name = "tiny"
study = "cartesian"
scenarios = ["lj-box"]
kernels = ["naive"]
n = [50]

[measure]
warmup_s = 0.0
samples = 2
rounds = 2
min_sample_s = 0.0
"#;

/// A directory holding `configs/tiny.toml`.
fn with_tiny_config() -> tempfile::TempDir {
    let dir = tempfile::tempdir().unwrap();
    std::fs::create_dir(dir.path().join("configs")).unwrap();
    std::fs::write(dir.path().join("configs/tiny.toml"), TINY).unwrap();
    dir
}

#[test]
fn configs_are_found_by_bare_name() {
    let dir = with_tiny_config();
    for name in ["tiny", "tiny.toml", "configs/tiny.toml"] {
        let o = bin(dir.path(), &["sweep", "--config", name, "--no-calibration"]);
        assert!(o.status.success(), "{name}: {}", text(&o.stderr));
        assert!(
            text(&o.stdout).contains("results in results/runs/tiny/"),
            "{name}"
        );
    }
}

#[test]
fn a_dry_run_creates_no_run_directory() {
    let dir = with_tiny_config();
    let o = bin(dir.path(), &["sweep", "--config", "tiny", "--dry-run"]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    assert!(
        text(&o.stdout).contains("a new run directory results/runs/tiny/"),
        "{}",
        text(&o.stdout)
    );
    assert!(!dir.path().join("results").exists(), "nothing written");
}

#[test]
fn a_missing_config_lists_the_places_looked_and_the_configs() {
    let dir = with_tiny_config();
    let o = bin(dir.path(), &["sweep", "--config", "strong"]);
    assert_eq!(o.status.code(), Some(2));
    let err = text(&o.stderr);
    for part in [
        "no config `strong`",
        "configs/strong",
        "configs/strong.toml",
        "tiny",
    ] {
        assert!(err.contains(part), "{part}: {err}");
    }
    assert!(!err.contains("panicked"), "{err}");
    assert!(!dir.path().join("results").exists(), "nothing written");
}

#[test]
fn no_error_repeats_its_cause() {
    let dir = tempfile::tempdir().unwrap();
    let o = bin(dir.path(), &["sweep", "--config", "./absent.toml"]);
    assert_eq!(o.status.code(), Some(2));
    let err = text(&o.stderr);
    assert_eq!(err.matches("No such file").count(), 0, "{err}");
    let o = bin(dir.path(), &["analyze", "absent.json"]);
    assert_eq!(o.status.code(), Some(2));
    let err = text(&o.stderr);
    assert!(err.matches("absent.json").count() >= 1, "{err}");
    let o = bin(
        dir.path(),
        &["gate", "--baseline", "absent.json", "--current", "b.json"],
    );
    let err = text(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(
        err.matches("No such file or directory").count() <= 1,
        "{err}"
    );
}

#[test]
fn resume_continues_the_latest_unfinished_run() {
    let dir = with_tiny_config();
    let o = bin(dir.path(), &["sweep", "--config", "tiny", "--resume"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(
        text(&o.stderr).contains("no unfinished run of `tiny`"),
        "{}",
        text(&o.stderr)
    );
    // A run cut short by the budget is unfinished.
    let budget = TINY.replace("min_sample_s = 0.0", "min_sample_s = 0.0\nbudget_s = 1e-9");
    std::fs::write(dir.path().join("configs/tiny.toml"), &budget).unwrap();
    let o = bin(
        dir.path(),
        &["sweep", "--config", "tiny", "--no-calibration"],
    );
    assert!(o.status.success(), "{}", text(&o.stderr));
    let o = bin(
        dir.path(),
        &["sweep", "--config", "tiny", "--resume", "--no-calibration"],
    );
    assert!(o.status.success(), "{}", text(&o.stderr));
    assert!(
        text(&o.stderr).contains("resuming results/runs/tiny/"),
        "{}",
        text(&o.stderr)
    );
    let runs: Vec<_> = std::fs::read_dir(dir.path().join("results/runs/tiny"))
        .unwrap()
        .collect();
    assert_eq!(runs.len(), 1, "resumed in place, no new run");
}
