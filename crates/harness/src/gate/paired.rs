//! The estimate a case is judged on: the log of the ratio current / baseline, with a standard
//! error from independent units, and Student's t for its intervals and p-values.
//!
//! **Units.** Samples of one round are not independent: a round's samples share its process,
//! its moment and its share of the machine, and on a shared 2-vCPU machine those move a round's
//! level by more than the samples inside it spread. The unit is therefore the round: each
//! round gives the log of its median sample. Treating samples as independent (as a bootstrap of
//! all samples does) understates the error when rounds differ and overstates it when the
//! machine drifts between rounds.
//!
//! **Pairs.** In an A/B run, round r of the base and round r of the current build are measured
//! back to back ([`super::ab::order`]): their difference cancels whatever the machine did at
//! that moment, so each round yields one log-ratio and the estimate is the 20%-trimmed mean of
//! those pairs, with Yuen's t interval ([`TRIM`]: a machine that changes state between the two
//! halves of a pair puts that pair far out, and a plain mean would follow it). Two files measured at different times
//! have no such pairs of rounds; there each sample is paired with the reference workload timed
//! right before it (when the gate normalises), and the samples of the two files are compared as
//! two independent groups (Yuen's trimmed t, with Welch's degrees of freedom). A
//! baseline file holds 3 or 4 rounds: as units they would leave 2 to 6 degrees of freedom and
//! intervals five times as wide at the family-wise level, so there the samples are the units,
//! and what their rounds share is left to the fast path's wider threshold.

use super::family::{Tails, incomplete_beta};
use nbody_engine::stats::median;

/// How the two sides' rounds relate.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Pairing {
    /// Round r of each side was measured back to back (an A/B run): one log-ratio per round.
    Rounds,
    /// The sides were measured apart (a baseline file): two independent groups.
    Independent,
}

/// An estimate of ln(current / baseline) with its standard error and degrees of freedom.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LogRatio {
    /// The estimate, natural log of the ratio.
    pub mean: f64,
    /// Its standard error (log units).
    pub se: f64,
    /// Degrees of freedom of its t distribution.
    pub df: f64,
    /// Units per side it was estimated from (pairs count once on each side).
    pub units: [usize; 2],
}

impl LogRatio {
    /// The paired estimate from each round's level (log of its median) on both sides, rounds
    /// aligned; rounds missing on either side are left out. `None` below two pairs.
    pub fn paired(base: &[Option<f64>], current: &[Option<f64>]) -> Option<LogRatio> {
        let d: Vec<f64> = base
            .iter()
            .zip(current)
            .filter_map(|(b, c)| Some((*c)? - (*b)?))
            .collect();
        let t = Trimmed::of(&d)?;
        Some(LogRatio {
            mean: t.mean,
            se: t.var.sqrt(),
            df: t.kept as f64 - 1.0,
            units: [d.len(), d.len()],
        })
    }

    /// Yuen's estimate from two independent groups of log levels (Welch's, for groups too
    /// small to trim). `None` when a group keeps fewer than two values.
    pub fn independent(base: &[f64], current: &[f64]) -> Option<LogRatio> {
        let (b, c) = (Trimmed::of(base)?, Trimmed::of(current)?);
        let se2 = b.var + c.var;
        let df = if se2 > 0.0 {
            se2 * se2
                / (b.var * b.var / (b.kept as f64 - 1.0) + c.var * c.var / (c.kept as f64 - 1.0))
        } else {
            (b.kept + c.kept) as f64 - 2.0
        };
        Some(LogRatio {
            mean: c.mean - b.mean,
            se: se2.sqrt(),
            df,
            units: [base.len(), current.len()],
        })
    }

    /// The ratio current / baseline the estimate stands for.
    pub fn ratio(&self) -> f64 {
        self.mean.exp()
    }

    /// The interval of the ratio that leaves `tail` on each side (0.025: the 95% interval).
    pub fn interval(&self, tail: f64) -> [f64; 2] {
        let t = t_quantile(1.0 - tail, self.df);
        [
            (self.mean - t * self.se).exp(),
            (self.mean + t * self.se).exp(),
        ]
    }

