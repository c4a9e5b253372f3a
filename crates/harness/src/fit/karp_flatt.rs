//! The Karp-Flatt metric `e(p) = (1/S − 1/p)/(1 − 1/p)`, the experimentally determined serial
//! fraction, and the verdict on how it changes with p.
//!
//! Under Amdahl's law with serial fraction f, `e(p) = f` at every p. Overhead that grows with
//! the worker count (synchronisation, reductions, communication) makes e(p) rise; superlinear
//! effects (more cache in total) make it fall. On a shared machine time-sharing with other
//! processes does either, so the verdict's meaning then blames neither the code nor the cache.

use super::bootstrap::estimate;
use super::{Estimate, SharedMachine};
use serde::Serialize;

/// e(p) with its bootstrap interval, at one p > 1.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct KarpFlattPoint {
    pub p: f64,
    pub e: Estimate,
}

/// How e(p) changes as p grows: the verdict on the slope's 95% interval.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Trend {
    /// The slope's interval contains 0: consistent with inherent serial work.
    Flat,
    /// The whole interval is above 0: overhead that grows with p.
    Rising,
    /// The whole interval is below 0: superlinear effects.
    Falling,
    /// Fewer than two p > 1: no slope to measure.
    Undetermined,
}

impl Trend {
    /// The verdict as tables and JSON write it: "flat", "rising", "falling", "undetermined".
    pub fn name(self) -> &'static str {
        match self {
            Trend::Flat => "flat",
            Trend::Rising => "rising",
            Trend::Falling => "falling",
            Trend::Undetermined => "undetermined",
        }
    }
}

/// How e(p) changes with p: the least-squares slope of e against log2 p (the change per
/// doubling of p, since studies usually double p) with its bootstrap interval, and the verdict.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct KarpFlattTrend {
    pub verdict: Trend,
    pub slope_per_doubling: Option<Estimate>,
    /// A sentence saying what the verdict means.
    pub meaning: String,
}

/// e(p) from the speedup at p > 1.
pub(crate) fn karp_flatt(p: f64, speedup: f64) -> f64 {
    (1.0 / speedup - 1.0 / p) / (1.0 - 1.0 / p)
}

/// Least-squares slope of e against log2 p; `None` with fewer than two points.
pub(crate) fn slope(ps: &[f64], es: &[f64]) -> Option<f64> {
    if ps.len() < 2 {
        return None;
    }
    let xs: Vec<f64> = ps.iter().map(|p| p.log2()).collect();
    let mx = xs.iter().sum::<f64>() / xs.len() as f64;
    let me = es.iter().sum::<f64>() / es.len() as f64;
    let sxx: f64 = xs.iter().map(|x| (x - mx).powi(2)).sum();
    let sxe: f64 = xs.iter().zip(es).map(|(x, e)| (x - mx) * (e - me)).sum();
    (sxx > 0.0).then(|| sxe / sxx)
}

/// The verdict from the point slope and the replicate slopes; `points` are e(p) at every
/// p > 1 (the one value is quoted when there is no slope), `shared` the machine's load when it
/// was shared.
pub(crate) fn trend(
    points: &[KarpFlattPoint],
    point: Option<f64>,
    replicates: impl IntoIterator<Item = f64>,
    shared: Option<&SharedMachine>,
) -> KarpFlattTrend {
    let Some(point) = point else {
        let measured = match points {
            [one] => format!(
                "one worker count above 1: e({}) = {:.4} [{:.4}, {:.4}] is the serial fraction \
                 measured there; whether e(p) changes with p needs at least two p > 1",
                one.p, one.e.estimate, one.e.ci95[0], one.e.ci95[1]
            ),
            _ => "fewer than two worker counts above 1: measure at least two p > 1 to see \
                  whether e(p) changes with p"
                .into(),
        };
        return KarpFlattTrend {
            verdict: Trend::Undetermined,
            slope_per_doubling: None,
            meaning: with_shared(measured, shared),
        };
    };
    let slope = estimate(point, replicates);
    let [lo, hi] = slope.ci95;
    let verdict = if lo > 0.0 {
        Trend::Rising
    } else if hi < 0.0 {
        Trend::Falling
    } else {
        Trend::Flat
    };
    let meaning = match (verdict, shared) {
        (Trend::Rising, None) => {
            "e(p) rises with p: overhead that grows with the worker count (synchronisation, \
             reductions, communication, memory contention) limits the speedup, not only serial work"
        }
        (Trend::Falling, None) => {
            "e(p) falls with p: superlinear effects (more cache in total, or a slow one-worker \
             baseline) more than offset the serial work"
        }
        (_, None) => {
            "e(p) shows no significant trend with p: the loss of speedup is consistent with \
             inherent serial work, as Amdahl's law assumes"
        }
        (Trend::Rising, Some(_)) => "e(p) rises with p",
        (Trend::Falling, Some(_)) => "e(p) falls with p",
        (_, Some(_)) => "e(p) shows no significant trend with p",
    };
    KarpFlattTrend {
        verdict,
        slope_per_doubling: Some(slope),
        meaning: with_shared(meaning.into(), shared),
    }
}

