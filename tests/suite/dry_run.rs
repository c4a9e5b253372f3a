//! `sweep --dry-run` (every planned case and an estimate, nothing written), the estimate
//! against a real sweep's wall time, and the guard that refuses a sweep of hours without
//! `--yes` when there is no terminal to ask.

use nbody_records::config::SweepConfig;
use nbody_records::plan::cases;
use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};
use std::sync::Mutex;
use std::time::{Instant, SystemTime};

/// One test at a time: the timing test must not share the CPUs with the others' probes.
static SERIAL: Mutex<()> = Mutex::new(());

fn serial() -> std::sync::MutexGuard<'static, ()> {
    SERIAL.lock().unwrap_or_else(|e| e.into_inner())
}

fn bin(args: &[&str], cwd: &Path) -> Output {
    Command::new(env!("CARGO_BIN_EXE_nbody-bench"))
        .args(args)
        .current_dir(cwd)
        .stdin(Stdio::null())
        .output()
        .expect("binary runs")
}

fn text(bytes: &[u8]) -> String {
    String::from_utf8_lossy(bytes).into_owned()
}

fn crate_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn quick() -> PathBuf {
    crate_dir().join("configs/quick.toml")
}

/// The `estimate_s:` line of a dry run.
fn estimate_s(stdout: &str) -> f64 {
    stdout
        .lines()
        .find_map(|l| l.strip_prefix("estimate_s: "))
        .and_then(|v| v.trim().parse().ok())
        .unwrap_or_else(|| panic!("no estimate_s line in:\n{stdout}"))
}

/// Every file under `dir` with its size and modification time.
fn snapshot(dir: &Path) -> Vec<(PathBuf, u64, Option<SystemTime>)> {
    let mut out = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for entry in std::fs::read_dir(&d).unwrap() {
            let entry = entry.unwrap();
            let meta = entry.metadata().unwrap();
            if meta.is_dir() {
                stack.push(entry.path());
            }
            out.push((entry.path(), meta.len(), meta.modified().ok()));
        }
    }
    out.sort();
    out
}

fn entries(dir: &Path) -> usize {
    std::fs::read_dir(dir).unwrap().count()
}

#[test]
fn help_names_both_flags() {
    let _serial = serial();
    let o = bin(&["sweep", "--help"], &crate_dir());
    assert!(o.status.success());
    let help = text(&o.stdout);
    assert!(
        help.contains("--dry-run") && help.contains("--yes"),
        "{help}"
    );
}

#[test]
fn dry_run_plans_every_case_and_writes_nothing() {
    let _serial = serial();
    let (config, _) = SweepConfig::load(&quick()).unwrap();
    let out = tempfile::tempdir().unwrap();
    let cwd = tempfile::tempdir().unwrap();
    let target = out.path().join("sweeps");
    let quick = quick();
    let args = [
        "sweep",
        "--config",
        quick.to_str().unwrap(),
        "--dry-run",
        "--out",
        target.to_str().unwrap(),
    ];
    let o = bin(&args, cwd.path());
    let stdout = text(&o.stdout);
    assert!(o.status.success(), "{}", text(&o.stderr));
    for case in cases(&config) {
        assert!(
            stdout.contains(&case.key()),
            "{} missing:\n{stdout}",
            case.key()
        );
    }
    assert!(stdout.contains("probe took") && stdout.contains("estimated wall time"));
    assert!(estimate_s(&stdout) > 0.0);
    assert_eq!(entries(out.path()), 0, "the dry run wrote into --out");
    assert_eq!(
        entries(cwd.path()),
        0,
        "the dry run wrote into its directory"
    );

    // An existing results file is no obstacle, and is left as it was.
    let existing = target.join("quick/results.json");
    std::fs::create_dir_all(existing.parent().unwrap()).unwrap();
    std::fs::write(&existing, "not a results file").unwrap();
    let before = snapshot(out.path());
    let o = bin(&args, cwd.path());
    assert!(o.status.success(), "{}", text(&o.stderr));
    assert!(text(&o.stdout).contains("exists: a real run needs --resume or --fresh"));
    assert_eq!(snapshot(out.path()), before);

    // Without --out, from the crate: the config's results/ is not touched.
    let results = crate_dir().join("results");
    let before = snapshot(&results);
    let o = bin(
        &["sweep", "--config", "configs/quick.toml", "--dry-run"],
        &crate_dir(),
    );
    assert!(o.status.success(), "{}", text(&o.stderr));
    assert_eq!(snapshot(&results), before, "the dry run changed results/");
}

#[test]
fn the_estimate_is_within_a_factor_of_three_of_the_sweep() {
    let _serial = serial();
    let out = tempfile::tempdir().unwrap();
    let dir = out.path().to_str().unwrap();
    let config = quick();
    let config = config.to_str().unwrap();
    let dry = bin(
        &["sweep", "--config", config, "--dry-run", "--out", dir],
        &crate_dir(),
    );
    assert!(dry.status.success(), "{}", text(&dry.stderr));
    let estimate = estimate_s(&text(&dry.stdout));
    let start = Instant::now();
    let real = bin(&["sweep", "--config", config, "--out", dir], &crate_dir());
    let measured = start.elapsed().as_secs_f64();
    assert!(real.status.success(), "{}", text(&real.stderr));
    assert!(out.path().join("quick/results.json").exists());
    eprintln!("quick sweep: estimated {estimate:.2} s, measured {measured:.2} s");
    let ratio = estimate / measured;
    assert!(
        (1.0 / 3.0..=3.0).contains(&ratio),
        "estimated {estimate:.2} s, measured {measured:.2} s"
    );
}

#[test]
fn a_sweep_of_hours_needs_yes_without_a_terminal() {
    let _serial = serial();
    let dir = tempfile::tempdir().unwrap();
    let config = dir.path().join("huge.toml");
    std::fs::write(
        &config,
        "name = \"huge\"\nstudy = \"cartesian\"\nscenarios = [\"lj-box\"]\n\
         kernels = [\"naive\"]\nn = [10000000]\n",
    )
    .unwrap();
    let out = dir.path().join("out");
    let args = [
        "sweep",
        "--config",
        config.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ];
    let start = Instant::now();
    let o = bin(&args, dir.path());
    assert!(
        start.elapsed().as_secs_f64() < 30.0,
        "it measured something"
    );
    let stderr = text(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{stderr}");
    assert!(stderr.contains("estimate_s: "), "{stderr}");
    assert!(
        stderr.contains("--yes") && stderr.contains("budget_s"),
        "{stderr}"
    );
    assert!(!out.exists(), "a refused sweep created {}", out.display());
    // The dry run of the same sweep says so, and succeeds.
    let mut dry = args.to_vec();
    dry.push("--dry-run");
    let o = bin(&dry, dir.path());
    assert!(o.status.success(), "{}", text(&o.stderr));
    let stdout = text(&o.stdout);
    assert!(estimate_s(&stdout) > 3600.0, "{stdout}");
    assert!(stdout.contains("more than an hour"), "{stdout}");
    assert!(!out.exists());
}
