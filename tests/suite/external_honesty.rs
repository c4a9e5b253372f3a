//! What a sweep shows for an external program: "–" (null in JSON) wherever it measured
//! nothing, never a zero or "ok"; a program that ignores its threads named as such; phases it
//! could not have taken refused; a family that would pass for a kernel refused; its own n and
//! steps that fall as n grows.

use super::external::{HEAD, MEASURE, program_dir, record, sweep};
use super::{bin, refused, text};
use std::path::Path;

/// Writes `config` into `dir` as ext.toml and sweeps it through the binary, without calibration.
fn sweep_cli(dir: &Path, config: &str) -> std::process::Output {
    std::fs::write(dir.join("ext.toml"), config).unwrap();
    bin()
        .current_dir(dir)
        .args([
            "sweep",
            "--config",
            "ext.toml",
            "--out",
            "out",
            "--no-calibration",
            "--yes",
        ])
        .output()
        .unwrap()
}

#[test]
fn what_an_external_program_did_not_measure_reads_as_not_measured() {
    let dir = program_dir();
    let config = format!(
        r#"{HEAD}
kernels = ["naive"]
[[external]]
name = "printed"
command = ["{{config_dir}}/prog", "ok", "0", "2"]
steps = 4
time = {{ regex = 'elapsed ([0-9.]+) ms', unit = "ms" }}
{MEASURE}"#
    );
    let out = sweep_cli(dir.path(), &config);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let stdout = text(&out.stdout);
    let row = |key: &str| {
        stdout
            .lines()
            .find(|l| l.starts_with(key))
            .unwrap_or_else(|| panic!("no row {key} in {stdout}"))
            .to_string()
    };
    // The console: no pair rate of zero, no "ok" for an energy nobody checked.
    let external = row("lj-box/printed/");
    assert!(
        external.split_whitespace().rev().take(2).all(|c| c == "–"),
        "{external}"
    );
    assert!(!external.contains("0.00e0") && !external.contains(" ok"));
    assert!(row("lj-box/naive/").contains(" ok"), "{stdout}");
    // The results file: null where nothing was measured.
    let results: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(dir.path().join("out/ext/results.json")).unwrap(),
    )
    .unwrap();
    let case = |kernel: &str| {
        results["cases"]
            .as_array()
            .unwrap()
            .iter()
            .find(|c| c["key"].as_str().unwrap().contains(kernel))
            .unwrap()
            .clone()
    };
    let ext = case("printed");
    for field in [
        "step_ns",
        "pair_evals_per_s",
        "pairs_interacting",
        "max_energy_drift",
        "sanity_ok",
    ] {
        assert!(
            ext["summary"][field].is_null(),
            "{field}: {}",
            ext["summary"]
        );
    }
    assert!(ext["rounds"][0]["energy_drift"].is_null());
    let naive = case("naive");
    assert!(naive["summary"]["step_ns"]["p50"].as_u64().unwrap() > 0);
    assert_eq!(naive["summary"]["sanity_ok"], true);
    // The summary's energy table and the percentiles figure.
    let analysis = dir.path().join("out/ext/analysis");
    let summary = std::fs::read_to_string(analysis.join("summary.md")).unwrap();
    let energy = summary
        .lines()
        .find(|l| l.starts_with("| lj-box | printed | 1 |"))
        .unwrap_or_else(|| panic!("{summary}"));
    assert!(energy.ends_with("| – | – |"), "{energy}");
    let svg = std::fs::read_to_string(analysis.join("percentiles-lj-box.svg")).unwrap();
    assert!(
        svg.contains("not drawn: printed"),
        "the figure names what it left out"
    );
    assert!(svg.contains("naive n=50"), "whole case names");
    // Without a calibration the caption describes no machine, and names no host.
    assert!(svg.contains("machine not calibrated"));
    let host = std::fs::read_to_string("/proc/sys/kernel/hostname").unwrap_or_default();
    if !host.trim().is_empty() {
        assert!(!svg.contains(host.trim()), "host name in the caption");
    }
}

