//! Cartesian multipole and local (Taylor) expansions of order p in 3-D, after Dehnen (falcON,
//! 2000; "A fast multipole method for stellar dynamics", 2014), all in f64.
//!
//! Coefficients are indexed by multi-indices `n = (a, b, c)` with `|n| = a + b + c ≤ p`, in
//! graded order: index 0 is `(0,0,0)`, 1..=3 are the unit vectors, then the six of order 2,
//! and so on, `(p+1)(p+2)(p+3)/6` in all. With `v^n = vx^a vy^b vz^c` and `n! = a! b! c!`:
//!
//! - a cell's multipole about its centre z is `M_n = Σ s_b w_b^n / n!` with `w_b = z − x_b`
//!   (the reflected offsets: then the potential of the cell at `z + R` is `Σ_n M_n ∂^n G(R)`
//!   with no signs to track);
//! - a cell's local expansion about its centre is `L_m = ∂^m ψ(z)`, the Taylor coefficients of
//!   the far field ψ, so that `ψ(z + r) = Σ_m L_m r^m / m!`;
//! - M2L from cell B onto cell A, `R = z_A − z_B`: `L_A[m] += Σ_{|n| ≤ p − |m|} M_B[n] T[n + m]`
//!   with `T[k] = ∂^k G(R)`, and the reaction onto B is the same at −R, where
//!   `T[k](−R) = (−1)^{|k|} T[k](R)`. The kernel computes the tensor twice, once in each cell's
//!   list of partners (its own R, the same bits up to sign): each cell sums its own list, so
//!   the results do not depend on the thread count, at twice the tensor work of one tensor per
//!   pair updating both cells. Truncating at `|n| + |m| ≤ p` makes the force of A on B the
//!   exact opposite of the force of B on A (Dehnen 2000), so momentum is conserved to
//!   rounding whatever the centres.
//!
//! The Green's function is the law's: `G(x) = g(|x|²)` with `g = κ (r² + ε²)^{-1/2}`, κ and
//! the sign convention taken from the law's own coefficient (see [`scaled_derivatives`]). Its
//! derivative tensors follow from the scalars `D_j = (d/du)^j g` with `u = r²/2`:
//! `∂^n G(x) = Σ_{i,j,l} C(a,i) C(b,j) C(c,l) x^{a−2i} y^{b−2j} z^{c−2l} D_{|n|−i−j−l}` with
//! `C(a,i) = a! / (2^i i! (a−2i)!)`, which handles Plummer softening exactly.

use crate::simd::LANES;

/// One value per SIMD lane.
pub(crate) type Lanes = [f64; LANES];

/// The rows of one M2L batch, `LANES` partner cells in the lanes; reused across batches.
pub(crate) struct Batch {
    /// The separations `z_A − z_B`, per dimension.
    pub r: [Lanes; 3],
    /// The scalar derivatives `κ D_j`, j = 0..=p (see [`scaled_derivatives`]).
    pub dj: Vec<Lanes>,
    /// The partners' multipoles, `len` rows.
    pub mb: Vec<Lanes>,
    /// The local expansion being summed, `len` rows.
    pub la: Vec<Lanes>,
    /// Scratch of `len` rows: the monomials and the derivative tensor.
    pub mono: Vec<Lanes>,
    pub t: Vec<Lanes>,
}

impl Batch {
    /// Zeroed rows for expansions of `len` coefficients.
    pub(crate) fn new(len: usize) -> Self {
        let rows = || vec![[0.0; LANES]; len];
        Batch {
            r: [[0.0; LANES]; 3],
            dj: vec![[0.0; LANES]; MAX_ORDER + 1],
            mb: rows(),
            la: rows(),
            mono: rows(),
            t: rows(),
        }
    }
}

/// Highest supported expansion order.
pub const MAX_ORDER: usize = 8;

/// Number of coefficients of an expansion of order `p`: the multi-indices with `|n| ≤ p`.
pub const fn terms(p: usize) -> usize {
    (p + 1) * (p + 2) * (p + 3) / 6
}

