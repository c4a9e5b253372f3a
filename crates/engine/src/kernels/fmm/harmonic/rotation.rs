//! Rotations of expansions: Wigner's small-d matrices `d^n_{m'm}(β)` of every degree up to p by
//! a three-term recurrence in the degree (from the closed form at the first degree where an
//! entry exists), and the rotation of a degree's coefficients by them.
//!
//! A translation along an arbitrary direction `t` costs O(p⁴) or more; rotated so that `t`
//! points along +z it costs O(p³), as only the order-0 harmonics are non-zero on the z-axis,
//! and so does each rotation (a `(2n+1)²` matrix per degree): the "point and shoot" of White &
//! Head-Gordon (1996) and Gumerov & Duraiswami (2005). The rotation taking `t` to +z is a turn
//! by `−φ` about z and `−θ` about y, `(θ, φ)` being `t`'s spherical angles.
//!
//! The recurrence (`c = cos β`; Edmonds, 1957, from the coupling of degree n−1 with degree 1)
//!
//! `d^n = n(2n−1)/√((n²−m²)(n²−m'²)) (c − m m'/(n(n−1))) d^{n−1}
//!      − n √(((n−1)²−m²)((n−1)²−m'²)) / ((n−1) √((n²−m²)(n²−m'²))) d^{n−2}`
//!
//! starts at `n₀ = max(|m|, |m'|)` from `d^{n₀}_{±n₀, m} = √C(2n₀, n₀ ± m) cos(β/2)^{n₀ ± m}
//! (∓ sin(β/2))^{n₀ ∓ m}` (by symmetry when |m| is the larger), so no entry is a difference of
//! large terms and none divides by sin β: directions along ±z, frequent in an octree, are as
//! exact as any.

use super::solid::{C, sign};

/// The small-d matrices of one angle, degrees `0..=p`.
pub struct Wigner {
    p: usize,
    /// Degree n's matrix at `start[n]`, row `m' + n`, column `m + n`.
    start: Vec<usize>,
    d: Vec<f64>,
    /// Per entry of `d` past its first degree, the recurrence's `(α, β, γ)` with
    /// `d^n = (α c + β) d^{n−1} − γ d^{n−2}`: they depend on the degree and orders only, so a
    /// new angle costs three multiply-adds per entry.
    steps: Vec<[f64; 3]>,
    /// `√C(2n, n + m)` at `n (2p + 1) + m + p`.
    binom: Vec<f64>,
    /// `cos(β/2)^k` and `sin(β/2)^k` for k = 0..=2p of the angle computed.
    powers: [Vec<f64>; 2],
}

impl Wigner {
    /// Room for degrees up to `p`, and the recurrence's coefficients.
    pub fn new(p: usize) -> Self {
        let mut start = Vec::with_capacity(p + 2);
        let mut at = 0;
        for n in 0..=p {
            start.push(at);
            at += (2 * n + 1) * (2 * n + 1);
        }
        start.push(at);
        let binom = binomials(p);
        let mut wigner = Wigner {
            p,
            start,
            d: vec![0.0; at],
            steps: vec![[0.0; 3]; at],
            binom,
            powers: std::array::from_fn(|_| vec![0.0; 2 * p + 1]),
        };
        let pi = p as isize;
        for mp in -pi..=pi {
            for m in -pi..=pi {
                let n0 = mp.unsigned_abs().max(m.unsigned_abs());
                for n in n0 + 1..=p {
                    let i = wigner.index(n, mp, m);
                    wigner.steps[i] = step(n, mp, m);
                }
            }
        }
        wigner
    }

    #[inline(always)]
    fn index(&self, n: usize, mp: isize, m: isize) -> usize {
        let w = 2 * n + 1;
        let row = (mp + n as isize) as usize;
        let col = (m + n as isize) as usize;
        self.start[n] + row * w + col
    }

    /// `d^n_{m'm}` (any m', by symmetry from the rows computed), for the tests; the rotations
    /// read the rows whole.
    #[cfg(test)]
    pub fn get(&self, n: usize, mp: isize, m: isize) -> f64 {
        if mp >= 0 {
            self.d[self.index(n, mp, m)]
        } else if m <= 0 {
            // d_{m'm} = d_{−m,−m'}.
            self.d[self.index(n, -m, -mp)]
        } else {
            // d_{m'm} = (−1)^{m−m'} d_{mm'}.
            sign((m - mp).unsigned_abs()) * self.d[self.index(n, m, mp)]
        }
    }

    /// The matrices for the angle β with `cos β = c` and `sin β = s ≥ 0` (β in [0, π]).
    pub fn compute(&mut self, c: f64, s: f64) {
        let p = self.p as isize;
        let (half_c, half_s) = half_angles(c, s);
        for (k, base) in [half_c, half_s].into_iter().enumerate() {
            let pw = &mut self.powers[k];
            pw[0] = 1.0;
            for j in 1..pw.len() {
                pw[j] = pw[j - 1] * base;
            }
        }
        // The rows m' ≥ 0 only: `apply` reads the others through d_{mm'} = (−1)^{m−m'} d_{m'm}.
        for mp in 0..=p {
            for m in -p..=p {
                let n0 = mp.unsigned_abs().max(m.unsigned_abs());
                let first = self.edge(n0, mp, m);
                let i = self.index(n0, mp, m);
                self.d[i] = first;
                let (mut older, mut old) = (0.0, first);
                for n in n0 + 1..=self.p {
                    let i = self.index(n, mp, m);
                    let [a, b, g] = self.steps[i];
                    let next = (a * c + b) * old - g * older;
                    self.d[i] = next;
                    older = old;
                    old = next;
                }
            }
        }
    }