#[test]
fn a_program_that_ignores_its_threads_is_not_read_as_contention() {
    let dir = program_dir();
    // Told its threads, it runs the same 20 ms whatever they are, 0.1% of it serial.
    let config = format!(
        r#"{HEAD}
threads = [1, 2]
[[external]]
name = "serial"
command = ["sh", "-c", "sleep 0.02; echo 'phase setup 0.02'; echo 'phase loop 19.98'; echo 'total 20 ms'"]
steps = 10
time = {{ regex = 'total ([0-9.]+) ms', unit = "ms" }}
env = {{ OMP_NUM_THREADS = "{{threads}}" }}
phases = {{ setup = {{ regex = 'phase setup ([0-9.]+)', unit = "ms", kind = "serial" }}, loop = {{ regex = 'phase loop ([0-9.]+)', unit = "ms" }} }}
{MEASURE}"#
    )
    .replace("\"cartesian\"", "\"strong\"");
    let out = sweep_cli(dir.path(), &config);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let summary = std::fs::read_to_string(dir.path().join("out/ext/analysis/summary.md")).unwrap();
    assert!(
        summary.contains("does not use its workers"),
        "the diagnosis: {summary}"
    );
    assert!(!summary.contains("memory contention"), "{summary}");
}

#[test]
fn a_phase_longer_than_its_run_or_not_a_number_fails_the_sample() {
    let dir = program_dir();
    for (printed, why) in [
        ("100", "longer than the run"),
        ("1.7e308", "longer than the run"),
    ] {
        let config = format!(
            r#"{HEAD}
[[external]]
name = "phased"
command = ["sh", "-c", "echo 'total 3 ms'; echo 'phase work {printed}'"]
steps = 1
time = {{ regex = 'total ([0-9.]+) ms', unit = "ms" }}
phases = {{ work = {{ regex = 'phase work ([0-9.e+]+)', unit = "s" }} }}
{MEASURE}"#
        );
        let r = sweep(&config, dir.path());
        let case = record(&r, "lj-box/phased/n=50/p=1/r=1/seed=1");
        assert!(case.summary.is_none(), "no sample from an impossible phase");
        let runs = &case.rounds[0].external.as_ref().unwrap().runs;
        let error = runs[0].error.as_ref().unwrap();
        assert!(
            error.what.contains("phase `work`") && error.what.contains(why),
            "{}",
            error.what
        );
        std::fs::remove_dir_all(dir.path().join("out")).unwrap();
    }
}

#[test]
fn a_family_named_like_a_kernel_is_refused() {
    let dir = program_dir();
    let config = format!(
        r#"{HEAD}
[[external]]
name = "tree-eps1"
command = ["{{config_dir}}/prog", "ok", "0", "1"]
steps = 1
time = "wall"
force_error = 'error ([0-9.e-]+)'
family = "octree"
{MEASURE}"#
    );
    std::fs::write(dir.path().join("ext.toml"), config).unwrap();
    let o = bin()
        .current_dir(dir.path())
        .args(["sweep", "--config", "ext.toml", "--dry-run"])
        .output()
        .unwrap();
    refused(&o, "external.tree-eps1.family");
    refused(&o, "built-in kernel's name");
}

#[test]
fn an_external_runs_its_own_n_with_steps_that_fall_as_n_grows() {
    let dir = program_dir();
    let config = format!(
        r#"{HEAD}
[[external]]
name = "direct"
command = ["{{config_dir}}/prog", "ok", "0", "1", "{{steps}}"]
n = [20, 40]
steps = {{ work = 16000, grows = "n^2" }}
time = {{ regex = 'elapsed ([0-9.]+) ms', unit = "ms" }}
{MEASURE}"#
    );
    std::fs::write(dir.path().join("ext.toml"), &config).unwrap();
    // The dry run counts every case it lists and shows each run's steps.
    let o = bin()
        .current_dir(dir.path())
        .args(["sweep", "--config", "ext.toml", "--dry-run"])
        .output()
        .unwrap();
    let plan = text(&o.stdout);
    assert!(o.status.success(), "{}", text(&o.stderr));
    assert!(
        plan.contains(": 2 cases (0 of the built-in kernels, 2 of external"),
        "{plan}"
    );
    assert!(
        plan.contains("40 steps") && plan.contains("10 steps"),
        "{plan}"
    );
    let r = sweep(&config, dir.path());
    let steps: Vec<(usize, u64)> = r
        .cases
        .iter()
        .map(|c| (c.n, c.rounds[0].steps_per_sample))
        .collect();
    // 16000 / 20² and 16000 / 40², and none at the config's n = 50.
    assert_eq!(steps, [(20, 40), (40, 10)]);
    // Each run was told its steps, and each sample divides by them.
    let told = std::fs::read_to_string(
        dir.path()
            .join("out/ext/work/lj-box_direct_n=20_p=1_r=1_seed=1/args.txt"),
    )
    .unwrap();
    assert_eq!(told.trim(), "40");
    let case = record(&r, "lj-box/direct/n=20/p=1/r=1/seed=1");
    assert!(
        case.rounds[0]
            .samples_s
            .iter()
            .all(|&s| (s - 1e-3 / 40.0).abs() < 1e-12)
    );
}

