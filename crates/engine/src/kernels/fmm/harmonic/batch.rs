//! The harmonic M2L of one target cell in batches: `V::WIDTH` partner cells in the lanes of
//! the vectors of [`Lanes`], each lane through the whole translation of [`Harmonic::m2l`]
//! (its angle's small-d matrices by the recurrence, the rotation to the z-axis, the shift
//! along it and the rotation back) with the same coefficient tables, so that a translation
//! is a run of vector multiply-adds with no per-lane branch. The lanes' local expansions are
//! added at the end of the cell in lane order: a fixed order whatever thread runs the cell.
//!
//! A translation of order p reads less than the whole of each matrix: the shifted local has
//! `L_n^m = 0` past `m = p − n` and the shift reads the rotated multipole's `M_j^m` only for
//! `m ≤ p − j`, so the rotation forward needs the rows `m' ≤ min(j, p − j)` and the rotation
//! back the columns `|m| ≤ p − n`; the recurrence runs each `(m', m)` only up to the degree
//! `p − min(m', |m|)` where one of them still needs it (about half of the matrices' entries
//! at p = 8).
//!
//! [`Harmonic::m2l`]: super::Harmonic::m2l

use super::rotation::{binomials, edge_form, half_angles, step};
use super::solid::{at, count, sign};
use crate::kernels::lanes::{Isa, Lanes, Scalar};
#[cfg(target_arch = "x86_64")]
use crate::{
    kernels::lanes::{Avx2F64, Avx512F64},
    simd::{run_avx2, run_avx512},
};

/// The widest vector a batch is run with (AVX-512's f64 lanes).
const MAX_WIDTH: usize = 8;

/// What the batched M2L of one order reads: where each entry of the small-d matrices is and
/// how it follows from the degrees below, and the harmonics' scales.
pub struct Plan {
    p: usize,
    /// Where `d^n_{m'0}` is, at `at(n, m')`: the row holds the orders |m| ≤ n that a
    /// translation reads (all if `m' ≤ p − n`, else `|m| ≤ p − n`), order m at `+ m`.
    row: Vec<usize>,
    /// The entries of all rows.
    size: usize,
    /// The `(m', m)` up their degrees, four at a time (four chains of dependent operations
    /// in flight, in registers), `QUAD` of the same length together.
    quads: Vec<Quad>,
    quad_steps: Vec<QuadStep>,
    /// `√((n+m)! (n−m)!)` and its inverse at `at(n, m)`.
    norm: Vec<f64>,
    inv_norm: Vec<f64>,
}

/// Chains interleaved per [`Quad`].
const QUAD: usize = 4;

/// `QUAD` chains of the same length: each starts at its edge, `d[at] = coef · cos(β/2)^cos ·
/// sin(β/2)^sin` at the first degree where its `(m', m)` exists, and goes up the degrees by
/// `quad_steps[steps.0..steps.1]`.
struct Quad {
    at: [u32; QUAD],
    cos: [u16; QUAD],
    sin: [u16; QUAD],
    coef: [f64; QUAD],
    steps: (usize, usize),
}

/// One degree up each chain of a quad: `d[at] = (a cos β + b) d[one degree down] − g d[two
/// down]` (`g = 0` one degree past the edge).
struct QuadStep {
    at: [u32; QUAD],
    a: [f64; QUAD],
    b: [f64; QUAD],
    g: [f64; QUAD],
}

/// One `(m', m)` while the plan is made: its edge and its steps `(at, [a, b, g])`.
struct Chain {
    at: u32,
    cos: u16,
    sin: u16,
    coef: f64,
    steps: Vec<(u32, [f64; 3])>,
}

