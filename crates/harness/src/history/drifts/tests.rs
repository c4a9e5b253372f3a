use super::*;
use rand::{Rng, SeedableRng};
use rand_distr::StandardNormal;
use rand_pcg::Pcg64Mcg;

/// `n` points of level 1 with log-normal noise of σ `sigma`, whose logarithm rises by
/// `ln(rate)` per point over `from..to` and holds after.
fn ramped(seed: u64, n: usize, from: usize, to: usize, rate: f64, sigma: f64) -> Vec<f64> {
    let mut rng = Pcg64Mcg::seed_from_u64(seed);
    (0..n)
        .map(|i| {
            let z: f64 = rng.sample(StandardNormal);
            let steps = i.clamp(from, to) - from;
            rate.powi(steps as i32) * (sigma * z).exp()
        })
        .collect()
}

#[test]
fn a_drift_is_one_drift_with_its_range_size_and_rate() {
    let (from, to, rate) = (30, 70, 1.002f64);
    let truth = rate.powi((to - from) as i32);
    let mut covered = 0;
    for seed in 0..20 {
        let values = ramped(seed, 100, from, to, rate, 0.007);
        let s = shape(&values, &Model::default()).unwrap();
        assert!(s.changes.is_empty(), "seed {seed}: {s:?}");
        assert_eq!(s.drifts.len(), 1, "seed {seed}: {s:?}");
        let d = s.drifts[0];
        // The range found overlaps the true one by more than half (its ends can fall inside,
        // the first or last few points of a ramp going to the level beside it).
        let overlap = (d.end.min(to) + 1).saturating_sub(d.start.max(from));
        assert!(2 * overlap > to - from, "{d:?}");
        assert!(d.ratio > 1.03 && d.ratio < truth * 1.04, "{d:?}");
        assert!((d.ratio - d.per_point.powi((d.end - d.start) as i32)).abs() < 1e-9);
        assert!((d.to / d.from - d.ratio).abs() < 1e-9);
        assert!(
            d.ratio_ci95[0] < d.ratio && d.ratio < d.ratio_ci95[1],
            "{d:?}"
        );
        if d.per_point_ci95[0] <= rate && rate <= d.per_point_ci95[1] {
            covered += 1;
        }
    }
    // A 95% interval: 19 of 20 expected; below 16 has a probability of 0.3%.
    assert!(
        covered >= 16,
        "the interval covered the true rate {covered} times in 20"
    );
}

#[test]
fn noise_alone_gives_no_drift_and_no_step() {
    let model = Model::default();
    let mut rng = Pcg64Mcg::seed_from_u64(5);
    for seed in 0..150 {
        let n = rng.random_range(10..140);
        let sigma = rng.random_range(0.002..0.03);
        let mut values = ramped(seed, n, 0, 0, 1.0, sigma);
        // A spike in a third of them.
        if seed % 3 == 0 {
            values[seed as usize % n] *= 1.8;
        }
        let s = shape(&values, &model).unwrap();
        assert_eq!(s, Shape::default(), "seed {seed}, {n} points, σ {sigma}");
    }
}

#[test]
fn a_pure_step_is_a_step_exactly_as_the_step_detector_finds_it() {
    let model = Model::default();
    for seed in 0..30 {
        let mut values = ramped(seed, 80, 0, 0, 1.0, 0.008);
        for v in &mut values[40..] {
            *v *= 1.06;
        }
        let s = shape(&values, &model).unwrap();
        assert!(s.drifts.is_empty(), "seed {seed}: {s:?}");
        assert_eq!(
            s.changes,
            change_points(&values, model.detector()).unwrap(),
            "seed {seed}"
        );
        assert_eq!(s.changes.len(), 1);
        assert!(s.changes[0].index.abs_diff(40) <= 1, "{s:?}");
    }
}

#[test]
fn a_step_after_a_drift_is_both() {
    let values: Vec<f64> = ramped(9, 100, 20, 60, 1.003, 0.007)
        .into_iter()
        .enumerate()
        .map(|(i, v)| if i >= 75 { v * 0.9 } else { v })
        .collect();
    let s = shape(&values, &Model::default()).unwrap();
    assert_eq!(s.drifts.len(), 1, "{s:?}");
    assert_eq!(s.changes.len(), 1, "{s:?}");
    assert!(s.changes[0].index.abs_diff(75) <= 1, "{s:?}");
    assert!((s.changes[0].ratio - 0.9).abs() < 0.02, "{s:?}");
}

#[test]
fn segments_found_on_one_series_describe_another() {
    let values = ramped(4, 90, 20, 60, 1.003, 0.006);
    let cut = segments(&values, &Model::default()).unwrap();
    assert!(cut.iter().any(|s| s.kind == Kind::Drift), "{cut:?}");
    assert_eq!(cut.first().map(|s| s.start), Some(0));
    assert_eq!(cut.last().map(|s| s.end), Some(90));
    assert!(cut.windows(2).all(|w| w[0].end == w[1].start));
    // Twice the values: the same drift, its levels twice as high.
    let doubled: Vec<f64> = values.iter().map(|v| 2.0 * v).collect();
    let (a, b) = (
        describe_segments(&values, &cut).unwrap(),
        describe_segments(&doubled, &cut).unwrap(),
    );
    assert!((b.drifts[0].from / a.drifts[0].from - 2.0).abs() < 1e-9);
    assert!((b.drifts[0].ratio - a.drifts[0].ratio).abs() < 1e-9);
}

#[test]
fn short_series_and_bad_models_are_handled() {
    let model = Model::default();
    assert_eq!(shape(&[], &model).unwrap(), Shape::default());
    assert_eq!(shape(&[1.0, 1.1, 1.2], &model).unwrap(), Shape::default());
    assert!(segments(&[1.0, -1.0], &model).is_err());
    let d = Detector::default();
    assert_eq!(Model::new(d, 12.0, 4), Err(ChangeError::ShortSegment(4)));
    assert!(Model::new(d, 0.0, 10).is_err());
    assert!(Model::new(d, f64::NAN, 10).is_err());
    let m = Model::new(d, 8.0, 12).unwrap();
    assert_eq!((m.slope_penalty(), m.min_drift()), (8.0, 12));
}