#[test]
fn an_external_round_is_null_where_nothing_was_measured_from_the_round_up() {
    let dir = program_dir();
    let config = format!(
        r#"{HEAD}
kernels = ["naive"]
[[external]]
name = "printed"
command = ["{{config_dir}}/prog", "ok", "0", "2"]
steps = 4
time = {{ regex = 'elapsed ([0-9.]+) ms', unit = "ms" }}
{MEASURE}"#
    );
    let out = sweep_cli(dir.path(), &config);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let path = dir.path().join("out/ext/results.json");
    let read = |p: &Path| -> serde_json::Value {
        serde_json::from_str(&std::fs::read_to_string(p).unwrap()).unwrap()
    };
    let case = |v: &serde_json::Value, kernel: &str| {
        v["cases"]
            .as_array()
            .unwrap()
            .iter()
            .find(|c| c["key"].as_str().unwrap().contains(kernel))
            .unwrap()
            .clone()
    };
    let results = read(&path);
    let (ext, naive) = (case(&results, "printed"), case(&results, "naive"));
    for round in ext["rounds"].as_array().unwrap() {
        for field in ["phases", "work", "pairs_interacting"] {
            assert!(round[field].is_null(), "{field}: {round}");
        }
    }
    for field in ["phases", "pair_checks_per_step", "cells_visited_per_step"] {
        assert!(
            ext["summary"][field].is_null(),
            "{field}: {}",
            ext["summary"]
        );
    }
    assert!(naive["rounds"][0]["work"]["pair_checks"].as_u64().unwrap() > 0);
    assert!(
        naive["summary"]["phases"]["force_interact"]
            .as_f64()
            .unwrap()
            > 0.0
    );
    let analysis = dir.path().join("out/ext/analysis");
    let fits = read(&analysis.join("fits.json"));
    assert!(case(&fits, "printed")["phases"].is_null(), "{fits}");
    assert!(case(&fits, "naive")["phases"].is_object());
    let svg = std::fs::read_to_string(analysis.join("phases-lj-box.svg")).unwrap();
    assert!(
        svg.contains("(not measured)") && svg.contains("printed n=50"),
        "the bar says it"
    );

    // A file of an older version holds zeros there: it still loads, and they read as null.
    let mut old = results.clone();
    for c in old["cases"].as_array_mut().unwrap() {
        if !c["key"].as_str().unwrap().contains("printed") {
            continue;
        }
        for round in c["rounds"].as_array_mut().unwrap() {
            round["phases"] = serde_json::json!({
                "force_build": 0.0, "force_interact": 0.0, "integrate": 0.0,
                "boundary": 0.0, "output": 0.0
            });
            round["work"] = serde_json::json!({
                "pair_checks": 0, "cells_visited": 0, "nodes_opened": 0, "nodes_accepted": 0,
                "rebuilds": 0, "list_entries": 0, "pairs_interacting": 0
            });
            round["pairs_interacting"] = 0.into();
        }
    }
    let old_path = dir.path().join("old.json");
    std::fs::write(&old_path, serde_json::to_string(&old).unwrap()).unwrap();
    let o = bin()
        .current_dir(dir.path())
        .args(["analyze", "old.json", "--out", "old-analysis"])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", text(&o.stderr));
    let fits = read(&dir.path().join("old-analysis/fits.json"));
    assert!(case(&fits, "printed")["phases"].is_null(), "{fits}");
}
