//! Every integration test in one binary: each test file of the suite is a module here, so the
//! library's generic kernels are compiled into one test executable instead of one per file
//! (that made most of the test build's time).
//!
//! The modules that time things (`gate`, `dry_run`) are meant to run alone: `scripts/test.sh`
//! runs the suite without them, then them with one test thread, so no other test loads the
//! CPUs during their sweeps.

mod after_failures;
mod analyze;
mod bad_input;
mod bad_sizes;
mod bisect;
mod causes;
mod checked_first;
mod cli;
mod config_corpus;
mod conservation;
mod course_codes;
mod docs;
mod dry_run;
mod dry_run_checks;
mod export;
mod export_history;
mod export_results;
mod external;
mod external_energy;
mod external_honesty;
mod external_phases;
mod fit_cli;
mod foreign_input;
mod gate;
mod gate_baselines;
mod gate_refusals;
mod history;
mod history_lines;
mod init;
mod init_lj;
mod init_python;
mod initial;
mod integrity;
mod invariants;
mod kernel_parts;
mod kernels_agree;
mod layering;
mod mpi_cli;
mod mpi_launch;
mod parsers;
mod peers;
mod publish;
mod readings;
mod report;
mod runs;
mod skin_auto;
mod slurm;
mod slurm_stand_ins;
mod supervision;
mod sweep;
mod verlet;
mod whole_step;

use std::path::Path;
use std::process::{Child, Command, Output, Stdio};
use std::time::Duration;
use wait_timeout::ChildExt;

/// A sweep observer that stops the sweep after this many measured rounds, as an interrupt
/// would.
pub struct StopAfter(pub usize);

impl nbody_harness::experiment::runner::Observer for StopAfter {
    fn round_done(&mut self, _: &nbody_records::results::CaseRecord, _: usize) {
        self.0 = self.0.saturating_sub(1);
    }

    fn keep_going(&mut self) -> bool {
        self.0 > 0
    }
}

/// This build's binary, without the test-only slowdown and with no standard input.
pub fn bin() -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_nbody-bench"));
    c.env_remove("NBODY_BENCH_TEST_SLOWDOWN")
        .stdin(Stdio::null());
    c
}

/// Longest any command the tests wait for with [`finish`] may take before it counts as a hang.
pub const HANG_S: u64 = 120;

/// Waits for `child` for at most [`HANG_S`]; a hang is killed and fails the test.
pub fn finish(mut child: Child, what: &str) -> Output {
    use std::io::Read;
    // Drain the pipes while waiting, so that a chatty child cannot block on a full pipe.
    let drain = |r: Option<Box<dyn Read + Send>>| {
        std::thread::spawn(move || {
            let mut v = Vec::new();
            if let Some(mut r) = r {
                let _ = r.read_to_end(&mut v);
            }
            v
        })
    };
    let out = drain(child.stdout.take().map(|s| Box::new(s) as _));
    let err = drain(child.stderr.take().map(|s| Box::new(s) as _));
    let status = match child.wait_timeout(Duration::from_secs(HANG_S)).unwrap() {
        Some(s) => s,
        None => {
            let _ = child.kill();
            let _ = child.wait();
            panic!("{what}: still running after {HANG_S} s");
        }
    };
    Output {
        status,
        stdout: out.join().unwrap(),
        stderr: err.join().unwrap(),
    }
}

/// Output bytes as text (invalid UTF-8 replaced).
pub fn text(bytes: &[u8]) -> String {
    String::from_utf8_lossy(bytes).into_owned()
}

/// Exit 2, the message names `what`, no panic.
pub fn refused(o: &Output, what: &str) {
    let err = text(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{what}: {err}");
    assert!(err.contains(what), "expected `{what}` in: {err}");
    assert!(!err.contains("panicked"), "{err}");
}

/// Copies the files of `from` (recursively) into `to`: tests that regenerate analyses or the
/// report work on a copy of the committed results, never on the repository's own files.
pub fn copy_tree(from: &Path, to: &Path) {
    std::fs::create_dir_all(to).unwrap();
    for entry in std::fs::read_dir(from).unwrap().flatten() {
        let (src, dst) = (entry.path(), to.join(entry.file_name()));
        if src.is_dir() {
            copy_tree(&src, &dst);
        } else {
            std::fs::copy(&src, &dst).unwrap();
        }
    }
}

/// The committed gate baselines (`results/baseline/*.json`, one per machine class), sorted;
/// the first of them is the one the tests read.
pub fn committed_baseline() -> std::path::PathBuf {
    let folder = Path::new(env!("CARGO_MANIFEST_DIR")).join("results/baseline");
    let mut files: Vec<_> = std::fs::read_dir(&folder)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "json"))
        .collect();
    files.sort();
    files.into_iter().next().expect("a committed baseline")
}

/// A temporary `results/` holding a copy of the committed quick sweep.
pub fn quick_results_copy() -> tempfile::TempDir {
    let dir = tempfile::tempdir().unwrap();
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    copy_tree(
        &root.join("results/quick"),
        &dir.path().join("results/quick"),
    );
    dir
}

/// Sweeps `text`, a cut-down copy of a config of `configs/` (its `{config_dir}` is that
/// folder), in this process into a temporary directory: the results and where they were saved
/// (kept while the directory lives).
pub fn sweep_committed_config(
    text: &str,
    name: &str,
) -> (
    nbody_records::results::ResultsFile,
    std::path::PathBuf,
    tempfile::TempDir,
) {
    use nbody_harness::experiment::runner::{Silent, SweepOptions, run_sweep};
    let configs = Path::new(env!("CARGO_MANIFEST_DIR")).join("configs");
    let config = nbody_records::config::SweepConfig::parse(text, &configs.join(name)).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let options = SweepOptions {
        out: Some(dir.path().to_path_buf()),
        config_dir: Some(configs),
        nbody_bench: Some(env!("CARGO_BIN_EXE_nbody-bench").into()),
        ..Default::default()
    };
    let clock = nbody_engine::clock::MockClock::new(std::time::Duration::from_millis(1));
    let report = run_sweep(&config, text, &options, &clock, &mut Silent).unwrap();
    let results = nbody_records::results::ResultsFile::load(&report.path).unwrap();
    (results, report.path, dir)
}
