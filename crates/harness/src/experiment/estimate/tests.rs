use super::*;
use nbody_records::plan::cases;
use std::path::Path;

const TOL: f64 = 1e-12;

fn config(extra: &str) -> SweepConfig {
    let text = format!(
        r#"
        name = "t"
        study = "cartesian"
        scenarios = ["lj-box"]
        kernels = ["naive"]
        n = [1000]
        [measure]
        warmup_s = 0.05
        samples = 10
        rounds = 2
        min_sample_s = 0.01
        {extra}
        "#
    );
    SweepConfig::parse(&text, Path::new("t.toml")).unwrap()
}

/// A probe at the case's n with only a force phase of `force_s` and no pairs to fork for.
fn flat(n: usize, force_s: f64) -> Probe {
    Probe {
        n,
        build_s: 0.0,
        energy_s: 0.0,
        force_s,
        other_s: 0.0,
        pair_checks: 0.0,
        error_pair_s: None,
    }
}

fn one(config: &SweepConfig, probe: Probe, done: &Done) -> Estimate {
    let probed: Vec<(Case, Probe)> = cases(config).into_iter().map(|c| (c, probe)).collect();
    estimate(config, &probed, done, false, 2)
}

#[test]
fn complexity_classes_scale_the_work() {
    assert!((Complexity::Quadratic.ratio(1000, 2000) - 4.0).abs() < TOL);
    assert!((Complexity::Linear.ratio(1000, 2000) - 2.0).abs() < TOL);
    let nlogn = Complexity::NLogN.ratio(1000, 2000);
    assert!((nlogn - 2.0 * 2000f64.ln() / 1000f64.ln()).abs() < TOL);
    assert!(Complexity::NLogN.ratio(1, 1).is_finite());
    assert_eq!(KernelKind::Naive.complexity(), Complexity::Quadratic);
    assert_eq!(KernelKind::CellList.complexity(), Complexity::Linear);
    assert_eq!(KernelKind::Octree.complexity(), Complexity::NLogN);
    let p = Probe {
        build_s: 1.0,
        other_s: 1.0,
        pair_checks: 1e6,
        ..flat(1000, 1.0)
    }
    .at(KernelKind::Naive, 2000);
    assert_eq!(p.n, 2000);
    assert!((p.force_s - 4.0).abs() < TOL && (p.pair_checks - 4e6).abs() < 1e-3);
    assert!((p.other_s - 2.0).abs() < TOL && (p.build_s - 2.0).abs() < TOL);
}

#[test]
fn speedup_counts_only_threads_that_can_work() {
    let big = 1e9;
    assert_eq!(speedup(KernelKind::Naive, 1, 1, big, 2), 1.0);
    assert!((speedup(KernelKind::Naive, 2, 1, big, 2) - 1.9).abs() < TOL);
    // Beyond the logical CPUs a thread adds nothing.
    assert!((speedup(KernelKind::PerThread, 8, 1, big, 2) - 1.9).abs() < TOL);
    assert!((speedup(KernelKind::CellList, 4, 1, big, 8) - 3.7).abs() < TOL);
    // The symmetric kernel is single-threaded; small steps do not fork.
    assert_eq!(speedup(KernelKind::Symmetric, 4, 1, big, 8), 1.0);
    assert_eq!(speedup(KernelKind::Naive, 4, 1, 1000.0, 8), 1.0);
    // Ranks are processes: they split any kernel's work.
    assert!((speedup(KernelKind::Symmetric, 1, 2, big, 8) - 1.9).abs() < TOL);
    assert!((speedup(KernelKind::Naive, 2, 2, big, 8) - 3.7).abs() < TOL);
}

#[test]
fn a_round_is_warm_up_plus_samples_of_whole_steps() {
    let c = config("");
    // 1 ms steps: 10 steps per 10 ms sample, 5 samples per round after a 50 ms warm-up.
    let e = one(&c, flat(1000, 1e-3), &Done::default());
    assert_eq!(e.cases.len(), 1);
    let round = ROUND_OVERHEAD_S + 0.05 + 5.0 * 0.01;
    assert!((e.cases[0].wall_s - 2.0 * round).abs() < 1e-9, "{e:?}");
    assert_eq!((e.cases[0].rounds, e.cases[0].samples), (2, 10));
    assert!((e.total_s - e.cases[0].wall_s).abs() < TOL);
    // 0.1 s steps: the warm-up lasts the cold first step and one more, each sample one step.
    let e = one(&c, flat(1000, 0.1), &Done::default());
    let round = ROUND_OVERHEAD_S + 0.2 + 5.0 * 0.1;
    assert!((e.total_s - 2.0 * round).abs() < 1e-9, "{e:?}");
    // A step of 3 ms takes 4 steps (12 ms) to reach a 10 ms sample.
    let e = one(&c, flat(1000, 3e-3), &Done::default());
    let round = ROUND_OVERHEAD_S + 0.05 + 5.0 * 0.012;
    assert!((e.total_s - 2.0 * round).abs() < 1e-9, "{e:?}");
}

