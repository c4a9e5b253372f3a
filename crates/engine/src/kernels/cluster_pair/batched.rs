//! The batched force loop of the 3-D cluster list for Lennard-Jones, written with intrinsics
//! over [`Lanes`]: AVX-512 in both precisions and AVX2 in f32 (the layout of GROMACS's 4xM
//! and, for 16 f32 lanes, 2xMM kernels).
//!
//! A run's eight particles fill a vector; with sixteen lanes (f32 in a zmm) it fills both
//! halves, and two particles of the i-cluster meet it at once, one per half. The
//! i-cluster's forces stay in registers across its list (12 vectors, or 6 of 16 lanes) and
//! the run's reactions in three, added to memory once per run. What it gains over the portable
//! loop of [`super::tile`] is what LLVM did not do with it: the sums kept in registers (the
//! portable loop's went through the stack at every run), fused multiply-adds, the lane masks
//! applied as mask registers.
//!
//! The forces are summed in a fixed order for a given part, so they are the same bits at
//! every thread count; they differ in the last bits from the portable loop and between
//! instruction sets (fused operations, and with two particles per vector the reactions of
//! the even and the odd particles summed apart).

use super::layout::CLUSTER;
use super::list::Part;
use super::tile::{Clusters, Out, run_forces};
use crate::kernels::images::Images;
#[cfg(target_arch = "x86_64")]
use crate::kernels::images::no_shift;
#[cfg(target_arch = "x86_64")]
use crate::kernels::lanes::{
    Avx2F32, Avx512F32, Avx512F64, Isa, Lanes, LennardJonesLanes, is, isa, same, same_mut,
};
#[cfg(target_arch = "x86_64")]
use crate::kernels::rows::lane_sum;
#[cfg(target_arch = "x86_64")]
use crate::physics::LennardJonesTerms;
use crate::physics::PairLaw;
use crate::real::Real;
use crate::simd;
#[cfg(target_arch = "x86_64")]
use crate::simd::{run_avx2, run_avx512};
#[cfg(target_arch = "x86_64")]
use num_traits::Zero;
#[cfg(target_arch = "x86_64")]
use std::arch::x86_64::*;

/// Particles of a run in 3-D (two clusters).
#[cfg(target_arch = "x86_64")]
const RUN: usize = 8;

/// Adds the forces of `part` to `out` by the fastest loop here: the batched one
/// ([`add`]) where there is one, else the portable loop compiled for the
/// instruction set.
#[inline(always)]
pub(crate) fn add_forces<T: Real, L: PairLaw<T>, const D: usize>(
    law: &L,
    clusters: &Clusters<'_, T, D>,
    part: &Part,
    images: Option<&Images<T, D>>,
    out: &mut Out<'_, T, D>,
) {
    if !add(law, clusters, part, images, out) {
        simd::dispatch(
            #[inline(always)]
            || run_forces::<T, L, D, false>(law, clusters, part, images, out),
        );
    }
}

/// Adds the forces of `part` to `out` as the portable loop does, by this machine's batched
/// loop; `false`, with nothing done, where there is none (another dimension or law, the
/// baseline instruction set, f64 without AVX-512).
#[inline(always)]
pub(super) fn add<T: Real, L: PairLaw<T>, const D: usize>(
    law: &L,
    clusters: &Clusters<'_, T, D>,
    part: &Part,
    images: Option<&Images<T, D>>,
    out: &mut Out<'_, T, D>,
) -> bool {
    #[cfg(target_arch = "x86_64")]
    if D == 3
        && let Some(isa) = isa()
        && let Some(terms) = law.lennard_jones()
    {
        // SAFETY: `isa()` has checked the CPU for this instruction set, and D is 3.
        return unsafe { add_on(isa, &terms, clusters, part, images, out) };
    }
    let _ = (law, clusters, part, images, out);
    false
}

/// [`add`] with the instruction set given; `false` for a precision without a loop.
///
/// # Safety
/// The CPU must have the instruction set's features, and `D` must be 3.
#[cfg(target_arch = "x86_64")]
#[inline(always)]
pub(super) unsafe fn add_on<T: Real, const D: usize>(
    isa: Isa,
    lj: &LennardJonesTerms<T>,
    clusters: &Clusters<'_, T, D>,
    part: &Part,
    images: Option<&Images<T, D>>,
    out: &mut Out<'_, T, D>,
) -> bool {
    // SAFETY (every block): `is` and the caller make `T` and `D` those of the types cast to,
    // and the caller has checked the CPU for the features `run_*` enables. The closures
    // inline into `run_*`, so the loop is compiled with the features.
    if is::<T, f32>() {
        let (lj, clusters, images, out) = unsafe {
            (
                same::<_, LennardJonesTerms<f32>>(lj),
                same::<_, Clusters<'_, f32, 3>>(clusters),
                images.map(|im| same::<_, Images<f32, 3>>(im)),
                same_mut::<_, Out<'_, f32, 3>>(out),
            )
        };
        unsafe {
            match isa {
                Isa::Avx512 => run_avx512(
                    #[inline(always)]
                    || part_forces::<Avx512F32, 2>(lj, clusters, part, images, out),
                ),
                Isa::Avx2 => run_avx2(
                    #[inline(always)]
                    || part_forces::<Avx2F32, 4>(lj, clusters, part, images, out),
                ),
            }
        }
        return true;
    }
    if is::<T, f64>() && isa == Isa::Avx512 {
        let (lj, clusters, images, out) = unsafe {
            (
                same::<_, LennardJonesTerms<f64>>(lj),
                same::<_, Clusters<'_, f64, 3>>(clusters),
                images.map(|im| same::<_, Images<f64, 3>>(im)),
                same_mut::<_, Out<'_, f64, 3>>(out),
            )
        };
        unsafe {
            run_avx512(
                #[inline(always)]
                || part_forces::<Avx512F64, 4>(lj, clusters, part, images, out),
            )
        };
        return true;
    }
    false
}

