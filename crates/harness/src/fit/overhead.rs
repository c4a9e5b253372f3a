//! Optional overhead terms on top of Amdahl's law, `T(p) = a + b/p + c·h(p)` with
//! `h = log2 p` (tree reductions, barriers) or `h = p` (per-worker setup, all-to-all), kept only
//! when leave-one-out cross-validation prefers them to plain `a + b/p`.

use super::Estimate;
use super::linear::{self, Basis};
use serde::Serialize;

#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub enum OverheadTerm {
    #[serde(rename = "c*log2(p)")]
    Log2P,
    #[serde(rename = "c*p")]
    P,
}

impl OverheadTerm {
    pub const ALL: [OverheadTerm; 2] = [OverheadTerm::Log2P, OverheadTerm::P];

    pub fn name(self) -> &'static str {
        match self {
            OverheadTerm::Log2P => "c*log2(p)",
            OverheadTerm::P => "c*p",
        }
    }

    pub fn h(self, p: f64) -> f64 {
        match self {
            OverheadTerm::Log2P => p.log2(),
            OverheadTerm::P => p,
        }
    }
}

/// One model of the comparison, fitted to all the medians.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct OverheadCandidate {
    /// `None` for plain Amdahl.
    pub term: Option<OverheadTerm>,
    /// Leave-one-out SMAPE in percent; `None` with too few thread counts (an overhead model
    /// has 3 parameters, so it needs 4 distinct p).
    pub loo_smape_percent: Option<f64>,
    /// `c` in seconds (per unit of the term) when the model has one.
    pub coefficient: Option<f64>,
}

/// The kept overhead model with bootstrap intervals.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct OverheadTermFit {
    pub term: OverheadTerm,
    /// `c`, seconds per unit of the term.
    pub coefficient: Estimate,
    /// `a / (a + b)`: the serial fraction once the overhead is modelled separately.
    pub serial_fraction: Estimate,
}

#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct OverheadSelection {
    pub candidates: Vec<OverheadCandidate>,
    /// The overhead model preferred by cross-validation, if any.
    pub kept: Option<OverheadTermFit>,
}

/// A model needs this much lower leave-one-out SMAPE than plain Amdahl to be kept: an extra
/// parameter fitted to noise alone sometimes wins by a hair, and a hair is not evidence.
const MIN_IMPROVEMENT: f64 = 0.9;
/// Below this (percent) errors are rounding, not evidence either way.
const NEGLIGIBLE: f64 = 1e-6;

fn one(_: f64) -> f64 {
    1.0
}
fn inverse(p: f64) -> f64 {
    1.0 / p
}
fn log2(p: f64) -> f64 {
    p.log2()
}
fn identity(p: f64) -> f64 {
    p
}

fn basis(term: Option<OverheadTerm>) -> Vec<Basis<'static>> {
    match term {
        None => vec![&one, &inverse],
        Some(OverheadTerm::Log2P) => vec![&one, &inverse, &log2],
        Some(OverheadTerm::P) => vec![&one, &inverse, &identity],
    }
}

/// `[a, b, c]` of the model with `term` (c = 0 without one), fitted on relative residuals.
pub(crate) fn fit(term: Option<OverheadTerm>, ps: &[f64], times: &[f64]) -> Option<[f64; 3]> {
    let beta = linear::fit_relative(&basis(term), ps, times)?;
    Some([beta[0], beta[1], beta.get(2).copied().unwrap_or(0.0)])
}

/// The model's time at p.
pub(crate) fn time(term: Option<OverheadTerm>, abc: [f64; 3], p: f64) -> f64 {
    abc[0] + abc[1] / p + term.map_or(0.0, |t| abc[2] * t.h(p))
}

