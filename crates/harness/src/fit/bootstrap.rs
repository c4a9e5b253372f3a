//! The seeded bootstrap shared by every fit: replicate per-x medians, refit, collect.

use super::{Data, Estimate, FitError};
use nbody_engine::stats::{BOOTSTRAP_RESAMPLES as RESAMPLES, bootstrap_medians, interval95};
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64Mcg;
use serde::Serialize;

/// How the replicate medians of a bootstrap were drawn.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum CiMethod {
    /// Every x has at least two samples: each replicate redraws that many samples with
    /// replacement from the same x and takes their median (x values stay fixed). The interval
    /// is the measurement noise propagated through the fit.
    ResampleWithinX,
    /// Some x has a single sample: each replicate is the fitted curve times the fit's own
    /// relative residuals (log ratios, centred, inflated by sqrt(m / (m - parameters))) redrawn
    /// across x. The interval then also carries the scatter of the points about the model.
    ResampleResiduals,
}

impl CiMethod {
    /// A phrase for reports saying how the intervals were obtained.
    pub fn describe(self) -> &'static str {
        match self {
            CiMethod::ResampleWithinX => "resampling the raw samples within each x",
            CiMethod::ResampleResiduals => {
                "resampling the fit's residuals across x (one sample at some x)"
            }
        }
    }
}

/// The replicate fits of one bootstrap run.
pub(crate) struct Replicates<T> {
    pub method: CiMethod,
    pub fits: Vec<T>,
}

/// Runs [`RESAMPLES`] replicates: draws replicate medians for every x of `data` (see
/// [`CiMethod`]) and calls `fit` on them. `fitted` are the point fit's predictions at each x
/// (used by residual resampling) and `params` its number of free parameters. Replicates where
/// `fit` returns `None` (a degenerate resample) are dropped; if more than half are, the fit is
/// refused.
pub(crate) fn bootstrap<T>(
    model: &'static str,
    data: &Data,
    fitted: &[f64],
    params: usize,
    seed: u64,
    mut fit: impl FnMut(&[f64]) -> Option<T>,
) -> Result<Replicates<T>, FitError> {
    let m = data.len();
    let within = data.values.iter().all(|v| v.len() >= 2);
    let fits = if within {
        let groups: Vec<&[f64]> = data.values.iter().map(Vec::as_slice).collect();
        bootstrap_medians(&groups, RESAMPLES, seed, &mut fit)
    } else {
        if m <= params {
            return Err(FitError::NoSpread {
                model,
                points: m,
                params,
            });
        }
        if fitted.iter().any(|&f| !(f > 0.0 && f.is_finite())) {
            return Err(FitError::Degenerate {
                model,
                why: "the fitted curve is not positive at every measured x",
            });
        }
        let logs: Vec<f64> = (0..m).map(|i| (data.medians[i] / fitted[i]).ln()).collect();
        let mean = logs.iter().sum::<f64>() / m as f64;
        let inflate = (m as f64 / (m - params) as f64).sqrt();
        let residuals: Vec<f64> = logs.iter().map(|r| (r - mean) * inflate).collect();
        let mut rng = Pcg64Mcg::seed_from_u64(seed);
        let mut medians = vec![0.0; m];
        let mut fits = Vec::with_capacity(RESAMPLES);
        for _ in 0..RESAMPLES {
            for i in 0..m {
                medians[i] = fitted[i] * residuals[rng.random_range(0..m)].exp();
            }
            fits.extend(fit(&medians));
        }
        fits
    };
    if fits.len() * 2 < RESAMPLES {
        return Err(FitError::Degenerate {
            model,
            why: "most bootstrap resamples give no fit; the data barely determine the model",
        });
    }
    Ok(Replicates {
        method: if within {
            CiMethod::ResampleWithinX
        } else {
            CiMethod::ResampleResiduals
        },
        fits,
    })
}

/// The 95% percentile interval of replicates (see `stats::interval95`).
pub(crate) fn percentile_ci(values: impl IntoIterator<Item = f64>) -> Option<[f64; 2]> {
    interval95(values)
}

/// A point estimate with the percentile interval of its replicates.
pub(crate) fn estimate(point: f64, replicates: impl IntoIterator<Item = f64>) -> Estimate {
    Estimate {
        estimate: point,
        ci95: percentile_ci(replicates).unwrap_or([point, point]),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fit::{Samples, XRule, prepare};

    #[test]
    fn method_follows_the_sample_counts_and_is_reproducible() {
        let many = [
            Samples::new(1.0, vec![1.0, 1.1, 0.9]),
            Samples::new(2.0, vec![2.0, 2.2]),
        ];
        let d = prepare("m", &many, XRule::Positive, 2).unwrap();
        let run = |seed| bootstrap("m", &d, &d.medians, 1, seed, |m| Some(m[0])).unwrap();
        let a = run(3);
        assert_eq!(a.method, CiMethod::ResampleWithinX);
        assert_eq!(a.fits, run(3).fits, "same seed, same replicates");
        assert!(a.fits.iter().all(|&m| (0.9..=1.1).contains(&m)));

        let single = [
            Samples::new(1.0, vec![1.0]),
            Samples::new(2.0, vec![2.1]),
            Samples::new(3.0, vec![2.9]),
        ];
        let d = prepare("m", &single, XRule::Positive, 2).unwrap();
        let fitted = [1.0, 2.0, 3.0];
        let r = bootstrap("m", &d, &fitted, 1, 1, |m| Some(m[1])).unwrap();
        assert_eq!(r.method, CiMethod::ResampleResiduals);
        let ci = percentile_ci(r.fits).unwrap();
        assert!(ci[0] < 2.0 && ci[1] > 2.0, "{ci:?}");
        assert!(matches!(
            bootstrap("m", &d, &fitted, 3, 1, |m| Some(m[0])),
            Err(FitError::NoSpread { points: 3, .. })
        ));
    }
}