/// A vector that holds a run (`BLOCKS` copies of its [`RUN`] lanes) against `BLOCKS`
/// particles of the i-cluster, one per block of lanes.
///
/// # Safety
/// Every method runs the intrinsics of its type: the caller must have its features.
#[cfg(target_arch = "x86_64")]
unsafe trait RunLanes: Lanes {
    const BLOCKS: usize;
    /// The [`RUN`] elements from `p` in every block.
    unsafe fn load_run(p: *const Self::Elem) -> Self;
    /// `x[k]` in every lane of block `k`.
    unsafe fn splat_blocks(x: &[Self::Elem]) -> Self;
    /// `self` in the lanes whose bit of `bits` is set, zeros elsewhere.
    unsafe fn keep_lanes(self, bits: u32) -> Self;
    /// Subtracts the sum of the blocks from the [`RUN`] elements at `p`.
    unsafe fn sub_blocks_from(self, p: *mut Self::Elem);
}

// SAFETY: AVX-512 F and DQ intrinsics, run under `run_avx512`.
#[cfg(target_arch = "x86_64")]
unsafe impl RunLanes for Avx512F32 {
    const BLOCKS: usize = 2;
    #[inline(always)]
    unsafe fn load_run(p: *const f32) -> Self {
        unsafe { Avx512F32(_mm512_broadcast_f32x8(_mm256_loadu_ps(p))) }
    }
    #[inline(always)]
    unsafe fn splat_blocks(x: &[f32]) -> Self {
        unsafe {
            Avx512F32(_mm512_insertf32x8::<1>(
                _mm512_set1_ps(x[0]),
                _mm256_set1_ps(x[1]),
            ))
        }
    }
    #[inline(always)]
    unsafe fn keep_lanes(self, bits: u32) -> Self {
        unsafe { Avx512F32(_mm512_maskz_mov_ps(bits as __mmask16, self.0)) }
    }
    #[inline(always)]
    unsafe fn sub_blocks_from(self, p: *mut f32) {
        unsafe {
            let sum = _mm256_add_ps(
                _mm512_castps512_ps256(self.0),
                _mm512_extractf32x8_ps::<1>(self.0),
            );
            _mm256_storeu_ps(p, _mm256_sub_ps(_mm256_loadu_ps(p), sum));
        }
    }
}

// SAFETY: AVX-512 F intrinsics, run under `run_avx512`.
#[cfg(target_arch = "x86_64")]
unsafe impl RunLanes for Avx512F64 {
    const BLOCKS: usize = 1;
    #[inline(always)]
    unsafe fn load_run(p: *const f64) -> Self {
        unsafe { Self::load(p) }
    }
    #[inline(always)]
    unsafe fn splat_blocks(x: &[f64]) -> Self {
        unsafe { Self::splat(x[0]) }
    }
    #[inline(always)]
    unsafe fn keep_lanes(self, bits: u32) -> Self {
        unsafe { Avx512F64(_mm512_maskz_mov_pd(bits as __mmask8, self.0)) }
    }
    #[inline(always)]
    unsafe fn sub_blocks_from(self, p: *mut f64) {
        unsafe { Self::load(p).sub(self).store(p) }
    }
}

// SAFETY: AVX and AVX2 intrinsics, run under `run_avx2`.
#[cfg(target_arch = "x86_64")]
unsafe impl RunLanes for Avx2F32 {
    const BLOCKS: usize = 1;
    #[inline(always)]
    unsafe fn load_run(p: *const f32) -> Self {
        unsafe { Self::load(p) }
    }
    #[inline(always)]
    unsafe fn splat_blocks(x: &[f32]) -> Self {
        unsafe { Self::splat(x[0]) }
    }
    #[inline(always)]
    unsafe fn keep_lanes(self, bits: u32) -> Self {
        unsafe {
            let lane_bit = _mm256_setr_epi32(1, 2, 4, 8, 16, 32, 64, 128);
            let set = _mm256_and_si256(_mm256_set1_epi32(bits as i32), lane_bit);
            let keep = _mm256_castsi256_ps(_mm256_cmpeq_epi32(set, lane_bit));
            Avx2F32(_mm256_and_ps(keep, self.0))
        }
    }
    #[inline(always)]
    unsafe fn sub_blocks_from(self, p: *mut f32) {
        unsafe { Self::load(p).sub(self).store(p) }
    }
}

