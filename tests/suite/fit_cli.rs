//! `nbody-bench fit`: every CSV format, the JSON fields, recovery of a known serial fraction,
//! reproducible seeds, and bad tables refused with exit code 2 and the line number.

use rand::SeedableRng;
use rand_distr::{Distribution, Normal};
use rand_pcg::Pcg64Mcg;
use serde_json::Value;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn bin(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_nbody-bench"))
        .args(args)
        .output()
        .expect("binary runs")
}

fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
    let path = dir.join(name);
    std::fs::write(&path, text).unwrap();
    path
}

/// `per_x` rows `x,model(x)·exp(σz)` per x under a header, from a seeded generator.
fn noisy_csv(
    header: &str,
    xs: &[f64],
    per_x: usize,
    seed: u64,
    model: impl Fn(f64) -> f64,
) -> String {
    let mut rng = Pcg64Mcg::seed_from_u64(seed);
    let z = Normal::new(0.0_f64, 0.04).unwrap();
    let mut text = format!("{header}\n");
    for &x in xs {
        for _ in 0..per_x {
            text.push_str(&format!("{x},{}\n", model(x) * z.sample(&mut rng).exp()));
        }
    }
    text
}

/// Runs `fit` with `--json` and returns the parsed document.
fn fit_json(dir: &Path, model: &str, csv: &Path, extra: &[&str]) -> Value {
    let out = dir.join(format!("{model}.json"));
    let mut args = vec![
        "fit",
        "--model",
        model,
        "--csv",
        csv.to_str().unwrap(),
        "--json",
        out.to_str().unwrap(),
    ];
    args.extend_from_slice(extra);
    let o = bin(&args);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    serde_json::from_str(&std::fs::read_to_string(&out).unwrap()).unwrap()
}

fn ci(v: &Value) -> [f64; 2] {
    let ci = v["ci95"].as_array().expect("ci95 is an array");
    [ci[0].as_f64().unwrap(), ci[1].as_f64().unwrap()]
}

#[test]
fn amdahl_recovers_a_serial_fraction_of_0_1() {
    let dir = tempfile::tempdir().unwrap();
    let text = noisy_csv("p,time", &[1.0, 2.0, 4.0, 8.0, 16.0], 6, 11, |p| {
        3.0 * (0.1 + 0.9 / p)
    });
    let csv = write(dir.path(), "strong.csv", &text);
    let doc = fit_json(dir.path(), "amdahl", &csv, &[]);
    assert_eq!(doc["schema"], "nbody-bench/fit/v1");
    assert_eq!(doc["model"], "amdahl");
    let [lo, hi] = ci(&doc["serial_fraction"]);
    assert!(lo < 0.1 && 0.1 < hi, "f interval [{lo}, {hi}]");
    let [lo, hi] = ci(&doc["t1"]);
    assert!(lo < 3.0 && 3.0 < hi, "T1 interval [{lo}, {hi}]");
    assert!(doc["max_speedup"]["estimate"].as_f64().unwrap() > 5.0);
    let kf = doc["karp_flatt"].as_array().unwrap();
    assert_eq!(kf.len(), 4);
    assert_eq!(kf[0]["p"], 2.0);
    assert_eq!(ci(&kf[3]["e"]).len(), 2);
    assert!(doc["karp_flatt_trend"]["verdict"].is_string());

    let table = bin(&["fit", "--model", "amdahl", "--csv", csv.to_str().unwrap()]);
    let stdout = String::from_utf8_lossy(&table.stdout);
    assert!(table.status.success());
    for want in ["serial fraction f", "max speedup 1/f", "Karp-Flatt trend"] {
        assert!(stdout.contains(want), "table lacks {want:?}:\n{stdout}");
    }
    // A row per thread count, the largest too.
    assert!(
        stdout.lines().any(|l| l.trim_start().starts_with("16 ")),
        "no row of p = 16:\n{stdout}"
    );
}

#[test]
fn power_and_gustafson_formats() {
    let dir = tempfile::tempdir().unwrap();
    let sizes: Vec<f64> = (10..=16).map(|e| f64::from(1u32 << e)).collect();
    let csv = write(
        dir.path(),
        "sizes.csv",
        &noisy_csv("N,Time", &sizes, 4, 3, |n| 2e-9 * n * n),
    );
    let doc = fit_json(dir.path(), "power", &csv, &[]);
    assert_eq!(doc["class"], "n^2");
    let [lo, hi] = ci(&doc["exponent"]);
    assert!(lo < 2.0 && 2.0 < hi, "k interval [{lo}, {hi}]");

    let gustafson = |p: f64| p / (p - 0.2 * (p - 1.0));
    let csv = write(
        dir.path(),
        "weak.csv",
        &noisy_csv("p,time", &[1.0, 2.0, 4.0, 8.0], 5, 4, gustafson),
    );
    let doc = fit_json(dir.path(), "gustafson", &csv, &[]);
    let [lo, hi] = ci(&doc["serial_fraction"]);
    assert!(lo < 0.2 && 0.2 < hi, "alpha interval [{lo}, {hi}]");
    assert_eq!(doc["efficiency"].as_array().unwrap().len(), 4);
    assert!(doc["efficiency"][3]["e"]["estimate"].as_f64().unwrap() < 1.0);

    // p,n,time: n doubled with p under an O(n²) cost; --cost n2 normalises the work.
    let mut text = String::from("p, n ,time\n");
    for (p, t) in [(1, 1.0), (1, 1.02), (2, 2.3), (2, 2.35), (4, 4.9), (4, 5.0)] {
        text.push_str(&format!("{p},{},{t}\n", 1000 * p));
    }
    let csv = write(dir.path(), "weak_n.csv", &text);
    let doc = fit_json(dir.path(), "gustafson", &csv, &["--cost", "n2"]);
    assert_eq!(doc["cost_model"], "n^2");
    assert_eq!(doc["work_per_worker"][2]["ratio"], 4.0);
    assert!(doc["serial_fraction"]["estimate"].is_number());
}

