//! Complexity in n: the free power law `T = c·n^k` (log-log least squares on the medians) and
//! the complexity class chosen among n, n log n, n^1.5, n², n² log n and n³ by leave-one-out
//! cross-validation on SMAPE, as Extra-P selects its hypotheses; what a reader is told of the
//! growth is [`GrowthReading`], which names that class only where k agrees with it.

use super::bootstrap::{bootstrap, estimate};
pub use super::growth::ComplexityClass;
use super::growth::{self, GrowthReading};
use super::linear::{self, Basis, Goodness};
use super::{CiMethod, Data, Estimate, FitError, Input, RESAMPLES, Samples, XRule, prepare};
use serde::Serialize;

const MODEL: &str = "power law";

/// One hypothesis of the class selection, fitted to all the medians.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ClassCandidate {
    /// The growth class `g(n)` of this hypothesis.
    pub class: ComplexityClass,
    /// `a + c·g(n)` when true, `c·g(n)` otherwise.
    pub with_constant: bool,
    /// `a`, seconds (0 without a constant).
    pub constant: f64,
    /// `c`, seconds per unit of `g(n)`.
    pub coefficient: f64,
    /// Leave-one-out SMAPE in percent; `None` when there are too few points (a constant term
    /// needs 3) or a fold is singular.
    pub loo_smape_percent: Option<f64>,
    /// Only hypotheses with `c > 0` and `a >= 0` (a time that grows and is never negative)
    /// can be selected.
    pub admissible: bool,
}

/// The selected hypothesis with bootstrap intervals on its parameters.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct SelectedClass {
    /// The growth class `g(n)` selected.
    pub class: ComplexityClass,
    /// Whether the selected model is `a + c·g(n)` rather than `c·g(n)`.
    pub with_constant: bool,
    /// `a`, seconds (exactly 0 when `with_constant` is false).
    pub constant: Estimate,
    /// `c`, seconds per unit of `g(n)`.
    pub coefficient: Estimate,
    /// The selected hypothesis' leave-one-out SMAPE, percent (at most 50, else the fit is refused).
    pub loo_smape_percent: f64,
    /// In-sample fit of the selected model to the medians (r² on relative residuals).
    pub goodness: Goodness,
    /// Fraction of bootstrap replicates whose own selection picked the same class (with or
    /// without a constant): how firmly the data decide.
    pub support: f64,
}

/// The fits of time against problem size.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct PowerFit {
    /// x = n, the median time and sample count at each n.
    pub inputs: Vec<Input>,
    /// `k` of the free power law `T = c·n^k`, with its bootstrap interval.
    pub exponent: Estimate,
    /// `c` of the free power law, seconds.
    pub coefficient: Estimate,
    /// Fit of the free power law in log-log space.
    pub power_law_goodness: Goodness,
    /// The class cross-validation selected (also in `selected`); what tables and figures say
    /// of the growth is `reading`, which names it only where k agrees.
    pub class: ComplexityClass,
    /// What may be said of the growth: the class, classes the data do not tell apart, or the
    /// exponent alone.
    pub reading: GrowthReading,
    /// The selected hypothesis with its parameters' intervals and how firmly it was selected.
    pub selected: SelectedClass,
    /// Every hypothesis with its leave-one-out SMAPE.
    pub candidates: Vec<ClassCandidate>,
    /// How the bootstrap drew its replicates (decides what the intervals include).
    pub ci_method: CiMethod,
    /// The number of bootstrap replicates drawn (before degenerate ones were dropped).
    pub resamples: usize,
    /// Warnings for a reader, one sentence each: why no class is named, weak class support,
    /// wide exponent interval, a runner-up class too close over the measured range of n.
    pub notes: Vec<String>,
}

impl PowerFit {
    /// Time predicted at `n` by the selected class model (the one to extrapolate with).
    #[cfg(test)]
    pub(crate) fn predict(&self, n: f64) -> f64 {
        self.selected.constant.estimate + self.selected.coefficient.estimate * self.class.g(n)
    }

    /// The curve the reading stands for at `n`: the named class's model, else the free power
    /// law `c·n^k` (a figure draws what its legend says).
    pub(crate) fn curve(&self, n: f64) -> f64 {
        match self.reading.class() {
            Some(class) => {
                self.selected.constant.estimate + self.selected.coefficient.estimate * class.g(n)
            }
            None => self.coefficient.estimate * n.powf(self.exponent.estimate),
        }
    }

    /// The reading as a table or legend says it (see [`GrowthReading::text`]).
    pub fn growth(&self) -> String {
        self.reading.text(self.exponent.estimate)
    }
}

