//! `run --initial` and the Lennard-Jones options of `run`: an exported state starts the same
//! run as the seed that made it, a Barnes-Hut body file starts galaxy with its bodies, a bad
//! file is refused at its line, and ε, σ and g reach the law and the field.

use crate::{bin, refused, text};
use std::path::Path;
use std::process::Output;

fn nbody(args: &[&str]) -> Output {
    bin().args(args).output().unwrap()
}

fn ok(o: &Output) -> String {
    assert!(o.status.success(), "{}", text(&o.stderr));
    text(&o.stdout)
}

fn export(dir: &Path, name: &str, args: &[&str]) -> std::path::PathBuf {
    let out = dir.join(name);
    let mut all = vec!["export", "--format", "text", "--out", out.to_str().unwrap()];
    all.extend_from_slice(args);
    ok(&nbody(&all));
    out
}

/// The `--dump-state` text of a run of `args` for `steps` steps with the naive kernel.
fn dump(dir: &Path, name: &str, steps: &str, args: &[&str]) -> String {
    let out = dir.join(name);
    let mut all = vec!["run", "--kernel", "naive", "--steps", steps, "--dump-state"];
    all.push(out.to_str().unwrap());
    all.extend_from_slice(args);
    ok(&nbody(&all));
    std::fs::read_to_string(out).unwrap()
}

#[test]
fn an_exported_state_starts_the_same_run_as_its_seed() {
    let dir = tempfile::tempdir().unwrap();
    for (scenario, n) in [("lj-box", "200"), ("coulomb", "60"), ("galaxy", "100")] {
        let file = export(dir.path(), "a.txt", &["--scenario", scenario, "-n", n]);
        let f = file.to_str().unwrap();
        // The state the file starts is the exported one, exactly.
        let again = export(
            dir.path(),
            "b.txt",
            &["--scenario", scenario, "--initial", f],
        );
        assert_eq!(
            std::fs::read_to_string(&file).unwrap(),
            std::fs::read_to_string(&again).unwrap(),
            "{scenario}"
        );
        // And it runs as the seed's state does.
        let seeded = dump(dir.path(), "s.txt", "5", &["--scenario", scenario, "-n", n]);
        let started = dump(
            dir.path(),
            "f.txt",
            "5",
            &["--scenario", scenario, "--initial", f],
        );
        assert_eq!(seeded, started, "{scenario}");
        // -n equal to the file's count is accepted.
        ok(&nbody(&[
            "run",
            "--scenario",
            scenario,
            "--kernel",
            "naive",
            "--steps",
            "1",
            "--initial",
            f,
            "-n",
            n,
        ]));
    }
}

#[test]
fn a_body_file_with_comments_and_blank_lines_starts_galaxy() {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("nbody_start.txt");
    std::fs::write(
        &file,
        "# m x y z vx vy vz\n\n1000 0 0 0 0 0 0\n# a planet\n1 3 0 0 0 18 0\n   \n\
         0.5 -1 2 0.25 0 0 0.1\n0.25\t0 -4 1 1 0 0\n",
    )
    .unwrap();
    let f = file.to_str().unwrap();
    let json = dir.path().join("r.json");
    let stdout = ok(&nbody(&[
        "run",
        "--scenario",
        "galaxy",
        "--kernel",
        "octree",
        "--steps",
        "2",
        "--initial",
        f,
        "--json",
        json.to_str().unwrap(),
    ]));
    assert!(stdout.contains("n = 4, 2 steps"), "{stdout}");
    assert!(stdout.contains(&format!("bodies from {f}")), "{stdout}");
    let v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    assert_eq!((v["n"].as_u64(), v["initial"].as_str()), (Some(4), Some(f)));
    // One step so short that nobody moves measurably: the bodies are the file's, in its order.
    let state = dump(
        dir.path(),
        "d.txt",
        "1",
        &["--scenario", "galaxy", "--initial", f, "--dt", "1e-12"],
    );
    let rows: Vec<Vec<f64>> = state
        .lines()
        .filter(|l| !l.starts_with('#'))
        .map(|l| l.split(' ').map(|x| x.parse().unwrap()).collect())
        .collect();
    let want = [
        [1000.0, 0.0, 0.0, 0.0],
        [1.0, 3.0, 0.0, 0.0],
        [0.5, -1.0, 2.0, 0.25],
        [0.25, 0.0, -4.0, 1.0],
    ];
    assert_eq!(rows.len(), 4);
    for (row, [m, x, y, z]) in rows.iter().zip(want) {
        // id x y z vx vy vz mass strength fx fy fz
        assert_eq!((row[7], row[8]), (m, m), "{row:?}");
        for (got, want) in row[1..4].iter().zip([x, y, z]) {
            assert!((got - want).abs() < 1e-6, "{row:?}");
        }
    }
    assert!((rows[1][5] - 18.0).abs() < 1e-6, "{:?}", rows[1]);
}