#[test]
fn build_probes_reference_and_force_error_add_to_each_round() {
    let c = config("reference_s = 0.02\nforce_error_sample = 100");
    let p = Probe {
        build_s: 0.3,
        energy_s: 0.002,
        error_pair_s: Some(1e-8),
        ..flat(1000, 1e-3)
    };
    let e = one(&c, p, &Done::default());
    let round =
        ROUND_OVERHEAD_S + 0.3 + 3.0 * 0.002 + 0.05 + 5.0 * (0.01 + 0.02) + 100.0 * 1000.0 * 1e-8;
    assert!((e.total_s - 2.0 * round).abs() < 1e-9, "{e:?}");
}

#[test]
fn a_resumed_sweep_counts_only_what_is_left() {
    let mut c = config("");
    (c.measure.samples, c.measure.rounds) = (5, 3);
    let key = cases(&c)[0].key();
    let done = Done {
        rounds: HashMap::from([(key, 1)]),
        calibrated: true,
    };
    let e = one(&c, flat(1000, 1e-3), &done);
    // 5 samples over 3 rounds are 2, 2 and 1: rounds 1 and 2 are left.
    assert_eq!((e.cases[0].rounds, e.cases[0].samples), (2, 3));
    let round = |k: f64| ROUND_OVERHEAD_S + 0.05 + k * 0.01;
    assert!((e.total_s - round(2.0) - round(1.0)).abs() < 1e-9, "{e:?}");
    // Calibrations: none when off, the end one only when the start one is in the file.
    let probed: Vec<(Case, Probe)> = cases(&c)
        .into_iter()
        .map(|x| (x, flat(1000, 1e-3)))
        .collect();
    assert_eq!(estimate(&c, &probed, &done, false, 2).calibration_s, 0.0);
    let resumed = estimate(&c, &probed, &done, true, 2).calibration_s;
    let fresh = estimate(&c, &probed, &Done::default(), true, 2).calibration_s;
    assert!((resumed - calibration_s(1)).abs() < TOL);
    assert!((fresh - 2.0 * calibration_s(1)).abs() < TOL);
    assert!(calibration_s(2) > calibration_s(1) && calibration_s(1) > 0.5);
}

#[test]
fn an_mpi_round_is_one_launch_of_all_its_steps() {
    let mut c = config("");
    c.mpi = Some(MpiLaunch {
        launcher: "mpirun".into(),
        ranks: vec![2],
        args: Vec::new(),
        rank_flag: "-n".into(),
        decomp: vec![nbody_engine::decomp::Decomposition::Allgather],
        steps: 100,
        warmup_steps: 10,
    });
    let p = Probe {
        energy_s: 0.01,
        other_s: 1e-3,
        pair_checks: 1e9,
        ..flat(1000, 9e-3)
    };
    let e = one(&c, p, &Done::default());
    assert_eq!(e.cases[0].case.ranks, 2);
    let step = 0.01 / 1.9;
    assert!((e.cases[0].step_s - step).abs() < 1e-12);
    let round = MPI_LAUNCH_S + 2.0 * 0.01 / 1.9 + 110.0 * step;
    assert!((e.total_s - 2.0 * round).abs() < 1e-9, "{e:?}");
}

#[test]
fn a_probe_measures_each_set_up_once() {
    let c = SweepConfig::parse(
        r#"
        name = "p"
        study = "cartesian"
        scenarios = ["lj-box"]
        kernels = ["naive", "cell-list"]
        n = [100, 300, 5000]
        threads = [1, 2]
        [measure]
        force_error_sample = 10
        "#,
        Path::new("p.toml"),
    )
    .unwrap();
    let all = cases(&c);
    let probed = probe(&c, &all).unwrap();
    assert_eq!(probed.setups, 2);
    assert_eq!(probed.cases.len(), all.len());
    for (case, p) in &probed.cases {
        assert_eq!(p.n, PROBE_MAX_N, "{}", case.key());
        assert!(p.force_s > 0.0 && p.energy_s > 0.0 && p.pair_checks > 0.0);
        assert!(p.error_pair_s.is_some_and(|s| s > 0.0));
    }
    let naive = probed
        .cases
        .iter()
        .find(|(c, _)| c.kernel == KernelKind::Naive);
    let n = PROBE_MAX_N as f64;
    assert_eq!(naive.map(|(_, p)| p.pair_checks), Some(n * (n - 1.0)));
    let e = estimate(&c, &probed.cases, &Done::default(), true, 2);
    assert!(e.total_s.is_finite() && e.total_s > e.calibration_s);
}