/// `meaning`, followed on a shared machine by the sentence that says so.
fn with_shared(meaning: String, shared: Option<&SharedMachine>) -> String {
    match shared {
        Some(s) => format!("{meaning}; but {}", s.sentence()),
        None => meaning,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn amdahl_speedups_give_a_constant_e() {
        let f = 0.1;
        for p in [2.0, 4.0, 16.0] {
            let s = 1.0 / (f + (1.0 - f) / p);
            assert!((karp_flatt(p, s) - f).abs() < 1e-12);
        }
        assert_eq!(slope(&[2.0, 4.0, 8.0], &[0.1, 0.1, 0.1]), Some(0.0));
        assert_eq!(slope(&[2.0], &[0.1]), None);
        let s = slope(&[2.0, 4.0, 8.0], &[0.1, 0.2, 0.3]).unwrap();
        assert!((s - 0.1).abs() < 1e-12);
    }

    #[test]
    fn verdicts_follow_the_slope_interval() {
        assert_eq!(
            trend(&[], Some(0.1), [0.05, 0.1, 0.2], None).verdict,
            Trend::Rising
        );
        assert_eq!(
            trend(&[], Some(-0.1), [-0.05, -0.2], None).verdict,
            Trend::Falling
        );
        assert_eq!(
            trend(&[], Some(0.0), [-0.05, 0.05], None).verdict,
            Trend::Flat
        );
        let none = trend(&[], None, [], None);
        assert_eq!(none.verdict, Trend::Undetermined);
        assert!(none.slope_per_doubling.is_none());
        assert_eq!(
            serde_json::to_value(Trend::Undetermined).unwrap(),
            "undetermined"
        );
    }

    #[test]
    fn one_worker_count_above_one_quotes_its_e_and_says_a_trend_needs_two() {
        let e2 = KarpFlattPoint {
            p: 2.0,
            e: Estimate {
                estimate: 0.05,
                ci95: [0.03, 0.07],
            },
        };
        let t = trend(&[e2], None, [], None);
        assert_eq!(t.verdict, Trend::Undetermined);
        assert!(
            t.meaning.contains("e(2) = 0.0500 [0.0300, 0.0700]"),
            "{}",
            t.meaning
        );
        assert!(
            t.meaning.contains("needs at least two p > 1"),
            "{}",
            t.meaning
        );
    }

    #[test]
    fn on_a_shared_machine_no_verdict_blames_the_code() {
        let shared = SharedMachine {
            background_cpus: 1.0,
        };
        for (point, reps) in [
            (0.1, [0.05, 0.2]),
            (-0.1, [-0.2, -0.05]),
            (0.0, [-0.1, 0.1]),
        ] {
            let t = trend(&[], Some(point), reps, Some(&shared));
            for blame in ["synchronisation", "communication", "contention", "cache"] {
                assert!(!t.meaning.contains(blame), "{}", t.meaning);
            }
            assert!(
                t.meaning.contains("the machine was shared"),
                "{}",
                t.meaning
            );
            assert!(t.meaning.contains("1.00 CPUs"), "{}", t.meaning);
        }
        let quiet = trend(&[], Some(0.1), [0.05, 0.2], None);
        assert!(quiet.meaning.contains("synchronisation"));
    }
}