impl Plan {
    /// The plan of order `p`, with `norm` the harmonics' scales (`Harmonic`'s table).
    pub fn new(p: usize, norm: &[f64]) -> Plan {
        let (mut row, mut size) = (vec![0; count(p)], 0);
        for n in 0..=p {
            for mp in 0..=n {
                let half_width = if mp <= p - n { n } else { p - n };
                row[at(n, mp)] = size + half_width;
                size += 2 * half_width + 1;
            }
        }
        let index = |n: usize, mp: usize, m: isize| (row[at(n, mp)] as isize + m) as usize;
        let binom = binomials(p);
        let mut chains = Vec::new();
        let pi = p as isize;
        for mp in 0..=p {
            for m in -pi..=pi {
                let (low, high) = (mp.min(m.unsigned_abs()), mp.max(m.unsigned_abs()));
                if low + high > p {
                    continue;
                }
                let (coef, cos, sin) = edge_form(&binom, p, high, mp as isize, m);
                let at = |n: usize| index(n, mp, m) as u32;
                chains.push(Chain {
                    at: at(high),
                    cos: cos as u16,
                    sin: sin as u16,
                    coef,
                    steps: (high + 1..=p - low)
                        .map(|n| (at(n), step(n, mp as isize, m)))
                        .collect(),
                });
            }
        }
        // Quads of chains of one length; a short quad repeats its last chain (which
        // computes and stores the same entries again).
        chains.sort_by_key(|c| c.steps.len());
        let (mut quads, mut quad_steps) = (Vec::new(), Vec::new());
        for same in chains.chunk_by(|a, b| a.steps.len() == b.steps.len()) {
            for group in same.chunks(QUAD) {
                let c: [&Chain; QUAD] = std::array::from_fn(|k| &group[k.min(group.len() - 1)]);
                let first = quad_steps.len();
                for s in 0..c[0].steps.len() {
                    quad_steps.push(QuadStep {
                        at: c.map(|c| c.steps[s].0),
                        a: c.map(|c| c.steps[s].1[0]),
                        b: c.map(|c| c.steps[s].1[1]),
                        g: c.map(|c| c.steps[s].1[2]),
                    });
                }
                quads.push(Quad {
                    at: c.map(|c| c.at),
                    cos: c.map(|c| c.cos),
                    sin: c.map(|c| c.sin),
                    coef: c.map(|c| c.coef),
                    steps: (first, quad_steps.len()),
                });
            }
        }
        let inv_norm = norm.iter().map(|x| 1.0 / x).collect();
        Plan {
            p,
            row,
            size,
            quads,
            quad_steps,
            norm: norm.to_vec(),
            inv_norm,
        }
    }
}

/// `MAX_WIDTH` f64 on a cache line of their own: a batch's rows start on one, so that no
/// vector load or store of a row splits two lines.
#[derive(Clone, Copy)]
#[repr(C, align(64))]
struct Block([f64; MAX_WIDTH]);

/// Rows of f64 from a line boundary on, seen as one slice.
struct Rows(Vec<Block>);

impl std::ops::Deref for Rows {
    type Target = [f64];
    fn deref(&self) -> &[f64] {
        // SAFETY: a `Block` is `MAX_WIDTH` f64 with no padding (64 bytes, aligned to 64).
        unsafe { std::slice::from_raw_parts(self.0.as_ptr().cast(), self.0.len() * MAX_WIDTH) }
    }
}

impl std::ops::DerefMut for Rows {
    fn deref_mut(&mut self) -> &mut [f64] {
        // SAFETY: as `deref`.
        unsafe {
            std::slice::from_raw_parts_mut(self.0.as_mut_ptr().cast(), self.0.len() * MAX_WIDTH)
        }
    }
}

/// Per-thread rows of a batch, `V::WIDTH` values each (one per lane).
pub struct Batch {
    /// The partners' multipoles (row 2i the real part of coefficient i, 2i + 1 the
    /// imaginary), then the shifted locals in their place.
    coef: Rows,
    /// The rotated multipoles, the same layout.
    rotated: Rows,
    /// The lanes' sums of the local expansion, the same layout.
    sum: Rows,
    d: Rows,
    /// `cos(β/2)^k`, k = 0..=2p, then `sin(β/2)^k`.
    half: Rows,
    /// `e^{imφ}` for m = 0..=p, real parts then imaginary.
    phase: Rows,
    /// A degree's coefficients before a rotation, real parts then imaginary.
    full: Rows,
    /// `k!/ρ^{k+1}`, k = 0..=2p + 1.
    axis: Rows,
    /// Per lane: cos β, 1/ρ, cos(β/2), sin(β/2), cos φ, sin φ.
    angles: Rows,
}

const COS: usize = 0;
const INV_RHO: usize = 1;
const HALF_COS: usize = 2;
const HALF_SIN: usize = 3;
const PHASE_RE: usize = 4;
const PHASE_IM: usize = 5;

impl Batch {
    pub fn new(plan: &Plan) -> Batch {
        let p = plan.p;
        let rows = |r: usize| Rows(vec![Block([0.0; MAX_WIDTH]); r]);
        Batch {
            coef: rows(2 * count(p)),
            rotated: rows(2 * count(p)),
            sum: rows(2 * count(p)),
            d: rows(plan.size),
            half: rows(2 * (2 * p + 1)),
            phase: rows(2 * (p + 1)),
            full: rows(2 * (p + 1)),
            axis: rows(2 * p + 2),
            angles: rows(6),
        }
    }
}

