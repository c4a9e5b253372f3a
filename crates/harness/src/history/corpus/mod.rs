//! The corpus the change-point detection is scored on, and the scores: 850 generated series
//! shaped like a performance history (30 to 120 points, one per commit), each from its own
//! seed, with steps of 3–20% up and down (one or two per series), isolated spikes, slow drifts
//! over the whole series, drifts of 0.1–0.5% per commit over 20–60 commits (some with a step
//! beside them), two-state noise and flat noise. The chosen model ([`super::drifts`]: level
//! or drift segments), the step detector alone ([`super::changes`]) and the alternative it was
//! chosen over (Apache Otava's E-divisive means with t-tests, [`EDivisive`]) are scored side by
//! side; the table of docs/explanation/change-points.md is [`render_scores_markdown`] of them,
//! and a test keeps it so.
//!
//! How a detection counts ([`score`]): a step within ±3 points of a true step is that step
//! found (one per step); any other is a false one. The scores for steps of 5% or more count
//! the series with such steps and the flat and spike-only series (their steps are all false);
//! the 3–5% scores count the series with steps of that size. A true drift is reported as a
//! drift when a reported drift in the same direction covers half its range or more; every step
//! reported inside a true drift's range is an error (a drift told as a step). The delay of a
//! found step is how many points after its first one the detector, fed one point at a time,
//! first reports it (within the tolerance); it has settled from the point after which it stays
//! where the whole series puts it.

mod edivisive;
mod score;
#[cfg(test)]
mod tests;

pub use edivisive::EDivisive;
pub use score::{CorpusScores, render_scores_markdown, score_corpus};

use rand::{Rng, SeedableRng};
use rand_distr::StandardNormal;
use rand_pcg::Pcg64Mcg;

/// The noise of one point is log-normal, its σ drawn per series between these two values.
/// Provenance: results/gate-study/AuthenticAMD-26-2-1-2cpu.json, `runs[].widths`, mode `ab`,
/// `raw`: the median width of the gate's A/A (unchanged code) 95% intervals of the ratio,
/// relative to the ratio, is 0.0279 with the machine quiet and 0.0391 under a spinning load. A
/// width is 2 × 1.96 standard errors of the log ratio: σ = 0.0279 / 3.92 = 0.0071 and
/// 0.0391 / 3.92 = 0.0100. Those are the spread of a ratio of two interleaved runs; a
/// history's point comes from a run of its own, on its own day and runner, so each point gets
/// the whole σ (not σ/√2), which keeps the corpus on the noisy side.
const SIGMA: [f64; 2] = [0.0071, 0.0100];

/// The first series' seed; series i has `SEED + i`.
const SEED: u64 = 20_261_205;

/// A detection within this many points of a true step finds it.
const TOLERANCE: usize = 3;

/// What a series holds besides noise.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    /// One or two steps of a band's size.
    Steps(Band),
    /// One to three isolated spikes.
    Spikes,
    /// A drift of 3–10% over the whole series.
    Drift,
    /// Nothing.
    Flat,
    /// A drift of 0.1–0.5% per commit over 20–60 commits, 5% or more in all, flat around it.
    Ramp,
    /// A ramp with a step of 5–20% 5 to 15 points before or after it.
    RampAndStep,
    /// Each point at one of two levels 2–5% apart, drawn independently (a machine that lands
    /// in one of two states): no step, no drift.
    TwoState,
}

/// The size of a series' steps, |ratio − 1|.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Band {
    /// 5% to 20%: the steps the detector must find (F1 ≥ 0.9).
    Large,
    /// 3% to 5%: reported, no target.
    Small,
}

impl Band {
    fn sizes(self) -> std::ops::Range<f64> {
        match self {
            Band::Large => 0.05..0.20,
            Band::Small => 0.03..0.05,
        }
    }
}

/// A true step: the first point of the new level and its ratio to the old.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Step {
    pub index: usize,
    pub ratio: f64,
}

/// A true drift: the log of the series moves by `ln(per_point)` at every point from `start`
/// to `end` (its first and last point).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Drift {
    pub start: usize,
    pub end: usize,
    pub per_point: f64,
}

impl Drift {
    /// The whole drift, last point over first.
    pub fn ratio(&self) -> f64 {
        self.per_point.powi((self.end - self.start) as i32)
    }
}

/// One generated series and what it truly holds.
#[derive(Clone, Debug, PartialEq)]
pub struct Series {
    pub kind: Kind,
    pub values: Vec<f64>,
    pub steps: Vec<Step>,
    pub drift: Option<Drift>,
}

/// How many series of each kind (with how many steps): 850 in all. New kinds go at the end,
/// so that every earlier series keeps its seed and its values.
const PLAN: [(Kind, usize, usize); 10] = [
    (Kind::Steps(Band::Large), 1, 150),
    (Kind::Steps(Band::Large), 2, 100),
    (Kind::Steps(Band::Small), 1, 75),
    (Kind::Steps(Band::Small), 2, 25),
    (Kind::Spikes, 0, 100),
    (Kind::Drift, 0, 50),
    (Kind::Flat, 0, 100),
    (Kind::Ramp, 0, 100),
    (Kind::RampAndStep, 1, 50),
    (Kind::TwoState, 0, 100),
];

/// How many series of `kind` the corpus has.
pub fn planned(kind: Kind) -> usize {
    PLAN.iter().filter(|p| p.0 == kind).map(|p| p.2).sum()
}

/// The corpus, the same on every call.
pub fn corpus() -> Vec<Series> {
    let mut out = Vec::new();
    for (kind, steps, count) in PLAN {
        for _ in 0..count {
            let seed = SEED + out.len() as u64;
            out.push(generate(kind, steps, &mut Pcg64Mcg::seed_from_u64(seed)));
        }
    }
    out
}

