//! Strong scaling (fixed problem, p workers): speedup and efficiency with propagated
//! uncertainty, Amdahl's law `T(p) = T1·(f + (1−f)/p)`, Karp-Flatt, and optional overhead terms.
//!
//! Amdahl's law is linear in 1/p, `T = a + b/p` with `T1 = a + b` and `f = a/(a + b)`, and is
//! fitted on relative residuals. Every interval comes from one bootstrap run, so the speedup
//! intervals carry the noise of both T1 and T(p).

use super::bootstrap::{Replicates, bootstrap, estimate, percentile_ci};
use super::karp_flatt::{self, KarpFlattPoint, KarpFlattTrend};
use super::linear::{self, Goodness};
use super::overhead::{self, OverheadCandidate, OverheadSelection, OverheadTerm, OverheadTermFit};
use super::{
    CiMethod, Data, Estimate, FitError, Input, RESAMPLES, Samples, SharedMachine, XRule,
    clamp_unit, prepare,
};
use serde::Serialize;

const MODEL: &str = "strong scaling";

/// Per thread count: the measured time and what follows from it.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct StrongPoint {
    /// The thread (worker) count.
    pub p: f64,
    /// The median time at `p`, seconds.
    pub median_s: f64,
    /// How many times were measured at `p`.
    pub samples: usize,
    /// `S = T1 / T(p)` from the medians.
    pub speedup: Estimate,
    /// `S / p`.
    pub efficiency: Estimate,
    /// The hardware's own throughput ratio at p, when given (taken as exact).
    pub ceiling: Option<f64>,
    /// `S / ceiling`: the share of the attainable speedup reached.
    pub speedup_vs_ceiling: Option<Estimate>,
}

/// A strong-scaling analysis.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct StrongFit {
    /// x = p, the median time and sample count at each p.
    pub inputs: Vec<Input>,
    /// Speedup and efficiency at each measured p, in increasing p (the first is p = 1).
    pub points: Vec<StrongPoint>,
    /// Amdahl's T(1), seconds.
    pub t1: Estimate,
    /// Amdahl's serial fraction f, clamped to [0, 1] (see `clamped`).
    pub serial_fraction: Estimate,
    /// f as fitted, which can leave [0, 1] (superlinear speedup gives f < 0).
    pub(crate) serial_fraction_unclamped: Estimate,
    /// Whether the estimate or an end of its interval was clamped to [0, 1].
    pub clamped: bool,
    /// `1/f`, the speedup Amdahl's law allows at any p; infinite (JSON null) when f reaches 0.
    pub max_speedup: Estimate,
    /// Amdahl's fit to the medians (r² on relative residuals).
    pub goodness: Goodness,
    /// e(p) at every p > 1.
    pub karp_flatt: Vec<KarpFlattPoint>,
    /// How e(p) changes as p doubles, and what that says about the overhead.
    pub karp_flatt_trend: KarpFlattTrend,
    /// Amdahl with an added overhead term, each tried by leave-one-out cross-validation
    /// (none with fewer than 4 thread counts).
    pub overhead: OverheadSelection,
    /// How the bootstrap drew its replicates (decides what the intervals include).
    pub ci_method: CiMethod,
    /// The number of bootstrap replicates drawn (before degenerate ones were dropped).
    pub resamples: usize,
    /// Warnings for a reader, one sentence each: clamping, too few thread counts, a kept
    /// overhead term, ceilings at unmeasured p, a machine shared with other processes.
    pub notes: Vec<String>,
    /// `(T1, clamped f)` of every bootstrap replicate, for curve bands.
    #[serde(skip)]
    replicates: Vec<[f64; 2]>,
}

impl StrongFit {
    #[cfg(test)]
    /// Amdahl's time at any p with its 95% band (pointwise, from the replicates).
    pub(crate) fn amdahl_time(&self, p: f64) -> (f64, [f64; 2]) {
        let at = |[t1, f]: [f64; 2]| t1 * (f + (1.0 - f) / p);
        self.curve(at)
    }

    /// Amdahl's speedup `1/(f + (1−f)/p)` at any p with its 95% band.
    pub(crate) fn amdahl_speedup(&self, p: f64) -> (f64, [f64; 2]) {
        self.curve(|[_, f]| 1.0 / (f + (1.0 - f) / p))
    }

    /// `[T1, f]` (f clamped) of every bootstrap replicate, for custom bands.
    pub fn replicates(&self) -> &[[f64; 2]] {
        &self.replicates
    }

    fn curve(&self, at: impl Fn([f64; 2]) -> f64) -> (f64, [f64; 2]) {
        let point = at([self.t1.estimate, self.serial_fraction.estimate]);
        let band = percentile_ci(self.replicates.iter().map(|&r| at(r)));
        (point, band.unwrap_or([point, point]))
    }
}

struct Replicate {
    speedups: Vec<f64>,
    t1: f64,
    f: f64,
    kf_slope: Option<f64>,
    /// `(c, f)` of the kept overhead model.
    overhead: Option<(f64, f64)>,
}

