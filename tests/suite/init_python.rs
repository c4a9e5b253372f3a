//! `nbody-bench init --external NAME --lang python`: the config and its driver NAME.py, both
//! refused over an existing file; the driver computes our `galaxy` physics (the energies of a
//! run of our symmetric kernel from the same exported bodies) and the config, cut down to one
//! small n, sweeps it through the binary into results with its samples.

use super::{bin, refused, text};
use nbody_records::config::SweepConfig;
use nbody_records::results::ResultsFile;
use std::path::Path;

/// Whether `python3` runs here; the tests that need it say so and pass without it.
pub(super) fn python3() -> bool {
    let ok = std::process::Command::new("python3")
        .arg("--version")
        .output()
        .is_ok_and(|o| o.status.success());
    if !ok {
        eprintln!("skipped: no python3 on the PATH, which the Python template runs");
    }
    ok
}

/// `text` with `from` replaced by `to`, which must occur in it: a template that changes under
/// the test fails here, not in a sweep of the full-size config.
pub(super) fn edit(text: &str, from: &str, to: &str) -> String {
    assert!(text.contains(from), "`{from}` is not in the template");
    text.replacen(from, to, 1)
}

/// The total energy of a line `energy initial E0 final E1 ...` of the driver's output.
pub(super) fn driver_energies(stdout: &str) -> (f64, f64) {
    let line = stdout
        .lines()
        .find(|l| l.starts_with("energy initial "))
        .unwrap_or_else(|| panic!("no energy line in {stdout}"));
    let words: Vec<&str> = line.split_whitespace().collect();
    (words[2].parse().unwrap(), words[4].parse().unwrap())
}

/// The total energy at the start and at the end of `nbody-bench run ARGS --json run.json`,
/// run in `dir`.
pub(super) fn run_energies(dir: &Path, args: &[&str]) -> (f64, f64) {
    let out = bin()
        .current_dir(dir)
        .args(args)
        .args(["--json", "run.json"])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("run.json")).unwrap()).unwrap();
    let total = |at: &str| -> f64 {
        let e = &json["energy"][at];
        ["kinetic", "potential", "external"]
            .iter()
            .map(|k| e[k].as_f64().unwrap())
            .sum()
    };
    (total("initial"), total("final"))
}

/// The config `NAME.toml` in `dir` cut down by `edits` (each `(from, to)` must occur in it),
/// swept into `dir/out` without a calibration: its results, with the keys of its cases.
pub(super) fn sweep_cut_down(
    dir: &Path,
    name: &str,
    edits: &[(&str, &str)],
) -> (ResultsFile, Vec<String>) {
    let config = dir.join(format!("{name}.toml"));
    let mut small = std::fs::read_to_string(&config).unwrap();
    for (from, to) in edits {
        small = edit(&small, from, to);
    }
    std::fs::write(&config, small).unwrap();
    let out = bin()
        .current_dir(dir)
        .args(["sweep", "--config", &format!("{name}.toml"), "--out", "out"])
        .arg("--no-calibration")
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    let results = ResultsFile::load(&dir.join(format!("out/{name}/results.json"))).unwrap();
    let keys = results.cases.iter().map(|c| c.key.clone()).collect();
    (results, keys)
}

