//! `run --skin auto`: the candidate skins timed on the run's system, the fastest used and
//! recorded in the run's kernel parameters; refused where no candidates can be timed.

use super::{bin, refused, text};

#[test]
fn the_chosen_skin_is_one_of_the_candidates_and_is_recorded() {
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
            "300",
        ])
        .args(["--steps", "20", "--skin", "auto", "--json"])
        .arg(&json)
        .output()
        .unwrap();
    let err = text(&o.stderr);
    assert!(o.status.success(), "{err}");
    let skins: Vec<f64> = err
        .lines()
        .filter_map(|l| l.trim().strip_prefix("skin "))
        .map(|l| l.split_whitespace().next().unwrap().parse().unwrap())
        .collect();
    assert_eq!(skins.len(), 6, "{err}");
    let run: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    let used = run["kernel_params"]["skin"].as_f64().unwrap();
    assert!(skins.contains(&used), "{used} not among {skins:?}");
    assert!(err.contains(&format!("chosen: skin {used}")), "{err}");
}

#[test]
fn auto_is_refused_where_it_cannot_be_timed() {
    let o = bin().args(["validate", "--skin", "auto"]).output().unwrap();
    refused(&o, "--skin auto is for `run` only");
    let o = bin()
        .args([
            "run",
            "--scenario",
            "lj-box",
            "--kernel",
            "naive",
            "-n",
            "100",
            "--skin",
            "auto",
        ])
        .output()
        .unwrap();
    refused(
        &o,
        "--skin applies to the verlet and cluster-pair kernels only",
    );
    let o = bin()
        .args([
            "run",
            "--scenario",
            "lj-box",
            "--kernel",
            "verlet",
            "-n",
            "100",
            "--skin",
            "often",
        ])
        .output()
        .unwrap();
    refused(&o, "or `auto`");
}
