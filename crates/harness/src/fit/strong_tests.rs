use super::*;
use crate::fit::karp_flatt::Trend;
use crate::fit::overhead::OverheadTerm;
use crate::fit::synthetic::{THREADS, count, noisy};

fn amdahl(t1: f64, f: f64) -> impl Fn(f64) -> f64 {
    move |p| t1 * (f + (1.0 - f) / p)
}

#[test]
fn serial_fraction_interval_covers_the_truth() {
    let hits = count(50, |seed| {
        let s = noisy(&THREADS, 7, 0.05, seed, amdahl(2.0, 0.1));
        let fit = fit_strong(&s, &[], seed).unwrap();
        fit.serial_fraction.contains(0.1) && fit.t1.contains(2.0)
    });
    assert!(hits >= 40, "{hits} of 50 intervals contain f and T1");
}

#[test]
fn speedup_intervals_cover_the_true_speedups() {
    let mut inside = 0;
    for seed in 1..=30 {
        let s = noisy(&THREADS, 9, 0.05, seed, amdahl(1.0, 0.2));
        let fit = fit_strong(&s, &[], seed).unwrap();
        for pt in &fit.points[1..] {
            let truth = 1.0 / (0.2 + 0.8 / pt.p);
            inside += usize::from(pt.speedup.contains(truth));
            assert!((pt.efficiency.estimate - pt.speedup.estimate / pt.p).abs() < 1e-12);
        }
    }
    assert!(inside >= 100, "{inside} of 120");
}

#[test]
fn pure_amdahl_is_flat_and_keeps_no_overhead() {
    let flat = count(20, |seed| {
        let s = noisy(&THREADS, 7, 0.05, seed, amdahl(1.0, 0.05));
        let fit = fit_strong(&s, &[], seed).unwrap();
        fit.karp_flatt_trend.verdict == Trend::Flat && fit.overhead.kept.is_none()
    });
    assert!(flat >= 16, "flat without overhead in {flat} of 20");
}

#[test]
fn linear_overhead_rises_and_is_kept() {
    let with_overhead = |p: f64| amdahl(1.0, 0.05)(p) + 0.01 * p;
    let fits: Vec<StrongFit> = (1..=20)
        .map(|seed| fit_strong(&noisy(&THREADS, 7, 0.05, seed, with_overhead), &[], seed).unwrap())
        .collect();
    let rising = fits
        .iter()
        .filter(|f| f.karp_flatt_trend.verdict == Trend::Rising && f.overhead.kept.is_some())
        .count();
    assert!(
        rising >= 18,
        "rising with an overhead term kept in {rising} of 20"
    );
    // With five thread counts and 5% noise, log2 p and p are not always told apart.
    let linear = fits
        .iter()
        .filter(|f| f.overhead.kept.is_some_and(|k| k.term == OverheadTerm::P))
        .count();
    assert!(linear >= 14, "c*p chosen in {linear} of 20");
    let s = noisy(&THREADS, 7, 0.02, 1, with_overhead);
    let kept = fit_strong(&s, &[], 1).unwrap().overhead.kept.unwrap();
    assert!(kept.coefficient.contains(0.01), "{kept:?}");
    assert!(kept.serial_fraction.contains(0.05), "{kept:?}");
}

#[test]
fn ceiling_and_curves() {
    let s = noisy(&THREADS, 7, 0.02, 4, amdahl(3.0, 0.1));
    let fit = fit_strong(&s, &[(2.0, 1.6), (32.0, 20.0)], 4).unwrap();
    let p2 = &fit.points[1];
    assert_eq!(p2.ceiling, Some(1.6));
    let rel = p2.speedup_vs_ceiling.unwrap();
    assert!((rel.estimate - p2.speedup.estimate / 1.6).abs() < 1e-12);
    assert!(fit.points[2].speedup_vs_ceiling.is_none());
    assert!(fit.notes.iter().any(|n| n.contains("p = 32")));

    let (t, band) = fit.amdahl_time(1.0);
    assert!((t - fit.t1.estimate).abs() < 1e-12 && band[0] <= t && t <= band[1]);
    let (s64, band64) = fit.amdahl_speedup(64.0);
    let (s16, _) = fit.amdahl_speedup(16.0);
    assert!(s64 > s16 && s64 < fit.max_speedup.estimate);
    assert!(band64[0] < s64 && s64 < band64[1], "{band64:?}");
    let json = serde_json::to_value(&fit).unwrap();
    for key in [
        "serial_fraction",
        "t1",
        "max_speedup",
        "karp_flatt",
        "points",
    ] {
        assert!(json.get(key).is_some(), "{key}");
    }
    assert!(json.get("replicates").is_none());
    assert_eq!(json["karp_flatt"][0]["p"], 2.0);
    assert!(json["karp_flatt"][0]["e"]["ci95"].is_array());
}

#[test]
fn superlinear_speedup_is_clamped_and_said() {
    let s = noisy(&THREADS, 5, 0.01, 2, |p| 1.0 / (1.1 * p));
    let s: Vec<Samples> = s
        .into_iter()
        .map(|mut x| {
            if x.x == 1.0 {
                x.values.iter_mut().for_each(|v| *v *= 1.1);
            }
            x
        })
        .collect();
    let fit = fit_strong(&s, &[], 2).unwrap();
    assert!(fit.clamped && fit.serial_fraction_unclamped.estimate < 0.0);
    assert_eq!(fit.serial_fraction.estimate, 0.0);
    assert!(fit.max_speedup.estimate.is_infinite());
    assert!(fit.notes.iter().any(|n| n.contains("clamped")));
    let json = serde_json::to_value(&fit).unwrap();
    assert!(json["max_speedup"]["estimate"].is_null());
}

#[test]
fn two_thread_counts_fit_but_leave_the_trend_undetermined() {
    let s = noisy(&[1.0, 2.0], 5, 0.03, 1, amdahl(1.0, 0.3));
    let fit = fit_strong(&s, &[], 1).unwrap();
    assert_eq!(fit.karp_flatt.len(), 1);
    assert_eq!(fit.karp_flatt_trend.verdict, Trend::Undetermined);
    assert!(fit.overhead.kept.is_none());
}

#[test]
fn degenerate_input_is_refused() {
    let no_one = noisy(&[2.0, 4.0], 3, 0.01, 1, amdahl(1.0, 0.1));
    assert!(matches!(
        fit_strong(&no_one, &[], 1),
        Err(FitError::NoBaseline { .. })
    ));
    let one_p = noisy(&[1.0], 3, 0.01, 1, amdahl(1.0, 0.1));
    assert!(matches!(
        fit_strong(&one_p, &[], 1),
        Err(FitError::OneX { .. })
    ));
    let ok = noisy(&THREADS, 3, 0.01, 1, amdahl(1.0, 0.1));
    assert!(matches!(
        fit_strong(&ok, &[(2.0, f64::NAN)], 1),
        Err(FitError::BadCeiling { .. })
    ));
    let mut zero = ok.clone();
    zero[1].values[0] = 0.0;
    assert!(matches!(
        fit_strong(&zero, &[], 1),
        Err(FitError::NonPositive { .. })
    ));
    let mut inf = ok;
    inf[3].values[2] = f64::INFINITY;
    assert!(matches!(
        fit_strong(&inf, &[], 1),
        Err(FitError::NotFinite { x: 8.0, .. })
    ));
    let single = noisy(&[1.0, 2.0], 1, 0.01, 1, amdahl(1.0, 0.1));
    assert!(matches!(
        fit_strong(&single, &[], 1),
        Err(FitError::NoSpread { .. })
    ));
}