    /// `d^{n}_{m'm}` at `n = max(|m|, |m'|)`, in closed form from the angle's powers.
    fn edge(&self, n: usize, mp: isize, m: isize) -> f64 {
        let (coef, cos_power, sin_power) = edge_form(&self.binom, self.p, n, mp, m);
        let [cos, sin] = &self.powers;
        coef * cos[cos_power] * sin[sin_power]
    }
}

/// `√C(2n, n + m)` at `n (2p + 1) + m + p`, for n ≤ p.
pub(super) fn binomials(p: usize) -> Vec<f64> {
    let mut ln_fact = vec![0.0; 2 * p + 2];
    for k in 1..ln_fact.len() {
        ln_fact[k] = ln_fact[k - 1] + (k as f64).ln();
    }
    let w = 2 * p + 1;
    let mut binom = vec![0.0; (p + 1) * w];
    for n in 0..=p {
        for m in 0..=2 * n {
            // m here is n + (the order).
            binom[n * w + m + p - n] =
                (0.5 * (ln_fact[2 * n] - ln_fact[m] - ln_fact[2 * n - m])).exp();
        }
    }
    binom
}

/// `cos(β/2)` and `sin(β/2)` from `cos β = c` and `sin β = s ≥ 0`, without cancellation near
/// either end.
#[inline(always)]
pub(super) fn half_angles(c: f64, s: f64) -> (f64, f64) {
    let half_c = ((1.0 + c) / 2.0).max(0.0).sqrt();
    let half_s = if half_c > 0.5 {
        s / (2.0 * half_c)
    } else {
        ((1.0 - c) / 2.0).max(0.0).sqrt()
    };
    (half_c, half_s)
}

/// The recurrence's `(α, β, γ)` of `d^n_{m'm}` from the degrees below, `n > max(|m|, |m'|)`.
pub(super) fn step(n: usize, mp: isize, m: isize) -> [f64; 3] {
    if n == 1 {
        // n0 = 0: m = m' = 0, d^1_00 = cos β.
        return [1.0, 0.0, 0.0];
    }
    let nf = n as f64;
    let (mf, mpf) = (m as f64, mp as f64);
    let norm = ((nf * nf - mf * mf) * (nf * nf - mpf * mpf)).sqrt();
    let n1 = nf - 1.0;
    let a = nf * (2.0 * nf - 1.0) / norm;
    let b = nf * ((n1 * n1 - mf * mf) * (n1 * n1 - mpf * mpf)).sqrt() / (n1 * norm);
    [a, -a * mf * mpf / (nf * n1), b]
}

/// `d^n_{m'm}` at `n = max(|m|, |m'|)` as `coef · cos(β/2)^a · sin(β/2)^b`: `(coef, a, b)`,
/// with `binom` the table of [`Wigner`] for order `p`.
pub(super) fn edge_form(
    binom: &[f64],
    p: usize,
    n: usize,
    mp: isize,
    m: isize,
) -> (f64, usize, usize) {
    if mp.unsigned_abs() < m.unsigned_abs() {
        // d_{m'm} = (−1)^{m−m'} d_{mm'}.
        let (coef, a, b) = edge_form(binom, p, n, m, mp);
        return (sign((m - mp).unsigned_abs()) * coef, a, b);
    }
    let nf = n as isize;
    let (plus, minus) = ((nf + m) as usize, (nf - m) as usize);
    let coef = binom[n * (2 * p + 1) + (m + p as isize) as usize];
    if mp >= 0 {
        // cos^{n+m} (−sin)^{n−m}.
        (coef * sign(minus), plus, minus)
    } else {
        (coef, minus, plus)
    }
}

/// Rotates the coefficients `a_m` of one degree n by `d`: `out[m'] = Σ_{m=−n}^{n} d^n_{m'm} a_m`
/// (`transpose`: `d^n_{mm'}`) for m' = 0..=n, from `a[0..=n]` alone, the orders `m ≥ 0`: the
/// rest are `a_{−m} = (−1)^m conj(a_m)`, as in every expansion of a real field, so each pair
/// `±m` takes one complex multiply-add by two real coefficients.
pub fn apply(w: &Wigner, n: usize, a: &[C], transpose: bool, out: &mut [C]) {
    let width = 2 * n + 1;
    let mat = &w.d[w.start[n]..w.start[n + 1]];
    for mp in 0..=n {
        // Row m' holds d^n_{m'm} at n + m; the transpose reads d^n_{mm'} = (−1)^{m'−m} d^n_{m'm}
        // (the same parity for ±m).
        let row = &mat[(mp + n) * width..(mp + n + 1) * width];
        let flip = |m: usize| {
            if transpose && (mp + m) % 2 == 1 {
                -1.0
            } else {
                1.0
            }
        };
        let mut sum = a[0].scale(row[n] * flip(0));
        for (m, am) in a.iter().enumerate().take(n + 1).skip(1) {
            let t = flip(m);
            let (plus, minus) = (t * row[n + m], t * sign(m) * row[n - m]);
            sum.re += (plus + minus) * am.re;
            sum.im += (plus - minus) * am.im;
        }
        out[mp] = sum;
    }
}
