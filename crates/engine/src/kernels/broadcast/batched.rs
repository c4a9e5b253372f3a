//! The batched inverse-square pair kernel: the tile's targets in vector registers, each source
//! broadcast to them, written with intrinsics for AVX-512 and AVX2 in both precisions (the
//! layout of Phantom-GRAPE's and PKDGRAV3's CPU kernels).
//!
//! Against the portable loop of [`super::tile_forces`] it gains what LLVM cannot do without
//! leave to reorder floating point: multiplies and adds fused (the squared distance, the
//! Newton steps, the force sums), the hardware's reciprocal-square-root estimate in place of
//! the integer one (two or three Newton steps instead of four), `k · s_i` taken out of the
//! sum, and the test of a lane's own slot only in the `LANES` sources that can hold it.
//!
//! Each target's force is still summed over the sources in their order, whatever its lane
//! or tile, so the forces are the same bits at every thread count. They differ in the last
//! bits between instruction sets (the estimates differ) and from the portable loop.

use super::Tile;
#[cfg(target_arch = "x86_64")]
use crate::kernels::lanes::{Avx2F32, Avx2F64, Avx512F32, Avx512F64, Isa, Lanes, is, isa, same};
use crate::kernels::rows::{LANES, Sources};
use crate::physics::InverseSquare;
use crate::real::Real;
#[cfg(target_arch = "x86_64")]
use crate::simd::{run_avx2, run_avx512};
use std::ops::Range;

/// The forces on the tile's targets from `src` under the law `p`, lane `l` skipping source
/// `own + l` (as [`super::tile_forces`]), by this machine's batched kernel; `None` at the
/// baseline instruction set, which has none.
#[inline(always)]
pub(super) fn forces<T: Real, const D: usize>(
    p: &InverseSquare<T>,
    tile: &Tile<T, D>,
    src: &Sources<'_, T, D>,
    own: usize,
) -> Option<[[T; LANES]; D]> {
    #[cfg(target_arch = "x86_64")]
    if let Some(isa) = isa() {
        // SAFETY: `isa()` has checked the CPU for this instruction set.
        return unsafe { forces_on(isa, p, tile, src, own) };
    }
    let _ = (p, tile, src, own);
    None
}

/// [`forces`] with the instruction set given; `None` for a precision without a kernel.
///
/// # Safety
/// The CPU must have the instruction set's features.
#[cfg(target_arch = "x86_64")]
#[inline(always)]
pub(super) unsafe fn forces_on<T: Real, const D: usize>(
    isa: Isa,
    p: &InverseSquare<T>,
    tile: &Tile<T, D>,
    src: &Sources<'_, T, D>,
    own: usize,
) -> Option<[[T; LANES]; D]> {
    // SAFETY (both blocks): `is` makes `T` the type the references are cast to, and
    // the caller has checked the CPU for the features `run_*` enables. Two vectors of targets
    // per pass where they fit the registers with their sums (16 f64 in zmm, 8 f64 or 16
    // f32 in ymm), one where a vector is the whole tile (16 f32 in a zmm).
    if is::<T, f64>() {
        let (p, tile, src) = unsafe { (same(p), same(tile), same(src)) };
        let f = unsafe {
            match isa {
                Isa::Avx512 => run_avx512(|| passes::<Avx512F64, D, 2>(p, tile, src, own)),
                Isa::Avx2 => run_avx2(|| passes::<Avx2F64, D, 2>(p, tile, src, own)),
            }
        };
        return Some(unsafe { *same(&f) });
    }
    if is::<T, f32>() {
        let (p, tile, src) = unsafe { (same(p), same(tile), same(src)) };
        let f = unsafe {
            match isa {
                Isa::Avx512 => run_avx512(|| passes::<Avx512F32, D, 1>(p, tile, src, own)),
                Isa::Avx2 => run_avx2(|| passes::<Avx2F32, D, 2>(p, tile, src, own)),
            }
        };
        return Some(unsafe { *same(&f) });
    }
    None
}

