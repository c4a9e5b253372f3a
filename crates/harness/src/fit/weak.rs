//! Weak scaling (the problem grows with p so that each worker keeps the same work):
//! efficiency `T1/T(p)`, Gustafson's scaled speedup `S(p) = p·T1/T(p)` and his serial fraction
//! α from `S = p − α(p − 1)`.
//!
//! α is fitted by least squares on S with weights 1/p² (the noise of S grows like p), through
//! the point `S(1) = 1` that the model passes by construction.

#[cfg(test)]
use super::bootstrap::percentile_ci;
use super::bootstrap::{bootstrap, estimate};
use super::linear::Goodness;
use super::power::ComplexityClass;
use super::{CiMethod, Estimate, FitError, Input, RESAMPLES, Samples, XRule, clamp_unit, prepare};
use serde::Serialize;

const MODEL: &str = "weak scaling";

/// Samples of one weak-scaling run where the problem size is known.
#[derive(Clone, Debug, PartialEq, Serialize, serde::Deserialize)]
pub struct WeakSamples {
    /// The worker count.
    pub p: f64,
    /// The problem size of the run at `p`, particles.
    pub n: f64,
    /// The measured times, seconds.
    pub values: Vec<f64>,
}

/// Weak-scaling efficiency at one worker count.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct EfficiencyPoint {
    /// The worker count.
    pub p: f64,
    /// `T1 / T(p)`; 1 is perfect weak scaling.
    pub e: Estimate,
}

/// Gustafson's scaled speedup at one worker count.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct ScaledSpeedupPoint {
    /// The worker count.
    pub p: f64,
    /// `p · T1 / T(p)`.
    pub s: Estimate,
}

/// How far a run's work per worker is from the one-worker run's, under the cost model.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct WorkPerWorker {
    /// The worker count.
    pub p: f64,
    /// The run's problem size, particles.
    pub n: f64,
    /// `(g(n)/p) / g(n1)`; the run's times were divided by it.
    pub ratio: f64,
}

/// A weak-scaling analysis: efficiency, scaled speedup and Gustafson's serial fraction.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct WeakFit {
    /// x = p, the median time (as measured) and sample count at each p.
    pub inputs: Vec<Input>,
    /// The one-worker time, seconds (median with interval).
    pub t1: Estimate,
    /// `T1 / T(p)` at each measured p, in increasing p (the first is p = 1).
    pub efficiency: Vec<EfficiencyPoint>,
    /// `p·T1 / T(p)` at each measured p, in increasing p.
    pub scaled_speedup: Vec<ScaledSpeedupPoint>,
    /// Gustafson's α, clamped to [0, 1] (see `clamped`).
    pub serial_fraction: Estimate,
    pub(crate) serial_fraction_unclamped: Estimate,
    /// Whether α or an end of its interval was clamped to [0, 1].
    pub clamped: bool,
    /// Fit of `p − α(p − 1)` to the measured scaled speedups (r² weighted by 1/p²).
    pub goodness: Goodness,
    /// With problem sizes given: the cost model `g(n)` used to check and normalise the work
    /// per worker.
    pub cost_model: Option<ComplexityClass>,
    /// With problem sizes given: each p's work per worker relative to p = 1's; `None` without.
    pub work_per_worker: Option<Vec<WorkPerWorker>>,
    /// How the bootstrap drew its replicates (decides what the intervals include).
    pub ci_method: CiMethod,
    /// The number of bootstrap replicates drawn (before degenerate ones were dropped).
    pub resamples: usize,
    /// Warnings for a reader, one sentence each: clamping, work per worker off by more than 2%.
    pub notes: Vec<String>,
    /// Clamped α of every bootstrap replicate, for curve bands.
    #[serde(skip)]
    replicates: Vec<f64>,
}

