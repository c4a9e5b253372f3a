//! Straight lines through a run of points (logarithms, one per commit): the quick robust fit
//! the drift model ([`super::drifts`]) costs its candidate segments with, and the Theil–Sen
//! fit with Sen's interval that a reported drift is described by.
//!
//! Both are built from slopes between pairs of points and medians, so that a spike moves them
//! by at most a rank, as the medians of the level segments are ([`super::changes`]). Least
//! squares would not do: one spike at the end of a 40-point ramp tilts a least-squares line by
//! 0.25% per commit, as much as the drifts to be found.

/// The two-sided 95% quantile of the standard normal.
const Z95: f64 = 1.959_963_984_540_054;

/// A line `intercept + slope × i` over the points `i = 0, 1, …` of a run.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Line {
    /// The value at the run's first point.
    pub intercept: f64,
    /// The change per point.
    pub slope: f64,
}

impl Line {
    /// The line's value at position `i` of the run (fractional positions allowed).
    pub fn at(&self, i: f64) -> f64 {
        self.intercept + self.slope * i
    }
}

/// A Theil–Sen fit with the 95% interval of its slope.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Fit {
    /// The line: the median of the pairwise slopes, through the median of the residuals.
    pub line: Line,
    /// Sen's (1968) distribution-free 95% interval of the slope, from the ranks of the
    /// pairwise slopes (Kendall's τ's variance): it holds for any continuous noise that is
    /// independent from point to point.
    pub slope_ci95: [f64; 2],
}

/// The sum of absolute deviations of `x` from a quick robust line, in linear time: the slope is
/// the median of the slopes between the points half a run apart (disjoint pairs: each point in
/// at most one), the intercept the median of what remains. `scratch` is reused between calls.
/// Not the least-absolute-deviations line, so the cost is an upper bound of that line's: a
/// sloped fit is never cheaper than it should be. `None` below 4 points.
pub fn quick_l1_cost(x: &[f64], scratch: &mut Vec<f64>) -> Option<f64> {
    let line = quick_line(x, scratch)?;
    Some(
        x.iter()
            .enumerate()
            .map(|(i, v)| (v - line.at(i as f64)).abs())
            .sum(),
    )
}

/// The quick line of [`quick_l1_cost`].
pub fn quick_line(x: &[f64], scratch: &mut Vec<f64>) -> Option<Line> {
    let m = x.len();
    if m < 4 {
        return None;
    }
    let h = m.div_ceil(2);
    scratch.clear();
    scratch.extend((0..m - h).map(|i| (x[i + h] - x[i]) / h as f64));
    let slope = median_in_place(scratch);
    scratch.clear();
    scratch.extend(x.iter().enumerate().map(|(i, v)| v - slope * i as f64));
    let intercept = median_in_place(scratch);
    Some(Line { intercept, slope })
}

/// The Theil–Sen fit of `x` with Sen's interval; `None` below 3 points. Quadratic in the
/// points: for the drifts reported, not for every candidate segment.
pub fn theil_sen(x: &[f64]) -> Option<Fit> {
    let m = x.len();
    if m < 3 {
        return None;
    }
    let mut slopes = Vec::with_capacity(m * (m - 1) / 2);
    for i in 0..m {
        for j in i + 1..m {
            slopes.push((x[j] - x[i]) / (j - i) as f64);
        }
    }
    slopes.sort_by(f64::total_cmp);
    let slope = median_sorted(&slopes);
    let mut rest: Vec<f64> = x
        .iter()
        .enumerate()
        .map(|(i, v)| v - slope * i as f64)
        .collect();
    let intercept = median_in_place(&mut rest);
    // Ranks (1-based) (N - C)/2 and (N + C)/2 + 1 of the N sorted slopes, C = z √Var(S) with
    // Var(S) = m(m-1)(2m+5)/18 (Hollander & Wolfe, Nonparametric Statistical Methods, §9.4).
    let n = slopes.len() as f64;
    let mf = m as f64;
    let c = Z95 * (mf * (mf - 1.0) * (2.0 * mf + 5.0) / 18.0).sqrt();
    let rank = |r: f64| slopes[(r.round().max(1.0) as usize).min(slopes.len()) - 1];
    Some(Fit {
        line: Line { intercept, slope },
        slope_ci95: [rank((n - c) / 2.0), rank((n + c) / 2.0 + 1.0)],
    })
}

/// The median of a non-empty slice, reordering it.
fn median_in_place(v: &mut [f64]) -> f64 {
    let odd = v.len() % 2 == 1;
    let (below, upper, _) = v.select_nth_unstable_by(v.len() / 2, f64::total_cmp);
    if odd {
        *upper
    } else {
        0.5 * (below.iter().copied().fold(f64::NEG_INFINITY, f64::max) + *upper)
    }
}

fn median_sorted(v: &[f64]) -> f64 {
    let mid = v.len() / 2;
    if v.len() % 2 == 1 {
        v[mid]
    } else {
        0.5 * (v[mid - 1] + v[mid])
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};
    use rand_distr::StandardNormal;
    use rand_pcg::Pcg64Mcg;

    fn ramp(seed: u64, m: usize, slope: f64, sigma: f64) -> Vec<f64> {
        let mut rng = Pcg64Mcg::seed_from_u64(seed);
        (0..m)
            .map(|i| {
                let z: f64 = rng.sample(StandardNormal);
                0.5 + slope * i as f64 + sigma * z
            })
            .collect()
    }

    #[test]
    fn an_exact_line_is_fitted_exactly_by_both() {
        let x: Vec<f64> = (0..11).map(|i| 2.0 - 0.25 * i as f64).collect();
        let quick = quick_line(&x, &mut Vec::new()).unwrap();
        assert!((quick.slope + 0.25).abs() < 1e-12 && (quick.intercept - 2.0).abs() < 1e-12);
        assert!(quick_l1_cost(&x, &mut Vec::new()).unwrap() < 1e-9);
        let ts = theil_sen(&x).unwrap();
        assert!((ts.line.slope + 0.25).abs() < 1e-12);
        assert!((ts.line.at(10.0) - -0.5).abs() < 1e-12);
        assert!(quick_line(&x[..3], &mut Vec::new()).is_none());
        assert!(theil_sen(&x[..2]).is_none());
    }

    /// Sen's interval covers the true slope about 95% of the time, on noise it was made for.
    #[test]
    fn sens_interval_covers_the_true_slope_about_95_percent_of_the_time() {
        let slope = 0.002;
        let covered = (0..400)
            .filter(|&seed| {
                let f = theil_sen(&ramp(seed, 40, slope, 0.01)).unwrap();
                f.slope_ci95[0] <= slope && slope <= f.slope_ci95[1]
            })
            .count();
        // Binomial(400, 0.95): 380 ± 4.4; 360..=395 is beyond ±4 standard deviations.
        assert!((360..=395).contains(&covered), "{covered} of 400");
    }

    /// A spike barely moves either fit, where it would tilt a least-squares line.
    #[test]
    fn a_spike_at_the_end_does_not_tilt_the_fits() {
        let mut x = ramp(3, 40, 0.002, 0.01);
        x[39] += 0.7;
        let quick = quick_line(&x, &mut Vec::new()).unwrap();
        let ts = theil_sen(&x).unwrap();
        for slope in [quick.slope, ts.line.slope] {
            assert!((slope - 0.002).abs() < 0.0008, "{slope}");
        }
    }
}