/// The tile in passes of `K` vectors of targets, each pass over every source. Runs `V`'s
/// intrinsics: only under `V`'s features (a safe function, so that it inlines into the
/// closures of [`forces`]).
#[cfg(target_arch = "x86_64")]
#[inline(always)]
fn passes<V: Lanes, const D: usize, const K: usize>(
    p: &InverseSquare<V::Elem>,
    tile: &Tile<V::Elem, D>,
    src: &Sources<'_, V::Elem, D>,
    own: usize,
) -> [[V::Elem; LANES]; D]
where
    V::Elem: Real,
{
    let zero = <V::Elem as num_traits::Zero>::zero();
    let lane_number: [V::Elem; LANES] = std::array::from_fn(|l| V::Elem::of(l as f64));
    let mut out = [[zero; LANES]; D];
    let per_pass = K * V::WIDTH;
    debug_assert!(LANES.is_multiple_of(per_pass));
    for first in (0..LANES).step_by(per_pass) {
        // SAFETY: `first + k · WIDTH + WIDTH ≤ LANES` for every k < K, so every load and
        // store stays inside the tile's arrays; the intrinsics are the caller's.
        unsafe {
            // Plain loops, not `array::from_fn`: its closures are functions of their own,
            // compiled without the features, where the intrinsics would not inline.
            let mut pass = Pass::<V, D, K> {
                x: [[V::splat(zero); K]; D],
                lane: [V::splat(zero); K],
                eps2: V::splat(p.eps2),
                quench2: V::splat(p.quench2),
            };
            for k in 0..K {
                let at = first + k * V::WIDTH;
                for d in 0..D {
                    pass.x[d][k] = V::load(&tile.x[d][at]);
                }
                pass.lane[k] = V::load(&lane_number[at]);
            }
            let mut acc = [[V::splat(zero); K]; D];
            if p.quench2 > zero {
                pass.sources::<true>(src, own, &mut acc);
            } else {
                pass.sources::<false>(src, own, &mut acc);
            }
            for k in 0..K {
                let at = first + k * V::WIDTH;
                let scale = V::load(&tile.s[at]).mul(V::splat(p.k));
                for d in 0..D {
                    acc[d][k].mul(scale).store(&mut out[d][at]);
                }
            }
        }
    }
    out
}

/// One pass's targets, in registers.
#[cfg(target_arch = "x86_64")]
struct Pass<V, const D: usize, const K: usize> {
    x: [[V; K]; D],
    /// Each lane's number within the tile.
    lane: [V; K],
    eps2: V,
    quench2: V,
}

#[cfg(target_arch = "x86_64")]
impl<V: Lanes, const D: usize, const K: usize> Pass<V, D, K>
where
    V::Elem: Real,
{
    /// Adds `s_j (r² + ε²)^{−3/2} (x_j − x_i)` over every source of `src` to each lane's
    /// sums, lane `l` skipping source `own + l`; with `QUENCH`, zero where `r² + ε²` is below
    /// the quench radius's square.
    ///
    /// # Safety
    /// The caller must have `V`'s features.
    #[inline(always)]
    unsafe fn sources<const QUENCH: bool>(
        &self,
        src: &Sources<'_, V::Elem, D>,
        own: usize,
        acc: &mut [[V; K]; D],
    ) {
        let n = src.len();
        let own = own.min(n);
        // Only these sources can be some lane's own slot.
        let mine = own..(own + LANES).min(n);
        // SAFETY: the runs lie within `src`; the features are the caller's.
        unsafe {
            self.run::<QUENCH, false>(src, 0..mine.start, own, acc);
            self.run::<QUENCH, true>(src, mine.clone(), own, acc);
            self.run::<QUENCH, false>(src, mine.end..n, own, acc);
        }
    }

    /// [`Pass::sources`] over the run `js`; with `MINE`, lane `l` skips source `own + l`.
    ///
    /// # Safety
    /// `js` must lie within `src`, and the caller must have `V`'s features.
    #[inline(always)]
    unsafe fn run<const QUENCH: bool, const MINE: bool>(
        &self,
        src: &Sources<'_, V::Elem, D>,
        js: Range<usize>,
        own: usize,
        acc: &mut [[V; K]; D],
    ) {
        debug_assert!(js.end <= src.len());
        for j in js {
            // SAFETY: j < src.len(), which every array of `src` has; the intrinsics are the
            // caller's.
            unsafe {
                let mut xj = [self.eps2; D];
                for d in 0..D {
                    xj[d] = V::splat(*src.pos[d].get_unchecked(j));
                }
                let sj = V::splat(*src.s.get_unchecked(j));
                for k in 0..K {
                    let mut r2 = self.eps2;
                    let mut dx = [self.eps2; D];
                    for d in 0..D {
                        dx[d] = xj[d].sub(self.x[d][k]);
                        r2 = dx[d].mul_add(dx[d], r2);
                    }
                    let mut c = r2.rsqrt_cubed_scaled(sj);
                    if QUENCH {
                        c = c.zero_where_less(r2, self.quench2);
                    }
                    if MINE {
                        // Lane `j − own` is the one whose own slot this is.
                        let slot = V::splat(V::Elem::of((j - own) as f64));
                        c = c.zero_where_equal(self.lane[k], slot);
                    }
                    for d in 0..D {
                        acc[d][k] = c.mul_add(dx[d], acc[d][k]);
                    }
                }
            }
        }
    }
}

#[cfg(all(test, target_arch = "x86_64"))]
mod tests {
    use super::*;
    use crate::kernels::lanes::isas_here;
    use crate::physics::{Coulomb, Gravity, PairLaw, pair_force};
    use crate::testing::SEED_1;
    use rand::{Rng, SeedableRng};
    use rand_pcg::Pcg64Mcg;