impl WeakFit {
    #[cfg(test)]
    /// Gustafson's scaled speedup `p − α(p − 1)` at any p with its 95% band.
    pub(crate) fn scaled_speedup_curve(&self, p: f64) -> (f64, [f64; 2]) {
        let at = |a: f64| p - a * (p - 1.0);
        let point = at(self.serial_fraction.estimate);
        let band = percentile_ci(self.replicates.iter().map(|&a| at(a)));
        (point, band.unwrap_or([point, point]))
    }

    /// α (clamped) of every bootstrap replicate, for custom bands.
    pub fn replicates(&self) -> &[f64] {
        &self.replicates
    }
}

/// Weak scaling from times at x = p (each at the scaled problem size). Needs p = 1 and one
/// more p.
pub fn fit_weak(samples: &[Samples], seed: u64) -> Result<WeakFit, FitError> {
    let data = prepare(MODEL, samples, XRule::AtLeastOne, 2)?;
    if data.xs[0] != 1.0 {
        return Err(FitError::NoBaseline {
            model: MODEL,
            measured: data
                .xs
                .iter()
                .map(f64::to_string)
                .collect::<Vec<_>>()
                .join(", "),
        });
    }
    let ps = &data.xs;
    let scaled = |t: &[f64]| -> Vec<f64> { (0..ps.len()).map(|i| ps[i] * t[0] / t[i]).collect() };
    let alpha_of = |t: &[f64]| -> f64 {
        let s = scaled(t);
        let (mut num, mut den) = (0.0, 0.0);
        for i in 0..ps.len() {
            let w = 1.0 / (ps[i] * ps[i]);
            num += w * (ps[i] - s[i]) * (ps[i] - 1.0);
            den += w * (ps[i] - 1.0).powi(2);
        }
        num / den
    };
    let alpha = alpha_of(&data.medians);
    let model_s = |a: f64, p: f64| p - a * (p - 1.0);
    let t1 = data.medians[0];
    let fitted: Vec<f64> = ps.iter().map(|&p| p * t1 / model_s(alpha, p)).collect();
    let reps = bootstrap(MODEL, &data, &fitted, 2, seed, |t| {
        Some((t[0], scaled(t), alpha_of(t)))
    })?;
    let fits = &reps.fits;

    let s_point = scaled(&data.medians);
    let mut efficiency = Vec::with_capacity(ps.len());
    let mut scaled_speedup = Vec::with_capacity(ps.len());
    for (i, &p) in ps.iter().enumerate() {
        let s = estimate(s_point[i], fits.iter().map(|r| r.1[i]));
        scaled_speedup.push(ScaledSpeedupPoint { p, s });
        efficiency.push(EfficiencyPoint {
            p,
            e: s.map(|s| s / p),
        });
    }
    let unclamped = estimate(alpha, fits.iter().map(|r| r.2));
    let serial_fraction = unclamped.map(|a| clamp_unit(a).0);
    let clamped = serial_fraction != unclamped;
    let predicted: Vec<f64> = ps.iter().map(|&p| model_s(alpha, p)).collect();
    let weights: Vec<f64> = ps.iter().map(|p| 1.0 / (p * p)).collect();
    let mut notes = Vec::new();
    if clamped {
        notes.push(format!(
            "the fitted serial fraction is {:.4} [{:.4}, {:.4}]; it is reported clamped to [0, 1]",
            unclamped.estimate, unclamped.ci95[0], unclamped.ci95[1]
        ));
    }
    Ok(WeakFit {
        inputs: data.inputs(),
        t1: estimate(t1, fits.iter().map(|r| r.0)),
        efficiency,
        scaled_speedup,
        serial_fraction,
        serial_fraction_unclamped: unclamped,
        clamped,
        goodness: Goodness::of(&s_point, &predicted, &weights),
        cost_model: None,
        work_per_worker: None,
        ci_method: reps.method,
        resamples: RESAMPLES,
        notes,
        replicates: fits.iter().map(|r| clamp_unit(r.2).0).collect(),
    })
}