#[test]
fn a_bad_initial_file_is_refused_at_its_line() {
    let dir = tempfile::tempdir().unwrap();
    let lj = export(dir.path(), "lj.txt", &["--scenario", "lj-box", "-n", "20"]);
    let lj_text = std::fs::read_to_string(&lj).unwrap();
    let good = "# bodies\n1 0 0 0 0 0 0\n";
    // The body of id 3 (line 10) moved to x = 5, far outside the box of side 0.2.
    let outside: Vec<String> = lj_text
        .lines()
        .map(|l| match l.strip_prefix("3 ") {
            Some(rest) => format!("3 5e0 {}", rest.split_once(' ').unwrap().1),
            None => l.to_string(),
        })
        .collect();
    let outside = outside.join("\n");
    // (scenario, file, where: what follows the path, what)
    let second_columns_at = format!(" line {}:", lj_text.lines().count() + 1);
    let cases: Vec<(&str, String, &str, &str)> = vec![
        (
            "galaxy",
            format!("{good}1 0 0 0 0 0\n"),
            " line 3:",
            "6 values where 7 were expected",
        ),
        (
            "galaxy",
            format!("{good}\n1 0 0 1e0x 0 0 0\n"),
            " line 4:",
            "`1e0x` (column 4, z) is not a number",
        ),
        (
            "galaxy",
            format!("{good}1 0 0 0 nan 0 0\n"),
            " line 3:",
            "vx (column 5) is NaN",
        ),
        (
            "galaxy",
            format!("{good}1 inf 0 0 0 0 0\n"),
            " line 3:",
            "x (column 2) is inf",
        ),
        (
            "galaxy",
            format!("{good}-1 0 0 0 0 0 0\n"),
            " line 3:",
            "mass -1 is not positive",
        ),
        (
            "galaxy",
            lj_text.clone(),
            " line 6:",
            "the bodies are 2-D (export format) but scenario `galaxy` is 3-D",
        ),
        (
            "lj-box",
            good.to_string(),
            " line 2:",
            "3-D (barnes-hut format) but scenario `lj-box` is 2-D",
        ),
        (
            "coulomb",
            good.to_string(),
            " line 2:",
            "gives masses, not charges",
        ),
        (
            "lj-box",
            outside,
            " line 10:",
            "is outside the reflecting box [0, 0.2]^2",
        ),
        (
            "galaxy",
            "# only a comment\n\n".to_string(),
            ": no bodies",
            "(2 lines of comments",
        ),
        // A second columns line would read the bodies after it in another dimension.
        (
            "lj-box",
            format!("{lj_text}# columns: id x y z vx vy vz mass strength\n"),
            &second_columns_at,
            "a second `# columns:` line",
        ),
    ];
    for (i, (scenario, content, at, what)) in cases.into_iter().enumerate() {
        let file = dir.path().join(format!("bad{i}.txt"));
        std::fs::write(&file, content).unwrap();
        let f = file.to_str().unwrap();
        let o = nbody(&[
            "run",
            "--scenario",
            scenario,
            "--kernel",
            "naive",
            "--initial",
            f,
        ]);
        refused(&o, &format!("initial state {f}{at}"));
        refused(&o, what);
    }
    let f = lj.to_str().unwrap();
    let run = |extra: &[&str]| {
        let mut args = vec![
            "run",
            "--scenario",
            "lj-box",
            "--kernel",
            "naive",
            "--initial",
            f,
        ];
        args.extend_from_slice(extra);
        nbody(&args)
    };
    refused(
        &run(&["-n", "21"]),
        &format!("n = 21 was asked but the initial state {f} holds 20 bodies"),
    );
    refused(
        &run(&["--t0", "2"]),
        "--t0 sets the velocities of generated particles",
    );
    let missing = dir.path().join("missing.txt");
    let o = nbody(&[
        "run",
        "--scenario",
        "galaxy",
        "--kernel",
        "naive",
        "--initial",
        missing.to_str().unwrap(),
    ]);
    refused(
        &o,
        &format!("cannot read initial state {}", missing.display()),
    );
}