#[test]
fn the_seed_fixes_the_intervals() {
    let dir = tempfile::tempdir().unwrap();
    // Enough distinct samples that the percentile ends do not land on the same resampled medians.
    let text = noisy_csv("p,time", &[1.0, 2.0, 4.0, 8.0, 16.0], 15, 5, |p| {
        0.2 + 0.8 / p
    });
    let csv = write(dir.path(), "s.csv", &text);
    let a = fit_json(dir.path(), "amdahl", &csv, &[]);
    let b = fit_json(dir.path(), "amdahl", &csv, &[]);
    let c = fit_json(dir.path(), "amdahl", &csv, &["--seed", "99"]);
    assert_eq!(a, b);
    assert_ne!(a["serial_fraction"], c["serial_fraction"]);
    assert_eq!(
        a["serial_fraction"]["estimate"],
        c["serial_fraction"]["estimate"]
    );
}

#[test]
fn bad_tables_exit_2_with_the_line_number() {
    let dir = tempfile::tempdir().unwrap();
    let cases: &[(&str, &str, &str)] = &[
        ("amdahl", "1,2.0\n2,1.1\n", "line 1: missing header"),
        ("amdahl", "", "line 1: the table ends with no header"),
        (
            "amdahl",
            "p,time\n1,2.0\n2,slow\n",
            "line 3: `slow` in column `time`",
        ),
        (
            "amdahl",
            "p,time\n1,2.0\n2,1.0,7\n",
            "line 3: 3 fields, but the header has 2",
        ),
        (
            "amdahl",
            "p,time,host\n1,2.0,a\n",
            "line 1: unknown column(s) `host`",
        ),
        ("amdahl", "p,time\n1,2.0\n\n2,-1\n", "line 4: time = -1"),
        ("power", "p,time\n1,2.0\n", "unknown column(s) `p`"),
        (
            "gustafson",
            "p,n,time\n1,10,1\n2,20,1\n2,40,1\n",
            "line 4: p = 2 has n = 40",
        ),
    ];
    let out = dir.path().join("never.json");
    for (model, text, message) in cases {
        let csv = write(dir.path(), "bad.csv", text);
        let o = bin(&[
            "fit",
            "--model",
            model,
            "--csv",
            csv.to_str().unwrap(),
            "--json",
            out.to_str().unwrap(),
        ]);
        let stderr = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{text:?}: {stderr}");
        assert!(stderr.contains(message), "{text:?}: {stderr}");
        assert!(stderr.contains("bad.csv"), "names the file: {stderr}");
        assert!(!out.exists(), "no JSON after a failure");
    }
}

#[test]
fn data_a_model_cannot_use_exit_2_with_what_to_do() {
    let dir = tempfile::tempdir().unwrap();
    let cases: &[(&[&str], &str, &str)] = &[
        (
            &["--model", "amdahl"],
            "p,time\n2,1.0\n4,0.6\n",
            "needs a measurement at p = 1",
        ),
        (
            &["--model", "amdahl"],
            "p,time\n1,1.0\n1,1.1\n",
            "every sample is at x = 1",
        ),
        (
            &["--model", "power"],
            "n,time\n10,1.0\n20,2.0\n",
            "at least 3 distinct x values",
        ),
        (
            &["--model", "amdahl", "--cost", "n2"],
            "p,time\n1,1\n2,1\n",
            "--cost applies",
        ),
        (
            &["--model", "gustafson", "--cost", "n2"],
            "p,time\n1,1\n2,1\n",
            "needs an n column",
        ),
    ];
    for (args, text, message) in cases {
        let csv = write(dir.path(), "d.csv", text);
        let mut full = vec!["fit", "--csv", csv.to_str().unwrap()];
        full.extend_from_slice(args);
        let o = bin(&full);
        let stderr = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {stderr}");
        assert!(stderr.contains(message), "{args:?}: {stderr}");
    }
    let o = bin(&["fit", "--model", "power", "--csv", "/nonexistent/t.csv"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("cannot read /nonexistent/t.csv"));
}
