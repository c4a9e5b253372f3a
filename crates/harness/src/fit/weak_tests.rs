use super::*;
use crate::fit::synthetic::{THREADS, count, noisy};

/// Times whose scaled speedup follows Gustafson's law with serial fraction `alpha`.
fn gustafson(t1: f64, alpha: f64) -> impl Fn(f64) -> f64 {
    move |p| p * t1 / (p - alpha * (p - 1.0))
}

#[test]
fn serial_fraction_interval_covers_the_truth() {
    let hits = count(50, |seed| {
        let s = noisy(&THREADS, 7, 0.05, seed, gustafson(1.5, 0.1));
        fit_weak(&s, seed).unwrap().serial_fraction.contains(0.1)
    });
    assert!(hits >= 40, "{hits} of 50 intervals contain alpha");
}

#[test]
fn efficiency_and_scaled_speedup_per_p() {
    let s = noisy(&THREADS, 9, 0.02, 3, gustafson(1.0, 0.2));
    let fit = fit_weak(&s, 3).unwrap();
    assert_eq!(fit.efficiency.len(), 5);
    assert_eq!(fit.efficiency[0].e.estimate, 1.0);
    for (e, s) in fit.efficiency.iter().zip(&fit.scaled_speedup) {
        let truth = (e.p - 0.2 * (e.p - 1.0)) / e.p;
        assert!((e.e.estimate / truth - 1.0).abs() < 0.05, "{e:?}");
        assert!((s.s.estimate - e.e.estimate * e.p).abs() < 1e-12);
    }
    let (s32, band) = fit.scaled_speedup_curve(32.0);
    assert!(band[0] <= s32 && s32 <= band[1]);
    assert!((s32 - (32.0 - 0.2 * 31.0)).abs() < 1.0, "{s32}");
    let json = serde_json::to_value(&fit).unwrap();
    assert!(json["serial_fraction"]["ci95"].is_array());
    assert_eq!(json["efficiency"][4]["p"], 16.0);
    assert!(json["efficiency"][4]["e"]["estimate"].is_number());
}

#[test]
fn problem_sizes_are_checked_and_normalised() {
    let n1 = 1000.0;
    // n grew like p, but the kernel is O(n²): each worker had p times the one-worker work.
    let base = gustafson(1.0, 0.1);
    let hits = count(30, |seed| {
        let s = noisy(&THREADS, 7, 0.05, seed, |p| base(p) * p);
        let with_n: Vec<WeakSamples> = s
            .into_iter()
            .map(|s| WeakSamples {
                p: s.x,
                n: n1 * s.x,
                values: s.values,
            })
            .collect();
        let fit = fit_weak_with_n(&with_n, ComplexityClass::N2, seed).unwrap();
        let work = fit.work_per_worker.as_ref().unwrap();
        assert!((work[4].ratio - 16.0).abs() < 1e-9);
        assert!(fit.notes.iter().any(|n| n.contains("divided")));
        fit.serial_fraction.contains(0.1)
    });
    assert!(hits >= 24, "{hits} of 30");

    // n grown by the cost model: nothing to normalise, the same fit as without n.
    let s = noisy(&THREADS, 5, 0.03, 1, base);
    let with_n: Vec<WeakSamples> = s
        .iter()
        .map(|s| WeakSamples {
            p: s.x,
            n: n1 * s.x.sqrt(),
            values: s.values.clone(),
        })
        .collect();
    let a = fit_weak_with_n(&with_n, ComplexityClass::N2, 1).unwrap();
    let b = fit_weak(&s, 1).unwrap();
    assert!((a.serial_fraction.estimate - b.serial_fraction.estimate).abs() < 1e-9);
    assert!((a.inputs[3].median - b.inputs[3].median).abs() < 1e-12);
    assert!(a.notes.is_empty(), "{:?}", a.notes);
}

#[test]
fn degenerate_input_is_refused() {
    let one = noisy(&[1.0], 3, 0.01, 1, |_| 1.0);
    assert!(matches!(fit_weak(&one, 1), Err(FitError::OneX { .. })));
    let no_base = noisy(&[2.0, 4.0], 3, 0.01, 1, |_| 1.0);
    assert!(matches!(
        fit_weak(&no_base, 1),
        Err(FitError::NoBaseline { .. })
    ));
    let ws = |p: f64, n: f64, v: f64| WeakSamples {
        p,
        n,
        values: vec![v, v * 1.01],
    };
    let mixed = [ws(1.0, 10.0, 1.0), ws(2.0, 20.0, 1.0), ws(2.0, 30.0, 1.0)];
    assert!(matches!(
        fit_weak_with_n(&mixed, ComplexityClass::N, 1),
        Err(FitError::InconsistentN { p: 2.0, .. })
    ));
    let log_of_one = [ws(1.0, 1.0, 1.0), ws(2.0, 2.0, 1.0)];
    assert!(matches!(
        fit_weak_with_n(&log_of_one, ComplexityClass::NLogN, 1),
        Err(FitError::BadX { .. })
    ));
    let nan = [ws(1.0, 10.0, f64::NAN), ws(2.0, 20.0, 1.0)];
    assert!(matches!(
        fit_weak_with_n(&nan, ComplexityClass::N, 1),
        Err(FitError::NotFinite { .. })
    ));
    let negative = [ws(1.0, 10.0, -1.0), ws(2.0, 20.0, 1.0)];
    assert!(matches!(
        fit_weak_with_n(&negative, ComplexityClass::N, 1),
        Err(FitError::NonPositive { .. })
    ));
}
