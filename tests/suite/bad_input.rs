//! Bad input never panics, hangs or destroys a file: a closed or full stdout, output paths
//! that are directories, devices, inputs or each other, config names and counts of the wrong
//! form, flags a kernel ignores, and interrupts while files are being written.

use crate::{bin, refused, text};
use std::io::{BufRead, BufReader};
use std::path::Path;
use std::process::{Command, Output, Stdio};

const CSV: &str = "p,time\n1,10.0\n2,5.6\n4,3.3\n8,2.2\n";

/// The names of the files in `dir`, sorted.
fn names(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .flatten()
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .collect();
    v.sort();
    v
}

#[test]
fn a_closed_pipe_ends_the_output_quietly() {
    let dir = tempfile::tempdir().unwrap();
    let csv = dir.path().join("s.csv");
    std::fs::write(&csv, CSV).unwrap();
    let baseline = crate::committed_baseline();
    let quick = Path::new(env!("CARGO_MANIFEST_DIR")).join("results/quick/results.json");
    let config = dir.path().join("tiny.toml");
    std::fs::write(
        &config,
        "name = \"tiny\"\nstudy = \"cartesian\"\nscenarios = [\"lj-box\"]\n\
         kernels = [\"naive\", \"symmetric\"]\nn = [50]\n[measure]\nsamples = 2\nrounds = 2\n\
         warmup_s = 0.0\nmin_sample_s = 0.0\n",
    )
    .unwrap();
    let analysis = dir.path().join("analysis");
    // A copy: `report` regenerates the analyses of the sweeps it reads.
    let copy = crate::quick_results_copy();
    let results_dir = copy.path().join("results");
    let report = dir.path().join("REPORT.md");
    let (r, o) = (results_dir.to_str().unwrap(), report.to_str().unwrap());
    let (b, q, c, d, a) = (
        baseline.to_str().unwrap(),
        quick.to_str().unwrap(),
        config.to_str().unwrap(),
        dir.path().to_str().unwrap(),
        analysis.to_str().unwrap(),
    );
    let run = [
        "run",
        "--scenario",
        "lj-box",
        "--kernel",
        "naive",
        "-n",
        "50",
        "--steps",
        "5",
    ];
    let commands: Vec<Vec<String>> = vec![
        vec!["fit", "--model", "amdahl", "--csv", csv.to_str().unwrap()],
        vec!["list"],
        vec!["validate", "--scenario", "lj-box", "-n", "200"],
        run.to_vec(),
        vec!["gate", "--baseline", b, "--current", b],
        vec!["analyze", q, "--out", a],
        vec!["report", "--results", r, "--out", o],
        vec![
            "sweep",
            "--config",
            c,
            "--out",
            d,
            "--no-calibration",
            "--fresh",
        ],
    ]
    .into_iter()
    .map(|v| v.into_iter().map(String::from).collect())
    .collect();
    for args in commands {
        let mut child = bin()
            .args(&args)
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap();
        let mut first = String::new();
        BufReader::new(child.stdout.take().unwrap())
            .read_line(&mut first)
            .unwrap();
        // The reader is gone: like `| head -1`.
        let o = child.wait_with_output().unwrap();
        let err = text(&o.stderr);
        assert!(!err.contains("panicked"), "{args:?}: {err}");
        assert_eq!(o.status.code(), Some(0), "{args:?}: {err}");
    }
    // The sweep behind a closed pipe still saved and analysed its results.
    let results = dir.path().join("tiny/results.json");
    let parsed: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&results).unwrap()).unwrap();
    assert_eq!(parsed["cases"].as_array().unwrap().len(), 2);
    assert!(dir.path().join("tiny/analysis/summary.md").is_file());
}

