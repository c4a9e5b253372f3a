//! Sweeps through Slurm (`[scheduler] kind = "slurm"`), against a real one: each test needs
//! `sbatch`, `squeue` and `scontrol` talking to a controller, so they are ignored by a plain
//! `cargo test` and run under the one-node Slurm of scripts/slurm-local.sh (scripts/test.sh):
//!
//!   scripts/slurm-local.sh -- cargo test --release --features mpi --test suite -- --ignored slurm::

use nbody_engine::clock::MockClock;
use nbody_harness::experiment::runner::{Silent, SweepOptions, run_sweep};
use nbody_records::config::SweepConfig;
use nbody_records::results::ResultsFile;
use std::path::{Path, PathBuf};
use std::time::Duration;

const SCHEDULER: &str = r#"
[scheduler]
kind = "slurm"
time_limit = "5:00"
poll_s = 0.2
"#;

fn threaded(scheduler: &str) -> String {
    format!(
        r#"
name = "threaded"
study = "cartesian"
scenarios = ["lj-box"]
kernels = ["cell-list"]
n = [2000]
threads = [1, 2]
{scheduler}
[measure]
warmup_s = 0.01
samples = 4
rounds = 2
min_sample_s = 0.01
"#
    )
}

fn sweep(text: &str, out: &Path, nbody_bench: &Path, calibrate: bool) -> ResultsFile {
    let config = SweepConfig::parse(text, Path::new("slurm.toml")).unwrap();
    let options = SweepOptions {
        out: Some(out.to_path_buf()),
        calibrate,
        nbody_bench: Some(nbody_bench.to_path_buf()),
        ..Default::default()
    };
    let clock = MockClock::new(Duration::from_millis(1));
    let report = run_sweep(&config, text, &options, &clock, &mut Silent).unwrap();
    ResultsFile::load(&report.path).unwrap()
}

fn exe() -> PathBuf {
    PathBuf::from(env!("CARGO_BIN_EXE_nbody-bench"))
}

/// A program that stands in for this one inside the job.
fn script(dir: &Path, body: &str) -> PathBuf {
    use std::os::unix::fs::PermissionsExt;
    let path = dir.join("stand-in");
    std::fs::write(&path, format!("#!/bin/sh\n{body}\n")).unwrap();
    std::fs::set_permissions(&path, std::fs::Permissions::from_mode(0o755)).unwrap();
    path
}

#[test]
#[ignore = "needs a Slurm: scripts/slurm-local.sh -- cargo test ... -- --ignored slurm::"]
fn a_sweep_through_slurm_has_the_shape_of_one_without() {
    let dir = tempfile::tempdir().unwrap();
    let with = sweep(
        &threaded(SCHEDULER),
        &dir.path().join("slurm"),
        &exe(),
        true,
    );
    let without = sweep(&threaded(""), &dir.path().join("here"), &exe(), false);
    let keys = |r: &ResultsFile| r.cases.iter().map(|c| c.key.clone()).collect::<Vec<_>>();
    assert_eq!(keys(&with), keys(&without));
    assert_eq!(keys(&with).len(), 2);
    let mut ids = Vec::new();
    for (a, b) in with.cases.iter().zip(&without.cases) {
        assert!(a.is_complete() && b.is_complete());
        assert_eq!(a.rounds.len(), b.rounds.len());
        let samples = |c: &nbody_records::results::CaseRecord| {
            c.rounds
                .iter()
                .map(|r| r.samples_s.len())
                .collect::<Vec<_>>()
        };
        assert_eq!(samples(a), samples(b));
        assert!(a.summary.is_some(), "{}", a.key);
        // The step-time histogram came back from the jobs too.
        assert!(!a.step_histogram.is_empty(), "{}", a.key);
        for round in &a.rounds {
            let job = round.job.as_ref().expect("every round names its job");
            assert!(job.node.as_deref().is_some_and(|n| !n.is_empty()));
            assert_eq!(job.state.as_deref(), Some("COMPLETED"), "{job:?}");
            assert!(job.error.is_none());
            ids.push(job.id.clone());
        }
        assert!(b.rounds.iter().all(|r| r.job.is_none()));
    }
    ids.sort();
    ids.dedup();
    assert_eq!(ids.len(), 4, "one job per case round");
    // Calibrated inside jobs, at the start and the end.
    assert!(with.calibration.start.is_some() && with.calibration.end.is_some());
    assert!(
        dir.path()
            .join("slurm/threaded/jobs/calibrate-start/result.json")
            .exists()
    );
}

#[cfg(feature = "mpi")]
#[test]
#[ignore = "needs a Slurm: scripts/slurm-local.sh -- cargo test ... -- --ignored slurm::"]
fn an_mpi_case_runs_its_ranks_with_srun_inside_its_job() {
    let dir = tempfile::tempdir().unwrap();
    let text = format!(
        r#"
name = "ranks"
study = "cartesian"
scenarios = ["lj-box"]
kernels = ["cell-list"]
n = [2000]
[mpi]
launcher = "srun"
ranks = [2]
args = ["--mpi=pmix"]
decomp = ["domain"]
steps = 20
warmup_steps = 2
{SCHEDULER}
[measure]
samples = 2
rounds = 1
"#
    );
    let r = sweep(&text, dir.path(), &exe(), false);
    let case = &r.cases[0];
    assert_eq!(case.key, "lj-box/cell-list/n=2000/p=1/r=2/seed=1/domain");
    let round = &case.rounds[0];
    assert_eq!(round.samples_s.len(), 2);
    let mpi = round.mpi.as_ref().expect("the ranks' report");
    assert_eq!(mpi.ranks, 2);
    assert_eq!(
        round.job.as_ref().unwrap().state.as_deref(),
        Some("COMPLETED")
    );
}

