//! Linear least squares over basis functions, goodness of fit, and leave-one-out
//! cross-validation on SMAPE (the model-selection criterion Extra-P uses).
//!
//! Times at different x often differ by orders of magnitude and their noise is roughly
//! proportional to them, so the time models are fitted on relative residuals: weight 1/y².

use serde::Serialize;

/// A basis function of x; a model is `Σ_j β_j · basis_j(x)`.
pub(crate) type Basis<'a> = &'a dyn Fn(f64) -> f64;

/// Weighted least squares: minimises `Σ w_i (y_i − Σ_j β_j basis_j(x_i))²`. `None` when the
/// problem is singular or has fewer points than parameters.
pub(crate) fn fit(basis: &[Basis], xs: &[f64], ys: &[f64], ws: &[f64]) -> Option<Vec<f64>> {
    let k = basis.len();
    if xs.len() < k {
        return None;
    }
    // Normal equations, equilibrated by the column norms; k is at most 3 here and the columns
    // are rescaled, so the squared condition number stays harmless.
    let mut normal = vec![vec![0.0; k]; k];
    let mut rhs = vec![0.0; k];
    let mut row = vec![0.0; k];
    for i in 0..xs.len() {
        for (j, b) in basis.iter().enumerate() {
            row[j] = b(xs[i]);
        }
        for a in 0..k {
            rhs[a] += ws[i] * row[a] * ys[i];
            for b in 0..k {
                normal[a][b] += ws[i] * row[a] * row[b];
            }
        }
    }
    let scale: Vec<f64> = (0..k).map(|j| normal[j][j].sqrt()).collect();
    if scale.iter().any(|&s| !(s > 0.0 && s.is_finite())) {
        return None;
    }
    for a in 0..k {
        rhs[a] /= scale[a];
        for b in 0..k {
            normal[a][b] /= scale[a] * scale[b];
        }
    }
    let beta = solve(normal, rhs)?;
    let beta: Vec<f64> = beta.iter().zip(&scale).map(|(b, s)| b / s).collect();
    beta.iter().all(|b| b.is_finite()).then_some(beta)
}

/// Gaussian elimination with partial pivoting on a small, equilibrated system.
fn solve(mut a: Vec<Vec<f64>>, mut b: Vec<f64>) -> Option<Vec<f64>> {
    let k = b.len();
    for col in 0..k {
        let pivot = (col..k).max_by(|&i, &j| a[i][col].abs().total_cmp(&a[j][col].abs()))?;
        if a[pivot][col].abs() < 1e-12 {
            return None;
        }
        a.swap(col, pivot);
        b.swap(col, pivot);
        for r in col + 1..k {
            let factor = a[r][col] / a[col][col];
            for c in col..k {
                a[r][c] -= factor * a[col][c];
            }
            b[r] -= factor * b[col];
        }
    }
    let mut x = vec![0.0; k];
    for r in (0..k).rev() {
        let tail: f64 = (r + 1..k).map(|c| a[r][c] * x[c]).sum();
        x[r] = (b[r] - tail) / a[r][r];
    }
    Some(x)
}

/// The model's value at x.
pub(crate) fn eval(basis: &[Basis], beta: &[f64], x: f64) -> f64 {
    basis.iter().zip(beta).map(|(b, c)| c * b(x)).sum()
}

/// Weights that make least squares minimise relative residuals.
pub(crate) fn relative_weights(ys: &[f64]) -> Vec<f64> {
    ys.iter().map(|y| 1.0 / (y * y)).collect()
}

/// [`fit`] on relative residuals.
pub(crate) fn fit_relative(basis: &[Basis], xs: &[f64], ys: &[f64]) -> Option<Vec<f64>> {
    fit(basis, xs, ys, &relative_weights(ys))
}

/// Symmetric mean absolute percentage error, in percent (0 to 200).
pub(crate) fn smape(observed: &[f64], predicted: &[f64]) -> f64 {
    let terms = observed.iter().zip(predicted).map(|(&o, &p)| {
        let denom = o.abs() + p.abs();
        if denom == 0.0 {
            0.0
        } else {
            2.0 * (p - o).abs() / denom
        }
    });
    100.0 * terms.sum::<f64>() / observed.len().max(1) as f64
}

