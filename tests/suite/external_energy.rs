//! An external program's energy drift (`energy` in its `[[external]]` entry): the first and
//! last match of the pattern in a run are its total energy at the start and the end, their
//! relative change is the run's drift, and the case is checked against `max_energy_drift` as
//! the built-in kernels are; a run that prints the energy once has no drift and fails.

use super::{bin, text};
use std::path::Path;

/// A config whose program prints `E = 2` then `E = <end>` (and its time), checked against
/// `max_drift`.
fn config(end: &str, max_drift: f64) -> String {
    format!(
        "name = \"ext\"\nstudy = \"cartesian\"\nscenarios = [\"lj-box\"]\nn = [50]\n\
         [[external]]\nname = \"prog\"\n\
         command = [\"sh\", \"-c\", \"echo 'E = 2'; echo 'took 3 ms'; {end}\"]\n\
         steps = 10\ntime = {{ regex = 'took ([0-9.]+) ms', unit = \"ms\" }}\n\
         energy = 'E = ([0-9.eE+-]+)'\n\
         [measure]\nwarmup_s = 0.0\nsamples = 2\nrounds = 2\nmin_sample_s = 0.001\n\
         max_energy_drift = {max_drift}\n"
    )
}

fn sweep(dir: &Path, config: &str) -> (std::process::Output, serde_json::Value) {
    std::fs::write(dir.join("ext.toml"), config).unwrap();
    let o = bin()
        .current_dir(dir)
        .args(["sweep", "--config", "ext.toml", "--out", "out", "--fresh"])
        .args(["--no-calibration", "--yes"])
        .output()
        .unwrap();
    let results = std::fs::read_to_string(dir.join("out/ext/results.json"))
        .map(|t| serde_json::from_str(&t).unwrap())
        .unwrap_or_default();
    (o, results)
}

#[test]
fn an_external_programs_energy_drift_is_read_and_checked_like_the_engines() {
    let dir = tempfile::tempdir().unwrap();
    // From 2 to 2.002: a drift of 1e-3, within 1e-2.
    let (o, r) = sweep(dir.path(), &config("echo 'E = 2.002'", 1e-2));
    assert!(o.status.success(), "{}", text(&o.stderr));
    let case = &r["cases"][0];
    for round in case["rounds"].as_array().unwrap() {
        let drift = round["energy_drift"].as_f64().unwrap();
        assert!((drift - 1e-3).abs() < 1e-12, "{drift}");
        let run = &round["external"]["runs"][0];
        assert!((run["energy_drift"].as_f64().unwrap() - 1e-3).abs() < 1e-12);
    }
    assert_eq!(case["summary"]["sanity_ok"], true, "{}", case["summary"]);
    let row = text(&o.stdout);
    assert!(
        row.lines()
            .any(|l| l.starts_with("lj-box/prog/") && l.contains(" ok")),
        "{row}"
    );
    // The same drift over a limit of 1e-4 fails the check, as an engine's run would.
    let (o, r) = sweep(dir.path(), &config("echo 'E = 2.002'", 1e-4));
    assert_eq!(r["cases"][0]["summary"]["sanity_ok"], false);
    assert!(
        text(&o.stdout)
            .lines()
            .any(|l| l.starts_with("lj-box/prog/") && l.contains("DRIFT")),
        "{}",
        text(&o.stdout)
    );
    let summary = std::fs::read_to_string(dir.path().join("out/ext/analysis/summary.md")).unwrap();
    assert!(
        summary.contains("## Physics checks that failed")
            && summary.contains("lj-box/prog/n=50/p=1/r=1/seed=1: energy drift 1.00e-3"),
        "{summary}"
    );
}

#[test]
fn a_run_that_prints_its_energy_once_has_no_drift_and_fails() {
    let dir = tempfile::tempdir().unwrap();
    let (o, r) = sweep(dir.path(), &config("true", 1e-2));
    assert_eq!(o.status.code(), Some(1), "{}", text(&o.stderr));
    let run = &r["cases"][0]["rounds"][0]["external"]["runs"][0];
    assert!(
        run["error"]["what"]
            .as_str()
            .unwrap()
            .contains("matches the energy regex `E = ([0-9.eE+-]+)` once"),
        "{run}"
    );
    // A pattern without a group around the number is refused before anything runs.
    let bad = config("true", 1e-2).replace("'E = ([0-9.eE+-]+)'", "'E = [0-9.]+'");
    let (o, _) = sweep(dir.path(), &bad);
    crate::refused(&o, "external.prog.energy");
}