/// Fits `T = c·n^k` and selects a complexity class. Needs 3 distinct n > 0 (leave-one-out with
/// a constant term needs 3 points).
pub fn fit_power(samples: &[Samples], seed: u64) -> Result<PowerFit, FitError> {
    let data = prepare(MODEL, samples, XRule::Positive, 3)?;
    let (ln_c, k) = free_law(&data.xs, &data.medians).ok_or(FitError::Degenerate {
        model: MODEL,
        why: "log-log least squares is singular",
    })?;
    let hypotheses = candidates(&data.xs, &data.medians);
    let best = select(&hypotheses).ok_or(FitError::Degenerate {
        model: MODEL,
        why: "no complexity class fits with a positive coefficient",
    })?;
    let chosen = hypotheses[best].clone();
    refuse_unsupported(k, &chosen)?;
    let fitted: Vec<f64> = data.xs.iter().map(|n| ln_c.exp() * n.powf(k)).collect();

    struct Replicate {
        ln_c: f64,
        k: f64,
        constant: f64,
        coefficient: f64,
        class: ComplexityClass,
    }
    let reps = bootstrap(MODEL, &data, &fitted, 2, seed, |medians| {
        let (ln_c, k) = free_law(&data.xs, medians)?;
        let beta = linear::fit_relative(
            &basis(chosen.class, chosen.with_constant),
            &data.xs,
            medians,
        )?;
        let (constant, coefficient) = split(&beta, chosen.with_constant);
        let all = candidates(&data.xs, medians);
        let class = all[select(&all)?].class;
        Some(Replicate {
            ln_c,
            k,
            constant,
            coefficient,
            class,
        })
    })?;
    let n_reps = reps.fits.len() as f64;
    let support = reps.fits.iter().filter(|r| r.class == chosen.class).count() as f64 / n_reps;
    let exponent = estimate(k, reps.fits.iter().map(|r| r.k));
    let selected_pred: Vec<f64> = data
        .xs
        .iter()
        .map(|&n| chosen.constant + chosen.coefficient * chosen.class.g(n))
        .collect();
    let selected = SelectedClass {
        class: chosen.class,
        with_constant: chosen.with_constant,
        constant: estimate(chosen.constant, reps.fits.iter().map(|r| r.constant)),
        coefficient: estimate(chosen.coefficient, reps.fits.iter().map(|r| r.coefficient)),
        loo_smape_percent: chosen
            .loo_smape_percent
            .expect("selected candidates have one"),
        goodness: Goodness::of(
            &data.medians,
            &selected_pred,
            &linear::relative_weights(&data.medians),
        ),
        support,
    };
    let (lo, hi) = (data.xs[0], data.xs[data.len() - 1]);
    let reading = growth::read(&exponent, chosen.class, support, lo, hi);
    let mut notes = notes(&exponent, &selected, &reading, lo, hi);
    if reading.class().is_some() {
        notes.extend(range_note(&hypotheses, chosen.class, &data.xs));
    }
    Ok(PowerFit {
        inputs: data.inputs(),
        exponent,
        coefficient: estimate(ln_c.exp(), reps.fits.iter().map(|r| r.ln_c.exp())),
        power_law_goodness: log_log_goodness(&data, ln_c, k),
        class: chosen.class,
        reading,
        selected,
        candidates: hypotheses,
        ci_method: reps.method,
        resamples: RESAMPLES,
        notes,
    })
}

/// The worst leave-one-out SMAPE, percent, at which a selected class still describes the
/// data; the committed sweeps' selections miss by 25 % at most.
pub(crate) const MAX_CLASS_SMAPE_PERCENT: f64 = 50.0;

/// A selection the data cannot support is an error, not a result: times that do not grow
/// with n fit no growth class (the least bad one would be "chosen" all the same), and a class
/// that misses the held-out points by more than [`MAX_CLASS_SMAPE_PERCENT`] describes nothing.
fn refuse_unsupported(k: f64, chosen: &ClassCandidate) -> Result<(), FitError> {
    let smape = chosen.loo_smape_percent.unwrap_or(f64::INFINITY);
    let why = if k <= 0.0 {
        format!(
            "the times do not grow with n (free exponent k = {k:.3}); no complexity class \
             applies: check that the cases differ only in n"
        )
    } else if smape > MAX_CLASS_SMAPE_PERCENT {
        format!(
            "the best complexity class, {}, misses the left-out points by {smape:.0} % \
             (leave-one-out SMAPE, more than {MAX_CLASS_SMAPE_PERCENT} %); measure more samples \
             or more sizes",
            chosen.class.name()
        )
    } else {
        return Ok(());
    };
    Err(FitError::Unsupported { model: MODEL, why })
}

/// `(ln c, k)` of the least-squares line through `(ln n, ln T)`.
fn free_law(ns: &[f64], times: &[f64]) -> Option<(f64, f64)> {
    let ln_n: Vec<f64> = ns.iter().map(|n| n.ln()).collect();
    let ln_t: Vec<f64> = times.iter().map(|t| t.ln()).collect();
    let beta = linear::fit(&[&|_| 1.0, &|x| x], &ln_n, &ln_t, &vec![1.0; ns.len()])?;
    Some((beta[0], beta[1]))
}

