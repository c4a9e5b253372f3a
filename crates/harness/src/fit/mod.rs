//! Scaling-model fits: pure functions from measured samples to parameters with 95% confidence
//! intervals. No I/O: every result is a plain struct that serializes to JSON.
//!
//! The input is always raw samples grouped by x ([`Samples`]): x is the thread count `p`, the
//! particle count `n` or a message size in bytes, the values are seconds. Each fit works on the
//! per-x medians and gets its confidence intervals from a seeded bootstrap ([`CiMethod`]):
//! resampling the raw samples within each x when every x has at least two, otherwise
//! resampling the fit's residuals across x.
//!
//! - [`power`]: `T = c·n^k` and the complexity class chosen by leave-one-out cross-validation;
//! - [`growth`]: what may be said of the growth: a class only where k agrees with it;
//! - [`strong`]: speedup, efficiency, Amdahl's serial fraction, Karp-Flatt and overhead terms;
//! - [`weak`]: weak-scaling efficiency and Gustafson's serial fraction;
//! - [`timed`]: the serial fraction from timed serial phases, compared with the fitted one;
//! - [`shared`]: a study measured on a shared machine, whose loss of speedup is not the code's;
//! - [`alpha_beta`]: the α-β (latency-bandwidth) model of message time;
//! - [`csv`]: reading `(p or n, time)` tables written by other codes.

pub mod alpha_beta;
mod bootstrap;
pub mod csv;
pub mod growth;
mod karp_flatt;
mod linear;
mod overhead;
pub mod power;
pub mod shared;
pub mod strong;
#[cfg(test)]
pub(crate) mod synthetic;
pub mod timed;
pub mod weak;

pub(crate) use alpha_beta::{AlphaBetaFit, fit_alpha_beta};
pub use bootstrap::CiMethod;
pub use growth::GrowthReading;
pub use karp_flatt::Trend;
use nbody_engine::stats::BOOTSTRAP_RESAMPLES as RESAMPLES;
pub use power::{ComplexityClass, PowerFit, fit_power};
pub use shared::SharedMachine;
pub(crate) use strong::StrongPoint;
pub use strong::{StrongFit, fit_strong, fit_strong_on};
pub use timed::TimedSerialFraction;
pub(crate) use timed::{SerialFractionComparison, compare_serial_fractions, timed_serial_fraction};
pub(crate) use weak::{EfficiencyPoint, WeakSamples};
pub use weak::{WeakFit, fit_weak, fit_weak_with_n};

use serde::Serialize;
use thiserror::Error;

/// The bootstrap seed used when the caller has no reason to choose one (the CLI's default).
pub const DEFAULT_SEED: u64 = 0x5eed_0f17;

/// Raw measurements at one x (threads, particles or bytes); `values` are seconds.
#[derive(Clone, Debug, PartialEq, Serialize, serde::Deserialize)]
pub struct Samples {
    /// Where the samples were taken: thread count p, particle count n or message bytes.
    pub x: f64,
    /// The times measured at `x`, seconds, in any order (entries with the same x are merged).
    pub values: Vec<f64>,
}

impl Samples {
    /// The samples `values` (seconds) measured at `x`.
    pub fn new(x: f64, values: Vec<f64>) -> Self {
        Samples { x, values }
    }
}

/// A fitted quantity with its 95% confidence interval. Serializes as
/// `{"estimate": .., "ci95": [lo, hi]}`; an unbounded end (e.g. the maximum speedup when the
/// serial fraction may be 0) is infinite and serializes as `null`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Estimate {
    /// The point estimate: the fit to the per-x medians.
    pub estimate: f64,
    /// The bootstrap's 95% percentile interval `[lo, hi]`, lo ≤ hi; an end may be infinite.
    pub ci95: [f64; 2],
}

impl Estimate {
    /// Whether `value` lies inside the interval (ends included).
    pub fn contains(&self, value: f64) -> bool {
        self.ci95[0] <= value && value <= self.ci95[1]
    }