#[test]
fn the_lennard_jones_options_change_the_law_and_the_field() {
    let dir = tempfile::tempdir().unwrap();
    let plain = dump(
        dir.path(),
        "p.txt",
        "2",
        &["--scenario", "lj-box", "-n", "100"],
    );
    assert!(
        plain
            .lines()
            .nth(2)
            .unwrap()
            .contains("epsilon 1 sigma 0.01 rc 0.025"),
        "{plain}"
    );
    let changed = dump(
        dir.path(),
        "c.txt",
        "2",
        &[
            "--scenario",
            "lj-liquid",
            "-n",
            "100",
            "--epsilon",
            "2",
            "--sigma",
            "0.02",
            "--g",
            "3",
        ],
    );
    let law = changed.lines().nth(2).unwrap();
    assert_eq!(
        law,
        "# law lennard-jones epsilon 2 sigma 0.02 rc 0.05 force truncated"
    );
    let field = |args: &[&str]| {
        let file = export(dir.path(), "e.txt", args);
        let text = std::fs::read_to_string(file).unwrap();
        text.lines()
            .find(|l| l.starts_with("# external"))
            .unwrap()
            .to_string()
    };
    assert_eq!(
        field(&["--scenario", "lj-box", "-n", "50"]),
        "# external acceleration [0.0, -1.0]"
    );
    assert_eq!(
        field(&["--scenario", "lj-liquid", "-n", "50", "--g", "-2.5"]),
        "# external acceleration [0.0, 2.5]"
    );
    // T0 = 0: the generated particles start at rest.
    let cold = export(
        dir.path(),
        "t.txt",
        &["--scenario", "lj-box", "-n", "50", "--t0", "0"],
    );
    let rows = std::fs::read_to_string(cold).unwrap();
    for row in rows.lines().filter(|l| !l.starts_with('#')) {
        let cols: Vec<f64> = row.split(' ').map(|x| x.parse().unwrap()).collect();
        assert_eq!(&cols[3..5], &[0.0, 0.0], "{row}");
    }
    // Refused where they mean nothing, and for values the law cannot take.
    for (scenario, flag, value) in [
        ("galaxy", "--epsilon", "2"),
        ("coulomb", "--g", "1"),
        ("galaxy", "--t0", "1"),
    ] {
        let o = nbody(&[
            "run",
            "--scenario",
            scenario,
            "--kernel",
            "naive",
            flag,
            value,
        ]);
        refused(
            &o,
            &format!(
                "{flag} applies to the Lennard-Jones scenarios (lj-box, lj-liquid, lj-gas, lj-melt) only; scenario `{scenario}`"
            ),
        );
    }
    let o = nbody(&[
        "run",
        "--scenario",
        "lj-box",
        "--kernel",
        "naive",
        "--sigma",
        "0",
    ]);
    refused(&o, "must be greater than 0");
    let o = nbody(&[
        "run",
        "--scenario",
        "lj-box",
        "--kernel",
        "naive",
        "--t0",
        "-1",
    ]);
    refused(&o, "must be 0 or greater");
}

/// A sweep of `config_text` written into `dir` (its `initial` relative to `dir`): the results, or the
/// command's exit code and error output.
fn sweep_config(dir: &Path, config_text: &str) -> Result<String, (Option<i32>, String)> {
    let config = dir.join("from-file.toml");
    std::fs::write(&config, config_text).unwrap();
    let out = nbody(&[
        "sweep",
        "--config",
        config.to_str().unwrap(),
        "--out",
        dir.join("out").to_str().unwrap(),
        "--no-calibration",
        "--yes",
    ]);
    if out.status.success() {
        Ok(std::fs::read_to_string(dir.join("out/from-file/results.json")).unwrap())
    } else {
        Err((out.status.code(), text(&out.stderr)))
    }
}

