use super::*;
use nbody_engine::decomp::Decomposition;
use nbody_engine::decomp::stats::{MasterSummary, RankStats, reduce};
use nbody_engine::kernels::KernelKind;
use nbody_engine::scenario::{Precision, ScenarioKind};

fn launch() -> MpiLaunch {
    MpiLaunch {
        launcher: "mpirun".into(),
        ranks: vec![1, 2],
        args: vec!["--oversubscribe".into()],
        rank_flag: "-n".into(),
        decomp: vec![Decomposition::Domain],
        steps: 40,
        warmup_steps: 5,
    }
}

fn case() -> Case {
    Case {
        scenario: ScenarioKind::LjBox,
        kernel: KernelKind::CellList.into(),
        n: 2000,
        threads: 1,
        ranks: 4,
        theta: None,
        multipole: Default::default(),
        order: None,
        skin: None,
        seed: 3,
        precision: Some(Precision::F64),
        time_factor: 1,
        decomp: Some(Decomposition::Domain),
    }
}

#[test]
fn a_launch_runs_this_program_under_the_launcher() {
    let args = launch_args(
        &launch(),
        &case(),
        Path::new("/bin/nb"),
        Path::new("/tmp/r.json"),
    );
    assert_eq!(
        args.join(" "),
        "--oversubscribe -n 4 /bin/nb run --scenario lj-box --kernel cell-list -n 2000 --seed 3 \
         --threads 1 --decomp domain --steps 40 --warmup-steps 5 --json /tmp/r.json --yes --precision f64"
    );
    assert!(
        case().key().ends_with("/r=4/seed=3/f64/domain"),
        "{}",
        case().key()
    );
}

fn run_json(step_ns: Vec<u64>) -> String {
    let per_rank = vec![
        RankStats {
            rank: 0,
            compute_s: 1.0,
            comm_s: 0.5,
            ..Default::default()
        },
        RankStats {
            rank: 1,
            compute_s: 1.2,
            comm_s: 0.3,
            ..Default::default()
        },
    ];
    let report = MpiReport {
        ranks: 2,
        decomposition: Decomposition::Domain,
        threads_per_rank: 1,
        rank_grid: Some(vec![2, 1]),
        library: "Open MPI".into(),
        hosts: vec!["h".into(), "h".into()],
        warmup_steps: 5,
        rebalances: 0,
        reduced: reduce(&per_rank),
        per_rank,
        master_summary: MasterSummary::default(),
        step_ns,
    };
    serde_json::json!({
        "schema": "nbody-bench/run/v1",
        "n": 2000,
        "steps": 10,
        "timing": {"phases": {"force_build": 0.1, "force_interact": 0.2, "integrate": 0.05,
                              "boundary": 0.0, "output": 0.0}},
        "counters": {"total": {"pair_checks": 500, "pairs_interacting": 0, "cells_visited": 10,
                               "nodes_opened": 0, "nodes_accepted": 0},
                     "pairs_interacting_final": 77},
        "energy": {"rel_drift": -1e-6},
        "mpi": report,
    })
    .to_string()
}

#[test]
fn a_round_groups_the_slowest_rank_step_times_into_samples() {
    let steps: Vec<u64> = (1..=10).map(|k| k * 1000).collect();
    let round = round_from_json(&run_json(steps), 3, 5).unwrap();
    // 10 steps into 3 samples of 3 steps; the last step is left out.
    assert_eq!(round.steps_per_sample, 3);
    assert_eq!(round.samples_s, vec![2e-6, 5e-6, 8e-6]);
    assert_eq!(round.step_ns.len(), 9);
    assert_eq!(round.steps, 10);
    assert_eq!(round.warmup_steps, 5);
    assert!((round.phases.unwrap().force_interact - 0.02).abs() < 1e-15);
    assert_eq!(round.work.unwrap().pair_checks, 500);
    assert_eq!(round.pairs_interacting, Some(77));
    assert_eq!(round.n, 2000);
    let mpi = round.mpi.unwrap();
    assert!(mpi.step_ns.is_empty(), "kept out of the results file");
    assert_eq!(mpi.per_rank.len(), 2);
}

/// The driver writes `rel_drift: null` when the initial energy is 0 (serde_json's NaN): the
/// round is read, its drift not measured.
#[test]
fn a_null_drift_is_read_as_not_measured() {
    let steps: Vec<u64> = (1..=4).map(|k| k * 1000).collect();
    let text = run_json(steps).replace("\"rel_drift\":-1e-6", "\"rel_drift\":null");
    assert!(text.contains("\"rel_drift\":null"), "{text}");
    let round = round_from_json(&text, 2, 5).unwrap();
    assert_eq!(round.energy_drift, None);
    assert_eq!(round.samples_s.len(), 2);
}

#[test]
fn a_round_needs_a_step_per_sample_and_a_complete_result() {
    let err = round_from_json(&run_json(vec![1, 2]), 3, 0).unwrap_err();
    assert!(err.contains("fewer than the 3 samples"), "{err}");
    assert!(round_from_json("{\"n\": 3}", 3, 0).is_err());
}

/// A round's result is written back in a private directory, never at a name another user could
/// predict: a link planted at the old name (`$TMPDIR/nbody-bench-round-<pid>-<case>.json`) is
/// not written through, and the directory is gone after the round, here a failed one. The
/// launcher is `sh -c SCRIPT`, which writes what a run would to the file given as `--json`
/// (through any link, as a run's atomic write does) and records that file's directory.
#[cfg(target_os = "linux")]
#[test]
fn a_round_is_written_back_in_a_private_directory_not_through_a_planted_link() {
    let tmp = tempfile::tempdir().unwrap();
    let victim = tmp.path().join("victim");
    std::fs::write(&victim, "precious").unwrap();
    let case = case();
    let planted = std::env::temp_dir().join(format!(
        "nbody-bench-round-{}-{}.json",
        std::process::id(),
        case.key().replace('/', "_")
    ));
    let _ = std::fs::remove_file(&planted);
    std::os::unix::fs::symlink(&victim, &planted).unwrap();
    let log = tmp.path().join("log");
    let script = format!(
        r#"while [ "$#" -gt 0 ]; do [ "$1" = --json ] && json=$2; shift; done
d=$(dirname "$json"); stat -c %a "$d" > '{log}'; echo "$d" >> '{log}'; echo junk > "$json""#,
        log = log.display()
    );
    let launch = MpiLaunch {
        launcher: "sh".into(),
        args: vec!["-c".into(), script, "sh".into()],
        ..launch()
    };
    let spec = RoundSpec::bare(2);
    let err = measure_round(&launch, &case, &spec, None).unwrap_err();
    std::fs::remove_file(&planted).unwrap();
    assert!(matches!(err, LaunchError::Result { .. }), "{err}");
    assert_eq!(std::fs::read_to_string(&victim).unwrap(), "precious");
    let log = std::fs::read_to_string(&log).unwrap();
    let (mode, dir) = log.trim().split_once('\n').unwrap();
    assert_eq!(mode, "700", "{log}");
    let dir = Path::new(dir);
    assert_ne!(dir, std::env::temp_dir(), "{log}");
    assert!(!dir.exists(), "{} left behind", dir.display());
}
