//! Step times: an HDR histogram whose memory does not grow with the number of steps, and its
//! percentiles.

use serde::Serialize;

/// Order statistics of per-step times in nanoseconds.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, serde::Deserialize)]
pub struct StepPercentiles {
    /// Fastest step.
    pub min: u64,
    /// Median step.
    pub p50: u64,
    /// 90th percentile.
    pub p90: u64,
    /// 99th percentile.
    pub p99: u64,
    /// Slowest step.
    pub max: u64,
    /// Mean step time, from the histogram's values (to its three digits).
    pub mean: f64,
}

/// Step times as a histogram, from 1 ns to an hour at three significant digits (values beyond
/// are clamped, not dropped). `run`, the MPI drivers and the sweep's records all use it, so
/// the same steps give the same p99 everywhere.
#[derive(Clone)]
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
    /// An empty histogram.
    pub fn new() -> Self {
        StepHistogram {
            hist: hdrhistogram::Histogram::new_with_bounds(1, 3_600_000_000_000, 3)
                .expect("valid histogram bounds"),
            sum_ns: 0,
        }
    }

    /// A histogram from stored `[value, count]` pairs (see [`StepHistogram::counts`]); its sum
    /// is then that of the stored values, exact to the histogram's resolution.
    pub fn from_counts(counts: &[[u64; 2]]) -> Self {
        let mut h = StepHistogram::new();
        for &[value, count] in counts {
            h.record_n(value, count);
        }
        h
    }

    /// Records one step of `ns` nanoseconds (0 counts as 1 ns).
    pub fn record(&mut self, ns: u64) {
        self.record_n(ns, 1);
    }

    /// Records `count` steps of `ns` each.
    pub fn record_n(&mut self, ns: u64, count: u64) {
        self.hist.saturating_record_n(ns.max(1), count);
        self.sum_ns += u128::from(ns) * u128::from(count);
    }

    /// The recorded values as `[value, count]` pairs, ascending: what a results file keeps.
    pub fn counts(&self) -> Vec<[u64; 2]> {
        self.hist
            .iter_recorded()
            .map(|v| [v.value_iterated_to(), v.count_at_value()])
            .collect()
    }

    /// Sum of the recorded step times, seconds.
    pub(crate) fn sum_s(&self) -> f64 {
        self.sum_ns as f64 * 1e-9
    }

    /// Nearest-rank percentiles (see the module `stats`) at the histogram's resolution;
    /// `None` when it is empty.
    pub fn percentiles(&self) -> Option<StepPercentiles> {
        let h = &self.hist;
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::stats::quantile_of_sorted;

    #[test]
    fn percentiles_are_the_nearest_rank_to_three_digits() {
        // Times spread over four decades, in a scrambled order.
        let mut steps: Vec<u64> = (0..997u64)
            .map(|i| 1_000 + (i * 7_919 % 997).pow(3))
            .collect();
        let mut h = StepHistogram::new();
        for &s in &steps {
            h.record(s);
        }
        steps.sort_unstable();
        let p = h.percentiles().unwrap();
        for (got, q) in [(p.p50, 0.5), (p.p90, 0.9), (p.p99, 0.99)] {
            let want = quantile_of_sorted(&steps, q).unwrap() as f64;
            assert!(
                (got as f64 - want).abs() <= 1e-3 * want,
                "q {q}: {got} vs {want}"
            );
        }
        assert_eq!(p.min, steps[0]);
        assert!((p.max as f64 - steps[996] as f64).abs() <= 1e-3 * steps[996] as f64);
        assert!(StepHistogram::new().percentiles().is_none());
    }

    #[test]
    fn counts_round_trip_and_sums_are_exact() {
        let mut h = StepHistogram::new();
        for s in [5, 5, 7, 1_000_000] {
            h.record(s);
        }
        assert_eq!(h.sum_s(), 1_000_017e-9);
        let back = StepHistogram::from_counts(&h.counts());
        assert_eq!(back.counts(), h.counts());
        assert_eq!(back.percentiles(), h.percentiles());
    }
}