#[test]
#[ignore = "needs a Slurm: scripts/slurm-local.sh -- cargo test ... -- --ignored slurm::"]
fn jobs_that_fail_or_run_out_of_time_give_rounds_without_samples() {
    let dir = tempfile::tempdir().unwrap();
    let one_round = |time_limit: &str| {
        threaded(SCHEDULER)
            .replace("threads = [1, 2]", "threads = [1]")
            .replace("samples = 4\nrounds = 2", "samples = 1\nrounds = 1")
            .replace(
                "time_limit = \"5:00\"",
                &format!("time_limit = \"{time_limit}\""),
            )
    };
    // Both at once: the time limit takes a minute or more to be enforced.
    let failing_dir = dir.path().join("failing");
    let late_dir = dir.path().join("late");
    std::fs::create_dir_all(&failing_dir).unwrap();
    std::fs::create_dir_all(&late_dir).unwrap();
    let failing = script(
        &failing_dir,
        "echo 'cannot measure: out of particles' >&2\nexit 3",
    );
    let late = script(&late_dir, "echo started\nexec sleep 600");
    let (quick, short) = (one_round("5:00"), one_round("1"));
    let (failed, timed_out) = std::thread::scope(|s| {
        let a = s.spawn(|| sweep(&quick, &failing_dir, &failing, false));
        let b = s.spawn(|| sweep(&short, &late_dir, &late, false));
        (a.join().unwrap(), b.join().unwrap())
    });
    for (r, state, line) in [
        (&failed, "FAILED", "cannot measure: out of particles"),
        (&timed_out, "TIMEOUT", "started"),
    ] {
        let case = &r.cases[0];
        // The round is done (nothing to resume) but has no samples: no summary.
        assert!(case.is_complete());
        assert!(case.summary.is_none());
        let job = case.rounds[0].job.as_ref().unwrap();
        assert_eq!(job.state.as_deref(), Some(state), "{job:?}");
        let error = job.error.as_ref().expect("why the round has no samples");
        assert!(error.what.contains(state), "{}", error.what);
        assert!(
            error.output_tail.iter().any(|l| l.contains(line)),
            "{:?}",
            error.output_tail
        );
    }
}

#[test]
#[ignore = "needs a Slurm: scripts/slurm-local.sh -- cargo test ... -- --ignored slurm::"]
fn a_sweep_killed_while_its_job_is_queued_resumes_without_submitting_it_again() {
    let dir = tempfile::tempdir().unwrap();
    let config = dir.path().join("threaded.toml");
    std::fs::write(&config, threaded(SCHEDULER)).unwrap();
    let out = dir.path().join("out");
    let sweep_cli = |resume: bool| {
        let mut c = std::process::Command::new(exe());
        c.args(["sweep", "--config", config.to_str().unwrap(), "--out"])
            .arg(&out)
            .args(["--no-calibration", "--yes"])
            .stdout(std::process::Stdio::null())
            .stderr(std::process::Stdio::piped());
        if resume {
            c.arg("--resume");
        }
        c
    };
    let mut first = sweep_cli(false).spawn().unwrap();
    // Killed as soon as its first job is submitted (queued or running).
    let jobs = out.join("threaded/jobs");
    let id_file = loop {
        let found = std::fs::read_dir(&jobs).ok().and_then(|d| {
            d.filter_map(|e| e.ok())
                .map(|e| e.path().join("job-id"))
                .find(|p| p.exists())
        });
        if let Some(p) = found {
            break p;
        }
        assert!(
            first.try_wait().unwrap().is_none(),
            "the sweep ended before submitting"
        );
        std::thread::sleep(Duration::from_millis(20));
    };
    first.kill().unwrap();
    first.wait().unwrap();
    let submitted = std::fs::read_to_string(&id_file)
        .unwrap()
        .trim()
        .to_string();
    let resumed = sweep_cli(true).output().unwrap();
    let stderr = String::from_utf8_lossy(&resumed.stderr);
    assert!(resumed.status.success(), "{stderr}");
    assert!(
        stderr.contains(&format!("job {submitted} was submitted before")),
        "{stderr}"
    );
    let r = ResultsFile::load(&out.join("threaded/results.json")).unwrap();
    let mut ids: Vec<String> = r
        .cases
        .iter()
        .flat_map(|c| {
            c.rounds
                .iter()
                .map(|round| round.job.as_ref().unwrap().id.clone())
        })
        .collect();
    assert!(ids.contains(&submitted), "{ids:?}");
    ids.sort();
    ids.dedup();
    assert_eq!(ids.len(), 4, "each round submitted once");
    assert!(
        r.cases
            .iter()
            .all(|c| c.is_complete() && c.summary.is_some())
    );
}