    /// One-sided p-values of "the ratio is at most 1 + threshold" (small when it is surely
    /// slower by more) and "at least 1 − threshold".
    pub fn tails(&self, threshold: f64) -> Tails {
        let up = (1.0 + threshold).ln();
        let down = (1.0 - threshold).max(0.0).ln();
        let upper_tail = |z: f64| 1.0 - self.cdf(z);
        Tails {
            regressed: upper_tail(self.mean - up),
            improved: self.cdf(self.mean - down),
        }
    }

    /// P(T ≤ x / se) for the estimate's t distribution, with a zero error read as certainty.
    fn cdf(&self, x: f64) -> f64 {
        if self.se > 0.0 {
            t_cdf(x / self.se, self.df)
        } else if x > 0.0 {
            1.0
        } else if x < 0.0 {
            0.0
        } else {
            0.5
        }
    }
}

/// Share of values trimmed from each end: 20%, Yuen's and Wilcox's usual choice, which keeps
/// 95% of the mean's efficiency on normal noise and ignores a few rounds caught by a change of
/// the machine's state.
pub const TRIM: f64 = 0.2;

/// A 20%-trimmed mean with the variance of its estimate from the winsorized values (Yuen 1974):
/// robust to the rounds a machine's change of state puts far out (on shared 2-vCPU machines
/// the reference workload's time jumps between levels 1.5x apart within seconds, and one pair
/// in four can straddle a jump), valid for symmetric noise of any tails.
struct Trimmed {
    /// The trimmed mean.
    mean: f64,
    /// The squared standard error of the trimmed mean.
    var: f64,
    /// Values kept after trimming (h); the t distribution has h − 1 degrees of freedom.
    kept: usize,
}

impl Trimmed {
    fn of(values: &[f64]) -> Option<Trimmed> {
        if values.iter().any(|x| !x.is_finite()) {
            return None;
        }
        let n = values.len();
        let g = (TRIM * n as f64).floor() as usize;
        let kept = n.checked_sub(2 * g)?;
        if kept < 2 {
            return None;
        }
        let mut v = values.to_vec();
        v.sort_by(f64::total_cmp);
        let mean = v[g..n - g].iter().sum::<f64>() / kept as f64;
        let (lo, hi) = (v[g], v[n - 1 - g]);
        let winsorized: Vec<f64> = v.iter().map(|x| x.clamp(lo, hi)).collect();
        let wmean = winsorized.iter().sum::<f64>() / n as f64;
        let wvar = winsorized.iter().map(|x| (x - wmean).powi(2)).sum::<f64>() / (n - 1) as f64;
        Some(Trimmed {
            mean,
            var: (n - 1) as f64 * wvar / (kept * (kept - 1)) as f64,
            kept,
        })
    }
}

/// The level of a round: log of the median of its positive, finite values; `None` without one.
pub fn round_level(values: impl Iterator<Item = f64>) -> Option<f64> {
    let v: Vec<f64> = values.filter(|x| x.is_finite() && *x > 0.0).collect();
    median(&v).map(f64::ln)
}

/// Student's t distribution function with `df` degrees of freedom (real, > 0).
pub fn t_cdf(t: f64, df: f64) -> f64 {
    if t.is_nan() {
        return f64::NAN;
    }
    if t.is_infinite() {
        return if t > 0.0 { 1.0 } else { 0.0 };
    }
    let x = df / (df + t * t);
    let tail = 0.5 * incomplete_beta(x, 0.5 * df, 0.5);
    if t > 0.0 { 1.0 - tail } else { tail }
}