/// The index tables of one order, built once per kernel.
pub struct Expansion {
    pub p: usize,
    /// `terms(p)`.
    pub len: usize,
    /// For every index past 0: the index of `n − e_d`, the dimension `d` and `1/n_d`, so that
    /// `v^n/n! = (v^{n−e_d}/(n−e_d)!) · v_d / n_d`.
    pub(super) step: Vec<(usize, usize, f64)>,
    /// `add[m · len + k]` = index of `m + k`, for `|k| ≤ p − |m|`: the first `row_len[m] =
    /// terms(p − |m|)` indices k, as the order is graded.
    pub(super) add: Vec<u16>,
    pub(super) row_len: Vec<usize>,
    /// Derivative terms of every index (CSR by `deriv_start`): `(coefficient, monomial index,
    /// j)`, the coefficient `Π a!/(2^i i!)` including the factorial of the scaled monomial.
    pub(super) deriv_start: Vec<usize>,
    pub(super) deriv: Vec<(f64, u16, u8)>,
    /// For every index n, the pairs `(k, n − k)` with `k ≤ n` componentwise (M2M).
    conv_start: Vec<usize>,
    conv: Vec<(u16, u16)>,
}

impl Expansion {
    /// Tables for order `p` (1 ≤ p ≤ [`MAX_ORDER`]).
    pub fn new(p: usize) -> Self {
        assert!(
            (1..=MAX_ORDER).contains(&p),
            "expansion order {p} out of range"
        );
        let len = terms(p);
        let mut index = Vec::with_capacity(len);
        for k in 0..=p {
            for a in (0..=k).rev() {
                for b in (0..=k - a).rev() {
                    index.push([a, b, k - a - b]);
                }
            }
        }
        let cube = |n: [usize; 3]| (n[0] * (p + 1) + n[1]) * (p + 1) + n[2];
        let mut lookup = vec![u16::MAX; (p + 1).pow(3)];
        for (i, &n) in index.iter().enumerate() {
            lookup[cube(n)] = i as u16;
        }
        let at = |n: [usize; 3]| lookup[cube(n)] as usize;
        let order = |n: [usize; 3]| n[0] + n[1] + n[2];

        let mut step = vec![(0, 0, 1.0); len];
        for (i, &n) in index.iter().enumerate().skip(1) {
            let d = (0..3).find(|&d| n[d] > 0).expect("not the zero index");
            let mut parent = n;
            parent[d] -= 1;
            step[i] = (at(parent), d, 1.0 / n[d] as f64);
        }

        let mut add = vec![0u16; len * len];
        for (m, &nm) in index.iter().enumerate() {
            for (k, &nk) in index.iter().enumerate() {
                if order(nm) + order(nk) <= p {
                    add[m * len + k] = at([nm[0] + nk[0], nm[1] + nk[1], nm[2] + nk[2]]) as u16;
                }
            }
        }

        let row_len = index.iter().map(|&n| terms(p - order(n))).collect();

        let fact = |k: usize| (1..=k).map(|x| x as f64).product::<f64>();
        // a!/(2^i i!): C(a, i) times the (a − 2i)! that the scaled monomial divides by.
        let coeff = |a: usize, i: usize| fact(a) / (2f64.powi(i as i32) * fact(i));
        let mut deriv_start = vec![0];
        let mut deriv = Vec::new();
        for &n in &index {
            for i in 0..=n[0] / 2 {
                for j in 0..=n[1] / 2 {
                    for l in 0..=n[2] / 2 {
                        let c = coeff(n[0], i) * coeff(n[1], j) * coeff(n[2], l);
                        let mono = at([n[0] - 2 * i, n[1] - 2 * j, n[2] - 2 * l]);
                        deriv.push((c, mono as u16, (order(n) - i - j - l) as u8));
                    }
                }
            }
            deriv_start.push(deriv.len());
        }

        let mut conv_start = vec![0];
        let mut conv = Vec::new();
        for &n in &index {
            for (k, &nk) in index.iter().enumerate() {
                if (0..3).all(|d| nk[d] <= n[d]) {
                    let rest = at([n[0] - nk[0], n[1] - nk[1], n[2] - nk[2]]);
                    conv.push((k as u16, rest as u16));
                }
            }
            conv_start.push(conv.len());
        }

        Expansion {
            p,
            len,
            step,
            add,
            row_len,
            deriv_start,
            deriv,
            conv_start,
            conv,
        }
    }

