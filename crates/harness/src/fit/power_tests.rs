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

/// Whether every class `fit`'s reading names grows with an exponent inside k's interval over
/// the measured n: a class is never printed beside an exponent that contradicts it.
fn named_classes_fit_k(fit: &PowerFit) -> bool {
    let (lo, hi) = (fit.inputs[0].x, fit.inputs[fit.inputs.len() - 1].x);
    let named = match &fit.reading {
        GrowthReading::Class { class } => vec![*class],
        GrowthReading::NotDistinguished { classes } => classes.clone(),
        GrowthReading::ExponentOnly => vec![],
    };
    named.iter().all(|&c| {
        let [a, b] = crate::fit::growth::nominal_exponents(c, lo, hi);
        a <= fit.exponent.ci95[1] && fit.exponent.ci95[0] <= b
    })
}

#[test]
fn data_growing_as_n_log_n_read_n_log_n_whatever_the_noise() {
    // The sizes of the report that read "n" in one run and "n log n" in the next.
    let ns = [1000.0, 2000.0, 4000.0, 8000.0, 16000.0];
    let readings: Vec<GrowthReading> = (1..=20)
        .map(|seed| {
            let s = noisy(&ns, 5, 0.05, seed, |n| 4e-8 * n * n.log2());
            let fit = fit_power(&s, seed).unwrap();
            assert!(
                named_classes_fit_k(&fit),
                "{:?} beside {:?}",
                fit.reading,
                fit.exponent
            );
            assert_ne!(fit.reading.class(), Some(ComplexityClass::N));
            fit.reading
        })
        .collect();
    assert!(
        readings.iter().all(|r| *r == readings[0]),
        "readings differ between noise seeds: {readings:?}"
    );
    assert_eq!(readings[0].class(), Some(ComplexityClass::NLogN));
}

#[test]
fn identical_runs_of_one_kernel_give_one_reading() {
    for model in [
        (|n: f64| 3e-9 * n * n) as fn(f64) -> f64,
        |n| 1e-7 * n * n.sqrt(),
        |n| 2e-5 + 2e-8 * n,
    ] {
        // The reading, not its text: an exponent alone is quoted as measured in each run.
        let readings: Vec<GrowthReading> = (1..=10)
            .map(|seed| fit_power(&noisy(&sizes(), 5, 0.05, seed, model), seed).unwrap())
            .map(|fit| fit.reading)
            .collect();
        assert!(
            readings.iter().all(|r| *r == readings[0]),
            "readings differ between noise seeds: {readings:?}"
        );
    }
}

#[test]
fn a_class_is_never_named_beside_an_exponent_that_contradicts_it() {
    // A setup cost that dominates at small n: cross-validation picks a + c·n log n while the
    // free exponent is about 0.8 ("n log n (n^0.79)" in a legend).
    let ns = [1000.0, 2000.0, 4000.0, 8000.0, 16000.0];
    let mut named_n_log_n = 0;
    for seed in 1..=20 {
        let s = noisy(&ns, 5, 0.03, seed, |n| 5e-4 + 4e-8 * n * n.log2());
        let fit = fit_power(&s, seed).unwrap();
        assert!(fit.exponent.ci95[1] < 1.0, "{:?}", fit.exponent);
        assert!(
            named_classes_fit_k(&fit),
            "{:?} beside {:?}",
            fit.reading,
            fit.exponent
        );
        assert_eq!(
            fit.reading,
            GrowthReading::ExponentOnly,
            "{:?}",
            fit.exponent
        );
        let text = fit.growth();
        assert!(text.starts_with("n^0.") && !text.contains("log"), "{text}");
        assert!(
            fit.notes
                .iter()
                .any(|n| n.contains("measured exponent alone"))
        );
        named_n_log_n += usize::from(fit.class == ComplexityClass::NLogN);
    }
    // The case the reading guards against did arise: cross-validation picked n log n.
    assert!(named_n_log_n > 0);
    // And whatever the data, the reading keeps to k's interval.
    for (seed, model) in [
        (1, (|n: f64| 1e-9 * n.powf(1.04)) as fn(f64) -> f64),
        (2, |n| 1e-9 * n.powf(1.9)),
        (3, |n| 1e-4 + 1e-9 * n * n),
    ] {
        let fit = fit_power(&noisy(&sizes(), 5, 0.05, seed, model), seed).unwrap();
        assert!(
            named_classes_fit_k(&fit),
            "{:?} beside {:?}",
            fit.reading,
            fit.exponent
        );
    }
}
