//! Synthetic measurements for the fit tests: a model's times with multiplicative log-normal
//! noise of median 1, so the median of the samples at each x estimates the model's value.

use super::Samples;
use rand::SeedableRng;
use rand_distr::{Distribution, Normal};
use rand_pcg::Pcg64Mcg;

/// `per_x` samples of `model(x)` at every x, each times `exp(sigma · z)` with z ~ N(0, 1).
pub(crate) fn noisy(
    xs: &[f64],
    per_x: usize,
    sigma: f64,
    seed: u64,
    model: impl Fn(f64) -> f64,
) -> Vec<Samples> {
    let mut rng = Pcg64Mcg::seed_from_u64(seed);
    let z = Normal::new(0.0, 1.0).expect("valid normal");
    xs.iter()
        .map(|&x| {
            let values = (0..per_x)
                .map(|_| model(x) * (sigma * z.sample(&mut rng)).exp())
                .collect();
            Samples::new(x, values)
        })
        .collect()
}

/// How many of `trials` seeded trials satisfy `check` (seeds 1, 2, …).
pub fn count(trials: u64, check: impl Fn(u64) -> bool) -> u64 {
    (1..=trials).filter(|&seed| check(seed)).count() as u64
}

/// The thread counts most scaling studies use.
pub(crate) const THREADS: [f64; 5] = [1.0, 2.0, 4.0, 8.0, 16.0];
