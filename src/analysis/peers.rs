//! Our kernels next to the external programs measured in the same sweep (the vs-*.toml
//! configs): for every case of an external program, each built-in kernel's case of the same
//! scenario, n and worker count, and the ratio of their times with a bootstrap CI; for tree
//! codes swept over θ, each code's cost interpolated to one median force error, so that cost
//! is compared at equal accuracy.

use super::ThetaAnalysis;
use super::groups::{Point, workers_suffix};
use crate::stats::{BOOTSTRAP_RESAMPLES, bootstrap_ratio_ci};
use serde::Serialize;

/// The median relative force error at which tree codes are compared (SPEC §6).
pub const EQUAL_ERROR: f64 = 1e-3;

/// The seed of the ratio bootstraps: the same results give the same intervals.
const SEED: u64 = 0x9EE2;

/// One of our cases next to one external program's case of the same system and workers.
#[derive(Clone, Debug, Serialize)]
pub struct PeerRatio {
    pub scenario: String,
    pub n: usize,
    /// Threads × ranks, the same for both.
    pub workers: usize,
    pub ours: String,
    pub theirs: String,
    /// Nanoseconds per particle-step: median and bootstrap 95% CI.
    pub ours_ns: f64,
    pub ours_ci_ns: [f64; 2],
    pub theirs_ns: f64,
    pub theirs_ci_ns: [f64; 2],
    /// Their time over ours (> 1: ours is faster), from the medians, with the bootstrap 95%
    /// CI of that ratio over both sets of samples.
    pub speedup: f64,
    pub speedup_ci: Option<[f64; 2]>,
    /// Median relative force errors, where measured.
    pub ours_error: Option<f64>,
    pub theirs_error: Option<f64>,
    /// Either case ran more workers than logical CPUs.
    pub oversubscribed: bool,
}

/// Each code's time per step at the median force error [`EQUAL_ERROR`], interpolated on its
/// sweep over θ (log time linear in log error between the two cases that bracket it).
#[derive(Clone, Debug, Serialize)]
pub struct EqualErrorCost {
    pub scenario: String,
    pub n: usize,
    pub workers: usize,
    pub error: f64,
    pub ours: String,
    pub theirs: String,
    /// Seconds per step at `error`; `None` when the code's measured errors do not bracket it.
    pub ours_s: Option<f64>,
    pub theirs_s: Option<f64>,
    /// `theirs_s / ours_s`.
    pub speedup: Option<f64>,
    /// The range of median errors each code measured, to say why a cost is missing.
    pub ours_errors: [f64; 2],
    pub theirs_errors: [f64; 2],
}

/// A case's legend label: code, θ, expansion order, workers.
pub fn case_label(p: &Point) -> String {
    let mut s = p.case.kernel.name().to_string();
    if let Some(t) = p.theta {
        s.push_str(&format!(" θ={t}"));
    }
    if p.case.multipole != crate::kernels::Multipole::Monopole {
        s.push_str(&format!(" {}", p.case.multipole.name()));
    }
    s.push_str(&workers_suffix(p.threads, p.ranks));
    s
}

fn ns_per_particle(p: &Point, seconds: f64) -> f64 {
    seconds * 1e9 / p.n.max(1) as f64
}

/// Every (ours, theirs) pair of cases of one scenario, n and worker count; when the external
/// case has a θ, only our cases at the same θ.
pub fn ratios(cases: &[Point]) -> Vec<PeerRatio> {
    let (theirs, ours): (Vec<&Point>, Vec<&Point>) =
        cases.iter().partition(|p| p.case.kernel.is_external());
    let mut out = Vec::new();
    for t in &theirs {
        for o in ours.iter().filter(|o| {
            o.case.scenario == t.case.scenario
                && o.n == t.n
                && o.p() == t.p()
                && (t.theta.is_none() || o.theta == t.theta)
        }) {
            out.push(PeerRatio {
                scenario: o.case.scenario.name().into(),
                n: o.n,
                workers: o.p(),
                ours: case_label(o),
                theirs: case_label(t),
                ours_ns: ns_per_particle(o, o.median_s),
                ours_ci_ns: o.ci95_s.map(|s| ns_per_particle(o, s)),
                theirs_ns: ns_per_particle(t, t.median_s),
                theirs_ci_ns: t.ci95_s.map(|s| ns_per_particle(t, s)),
                speedup: t.median_s / o.median_s,
                speedup_ci: bootstrap_ratio_ci(&o.samples, &t.samples, BOOTSTRAP_RESAMPLES, SEED),
                ours_error: o.force_error.map(|e| e[0]),
                theirs_error: t.force_error.map(|e| e[0]),
                oversubscribed: o.oversubscribed || t.oversubscribed,
            });
        }
    }
    out
}