fn generate(kind: Kind, n_steps: usize, rng: &mut Pcg64Mcg) -> Series {
    if matches!(kind, Kind::Ramp | Kind::RampAndStep | Kind::TwoState) {
        return generate_new(kind, rng);
    }
    let n: usize = rng.random_range(if n_steps == 2 { 40..=120 } else { 30..=120 });
    let sigma = rng.random_range(SIGMA[0]..=SIGMA[1]);
    let base = 10f64.powf(rng.random_range(-6.0..0.0));
    let mut factor = vec![1.0; n];
    let mut steps = Vec::new();
    let mut spikes = Vec::new();
    let mut drift = None;
    match kind {
        Kind::Steps(band) => {
            // At least 10 points on each side of a step and between two.
            let first = rng.random_range(10..=n - 10 * n_steps);
            let mut at = first;
            for i in 0..n_steps {
                if i > 0 {
                    at = rng.random_range(at + 10..=n - 10);
                }
                let size = rng.random_range(band.sizes());
                let ratio = if rng.random_bool(0.5) {
                    1.0 + size
                } else {
                    1.0 - size
                };
                steps.push(Step { index: at, ratio });
            }
            // A quarter of them also have a spike, at least 2 points from any step.
            if rng.random_bool(0.25) {
                let at = rng.random_range(0..n);
                if steps.iter().all(|s| at.abs_diff(s.index) >= 2) {
                    spikes.push(at);
                }
            }
        }
        Kind::Spikes => {
            let count = rng.random_range(1..=3);
            for _ in 0..50 {
                let at = rng.random_range(0..n);
                if spikes.len() < count && spikes.iter().all(|&s: &usize| at.abs_diff(s) >= 10) {
                    spikes.push(at);
                }
            }
        }
        Kind::Drift => {
            let size = rng.random_range(0.03..0.10);
            let total: f64 = if rng.random_bool(0.5) {
                1.0 + size
            } else {
                1.0 - size
            };
            for (i, f) in factor.iter_mut().enumerate() {
                *f = total.powf(i as f64 / (n - 1) as f64);
            }
            drift = Some(Drift {
                start: 0,
                end: n - 1,
                per_point: total.powf(1.0 / (n - 1) as f64),
            });
        }
        _ => {}
    }
    for s in &steps {
        for f in &mut factor[s.index..] {
            *f *= s.ratio;
        }
    }
    for &at in &spikes {
        // Mostly slow outliers (a busy neighbour), up to twice the time; some fast ones.
        factor[at] *= if rng.random_bool(0.8) {
            1.0 + rng.random_range(0.05..1.0)
        } else {
            1.0 - rng.random_range(0.05..0.3)
        };
    }
    Series {
        kind,
        values: noisy(&factor, base, sigma, rng),
        steps,
        drift,
    }
}

/// The kinds added with the drift model: ramps over part of the series, a ramp beside a step,
/// and two-state noise.
fn generate_new(kind: Kind, rng: &mut Pcg64Mcg) -> Series {
    let sigma = rng.random_range(SIGMA[0]..=SIGMA[1]);
    let base = 10f64.powf(rng.random_range(-6.0..0.0));
    let (mut steps, mut drift) = (Vec::new(), None);
    let factor: Vec<f64> = if kind == Kind::TwoState {
        let n: usize = rng.random_range(30..=120);
        let gap = rng.random_range(0.02..0.05);
        let upper = rng.random_range(0.2..0.8);
        (0..n)
            .map(|_| {
                if rng.random_bool(upper) {
                    1.0 + gap
                } else {
                    1.0
                }
            })
            .collect()
    } else {
        // 20 to 60 commits at 0.1–0.5% each, 5% or more in all (the rate's floor rises for
        // the short ones), flat for 5 to 30 points either side.
        let len: usize = rng.random_range(20..=60);
        let floor = (1.05f64.ln() / (len - 1) as f64).max(0.001);
        let rate = rng.random_range(floor..0.005);
        let sign = if rng.random_bool(0.5) { 1.0 } else { -1.0 };
        // Beside a step, 20 or more either side: room for the step and its level.
        let least = if kind == Kind::RampAndStep { 20 } else { 5 };
        let (before, after) = (rng.random_range(least..=30), rng.random_range(least..=30));
        let start = before;
        let end = start + len - 1;
        let n = end + 1 + after;
        let mut factor: Vec<f64> = (0..n)
            .map(|i| (sign * rate * (i.clamp(start, end) - start) as f64).exp())
            .collect();
        drift = Some(Drift {
            start,
            end,
            per_point: (sign * rate).exp(),
        });
        if kind == Kind::RampAndStep {
            // The step 5 to 15 points outside the ramp, before or after it: at least 5 points
            // of level on each of its sides.
            let gap = rng.random_range(5..=15);
            let at = if rng.random_bool(0.5) {
                start - gap
            } else {
                end + gap
            };
            let size = rng.random_range(Band::Large.sizes());
            let ratio = if rng.random_bool(0.5) {
                1.0 + size
            } else {
                1.0 - size
            };
            for f in &mut factor[at..] {
                *f *= ratio;
            }
            steps.push(Step { index: at, ratio });
        }
        factor
    };
    Series {
        kind,
        values: noisy(&factor, base, sigma, rng),
        steps,
        drift,
    }
}

/// The series' values: each point's level `base × factor` with log-normal noise of `sigma`.
fn noisy(factor: &[f64], base: f64, sigma: f64, rng: &mut Pcg64Mcg) -> Vec<f64> {
    factor
        .iter()
        .map(|f| {
            let z: f64 = rng.sample(StandardNormal);
            base * f * (sigma * z).exp()
        })
        .collect()
}