/// The i-cluster's coordinates `x` (per axis, per particle), `G = CLUSTER / BLOCKS` vectors
/// per axis.
#[cfg(target_arch = "x86_64")]
#[inline(always)]
unsafe fn splat_cluster<V: RunLanes, const G: usize>(x: &[[V::Elem; CLUSTER]; 3]) -> [[V; 3]; G] {
    // SAFETY: the caller's features.
    std::array::from_fn(|g| {
        std::array::from_fn(|d| unsafe {
            V::splat_blocks(&x[d][g * V::BLOCKS..(g + 1) * V::BLOCKS])
        })
    })
}

/// Adds the forces of the runs of `part` to `out`, each run through its image of `images`:
/// both ends of every pair, each pair once. `G · V::BLOCKS` is [`CLUSTER`], `V::WIDTH` is
/// `V::BLOCKS · RUN`. Runs `V`'s intrinsics: only under `V`'s features (a safe function, so
/// that it inlines into the closures of [`add_on`]).
#[cfg(target_arch = "x86_64")]
#[inline(always)]
fn part_forces<V: RunLanes, const G: usize>(
    lj: &LennardJonesTerms<V::Elem>,
    clusters: &Clusters<'_, V::Elem, 3>,
    part: &Part,
    images: Option<&Images<V::Elem, 3>>,
    out: &mut Out<'_, V::Elem, 3>,
) where
    V::Elem: Real,
{
    debug_assert!(G * V::BLOCKS == CLUSTER && V::WIDTH == V::BLOCKS * RUN);
    let pos = &clusters.pos;
    let unshifted = no_shift::<3>();
    // SAFETY: the caller runs under `V`'s features; every load and store is of a whole run or
    // cluster, taken from a slice of that length first.
    unsafe {
        let lj = LennardJonesLanes::<V>::new(lj);
        let zero = V::splat(V::Elem::zero());
        for (k, c) in part.clusters.clone().enumerate() {
            let ic = c * CLUSTER;
            let xi: [[V::Elem; CLUSTER]; 3] = std::array::from_fn(|d| {
                pos[d][ic..ic + CLUSTER]
                    .try_into()
                    .expect("clusters are whole")
            });
            let xi_lanes = splat_cluster::<V, G>(&xi);
            let mut fi = [[zero; 3]; G];
            for r in part.first[k] as usize..part.first[k + 1] as usize {
                let js = part.start[r] as usize * CLUSTER;
                let masks = &part.masks[r];
                let xj: [V; 3] =
                    std::array::from_fn(|d| V::load_run(pos[d][js..js + RUN].as_ptr()));
                // The i-cluster moved by minus the run's shift: each pair's difference is
                // then the partner's image's.
                let xg = match images {
                    Some(im) if part.shift[r] != unshifted => {
                        let s = im.shift_of(part.shift[r]);
                        splat_cluster::<V, G>(&std::array::from_fn(|d| xi[d].map(|x| x - s[d])))
                    }
                    _ => xi_lanes,
                };
                let mut fj = [zero; 3];
                for g in 0..G {
                    let mut bits = 0u32;
                    for b in 0..V::BLOCKS {
                        bits |= u32::from(masks[g * V::BLOCKS + b]) << (b * RUN);
                    }
                    let dx: [V; 3] = std::array::from_fn(|d| xj[d].sub(xg[g][d]));
                    let r2 = dx[2].mul_add(dx[2], dx[1].mul_add(dx[1], dx[0].mul(dx[0])));
                    let coeff = lj.at(r2).keep_lanes(bits);
                    for d in 0..3 {
                        fi[g][d] = coeff.mul_add(dx[d], fi[g][d]);
                        fj[d] = coeff.mul_add(dx[d], fj[d]);
                    }
                }
                for (d, f) in fj.iter().enumerate() {
                    f.sub_blocks_from(out.run::<RUN>(d, js).as_mut_ptr());
                }
            }
            let mut lanes = [V::Elem::zero(); 16];
            for (g, fg) in fi.iter().enumerate() {
                for (d, f) in fg.iter().enumerate() {
                    f.store(lanes[..V::WIDTH].as_mut_ptr());
                    for b in 0..V::BLOCKS {
                        let block: [V::Elem; RUN] = lanes[b * RUN..(b + 1) * RUN]
                            .try_into()
                            .expect("blocks are runs");
                        out.near[d][ic - out.near_base + g * V::BLOCKS + b] += lane_sum(block);
                    }
                }
            }
        }
    }
}
