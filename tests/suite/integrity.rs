//! Nothing measured is lost or misreported, through the binary: impossible values are failed
//! samples and the file stays readable; one writer per results file, backups never replaced;
//! outputs never replace inputs or escape through links and devices; duplicated keys, failed
//! cases, unsupported fits, the wrong run to resume and a weak study's `n` are refused.

use crate::{bin, refused};
use nbody_records::results::ResultsFile;
use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

fn run(args: &[&str], dir: &Path) -> Output {
    bin().args(args).current_dir(dir).output().unwrap()
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// A sweep of one tiny built-in case and the given `[[external]]` entries.
fn config(dir: &Path, externals: &str) -> PathBuf {
    let path = dir.join("c.toml");
    std::fs::write(
        &path,
        format!(
            "name = \"c\"\nstudy = \"cartesian\"\nscenarios = [\"lj-box\"]\nkernels = \
             [\"naive\"]\nn = [40]\n{externals}\n[measure]\nsamples = 2\nrounds = 2\n\
             warmup_s = 0.0\nmin_sample_s = 0.0\n"
        ),
    )
    .unwrap();
    path
}

fn sweep(dir: &Path, extra: &[&str]) -> Output {
    let mut args = vec![
        "sweep",
        "--config",
        "c.toml",
        "--out",
        "out",
        "--no-calibration",
    ];
    args.extend_from_slice(extra);
    run(&args, dir)
}

const IMPOSSIBLE: &str = r#"
[[external]]
name = "nan-error"
command = ["sh", "-c", "echo 'err median nan max nan'"]
steps = 1
time = "wall"
force_error = 'err median (\S+) max (\S+)'

[[external]]
name = "huge-time"
command = ["sh", "-c", "echo 'took 1e308 s'"]
steps = 10
time = { regex = 'took (\S+) s', unit = "s" }

[[external]]
name = "zero-time"
command = ["sh", "-c", "echo 'took 0 s'"]
steps = 1
time = { regex = 'took (\S+) s', unit = "s" }
"#;

#[test]
fn impossible_values_are_failed_samples_and_the_file_stays_readable() {
    let dir = tempfile::tempdir().unwrap();
    config(dir.path(), IMPOSSIBLE);
    let o = sweep(dir.path(), &[]);
    let err = stderr(&o);
    assert_eq!(
        o.status.code(),
        Some(1),
        "failed cases fail the sweep: {err}"
    );
    assert!(err.contains("3 of 4 cases failed"), "{err}");
    let out = String::from_utf8_lossy(&o.stdout);
    assert!(out.contains("FAILED: no sample succeeded"), "{out}");
    assert!(
        !out.contains("0.00 ns"),
        "a failed case shows no time: {out}"
    );
    let path = dir.path().join("out/c/results.json");
    // NaN and infinity would be written as null: inside a list of numbers there is none.
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap();
    assert!(!null_in_a_list(&json), "nothing non-finite is written");
    let r = ResultsFile::load(&path).unwrap();
    let case = |code: &str| {
        r.cases
            .iter()
            .find(|c| c.key.contains(&format!("/{code}/")))
            .unwrap()
    };
    assert!(case("naive").summary.is_some());
    for (code, why) in [
        ("nan-error", "not a finite number"),
        ("huge-time", "a unit or parsing error"),
        ("zero-time", "not a duration"),
    ] {
        let c = case(code);
        assert!(c.failed(), "{code}");
        assert!(
            c.failures().iter().any(|f| f.contains(why)),
            "{code}: {:?}",
            c.failures()
        );
    }
    // Every reader still takes the file: resume (nothing left to do), analyze.
    let o = sweep(dir.path(), &["--resume"]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    let o = run(&["analyze", "out/c/results.json"], dir.path());
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
}

fn null_in_a_list(v: &serde_json::Value) -> bool {
    match v {
        serde_json::Value::Array(items) => items.iter().any(|i| i.is_null() || null_in_a_list(i)),
        serde_json::Value::Object(map) => map.values().any(null_in_a_list),
        _ => false,
    }
}

#[test]
fn stored_summaries_are_recomputed_from_the_raw_samples() {
    let dir = tempfile::tempdir().unwrap();
    config(dir.path(), "");
    assert_eq!(sweep(dir.path(), &[]).status.code(), Some(0));
    let path = dir.path().join("out/c/results.json");
    let mut json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap();
    let case = &mut json["cases"][0];
    let stored = case["summary"]["median_s"].as_f64().unwrap();
    let rounds = case["rounds"].as_array_mut().unwrap();
    rounds[0]["samples_s"] = serde_json::json!([-1.0, 0.0]);
    let kept: Vec<f64> = rounds[1]["samples_s"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_f64().unwrap())
        .collect();
    let edited = dir.path().join("edited.json");
    std::fs::write(&edited, json.to_string()).unwrap();
    let r = ResultsFile::load(&edited).unwrap();
    let c = &r.cases[0];
    let s = c.summary.as_ref().unwrap();
    assert_eq!(s.samples, kept.len(), "the impossible samples are out");
    assert_eq!(
        s.median_s,
        nbody_engine::stats::median(&kept).unwrap(),
        "stored {stored}"
    );
    assert_eq!(c.rejected.len(), 2);
    // All samples impossible: the case is failed, whatever its stored summary says.
    let rounds = json["cases"][0]["rounds"].as_array_mut().unwrap();
    rounds[1]["samples_s"] = serde_json::json!([-3.0]);
    std::fs::write(&edited, json.to_string()).unwrap();
    assert!(ResultsFile::load(&edited).unwrap().cases[0].failed());
}

/// Waits until `path` exists (or `limit` passes).
fn wait_for(path: &Path, limit: Duration) -> bool {
    let start = Instant::now();
    while start.elapsed() < limit {
        if path.exists() {
            return true;
        }
        std::thread::sleep(Duration::from_millis(20));
    }
    false
}

const SLOW: &str = r#"
[[external]]
name = "slow"
command = ["sleep", "0.4"]
steps = 1
time = "wall"
"#;

#[test]
fn a_results_file_has_one_writer_and_backups_are_never_replaced() {
    let dir = tempfile::tempdir().unwrap();
    config(dir.path(), SLOW);
    let mut first = bin()
        .args([
            "sweep",
            "--config",
            "c.toml",
            "--out",
            "out",
            "--no-calibration",
        ])
        .current_dir(dir.path())
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let lock = dir.path().join("out/c/.results.json.lock");
    assert!(wait_for(&lock, Duration::from_secs(60)), "the sweep locks");
    let second = sweep(dir.path(), &["--fresh"]);
    refused(&second, "being written by another sweep");
    assert!(stderr(&second).contains("pid "), "{}", stderr(&second));
    let resume = sweep(dir.path(), &["--resume"]);
    refused(&resume, "being written by another sweep");
    assert!(first.wait().unwrap().success());
    assert!(!lock.exists(), "the lock goes with the sweep");
    let path = dir.path().join("out/c/results.json");
    let r = ResultsFile::load(&path).unwrap();
    assert!(
        r.cases
            .iter()
            .all(|c| c.is_complete() && c.rounds.len() == 2)
    );
    let original = std::fs::read(&path).unwrap();
    // Twice in the same second: two backups, the original kept.
    for _ in 0..2 {
        let o = sweep(dir.path(), &["--fresh"]);
        assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    }
    let backups: Vec<PathBuf> = std::fs::read_dir(dir.path().join("out/c"))
        .unwrap()
        .flatten()
        .map(|e| e.path())
        .filter(|p| p.to_string_lossy().ends_with(".bak"))
        .collect();
    assert_eq!(backups.len(), 2, "{backups:?}");
    assert!(
        backups
            .iter()
            .any(|b| std::fs::read(b).unwrap() == original)
    );
}

#[test]
fn outputs_never_replace_inputs_links_or_devices() {
    let dir = tempfile::tempdir().unwrap();
    config(dir.path(), "");
    assert_eq!(sweep(dir.path(), &[]).status.code(), Some(0));
    // A results file named fits.json, analysed into its own directory.
    let x = dir.path().join("x");
    std::fs::create_dir(&x).unwrap();
    let input = x.join("fits.json");
    std::fs::copy(dir.path().join("out/c/results.json"), &input).unwrap();
    let before = std::fs::read(&input).unwrap();
    let o = run(&["analyze", "x/fits.json", "--out", "x"], dir.path());
    refused(&o, "also an input");
    assert_eq!(std::fs::read(&input).unwrap(), before);
    assert_eq!(std::fs::read_dir(&x).unwrap().count(), 1, "nothing written");
    // Links that lead nowhere stay links.
    std::fs::write(dir.path().join("t.csv"), "n,time\n10,1\n20,2\n40,4\n80,8\n").unwrap();
    std::os::unix::fs::symlink("missing/target.json", dir.path().join("dangling")).unwrap();
    std::os::unix::fs::symlink("loop-b", dir.path().join("loop-a")).unwrap();
    std::os::unix::fs::symlink("loop-a", dir.path().join("loop-b")).unwrap();
    for link in ["dangling", "loop-a"] {
        let o = run(
            &["fit", "--model", "power", "--csv", "t.csv", "--json", link],
            dir.path(),
        );
        refused(&o, "symbolic link that leads nowhere");
        let meta = std::fs::symlink_metadata(dir.path().join(link)).unwrap();
        assert!(meta.file_type().is_symlink(), "{link}");
    }
    // A device or pipe typed as the prefix of every scenario's dump.
    let fifo = dir.path().join("pipe");
    assert!(
        Command::new("mkfifo")
            .arg(&fifo)
            .status()
            .unwrap()
            .success()
    );
    for typed in ["/dev/full", "pipe"] {
        let o = run(&["validate", "-n", "20", "--dump", typed], dir.path());
        refused(&o, "not a regular file");
    }
    assert!(!Path::new("/dev/full.lj-box").exists());
    assert!(!dir.path().join("pipe.lj-box").exists());
}

#[test]
fn duplicated_case_keys_are_refused_everywhere() {
    let dir = tempfile::tempdir().unwrap();
    config(dir.path(), "");
    assert_eq!(sweep(dir.path(), &[]).status.code(), Some(0));
    let path = dir.path().join("out/c/results.json");
    let mut json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap();
    let copy = json["cases"][0].clone();
    json["cases"].as_array_mut().unwrap().push(copy);
    std::fs::write(&path, json.to_string()).unwrap();
    let key = "lj-box/naive/n=40/p=1/r=1/seed=1";
    refused(&run(&["analyze", "out/c/results.json"], dir.path()), key);
    refused(&sweep(dir.path(), &["--resume"]), key);
    refused(
        &run(
            &[
                "gate",
                "--baseline",
                "out/c/results.json",
                "--current",
                "out/c/results.json",
            ],
            dir.path(),
        ),
        key,
    );
    // In a config: a value listed twice.
    let text = std::fs::read_to_string(dir.path().join("c.toml"))
        .unwrap()
        .replace("n = [40]", "n = [40, 40]");
    std::fs::write(dir.path().join("c.toml"), text).unwrap();
    let o = sweep(dir.path(), &["--dry-run"]);
    refused(&o, "lists 40 twice");
    assert!(stderr(&o).contains("`n`"), "{}", stderr(&o));
}

#[test]
fn the_run_to_resume_is_the_one_meant_or_none() {
    let dir = tempfile::tempdir().unwrap();
    config(dir.path(), "");
    let runs = dir.path().join("results/runs/c");
    // Two unfinished runs (a stop after the first save): the newest truncated.
    for stamp in ["20261201T100000Z", "20261201T110000Z"] {
        std::fs::create_dir_all(runs.join(stamp)).unwrap();
    }
    assert_eq!(sweep(dir.path(), &[]).status.code(), Some(0));
    let good = std::fs::read_to_string(dir.path().join("out/c/results.json")).unwrap();
    let mut unfinished: serde_json::Value = serde_json::from_str(&good).unwrap();
    unfinished["cases"][0]["rounds"]
        .as_array_mut()
        .unwrap()
        .truncate(1);
    unfinished["cases"][0]["rounds_done"] = 1.into();
    let unfinished = unfinished.to_string();
    std::fs::write(runs.join("20261201T100000Z/results.json"), &unfinished).unwrap();
    std::fs::write(
        runs.join("20261201T110000Z/results.json"),
        &unfinished[..unfinished.len() / 2],
    )
    .unwrap();
    let o = run(&["sweep", "--config", "c.toml", "--resume"], dir.path());
    refused(&o, "20261201T110000Z cannot be read");
    let o = run(
        &["sweep", "--config", "c.toml", "--resume", "--dry-run"],
        dir.path(),
    );
    refused(&o, "20261201T110000Z cannot be read");
    let o = run(
        &[
            "sweep",
            "--config",
            "c.toml",
            "--dry-run",
            "--resume",
            "results/runs/c/20261201T110000Z",
        ],
        dir.path(),
    );
    refused(&o, "not a valid results file");
    std::fs::write(runs.join("20261201T100000Z/other.json"), &unfinished).unwrap();
    let o = run(
        &[
            "sweep",
            "--config",
            "c.toml",
            "--resume",
            "results/runs/c/20261201T100000Z/other.json",
        ],
        dir.path(),
    );
    refused(&o, "not a run directory or its results.json");
}

#[test]
fn fits_and_plans_the_data_cannot_support_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(
        dir.path().join("falling.csv"),
        "n,time\n100,8\n200,4\n400,2.5\n800,1\n1600,0.6\n",
    )
    .unwrap();
    let o = run(
        &["fit", "--model", "power", "--csv", "falling.csv"],
        dir.path(),
    );
    refused(&o, "do not grow with n");
    std::fs::write(
        dir.path().join("w.toml"),
        "name = \"w\"\nstudy = \"weak\"\nscenarios = [\"lj-box\"]\nkernels = [\"naive\"]\n\
         n = [999]\nthreads = [1, 2]\n[weak]\nrule = \"cost-model\"\nbase_n = 100\n",
    )
    .unwrap();
    let o = run(&["sweep", "--config", "w.toml", "--dry-run"], dir.path());
    refused(&o, "does not apply to study = \"weak\"");
}