#[test]
fn a_full_stdout_is_an_error_with_exit_2() {
    let baseline = crate::committed_baseline();
    let b = baseline.to_str().unwrap();
    let dir = tempfile::tempdir().unwrap();
    // A copy: `report` regenerates the analyses of the sweeps it reads.
    let copy = crate::quick_results_copy();
    let results_dir = copy.path().join("results");
    let report = dir.path().join("REPORT.md");
    let (r, o) = (results_dir.to_str().unwrap(), report.to_str().unwrap());
    let commands: [&[&str]; 4] = [
        &["list"],
        &["report", "--results", r, "--out", o],
        &["gate", "--baseline", b, "--current", b],
        &[
            "run",
            "--scenario",
            "lj-box",
            "--kernel",
            "naive",
            "-n",
            "50",
            "--steps",
            "2",
        ],
    ];
    for args in commands {
        let full = std::fs::OpenOptions::new()
            .write(true)
            .open("/dev/full")
            .unwrap();
        let o = bin().args(args).stdout(full).output().unwrap();
        refused(&o, "cannot write to standard output");
    }
}

#[test]
fn output_paths_are_checked_before_any_work() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let csv = d.join("s.csv");
    std::fs::write(&csv, CSV).unwrap();
    let run = |extra: &[&str]| {
        bin()
            .args([
                "run",
                "--scenario",
                "lj-box",
                "--kernel",
                "naive",
                "-n",
                "50",
            ])
            .args(["--steps", "3"])
            .args(extra)
            .output()
            .unwrap()
    };
    refused(&run(&["--json", d.to_str().unwrap()]), "is a directory");
    refused(&run(&["--json", "/dev/full"]), "not a regular file");
    refused(&run(&["--json", "/dev/null"]), "not a regular file");
    let x = d.join("x.out");
    let x = x.to_str().unwrap();
    refused(
        &run(&["--json", x, "--trajectory", x]),
        "--trajectory and --json both name",
    );
    refused(
        &run(&["--dump-state", d.join("no/such/dir.txt").to_str().unwrap()]),
        "does not exist",
    );
    let o = bin()
        .args(["fit", "--model", "amdahl", "--csv"])
        .arg(&csv)
        .arg("--json")
        .arg(&csv)
        .output()
        .unwrap();
    refused(&o, "is also an input of this command (--csv)");
    assert_eq!(
        std::fs::read_to_string(&csv).unwrap(),
        CSV,
        "input untouched"
    );
    assert_eq!(names(d), vec!["s.csv"], "nothing left behind");
    let meta = std::fs::metadata("/dev/full").unwrap();
    use std::os::unix::fs::FileTypeExt;
    assert!(
        meta.file_type().is_char_device(),
        "/dev/full is still a device"
    );
}

#[test]
fn configs_name_the_key_and_the_allowed_forms() {
    let dir = tempfile::tempdir().unwrap();
    let base = "study = \"cartesian\"\nscenarios = [\"lj-box\"]\nkernels = [\"naive\"]\n";
    let cases = [
        ("name = \"..\"\nn = [50]\n", "`name` is `..`"),
        ("name = \".hidden\"\nn = [50]\n", "plain file name"),
        ("name = \"a/b\"\nn = [50]\n", "plain file name"),
        (
            "name = \"x\"\nn = [\"50\"]\n",
            "`n` must be a list of whole numbers",
        ),
        (
            "name = \"x\"\nn = [50.5]\n",
            "`n` must be a list of whole numbers",
        ),
        (
            "name = \"x\"\nn = [-50]\n",
            "`n` must be a list of whole numbers",
        ),
        ("name = \"x\"\nn = 50\n", "or a geometric range"),
    ];
    for (i, (head, message)) in cases.iter().enumerate() {
        let config = dir.path().join(format!("c{i}.toml"));
        std::fs::write(&config, format!("{head}{base}")).unwrap();
        let o = bin()
            .args(["sweep", "--config"])
            .arg(&config)
            .arg("--out")
            .arg(dir.path().join("out"))
            .output()
            .unwrap();
        refused(&o, message);
    }
    assert!(!dir.path().join("out").exists(), "nothing written");
}

#[test]
fn a_missing_config_lists_the_places_and_the_configs() {
    let o = bin()
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .args(["sweep", "--config", "no-such-config", "--dry-run"])
        .output()
        .unwrap();
    refused(&o, "configs/no-such-config.toml");
    assert!(text(&o.stderr).contains("quick"), "{}", text(&o.stderr));
}