/// The `p` quantile of Student's t with `df` degrees of freedom, by bisection on [`t_cdf`].
pub fn t_quantile(p: f64, df: f64) -> f64 {
    if p <= 0.0 {
        return f64::NEG_INFINITY;
    }
    if p >= 1.0 {
        return f64::INFINITY;
    }
    let (mut lo, mut hi) = (-1e7, 1e7);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if t_cdf(mid, df) < p {
            lo = mid;
        } else {
            hi = mid;
        }
        if hi - lo < 1e-12 * hi.abs().max(1.0) {
            break;
        }
    }
    0.5 * (lo + hi)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn t_quantiles_match_the_tables() {
        // Two-sided 95% critical values of Student's t (Fisher & Yates).
        for (df, t) in [(1.0, 12.706), (3.0, 3.182), (7.0, 2.365), (15.0, 2.131)] {
            assert!((t_quantile(0.975, df) - t).abs() < 5e-4, "{df}");
        }
        assert!((t_quantile(0.975, 1e6) - 1.960).abs() < 1e-3);
        assert!(t_quantile(0.5, 4.0).abs() < 1e-6);
        assert!((t_cdf(-2.0, 5.0) + t_cdf(2.0, 5.0) - 1.0).abs() < 1e-12);
    }

    #[test]
    fn pairs_cancel_what_the_rounds_share() {
        // Rounds 30% apart, the current one 5% slower in each: the pairs see 5% exactly.
        let base: Vec<Option<f64>> = [1.0f64, 1.3, 0.9, 1.2]
            .iter()
            .map(|x| Some(x.ln()))
            .collect();
        let cur: Vec<Option<f64>> = base.iter().map(|b| b.map(|b| b + 1.05f64.ln())).collect();
        let p = LogRatio::paired(&base, &cur).unwrap();
        assert!((p.ratio() - 1.05).abs() < 1e-12 && p.se < 1e-12);
        assert_eq!(p.tails(0.03).regressed, 0.0);
        assert_eq!(p.tails(0.10).regressed, 1.0);
        // As independent groups the same rounds show nothing at 3%.
        let levels = |v: &[Option<f64>]| v.iter().map(|x| x.unwrap()).collect::<Vec<_>>();
        let w = LogRatio::independent(&levels(&base), &levels(&cur)).unwrap();
        assert!((w.ratio() - 1.05).abs() < 1e-9 && w.tails(0.03).regressed > 0.1);
        // A missing round drops its pair only.
        let mut gap = cur.clone();
        gap[1] = None;
        assert_eq!(LogRatio::paired(&base, &gap).unwrap().units, [3, 3]);
    }

    #[test]
    fn a_round_caught_by_a_change_of_state_does_not_move_the_estimate() {
        // Ten pairs within ±0.5% of 3% slower, two caught 40% apart by the machine's state.
        let mut d: Vec<f64> = (0..10).map(|i| 0.03 + 0.001 * (i as f64 - 4.5)).collect();
        d.extend([0.4, -0.35]);
        let base = vec![Some(0.0); d.len()];
        let cur: Vec<Option<f64>> = d.iter().map(|&x| Some(x)).collect();
        let e = LogRatio::paired(&base, &cur).unwrap();
        assert!((e.mean - 0.03).abs() < 0.002, "{e:?}");
        assert!(e.tails(0.01).regressed < 1e-3, "{e:?}");
        assert_eq!(e.df, 7.0);
    }

    #[test]
    fn welch_degrees_of_freedom_follow_the_noisier_group() {
        let quiet = [0.0, 0.001, -0.001, 0.0005];
        let noisy = [0.1, -0.1, 0.05, -0.05];
        let e = LogRatio::independent(&quiet, &noisy).unwrap();
        assert!(e.df > 3.0 && e.df < 3.2, "{e:?}");
        assert!(LogRatio::independent(&[1.0], &noisy).is_none());
    }

    #[test]
    fn intervals_cover_at_their_level() {
        // 4000 seeded paired A/A decisions of 6 rounds: the 90% interval covers 1 about 90%
        // of the time, and the one-sided p-value against 1 is below 5% about 5% of the time.
        use rand::{Rng, SeedableRng};
        let mut rng = rand_pcg::Pcg64Mcg::seed_from_u64(17);
        let (mut covered, mut rejected) = (0, 0);
        let trials = 4000;
        for _ in 0..trials {
            let mut normal = || 0.02 * rng.sample::<f64, _>(rand_distr::StandardNormal);
            let base: Vec<Option<f64>> = (0..6).map(|_| Some(normal())).collect();
            let cur: Vec<Option<f64>> = (0..6).map(|_| Some(normal())).collect();
            let e = LogRatio::paired(&base, &cur).unwrap();
            let [lo, hi] = e.interval(0.05);
            covered += usize::from(lo <= 1.0 && 1.0 <= hi);
            rejected += usize::from(e.tails(0.0).regressed <= 0.05);
        }
        let share = |k: usize| k as f64 / trials as f64;
        assert!((share(covered) - 0.90).abs() < 0.02, "{}", share(covered));
        assert!(
            (share(rejected) - 0.05).abs() < 0.015,
            "{}",
            share(rejected)
        );
    }
}
