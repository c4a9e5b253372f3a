//! Summary statistics of measured samples.

use serde::Serialize;

/// Order statistics of per-step times in nanoseconds.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, serde::Deserialize)]
pub struct StepPercentiles {
    pub min: u64,
    pub p50: u64,
    pub p90: u64,
    pub p99: u64,
    pub max: u64,
    pub mean: f64,
}

impl StepPercentiles {
    /// Percentiles by the nearest-rank method; `None` for no samples.
    pub fn of(samples: &[u64]) -> Option<Self> {
        if samples.is_empty() {
            return None;
        }
        let mut s = samples.to_vec();
        s.sort_unstable();
        let rank = |q: f64| s[((q * s.len() as f64).ceil() as usize).clamp(1, s.len()) - 1];
        Some(StepPercentiles {
            min: s[0],
            p50: rank(0.5),
            p90: rank(0.9),
            p99: rank(0.99),
            max: s[s.len() - 1],
            mean: s.iter().map(|&x| x as f64).sum::<f64>() / s.len() as f64,
        })
    }
}

impl StepPercentiles {
    /// Percentiles of an HDR histogram (3 significant digits); `None` when it is empty. The
    /// one definition `run` and `sweep` share, so both give the same p99 for the same steps.
    pub fn of_histogram(h: &hdrhistogram::Histogram<u64>) -> Option<Self> {
        (!h.is_empty()).then(|| StepPercentiles {
            min: h.min(),
            p50: h.value_at_quantile(0.5),
            p90: h.value_at_quantile(0.9),
            p99: h.value_at_quantile(0.99),
            max: h.max(),
            mean: h.mean(),
        })
    }
}

/// Step times as a histogram: memory that does not grow with the number of steps.
pub struct StepHistogram {
    hist: hdrhistogram::Histogram<u64>,
    sum_ns: u128,
}

impl Default for StepHistogram {
    fn default() -> Self {
        Self::new()
    }
}

impl StepHistogram {
    /// From 1 ns to an hour, 3 significant digits (values beyond are clamped, not dropped).
    pub fn new() -> Self {
        StepHistogram {
            hist: hdrhistogram::Histogram::new_with_bounds(1, 3_600_000_000_000, 3)
                .expect("valid histogram bounds"),
            sum_ns: 0,
        }
    }

    pub fn record(&mut self, ns: u64) {
        self.hist.saturating_record(ns.max(1));
        self.sum_ns += u128::from(ns);
    }

    /// Sum of the recorded step times, seconds.
    pub fn sum_s(&self) -> f64 {
        self.sum_ns as f64 * 1e-9
    }

    pub fn percentiles(&self) -> Option<StepPercentiles> {
        StepPercentiles::of_histogram(&self.hist)
    }
}

/// Median of a slice of floats (NaN-free); `None` when empty.
pub fn median(values: &[f64]) -> Option<f64> {
    if values.is_empty() {
        return None;
    }
    let mut v = values.to_vec();
    v.sort_by(f64::total_cmp);
    let m = v.len() / 2;
    Some(if v.len() % 2 == 1 {
        v[m]
    } else {
        0.5 * (v[m - 1] + v[m])
    })
}

/// Median absolute deviation from the median; `None` when empty.
pub fn mad(values: &[f64]) -> Option<f64> {
    let m = median(values)?;
    let dev: Vec<f64> = values.iter().map(|v| (v - m).abs()).collect();
    median(&dev)
}

/// Percentile bootstrap 95% confidence interval of the median: `resamples` resamples with
/// replacement drawn from a generator seeded with `seed`, so the interval is reproducible.
pub fn bootstrap_median_ci(values: &[f64], resamples: usize, seed: u64) -> Option<[f64; 2]> {
    use rand::{Rng, SeedableRng};
    if values.is_empty() {
        return None;
    }
    let mut rng = rand_pcg::Pcg64Mcg::seed_from_u64(seed);
    let mut medians = Vec::with_capacity(resamples);
    let mut buf = vec![0.0; values.len()];
    for _ in 0..resamples.max(1) {
        for b in buf.iter_mut() {
            *b = values[rng.random_range(0..values.len())];
        }
        medians.push(median(&buf).expect("non-empty"));
    }
    medians.sort_by(f64::total_cmp);
    let at = |q: f64| medians[((q * medians.len() as f64) as usize).min(medians.len() - 1)];
    Some([at(0.025), at(0.975)])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn nearest_rank_percentiles() {
        let s: Vec<u64> = (1..=100).rev().collect();
        let p = StepPercentiles::of(&s).unwrap();
        assert_eq!((p.min, p.p50, p.p90, p.p99, p.max), (1, 50, 90, 99, 100));
        assert_eq!(p.mean, 50.5);
        let one = StepPercentiles::of(&[7]).unwrap();
        assert_eq!((one.p50, one.p99, one.max), (7, 7, 7));
        assert!(StepPercentiles::of(&[]).is_none());
    }

    #[test]
    fn mad_and_bootstrap() {
        assert_eq!(mad(&[1.0, 2.0, 3.0, 4.0, 100.0]), Some(1.0));
        let v: Vec<f64> = (0..101).map(|i| i as f64).collect();
        let ci = bootstrap_median_ci(&v, 2000, 7).unwrap();
        assert!(
            ci[0] < 50.0 && ci[1] > 50.0 && ci[0] > 35.0 && ci[1] < 65.0,
            "{ci:?}"
        );
        assert_eq!(
            ci,
            bootstrap_median_ci(&v, 2000, 7).unwrap(),
            "seeded: reproducible"
        );
        assert_eq!(bootstrap_median_ci(&[3.0], 100, 1), Some([3.0, 3.0]));
    }

    #[test]
    fn median_of_even_and_odd() {
        assert_eq!(median(&[3.0, 1.0, 2.0]), Some(2.0));
        assert_eq!(median(&[4.0, 1.0, 2.0, 3.0]), Some(2.5));
        assert_eq!(median(&[]), None);
    }
}