/// Weak scaling where each run's problem size n is known. Under the cost model `g(n)` (work
/// of the whole problem) a worker's work is `g(n)/p`; a run whose work per worker differs from
/// the one-worker run's by the ratio r had its times divided by r before [`fit_weak`], i.e.
/// time is taken as proportional to work per worker. The ratios are reported, with a note when
/// any differs from 1 by more than 2%.
pub fn fit_weak_with_n(
    samples: &[WeakSamples],
    cost: ComplexityClass,
    seed: u64,
) -> Result<WeakFit, FitError> {
    let mut sizes: Vec<(f64, f64)> = Vec::new();
    for s in samples {
        if !(s.p.is_finite() && s.n.is_finite()) {
            return Err(FitError::NotFinite {
                model: MODEL,
                x: s.p,
            });
        }
        if s.p < 1.0 {
            return Err(FitError::BadX {
                model: MODEL,
                x: s.p,
                expected: "worker counts must be >= 1",
            });
        }
        if cost.g(s.n).is_nan() || cost.g(s.n) <= 0.0 {
            return Err(FitError::BadX {
                model: MODEL,
                x: s.n,
                expected: "problem sizes must be > 0, and > 1 for a cost model with log n",
            });
        }
        // Checked here so that errors quote the measured values, not normalised ones.
        if let Some(&v) = s.values.iter().find(|v| !v.is_finite() || **v <= 0.0) {
            return Err(if v.is_finite() {
                FitError::NonPositive {
                    model: MODEL,
                    x: s.p,
                    value: v,
                }
            } else {
                FitError::NotFinite {
                    model: MODEL,
                    x: s.p,
                }
            });
        }
        match sizes.iter().find(|(p, _)| *p == s.p) {
            Some(&(p, n)) if n != s.n => {
                return Err(FitError::InconsistentN {
                    model: MODEL,
                    p,
                    n_first: n,
                    n_other: s.n,
                });
            }
            Some(_) => {}
            None => sizes.push((s.p, s.n)),
        }
    }
    let Some(&(_, n1)) = sizes.iter().find(|(p, _)| *p == 1.0) else {
        let mut ps: Vec<f64> = sizes.iter().map(|s| s.0).collect();
        ps.sort_by(f64::total_cmp);
        return Err(FitError::NoBaseline {
            model: MODEL,
            measured: ps.iter().map(f64::to_string).collect::<Vec<_>>().join(", "),
        });
    };
    let ratio = |p: f64, n: f64| (cost.g(n) / p) / cost.g(n1);
    let normalised: Vec<Samples> = samples
        .iter()
        .map(|s| {
            let r = ratio(s.p, s.n);
            Samples::new(s.p, s.values.iter().map(|v| v / r).collect())
        })
        .collect();
    let mut fit = fit_weak(&normalised, seed)?;
    sizes.sort_by(|a, b| a.0.total_cmp(&b.0));
    let work: Vec<WorkPerWorker> = sizes
        .iter()
        .map(|&(p, n)| WorkPerWorker {
            p,
            n,
            ratio: ratio(p, n),
        })
        .collect();
    // Report the times as measured; the fit itself used the normalised ones.
    for (input, w) in fit.inputs.iter_mut().zip(&work) {
        input.median *= w.ratio;
    }
    if let Some(worst) = work
        .iter()
        .max_by(|a, b| (a.ratio - 1.0).abs().total_cmp(&(b.ratio - 1.0).abs()))
        .filter(|w| (w.ratio - 1.0).abs() > 0.02)
    {
        fit.notes.push(format!(
            "under cost model {} the work per worker at p = {} (n = {}) is {:.3} times that at \
             p = 1; times were divided by these ratios before fitting (time taken as proportional \
             to work per worker)",
            cost.name(),
            worst.p,
            worst.n,
            worst.ratio
        ));
    }
    fit.cost_model = Some(cost);
    fit.work_per_worker = Some(work);
    Ok(fit)
}

#[cfg(test)]
#[path = "weak_tests.rs"]
mod tests;
