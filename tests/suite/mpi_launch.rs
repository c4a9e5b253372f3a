//! Sweeps with an `[mpi]` table through the binary, against a stand-in launcher (a shell script
//! named as `mpi.launcher`) that writes a prepared run result where the sweep asked (`--json`)
//! and keeps the file of bodies it was given (`--initial`): no MPI is started. The MPI drivers
//! themselves are tested under mpirun (`scripts/mpi-tests.sh`).
#![cfg(feature = "mpi")]

use crate::text;
use nbody_engine::decomp::Decomposition;
use nbody_engine::decomp::stats::{MasterSummary, MpiReport, RankStats, reduce};
use nbody_records::results::ResultsFile;
use std::path::{Path, PathBuf};
use std::process::{Output, Stdio};

/// The prepared result of a launched run of `n` bodies: 10 timed steps after 2 warm-up steps on
/// 2 ranks, with `rel_drift` as given (JSON).
fn run_result(n: usize, rel_drift: serde_json::Value) -> String {
    let per_rank = vec![
        RankStats {
            rank: 0,
            compute_s: 1.0,
            ..Default::default()
        },
        RankStats {
            rank: 1,
            compute_s: 1.1,
            ..Default::default()
        },
    ];
    let report = MpiReport {
        ranks: 2,
        decomposition: Decomposition::Domain,
        threads_per_rank: 1,
        rank_grid: Some(vec![2, 1, 1]),
        library: "stand-in".into(),
        hosts: vec!["h".into(), "h".into()],
        warmup_steps: 2,
        rebalances: 0,
        reduced: reduce(&per_rank),
        per_rank,
        master_summary: MasterSummary::default(),
        step_ns: (1..=10).map(|k| 1000 * k).collect(),
    };
    serde_json::json!({
        "schema": "nbody-bench/run/v1",
        "n": n,
        "steps": 10,
        "timing": {"phases": {"force_build": 0.1, "force_interact": 0.2, "integrate": 0.05,
                              "boundary": 0.0, "output": 0.0}},
        "counters": {"total": {"pair_checks": 500, "pairs_interacting": 0, "cells_visited": 10,
                               "nodes_opened": 0, "nodes_accepted": 0},
                     "pairs_interacting_final": 7},
        "energy": {"rel_drift": rel_drift},
        "mpi": report,
    })
    .to_string()
}

/// A directory with the user's file of bodies (`bodies.txt`, 20 bodies of the gas), a config
/// of one case under the stand-in launcher in `rounds` rounds, and the launcher, which copies
/// each `--initial` file it is given to `seen-<k>` and writes `result.json` to `--json`. With
/// `replace`, its first launch then replaces the user's file with other bodies (`other.txt`),
/// as a user editing the file while the sweep runs would.
struct Setup {
    dir: tempfile::TempDir,
    config: PathBuf,
}