/// The local expansion of the cell at `z` (overwritten, f64 pairs as in the cells' arrays)
/// from its `partners`, the cells at `centres[b]` with multipoles `multipoles[b]`: `κ ψ` of
/// each about its centre, by the vectors of `isa` (`None`: the portable loop).
#[allow(clippy::too_many_arguments)]
pub fn far(
    plan: &Plan,
    kappa: f64,
    isa: Option<Isa>,
    z: [f64; 3],
    partners: &[u32],
    centres: &[[f64; 3]],
    multipoles: &[f64],
    local: &mut [f64],
    batch: &mut Batch,
) {
    let cell = Cell {
        plan,
        kappa,
        z,
        partners,
        centres,
        multipoles,
    };
    #[cfg(target_arch = "x86_64")]
    if let Some(isa) = isa {
        // SAFETY: `isa` came from `lanes::isa()`, which checked the CPU for its features.
        unsafe {
            match isa {
                Isa::Avx512 => run_avx512(|| cell.run::<Avx512F64>(local, batch)),
                Isa::Avx2 => run_avx2(|| cell.run::<Avx2F64>(local, batch)),
            }
        }
        return;
    }
    let _ = isa;
    cell.run::<Scalar>(local, batch);
}

/// One target cell's translations.
struct Cell<'a> {
    plan: &'a Plan,
    kappa: f64,
    z: [f64; 3],
    partners: &'a [u32],
    centres: &'a [[f64; 3]],
    multipoles: &'a [f64],
}

impl Cell<'_> {
    /// Every partner, `V::WIDTH` at a time, then the lanes' sums into `local`. Runs `V`'s
    /// intrinsics: only under `V`'s features (a safe function, so that it inlines into the
    /// closures of [`far`]).
    #[inline(always)]
    fn run<V: Lanes<Elem = f64>>(&self, local: &mut [f64], batch: &mut Batch) {
        let w = V::WIDTH;
        let len = 2 * count(self.plan.p);
        assert!(w <= MAX_WIDTH && local.len() == len, "M2L batch rows");
        assert!(
            self.multipoles.len() >= self.centres.len() * len,
            "a multipole per cell"
        );
        batch.sum[..len * w].fill(0.0);
        for group in self.partners.chunks(w) {
            self.gather(group, w, batch);
            // SAFETY: the rows hold `w` lanes each (the assert above), sized by `Batch::new`
            // for this plan; the intrinsics run under the caller's features.
            unsafe { translate::<V>(self.plan, self.kappa, batch) };
        }
        for (i, out) in local.iter_mut().enumerate() {
            *out = batch.sum[i * w..(i + 1) * w].iter().sum();
        }
    }

    /// The lanes' angles and multipoles; lanes past the group repeat its first partner's
    /// direction with a zero multipole.
    fn gather(&self, group: &[u32], w: usize, batch: &mut Batch) {
        let len = 2 * count(self.plan.p);
        let coef = &mut batch.coef[..len * w];
        for l in 0..w {
            let b = group.get(l).map_or(group[0], |&b| b) as usize;
            let zb = self.centres[b];
            let t = [self.z[0] - zb[0], self.z[1] - zb[1], self.z[2] - zb[2]];
            // (No hypot: a cell pair's offset is far from overflow and underflow.)
            let xy2 = t[0] * t[0] + t[1] * t[1];
            let (xy, rho) = (xy2.sqrt(), (xy2 + t[2] * t[2]).sqrt());
            let (c, s) = (t[2] / rho, xy / rho);
            let (half_c, half_s) = half_angles(c, s);
            let (cos_phi, sin_phi) = if xy > 0.0 {
                (t[0] / xy, t[1] / xy)
            } else {
                (1.0, 0.0)
            };
            let angles = [c, 1.0 / rho, half_c, half_s, cos_phi, sin_phi];
            for (row, v) in batch.angles.chunks_exact_mut(w).zip(angles) {
                row[l] = v;
            }
            let rows = coef.chunks_exact_mut(w);
            if l < group.len() {
                let m = &self.multipoles[b * len..(b + 1) * len];
                for (row, &v) in rows.zip(m) {
                    row[l] = v;
                }
            } else {
                for row in rows {
                    row[l] = 0.0;
                }
            }
        }
    }
}

