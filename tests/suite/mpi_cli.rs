//! The MPI entry points on the command line. In a build without the `mpi` feature they are
//! listed in `--help` and refuse with exit code 2 and the rebuild hint. With the feature (a
//! single rank without mpirun, and the distributed runs under mpirun) they are tested by
//! `scripts/mpi-tests.sh`.

use std::process::{Command, Output};

fn bin(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_nbody-bench"))
        .args(args)
        .output()
        .expect("binary runs")
}

fn text(o: &Output) -> (String, String) {
    (
        String::from_utf8_lossy(&o.stdout).into_owned(),
        String::from_utf8_lossy(&o.stderr).into_owned(),
    )
}

#[test]
fn mpi_options_and_subcommands_are_in_the_help() {
    let (top, _) = text(&bin(&["--help"]));
    assert!(
        top.contains("mpi-bench") && top.contains("mpi-check"),
        "{top}"
    );
    let (run, _) = text(&bin(&["run", "--help"]));
    for option in [
        "--decomp",
        "--warmup-steps",
        "--rank-grid",
        "--rebalance-above",
        "--no-rebalance",
    ] {
        assert!(run.contains(option), "run --help lacks {option}");
    }
    assert!(run.contains("allgather") && run.contains("domain"));
    for sub in ["mpi-bench", "mpi-check"] {
        let o = bin(&[sub, "--help"]);
        assert!(o.status.success(), "{sub} --help");
    }
}

#[test]
fn mpi_options_need_a_decomposition() {
    let o = bin(&[
        "run",
        "--scenario",
        "lj-box",
        "--kernel",
        "cell-list",
        "--rank-grid",
        "2x1",
    ]);
    assert_eq!(o.status.code(), Some(2));
    assert!(text(&o).1.contains("--decomp"), "{}", text(&o).1);
}

#[cfg(not(feature = "mpi"))]
#[test]
fn without_the_feature_mpi_entry_points_exit_2_with_the_rebuild_hint() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("b.json");
    let config = dir.path().join("c.toml");
    std::fs::write(
        &config,
        "name = \"m\"\nstudy = \"cartesian\"\nscenarios = [\"lj-box\"]\nkernels = [\"naive\"]\n\
         n = [100]\n[mpi]\nranks = [1]\n",
    )
    .unwrap();
    let runs: Vec<Vec<&str>> = vec![
        vec![
            "run",
            "--scenario",
            "lj-box",
            "--kernel",
            "cell-list",
            "--decomp",
            "domain",
        ],
        vec!["mpi-bench", "--out", out.to_str().unwrap()],
        vec![
            "mpi-check",
            "--scenario",
            "coulomb",
            "--kernel",
            "naive",
            "--decomp",
            "allgather",
        ],
        vec![
            "sweep",
            "--config",
            config.to_str().unwrap(),
            "--out",
            dir.path().to_str().unwrap(),
        ],
    ];
    for args in runs {
        let o = bin(&args);
        let (_, err) = text(&o);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {err}");
        assert!(
            err.contains("built without the `mpi` feature; rebuild with `--features mpi`"),
            "{args:?}: {err}"
        );
    }
    assert!(!out.exists(), "no output file");
    assert!(!dir.path().join("m").exists(), "no results directory");
}