impl Setup {
    fn new(rounds: usize, rel_drift: serde_json::Value, replace: bool) -> Setup {
        use std::os::unix::fs::PermissionsExt;
        let dir = tempfile::tempdir().unwrap();
        let d = dir.path();
        for (name, seed) in [("bodies.txt", "1"), ("other.txt", "2")] {
            let o = crate::bin()
                .args([
                    "export",
                    "--format",
                    "text",
                    "--scenario",
                    "lj-box",
                    "-n",
                    "20",
                ])
                .args(["--seed", seed, "--out"])
                .arg(d.join(name))
                .output()
                .unwrap();
            assert!(o.status.success(), "{}", text(&o.stderr));
        }
        std::fs::write(d.join("result.json"), run_result(20, rel_drift)).unwrap();
        let replace = if replace {
            format!(
                "[ -e '{d}/replaced' ] || {{ touch '{d}/replaced'; cp '{d}/other.txt' '{d}/bodies.txt'; }}",
                d = d.display()
            )
        } else {
            String::new()
        };
        let launcher = d.join("launcher");
        std::fs::write(
            &launcher,
            format!(
                r#"#!/bin/sh
while [ $# -gt 0 ]; do case $1 in --json) json=$2 ;; --initial) initial=$2 ;; esac; shift; done
k=$(( $(cat '{d}/launches' 2>/dev/null || echo 0) + 1 )); echo $k > '{d}/launches'
cp "$initial" '{d}/seen-'$k; echo "$initial" > '{d}/path-'$k
{replace}
cp '{d}/result.json' "$json"
"#,
                d = d.display()
            ),
        )
        .unwrap();
        std::fs::set_permissions(&launcher, std::fs::Permissions::from_mode(0o755)).unwrap();
        let config = d.join("launched.toml");
        std::fs::write(
            &config,
            format!(
                "name = \"launched\"\nstudy = \"cartesian\"\nscenarios = [\"lj-box\"]\n\
                 kernels = [\"cell-list\"]\nn = [20]\ninitial = \"bodies.txt\"\n\
                 [mpi]\nlauncher = \"{}\"\nranks = [2]\ndecomp = [\"domain\"]\nsteps = 10\n\
                 warmup_steps = 2\n[measure]\nsamples = {rounds}\nrounds = {rounds}\n",
                launcher.display()
            ),
        )
        .unwrap();
        Setup { dir, config }
    }

    fn path(&self, name: &str) -> PathBuf {
        self.dir.path().join(name)
    }

    fn sweep(&self) -> Output {
        let child = crate::bin()
            .args(["sweep", "--no-calibration", "--yes", "--config"])
            .arg(&self.config)
            .arg("--out")
            .arg(self.path("out"))
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap();
        crate::finish(child, "sweep")
    }

    fn results(&self) -> ResultsFile {
        ResultsFile::load(&self.path("out/launched/results.json")).unwrap()
    }
}

/// The file of bodies is read once, at the start, and every launch reads the sweep's copy of
/// what was read: a file replaced after the first round changes nothing the rounds measure,
/// and the results' fingerprint names the bodies every round started from.
#[test]
fn every_launch_starts_from_the_bodies_read_at_the_start() {
    let s = Setup::new(3, serde_json::json!(-1e-6), true);
    let original = std::fs::read(s.path("bodies.txt")).unwrap();
    let o = s.sweep();
    assert!(o.status.success(), "{}", text(&o.stderr));
    assert!(s.path("replaced").exists(), "the file was replaced");
    assert_ne!(std::fs::read(s.path("bodies.txt")).unwrap(), original);
    let copy: &Path = &s.path("out/launched/initial/bodies.txt");
    for k in 1..=3 {
        let seen = std::fs::read(s.path(&format!("seen-{k}"))).unwrap();
        assert!(seen == original, "launch {k} read other bodies");
        let path = std::fs::read_to_string(s.path(&format!("path-{k}"))).unwrap();
        assert_eq!(Path::new(path.trim()), copy, "launch {k}");
    }
    let r = s.results();
    let record = r.metadata.initial.as_ref().unwrap();
    assert_eq!(Path::new(&record.path), s.path("bodies.txt"));
    // FNV-1a, 64 bits, as the results file's fingerprint.
    let fnv1a = |bytes: &[u8]| {
        bytes.iter().fold(0xcbf2_9ce4_8422_2325_u64, |h, &b| {
            (h ^ b as u64).wrapping_mul(0x0100_0000_01b3)
        })
    };
    assert_eq!(record.fnv1a, format!("{:016x}", fnv1a(&original)));
    assert!(std::fs::read(copy).unwrap() == original);
    let case = &r.cases[0];
    assert_eq!(case.rounds.len(), 3);
    assert!(case.summary.is_some());
}

/// The driver writes `rel_drift: null` when the initial energy is 0: the sweep reads the run,
/// keeps its samples and records the drift as not measured: null, and no energy check ("–").
#[test]
fn a_null_drift_from_a_launched_run_is_not_measured() {
    let s = Setup::new(1, serde_json::Value::Null, false);
    let o = s.sweep();
    assert!(o.status.success(), "{}", text(&o.stderr));
    let r = s.results();
    let case = &r.cases[0];
    let round = &case.rounds[0];
    assert_eq!(round.samples_s.len(), 1);
    assert_eq!(round.energy_drift, None);
    assert!(case.rejected.is_empty(), "{:?}", case.rejected);
    let summary = case.summary.as_ref().unwrap();
    assert_eq!((summary.max_energy_drift, summary.sanity_ok), (None, None));
}