/// The time at median error `target` from `(error, seconds)` points, interpolating log time
/// linearly in log error between the first two neighbours (in error) that bracket it; `None`
/// when no pair does.
pub fn cost_at_error(points: &[(f64, f64)], target: f64) -> Option<f64> {
    let mut v: Vec<(f64, f64)> = points
        .iter()
        .copied()
        .filter(|&(e, s)| e > 0.0 && s > 0.0 && e.is_finite() && s.is_finite())
        .collect();
    v.sort_by(|a, b| a.0.total_cmp(&b.0));
    v.windows(2).find_map(|w| {
        let ((e0, s0), (e1, s1)) = (w[0], w[1]);
        if !(e0 <= target && target <= e1) {
            return None;
        }
        if e0 == e1 {
            return Some(s0.min(s1));
        }
        let f = (target.ln() - e0.ln()) / (e1.ln() - e0.ln());
        Some((s0.ln() + f * (s1.ln() - s0.ln())).exp())
    })
}

fn error_points(t: &ThetaAnalysis) -> Vec<(f64, f64)> {
    t.points
        .iter()
        .filter_map(|p| Some((p.force_error?[0], p.median_s)))
        .collect()
}

fn error_range(points: &[(f64, f64)]) -> [f64; 2] {
    points
        .iter()
        .fold([f64::INFINITY, 0.0], |[lo, hi], &(e, _)| {
            [lo.min(e), hi.max(e)]
        })
}

/// Our tree series next to each external one of the same scenario, n and workers, at
/// [`EQUAL_ERROR`].
pub fn equal_error(theta: &[ThetaAnalysis]) -> Vec<EqualErrorCost> {
    let (theirs, ours): (Vec<&ThetaAnalysis>, Vec<&ThetaAnalysis>) =
        theta.iter().partition(|t| t.series.kernel.is_external());
    let workers = |t: &ThetaAnalysis| t.series.threads.unwrap_or(1) * t.series.ranks.unwrap_or(1);
    let mut out = Vec::new();
    for t in &theirs {
        let tp = error_points(t);
        let theirs_s = cost_at_error(&tp, EQUAL_ERROR);
        for o in ours.iter().filter(|o| {
            o.series.scenario == t.series.scenario
                && o.series.n == t.series.n
                && workers(o) == workers(t)
        }) {
            let op = error_points(o);
            let ours_s = cost_at_error(&op, EQUAL_ERROR);
            out.push(EqualErrorCost {
                scenario: o.series.scenario.name().into(),
                n: o.series.n.unwrap_or(0),
                workers: workers(o),
                error: EQUAL_ERROR,
                ours: o.label.clone(),
                theirs: t.label.clone(),
                ours_s,
                theirs_s,
                speedup: ours_s.zip(theirs_s).map(|(o, t)| t / o),
                ours_errors: error_range(&op),
                theirs_errors: error_range(&tp),
            });
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cost_at_error_is_exact_on_a_power_law_and_refuses_to_extrapolate() {
        // cost = 2e-3 · e^-0.5: straight in log-log, so the interpolation is exact.
        let law = |e: f64| 2e-3 * e.powf(-0.5);
        let pts: Vec<(f64, f64)> = [3e-4, 8e-4, 2.5e-3, 7e-3]
            .iter()
            .map(|&e| (e, law(e)))
            .collect();
        for target in [3e-4, 1e-3, 5e-3] {
            let got = cost_at_error(&pts, target).unwrap();
            assert!((got / law(target) - 1.0).abs() < 1e-12, "{target}: {got}");
        }
        // Outside the measured errors there is no answer, whatever the order of the points.
        let mut rev = pts.clone();
        rev.reverse();
        assert_eq!(cost_at_error(&rev, 1e-4), None);
        assert_eq!(cost_at_error(&rev, 1e-2), None);
        assert!(cost_at_error(&rev, 1e-3).is_some());
        // Points without an error or a time do not count.
        assert_eq!(cost_at_error(&[(0.0, 1.0), (f64::NAN, 1.0)], 1e-3), None);
    }
}
