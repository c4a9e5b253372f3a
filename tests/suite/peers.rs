//! One small LAMMPS case through the harness, as `configs/vs-lammps.toml` runs it (the shipped
//! input and the exported particles): it must run, pass its check and report its loop time. A
//! machine without LAMMPS fails this test (scripts/test.sh installs it), it does not skip it.

use nbody_bench::clock::MockClock;
use nbody_bench::experiment::config::SweepConfig;
use nbody_bench::experiment::results::ResultsFile;
use nbody_bench::experiment::runner::{Silent, SweepOptions, run_sweep};
use std::path::Path;
use std::time::Duration;

#[test]
fn a_small_lammps_case_runs_through_the_harness() {
    assert!(
        nbody_bench::experiment::external::process::resolve("lmp", None).is_ok(),
        "LAMMPS (`lmp`) is not installed: run scripts/install-peers.sh (or apt-get install -y lammps)"
    );
    let shipped = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("configs/vs-lammps.toml"),
    )
    .unwrap();
    // The shipped entry at CI size: 1 rank (no mpirun), 500 particles, 20 steps, 2 samples.
    let text = shipped
        .replace("n = [10000, 100000, 1000000]", "n = [500]")
        .replace(
            "kernels = [\"cell-list\", \"verlet\"]",
            "kernels = [\"cell-list\"]",
        )
        .replace("threads = [1, 2]", "threads = [1]")
        .replace(
            "command = [\"mpirun\", \"-n\", \"{ranks}\", \"--bind-to\", \"none\", \"lmp\"",
            "command = [\"lmp\"",
        )
        .replace("ranks = [1, 2]", "ranks = [1]")
        .replace("steps = 200", "steps = 20")
        .replace(
            "samples = 10\nrounds = 5\nmin_sample_s = 0.2",
            "samples = 2\nrounds = 1\nmin_sample_s = 0.001",
        );
    assert!(
        text.contains("n = [500]") && text.contains("command = [\"lmp\""),
        "{text}"
    );
    let config = SweepConfig::parse(&text, Path::new("vs-lammps.toml")).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let options = SweepOptions {
        out: Some(dir.path().to_path_buf()),
        config_dir: Some(Path::new(env!("CARGO_MANIFEST_DIR")).join("configs")),
        nbody_bench: Some(env!("CARGO_BIN_EXE_nbody-bench").into()),
        ..Default::default()
    };
    let clock = MockClock::new(Duration::from_millis(1));
    let report = run_sweep(&config, &text, &options, &clock, &mut Silent).unwrap();
    let results = ResultsFile::load(&report.path).unwrap();
    let lammps = results
        .cases
        .iter()
        .find(|c| c.key == "lj-box/lammps/n=500/p=1/r=1/seed=1")
        .expect("the LAMMPS case");
    let round = &lammps.rounds[0];
    let runs = &round.external.as_ref().unwrap().runs;
    for run in runs {
        assert!(run.error.is_none(), "{:?}", run.error);
        assert!(run.reported_s.is_some_and(|t| t > 0.0 && t <= run.wall_s));
    }
    assert_eq!(round.samples_s.len(), 2);
    assert!(
        results.metadata.externals[0].version.contains("Molecular"),
        "{:?}",
        results.metadata.externals
    );
}
