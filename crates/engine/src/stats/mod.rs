//! The statistics of measured samples, written once for `run`, `sweep`, `fit` and `gate`.
//!
//! - **Median**: the middle value, the mean of the two middle values for an even count.
//! - **Quantile** (one definition everywhere): the nearest rank, `Q(q) = x₍⌈qN⌉₎` of the `N`
//!   sorted values (rank clamped to 1…N) — the value below which at least a fraction `q` of
//!   the samples lie. Step-time histograms ([`StepHistogram`]) give the same rank to their
//!   three significant digits; percentile intervals of bootstraps use it on the replicates.
//! - **MAD**: the median absolute deviation from the median, unscaled.
//! - **Bootstrap** ([`bootstrap_medians`]): seeded resampling with replacement within each
//!   group of samples, the statistic computed from the groups' medians.

mod bootstrap;
mod steps;

pub use bootstrap::{
    BOOTSTRAP_RESAMPLES, bootstrap_median_ci, bootstrap_medians, bootstrap_ratio_ci,
};
pub use steps::{StepHistogram, StepPercentiles};

/// Median of a slice of floats (NaN-free); `None` when empty.
pub fn median(values: &[f64]) -> Option<f64> {
    (!values.is_empty()).then(|| median_in_place(&mut values.to_vec()))
}

/// The median of a non-empty slice, reordering it (linear time: a bootstrap takes thousands).
pub(crate) fn median_in_place(v: &mut [f64]) -> f64 {
    let (len, mid) = (v.len(), v.len() / 2);
    let (below, upper, _) = v.select_nth_unstable_by(mid, f64::total_cmp);
    let upper = *upper;
    if len % 2 == 1 {
        upper
    } else {
        let lower = below.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        0.5 * (lower + upper)
    }
}

/// Median absolute deviation from the median; `None` when empty.
pub fn mad(values: &[f64]) -> Option<f64> {
    let m = median(values)?;
    let dev: Vec<f64> = values.iter().map(|v| (v - m).abs()).collect();
    median(&dev)
}

/// The nearest-rank quantile `q` (in [0, 1]) of values sorted in ascending order; `None` when
/// there are none.
pub(crate) fn quantile_of_sorted<T: Copy>(sorted: &[T], q: f64) -> Option<T> {
    let n = sorted.len();
    let rank = ((q.clamp(0.0, 1.0) * n as f64).ceil() as usize).clamp(1, n.max(1));
    sorted.get(rank - 1).copied()
}

/// The 2.5% and 97.5% quantiles of `values` (NaN ignored; infinities kept): the 95%
/// percentile interval of bootstrap replicates. `None` if no value is left.
pub fn interval95(values: impl IntoIterator<Item = f64>) -> Option<[f64; 2]> {
    let mut v: Vec<f64> = values.into_iter().filter(|x| !x.is_nan()).collect();
    v.sort_by(f64::total_cmp);
    Some([
        quantile_of_sorted(&v, 0.025)?,
        quantile_of_sorted(&v, 0.975)?,
    ])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn median_of_even_and_odd() {
        assert_eq!(median(&[3.0, 1.0, 2.0]), Some(2.0));
        assert_eq!(median(&[4.0, 1.0, 2.0, 3.0]), Some(2.5));
        assert_eq!(median(&[]), None);
        for v in [
            vec![3.0],
            vec![2.0, 1.0],
            vec![5.0, 1.0, 4.0, 2.0],
            vec![1.0, 9.0, 3.0, 3.0, 7.0],
        ] {
            let mut sorted = v.clone();
            sorted.sort_by(f64::total_cmp);
            let m = sorted.len() / 2;
            let want = if sorted.len() % 2 == 1 {
                sorted[m]
            } else {
                0.5 * (sorted[m - 1] + sorted[m])
            };
            assert_eq!(median_in_place(&mut v.clone()), want, "{v:?}");
        }
    }

    #[test]
    fn mad_of_an_outlier() {
        assert_eq!(mad(&[1.0, 2.0, 3.0, 4.0, 100.0]), Some(1.0));
        assert_eq!(mad(&[]), None);
    }

    #[test]
    fn nearest_rank_quantiles() {
        let v: Vec<u64> = (1..=100).collect();
        let q = |p| quantile_of_sorted(&v, p).unwrap();
        assert_eq!(
            (q(0.0), q(0.5), q(0.9), q(0.99), q(1.0)),
            (1, 50, 90, 99, 100)
        );
        // Between ranks the next one up: 0.505 × 100 = 50.5 → rank 51.
        assert_eq!(q(0.505), 51);
        assert_eq!(quantile_of_sorted(&[7], 0.99), Some(7));
        assert_eq!(quantile_of_sorted::<u64>(&[], 0.5), None);
    }

    #[test]
    fn interval_skips_nan_and_keeps_infinity() {
        let v: Vec<f64> = (1..=1000).map(f64::from).collect();
        assert_eq!(interval95(v), Some([25.0, 975.0]));
        assert_eq!(interval95([f64::NAN, 3.0]), Some([3.0, 3.0]));
        assert_eq!(interval95([f64::NAN]), None);
        assert_eq!(interval95([0.0, f64::INFINITY]).unwrap()[1], f64::INFINITY);
    }
}
