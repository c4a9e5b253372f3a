//! The α-β (Hockney) model of message time, `t = α + β·bytes`: latency α and inverse bandwidth
//! β, fitted on relative residuals so that small messages (which fix α) count as much as large
//! ones (which fix β). Used to predict communication time beyond the sizes measured.

#[cfg(test)]
use super::bootstrap::percentile_ci;
use super::bootstrap::{bootstrap, estimate};
use super::linear::{self, Goodness};
use super::{CiMethod, Estimate, FitError, Input, RESAMPLES, Samples, XRule, prepare};
use serde::Serialize;

const MODEL: &str = "alpha-beta";

#[derive(Clone, Debug, PartialEq, Serialize)]
pub(crate) struct AlphaBetaFit {
    /// x = bytes, the median seconds per message and sample count at each size.
    pub inputs: Vec<Input>,
    /// Latency, seconds.
    pub alpha: Estimate,
    /// Seconds per byte.
    pub(crate) beta: Estimate,
    /// `1/β`, bytes per second (infinite, JSON null, when β's interval reaches 0).
    pub bandwidth: Estimate,
    /// Fit to the medians (r² on relative residuals).
    pub goodness: Goodness,
    pub ci_method: CiMethod,
    pub resamples: usize,
    pub notes: Vec<String>,
    /// `(α, β)` of every bootstrap replicate, for prediction intervals.
    #[serde(skip)]
    replicates: Vec<[f64; 2]>,
}

impl AlphaBetaFit {
    #[cfg(test)]
    /// Predicted seconds for one message of `bytes`, with the 95% interval of the fitted line
    /// there (parameter uncertainty; a single message scatters more). Far beyond the measured
    /// sizes the interval only says how well the line is known, not that the line still holds.
    pub(crate) fn predict(&self, bytes: f64) -> (f64, [f64; 2]) {
        let point = self.alpha.estimate + self.beta.estimate * bytes;
        let band = percentile_ci(self.replicates.iter().map(|[a, b]| a + b * bytes));
        (point, band.unwrap_or([point, point]))
    }

    /// `[α, β]` of every bootstrap replicate, for custom bands.
    pub fn replicates(&self) -> &[[f64; 2]] {
        &self.replicates
    }
}

fn one(_: f64) -> f64 {
    1.0
}
fn identity(bytes: f64) -> f64 {
    bytes
}

/// Fits `t = α + β·bytes` to samples at x = message size in bytes (>= 0), values = seconds per
/// message. Needs 2 distinct sizes (3 when some size has a single sample).
pub(crate) fn fit_alpha_beta(samples: &[Samples], seed: u64) -> Result<AlphaBetaFit, FitError> {
    let data = prepare(MODEL, samples, XRule::NonNegative, 2)?;
    let line = |t: &[f64]| -> Option<[f64; 2]> {
        let beta = linear::fit_relative(&[&one, &identity], &data.xs, t)?;
        Some([beta[0], beta[1]])
    };
    let [alpha, beta] = line(&data.medians).ok_or(FitError::Degenerate {
        model: MODEL,
        why: "least squares is singular",
    })?;
    let fitted: Vec<f64> = data.xs.iter().map(|b| alpha + beta * b).collect();
    let reps = bootstrap(MODEL, &data, &fitted, 2, seed, line)?;
    let alpha_est = estimate(alpha, reps.fits.iter().map(|r| r[0]));
    let beta_est = estimate(beta, reps.fits.iter().map(|r| r[1]));
    let mut notes = Vec::new();
    if alpha_est.ci95[0] <= 0.0 {
        notes.push(
            "the latency's interval reaches 0 or below: the smallest messages do not resolve it; \
             measure smaller messages or more repetitions"
                .into(),
        );
    }
    if beta_est.ci95[0] <= 0.0 {
        notes.push(
            "the per-byte cost's interval reaches 0 or below: the largest messages are too small \
             to resolve the bandwidth; measure larger messages"
                .into(),
        );
    }
    Ok(AlphaBetaFit {
        inputs: data.inputs(),
        alpha: alpha_est,
        beta: beta_est,
        bandwidth: beta_est.map(|b| if b > 0.0 { 1.0 / b } else { f64::INFINITY }),
        goodness: Goodness::of(
            &data.medians,
            &fitted,
            &linear::relative_weights(&data.medians),
        ),
        ci_method: reps.method,
        resamples: RESAMPLES,
        notes,
        replicates: reps.fits,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fit::synthetic::{count, noisy};

    const ALPHA: f64 = 2e-6;
    const BETA: f64 = 1e-10;

    fn sizes() -> Vec<f64> {
        (0..=10).map(|e| 8.0 * 4f64.powi(e)).collect()
    }

    #[test]
    fn latency_and_bandwidth_intervals_cover_the_truth() {
        let hits = count(50, |seed| {
            let s = noisy(&sizes(), 7, 0.05, seed, |b| ALPHA + BETA * b);
            let fit = fit_alpha_beta(&s, seed).unwrap();
            fit.alpha.contains(ALPHA) && fit.beta.contains(BETA)
        });
        assert!(hits >= 40, "{hits} of 50 contain both");
    }

    #[test]
    fn prediction_beyond_the_measured_sizes() {
        let s = noisy(&sizes(), 9, 0.03, 7, |b| ALPHA + BETA * b);
        let fit = fit_alpha_beta(&s, 7).unwrap();
        let far = 1e9;
        let (t, band) = fit.predict(far);
        let truth = ALPHA + BETA * far;
        assert!(band[0] < t && t < band[1] && band[0] < truth && truth < band[1]);
        assert!((t / truth - 1.0).abs() < 0.05);
        let (t0, band0) = fit.predict(0.0);
        assert!((t0 - fit.alpha.estimate).abs() < 1e-18 && band0 == fit.alpha.ci95);
        assert!(fit.bandwidth.contains(1.0 / BETA));
        let json = serde_json::to_value(&fit).unwrap();
        assert!(json["alpha"]["ci95"].is_array() && json["beta"]["estimate"].is_number());
        assert!(json.get("replicates").is_none());
    }

    #[test]
    fn degenerate_input_is_refused() {
        let one = noisy(&[1024.0], 5, 0.01, 1, |b| ALPHA + BETA * b);
        assert!(matches!(
            fit_alpha_beta(&one, 1),
            Err(FitError::OneX { .. })
        ));
        let mut s = noisy(&sizes(), 3, 0.01, 1, |b| ALPHA + BETA * b);
        s[0].x = -8.0;
        assert!(matches!(fit_alpha_beta(&s, 1), Err(FitError::BadX { .. })));
        s[0].x = 0.0;
        assert!(
            fit_alpha_beta(&s, 1).is_ok(),
            "zero-byte messages are valid"
        );
        s[1].values[0] = 0.0;
        assert!(matches!(
            fit_alpha_beta(&s, 1),
            Err(FitError::NonPositive { .. })
        ));
        s[1].values[0] = f64::NAN;
        assert!(matches!(
            fit_alpha_beta(&s, 1),
            Err(FitError::NotFinite { .. })
        ));
    }
}
