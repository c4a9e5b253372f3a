//! Complex numbers and the solid harmonics of the expansions, for `0 ≤ m ≤ n ≤ p`.
//!
//! With `P_n^m` the associated Legendre functions with the Condon–Shortley phase, in spherical
//! coordinates `(r, θ, φ)`:
//!
//! - regular `R_n^m(x) = r^n P_n^m(cos θ) e^{imφ} / (n+m)!`,
//! - irregular `S_n^m(x) = (n−m)! P_n^m(cos θ) e^{imφ} / r^{n+1}`,
//!
//! and for negative orders `R_n^{−m} = (−1)^m conj(R_n^m)`, the same for `S`. With these
//! scalings the translation theorems carry no factors (Epton & Dembart 1995; Dehnen 2014):
//! `R_n^m(a + b) = Σ_{k,l} R_k^l(a) R_{n−k}^{m−l}(b)`, `1/|x − y| = Σ_{n,m} conj(R_n^m(y))
//! S_n^m(x)` for `|y| < |x|`, and `S_n^m(a + b) = Σ_{k,l} (−1)^k conj(R_k^l(b)) S_{n+k}^{m+l}(a)`
//! for `|b| < |a|`. Both are computed by the Legendre recurrences in Cartesian form, with no
//! trigonometric function and no division by a factorial.

use std::ops::{Add, AddAssign, Mul, Neg, Sub};

/// A complex number, laid out as two f64 (real part first), so that a cell's coefficients
/// can live in the kernel's f64 arrays ([`complex`], [`complex_mut`]).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[repr(C)]
pub struct C {
    pub re: f64,
    pub im: f64,
}

impl C {
    pub const ZERO: C = C { re: 0.0, im: 0.0 };
    pub const ONE: C = C { re: 1.0, im: 0.0 };

    #[inline(always)]
    pub const fn new(re: f64, im: f64) -> C {
        C { re, im }
    }

    #[inline(always)]
    pub fn conj(self) -> C {
        C::new(self.re, -self.im)
    }

    #[inline(always)]
    pub fn scale(self, s: f64) -> C {
        C::new(self.re * s, self.im * s)
    }

    #[cfg(test)]
    pub fn abs(self) -> f64 {
        self.re.hypot(self.im)
    }
}

impl Add for C {
    type Output = C;
    #[inline(always)]
    fn add(self, o: C) -> C {
        C::new(self.re + o.re, self.im + o.im)
    }
}

impl AddAssign for C {
    #[inline(always)]
    fn add_assign(&mut self, o: C) {
        self.re += o.re;
        self.im += o.im;
    }
}

impl Sub for C {
    type Output = C;
    #[inline(always)]
    fn sub(self, o: C) -> C {
        C::new(self.re - o.re, self.im - o.im)
    }
}

impl Neg for C {
    type Output = C;
    #[inline(always)]
    fn neg(self) -> C {
        C::new(-self.re, -self.im)
    }
}

impl Mul for C {
    type Output = C;
    #[inline(always)]
    fn mul(self, o: C) -> C {
        C::new(
            self.re * o.re - self.im * o.im,
            self.re * o.im + self.im * o.re,
        )
    }
}

/// Index of `(n, m)`, `0 ≤ m ≤ n`, in a triangle of coefficients: `n(n+1)/2 + m`.
#[inline(always)]
pub const fn at(n: usize, m: usize) -> usize {
    n * (n + 1) / 2 + m
}

/// Coefficients `(n, m)` with `0 ≤ m ≤ n ≤ p`.
pub const fn count(p: usize) -> usize {
    (p + 1) * (p + 2) / 2
}

/// `(−1)^k`.
#[inline(always)]
pub fn sign(k: usize) -> f64 {
    if k.is_multiple_of(2) { 1.0 } else { -1.0 }
}

/// The value of order `m` of a triangle holding the orders `≥ 0`: `(−1)^m conj` of the entry
/// for negative `m`.
#[inline(always)]
pub fn signed(t: &[C], n: usize, m: isize) -> C {
    if m >= 0 {
        t[at(n, m as usize)]
    } else {
        let k = m.unsigned_abs();
        t[at(n, k)].conj().scale(sign(k))
    }
}

/// `R_n^m(x)` for `0 ≤ m ≤ n ≤ p` into `out` (`count(p)` entries).
pub fn regular(x: [f64; 3], p: usize, out: &mut [C]) {
    let r2 = x[0] * x[0] + x[1] * x[1] + x[2] * x[2];
    let xy = C::new(x[0], x[1]);
    let mut diag = C::ONE;
    for m in 0..=p {
        if m > 0 {
            diag = (diag * xy).scale(-1.0 / (2 * m) as f64);
        }
        out[at(m, m)] = diag;
        let mut prev = C::ZERO;
        let mut cur = diag;
        for n in m + 1..=p {
            let next = (cur.scale((2 * n - 1) as f64 * x[2]) - prev.scale(r2))
                .scale(1.0 / ((n + m) * (n - m)) as f64);
            out[at(n, m)] = next;
            prev = cur;
            cur = next;
        }
    }
}

/// `S_n^m(x)` for `0 ≤ m ≤ n ≤ p` into `out` (`count(p)` entries); `x ≠ 0`. (The M2L needs
/// them on the z-axis only, where they are `n!/ρ^{n+1}`: the tests check the theorems.)
#[cfg(test)]
pub fn irregular(x: [f64; 3], p: usize, out: &mut [C]) {
    let r2 = x[0] * x[0] + x[1] * x[1] + x[2] * x[2];
    let inv2 = 1.0 / r2;
    let xy = C::new(x[0], x[1]);
    let mut diag = C::new(inv2.sqrt(), 0.0);
    for m in 0..=p {
        if m > 0 {
            diag = (diag * xy).scale(-((2 * m - 1) as f64) * inv2);
        }
        out[at(m, m)] = diag;
        let mut prev = C::ZERO;
        let mut cur = diag;
        for n in m + 1..=p {
            let back = if n >= m + 2 {
                ((n + m - 1) * (n - m - 1)) as f64
            } else {
                0.0
            };
            let next = (cur.scale((2 * n - 1) as f64 * x[2]) - prev.scale(back)).scale(inv2);
            out[at(n, m)] = next;
            prev = cur;
            cur = next;
        }
    }
}

/// `values` (of even length) as complex numbers, real parts first.
pub fn complex(values: &[f64]) -> &[C] {
    assert!(values.len().is_multiple_of(2), "an odd number of parts");
    // SAFETY: `C` is `repr(C)` of two f64, so it has f64's alignment and twice its size; the
    // length is even, and the borrow is carried over.
    unsafe { std::slice::from_raw_parts(values.as_ptr().cast::<C>(), values.len() / 2) }
}

/// `values` (of even length) as complex numbers, mutably.
pub fn complex_mut(values: &mut [f64]) -> &mut [C] {
    assert!(values.len().is_multiple_of(2), "an odd number of parts");
    // SAFETY: as in `complex`, with the exclusive borrow carried over.
    unsafe { std::slice::from_raw_parts_mut(values.as_mut_ptr().cast::<C>(), values.len() / 2) }
}
