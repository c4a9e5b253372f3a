//! The gate on synthetic results files: every rule, deterministic (scripted samples).

use super::*;
use nbody_calibrate::Calibration;
use nbody_engine::engine::PhaseTimes;
use nbody_engine::kernels::WorkCounters;
use nbody_engine::testing::{SEED_1, SEED_2};
use nbody_records::config::SweepConfig;
use nbody_records::plan::cases;
use nbody_records::results::{CaseRecord, Metadata, RESULTS_SCHEMA};
use nbody_records::round::RoundOutcome;
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64Mcg;
use std::path::Path;

const CONFIG: &str = r#"
name = "synthetic"
study = "cartesian"
scenarios = ["lj-box"]
kernels = ["naive", "symmetric", "cell-list"]
n = [1000]

[measure]
samples = 12
rounds = 3
reference_s = 0.01
"#;

/// How a synthetic run differs from the nominal machine and code.
#[derive(Clone, Copy)]
struct Run {
    seed: u64,
    /// Every time (cases and reference) multiplied by this: a slower machine.
    machine: f64,
    /// The time of one kernel's cases multiplied by this: slower code.
    kernel: Option<(&'static str, f64)>,
    /// Relative sample noise (uniform ±).
    noise: f64,
}

impl Run {
    fn nominal(seed: u64) -> Run {
        Run {
            seed,
            machine: 1.0,
            kernel: None,
            noise: 0.02,
        }
    }
}

fn calibration(gflops: f64) -> Calibration {
    Calibration {
        cpu_model: "AMD EPYC 9R14".to_string(),
        cpu_signature: Some("AuthenticAMD 25/17/1".to_string()),
        logical_cpus: 2,
        simd: "avx512".to_string(),
        fma_gflops_1t: gflops,
        parallel_ceiling: Vec::new(),
        fork_join_us: 20.0,
        fork_join_hot_us: 3.0,
        fork_join_threads: 2,
        team_barrier_us: None,
        team_region_us: None,
        memory_bandwidth_gbs: 20.0,
        duration_s: 1.0,
        background_cpus: None,
        warnings: Vec::new(),
    }
}

fn metadata() -> Metadata {
    Metadata {
        tool_version: "0.1.0".into(),
        git_commit: "0123456789abcdef".into(),
        git_dirty: false,
        rustc_version: "rustc".into(),
        simd: "avx512".into(),
        target_features: Vec::new(),
        cargo_features: Vec::new(),
        profile: "release".into(),
        host: "ci-1".into(),
        os: "linux x86_64".into(),
        started: "2026-11-22T00:00:00Z".into(),
        externals: Vec::new(),
        initial: None,
    }
}

/// A complete results file: three cases of 12 samples in 3 rounds, nominal step times of 1, 2
/// and 3 ms, a reference of 0.3 ms, all scaled as `run` says.
fn results(run: Run) -> ResultsFile {
    let config = SweepConfig::parse(CONFIG, Path::new("synthetic.toml")).unwrap();
    let mut rng = Pcg64Mcg::seed_from_u64(run.seed);
    let mut jitter = |x: f64| x * (1.0 + run.noise * (2.0 * rng.random::<f64>() - 1.0));
    let mut records = Vec::new();
    for (i, case) in cases(&config).into_iter().enumerate() {
        let slow = match run.kernel {
            Some((k, f)) if k == case.kernel.name() => f,
            _ => 1.0,
        };
        let step = 1e-3 * (i + 1) as f64 * run.machine * slow;
        let mut record = CaseRecord::new(case, 3, 2);
        for _ in 0..3 {
            let round = RoundOutcome {
                steps_per_sample: 10,
                samples_s: (0..4).map(|_| jitter(step)).collect(),
                step_ns: vec![(step * 1e9) as u64; 40],
                steps: 40,
                warmup_steps: 5,
                phases: Some(PhaseTimes::default()),
                work: Some(WorkCounters::default()),
                pairs_interacting: Some(10),
                energy_drift: Some(1e-6),
                force_error: None,
                n: 1000,
                clock_overhead: 1e-5,
                reference_s: (0..4).map(|_| jitter(1e-4 * run.machine)).collect(),
                initial_work: Some(WorkCounters {
                    pair_checks: 999_000,
                    pairs_interacting: 500,
                    ..Default::default()
                }),
                mpi: None,
                external: None,
                job: None,
            };
            record.add_round(round, 0.05);
        }
        records.push(record);
    }
    ResultsFile {
        schema: RESULTS_SCHEMA.to_string(),
        metadata: metadata(),
        config,
        config_text: CONFIG.to_string(),
        calibration: nbody_records::results::Calibrations {
            start: Some(calibration(100.0 / run.machine)),
            end: Some(calibration(100.0 / run.machine)),
        },
        cases: records,
    }
}

fn verdicts(report: &GateReport) -> Vec<(&str, Verdict)> {
    report
        .cases
        .iter()
        .map(|c| (c.key.split('/').nth(1).unwrap(), c.verdict))
        .collect()
}

#[test]
fn same_code_same_machine_is_unchanged() {
    let report = compare(
        &results(Run::nominal(SEED_1)),
        &results(Run::nominal(SEED_2)),
        &GateOptions::default(),
    )
    .unwrap();
    assert_eq!(report.cases.len(), 3);
    for c in &report.cases {
        assert_eq!(c.verdict, Verdict::Unchanged, "{c:?}");
        assert_eq!(c.normalization, Normalization::Reference);
        assert!(c.ci95[0] <= c.ratio && c.ratio <= c.ci95[1], "{c:?}");
        assert!((c.ratio - 1.0).abs() < 0.05, "{c:?}");
        assert_eq!(c.samples, [12, 12]);
        assert!(c.work_changes.is_empty() && c.notes.is_empty(), "{c:?}");
    }
    assert!(report.missing.is_empty() && report.extra.is_empty());
    assert_eq!(report.exit_code(), 0);
}

#[test]
fn a_slower_machine_is_not_a_regression_once_normalised() {
    let slow_machine = Run {
        machine: 2.0,
        ..Run::nominal(SEED_2)
    };
    let (base, cur) = (results(Run::nominal(SEED_1)), results(slow_machine));
    for choice in [
        NormalizationChoice::Auto,
        NormalizationChoice::Reference,
        NormalizationChoice::Calibration,
    ] {
        let options = GateOptions {
            normalization: choice,
            ..GateOptions::default()
        };
        let report = compare(&base, &cur, &options).unwrap();
        assert_eq!(report.exit_code(), 0, "{choice:?}: {report:?}");
        assert!(report.cases.iter().all(|c| (c.raw_ratio - 2.0).abs() < 0.1));
    }
    let raw = GateOptions {
        normalization: NormalizationChoice::None,
        ..GateOptions::default()
    };
    let report = compare(&base, &cur, &raw).unwrap();
    assert_eq!(report.count(Verdict::Regressed), 3);
    assert_eq!(report.exit_code(), 1);
}

#[test]
fn a_slower_kernel_is_flagged_alone() {
    let slower = Run {
        kernel: Some(("symmetric", 2.0)),
        ..Run::nominal(SEED_2)
    };
    // On a machine that is also 30% slower during the run: still only that kernel.
    let slower_on_slow_machine = Run {
        machine: 1.3,
        ..slower
    };
    for run in [slower, slower_on_slow_machine] {
        let report = compare(
            &results(Run::nominal(SEED_1)),
            &results(run),
            &GateOptions::default(),
        )
        .unwrap();
        assert_eq!(
            verdicts(&report),
            [
                ("naive", Verdict::Unchanged),
                ("symmetric", Verdict::Regressed),
                ("cell-list", Verdict::Unchanged)
            ]
        );
        let c = &report.cases[1];
        assert!(c.ci95[0] > 1.8 && c.ci95[1] < 2.2, "{c:?}");
        assert_eq!(report.exit_code(), 1);
    }
}

#[test]
fn a_faster_kernel_is_an_improvement_and_passes() {
    let faster = Run {
        kernel: Some(("naive", 0.5)),
        ..Run::nominal(SEED_2)
    };
    let report = compare(
        &results(Run::nominal(SEED_1)),
        &results(faster),
        &GateOptions::default(),
    )
    .unwrap();
    assert_eq!(report.cases[0].verdict, Verdict::Improved);
    assert_eq!(report.count(Verdict::Improved), 1);
    assert_eq!(report.exit_code(), 0);
}

#[test]
fn a_change_within_the_threshold_is_unchanged() {
    // 5% slower with 2% noise: clearly different, but inside a 10% threshold.
    let run = Run {
        kernel: Some(("naive", 1.05)),
        ..Run::nominal(SEED_2)
    };
    let base = results(Run::nominal(SEED_1));
    let report = compare(&base, &results(run), &GateOptions::default()).unwrap();
    assert_eq!(report.cases[0].verdict, Verdict::Unchanged);
    let strict = GateOptions {
        threshold: 0.0,
        ..GateOptions::default()
    };
    let report = compare(&base, &results(run), &strict).unwrap();
    assert_eq!(report.cases[0].verdict, Verdict::Regressed);
}

#[test]
fn missing_and_extra_cases_are_reported() {
    let base = results(Run::nominal(SEED_1));
    let mut cur = results(Run::nominal(SEED_2));
    let removed = cur.cases.remove(0);
    let mut unmeasured = cur.cases[0].clone();
    cur.cases[0].rounds.clear();
    let mut extra = removed.clone();
    extra.key = "lj-box/naive/n=2000/p=1/r=1/seed=1".into();
    cur.cases.push(extra);
    let report = compare(&base, &cur, &GateOptions::default()).unwrap();
    assert_eq!(
        report.missing,
        vec![
            MissingCase {
                key: removed.key.clone(),
                reason: "not in the current results".into()
            },
            MissingCase {
                key: unmeasured.key.clone(),
                reason: "not measured in the current run".into()
            }
        ]
    );
    assert_eq!(report.extra, vec!["lj-box/naive/n=2000/p=1/r=1/seed=1"]);
    assert_eq!(report.cases.len(), 1);
    assert_eq!(report.exit_code(), 2);
    let text = formatted(&report, Format::Text);
    assert!(text.starts_with("gate INCOMPLETE: 1 cases"), "{text}");
    assert!(
        text.contains(&format!("missing: {}", removed.key)),
        "{text}"
    );
    // A case measured in fewer rounds than planned is compared, with a note.
    // (Two rounds of four samples: enough for a CI, see `too_few_samples_...`.)
    unmeasured.rounds.truncate(2);
    unmeasured.rounds_done = 2;
    cur.cases[0] = unmeasured;
    let report = compare(&base, &cur, &GateOptions::default()).unwrap();
    assert!(report.cases[0].notes[0].contains("current incomplete (2/3 rounds)"));
}

#[test]
fn other_machines_builds_and_configs_are_refused_unless_forced() {
    let base = results(Run::nominal(SEED_1));
    let refuse = |cur: &ResultsFile| compare(&base, cur, &GateOptions::default()).unwrap_err();
    let mut other_cpu = results(Run::nominal(SEED_2));
    other_cpu.calibration.start.as_mut().unwrap().cpu_model = "Intel Xeon".into();
    let e = refuse(&other_cpu);
    assert!(matches!(
        e,
        GateError::OtherMachine {
            what: "CPU model",
            ..
        }
    ));
    assert!(
        e.to_string()
            .contains("`AMD EPYC 9R14` there, `Intel Xeon` here"),
        "{e}"
    );
    let mut more_cpus = results(Run::nominal(SEED_2));
    more_cpus.calibration.start.as_mut().unwrap().logical_cpus = 4;
    assert!(matches!(
        refuse(&more_cpus),
        GateError::OtherMachine {
            what: "logical CPU count",
            ..
        }
    ));
    let mut other_host = results(Run::nominal(SEED_2));
    other_host.metadata.host = "ci-2".into();
    assert!(compare(&base, &other_host, &GateOptions::default()).is_ok());
    let mut uncalibrated = results(Run::nominal(SEED_2));
    uncalibrated.calibration = Default::default();
    assert!(matches!(
        refuse(&uncalibrated),
        GateError::UnknownMachine { which: "current" }
    ));
    let mut other_simd = results(Run::nominal(SEED_2));
    other_simd.metadata.simd = "avx2+fma".into();
    assert!(matches!(refuse(&other_simd), GateError::OtherBuild { .. }));
    let mut other_config = results(Run::nominal(SEED_2));
    other_config.config.measure.samples = 20;
    other_config.config.n = None;
    let e = refuse(&other_config);
    assert!(
        e.to_string().contains("differ in measure.samples, n"),
        "{e}"
    );

    let mut busy = results(Run::nominal(SEED_1));
    busy.calibration.end.as_mut().unwrap().background_cpus = Some(1.4);
    let report = compare(&busy, &other_host, &GateOptions::default()).unwrap();
    assert!(
        report.warnings[0]
            .starts_with("the baseline was measured while other processes used 1.4 CPUs"),
        "{:?}",
        report.warnings
    );

    let forced = GateOptions {
        force: true,
        ..GateOptions::default()
    };
    let report = compare(&base, &other_cpu, &forced).unwrap();
    assert_eq!(report.exit_code(), 0);
    assert!(report.warnings[0].starts_with("forced: the baseline comes from another machine"));
}

#[test]
fn work_counters_are_compared_exactly() {
    let base = results(Run::nominal(SEED_1));
    let mut cur = results(Run::nominal(SEED_2));
    for round in &mut cur.cases[2].rounds {
        round.initial_work.as_mut().unwrap().pair_checks += 1;
    }
    let report = compare(&base, &cur, &GateOptions::default()).unwrap();
    assert_eq!(
        report.cases[2].work_changes,
        vec![WorkChange {
            counter: "pair_checks".into(),
            baseline: 999_000,
            current: 999_001
        }]
    );
    assert_eq!(report.work_changed(), 1);
    assert_eq!(report.exit_code(), 0, "reported, not failed, by default");
    let strict = GateOptions {
        fail_on_work_change: true,
        ..GateOptions::default()
    };
    assert_eq!(compare(&base, &cur, &strict).unwrap().exit_code(), 1);
    assert!(formatted(&report, Format::Markdown).contains("work changed: lj-box/cell-list"));
}

#[test]
fn normalisation_falls_back_and_explicit_choices_are_checked() {
    let base = results(Run::nominal(SEED_1));
    let mut cur = results(Run::nominal(SEED_2));
    for round in &mut cur.cases[0].rounds {
        round.reference_s.clear();
    }
    let report = compare(&base, &cur, &GateOptions::default()).unwrap();
    assert_eq!(report.cases[0].normalization, Normalization::Calibration);
    assert_eq!(report.cases[1].normalization, Normalization::Reference);
    let reference = GateOptions {
        normalization: NormalizationChoice::Reference,
        ..GateOptions::default()
    };
    let e = compare(&base, &cur, &reference).unwrap_err();
    assert!(
        matches!(e, GateError::NormalizationUnavailable { .. }),
        "{e}"
    );
}

#[test]
fn renderings() {
    let slower = Run {
        kernel: Some(("symmetric", 2.0)),
        ..Run::nominal(SEED_2)
    };
    let report = compare(
        &results(Run::nominal(SEED_1)),
        &results(slower),
        &GateOptions::default(),
    )
    .unwrap();
    let text = formatted(&report, Format::Text);
    assert!(
        text.starts_with(
            "gate FAIL: 3 cases: 1 regressed, 0 improved, 2 unchanged, 0 unknown (threshold ±10%)"
        ),
        "{text}"
    );
    assert!(text.contains("REGRESSED"), "{text}");
    let md = formatted(&report, Format::Markdown);
    assert!(
        md.starts_with("### Performance gate: regression found"),
        "{md}"
    );
    assert!(md.contains(
        "| case | baseline | current | ratio | family CI | raw ratio | raw family CI | adj. p | rounds | verdict |"
    ));
    assert!(md.contains("| **regressed** |"), "{md}");
    let json: serde_json::Value = serde_json::from_str(&formatted(&report, Format::Json)).unwrap();
    assert_eq!(json["schema"], GATE_SCHEMA);
    assert_eq!(json["cases"][1]["verdict"], "regressed");
    assert_eq!(json["cases"][1]["normalization"], "reference");
}

/// Every check that could compare nothing is an error (exit 2), never a pass.
#[test]
fn too_few_samples_for_a_ci_are_not_judged() {
    let base = results(Run::nominal(SEED_1));
    let slower = Run {
        kernel: Some(("symmetric", 1.5)),
        ..Run::nominal(SEED_2)
    };
    let cur = results(slower);
    // Keeps `per_round` samples (and their references) of each round of the symmetric case.
    let keep = |file: &ResultsFile, per_round: [usize; 3]| {
        let mut file = file.clone();
        for (round, k) in file.cases[1].rounds.iter_mut().zip(per_round) {
            round.samples_s.truncate(k);
            round.reference_s.truncate(k);
        }
        file
    };
    // One sample per side of the symmetric case: a "CI" of [1.500, 1.500] is no interval.
    let (one, cur_one) = (keep(&base, [1, 0, 0]), keep(&cur, [1, 0, 0]));
    let report = compare(&one, &cur_one, &GateOptions::default()).unwrap();
    assert_eq!(report.missing.len(), 1, "{:?}", report.missing);
    assert!(report.missing[0].key.contains("/symmetric/"));
    assert!(
        report.missing[0]
            .reason
            .contains("1 successful sample(s) in the baseline and 1 in the current run"),
        "{}",
        report.missing[0].reason
    );
    assert!(
        report.missing[0].reason.contains("at least 6 per side"),
        "{}",
        report.missing[0].reason
    );
    assert_eq!(report.count(Verdict::Regressed), 0, "not judged");
    assert_eq!(report.exit_code(), 2);
    // Exactly the minimum is judged.
    let (six_base, six) = (keep(&base, [3, 3, 0]), keep(&cur, [3, 3, 0]));
    let report = compare(&six_base, &six, &GateOptions::default()).unwrap();
    assert!(report.missing.is_empty(), "{:?}", report.missing);
    assert_eq!(report.cases[1].samples, [6, 6]);
    assert_eq!(report.cases[1].verdict, Verdict::Regressed);
    // Failed (zero or negative) samples do not count.
    let mut zeros = base.clone();
    for round in &mut zeros.cases[0].rounds {
        round.samples_s.iter_mut().for_each(|s| *s = 0.0);
    }
    let report = compare(&zeros, &base, &GateOptions::default()).unwrap();
    assert_eq!(report.missing[0].reason, "no samples in the baseline");
    assert_eq!(report.exit_code(), 2);
}

#[test]
fn fail_on_work_change_with_no_counters_to_compare_is_an_error() {
    let base = results(Run::nominal(SEED_1));
    let mut old = results(Run::nominal(SEED_2));
    for case in &mut old.cases {
        for round in &mut case.rounds {
            round.initial_work = None;
        }
    }
    let lenient = compare(&base, &old, &GateOptions::default()).unwrap();
    assert!(lenient.missing.is_empty(), "only a note without the flag");
    assert_eq!(lenient.exit_code(), 0);
    assert!(lenient.cases.iter().all(|c| !c.work_compared));
    let strict = GateOptions {
        fail_on_work_change: true,
        ..GateOptions::default()
    };
    let report = compare(&base, &old, &strict).unwrap();
    assert_eq!(report.missing.len(), 3);
    assert!(
        report.missing[0]
            .reason
            .contains("--fail-on-work-change asks for them"),
        "{}",
        report.missing[0].reason
    );
    assert_eq!(report.exit_code(), 2, "not a pass");
    // Counters on both sides: compared, and a pass.
    let report = compare(&base, &results(Run::nominal(SEED_2)), &strict).unwrap();
    assert!(report.missing.is_empty());
    assert!(report.cases.iter().all(|c| c.work_compared));
    assert_eq!(report.exit_code(), 0);
}

#[test]
fn the_threshold_is_bounded() {
    let base = results(Run::nominal(SEED_1));
    for bad in [1e300, 1.0001, -0.1, f64::NAN, f64::INFINITY] {
        let options = GateOptions {
            threshold: bad,
            ..GateOptions::default()
        };
        let e = compare(&base, &base, &options).unwrap_err();
        assert!(matches!(e, GateError::BadThreshold(_)), "{bad}: {e}");
        assert!(e.to_string().contains("from 0 to 1"), "{e}");
    }
    for good in [0.0, 0.25, MAX_THRESHOLD] {
        assert!(check_threshold(good).is_ok(), "{good}");
    }
}

#[test]
fn calibrated_rates_too_far_apart_are_named() {
    // The machine's own drift (9.6% across one hour on one class) passes...
    assert_eq!(rates_differ(219.4, 240.5), None);
    assert_eq!(rates_differ(91.4, 96.0), None);
    // ...the 25% that made the reference over-correct does not, either way round.
    let why = rates_differ(175.0, 140.0).unwrap();
    assert!(
        why.contains("175.0 GFLOP/s and this run's 140.0 (0.80x)"),
        "{why}"
    );
    assert!(rates_differ(140.0, 175.0).is_some());
    assert!(rates_differ(100.0, 100.0 * (1.0 + RATE_TOLERANCE) * 1.01).is_some());
    assert!(rates_differ(100.0, 100.0 * (1.0 + RATE_TOLERANCE) * 0.99).is_none());
    // Nothing to compare is no finding here (the file checks handle missing calibrations).
    assert_eq!(rates_differ(0.0, 100.0), None);
    assert_eq!(rates_differ(f64::NAN, 100.0), None);
    // Two files whose calibrations differ that much are compared with a warning.
    let base = results(Run::nominal(SEED_1));
    let mut cur = results(Run::nominal(SEED_2));
    for c in [&mut cur.calibration.start, &mut cur.calibration.end] {
        c.as_mut().unwrap().fma_gflops_1t = 80.0;
    }
    let report = compare(&base, &cur, &GateOptions::default()).unwrap();
    assert!(
        report
            .warnings
            .iter()
            .any(|w| w.contains("would over-correct")),
        "{:?}",
        report.warnings
    );
}

/// `n` samples of `level` with ±2% uniform noise.
fn noisy(rng: &mut Pcg64Mcg, n: usize, level: f64) -> Vec<f64> {
    (0..n)
        .map(|_| level * (1.0 + 0.02 * (2.0 * rng.random::<f64>() - 1.0)))
        .collect()
}

/// Twenty unchanged cases per gate run, judged at threshold 0 (each ratio's true value on the
/// margin: the hardest null): judged alone at 2.5% each, some case is flagged in a large share
/// of runs; under Holm's step-down the share of runs with any flagged case stays near the
/// stated family-wise 2.5%. A case 10% slower among nineteen unchanged ones is flagged.
#[test]
fn the_family_wise_rule_holds_its_rate_over_twenty_cases() {
    use super::compare::ratio_interval;
    use super::family::{FAMILY_ALPHA, holm};
    let mut rng = Pcg64Mcg::seed_from_u64(SEED_1);
    let runs = 200;
    let (mut alone, mut family) = (0, 0);
    for run in 0..runs {
        let p: Vec<f64> = (0..20)
            .map(|case| {
                let (b, c) = (noisy(&mut rng, 16, 1.0), noisy(&mut rng, 16, 1.0));
                ratio_interval(&b, &c, 1000, (run * 20 + case) as u64, 0.0)
                    .1
                    .regressed
            })
            .collect();
        alone += usize::from(p.iter().any(|&p| p <= FAMILY_ALPHA));
        family += usize::from(holm(&p, FAMILY_ALPHA).contains(&true));
    }
    let (alone, family) = (alone as f64 / runs as f64, family as f64 / runs as f64);
    assert!(alone > 0.2, "case by case: {alone}");
    assert!(family <= 0.05, "family-wise: {family}");

    let mut caught = 0;
    for run in 0..50 {
        let p: Vec<f64> = (0..20)
            .map(|case| {
                let slower = if case == 7 { 1.10 } else { 1.0 };
                let (b, c) = (noisy(&mut rng, 16, 1.0), noisy(&mut rng, 16, slower));
                ratio_interval(&b, &c, 1000, (run * 20 + case) as u64, 0.03)
                    .1
                    .regressed
            })
            .collect();
        let flagged = holm(&p, FAMILY_ALPHA);
        caught += usize::from(flagged[7] && flagged.iter().filter(|&&f| f).count() == 1);
    }
    assert!(
        caught >= 48,
        "the 10% case flagged alone in {caught} of 50 runs"
    );
}