    /// The multiply-adds of one M2L's contraction: one per pair of indices `(n, m)` with
    /// `|n| + |m| ≤ p`, `(p+1)(p+2)...(p+6)/6!` (210 at order 4).
    pub(crate) fn m2l_terms(&self) -> usize {
        self.row_len.iter().sum()
    }

    /// `out[n] = v^n / n!` for the first `out.len()` indices (all of order ≤ q when
    /// `out.len() = terms(q)`).
    #[inline(always)]
    pub(crate) fn monomials(&self, v: [f64; 3], out: &mut [f64]) {
        out[0] = 1.0;
        for i in 1..out.len() {
            let (parent, d, inv) = self.step[i];
            out[i] = out[parent] * v[d] * inv;
        }
    }

    /// P2M: adds source `s` at offset `w = z − x` from the centre z to the multipole `m`.
    /// `mono` is scratch of `len` values.
    #[inline(always)]
    pub(crate) fn p2m(&self, w: [f64; 3], s: f64, m: &mut [f64], mono: &mut [f64]) {
        self.monomials(w, mono);
        for (a, b) in m.iter_mut().zip(mono.iter()) {
            *a += s * b;
        }
    }

    /// M2M: adds the multipole `child` about its centre to `parent` about a centre at
    /// `d = z_parent − z_child` from it (`(d + w)^n/n! = Σ_k d^k/k! · w^{n−k}/(n−k)!`).
    pub(crate) fn m2m(&self, d: [f64; 3], child: &[f64], parent: &mut [f64], mono: &mut [f64]) {
        self.monomials(d, mono);
        for (n, out) in parent.iter_mut().enumerate() {
            let mut sum = 0.0;
            for &(k, rest) in &self.conv[self.conv_start[n]..self.conv_start[n + 1]] {
                sum += mono[k as usize] * child[rest as usize];
            }
            *out += sum;
        }
    }

    /// M2L onto one cell from `LANES` source cells at once, one in each lane (SIMD across
    /// the cell's partners): with `b.r[d][l]` the separation `z_A − z_B` of lane l's partner,
    /// `b.dj[j][l]` the scalar derivatives there (see [`scaled_derivatives`]) and `b.mb[n][l]`
    /// its multipole, adds `Σ_{|n| ≤ p − |m|} M[n] ∂^{n+m} G(R)` to `b.la[m][l]` for every
    /// local index m from `first` on (1 for forces only: the potential `L_0` is needed for
    /// the energy alone). A lane of zero multipole adds nothing. Lanes never mix, so each
    /// lane's sum is the same whichever lanes share its batch.
    #[inline(always)]
    pub(crate) fn m2l_lanes(&self, b: &mut Batch, first: usize) {
        let len = self.len;
        let (r, dj) = (&b.r, &b.dj);
        let (mono, t, mb, la) = (
            &mut b.mono[..len],
            &mut b.t[..len],
            &b.mb[..len],
            &mut b.la[..len],
        );
        mono[0] = [1.0; LANES];
        for i in 1..len {
            let (parent, d, inv) = self.step[i];
            let p = mono[parent];
            for l in 0..LANES {
                mono[i][l] = p[l] * r[d][l] * inv;
            }
        }
        // T[k] = ∂^k G(R): the derivative terms of each index over the scaled monomials.
        for (k, out) in t.iter_mut().enumerate() {
            let mut sum = [0.0; LANES];
            for &(c, m, j) in &self.deriv[self.deriv_start[k]..self.deriv_start[k + 1]] {
                let (mono, dj) = (&mono[m as usize], &dj[j as usize]);
                for l in 0..LANES {
                    sum[l] += c * mono[l] * dj[l];
                }
            }
            *out = sum;
        }
        for m in first..len {
            let row = &self.add[m * len..m * len + self.row_len[m]];
            // Four partial sums (n mod 4), so that the additions of a row do not wait on
            // each other; then added in a fixed order.
            let mut sums = [[0.0; LANES]; 4];
            let (quads, rest) = row.split_at(row.len() / 4 * 4);
            for (q, ks) in quads.chunks_exact(4).enumerate() {
                for (u, &k) in ks.iter().enumerate() {
                    let (mn, tk) = (&mb[4 * q + u], &t[k as usize]);
                    for l in 0..LANES {
                        sums[u][l] += mn[l] * tk[l];
                    }
                }
            }
            for (u, &k) in rest.iter().enumerate() {
                let (mn, tk) = (&mb[quads.len() + u], &t[k as usize]);
                for l in 0..LANES {
                    sums[u][l] += mn[l] * tk[l];
                }
            }
            for l in 0..LANES {
                la[m][l] += (sums[0][l] + sums[1][l]) + (sums[2][l] + sums[3][l]);
            }
        }
    }

