//! Sizes the machine cannot hold or finish are refused before any work starts, with the limit
//! in the message; config errors name their key and what it accepts.

use std::process::{Command, Output, Stdio};

fn bin() -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_nbody-bench"));
    c.env_remove("NBODY_BENCH_TEST_SLOWDOWN")
        .stdin(Stdio::null());
    c
}

/// Exit 2 within a few seconds' work, the message names `what`, no panic.
fn refused(o: &Output, what: &str) {
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{what}: {err}");
    assert!(err.contains(what), "expected `{what}` in: {err}");
    assert!(!err.contains("panicked"), "{err}");
}

fn run(args: &[&str]) -> Output {
    bin().args(args).output().unwrap()
}

#[test]
fn steps_a_run_cannot_finish_are_refused_unless_asked() {
    let lj = [
        "run",
        "--scenario",
        "lj-box",
        "--kernel",
        "naive",
        "-n",
        "10",
    ];
    for steps in ["18446744073709551615", "1000000000000"] {
        let o = bin().args(lj).args(["--steps", steps]).output().unwrap();
        refused(&o, "pass --yes to run it anyway");
    }
    // Quadratic work at a large n: refused from the probe, before the system is built.
    let o = run(&[
        "run",
        "--scenario",
        "galaxy",
        "--kernel",
        "naive",
        "-n",
        "400000",
        "--steps",
        "100",
    ]);
    refused(&o, "is refused above 1.0 h");
    let o = run(&["validate", "--scenario", "galaxy", "-n", "2000000"]);
    refused(&o, "lower -n, or pass --yes");
}

#[test]
fn systems_larger_than_memory_are_refused() {
    let o = run(&[
        "run",
        "--scenario",
        "galaxy",
        "--kernel",
        "octree",
        "-n",
        "500000000",
        "--steps",
        "1",
    ]);
    refused(&o, "GiB available");
    let dir = tempfile::tempdir().unwrap();
    let config = dir.path().join("m.toml");
    std::fs::write(
        &config,
        "name = \"m\"\nstudy = \"cartesian\"\nscenarios = [\"galaxy\"]\nkernels = [\"octree\"]\n\
         n = [100, 500000000]\n",
    )
    .unwrap();
    let o = bin()
        .args(["sweep", "--yes", "--no-calibration", "--config"])
        .arg(&config)
        .arg("--out")
        .arg(dir.path().join("out"))
        .output()
        .unwrap();
    refused(&o, "GiB available");
    assert!(
        !dir.path().join("out").exists(),
        "nothing measured, nothing written"
    );
}

#[test]
fn mpi_sizes_are_bounded_in_any_build() {
    refused(
        &run(&["mpi-bench", "--max-bytes", "10000000000"]),
        "more than 1073741824",
    );
    refused(
        &run(&["mpi-bench", "--reps", "100000000"]),
        "more than 1000000",
    );
    let check = [
        "mpi-check",
        "--scenario",
        "lj-box",
        "--kernel",
        "naive",
        "--decomp",
        "allgather",
    ];
    let o = bin()
        .args(check)
        .args(["--steps", "5000000"])
        .output()
        .unwrap();
    refused(&o, "more than 1000000");
    let o = bin()
        .args(check)
        .args(["--warmup-steps", "5000000"])
        .output()
        .unwrap();
    refused(&o, "more than 1000000");
}

