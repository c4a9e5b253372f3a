//! The batched cell–cell interaction (M2L) written with intrinsics for AVX-512 and AVX2: one
//! target cell and `LANES` partner cells in the lanes, in vectors of `V::WIDTH` partners.
//!
//! It does the operations of [`Expansion::m2l_lanes`], the portable loop that the baseline
//! instruction set runs, in the same order, with what LLVM did not do there: every
//! coefficient row is one vector load, and multiplies and adds are fused. (The portable loop
//! compiled to one scalar multiply, add and store per lane and term: its rows are arrays
//! indexed through the expansion's tables, which LLVM did not turn into vectors.) A lane's
//! sum still takes its terms in the portable loop's order, so the local expansions are the
//! same bits at every thread count; they differ from the portable loop's in the last bits,
//! where a fused multiply-add rounds once.

use super::expansion::{Batch, Expansion};
pub(super) use crate::kernels::lanes::{Isa, isa};
use crate::kernels::rows::LANES;
#[cfg(target_arch = "x86_64")]
use crate::{
    kernels::lanes::{Avx2F64, Avx512F64, Lanes},
    simd::{run_avx2, run_avx512},
};

/// One batch of M2L, as [`Expansion::m2l_lanes`] (same arguments and result), by the
/// vector loop of `isa` ([`isa`] gives this machine's), or by the portable one for `None`.
///
/// # Safety
/// The CPU must have the features of `isa`.
#[inline(always)]
pub(super) unsafe fn m2l_batch(isa: Option<Isa>, exp: &Expansion, b: &mut Batch, first: usize) {
    #[cfg(target_arch = "x86_64")]
    if let Some(isa) = isa {
        // SAFETY: the caller has checked the CPU for the features `run_*` enables.
        unsafe {
            match isa {
                Isa::Avx512 => run_avx512(|| batch::<Avx512F64>(exp, b, first)),
                Isa::Avx2 => run_avx2(|| batch::<Avx2F64>(exp, b, first)),
            }
        }
        return;
    }
    exp.m2l_lanes(b, first);
}

/// The batch in vectors of `V::WIDTH` lanes, each vector of partners through the whole
/// M2L before the next. Runs `V`'s intrinsics: only under `V`'s features (a safe function, so
/// that it inlines into the closures above).
#[cfg(target_arch = "x86_64")]
#[inline(always)]
fn batch<V: Lanes<Elem = f64>>(exp: &Expansion, b: &mut Batch, first: usize) {
    let len = exp.len;
    assert!(
        b.mb.len() >= len && b.la.len() >= len && b.mono.len() >= len && b.t.len() >= len,
        "M2L scratch rows shorter than the expansion"
    );
    assert!(b.dj.len() > exp.p, "M2L derivatives shorter than the order");
    debug_assert!(LANES.is_multiple_of(V::WIDTH));
    let r = &b.r;
    // Row `i`'s lanes `h..h + WIDTH` of a table of rows, by pointer (slicing each row,
    // with its bounds checks, cost a quarter of the loop).
    let (mono, t, la) = (
        b.mono.as_mut_ptr().cast::<f64>(),
        b.t.as_mut_ptr().cast::<f64>(),
        b.la.as_mut_ptr().cast::<f64>(),
    );
    let (mb, dj) = (b.mb.as_ptr().cast::<f64>(), b.dj.as_ptr().cast::<f64>());
    // SAFETY: every load and store touches lanes `h..h + WIDTH ≤ LANES` of a row that the
    // asserts above put in bounds (the tables' indices are below `len`, the derivatives'
    // below p + 1); the intrinsics run under the caller's features.
    unsafe {
        let row = |i: usize, h: usize| i * LANES + h;
        for h in (0..LANES).step_by(V::WIDTH) {
            let rv = [
                V::load(r[0][h..].as_ptr()),
                V::load(r[1][h..].as_ptr()),
                V::load(r[2][h..].as_ptr()),
            ];
            V::splat(1.0).store(mono.add(row(0, h)));
            for i in 1..len {
                let (parent, d, inv) = exp.step[i];
                let v = V::load(mono.add(row(parent, h)))
                    .mul(rv[d])
                    .mul(V::splat(inv));
                v.store(mono.add(row(i, h)));
            }
            // T[k] = ∂^k G(R), as the portable loop: Σ (c · mono) · D_j, here fused.
            for k in 0..len {
                let mut sum = V::splat(0.0);
                for &(c, m, j) in &exp.deriv[exp.deriv_start[k]..exp.deriv_start[k + 1]] {
                    let cm = V::splat(c).mul(V::load(mono.add(row(m as usize, h))));
                    sum = cm.mul_add(V::load(dj.add(row(j as usize, h))), sum);
                }
                sum.store(t.add(row(k, h)));
            }
            for m in first..len {
                let ks = &exp.add[m * len..m * len + exp.row_len[m]];
                // Four partial sums (n mod 4), added in a fixed order, as the portable loop.
                let mut sums = [V::splat(0.0); 4];
                let (quads, rest) = ks.split_at(ks.len() / 4 * 4);
                for (q, four) in quads.chunks_exact(4).enumerate() {
                    for u in 0..4 {
                        let mn = V::load(mb.add(row(4 * q + u, h)));
                        sums[u] = mn.mul_add(V::load(t.add(row(four[u] as usize, h))), sums[u]);
                    }
                }
                for (u, &k) in rest.iter().enumerate() {
                    let mn = V::load(mb.add(row(quads.len() + u, h)));
                    sums[u] = mn.mul_add(V::load(t.add(row(k as usize, h))), sums[u]);
                }
                let total = sums[0].add(sums[1]).add(sums[2].add(sums[3]));
                V::load(la.add(row(m, h)))
                    .add(total)
                    .store(la.add(row(m, h)));
            }
        }
    }
}