/// Compares plain Amdahl with each overhead model. A term is kept when its leave-one-out SMAPE
/// is below [`MIN_IMPROVEMENT`] times Amdahl's, its fitted coefficient and parallel part are
/// positive (an overhead that makes the run faster is not an overhead) and its serial part is
/// not negative: the serial fraction `a / (a + b)` must lie in [0, 1], or the term is dropped
/// (the candidates table still shows its fit).
pub(crate) fn select(ps: &[f64], times: &[f64]) -> (Vec<OverheadCandidate>, Option<OverheadTerm>) {
    let mut candidates = Vec::new();
    for term in [None, Some(OverheadTerm::Log2P), Some(OverheadTerm::P)] {
        let abc = fit(term, ps, times);
        candidates.push(OverheadCandidate {
            term,
            loo_smape_percent: linear::loo_smape(&basis(term), ps, times),
            coefficient: term.and(abc).map(|abc| abc[2]),
        });
    }
    let base = candidates[0].loo_smape_percent;
    let mut kept: Option<(OverheadTerm, f64)> = None;
    for c in &candidates[1..] {
        let (Some(term), Some(loo), Some(base)) = (c.term, c.loo_smape_percent, base) else {
            continue;
        };
        let positive = fit(Some(term), ps, times)
            .is_some_and(|abc| abc[0] >= 0.0 && abc[1] > 0.0 && abc[2] > 0.0);
        if positive
            && loo < MIN_IMPROVEMENT * base - NEGLIGIBLE
            && kept.is_none_or(|(_, best)| loo < best)
        {
            kept = Some((term, loo));
        }
    }
    (candidates, kept.map(|(t, _)| t))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn exact_overhead_is_recovered_and_kept() {
        let ps = [1.0, 2.0, 4.0, 8.0, 16.0, 32.0];
        let t: Vec<f64> = ps.iter().map(|p| 0.1 + 0.9 / p + 0.02 * p).collect();
        let (candidates, kept) = select(&ps, &t);
        assert_eq!(kept, Some(OverheadTerm::P));
        assert_eq!(candidates.len(), 3);
        let abc = fit(kept, &ps, &t).unwrap();
        assert!((abc[2] - 0.02).abs() < 1e-9, "{abc:?}");
        assert!((time(kept, abc, 3.0) - (0.1 + 0.3 + 0.06)).abs() < 1e-9);

        let pure: Vec<f64> = ps.iter().map(|p| 0.1 + 0.9 / p).collect();
        assert_eq!(select(&ps, &pure).1, None);
    }

    #[test]
    fn a_term_that_needs_a_negative_serial_part_is_dropped() {
        // Exactly T = -0.05 + 1/p + 0.02 p: the P term fits perfectly, but with a serial part
        // below zero, so f = a / (a + b) < 0: not a physical answer, the term is not kept.
        let ps = [1.0, 2.0, 4.0, 8.0, 16.0, 32.0];
        let t: Vec<f64> = ps.iter().map(|p| -0.05 + 1.0 / p + 0.02 * p).collect();
        let abc = fit(Some(OverheadTerm::P), &ps, &t).unwrap();
        assert!(abc[0] < 0.0, "{abc:?}");
        let (_, kept) = select(&ps, &t);
        if let Some(term) = kept {
            let abc = fit(Some(term), &ps, &t).unwrap();
            let f = abc[0] / (abc[0] + abc[1]);
            assert!((0.0..=1.0).contains(&f), "kept {term:?} with f = {f}");
        }
        assert_ne!(kept, Some(OverheadTerm::P));
    }

    #[test]
    fn three_thread_counts_cannot_test_a_third_parameter() {
        let ps = [1.0, 2.0, 4.0];
        let t = [1.0, 0.6, 0.5];
        let (candidates, kept) = select(&ps, &t);
        assert_eq!(kept, None);
        assert!(candidates[1].loo_smape_percent.is_none());
        assert_eq!(
            serde_json::to_value(OverheadTerm::Log2P).unwrap(),
            "c*log2(p)"
        );
    }
}
