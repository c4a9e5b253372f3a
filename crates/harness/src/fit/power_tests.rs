use super::*;
use crate::fit::synthetic::{count, noisy};

fn sizes() -> Vec<f64> {
    (10..=17).map(|e| f64::from(1u32 << e)).collect()
}

#[test]
fn free_exponent_interval_covers_the_true_exponent() {
    let k_true = 1.7;
    let hits = count(50, |seed| {
        let s = noisy(&sizes(), 7, 0.05, seed, |n| 2e-9 * n.powf(k_true));
        fit_power(&s, seed).unwrap().exponent.contains(k_true)
    });
    assert!(hits >= 40, "{hits} of 50 intervals contain k");
}

#[test]
fn one_sample_per_n_resamples_residuals() {
    let hits = count(30, |seed| {
        let s = noisy(&sizes(), 1, 0.05, seed, |n| 1e-8 * n.powf(1.2));
        let fit = fit_power(&s, seed).unwrap();
        assert_eq!(fit.ci_method, CiMethod::ResampleResiduals);
        assert!(fit.exponent.ci95[1] > fit.exponent.ci95[0]);
        fit.exponent.contains(1.2)
    });
    assert!(hits >= 24, "{hits} of 30");
}

#[test]
fn selection_picks_n_squared_and_n_log_n() {
    let picks = |class: ComplexityClass, model: fn(f64) -> f64| {
        count(20, |seed| {
            let s = noisy(&sizes(), 5, 0.05, seed, model);
            fit_power(&s, seed).unwrap().class == class
        })
    };
    let n2 = picks(ComplexityClass::N2, |n| 3e-9 * n * n);
    let nlogn = picks(ComplexityClass::NLogN, |n| 4e-8 * n * n.log2());
    let linear_with_setup = picks(ComplexityClass::N, |n| 2e-5 + 2e-8 * n);
    assert!(n2 >= 18, "n^2 picked in {n2} of 20");
    assert!(nlogn >= 18, "n log n picked in {nlogn} of 20");
    assert!(
        linear_with_setup >= 18,
        "a + c n picked in {linear_with_setup} of 20"
    );
}

#[test]
fn every_candidate_reports_its_loo_smape() {
    let s = noisy(&sizes(), 5, 0.02, 3, |n| 3e-9 * n * n);
    let fit = fit_power(&s, 1).unwrap();
    assert_eq!(fit.candidates.len(), 12);
    assert!(fit.candidates.iter().all(|c| c.loo_smape_percent.is_some()));
    assert!(fit.selected.support > 0.9, "{}", fit.selected.support);
    assert!(
        fit.selected.coefficient.contains(3e-9),
        "{:?}",
        fit.selected
    );
    let p = fit.predict(1e6);
    assert!((p / (3e-9 * 1e12) - 1.0).abs() < 0.05, "{p}");
    let json = serde_json::to_value(&fit).unwrap();
    assert_eq!(json["class"], "n^2");
    assert!(json["exponent"]["ci95"].as_array().unwrap().len() == 2);
    assert_eq!(json["inputs"].as_array().unwrap().len(), 8);
}

#[test]
fn crossover_of_quadratic_and_linear_kernels() {
    let s = sizes();
    let quadratic = fit_power(&noisy(&s, 5, 0.01, 1, |n| 1e-9 * n * n), 1).unwrap();
    let linear = fit_power(&noisy(&s, 5, 0.01, 2, |n| 2e-6 * n), 1).unwrap();
    let n = crossover(&quadratic, &linear, 10.0, 1e6).unwrap();
    // 1e-9 n² = 2e-6 n at n = 2000.
    assert!((n / 2000.0 - 1.0).abs() < 0.1, "{n}");
    assert!((quadratic.predict(n) / linear.predict(n) - 1.0).abs() < 1e-9);
    assert_eq!(crossover(&quadratic, &linear, 1e4, 1e6), None);
    assert_eq!(crossover(&quadratic, &linear, 1e6, 1e4), None);
}

#[test]
fn degenerate_input_is_refused() {
    let one = [Samples::new(100.0, vec![1.0, 1.1])];
    assert!(matches!(fit_power(&one, 1), Err(FitError::OneX { .. })));
    let two = [
        Samples::new(100.0, vec![1.0]),
        Samples::new(200.0, vec![2.0]),
    ];
    assert!(matches!(
        fit_power(&two, 1),
        Err(FitError::TooFewPoints {
            need: 3,
            got: 2,
            ..
        })
    ));
    let mut s = noisy(&sizes(), 3, 0.05, 1, |n| n);
    s[2].values[1] = -1.0;
    assert!(matches!(
        fit_power(&s, 1),
        Err(FitError::NonPositive { .. })
    ));
    s[2].values[1] = f64::NAN;
    assert!(matches!(fit_power(&s, 1), Err(FitError::NotFinite { .. })));
    s[2].values[1] = 1.0;
    s[0].x = 0.0;
    assert!(matches!(fit_power(&s, 1), Err(FitError::BadX { .. })));
}

#[test]
fn a_range_too_short_to_tell_two_classes_apart_is_said() {
    // A tree code's n log n over n = 500–8000: n^1.5 grows only 2.8× differently over it.
    let short: Vec<f64> = [500.0, 1000.0, 2000.0, 4000.0, 8000.0].to_vec();
    let s = noisy(&short, 5, 0.02, 4, |n| 4e-8 * n * n.log2());
    let fit = fit_power(&s, 1).unwrap();
    let note = fit
        .notes
        .iter()
        .find(|n| n.contains("too short a range"))
        .unwrap_or_else(|| panic!("{:?}", fit.notes));
    assert!(note.contains("n = 500–8000"), "{note}");
    assert!(note.contains(fit.class.name()), "{note}");
    // n^1.5 against its neighbours over 2^10–2^17 (6.6× from n log n, 11× from n²): no note.
    let s = noisy(&sizes(), 5, 0.02, 5, |n| 1e-7 * n * n.sqrt());
    let fit = fit_power(&s, 1).unwrap();
    assert!(
        fit.notes.iter().all(|n| !n.contains("too short")),
        "{:?}",
        fit.notes
    );
}
