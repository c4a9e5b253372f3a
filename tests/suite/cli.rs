//! The command line: help, every bad input gives exit code 2 and a message (never a panic),
//! `run --json` has the documented fields, dumps are reproducible, `validate` passes.

use std::path::Path;
use std::process::{Command, Output};

fn bin(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_nbody-bench"))
        .args(args)
        .output()
        .expect("binary runs")
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

#[test]
fn help_and_list() {
    for args in [
        &["--help"][..],
        &["run", "--help"],
        &["validate", "--help"],
        &["list", "--help"],
    ] {
        let o = bin(args);
        assert!(o.status.success(), "{args:?}");
        assert!(String::from_utf8_lossy(&o.stdout).contains("Usage"));
    }
    let o = bin(&["list"]);
    let out = String::from_utf8_lossy(&o.stdout);
    assert!(o.status.success());
    for word in [
        "naive",
        "symmetric",
        "per-thread",
        "cell-list",
        "octree",
        "lj-box",
        "lj-liquid",
        "coulomb",
        "galaxy",
    ] {
        assert!(out.contains(word), "list lacks {word}");
    }
    assert!(out.contains("galaxy     (gravity): naive, symmetric, per-thread, octree"));
    // The top-level help's summary names every kernel the binary has.
    let help = String::from_utf8_lossy(&bin(&["--help"]).stdout).into_owned();
    let summary = help.split("Exit codes").next().unwrap_or_default();
    for kind in nbody_engine::kernels::KernelKind::ALL {
        assert!(
            summary.contains(kind.name()),
            "--help's summary lacks the {} kernel",
            kind.name()
        );
    }
}

#[test]
fn bad_input_exits_2_with_a_message() {
    let cases: &[(&[&str], &str)] = &[
        (
            &["run", "--scenario", "lj-box", "--kernel", "fast"],
            "invalid value 'fast'",
        ),
        (
            &["run", "--scenario", "box", "--kernel", "naive"],
            "invalid value 'box'",
        ),
        (
            &[
                "run",
                "--scenario",
                "lj-box",
                "--kernel",
                "naive",
                "-n",
                "0",
            ],
            "must be at least 1",
        ),
        (
            &[
                "run",
                "--scenario",
                "lj-box",
                "--kernel",
                "naive",
                "--dt",
                "-1e-4",
            ],
            "must be greater than 0",
        ),
        (
            &[
                "run",
                "--scenario",
                "lj-box",
                "--kernel",
                "naive",
                "--dt",
                "NaN",
            ],
            "must be finite",
        ),
        (
            &[
                "run",
                "--scenario",
                "galaxy",
                "--kernel",
                "octree",
                "--theta",
                "-0.5",
            ],
            "must be 0 or greater",
        ),
        (
            &[
                "run",
                "--scenario",
                "galaxy",
                "--kernel",
                "octree",
                "--theta",
                "nan",
            ],
            "must be finite",
        ),
        (
            &[
                "run",
                "--scenario",
                "lj-box",
                "--kernel",
                "naive",
                "--density",
                "0",
            ],
            "must be greater than 0",
        ),
        (
            &[
                "run",
                "--scenario",
                "lj-box",
                "--kernel",
                "naive",
                "--threads",
                "0",
            ],
            "must be at least 1",
        ),
        (
            &[
                "run",
                "--scenario",
                "galaxy",
                "--kernel",
                "naive",
                "-n",
                "1000000000",
            ],
            "more than this tool handles",
        ),
        (
            &["run", "--scenario", "galaxy", "--kernel", "cell-list"],
            "kernels for gravity: naive, symmetric, per-thread, octree",
        ),
        (
            &["run", "--scenario", "lj-box", "--kernel", "octree"],
            "kernels for lennard-jones: naive, symmetric, per-thread, cell-list",
        ),
        (
            &[
                "run",
                "--scenario",
                "galaxy",
                "--kernel",
                "naive",
                "--density",
                "5",
            ],
            "has no density parameter",
        ),
        (
            &[
                "run",
                "--scenario",
                "lj-box",
                "--kernel",
                "naive",
                "-n",
                "20000",
                "--density",
                "20000",
            ],
            "--allow-fewer",
        ),
        (
            &[
                "run",
                "--scenario",
                "lj-box",
                "--kernel",
                "naive",
                "--dt",
                "10",
                "--steps",
                "5",
            ],
            "reduce --dt",
        ),
        (
            &[
                "run",
                "--scenario",
                "lj-box",
                "--kernel",
                "naive",
                "--steps",
                "2",
                "--json",
                "/nonexistent/r.json",
            ],
            "/nonexistent/r.json",
        ),
        (
            &[
                "run",
                "--scenario",
                "lj-box",
                "--kernel",
                "naive",
                "--every",
                "5",
            ],
            "--trajectory",
        ),
        (&["frobnicate"], "unrecognized subcommand"),
    ];
    for (args, expected) in cases {
        let o = bin(args);
        let err = stderr(&o);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {err}");
        assert!(
            err.contains(expected),
            "{args:?}: expected `{expected}` in: {err}"
        );
        assert!(!err.contains("panicked"), "{args:?} panicked: {err}");
    }
}

/// The `run --json` document of a run of `kernel` on lj-box.
fn run_json(kernel: &str, n: usize, steps: u64) -> serde_json::Value {
    let dir = tempfile::tempdir().unwrap();
    let json = dir.path().join("r.json");
    let (n, steps) = (n.to_string(), steps.to_string());
    let o = bin(&[
        "run",
        "--scenario",
        "lj-box",
        "--kernel",
        kernel,
        "-n",
        &n,
        "--steps",
        &steps,
        "--json",
        json.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap()
}

#[test]
fn run_json_has_the_documented_fields() {
    let v = run_json("cell-list", 400, 30);
    for path in [
        "/schema",
        "/scenario",
        "/kernel",
        "/n",
        "/steps",
        "/threads",
        "/dim",
        "/precision",
        "/seed",
        "/timing/total_s",
        "/timing/per_step_ns/p50",
        "/timing/per_step_ns/p90",
        "/timing/per_step_ns/p99",
        "/timing/per_step_ns/max",
        "/timing/phases/force_build",
        "/timing/phases/force_interact",
        "/timing/phases/integrate",
        "/timing/phases/boundary",
        "/timing/phases/output",
        "/throughput/particle_steps_per_s",
        "/throughput/pair_evals_per_s",
        "/counters/total/pair_checks",
        "/counters/total/cells_visited",
        "/energy/rel_drift",
    ] {
        assert!(v.pointer(path).is_some(), "missing {path}");
    }
    assert_eq!(v["schema"], "nbody-bench/run/v1");
    assert_eq!(
        (v["n"].as_u64(), v["steps"].as_u64(), v["dim"].as_u64()),
        (Some(400), Some(30), Some(2))
    );
    assert_eq!(v["precision"], "f32");
    assert!(v["timing"]["per_step_ns"]["p50"].as_u64().unwrap() > 0);
    assert!(v["counters"]["total"]["pair_checks"].as_u64().unwrap() > 0);
}

#[test]
fn run_reports_the_mean_step_not_the_median_one() {
    // The Verlet list rebuilds every few steps: the median step is one without a rebuild, and
    // a cost per particle-step from it would leave the rebuilds out.
    let v = run_json("verlet", 2000, 60);
    let t = &v["timing"];
    let (steps_s, per) = (
        t["steps_s"].as_f64().unwrap(),
        t["ns_per_particle_step"].as_f64().unwrap(),
    );
    let mean = steps_s * 1e9 / (60.0 * 2000.0);
    assert!((per - mean).abs() <= 1e-9 * mean, "{per} vs {mean}");
    assert!(steps_s <= t["total_s"].as_f64().unwrap());
    assert!(v["counters"]["total"]["rebuilds"].as_u64().unwrap() > 0);
    let ps = v["throughput"]["particle_steps_per_s"].as_f64().unwrap();
    assert!(
        (ps * per * 1e-9 - 1.0).abs() < 1e-9,
        "{ps} and {per} disagree"
    );
}

fn dump(dir: &Path, name: &str, extra: &[&str]) -> String {
    let path = dir.join(name);
    let mut args = vec![
        "run",
        "--scenario",
        "galaxy",
        "-n",
        "300",
        "--steps",
        "20",
        "--dump-state",
        path.to_str().unwrap(),
    ];
    args.extend_from_slice(extra);
    let o = bin(&args);
    assert!(o.status.success(), "{}", stderr(&o));
    std::fs::read_to_string(path).unwrap()
}

#[test]
fn state_dumps_are_reproducible_and_documented() {
    let dir = tempfile::tempdir().unwrap();
    let a = dump(
        dir.path(),
        "a.txt",
        &["--kernel", "naive", "--threads", "1"],
    );
    let b = dump(
        dir.path(),
        "b.txt",
        &["--kernel", "naive", "--threads", "2"],
    );
    assert_eq!(
        a, b,
        "naive computes each row the same way on any thread count"
    );
    let lines: Vec<&str> = a.lines().collect();
    assert_eq!(lines[0], "# nbody-bench state v2");
    assert_eq!(
        lines[1],
        "# scenario galaxy dim 3 precision f64 n 300 seed 1 steps 20 dt 0.001"
    );
    assert!(lines[2].starts_with("# law gravity G "), "{}", lines[2]);
    assert_eq!(
        lines[3],
        "# columns: id x y z vx vy vz mass strength fx fy fz"
    );
    assert_eq!(lines.len(), 304);
    assert!(lines[4].starts_with("0 ") && lines[303].starts_with("299 "));
    // Another kernel differs by rounding only.
    let c = dump(dir.path(), "c.txt", &["--kernel", "symmetric"]);
    for (la, lc) in a.lines().zip(c.lines()).skip(4) {
        let xa: Vec<f64> = la.split(' ').map(|x| x.parse().unwrap()).collect();
        let xc: Vec<f64> = lc.split(' ').map(|x| x.parse().unwrap()).collect();
        for (p, q) in xa.iter().zip(&xc).take(7) {
            assert!((p - q).abs() <= 1e-9 * p.abs().max(1.0), "{la} vs {lc}");
        }
    }
}

#[test]
fn trajectory_is_written_in_nbview_binary() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("t.nbv");
    let o = bin(&[
        "run",
        "--scenario",
        "lj-box",
        "--kernel",
        "naive",
        "-n",
        "50",
        "--steps",
        "20",
        "--every",
        "5",
        "--trajectory",
        path.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let t = nbody_engine::output::nbview::read_binary(std::fs::File::open(&path).unwrap()).unwrap();
    assert_eq!((t.n, t.frames.len()), (50, 5));
    assert!((t.scale - 0.316).abs() < 0.01, "scale {}", t.scale);
}

#[test]
fn validate_passes_for_every_scenario_and_dumps_forces() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("f.txt");
    let o = bin(&[
        "validate",
        "-n",
        "700",
        "--threads",
        "2",
        "--dump",
        path.to_str().unwrap(),
    ]);
    let out = String::from_utf8_lossy(&o.stdout);
    assert!(o.status.success(), "{out}\n{}", stderr(&o));
    // The melt's largest lattice within 700 atoms is a box too small for verlet's bins.
    assert!(
        out.contains("all kernels checked agree with the reference; skipped: lj-melt/verlet"),
        "{out}"
    );
    let text = std::fs::read_to_string(dir.path().join("f.txt.coulomb")).unwrap();
    assert!(
        text.lines()
            .nth(3)
            .unwrap()
            .starts_with("# columns: id x y z strength fx_ref fy_ref fz_ref fx_naive")
    );
    assert_eq!(text.lines().count(), 704);
    for scenario in ["coulomb", "galaxy"] {
        let path = dir.path().join(format!("f.txt.{scenario}"));
        recomputes_from_the_dump(&std::fs::read_to_string(path).unwrap());
    }
}

/// The value after `word` on a header line.
fn header_value(line: &str, word: &str) -> f64 {
    let mut it = line.split(' ');
    it.find(|w| *w == word)
        .and_then(|_| it.next())
        .and_then(|v| v.parse().ok())
        .unwrap_or_else(|| panic!("no `{word} <number>` in {line}"))
}

/// Another code's check of a force dump: from the positions, the strengths and the law line
/// alone, a direct sum (written here, independently of the crate's laws) gives the reference
/// forces of the dump.
fn recomputes_from_the_dump(text: &str) {
    let law = text.lines().nth(2).unwrap();
    let rows: Vec<Vec<f64>> = text
        .lines()
        .filter(|l| !l.starts_with('#'))
        .map(|l| l.split(' ').map(|x| x.parse().unwrap()).collect())
        .collect();
    // id x y z strength fx_ref fy_ref fz_ref ...
    let pos = |r: &Vec<f64>| [r[1], r[2], r[3]];
    for i in (0..rows.len()).step_by(37) {
        let xi = pos(&rows[i]);
        let mut f = [0.0f64; 3];
        for (j, row) in rows.iter().enumerate() {
            if j == i {
                continue;
            }
            let xj = pos(row);
            let d = [xj[0] - xi[0], xj[1] - xi[1], xj[2] - xi[2]];
            let r2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
            let (qi, qj) = (rows[i][4], row[4]);
            let coeff = if law.starts_with("# law coulomb") {
                let quench = header_value(law, "quench");
                if r2 < quench * quench {
                    0.0
                } else {
                    -qi * qj / (r2 * r2.sqrt())
                }
            } else {
                assert!(law.starts_with("# law gravity"), "{law}");
                let g = header_value(law, "G");
                let eps = header_value(law, "softening");
                g * qi * qj / (r2 + eps * eps).powf(1.5)
            };
            for a in 0..3 {
                f[a] += coeff * d[a];
            }
        }
        let want = &rows[i][5..8];
        let scale = want.iter().map(|x| x.abs()).fold(1e-300, f64::max);
        for a in 0..3 {
            assert!(
                (f[a] - want[a]).abs() <= 1e-9 * scale,
                "particle {i} axis {a}: recomputed {} vs dumped {} ({law})",
                f[a],
                want[a]
            );
        }
    }
}