    /// The same quantity transformed by a monotonic function (ends swapped if decreasing).
    pub fn map(&self, f: impl Fn(f64) -> f64) -> Estimate {
        let (a, b) = (f(self.ci95[0]), f(self.ci95[1]));
        Estimate {
            estimate: f(self.estimate),
            ci95: [a.min(b), a.max(b)],
        }
    }
}

/// What a fit was given at one x: the median of the samples and how many there were.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Input {
    /// The x (threads, particles or bytes) after merging entries with the same x.
    pub x: f64,
    /// The median of the samples at `x`, seconds; what the point fit is fitted to.
    pub median: f64,
    /// How many samples were measured at `x` (at least 1).
    pub samples: usize,
}

/// Why a fit was refused. Every message says what was wrong and what to do about it.
#[derive(Clone, Debug, PartialEq, Error)]
#[non_exhaustive]
pub enum FitError {
    /// Fewer distinct x values than the model has to have (but more than one).
    #[error("{model}: needs at least {need} distinct x values, got {got}; measure more points")]
    TooFewPoints {
        /// The model refusing, as named in messages (e.g. "strong scaling").
        model: &'static str,
        /// The least number of distinct x values it fits.
        need: usize,
        /// The number of distinct x values given.
        got: usize,
    },
    /// Every sample has the same x, so nothing varies to fit a model to.
    #[error("{model}: every sample is at x = {x}; a fit needs at least {need} distinct x values")]
    OneX {
        /// The model refusing, as named in messages.
        model: &'static str,
        /// The one x every sample was measured at.
        x: f64,
        /// The least number of distinct x values the model fits.
        need: usize,
    },
    /// An entry of the input has an x but an empty list of times.
    #[error("{model}: no samples at x = {x}; every x needs at least one measured time")]
    NoSamples {
        /// The model refusing, as named in messages.
        model: &'static str,
        /// The x without samples.
        x: f64,
    },
    /// A measured time is zero or negative (a failed run or a unit mix-up).
    #[error(
        "{model}: time {value} at x = {x} is not positive; times must be seconds > 0 (check units and failed runs)"
    )]
    NonPositive {
        /// The model refusing, as named in messages.
        model: &'static str,
        /// The x the time was measured at.
        x: f64,
        /// The offending time, seconds.
        value: f64,
    },
    /// An x or a time is NaN or infinite.
    #[error("{model}: a NaN or infinite value at x = {x}; remove it or measure again")]
    NotFinite {
        /// The model refusing, as named in messages.
        model: &'static str,
        /// The x at which it was found (itself, when the x is the non-finite value).
        x: f64,
    },
    /// An x outside what the model accepts (worker counts below 1, sizes not positive).
    #[error("{model}: x = {x} is out of range: {expected}")]
    BadX {
        /// The model refusing, as named in messages.
        model: &'static str,
        /// The x out of range (for weak scaling with n, possibly the problem size n).
        x: f64,
        /// What the model accepts, as a phrase for the message.
        expected: &'static str,
    },
    /// A strong- or weak-scaling fit has no one-worker run to take T1 from.
    #[error(
        "{model}: needs a measurement at p = 1 (the baseline T1); measured p = {measured}; add runs with one worker"
    )]
    NoBaseline {
        /// The model refusing, as named in messages.
        model: &'static str,
        /// The worker counts that were measured, comma-separated in increasing order.
        measured: String,
    },
    /// A hardware-ceiling entry given to the strong-scaling fit is not a finite p ≥ 1 with a
    /// finite positive ratio.
    #[error("{model}: hardware ceiling {ratio} at p = {p} must be a finite ratio > 0 at p >= 1")]
    BadCeiling {
        /// The model refusing, as named in messages.
        model: &'static str,
        /// The worker count of the entry.
        p: f64,
        /// The ceiling's speedup ratio at `p`.
        ratio: f64,
    },
    /// Residual resampling was needed (some x has a single sample) but there are no more x
    /// values than parameters, so no residual spread is left.
    #[error(
        "{model}: one sample per x and only {points} x values for {params} parameters leaves no \
         spread to put a confidence interval on; repeat the measurements or add x values"
    )]
    NoSpread {
        /// The model refusing, as named in messages.
        model: &'static str,
        /// The number of distinct x values.
        points: usize,
        /// The model's number of free parameters.
        params: usize,
    },
    /// The point fit or most bootstrap replicates give no usable parameters.
    #[error("{model}: the fit is degenerate ({why})")]
    Degenerate {
        /// The model refusing, as named in messages.
        model: &'static str,
        /// What went wrong, as a phrase for the message.
        why: &'static str,
    },
    /// Weak scaling with n: one worker count was measured at two different problem sizes.
    #[error(
        "{model}: p = {p} appears with n = {n_first} and n = {n_other}; each p needs one problem size"
    )]
    InconsistentN {
        /// The model refusing, as named in messages.
        model: &'static str,
        /// The worker count measured twice.
        p: f64,
        /// The problem size (particles) first seen at `p`.
        n_first: f64,
        /// The different problem size seen later at `p`.
        n_other: f64,
    },
    /// The power-law fit found no complexity class that describes the data (times not growing
    /// with n, or the best class missing held-out points by too much).
    #[error("{model}: the data do not support it: {why}")]
    Unsupported {
        /// The model refusing, as named in messages.
        model: &'static str,
        /// Why, with the numbers and what to do, as a sentence for the message.
        why: String,
    },
    /// Phase times given for the timed serial fraction are negative, not finite or add up to 0.
    #[error("timed serial fraction: {what}")]
    BadPhases {
        /// What was wrong with the phase times, as a sentence for the message.
        what: String,
    },
}