#[test]
fn a_sweep_starts_every_case_from_the_configs_file_of_bodies() {
    let dir = tempfile::tempdir().unwrap();
    export(
        dir.path(),
        "galaxy.txt",
        &["--scenario", "galaxy", "-n", "64", "--seed", "9"],
    );
    let config = |n: usize, extra: &str| {
        format!(
            "name = \"from-file\"\nstudy = \"cartesian\"\nscenarios = [\"galaxy\"]\n\
             kernels = [\"naive\", \"octree\"]\nn = [{n}]\nthreads = [1]\n\
             initial = \"galaxy.txt\"\n{extra}\n[measure]\nwarmup_s = 0.001\nsamples = 2\n\
             rounds = 1\nmin_sample_s = 0.001\n"
        )
    };
    let results = sweep_config(dir.path(), &config(64, "")).unwrap();
    let file: nbody_records::results::ResultsFile = serde_json::from_str(&results).unwrap();
    let record = file.metadata.initial.expect("the file recorded");
    assert!(record.path.ends_with("galaxy.txt") && Path::new(&record.path).is_absolute());
    assert_eq!((record.format.as_str(), record.bodies), ("export", 64));
    assert_eq!(record.fnv1a.len(), 16);
    assert!(file.cases.iter().all(|c| c.summary.is_some()));
    // Other bodies in the same file do not resume the sweep that started from the old ones.
    std::fs::remove_file(dir.path().join("galaxy.txt")).unwrap();
    export(
        dir.path(),
        "galaxy.txt",
        &["--scenario", "galaxy", "-n", "64", "--seed", "10"],
    );
    let resumed = nbody(&[
        "sweep",
        "--config",
        dir.path().join("from-file.toml").to_str().unwrap(),
        "--out",
        dir.path().join("out").to_str().unwrap(),
        "--resume",
        "--no-calibration",
    ]);
    assert_eq!(resumed.status.code(), Some(2));
    assert!(
        text(&resumed.stderr).contains("fingerprint"),
        "{}",
        text(&resumed.stderr)
    );
    // The file's n is the only n; a bad file is refused at its line; neither runs anything.
    let (code, err) = sweep_config(dir.path(), &config(50, "")).unwrap_err();
    assert_eq!(code, Some(2), "{err}");
    assert!(err.contains("64"), "{err}");
    std::fs::write(
        dir.path().join("galaxy.txt"),
        "1 0 0 0 0 0 0\n1 0 0 x 0 0 0\n",
    )
    .unwrap();
    let (code, err) = sweep_config(dir.path(), &config(2, "")).unwrap_err();
    assert_eq!(code, Some(2), "{err}");
    assert!(err.contains("line 2"), "{err}");
    let weak = config(2, "[weak]\nrule = \"linear\"\nbase_n = 2").replace("cartesian", "weak");
    let (code, err) = sweep_config(dir.path(), &weak).unwrap_err();
    assert_eq!(code, Some(2), "{err}");
    assert!(err.contains("initial"), "{err}");
}

/// The file of bodies a run or an export starts from is an input: naming it (or a link to it)
/// as an output is refused before anything runs, and the file stays as it was.
#[test]
fn the_initial_file_is_never_overwritten() {
    let dir = tempfile::tempdir().unwrap();
    let bodies = export(
        dir.path(),
        "bodies.txt",
        &["--scenario", "lj-box", "-n", "20"],
    );
    let before = std::fs::read(&bodies).unwrap();
    let link = dir.path().join("link.txt");
    std::os::unix::fs::symlink(&bodies, &link).unwrap();
    let f = bodies.to_str().unwrap();
    for target in [f, link.to_str().unwrap()] {
        for flag in ["--dump-state", "--json", "--trajectory"] {
            let o = nbody(&[
                "run",
                "--scenario",
                "lj-box",
                "--kernel",
                "naive",
                "--steps",
                "2",
                "--initial",
                f,
                flag,
                target,
            ]);
            assert_eq!(
                o.status.code(),
                Some(2),
                "{flag} {target}: {}",
                text(&o.stderr)
            );
            let err = text(&o.stderr);
            assert!(err.contains("--initial"), "{flag}: {err}");
        }
        for format in ["text", "npy", "lammps-data"] {
            let o = nbody(&[
                "export",
                "--scenario",
                "lj-box",
                "--initial",
                f,
                "--format",
                format,
                "--out",
                target,
            ]);
            assert_eq!(
                o.status.code(),
                Some(2),
                "export {format}: {}",
                text(&o.stderr)
            );
        }
    }
    assert_eq!(
        std::fs::read(&bodies).unwrap(),
        before,
        "the bodies are untouched"
    );
}