/// One batch of translations, adding the lanes' locals to `batch.sum`.
///
/// # Safety
/// The CPU must have `V`'s features, and `batch` must be sized for `plan` with
/// `V::WIDTH ≤ MAX_WIDTH`.
#[inline(always)]
unsafe fn translate<V: Lanes<Elem = f64>>(plan: &Plan, kappa: f64, batch: &mut Batch) {
    let (w, p) = (V::WIDTH, plan.p);
    let ld = |b: &[f64], i: usize| {
        debug_assert!((i + 1) * w <= b.len());
        // SAFETY: row i of a batch buffer, in bounds (sized by `Batch::new`).
        unsafe { V::load(b.as_ptr().add(i * w)) }
    };
    let st = |b: &mut [f64], i: usize, v: V| {
        debug_assert!((i + 1) * w <= b.len());
        // SAFETY: as `ld`.
        unsafe { v.store(b.as_mut_ptr().add(i * w)) }
    };
    let splat = |x: f64| unsafe { V::splat(x) };
    // SAFETY (all the vector arithmetic below): the caller runs this under `V`'s features.
    unsafe {
        let Batch {
            coef,
            rotated,
            sum,
            d,
            half,
            phase,
            full,
            axis,
            angles,
        } = batch;
        let c = ld(angles, COS);
        // cos(β/2)^k and sin(β/2)^k; e^{imφ}; k!/ρ^{k+1}.
        let sin_at = 2 * p + 1;
        let (hc, hs) = (ld(angles, HALF_COS), ld(angles, HALF_SIN));
        st(half, 0, splat(1.0));
        st(half, sin_at, splat(1.0));
        for k in 1..=2 * p {
            let (cos, sin) = (ld(half, k - 1).mul(hc), ld(half, sin_at + k - 1).mul(hs));
            st(half, k, cos);
            st(half, sin_at + k, sin);
        }
        let (pr, pi) = (ld(angles, PHASE_RE), ld(angles, PHASE_IM));
        let im_at = p + 1;
        st(phase, 0, splat(1.0));
        st(phase, im_at, splat(0.0));
        for m in 1..=p {
            let (re, im) = (ld(phase, m - 1), ld(phase, im_at + m - 1));
            st(phase, m, re.mul(pr).sub(im.mul(pi)));
            st(phase, im_at + m, re.mul(pi).add(im.mul(pr)));
        }
        let inv = ld(angles, INV_RHO);
        st(axis, 0, inv);
        for k in 1..=2 * p + 1 {
            let next = ld(axis, k - 1).mul(splat(k as f64).mul(inv));
            st(axis, k, next);
        }

        // The small-d matrices, each (m', m) from its edge up the degrees.
        for q in &plan.quads {
            let mut old: [V; QUAD] = std::array::from_fn(|k| {
                splat(q.coef[k])
                    .mul(ld(half, q.cos[k] as usize))
                    .mul(ld(half, sin_at + q.sin[k] as usize))
            });
            for k in 0..QUAD {
                st(d, q.at[k] as usize, old[k]);
            }
            let mut older = [splat(0.0); QUAD];
            for s in &plan.quad_steps[q.steps.0..q.steps.1] {
                for k in 0..QUAD {
                    let factor = splat(s.a[k]).mul_add(c, splat(s.b[k]));
                    let next = splat(s.g[k]).neg_mul_add(older[k], factor.mul(old[k]));
                    st(d, s.at[k] as usize, next);
                    older[k] = old[k];
                    old[k] = next;
                }
            }
        }

        // Forward: M_j^m N e^{imφ} rotated by d's transpose (rows m' ≤ min(j, p − j)), over N.
        for j in 0..=p {
            for m in 0..=j {
                let i = at(j, m);
                let (re, im) = (ld(coef, 2 * i), ld(coef, 2 * i + 1));
                let (er, ei) = (ld(phase, m), ld(phase, im_at + m));
                let n = splat(plan.norm[i]);
                st(full, m, re.mul(er).sub(im.mul(ei)).mul(n));
                st(full, im_at + m, re.mul(ei).add(im.mul(er)).mul(n));
            }
            for mp in 0..=j.min(p - j) {
                let base = plan.row[at(j, mp)];
                let row = |m: usize| (ld(d, base + m), ld(d, base - m));
                let inputs = |m: usize| (ld(full, m), ld(full, im_at + m));
                let [even, odd] = parity_sums::<V>(j, ld(d, base), row, inputs);
                // d_{mm'} = (−1)^{m+m'} d_{m'm}: the terms of m's parity other than m''s
                // change sign.
                let (re, im) = if mp % 2 == 0 {
                    (even.0.sub(odd.0), even.1.sub(odd.1))
                } else {
                    (odd.0.sub(even.0), odd.1.sub(even.1))
                };
                let i = at(j, mp);
                let scale = splat(plan.inv_norm[i]);
                st(rotated, 2 * i, re.mul(scale));
                st(rotated, 2 * i + 1, im.mul(scale));
            }
        }

        // Shift along z: L_n^m = κ (−1)^{n+m} conj(Σ_j M_j^m (j+n)!/ρ^{j+n+1}), over N for
        // the rotation back, into `coef`.
        for n in 0..=p {
            for m in 0..=n.min(p - n) {
                // Two partial sums (j's parity), for two chains of additions in flight.
                let zero = splat(0.0);
                let (mut first, mut second) = ((zero, zero), (zero, zero));
                let mut j = m;
                while j <= p - n {
                    let i = at(j, m);
                    let a = ld(axis, j + n);
                    first.0 = ld(rotated, 2 * i).mul_add(a, first.0);
                    first.1 = ld(rotated, 2 * i + 1).mul_add(a, first.1);
                    if j < p - n {
                        let i = at(j + 1, m);
                        let a = ld(axis, j + n + 1);
                        second.0 = ld(rotated, 2 * i).mul_add(a, second.0);
                        second.1 = ld(rotated, 2 * i + 1).mul_add(a, second.1);
                    }
                    j += 2;
                }
                let (re, im) = (first.0.add(second.0), first.1.add(second.1));
                let i = at(n, m);
                let scale = kappa * sign(n) * sign(m) * plan.inv_norm[i];
                st(coef, 2 * i, re.mul(splat(scale)));
                st(coef, 2 * i + 1, im.mul(splat(-scale)));
            }
        }

        // Back: by d (columns |m| ≤ p − n), times N e^{im'φ}, into the sums.
        for n in 0..=p {
            let top = n.min(p - n);
            for mp in 0..=n {
                let base = plan.row[at(n, mp)];
                let row = |m: usize| (ld(d, base + m), ld(d, base - m));
                let inputs = |m: usize| {
                    let i = at(n, m);
                    (ld(coef, 2 * i), ld(coef, 2 * i + 1))
                };
                let [even, odd] = parity_sums::<V>(top, ld(d, base), row, inputs);
                let (re, im) = (even.0.add(odd.0), even.1.add(odd.1));
                let (er, ei) = (ld(phase, mp), ld(phase, im_at + mp));
                let i = at(n, mp);
                let scale = splat(plan.norm[i]);
                let out_re = re.mul(er).sub(im.mul(ei)).mul(scale);
                let out_im = re.mul(ei).add(im.mul(er)).mul(scale);
                let (re, im) = (ld(sum, 2 * i).add(out_re), ld(sum, 2 * i + 1).add(out_im));
                st(sum, 2 * i, re);
                st(sum, 2 * i + 1, im);
            }
        }
    }
}