/// Which x values a model accepts.
#[derive(Clone, Copy, Debug)]
pub(crate) enum XRule {
    /// Worker counts: p >= 1.
    AtLeastOne,
    /// Problem sizes: n > 0.
    Positive,
    /// Message sizes: bytes >= 0.
    NonNegative,
}

impl XRule {
    fn accepts(self, x: f64) -> bool {
        match self {
            XRule::AtLeastOne => x >= 1.0,
            XRule::Positive => x > 0.0,
            XRule::NonNegative => x >= 0.0,
        }
    }

    fn expected(self) -> &'static str {
        match self {
            XRule::AtLeastOne => "worker counts must be >= 1",
            XRule::Positive => "sizes must be > 0",
            XRule::NonNegative => "message sizes must be >= 0 bytes",
        }
    }
}

/// Validated input: distinct x in increasing order, their raw samples and medians.
#[derive(Clone, Debug)]
pub(crate) struct Data {
    pub xs: Vec<f64>,
    pub values: Vec<Vec<f64>>,
    pub medians: Vec<f64>,
}

impl Data {
    pub fn len(&self) -> usize {
        self.xs.len()
    }

    pub fn inputs(&self) -> Vec<Input> {
        (0..self.len())
            .map(|i| Input {
                x: self.xs[i],
                median: self.medians[i],
                samples: self.values[i].len(),
            })
            .collect()
    }
}