#[test]
fn tree_flags_with_a_kernel_that_ignores_them_are_refused() {
    for (kernel, flag, users) in [
        (
            "naive",
            ["--theta", "0.7"],
            "octree, fmm and fmm-harmonic kernels",
        ),
        (
            "naive",
            ["--leaf-size", "4"],
            "octree, fmm and fmm-harmonic kernels",
        ),
        ("naive", ["--multipole", "quadrupole"], "octree kernel"),
        ("fmm", ["--multipole", "quadrupole"], "octree kernel"),
        ("naive", ["--order", "3"], "fmm and fmm-harmonic kernels"),
        ("octree", ["--order", "3"], "fmm and fmm-harmonic kernels"),
    ] {
        let o = bin()
            .args([
                "run",
                "--scenario",
                "galaxy",
                "--kernel",
                kernel,
                "-n",
                "20",
            ])
            .args(flag)
            .output()
            .unwrap();
        refused(&o, &format!("{} applies to the {users} only", flag[0]));
    }
    let o = bin()
        .args([
            "run",
            "--scenario",
            "galaxy",
            "--kernel",
            "octree",
            "-n",
            "20",
        ])
        .args(["--theta", "0.7", "--leaf-size", "4", "--steps", "2"])
        .args(["--multipole", "quadrupole"])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", text(&o.stderr));
}

#[test]
fn skin_with_a_kernel_that_ignores_it_or_out_of_range_is_refused() {
    let run = |kernel: &str, skin: &str| {
        bin()
            .args([
                "run",
                "--scenario",
                "lj-box",
                "--kernel",
                kernel,
                "-n",
                "50",
            ])
            .args(["--steps", "2", "--skin", skin])
            .output()
            .unwrap()
    };
    refused(
        &run("cell-list", "0.003"),
        "--skin applies to the verlet and cluster-pair kernels only",
    );
    for bad in ["0", "-0.001", "inf", "nan"] {
        let o = run("verlet", bad);
        assert_eq!(
            o.status.code(),
            Some(2),
            "--skin {bad}: {}",
            text(&o.stderr)
        );
        assert!(text(&o.stderr).contains("--skin"), "{}", text(&o.stderr));
    }
    let dir = tempfile::tempdir().unwrap();
    let json = dir.path().join("run.json");
    let o = bin()
        .args([
            "run",
            "--scenario",
            "lj-box",
            "--kernel",
            "verlet",
            "-n",
            "50",
        ])
        .args(["--steps", "2", "--skin", "0.005", "--json"])
        .arg(&json)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", text(&o.stderr));
    let v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    assert_eq!(v["kernel_params"]["skin"], 0.005);
    assert!(v["counters"]["total"]["list_entries"].is_u64());
    assert!(
        text(&o.stdout).contains("neighbour list"),
        "{}",
        text(&o.stdout)
    );
}

#[test]
fn the_trajectory_ends_with_the_final_state() {
    let dir = tempfile::tempdir().unwrap();
    let frames = |steps: &str| {
        let path = dir.path().join(format!("t{steps}.txt"));
        let o = bin()
            .args([
                "run",
                "--scenario",
                "lj-box",
                "--kernel",
                "naive",
                "-n",
                "20",
            ])
            .args(["--steps", steps, "--every", "4", "--format", "nbview-bin"])
            .arg("--trajectory")
            .arg(&path)
            .output()
            .unwrap();
        assert!(o.status.success(), "{}", text(&o.stderr));
        std::fs::metadata(&path).unwrap().len()
    };
    // Frames: 4 steps: initial, 4; 8 steps: initial, 4, 8; 10 steps: initial, 4, 8 and the
    // final state at 10; 1 step: initial and the final state.
    let (four, eight, ten, one) = (frames("4"), frames("8"), frames("10"), frames("1"));
    let frame = eight - four;
    assert!(frame > 0);
    assert_eq!(ten - eight, frame, "the final state is written");
    assert_eq!(one, four, "initial and final state");
}

