//! Control across cases. A gate run judges 15-20 cases; judged one by one at 2.5% each, the
//! chance that some unchanged case is flagged grows with their number. Each case instead gets
//! a one-sided bootstrap p-value against its margin, and Holm's step-down keeps the
//! probability that any unchanged case is flagged in a gate run at [`FAMILY_ALPHA`], whatever
//! the number of cases and however they are correlated (Holm 1979: no independence assumed).

/// Family-wise error of one gate run's regressions (and, separately, of its improvements):
/// the one-sided level of the 95% interval each case used to be judged on alone.
pub const FAMILY_ALPHA: f64 = 0.025;

/// One-sided bootstrap p-values of a ratio against the threshold's two margins.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct Tails {
    /// For "the ratio is at most 1 + threshold": small when the case is slower by more.
    pub regressed: f64,
    /// For "the ratio is at least 1 − threshold": small when the case is faster by more.
    pub improved: f64,
}

impl Tails {
    /// Both p-values 1: nothing can be claimed (a side without samples).
    pub const NONE: Tails = Tails {
        regressed: 1.0,
        improved: 1.0,
    };

    /// From the bootstrap replicates of the ratio: the share of replicates on the null's
    /// side of each margin, counted as (1 + k) / (1 + B) so that no p-value is 0.
    pub fn of(replicates: &[f64], threshold: f64) -> Tails {
        let finite: Vec<f64> = replicates.iter().copied().filter(|r| !r.is_nan()).collect();
        if finite.is_empty() {
            return Tails::NONE;
        }
        let share = |k: usize| (1 + k) as f64 / (1 + finite.len()) as f64;
        Tails {
            regressed: share(finite.iter().filter(|&&r| r <= 1.0 + threshold).count()),
            improved: share(finite.iter().filter(|&&r| r >= 1.0 - threshold).count()),
        }
    }

    /// The intersection-union test of two statistics (normalised and raw): a change is
    /// claimed only when both claim it, so each p-value is the larger of the two.
    pub fn both(self, other: Tails) -> Tails {
        Tails {
            regressed: self.regressed.max(other.regressed),
            improved: self.improved.max(other.improved),
        }
    }
}

/// Holm's step-down at family-wise level `alpha`: whether each hypothesis is rejected. The
/// p-values are taken in increasing order; the k-th smallest (from 0) is rejected while it is
/// at most alpha / (m − k), and every later one is kept once one is not.
pub fn holm(p: &[f64], alpha: f64) -> Vec<bool> {
    let m = p.len();
    let mut order: Vec<usize> = (0..m).collect();
    order.sort_by(|&a, &b| p[a].total_cmp(&p[b]).then(a.cmp(&b)));
    let mut rejected = vec![false; m];
    for (k, &i) in order.iter().enumerate() {
        if p[i] <= alpha / (m - k) as f64 {
            rejected[i] = true;
        } else {
            break;
        }
    }
    rejected
}

/// The exact (Clopper–Pearson) two-sided 95% interval of a binomial rate with `k` events in
/// `n` trials; `[0, 1]` for no trials.
pub fn clopper_pearson(k: usize, n: usize) -> [f64; 2] {
    if n == 0 {
        return [0.0, 1.0];
    }
    let lower = if k == 0 {
        0.0
    } else {
        beta_quantile(0.025, k as f64, (n - k + 1) as f64)
    };
    let upper = if k == n {
        1.0
    } else {
        beta_quantile(0.975, (k + 1) as f64, (n - k) as f64)
    };
    [lower, upper]
}