/// Checks `samples` (finite, positive times, x in range), merges entries with the same x,
/// sorts by x and requires `need` distinct x values.
pub(crate) fn prepare(
    model: &'static str,
    samples: &[Samples],
    rule: XRule,
    need: usize,
) -> Result<Data, FitError> {
    let mut groups: Vec<(f64, Vec<f64>)> = Vec::new();
    for s in samples {
        if !s.x.is_finite() {
            return Err(FitError::NotFinite { model, x: s.x });
        }
        if !rule.accepts(s.x) {
            return Err(FitError::BadX {
                model,
                x: s.x,
                expected: rule.expected(),
            });
        }
        if s.values.is_empty() {
            return Err(FitError::NoSamples { model, x: s.x });
        }
        for &v in &s.values {
            if !v.is_finite() {
                return Err(FitError::NotFinite { model, x: s.x });
            }
            if v <= 0.0 {
                return Err(FitError::NonPositive {
                    model,
                    x: s.x,
                    value: v,
                });
            }
        }
        match groups.iter_mut().find(|(x, _)| *x == s.x) {
            Some((_, values)) => values.extend_from_slice(&s.values),
            None => groups.push((s.x, s.values.clone())),
        }
    }
    groups.sort_by(|a, b| a.0.total_cmp(&b.0));
    if groups.len() < need {
        return Err(match groups.as_slice() {
            [(x, _)] => FitError::OneX { model, x: *x, need },
            _ => FitError::TooFewPoints {
                model,
                need,
                got: groups.len(),
            },
        });
    }
    let medians = groups
        .iter()
        .map(|(_, v)| nbody_engine::stats::median(v).expect("groups are non-empty"))
        .collect();
    let (xs, values) = groups.into_iter().unzip();
    Ok(Data {
        xs,
        values,
        medians,
    })
}

/// Clamps `value` into [0, 1] (serial fractions); the flag says whether it had to.
pub(crate) fn clamp_unit(value: f64) -> (f64, bool) {
    let c = value.clamp(0.0, 1.0);
    (c, c != value)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn prepare_merges_sorts_and_refuses_bad_input() {
        let s = [
            Samples::new(4.0, vec![1.0, 3.0]),
            Samples::new(1.0, vec![4.0]),
            Samples::new(4.0, vec![2.0]),
        ];
        let d = prepare("m", &s, XRule::AtLeastOne, 2).unwrap();
        assert_eq!(d.xs, vec![1.0, 4.0]);
        assert_eq!(d.medians, vec![4.0, 2.0]);
        assert_eq!(d.inputs()[1].samples, 3);

        let one = [Samples::new(2.0, vec![1.0, 1.1])];
        assert!(matches!(
            prepare("m", &one, XRule::AtLeastOne, 2),
            Err(FitError::OneX { x: 2.0, .. })
        ));
        assert!(matches!(
            prepare("m", &[], XRule::AtLeastOne, 2),
            Err(FitError::TooFewPoints { got: 0, .. })
        ));
        let zero = [Samples::new(1.0, vec![0.0]), Samples::new(2.0, vec![1.0])];
        assert!(matches!(
            prepare("m", &zero, XRule::AtLeastOne, 2),
            Err(FitError::NonPositive { value: 0.0, .. })
        ));
        let nan = [
            Samples::new(1.0, vec![f64::NAN]),
            Samples::new(2.0, vec![1.0]),
        ];
        assert!(matches!(
            prepare("m", &nan, XRule::AtLeastOne, 2),
            Err(FitError::NotFinite { x: 1.0, .. })
        ));
        let bad_x = [Samples::new(0.5, vec![1.0]), Samples::new(2.0, vec![1.0])];
        assert!(matches!(
            prepare("m", &bad_x, XRule::AtLeastOne, 2),
            Err(FitError::BadX { .. })
        ));
        assert!(prepare("m", &bad_x, XRule::Positive, 2).is_ok());
        let empty = [Samples::new(1.0, vec![]), Samples::new(2.0, vec![1.0])];
        assert!(matches!(
            prepare("m", &empty, XRule::AtLeastOne, 2),
            Err(FitError::NoSamples { .. })
        ));
    }

    #[test]
    fn estimate_serializes_with_ci95_and_maps_monotonically() {
        let e = Estimate {
            estimate: 0.1,
            ci95: [0.05, 0.2],
        };
        let json = serde_json::to_string(&e).unwrap();
        assert_eq!(json, r#"{"estimate":0.1,"ci95":[0.05,0.2]}"#);
        let inv = e.map(|f| 1.0 / f);
        assert_eq!(inv.ci95, [5.0, 20.0]);
        assert!(inv.contains(10.0) && !inv.contains(21.0));
    }
}