    /// L2L: adds the local expansion `parent` about its centre, moved to a centre at
    /// `d = z_child − z_parent`, to `child` (`L_c[m] = Σ_k L[m + k] d^k/k!`).
    pub(crate) fn l2l(&self, d: [f64; 3], parent: &[f64], child: &mut [f64], mono: &mut [f64]) {
        self.monomials(d, mono);
        let len = self.len;
        for (m, out) in child.iter_mut().enumerate() {
            let row = &self.add[m * len..m * len + self.row_len[m]];
            let mut sum = 0.0;
            for (k, &mk) in row.iter().enumerate() {
                sum += mono[k] * parent[mk as usize];
            }
            *out += sum;
        }
    }

    /// L2P: the gradient of the far field at offset `r` from the centre, and with `potential`
    /// also the field itself (else 0). `mono` holds at least `len` values.
    #[inline(always)]
    pub(crate) fn l2p(
        &self,
        r: [f64; 3],
        l: &[f64],
        potential: bool,
        mono: &mut [f64],
    ) -> ([f64; 3], f64) {
        let below = terms(self.p - 1);
        let upto = if potential { self.len } else { below };
        self.monomials(r, &mut mono[..upto]);
        let len = self.len;
        let mut grad = [0.0; 3];
        for m in 0..below {
            // m + e_d for d = 0, 1, 2: the unit vectors are indices 1, 2, 3.
            let row = &self.add[m * len..];
            for d in 0..3 {
                grad[d] += mono[m] * l[row[1 + d] as usize];
            }
        }
        let pot = if potential {
            (0..len).map(|m| mono[m] * l[m]).sum()
        } else {
            0.0
        };
        (grad, pot)
    }
}

/// The scalar derivatives `κ D_j`, j = 0..=p, of the law's Green's function at squared
/// distance `r2` in each lane, from the law's own force coefficient `coeff = coeff(r², 1, 1)`
/// and `r2_soft = r² + ε²`: for a law with `coeff(r², 1, 1) = −κ (r² + ε²)^{-3/2}` (force on
/// i along `x_j − x_i`) the potential of a pair is `κ s_i s_j g` with `g = (r² + ε²)^{-1/2}`,
/// and `D_1 = −(r² + ε²)^{-3/2}`, so `κ D_1 = coeff`. Then `D_0 = −D_1 (r² + ε²)` and
/// `D_{j+1} = −(2j+1) D_j / (r² + ε²)`.
#[inline(always)]
pub(crate) fn scaled_derivatives(coeff: &Lanes, r2_soft: &Lanes, p: usize, out: &mut [Lanes]) {
    for l in 0..LANES {
        out[1][l] = coeff[l];
        out[0][l] = -coeff[l] * r2_soft[l];
    }
    let inv: Lanes = std::array::from_fn(|l| 1.0 / r2_soft[l]);
    for j in 1..p {
        let f = -((2 * j + 1) as f64);
        for l in 0..LANES {
            out[j + 1][l] = f * out[j][l] * inv[l];
        }
    }
}