/// Analyses strong scaling from samples at x = p. Needs p = 1 and one more p. `ceiling` gives
/// the measured hardware throughput ratio per p (may be empty; entries at unmeasured p are
/// ignored).
pub fn fit_strong(
    samples: &[Samples],
    ceiling: &[(f64, f64)],
    seed: u64,
) -> Result<StrongFit, FitError> {
    fit_strong_on(samples, ceiling, seed, None)
}

/// [`fit_strong`] of times measured on a machine that was `shared` with other processes when
/// it was: then no reading of the fit attributes the loss of speedup to the code.
pub fn fit_strong_on(
    samples: &[Samples],
    ceiling: &[(f64, f64)],
    seed: u64,
    shared: Option<SharedMachine>,
) -> Result<StrongFit, FitError> {
    let data = prepare(MODEL, samples, XRule::AtLeastOne, 2)?;
    check_inputs(&data.xs, ceiling)?;
    let ps = &data.xs;
    let (t1, f_raw) = amdahl(ps, &data.medians).ok_or(FitError::Degenerate {
        model: MODEL,
        why: "Amdahl's law gives no positive T1",
    })?;
    let (candidates, kept) = overhead::select(ps, &data.medians);
    let kept_abc = overhead::fit(kept, ps, &data.medians).expect("selection fitted it");
    let reps = bootstrap_replicates(&data, kept, kept_abc, seed)?;
    let fits = &reps.fits;

    let above_one: Vec<f64> = ps[1..].to_vec();
    let speedups = speedups_of(&data.medians);
    let points = strong_points(&data, &speedups, fits, ceiling);
    let kf_point = karp_flatt_values(ps, &speedups);
    let karp_flatt = karp_flatt_points(ps, &kf_point, fits);
    let karp_flatt_trend = karp_flatt::trend(
        &karp_flatt,
        karp_flatt::slope(&above_one, &kf_point),
        fits.iter().filter_map(|r| r.kf_slope),
        shared.as_ref(),
    );

    let unclamped = estimate(f_raw, fits.iter().map(|r| r.f));
    let serial_fraction = unclamped.map(|f| clamp_unit(f).0);
    let clamped = serial_fraction != unclamped;
    let t1_est = estimate(t1, fits.iter().map(|r| r.t1));
    let predicted: Vec<f64> = ps
        .iter()
        .map(|p| t1 * (f_raw + (1.0 - f_raw) / p))
        .collect();
    let overhead = overhead_selection(candidates, kept, kept_abc, fits);
    let mut notes = notes(ps, ceiling, &unclamped, clamped, &overhead);
    notes.extend(shared.map(|s| s.sentence()));
    Ok(StrongFit {
        inputs: data.inputs(),
        points,
        t1: t1_est,
        serial_fraction,
        serial_fraction_unclamped: unclamped,
        clamped,
        max_speedup: serial_fraction.map(|f| 1.0 / f),
        goodness: Goodness::of(
            &data.medians,
            &predicted,
            &linear::relative_weights(&data.medians),
        ),
        karp_flatt,
        karp_flatt_trend,
        overhead,
        ci_method: reps.method,
        resamples: RESAMPLES,
        notes,
        replicates: fits.iter().map(|r| [r.t1, clamp_unit(r.f).0]).collect(),
    })
}

/// Refuses samples without a p = 1 baseline (the sorted `ps` start elsewhere) and ceiling
/// entries that are not a finite p ≥ 1 with a finite positive ratio.
fn check_inputs(ps: &[f64], ceiling: &[(f64, f64)]) -> Result<(), FitError> {
    if ps[0] != 1.0 {
        return Err(FitError::NoBaseline {
            model: MODEL,
            measured: list(ps),
        });
    }
    for &(p, ratio) in ceiling {
        if !(p.is_finite() && p >= 1.0 && ratio.is_finite() && ratio > 0.0) {
            return Err(FitError::BadCeiling {
                model: MODEL,
                p,
                ratio,
            });
        }
    }
    Ok(())
}

/// Amdahl's `(T1, f)` fitted to the times at `ps`; `None` when the fit fails or gives no
/// positive T1.
fn amdahl(ps: &[f64], times: &[f64]) -> Option<(f64, f64)> {
    let [a, b, _] = overhead::fit(None, ps, times)?;
    (a + b > 0.0).then(|| (a + b, a / (a + b)))
}

/// The speedups `T1 / T(p)` of times whose first entry is at p = 1.
fn speedups_of(t: &[f64]) -> Vec<f64> {
    t.iter().map(|tp| t[0] / tp).collect()
}

/// The Karp-Flatt serial fraction e(p) at every p > 1, from the speedups at every p.
fn karp_flatt_values(ps: &[f64], speedups: &[f64]) -> Vec<f64> {
    (1..ps.len())
        .map(|i| karp_flatt::karp_flatt(ps[i], speedups[i]))
        .collect()
}

