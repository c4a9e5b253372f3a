//! Decisions in looks: a case is judged after a first block of rounds, and only the cases not
//! yet decided are measured further, up to a cap.
//!
//! Each case ends in one of four verdicts: **regressed** or **improved** (beyond the threshold,
//! at the family-wise error), **unchanged** (its 90% interval lies within ±[`EQUIVALENCE`] ×
//! threshold: no change of the size the gate looks for), or **unknown** (none of these after
//! the last look: measure more). Only the first two are claims the error rate is about;
//! stopping a case as unchanged early costs power, never a false alarm.
//!
//! **Error control over looks and cases.** Looking K times at a growing sample and stopping at
//! the first rejection inflates the error of a test run at its level each time. Here look k
//! runs Holm's step-down over all m cases at level α/K (Bonferroni over the looks): a case
//! already decided enters a later look with p = 1 (a valid p-value of any hypothesis), so each
//! look is a level-α/K procedure on m hypotheses and, by the union bound, the run as a whole
//! flags an unchanged case with probability at most α — whatever the stopping rule, however
//! the cases are correlated. The price is α/K at every look, including the first; in return a
//! clear case is decided from the first block, and an unclear one gets up to K times its rounds.

use super::family::holm;
use super::{CaseComparison, Verdict};
use serde::Serialize;

/// A case is unchanged when its 90% interval lies within ±`EQUIVALENCE` × threshold.
pub const EQUIVALENCE: f64 = 2.0;

/// The two-sided level of the interval that decides "unchanged": 90%.
pub const EQUIVALENCE_TAIL: f64 = 0.05;

/// Where a run is in its looks.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub struct Look {
    /// This look, counted from 0.
    pub index: usize,
    /// Looks the run may take in all (K): each runs at the family-wise error / K.
    pub count: usize,
}

impl Look {
    /// A run that judges once, on everything measured (two files, the fast path).
    pub const SINGLE: Look = Look { index: 0, count: 1 };

    /// The level of this look's Holm procedure for a run at family-wise error `alpha`.
    pub fn alpha(&self, alpha: f64) -> f64 {
        alpha / self.count.max(1) as f64
    }

    /// Whether no look follows this one.
    pub fn is_last(&self) -> bool {
        self.index + 1 >= self.count
    }
}

/// The rounds per build after each look of an A/B run: `first`, then as many more each time,
/// up to `max` (the last look may be shorter, to stop at `max` exactly).
pub fn schedule(first: usize, max: usize) -> Vec<usize> {
    let first = first.max(1);
    let mut looks = vec![first.min(max.max(1))];
    while let Some(&last) = looks.last()
        && last < max
    {
        looks.push((last + first).min(max));
    }
    looks
}

/// Verdicts of `look` for the cases marked `open` (measured at this look); the others keep the
/// verdict an earlier look gave them and enter the procedure with p = 1. Sets each open case's
/// verdict, adjusted p-value and the look it was decided at.
pub fn decide(cases: &mut [CaseComparison], open: &[bool], look: Look, alpha: f64) {
    let level = look.alpha(alpha);
    let p = |pick: fn(&CaseComparison) -> f64| -> Vec<f64> {
        cases
            .iter()
            .zip(open)
            .map(|(c, &o)| if o { pick(c) } else { 1.0 })
            .collect()
    };
    let (up_p, down_p) = (p(|c| c.p.regressed), p(|c| c.p.improved));
    let (up, down) = (holm(&up_p, level), holm(&down_p, level));
    let (up_adj, down_adj) = (holm_adjusted(&up_p), holm_adjusted(&down_p));
    for (i, case) in cases.iter_mut().enumerate() {
        if !open[i] {
            continue;
        }
        // Adjusted p-values on the family's scale: rejected exactly when at most `alpha`.
        let scale = |q: f64| (q * look.count.max(1) as f64).min(1.0);
        let (verdict, adjusted) = if up[i] {
            (Verdict::Regressed, up_adj[i])
        } else if down[i] {
            (Verdict::Improved, down_adj[i])
        } else if case.equivalent {
            (Verdict::Unchanged, up_adj[i])
        } else {
            (Verdict::Unknown, up_adj[i])
        };
        case.verdict = verdict;
        case.adjusted_p = scale(adjusted);
        case.look = look.index + 1;
    }
}

/// Whether a case stays open after a look that is not the last: neither flagged nor shown
/// unchanged.
pub fn still_open(case: &CaseComparison) -> bool {
    case.verdict == Verdict::Unknown
}

/// Holm-adjusted p-values: the smallest level at which Holm's step-down rejects each
/// hypothesis (Wright 1992), capped at 1.
pub fn holm_adjusted(p: &[f64]) -> Vec<f64> {
    let m = p.len();
    let mut order: Vec<usize> = (0..m).collect();
    order.sort_by(|&a, &b| p[a].total_cmp(&p[b]).then(a.cmp(&b)));
    let mut adjusted = vec![1.0; m];
    let mut running: f64 = 0.0;
    for (k, &i) in order.iter().enumerate() {
        running = running.max(((m - k) as f64 * p[i]).min(1.0));
        adjusted[i] = running;
    }
    adjusted
}

#[cfg(test)]
mod tests;