/// Leave-one-out cross-validated SMAPE (percent) of a relative-residual fit: every point is
/// predicted by the model fitted to the others. `None` when there are too few points to leave
/// one out or a fold is singular.
pub(crate) fn loo_smape(basis: &[Basis], xs: &[f64], ys: &[f64]) -> Option<f64> {
    let m = xs.len();
    if m < basis.len() + 1 {
        return None;
    }
    let mut predicted = vec![0.0; m];
    let (mut tx, mut ty) = (Vec::with_capacity(m), Vec::with_capacity(m));
    for out in 0..m {
        tx.clear();
        ty.clear();
        for i in (0..m).filter(|&i| i != out) {
            tx.push(xs[i]);
            ty.push(ys[i]);
        }
        let beta = fit_relative(basis, &tx, &ty)?;
        predicted[out] = eval(basis, &beta, xs[out]);
    }
    Some(smape(ys, &predicted))
}

/// How well a fitted curve matches the medians it was fitted to.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Goodness {
    /// Coefficient of determination with the fit's own weights (relative residuals for time
    /// models, log space for the free power law); `None` when the data have no variance.
    pub r2: Option<f64>,
    /// In-sample symmetric mean absolute percentage error of the medians, in percent.
    pub smape_percent: f64,
}

impl Goodness {
    pub(crate) fn of(observed: &[f64], predicted: &[f64], weights: &[f64]) -> Goodness {
        Goodness {
            r2: r2(observed, predicted, weights),
            smape_percent: smape(observed, predicted),
        }
    }
}

/// Weighted coefficient of determination.
pub(crate) fn r2(observed: &[f64], predicted: &[f64], weights: &[f64]) -> Option<f64> {
    let wsum: f64 = weights.iter().sum();
    let mean = observed
        .iter()
        .zip(weights)
        .map(|(y, w)| y * w)
        .sum::<f64>()
        / wsum;
    let total: f64 = observed
        .iter()
        .zip(weights)
        .map(|(y, w)| w * (y - mean).powi(2))
        .sum();
    let residual: f64 = (0..observed.len())
        .map(|i| weights[i] * (observed[i] - predicted[i]).powi(2))
        .sum();
    (total > 1e-300 * wsum).then(|| 1.0 - residual / total)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn recovers_an_exact_line_and_a_three_term_model() {
        let one = |_: f64| 1.0;
        let inv = |p: f64| 1.0 / p;
        let lin = |p: f64| p;
        let xs = [1.0, 2.0, 4.0, 8.0, 16.0];
        let ys: Vec<f64> = xs.iter().map(|p| 0.2 + 0.8 / p + 0.01 * p).collect();
        let basis: [Basis; 3] = [&one, &inv, &lin];
        let beta = fit_relative(&basis, &xs, &ys).unwrap();
        for (b, want) in beta.iter().zip([0.2, 0.8, 0.01]) {
            assert!((b - want).abs() < 1e-10, "{beta:?}");
        }
        assert!(loo_smape(&basis, &xs, &ys).unwrap() < 1e-6);
        let g = Goodness::of(&ys, &ys, &relative_weights(&ys));
        assert_eq!(g.smape_percent, 0.0);
        assert!((g.r2.unwrap() - 1.0).abs() < 1e-12);
        // Bytes in the millions next to a constant column: equilibration keeps it solvable.
        let bytes = [0.0, 1e3, 1e6, 1e9];
        let t: Vec<f64> = bytes.iter().map(|b| 2e-6 + 1e-10 * b).collect();
        let beta = fit_relative(&[&one, &lin], &bytes, &t).unwrap();
        assert!((beta[0] / 2e-6 - 1.0).abs() < 1e-9 && (beta[1] / 1e-10 - 1.0).abs() < 1e-9);
    }

    #[test]
    fn singular_and_short_problems_are_refused() {
        let one = |_: f64| 1.0;
        let also_one = |_: f64| 2.0;
        let xs = [1.0, 2.0, 3.0];
        let ys = [1.0, 2.0, 3.0];
        assert!(fit_relative(&[&one, &also_one], &xs, &ys).is_none());
        assert!(fit_relative(&[&one, &|x| x], &xs[..1], &ys[..1]).is_none());
        assert!(loo_smape(&[&one, &|x| x], &xs[..2], &ys[..2]).is_none());
        assert_eq!(r2(&[1.0, 1.0], &[1.0, 1.0], &[1.0, 1.0]), None);
    }

    #[test]
    fn smape_is_symmetric_and_bounded() {
        assert_eq!(smape(&[1.0], &[3.0]), smape(&[3.0], &[1.0]));
        assert_eq!(smape(&[1.0], &[3.0]), 100.0);
        assert_eq!(smape(&[1.0], &[-1.0]), 200.0);
    }
}