/// Bootstraps Amdahl's law, the speedups, the Karp-Flatt slope and the kept overhead model
/// (`kept_abc` its point fit, whose predictions drive residual resampling).
fn bootstrap_replicates(
    data: &Data,
    kept: Option<OverheadTerm>,
    kept_abc: [f64; 3],
    seed: u64,
) -> Result<Replicates<Replicate>, FitError> {
    let ps = &data.xs;
    let fitted: Vec<f64> = ps
        .iter()
        .map(|&p| overhead::time(kept, kept_abc, p))
        .collect();
    let above_one: Vec<f64> = ps[1..].to_vec();
    let params = if kept.is_some() { 3 } else { 2 };
    bootstrap(MODEL, data, &fitted, params, seed, |t| {
        let (t1, f) = amdahl(ps, t)?;
        let speedups = speedups_of(t);
        let kf_slope = karp_flatt::slope(&above_one, &karp_flatt_values(ps, &speedups));
        let overhead = match kept {
            Some(term) => {
                let [a, b, c] = overhead::fit(Some(term), ps, t)?;
                // A replicate's serial fraction is a fraction: clamped like Amdahl's.
                Some((c, clamp_unit(a / (a + b)).0))
            }
            None => None,
        };
        Some(Replicate {
            speedups,
            t1,
            f,
            kf_slope,
            overhead,
        })
    })
}

/// Per measured p: the median time, the speedup and efficiency with their intervals from the
/// replicates, and the hardware ceiling when given at that p.
fn strong_points(
    data: &Data,
    speedups: &[f64],
    fits: &[Replicate],
    ceiling: &[(f64, f64)],
) -> Vec<StrongPoint> {
    let ps = &data.xs;
    (0..ps.len())
        .map(|i| {
            let p = ps[i];
            let speedup = estimate(speedups[i], fits.iter().map(|r| r.speedups[i]));
            let ceiling = ceiling.iter().find(|(cp, _)| *cp == p).map(|&(_, r)| r);
            StrongPoint {
                p,
                median_s: data.medians[i],
                samples: data.values[i].len(),
                speedup,
                efficiency: speedup.map(|s| s / p),
                ceiling,
                speedup_vs_ceiling: ceiling.map(|c| speedup.map(|s| s / c)),
            }
        })
        .collect()
}

/// e(p) at every p > 1 (`kf_point` from the medians) with its interval from the replicates.
fn karp_flatt_points(ps: &[f64], kf_point: &[f64], fits: &[Replicate]) -> Vec<KarpFlattPoint> {
    (1..ps.len())
        .map(|i| KarpFlattPoint {
            p: ps[i],
            e: estimate(
                kf_point[i - 1],
                fits.iter()
                    .map(|r| karp_flatt::karp_flatt(ps[i], r.speedups[i])),
            ),
        })
        .collect()
}

/// The overhead candidates and the kept model's coefficient and serial fraction with their
/// intervals from the replicates.
fn overhead_selection(
    candidates: Vec<OverheadCandidate>,
    kept: Option<OverheadTerm>,
    kept_abc: [f64; 3],
    fits: &[Replicate],
) -> OverheadSelection {
    OverheadSelection {
        candidates,
        kept: kept.map(|term| OverheadTermFit {
            term,
            coefficient: estimate(
                kept_abc[2],
                fits.iter().filter_map(|r| r.overhead.map(|o| o.0)),
            ),
            serial_fraction: estimate(
                kept_abc[0] / (kept_abc[0] + kept_abc[1]),
                fits.iter().filter_map(|r| r.overhead.map(|o| o.1)),
            ),
        }),
    }
}

fn list(xs: &[f64]) -> String {
    xs.iter().map(f64::to_string).collect::<Vec<_>>().join(", ")
}

fn notes(
    ps: &[f64],
    ceiling: &[(f64, f64)],
    f: &Estimate,
    clamped: bool,
    overhead: &OverheadSelection,
) -> Vec<String> {
    let mut notes = Vec::new();
    if clamped {
        notes.push(format!(
            "the fitted serial fraction is {:.4} [{:.4}, {:.4}]; it is reported clamped to [0, 1]{}",
            f.estimate,
            f.ci95[0],
            f.ci95[1],
            if f.ci95[0] < 0.0 {
                " (below 0: speedup beyond what Amdahl's law allows, e.g. cache effects)"
            } else {
                ""
            }
        ));
    }
    if ps.len() == 2 {
        notes.push(
            "with two thread counts Amdahl's law passes through both medians; the interval \
             reflects measurement noise only, not the model's adequacy"
                .into(),
        );
    }
    if ps.len() < 4 {
        notes.push("overhead terms need at least 4 thread counts; not tried".into());
    }
    if let Some(kept) = &overhead.kept {
        notes.push(format!(
            "an overhead term {} is preferred by leave-one-out cross-validation; the serial \
             fraction without it ({:.4}) absorbs that overhead, with it f = {:.4}",
            kept.term.name(),
            f.estimate,
            kept.serial_fraction.estimate
        ));
    }
    let unused: Vec<String> = ceiling
        .iter()
        .filter(|(p, _)| !ps.contains(p))
        .map(|(p, _)| p.to_string())
        .collect();
    if !unused.is_empty() {
        notes.push(format!(
            "hardware ceilings at unmeasured p = {} are ignored",
            unused.join(", ")
        ));
    }
    notes
}

#[cfg(test)]
#[path = "strong_tests.rs"]
mod tests;