/// Sends SIGINT to a child after `after`, then waits for it.
fn interrupt(mut child: std::process::Child, after: std::time::Duration) -> Output {
    std::thread::sleep(after);
    let status = Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .unwrap();
    assert!(status.success());
    let _ = child.stdout.take();
    child.wait_with_output().unwrap()
}

#[test]
fn an_interrupt_leaves_no_temporary_file() {
    let dir = tempfile::tempdir().unwrap();
    let child = bin()
        .args([
            "run",
            "--scenario",
            "lj-box",
            "--kernel",
            "naive",
            "-n",
            "2000",
        ])
        // A run that would take days, started on purpose.
        .args(["--steps", "100000000", "--every", "1", "--yes"])
        .arg("--trajectory")
        .arg(dir.path().join("t.nbv"))
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let o = interrupt(child, std::time::Duration::from_millis(700));
    assert_eq!(o.status.code(), Some(130), "{}", text(&o.stderr));
    assert!(
        names(dir.path()).is_empty(),
        "left: {:?}",
        names(dir.path())
    );

    // A sweep: no temporary is left, and its results file stays whole (resumable).
    let config = dir.path().join("long.toml");
    std::fs::write(
        &config,
        "name = \"long\"\nstudy = \"cartesian\"\nscenarios = [\"lj-box\"]\n\
         kernels = [\"naive\", \"symmetric\"]\nn = [400, 800]\n[measure]\nsamples = 40\n\
         rounds = 20\nmin_sample_s = 0.05\nwarmup_s = 0.0\n",
    )
    .unwrap();
    let out = dir.path().join("out");
    let child = bin()
        .args(["sweep", "--no-calibration", "--config"])
        .arg(&config)
        .arg("--out")
        .arg(&out)
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let o = interrupt(child, std::time::Duration::from_millis(1500));
    assert_eq!(o.status.code(), Some(130), "{}", text(&o.stderr));
    let results = out.join("long");
    let left: Vec<String> = names(&results)
        .into_iter()
        .filter(|n| n.ends_with(".tmp"))
        .collect();
    assert!(left.is_empty(), "temporaries left: {left:?}");
    let file = std::fs::read_to_string(results.join("results.json")).unwrap();
    let parsed: serde_json::Value = serde_json::from_str(&file).expect("whole JSON");
    assert_eq!(parsed["schema"], "nbody-bench/results/v1");
}

#[test]
fn a_box_the_precision_cannot_resolve_is_refused_before_any_work() {
    let o = bin()
        .args([
            "run",
            "--scenario",
            "lj-box",
            "--kernel",
            "cell-list",
            "-n",
            "500",
        ])
        .args(["--density", "1e-300"])
        .output()
        .unwrap();
    refused(&o, "too large for f32 positions");
    // A huge but resolvable box in f64 runs, in little memory: placement keeps only the
    // occupied cells.
    let o = bin()
        .args([
            "run",
            "--scenario",
            "lj-box",
            "--kernel",
            "naive",
            "-n",
            "500",
        ])
        .args(["--density", "1e-6", "--precision", "f64", "--steps", "2"])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", text(&o.stderr));
}

#[test]
fn a_sweep_checks_every_case_before_the_first() {
    let dir = tempfile::tempdir().unwrap();
    let config = dir.path().join("big.toml");
    std::fs::write(
        &config,
        "name = \"big\"\nstudy = \"cartesian\"\nscenarios = [\"lj-box\"]\nkernels = [\"naive\"]\n\
         n = [100, 1000000000]\n",
    )
    .unwrap();
    let o = bin()
        .args(["sweep", "--no-calibration", "--yes", "--config"])
        .arg(&config)
        .arg("--out")
        .arg(dir.path().join("out"))
        .output()
        .unwrap();
    refused(&o, "case lj-box/naive/n=1000000000");
    assert!(text(&o.stderr).contains("more than this tool handles"));
    assert!(
        !dir.path().join("out").exists(),
        "nothing measured, nothing written"
    );
}