#[test]
fn init_python_writes_a_config_and_driver_and_never_replaces_either() {
    let dir = tempfile::tempdir().unwrap();
    let run = |args: &[&str]| bin().current_dir(dir.path()).args(args).output().unwrap();
    let out = run(&["init", "--external", "pysim", "--lang", "python"]);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    let (config, driver) = (dir.path().join("pysim.toml"), dir.path().join("pysim.py"));
    let config_text = std::fs::read_to_string(&config).unwrap();
    let driver_text = std::fs::read_to_string(&driver).unwrap();
    let parsed = SweepConfig::parse(&config_text, &config).unwrap();
    assert_eq!(parsed.external[0].name, "pysim");
    assert!(config_text.contains(r#""python3", "{config_dir}/pysim.py""#));
    assert!(!config_text.contains("mycode") && !driver_text.contains("mycode"));
    assert_eq!(
        parsed.external[0].threads.as_deref(),
        Some(&[1][..]),
        "a pure-Python program runs one thread"
    );
    assert!(driver_text.contains("def evolve(") && driver_text.contains("sim.step()"));

    // Either file in the way refuses the whole init and leaves both as they were.
    refused(
        &run(&["init", "--external", "pysim", "--lang", "python"]),
        "pysim.toml exists",
    );
    let other = ["--out", "other.toml"];
    refused(
        &run(&[
            &["init", "--external", "pysim", "--lang", "python"][..],
            &other,
        ]
        .concat()),
        "pysim.py exists",
    );
    refused(
        &run(&[
            "init",
            "--external",
            "q",
            "--lang",
            "python",
            "--out",
            "q.py",
        ]),
        "both name",
    );
    assert!(!dir.path().join("other.toml").exists() && !dir.path().join("q.py").exists());
    assert_eq!(std::fs::read_to_string(&config).unwrap(), config_text);
    assert_eq!(std::fs::read_to_string(&driver).unwrap(), driver_text);
    // The C template stays the default.
    let out = run(&["init", "--external", "csim"]);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    assert!(!dir.path().join("csim.py").exists());
}

#[test]
fn the_python_driver_computes_our_galaxy_and_its_config_sweeps() {
    if !python3() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let run = |args: &[&str]| bin().current_dir(dir.path()).args(args).output().unwrap();
    let out = run(&["init", "--external", "pysim", "--lang", "python"]);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));

    // The same bodies and steps as our symmetric kernel: the same energies, to rounding.
    // The driver on 40 exported bodies of `scenario`, for `steps` steps.
    let driver = |scenario: &str, file: &str, steps: &str| {
        let out = run(&[
            "export",
            "--scenario",
            scenario,
            "-n",
            "40",
            "--format",
            "text",
            "--out",
            file,
        ]);
        assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
        std::process::Command::new("python3")
            .current_dir(dir.path())
            .args(["pysim.py", "--n", "40", "--steps", steps, "--initial", file])
            .output()
            .unwrap()
    };
    let out = driver("galaxy", "s.txt", "10");
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    let (e0, e1) = driver_energies(&text(&out.stdout));
    let (initial, last) = run_energies(
        dir.path(),
        &[
            "run",
            "--scenario",
            "galaxy",
            "--kernel",
            "symmetric",
            "-n",
            "40",
            "--steps",
            "10",
        ],
    );
    for (ours, theirs) in [(initial, e0), (last, e1)] {
        assert!(
            (ours - theirs).abs() <= 1e-8 * ours.abs(),
            "{ours} vs {theirs}"
        );
    }
    // The same bodies with another law are refused, with what to do.
    let out = driver("lj-box", "lj.txt", "1");
    assert_eq!(out.status.code(), Some(2));
    assert!(text(&out.stderr).contains("export the `galaxy` scenario"));

    let out = run(&["sweep", "--config", "pysim.toml", "--dry-run"]);
    let said = format!("{}{}", text(&out.stdout), text(&out.stderr));
    assert_eq!(out.status.code(), Some(0), "{said}");
    assert!(said.contains("galaxy/pysim/n=250/p=1/r=1/seed=1"), "{said}");
    assert!(!said.contains("galaxy/pysim/n=250/p=2/"), "{said}");
    // Steps that fall as n grows: 2.5e6 / 250² and / 1000² (rounded).
    assert!(
        said.contains("40 steps") && said.contains("3 steps"),
        "{said}"
    );

    // One small n, one kernel, two samples in one round: a real sweep in about a second.
    let (results, keys) = sweep_cut_down(
        dir.path(),
        "pysim",
        &[
            ("\nn = [250, 500, 1000]\n", "\nn = [40]\n"),
            ("\nthreads = [1, 2]\n", "\nthreads = [1]\n"),
            (
                "\nkernels = [\"symmetric\", \"naive\", \"octree\"]\n",
                "\nkernels = [\"symmetric\"]\n",
            ),
            // 16000 / 40² = 10 steps a run.
            (
                "\nsteps = { work = 2.5e6, grows = \"n^2\" }\n",
                "\nsteps = { work = 16000, grows = \"n^2\" }\n",
            ),
            ("\nsamples = 5\n", "\nsamples = 2\n"),
            ("\nrounds = 2\n", "\nrounds = 1\n"),
        ],
    );
    assert_eq!(
        keys,
        [
            "galaxy/symmetric/n=40/p=1/r=1/seed=1",
            "galaxy/pysim/n=40/p=1/r=1/seed=1"
        ]
    );
    let case = &results.cases[1];
    assert!(case.is_complete());
    assert_eq!(case.summary.as_ref().map(|s| s.samples), Some(2));
    for round in &case.rounds {
        let runs = &round.external.as_ref().unwrap().runs;
        assert_eq!(runs.len(), 2);
        // Each sample is the printed loop time over the run's 10 steps.
        assert_eq!(round.steps_per_sample, 10);
        for (run, sample) in runs.iter().zip(&round.samples_s) {
            let printed = run.reported_s.unwrap();
            assert!(printed > 0.0 && (sample * 10.0 - printed).abs() <= 1e-12 * printed);
        }
    }
    let version = &results.metadata.externals[0];
    assert!(version.version.starts_with("Python 3"), "{version:?}");
    // The program's output is kept in its case's work directory.
    let stdout = dir
        .path()
        .join("out/pysim/work/galaxy_pysim_n=40_p=1_r=1_seed=1/stdout.txt");
    let kept = std::fs::read_to_string(&stdout).unwrap();
    assert!(
        kept.contains("relative drift") && kept.contains("time total"),
        "{kept}"
    );
}