/// The `q` quantile of Beta(a, b), by bisection on the regularised incomplete beta function.
fn beta_quantile(q: f64, a: f64, b: f64) -> f64 {
    let (mut lo, mut hi) = (0.0, 1.0);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if incomplete_beta(mid, a, b) < q {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}

/// The regularised incomplete beta function I_x(a, b), from its continued fraction (Lentz's
/// method), using the symmetry I_x(a, b) = 1 − I_{1−x}(b, a) where the fraction converges
/// slowly.
pub(crate) fn incomplete_beta(x: f64, a: f64, b: f64) -> f64 {
    if x <= 0.0 {
        return 0.0;
    }
    if x >= 1.0 {
        return 1.0;
    }
    let ln_front = ln_gamma(a + b) - ln_gamma(a) - ln_gamma(b) + a * x.ln() + b * (1.0 - x).ln();
    if x < (a + 1.0) / (a + b + 2.0) {
        ln_front.exp() * beta_fraction(x, a, b) / a
    } else {
        1.0 - ln_front.exp() * beta_fraction(1.0 - x, b, a) / b
    }
}

fn beta_fraction(x: f64, a: f64, b: f64) -> f64 {
    const TINY: f64 = 1e-300;
    let mut c = 1.0;
    let mut d = 1.0 - (a + b) * x / (a + 1.0);
    d = 1.0 / if d.abs() < TINY { TINY } else { d };
    let mut h = d;
    for m in 1..500 {
        let m = f64::from(m);
        for numerator in [
            m * (b - m) * x / ((a + 2.0 * m - 1.0) * (a + 2.0 * m)),
            -(a + m) * (a + b + m) * x / ((a + 2.0 * m) * (a + 2.0 * m + 1.0)),
        ] {
            d = 1.0 + numerator * d;
            d = 1.0 / if d.abs() < TINY { TINY } else { d };
            c = 1.0 + numerator / c;
            if c.abs() < TINY {
                c = TINY;
            }
            h *= d * c;
        }
        if (d * c - 1.0).abs() < 1e-15 {
            break;
        }
    }
    h
}

/// ln Γ(x) for x > 0 (Lanczos, g = 7, nine terms: about 15 significant digits).
fn ln_gamma(x: f64) -> f64 {
    const G: [f64; 9] = [
        0.999_999_999_999_809_9,
        676.520_368_121_885_1,
        -1_259.139_216_722_402_8,
        771.323_428_777_653_1,
        -176.615_029_162_140_6,
        12.507_343_278_686_905,
        -0.138_571_095_265_720_12,
        9.984_369_578_019_572e-6,
        1.505_632_735_149_311_6e-7,
    ];
    if x < 0.5 {
        let pi = std::f64::consts::PI;
        return (pi / (pi * x).sin()).ln() - ln_gamma(1.0 - x);
    }
    let x = x - 1.0;
    let mut sum = G[0];
    for (i, g) in G.iter().enumerate().skip(1) {
        sum += g / (x + i as f64);
    }
    let t = x + 7.5;
    0.5 * (2.0 * std::f64::consts::PI).ln() + (x + 0.5) * t.ln() - t + sum.ln()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn holm_steps_down_and_stops_at_the_first_kept() {
        // m = 4: thresholds 0.0125/4, /3, /2, /1 for the sorted p-values.
        let alpha = 0.05;
        assert_eq!(
            holm(&[0.01, 0.001, 0.04, 0.3], alpha),
            [true, true, false, false]
        );
        // The smallest fails alpha / m: nothing is rejected, even a later small one.
        assert_eq!(holm(&[0.02, 0.02, 0.02], alpha), [false, false, false]);
        assert_eq!(holm(&[0.001, 0.02, 0.04], alpha), [true, true, true]);
        assert!(holm(&[], alpha).is_empty());
    }

    #[test]
    fn tails_count_the_replicates_beyond_each_margin() {
        let r: Vec<f64> = (0..99).map(|i| 1.0 + 0.002 * f64::from(i)).collect();
        // 1.0 .. 1.196: 51 replicates at or below 1.10, 51 at or above 1.098.
        let t = Tails::of(&r, 0.10);
        assert_eq!(t.regressed, 52.0 / 100.0);
        assert_eq!(t.improved, 1.0);
        let fast = Tails::of(&[0.5, 0.6, f64::NAN], 0.10);
        assert_eq!(fast.improved, 1.0 / 3.0);
        assert_eq!(fast.regressed, 1.0);
        assert_eq!(Tails::of(&[], 0.1), Tails::NONE);
        let both = Tails::of(&[2.0], 0.1).both(Tails::of(&[1.0], 0.1));
        assert_eq!(both.regressed, 1.0);
    }

    #[test]
    fn clopper_pearson_matches_published_values() {
        // 0 of 100: the "rule of three" bound, exactly 1 − 0.025^(1/100).
        let [lo, hi] = clopper_pearson(0, 100);
        assert_eq!(lo, 0.0);
        assert!((hi - (1.0 - 0.025f64.powf(0.01))).abs() < 1e-9, "{hi}");
        // 5 of 50: R's binom.test gives [0.03327, 0.21813].
        let [lo, hi] = clopper_pearson(5, 50);
        assert!(
            (lo - 0.033_27).abs() < 1e-4 && (hi - 0.218_13).abs() < 1e-4,
            "{lo} {hi}"
        );
        assert_eq!(clopper_pearson(7, 7)[1], 1.0);
        assert_eq!(clopper_pearson(0, 0), [0.0, 1.0]);
    }

    #[test]
    fn ln_gamma_is_right_at_known_points() {
        assert!((ln_gamma(1.0)).abs() < 1e-12);
        assert!((ln_gamma(5.0) - 24f64.ln()).abs() < 1e-12);
        assert!((ln_gamma(0.5) - std::f64::consts::PI.sqrt().ln()).abs() < 1e-12);
    }
}
