//! The `gate` command end to end: real tiny sweeps of the same code pass, a kernel made
//! genuinely slower (the test-only slowdown knob) is flagged alone with exit 1, and bad input
//! (truncated or wrong-schema JSON, another machine, missing cases) exits 2 with a message.

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

/// One test, so that the sweeps never run at the same time as each other.
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
    let warnings = report["warnings"].as_array().unwrap();
    assert!(
        warnings
            .iter()
            .any(|w| w.as_str().unwrap().contains("slowdown knob (symmetric:5)")),
        "{report}"
    );
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
    assert!(
        md.starts_with("### Performance gate: regression found"),
        "{md}"
    );
    assert!(
        md.contains("| `lj-box/symmetric/n=1000/p=1/r=1/seed=1` |"),
        "{md}"
    );
}

/// The committed baseline: a real results file of this machine class.
fn committed_baseline() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("results/baseline/ci.json")
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
        "cannot read",
    );
    assert_bad_input(
        &gate(&base, &base, &["--threshold", "-1"]),
        "must be 0 or greater",
    );
    assert_bad_input(
        &gate(&base, &base, &["--threshold", "x"]),
        "is not a number",
    );
}
