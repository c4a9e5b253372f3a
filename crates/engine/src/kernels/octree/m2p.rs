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
use crate::kernels::rows::{LANES, Target};
use crate::physics::{InverseSquare, PairLaw};
use crate::real::Real;
#[cfg(target_arch = "x86_64")]
use crate::{
    kernels::lanes::{Avx2F32, Avx2F64, Avx512F32, Avx512F64, Isa, Lanes, is, isa, same},
    simd::{run_avx2, run_avx512},
};

impl<T: Real, const D: usize> NodeList<T, D> {
    /// Force on `t` from every listed node, on the timed path: the batched loop for an
    /// inverse-square law where the machine has one, else [`NodeList::gather`].
    #[inline(always)]
    pub fn forces<L: PairLaw<T>>(&self, law: &L, t: &Target<T, D>) -> [T; D] {
        if let Some(p) = law.inverse_square()
            && let Some(force) = node_forces(self, &p, t)
        {
            return force;
        }
        self.gather::<L, false>(law, t).force
    }
}

/// The force on `t` from every node of `list` under the law `p`, by this machine's batched
/// loop; `None` at the baseline instruction set.
#[inline(always)]
pub(super) fn node_forces<T: Real, const D: usize>(
    list: &NodeList<T, D>,
    p: &InverseSquare<T>,
    t: &Target<T, D>,
) -> Option<[T; D]> {
    #[cfg(target_arch = "x86_64")]
    if let Some(isa) = isa() {
        // SAFETY: `isa()` has checked the CPU for this instruction set.
        return unsafe { node_forces_on(isa, list, p, t) };
    }
    let _ = (list, p, t);
    None
}

/// [`node_forces`] with the instruction set given; `None` for a precision without a kernel.
///
/// # Safety
/// The CPU must have the instruction set's features.
#[cfg(target_arch = "x86_64")]
#[inline(always)]
pub(super) unsafe fn node_forces_on<T: Real, const D: usize>(
    isa: Isa,
    list: &NodeList<T, D>,
    p: &InverseSquare<T>,
    t: &Target<T, D>,
) -> Option<[T; D]> {
    // SAFETY (both blocks): `is` makes `T` the type the references are cast to, and
    // the caller has checked the CPU for the features `run_*` enables.
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
            let mut lanes = [zero; LANES];
            acc[d].store(&mut lanes[0]);
            for &v in &lanes[..width] {
                force[d] += v;
            }
            force[d] *= scale;
        }
        force
    }
}

#[cfg(all(test, target_arch = "x86_64"))]
mod tests {
    use super::*;
    use crate::physics::{Coulomb, Gravity};
    use crate::simd::{SimdLevel, level};
    use rand::{Rng, SeedableRng};
    use rand_pcg::Pcg64Mcg;

    /// A node list of `len` nodes (a fixed sequence of centres in the unit cube, strengths,
    /// second moments of both signs and traces), padded to whole blocks with empty nodes.
    fn list<T: Real>(len: usize, seed: u64) -> NodeList<T, 3> {
        let mut rng = Pcg64Mcg::seed_from_u64(seed);
        let mut next = || rng.random::<f64>();
        let padded = len.next_multiple_of(16);
        let mut l = NodeList::new();
        l.pos = std::array::from_fn(|_| vec![T::of(5.0); padded]);
        l.m = vec![T::zero(); padded];
        l.q = std::array::from_fn(|_| vec![T::zero(); padded]);
        l.trace = vec![T::zero(); padded];
        for k in 0..len {
            for d in 0..3 {
                l.pos[d][k] = T::of(next());
            }
            l.m[k] = T::of(0.5 + next());
            for c in 0..6 {
                l.q[c][k] = T::of(0.02 * (next() - 0.5));
            }
            l.trace[k] = T::of(0.01 * next());
        }
        (l.len, l.padded) = (len, padded);
        l
    }

    /// Each node's force alone, by the portable loop: the scale of the sum's rounding.
    fn magnitude<T: Real, L: PairLaw<T>>(law: &L, full: &NodeList<T, 3>, t: &Target<T, 3>) -> f64 {
        let mut one = list::<T>(1, 1);
        (0..full.len)
            .map(|k| {
                for d in 0..3 {
                    one.pos[d][0] = full.pos[d][k];
                }
                one.m[0] = full.m[k];
                for c in 0..6 {
                    one.q[c][0] = full.q[c][k];
                }
                one.trace[0] = full.trace[k];
                let f = one.gather::<L, false>(law, t).force;
                f.iter().map(|v| v.as_f64().abs()).sum::<f64>()
            })
            .sum()
    }

    fn check<T: Real, L: PairLaw<T>>(law: &L, tol: f64) {
        let isas = match level() {
            SimdLevel::Avx512 => vec![Isa::Avx512, Isa::Avx2],
            SimdLevel::Avx2 => vec![Isa::Avx2],
            SimdLevel::Baseline => vec![],
        };
        let p = law.inverse_square().expect("an inverse-square law");
        for len in [0, 1, 15, 16, 17, 100] {
            let nodes = list::<T>(len, 7 + len as u64);
            // Targets inside and around the nodes' cube, one on the first node's centre.
            for (i, x) in [[0.3, 0.6, 0.1], [1.7, -0.4, 0.9], [0.5, 0.5, 0.5]]
                .iter()
                .enumerate()
            {
                let mut t = Target {
                    x: x.map(T::of),
                    s: T::of(0.8),
                };
                if i == 2 && len > 0 {
                    if p.quench2 > T::zero() {
                        // Unsoftened, the expansion is infinite there (for both loops); the
                        // walk accepts a node only far from its targets.
                        continue;
                    }
                    t.x = std::array::from_fn(|d| nodes.pos[d][0]);
                }
                let want = nodes.gather::<L, false>(law, &t).force;
                let scale = magnitude(law, &nodes, &t);
                for &isa in &isas {
                    // SAFETY: `isas` lists only what this CPU runs.
                    let got = unsafe { node_forces_on(isa, &nodes, &p, &t) }.expect("a kernel");
                    for d in 0..3 {
                        let err = (got[d].as_f64() - want[d].as_f64()).abs();
                        assert!(
                            err <= tol * scale && got[d].is_finite(),
                            "{isa:?} {}: {len} nodes, target {i}, component {d}: {} against {}",
                            T::NAME,
                            got[d],
                            want[d]
                        );
                    }
                }
            }
        }
    }

    /// The batched loop against the portable one at every instruction set here, in both laws
    /// and precisions: no nodes, one, blocks partly filled and whole, and (softened gravity)
    /// a target on a node's centre. f64 to 1e-13 of the summed node magnitudes, f32 to 2e-5.
    #[test]
    fn batched_nodes_match_the_portable_loop() {
        check(&Gravity::<f64>::new(1.0, 0.01), 1e-13);
        check(&Coulomb::<f64>::new(1e-3), 1e-13);
        check(&Gravity::<f32>::new(1.0, 0.01), 2e-5);
        check(&Coulomb::<f32>::new(1e-3), 2e-5);
    }
}
