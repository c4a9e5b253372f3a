//! `nbody-bench init --external NAME --lang python --physics lj`: the Lennard-Jones driver
//! computes our `lj-melt` physics (the energies of a run of our periodic naive kernel from the
//! same exported atoms), refuses a 2-D state with what to export, and its config, cut down to
//! one small n, sweeps it through the binary with the sweep's thread count passed on.

use super::init_python::{driver_energies, python3, run_energies, sweep_cut_down};
use super::{bin, refused, text};

#[test]
fn the_lj_driver_computes_our_melt_and_its_config_sweeps() {
    if !python3() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let run = |args: &[&str]| bin().current_dir(dir.path()).args(args).output().unwrap();
    let out = run(&[
        "init",
        "--external",
        "md",
        "--lang",
        "python",
        "--physics",
        "lj",
    ]);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    assert!(
        text(&out.stderr).contains("export --scenario lj-melt"),
        "{}",
        text(&out.stderr)
    );

    // 256 atoms in f64, the driver and our naive kernel 10 steps each: the same energies.
    let export = |scenario: &str, file: &str, n: &str| {
        let out = run(&[
            "export",
            "--scenario",
            scenario,
            "-n",
            n,
            "--precision",
            "f64",
            "--format",
            "lammps-data",
            "--out",
            file,
        ]);
        assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    };
    let driver = |file: &str| {
        std::process::Command::new("python3")
            .current_dir(dir.path())
            .args([
                "md.py",
                "--initial",
                file,
                "--steps",
                "10",
                "--threads",
                "2",
            ])
            .output()
            .unwrap()
    };
    export("lj-melt", "melt.data", "256");
    let out = driver("melt.data");
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    let (e0, e1) = driver_energies(&text(&out.stdout));
    let (initial, last) = run_energies(
        dir.path(),
        &[
            "run",
            "--scenario",
            "lj-melt",
            "--kernel",
            "naive",
            "-n",
            "256",
            "--steps",
            "10",
            "--precision",
            "f64",
        ],
    );
    // The energies differ from the start by more than rounding when a pair, an image or the
    // step were wrong; 10 steps of the melt move each atom about 0.06 sigma.
    assert!((initial - e0).abs() <= 1e-9 * e0.abs(), "{initial} vs {e0}");
    assert!((last - e1).abs() <= 1e-8 * e1.abs(), "{last} vs {e1}");
    assert!(
        (e1 - e0).abs() > 1e-6 * e0.abs(),
        "the atoms moved: {e0} {e1}"
    );

    // A 2-D state (the walled lj-box) is refused with what to export.
    export("lj-box", "box.data", "100");
    let out = driver("box.data");
    assert_eq!(out.status.code(), Some(2));
    assert!(text(&out.stderr).contains("export the `lj-melt` scenario"));
    // So is a box under twice the cutoff (the export refuses one: the melt's box, narrowed).
    let melt = std::fs::read_to_string(dir.path().join("melt.data")).unwrap();
    let narrowed: String = melt
        .lines()
        .map(|l| match l.ends_with(" xlo xhi") {
            true => "0 4.9 xlo xhi\n".to_string(),
            false => format!("{l}\n"),
        })
        .collect();
    assert!(narrowed.contains("0 4.9 xlo xhi"), "{melt}");
    std::fs::write(dir.path().join("tiny.data"), narrowed).unwrap();
    let out = driver("tiny.data");
    assert_eq!(out.status.code(), Some(2));
    assert!(text(&out.stderr).contains("under twice the cutoff"));
    // And a line that is not an atom's, at its line number.
    let broken = melt.replacen("\n1 1 ", "\nx 1 ", 1);
    assert_ne!(broken, melt);
    std::fs::write(dir.path().join("broken.data"), broken).unwrap();
    let out = driver("broken.data");
    assert_eq!(out.status.code(), Some(2));
    assert!(
        text(&out.stderr).contains("expected an atom id"),
        "{}",
        text(&out.stderr)
    );

    let out = run(&["sweep", "--config", "md.toml", "--dry-run"]);
    let said = format!("{}{}", text(&out.stdout), text(&out.stderr));
    assert_eq!(out.status.code(), Some(0), "{said}");
    assert!(said.contains("lj-melt/md/n=4000/p=1/r=1/seed=1"), "{said}");
    assert!(said.contains("lj-melt/cluster-pair/n=4000/p=2/"), "{said}");
    assert!(!said.contains("lj-melt/md/n=4000/p=2/"), "{said}");

    // The driver told two threads (the config's line for a code that uses them), one small n,
    // our naive kernel beside it: a real sweep in about a second.
    let (results, keys) = sweep_cut_down(
        dir.path(),
        "md",
        &[
            ("\nn = [4000]\n", "\nn = [256]\n"),
            ("\nthreads = [1, 2]\n", "\nthreads = [2]\n"),
            (
                "\nkernels = [\"verlet\", \"cluster-pair\"]\n",
                "\nkernels = [\"naive\"]\n",
            ),
            ("\nthreads = [1]\n", "\nthreads = [2]\n"),
            (
                "\nsteps = { work = 12000, grows = \"n\" }\n",
                "\nsteps = 2\n",
            ),
            ("\nsamples = 4\n", "\nsamples = 2\n"),
            ("\nrounds = 2\n", "\nrounds = 1\n"),
        ],
    );
    assert_eq!(
        keys,
        [
            "lj-melt/naive/n=256/p=2/r=1/seed=1",
            "lj-melt/md/n=256/p=2/r=1/seed=1"
        ]
    );
    assert!(results.cases[1].is_complete());
    let stdout = dir
        .path()
        .join("out/md/work/lj-melt_md_n=256_p=2_r=1_seed=1/stdout.txt");
    let kept = std::fs::read_to_string(&stdout).unwrap();
    assert!(kept.contains("threads 2 from"), "{kept}");
}

#[test]
fn the_lj_template_is_pythons_alone() {
    let dir = tempfile::tempdir().unwrap();
    let out = bin()
        .current_dir(dir.path())
        .args(["init", "--external", "md", "--physics", "lj"])
        .output()
        .unwrap();
    refused(&out, "--lang python");
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
}
