//! The batched quadrupole loop (M2P): a group's accepted nodes in vector lanes against one
//! target, written with intrinsics for AVX-512 and AVX2 in both precisions.
//!
//! It evaluates [`NodeList::gather`]'s expansion (see [`super::nodes`]) with what LLVM cannot
//! do there without leave to reorder floating point: multiplies and adds fused, the hardware's
//! reciprocal-square-root estimate refined by Newton steps, and `κ s_t` taken out of the sum.
//! A target's force is summed over the nodes in list order, block by block into per-lane sums
//! added in lane order at the end: the same bits at every thread count, not across
//! instruction sets.

use super::moments::sym;
use super::nodes::NodeList;
use crate::kernels::rows::Target;
use crate::physics::InverseSquare;
use crate::real::Real;
#[cfg(target_arch = "x86_64")]
use crate::{
    kernels::lanes::{Avx2F32, Avx2F64, Avx512F32, Avx512F64, Isa, Lanes, is, isa, same},
    simd::{run_avx2, run_avx512},
};

/// The force on `t` from every node of `list` under the law `p`, by this machine's batched
/// loop; `None` at the baseline instruction set.
#[inline(always)]
pub(super) fn node_forces<T: Real, const D: usize>(
    list: &NodeList<T, D>,
    p: &InverseSquare<T>,
    t: &Target<T, D>,
) -> Option<[T; D]> {
    #[cfg(target_arch = "x86_64")]
    {
        let isa = isa()?;
        // SAFETY (both blocks): `is` makes `T` the type the references are cast to, and
        // `isa()` has checked the CPU for the features `run_*` enables.
        if is::<T, f64>() {
            let (list, p, t) = unsafe { (same(list), same(p), same(t)) };
            let f = unsafe {
                match isa {
                    Isa::Avx512 => run_avx512(|| sums::<Avx512F64, D>(list, p, t)),
                    Isa::Avx2 => run_avx2(|| sums::<Avx2F64, D>(list, p, t)),
                }
            };
            return Some(unsafe { *same(&f) });
        }
        if is::<T, f32>() {
            let (list, p, t) = unsafe { (same(list), same(p), same(t)) };
            let f = unsafe {
                match isa {
                    Isa::Avx512 => run_avx512(|| sums::<Avx512F32, D>(list, p, t)),
                    Isa::Avx2 => run_avx2(|| sums::<Avx2F32, D>(list, p, t)),
                }
            };
            return Some(unsafe { *same(&f) });
        }
    }
    let _ = (list, p, t);
    None
}

/// The loop over the padded list in blocks of `V::WIDTH` nodes. Runs `V`'s intrinsics: only
/// under `V`'s features (a safe function, so that it inlines into the closures above).
#[cfg(target_arch = "x86_64")]
#[inline(always)]
fn sums<V: Lanes, const D: usize>(
    list: &NodeList<V::Elem, D>,
    p: &InverseSquare<V::Elem>,
    t: &Target<V::Elem, D>,
) -> [V::Elem; D]
where
    V::Elem: Real,
{
    let zero = <V::Elem as num_traits::Zero>::zero();
    let width = V::WIDTH;
    // The list is padded to whole blocks of `LANES`, a multiple of every width.
    debug_assert!(list.padded.is_multiple_of(width));
    let quench = p.quench2 > zero;
    // SAFETY: every load reads `width` entries at `base < padded`, inside arrays of at least
    // `padded` entries; the intrinsics run under the caller's features.
    unsafe {
        // Plain loops, not `array::from_fn`: its closures are functions of their own, compiled
        // without the features, where the intrinsics would not inline.
        let mut x = [V::splat(zero); D];
        for d in 0..D {
            x[d] = V::splat(t.x[d]);
        }
        let (eps2, quench2) = (V::splat(p.eps2), V::splat(p.quench2));
        let five_halves = V::splat(V::Elem::of(2.5));
        let mut acc = [V::splat(zero); D];
        for base in (0..list.padded).step_by(width) {
            let mut y = [V::splat(zero); D];
            let mut r2 = eps2;
            for d in 0..D {
                y[d] = x[d].sub(V::load(&list.pos[d][base]));
                r2 = y[d].mul_add(y[d], r2);
            }
            let inv = r2.rsqrt();
            let inv2 = inv.mul(inv);
            // Q y, with Q's diagonal first, then (a, b) for a < b in row order.
            let mut qy = [V::splat(zero); D];
            for a in 0..D {
                qy[a] = V::load(&list.q[a][base]).mul(y[a]);
            }
            let mut c = D;
            for a in 0..D {
                for b in a + 1..D {
                    let q = V::load(&list.q[c][base]);
                    qy[a] = q.mul_add(y[b], qy[a]);
                    qy[b] = q.mul_add(y[a], qy[b]);
                    c += 1;
                }
            }
            debug_assert_eq!(c, sym(D));
            let mut yqy = y[0].mul(qy[0]);
            for d in 1..D {
                yqy = y[d].mul_add(qy[d], yqy);
            }
            // (yᵀQy − ε²T) / r_s⁴, and the factor of y.
            let quad = eps2
                .neg_mul_add(V::load(&list.trace[base]), yqy)
                .mul(inv2.mul(inv2));
            let radial = five_halves.mul_add(quad, V::load(&list.m[base]));
            let mut c1 = inv2.mul(inv);
            if quench {
                c1 = c1.zero_where_less(r2, quench2);
            }
            for d in 0..D {
                let f = radial.neg_mul_add(y[d], inv2.mul(qy[d]));
                acc[d] = c1.mul_add(f, acc[d]);
            }
        }
        let scale = p.k * t.s;
        let mut force = [zero; D];
        for d in 0..D {
            let mut lanes = [zero; 16];
            acc[d].store(&mut lanes[0]);
            for &v in &lanes[..width] {
                force[d] += v;
            }
            force[d] *= scale;
        }
        force
    }
}
