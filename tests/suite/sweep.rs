//! The runner with a scripted clock (deterministic sample counts, resume without loss or
//! repetition) and an end-to-end sweep through the CLI.

use nbody_engine::clock::MockClock;
use nbody_harness::experiment::runner::{Silent, SweepError, SweepOptions, run_sweep};
use nbody_records::config::SweepConfig;
use nbody_records::results::{RESULTS_SCHEMA, ResultsFile};
use std::path::Path;
use std::time::Duration;

const TINY: &str = r#"
name = "mock"
study = "cartesian"
scenarios = ["lj-box", "galaxy"]
kernels = ["naive", "symmetric"]
n = [40, 70]
threads = [1, 2]

[measure]
warmup_s = 0.005
samples = 5
rounds = 2
min_sample_s = 0.0035
"#;

fn options(dir: &Path) -> SweepOptions {
    SweepOptions {
        out: Some(dir.to_path_buf()),
        ..Default::default()
    }
}

#[test]
fn mock_clock_gives_deterministic_sample_counts() {
    let dir = tempfile::tempdir().unwrap();
    let config = SweepConfig::parse(TINY, Path::new("mock.toml")).unwrap();
    // Every clock reading advances 1 ms: a timed step reads twice, so it lasts 1 ms and a
    // 3.5 ms sample takes 4 steps.
    let clock = MockClock::new(Duration::from_millis(1));
    let report = run_sweep(&config, TINY, &options(dir.path()), &clock, &mut Silent).unwrap();
    assert_eq!(
        (report.cases, report.rounds_measured, report.incomplete),
        (16, 32, 0)
    );
    let results = ResultsFile::load(&report.path).unwrap();
    assert_eq!(results.schema, RESULTS_SCHEMA);
    for c in &results.cases {
        assert_eq!(c.rounds_done, 2);
        assert_eq!(c.steps_per_sample, 4, "{}", c.key);
        let samples: Vec<usize> = c.rounds.iter().map(|r| r.samples_s.len()).collect();
        assert_eq!(samples, vec![3, 2], "{}", c.key);
        let s = c.summary.as_ref().unwrap();
        assert_eq!(s.samples, 5);
        assert!(
            (s.median_s - 1e-3).abs() < 1e-12,
            "{}: {}",
            c.key,
            s.median_s
        );
        let p50 = s.step_ns.as_ref().unwrap().p50;
        assert!((p50 as f64 / 1e6 - 1.0).abs() < 1e-3, "{}: {p50}", c.key);
        assert_eq!(s.sanity_ok, Some(true));
    }
}

#[test]
fn resume_after_interruption_repeats_nothing_and_loses_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let config = SweepConfig::parse(TINY, Path::new("mock.toml")).unwrap();
    let clock = MockClock::new(Duration::from_millis(1));
    let opts = options(dir.path());
    let first = run_sweep(&config, TINY, &opts, &clock, &mut crate::StopAfter(11)).unwrap();
    assert_eq!((first.rounds_measured, first.incomplete), (11, 16));
    let partial = ResultsFile::load(&first.path).unwrap();
    // Without --resume the existing file is refused, not overwritten.
    let refused = run_sweep(&config, TINY, &options(dir.path()), &clock, &mut Silent);
    assert!(matches!(refused, Err(SweepError::Exists(_))));
    // A different config is refused on resume.
    let other = TINY.replace("samples = 5", "samples = 6");
    let other_config = SweepConfig::parse(&other, Path::new("mock.toml")).unwrap();
    let mut resume = options(dir.path());
    resume.resume = true;
    assert!(matches!(
        run_sweep(&other_config, &other, &resume, &clock, &mut Silent),
        Err(SweepError::Mismatch { what: "config", .. })
    ));
    let second = run_sweep(&config, TINY, &resume, &clock, &mut Silent).unwrap();
    assert_eq!((second.rounds_measured, second.incomplete), (32 - 11, 0));
    let done = ResultsFile::load(&second.path).unwrap();
    for c in &done.cases {
        assert_eq!(c.rounds.len(), 2, "{} measured once per round", c.key);
        // Rounds measured before the interruption are kept as they were.
        if let Some(old) = partial.cases.iter().find(|o| o.key == c.key) {
            assert_eq!(&c.rounds[..old.rounds.len()], &old.rounds[..], "{}", c.key);
        }
    }
}

#[test]
fn sweep_cli_writes_results_with_every_documented_field() {
    let dir = tempfile::tempdir().unwrap();
    let config = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/configs/good/tiny.toml");
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_nbody-bench"))
        .args([
            "sweep",
            "--config",
            config.to_str().unwrap(),
            "--out",
            dir.path().to_str().unwrap(),
        ])
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let path = dir.path().join("tiny/results.json");
    let results = ResultsFile::load(&path).unwrap();
    assert_eq!(results.cases.len(), 16);
    let v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap();
    for p in [
        "/schema",
        "/metadata/tool_version",
        "/metadata/git_commit",
        "/metadata/rustc_version",
        "/metadata/simd",
        "/metadata/target_features",
        "/metadata/profile",
        "/metadata/host",
        "/metadata/os",
        "/metadata/started",
        "/config_text",
        "/config/measure/samples",
        "/calibration/start/cpu_model",
        "/calibration/end",
        "/cases/0/key",
        "/cases/0/case/kernel",
        "/cases/0/oversubscribed",
        "/cases/0/rounds/0/samples_s",
        "/cases/0/step_histogram",
        "/cases/0/summary/median_s",
        "/cases/0/summary/ci95_s",
        "/cases/0/summary/mad_s",
        "/cases/0/summary/step_ns/p99",
        "/cases/0/summary/phases/force_interact",
        "/cases/0/summary/pair_checks_per_step",
        "/cases/0/summary/max_energy_drift",
    ] {
        assert!(v.pointer(p).is_some(), "missing {p}");
    }
    // Parses back into the same types and serializes to the same document.
    let again = serde_json::to_value(&results).unwrap();
    assert_eq!(again, v);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        stdout.contains("lj-box/cell-list/n=60/p=1/r=1/seed=1"),
        "{stdout}"
    );
}