#[test]
fn config_type_errors_name_the_key_and_its_forms() {
    let dir = tempfile::tempdir().unwrap();
    let head = "name = \"t\"\nscenarios = [\"lj-box\"]\nkernels = [\"naive\"]\nn = [100]\n";
    let cases = [
        (
            "study = \"cartesian\"\nthreads = [\"2\"]\n",
            "`threads`: invalid type",
            "a list of thread counts",
        ),
        (
            "study = \"cartesian\"\nthreads = 2\n",
            "`threads`",
            "such as threads = [1, 2]",
        ),
        (
            "study = \"cartesian\"\nseeds = [-1]\n",
            "`seeds`",
            "whole numbers of at least 0",
        ),
        ("study = \"diag\"\n", "`study`", "one of \"strong\""),
        (
            "study = \"cartesian\"\nprecision = \"f16\"\n",
            "`precision`",
            "\"f32\" or \"f64\"",
        ),
        (
            "study = \"cartesian\"\n[measure]\nsamples = \"6\"\n",
            "`measure.samples`",
            "at least 1",
        ),
        (
            "study = \"cartesian\"\n[measure]\nwarmup_s = \"a\"\n",
            "`measure.warmup_s`",
            "seconds",
        ),
        (
            "study = \"weak\"\n[weak]\nrule = \"x\"\nbase_n = 5\n",
            "`weak.rule`",
            "\"cost-model\"",
        ),
        (
            "study = \"weak\"\n[weak]\nrule = \"linear\"\n",
            "`weak.base_n` is missing",
            "particles",
        ),
        (
            "study = \"cartesian\"\n[mpi]\nranks = [\"a\"]\n",
            "`mpi.ranks`",
            "rank counts",
        ),
        ("", "`study` is missing", "one of \"strong\""),
    ];
    for (i, (body, key, forms)) in cases.iter().enumerate() {
        let config = dir.path().join(format!("c{i}.toml"));
        std::fs::write(&config, format!("{head}{body}")).unwrap();
        let o = bin()
            .args(["sweep", "--dry-run", "--config"])
            .arg(&config)
            .output()
            .unwrap();
        refused(&o, key);
        refused(&o, forms);
    }
}

#[test]
fn thread_counts_are_bounded() {
    let o = bin()
        .args([
            "run",
            "--scenario",
            "lj-box",
            "--kernel",
            "naive",
            "-n",
            "50",
        ])
        .args(["--threads", "100000"])
        .output()
        .unwrap();
    refused(&o, "more than 1024");
    let dir = tempfile::tempdir().unwrap();
    let config = dir.path().join("t.toml");
    std::fs::write(
        &config,
        "name = \"t\"\nstudy = \"cartesian\"\nscenarios = [\"lj-box\"]\nkernels = [\"naive\"]\n\
         n = [100]\nthreads = [1, 5000]\n",
    )
    .unwrap();
    let o = bin()
        .args(["sweep", "--config"])
        .arg(&config)
        .output()
        .unwrap();
    refused(&o, "thread counts from 1 to 1024");
}

#[test]
fn endless_inputs_and_report_outputs_are_refused() {
    refused(
        &run(&["fit", "--model", "amdahl", "--csv", "/dev/zero"]),
        "is a device or socket, not a file",
    );
    let copy = crate::quick_results_copy();
    let results = copy.path().join("results");
    let quick = results.join("quick/results.json");
    let before = std::fs::read(&quick).unwrap();
    let r = results.to_str().unwrap();
    // Reading the old report from a device would never end; replacing an input loses it.
    refused(
        &run(&["report", "--results", r, "--out", "/dev/full"]),
        "not a regular file",
    );
    refused(
        &run(&["report", "--results", r, "--out", quick.to_str().unwrap()]),
        "is also an input of this command (--results)",
    );
    refused(
        &run(&["report", "--results", r, "--out", "/tmp"]),
        "is a directory",
    );
    assert_eq!(std::fs::read(&quick).unwrap(), before, "input untouched");
}

#[test]
fn a_range_of_n_past_the_limit_is_refused_with_the_limit() {
    let dir = tempfile::tempdir().unwrap();
    for (range, what) in [
        (
            "{ from = 1, to = 1000000, factor = 1.0001 }",
            "gives more than 10000 counts, the most a range may give: raise the factor",
        ),
        (
            "{ from = 1000, to = 2000, factor = 1.0000000001 }",
            "the factor is so close to 1",
        ),
    ] {
        let config = dir.path().join("r.toml");
        std::fs::write(
            &config,
            format!(
                "name = \"r\"\nstudy = \"cartesian\"\nscenarios = [\"lj-box\"]\n\
                 kernels = [\"naive\"]\nn = {range}\n"
            ),
        )
        .unwrap();
        let o = bin()
            .args(["sweep", "--yes", "--no-calibration", "--config"])
            .arg(&config)
            .arg("--out")
            .arg(dir.path().join("out"))
            .output()
            .unwrap();
        refused(&o, what);
        assert!(!dir.path().join("out").exists(), "nothing measured");
    }
}