    /// Sources scattered in the unit cube with strengths of both signs (a fixed sequence),
    /// source 3 placed on source 0 (a coincident pair).
    fn sources<T: Real>(n: usize) -> ([Vec<T>; 3], Vec<T>) {
        let mut rng = Pcg64Mcg::seed_from_u64(SEED_1);
        let mut next = || rng.random::<f64>();
        let mut pos: [Vec<T>; 3] = std::array::from_fn(|_| Vec::new());
        let mut s = Vec::new();
        for j in 0..n {
            for p in &mut pos {
                p.push(T::of(next()));
            }
            s.push(T::of(if j % 4 == 1 { -0.5 } else { 1.0 + next() }));
        }
        if n > 3 {
            for p in &mut pos {
                p[3] = p[0];
            }
        }
        (pos, s)
    }

    /// For every lane, |F − F_ref| ≤ `tol` · Σ_j |F_ij|, the reference summed in f64 with the
    /// law's textbook coefficient, skipping the lane's own slot.
    fn check<T: Real, L: PairLaw<T>>(law: &L, n: usize, lo: usize, hi: usize, own: bool, tol: f64)
    where
        L::Wide: PairLaw<f64>,
    {
        let (pos, s) = sources::<T>(n);
        // Targets: the sources lo..hi themselves, or copies of them moved off the sources.
        let targets: [Vec<T>; 3] = if own {
            pos.clone()
        } else {
            std::array::from_fn(|d| pos[d].iter().map(|&x| x + T::of(0.013)).collect())
        };
        let tile = Tile::load(&targets, &s, lo, hi);
        let src = Sources::range(&pos, &s, 0, n);
        let wide = law.widen();
        let p = law.inverse_square().expect("an inverse-square law");
        for isa in isas_here() {
            // SAFETY: `isas` lists only what this CPU runs.
            let got = unsafe { forces_on(isa, &p, &tile, &src, if own { lo } else { usize::MAX }) }
                .expect("a kernel for f32 and f64");
            for l in 0..hi - lo {
                let i = lo + l;
                let (mut want, mut scale) = ([0.0; 3], 0.0);
                for j in (0..n).filter(|&j| !(own && j == i)) {
                    let dx: [f64; 3] =
                        std::array::from_fn(|d| pos[d][j].as_f64() - targets[d][i].as_f64());
                    let f = pair_force(&wide, dx, s[i].as_f64(), s[j].as_f64());
                    for d in 0..3 {
                        want[d] += f[d];
                        scale += f[d].abs();
                    }
                }
                for d in 0..3 {
                    let err = (got[d][l].as_f64() - want[d]).abs();
                    assert!(
                        err <= tol * scale && got[d][l].is_finite(),
                        "{isa:?} {}: n {n}, target {i}, component {d}: {} against {} (scale {scale})",
                        T::NAME,
                        got[d][l],
                        want[d]
                    );
                }
            }
        }
    }

    /// Both laws and precisions at every instruction set here, against the f64 reference sum:
    /// no sources, one, a partial tile, tiles across the run's start and end, targets among
    /// the sources (own slot skipped) and apart from them, and a coincident pair (softened in
    /// gravity, quenched in Coulomb). f64 to 1e-13 of the summed magnitudes (the estimate is
    /// refined to rounding); f32 to 2e-5 (its rounding over about a hundred terms).
    #[test]
    fn batched_tiles_match_the_reference_sum() {
        let gravity = Gravity::<f64>::new(1.0, 0.01);
        let coulomb = Coulomb::<f64>::new(1e-3);
        let (gravity32, coulomb32) = (Gravity::<f32>::new(1.0, 0.01), Coulomb::<f32>::new(1e-3));
        for (n, lo, hi, own) in [
            (0, 0, 1, false),
            (1, 0, 1, true),
            (1, 0, 1, false),
            (5, 0, 5, true),
            (37, 3, 19, true),
            (37, 30, 37, true),
            (100, 84, 100, true),
            (100, 40, 56, false),
        ] {
            if n == 0 {
                // No sources: a target somewhere, no force.
                let (pos, s) = sources::<f64>(1);
                let tile = Tile::load(&pos, &s, 0, 1);
                let none = Sources::range(&pos, &s, 0, 0);
                let p = gravity.inverse_square().expect("gravity");
                for isa in isas_here() {
                    // SAFETY: as above.
                    let got = unsafe { forces_on(isa, &p, &tile, &none, usize::MAX) };
                    assert_eq!(got, Some([[0.0; LANES]; 3]));
                }
                continue;
            }
            check(&gravity, n, lo, hi, own, 1e-13);
            check(&coulomb, n, lo, hi, own, 1e-13);
            check(&gravity32, n, lo, hi, own, 2e-5);
            check(&coulomb32, n, lo, hi, own, 2e-5);
        }
    }
}