/// `Σ_{m=0}^{top}` of a row's terms `d_{m'm} a_m + d_{m',−m} a_{−m}` for coefficients of a
/// real field (`a_{−m} = (−1)^m conj(a_m)`: the pair is `e Re a_m + i o Im a_m` with
/// `e, o = d₊ ± (−1)^m d₋`), the even m and the odd m apart (each a real and an imaginary
/// part): four chains of multiply-adds. `row(m)` is `(d_{m'm}, d_{m',−m})`, `inputs(m)` is `a_m`.
#[inline(always)]
unsafe fn parity_sums<V: Lanes<Elem = f64>>(
    top: usize,
    d0: V,
    row: impl Fn(usize) -> (V, V),
    inputs: impl Fn(usize) -> (V, V),
) -> [(V, V); 2] {
    // SAFETY: the caller runs this under `V`'s features.
    unsafe {
        let (re0, im0) = inputs(0);
        let mut even = (d0.mul(re0), d0.mul(im0));
        let mut odd = (V::splat(0.0), V::splat(0.0));
        let mut m = 1;
        while m <= top {
            let (plus, minus) = row(m);
            let (re, im) = inputs(m);
            // Odd m: e = d₊ − d₋, o = d₊ + d₋.
            odd.0 = plus.sub(minus).mul_add(re, odd.0);
            odd.1 = plus.add(minus).mul_add(im, odd.1);
            if m < top {
                let (plus, minus) = row(m + 1);
                let (re, im) = inputs(m + 1);
                even.0 = plus.add(minus).mul_add(re, even.0);
                even.1 = plus.sub(minus).mul_add(im, even.1);
            }
            m += 2;
        }
        [even, odd]
    }
}