fn log_log_goodness(data: &Data, ln_c: f64, k: f64) -> Goodness {
    let ln_t: Vec<f64> = data.medians.iter().map(|t| t.ln()).collect();
    let pred_ln: Vec<f64> = data.xs.iter().map(|n| ln_c + k * n.ln()).collect();
    let predicted: Vec<f64> = pred_ln.iter().map(|l| l.exp()).collect();
    Goodness {
        r2: linear::r2(&ln_t, &pred_ln, &vec![1.0; ln_t.len()]),
        smape_percent: linear::smape(&data.medians, &predicted),
    }
}

fn basis(class: ComplexityClass, with_constant: bool) -> Vec<Basis<'static>> {
    let g: Basis<'static> = match class {
        ComplexityClass::N => &|n| ComplexityClass::N.g(n),
        ComplexityClass::NLogN => &|n| ComplexityClass::NLogN.g(n),
        ComplexityClass::NSqrtN => &|n| ComplexityClass::NSqrtN.g(n),
        ComplexityClass::N2 => &|n| ComplexityClass::N2.g(n),
        ComplexityClass::N2LogN => &|n| ComplexityClass::N2LogN.g(n),
        ComplexityClass::N3 => &|n| ComplexityClass::N3.g(n),
    };
    if with_constant {
        vec![&|_| 1.0, g]
    } else {
        vec![g]
    }
}

/// `(constant, coefficient)` from a fitted basis vector.
fn split(beta: &[f64], with_constant: bool) -> (f64, f64) {
    if with_constant {
        (beta[0], beta[1])
    } else {
        (0.0, beta[0])
    }
}

fn candidates(ns: &[f64], times: &[f64]) -> Vec<ClassCandidate> {
    let mut out = Vec::with_capacity(2 * ComplexityClass::ALL.len());
    for class in ComplexityClass::ALL {
        for with_constant in [false, true] {
            let basis = basis(class, with_constant);
            let Some(beta) = linear::fit_relative(&basis, ns, times) else {
                continue;
            };
            let (constant, coefficient) = split(&beta, with_constant);
            out.push(ClassCandidate {
                class,
                with_constant,
                constant,
                coefficient,
                loo_smape_percent: linear::loo_smape(&basis, ns, times),
                admissible: coefficient > 0.0 && constant >= 0.0,
            });
        }
    }
    out
}

/// Index of the admissible candidate with the lowest leave-one-out SMAPE; on a tie the
/// simpler one (listed first) wins.
fn select(candidates: &[ClassCandidate]) -> Option<usize> {
    let mut best: Option<(usize, f64)> = None;
    for (i, c) in candidates.iter().enumerate() {
        if let (true, Some(s)) = (c.admissible, c.loo_smape_percent)
            && best.is_none_or(|(_, b)| s < b)
        {
            best = Some((i, s));
        }
    }
    best.map(|(i, _)| i)
}

/// Below this ratio between two classes' growth over the measured n, the range cannot tell
/// them apart: effects the classes leave out (a working set leaving a cache level) change a
/// step's time by as much.
const DISTINCT_GROWTH: f64 = 4.0;

/// A note when the runner-up class grows over the measured range of n by less than
/// [`DISTINCT_GROWTH`] times differently from the chosen one (n log n against n^1.5 over
/// n = 500–8000 differ by 2.8×): the choice between them is the range's, not the code's.
fn range_note(
    candidates: &[ClassCandidate],
    chosen: ComplexityClass,
    xs: &[f64],
) -> Option<String> {
    let lo = xs.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = xs.iter().copied().fold(0.0, f64::max);
    let runner_up = candidates
        .iter()
        .filter(|c| c.admissible && c.class != chosen)
        .filter_map(|c| Some((c.class, c.loo_smape_percent?)))
        .min_by(|a, b| a.1.total_cmp(&b.1))?
        .0;
    let growth = |c: ComplexityClass| c.g(hi) / c.g(lo);
    let apart = growth(chosen) / growth(runner_up);
    let apart = apart.max(1.0 / apart);
    (apart < DISTINCT_GROWTH).then(|| {
        format!(
            "n = {lo}–{hi} is too short a range to tell {} from {} for sure: their growth over \
             it differs by only {apart:.1}×, which effects outside the model (a working set \
             leaving a cache) can give as well; widen the range of n to confirm the class",
            chosen.name(),
            runner_up.name()
        )
    })
}

fn notes(
    exponent: &Estimate,
    selected: &SelectedClass,
    reading: &GrowthReading,
    lo: f64,
    hi: f64,
) -> Vec<String> {
    let mut notes = Vec::new();
    notes.extend(growth::note(reading, exponent, lo, hi));
    if reading.class().is_some() && selected.support < 0.7 {
        notes.push(format!(
            "only {:.0}% of bootstrap replicates select {}: the class is not firmly determined by \
             these points; widen the range of n or take more samples",
            100.0 * selected.support,
            selected.class.name()
        ));
    }
    if exponent.ci95[1] - exponent.ci95[0] > 0.5 {
        notes.push("the exponent's interval is wider than 0.5: too few or too noisy points".into());
    }
    notes
}

#[cfg(test)]
#[path = "power_tests.rs"]
mod tests;
