//! `symmetric`: each pair once (i < j) with Newton's third law, n(n−1)/2 pair evaluations (the
//! form of the serial source code), single-threaded.
//!
//! The reaction is scattered into the sources' force entries, which is a read-modify-write
//! stream; to keep that stream in L1 the j loop is tiled: targets of one block of `BLOCK`
//! particles meet sources one block at a time.

use super::rows::{Exclude, LANES, RowSum, Sources, Target, scatter};
use super::{ForceKernel, ForceReport, KernelKind, Share, WorkCounters};
use crate::physics::PairLaw;
use crate::real::Real;
use crate::simd;
use crate::state::{Field, State};
use std::ops::Range;

/// Particles per tile: positions, source strength and forces of a tile stay inside L1.
pub(crate) const BLOCK: usize = 512;

/// The `symmetric` kernel: each pair once with Newton's third law, on one thread.
pub struct Symmetric<L> {
    law: L,
}

impl<L> Symmetric<L> {
    /// The kernel for `law`.
    pub fn new(law: L) -> Self {
        Symmetric { law }
    }
}

/// Number of tiles for `n` particles.
pub fn blocks(n: usize) -> usize {
    n.div_ceil(BLOCK)
}

/// Pair evaluations done for target tile `b` (its own triangle plus every later tile).
pub(crate) fn tile_pairs(n: usize, b: usize) -> u64 {
    let lo = b * BLOCK;
    let hi = ((b + 1) * BLOCK).min(n);
    let len = (hi - lo) as u64;
    len * (len.saturating_sub(1)) / 2 + len * (n - hi) as u64
}

/// Splits the target tiles `tiles` into `parts` contiguous ranges of near-equal pair work
/// (some empty when there are fewer tiles than parts).
pub(crate) fn split_tiles(n: usize, tiles: Range<usize>, parts: usize) -> Vec<Range<usize>> {
    let parts = parts.max(1);
    let total: u64 = tiles.clone().map(|b| tile_pairs(n, b)).sum();
    let mut ranges = Vec::with_capacity(parts);
    let (mut start, mut acc) = (tiles.start, 0u64);
    for b in tiles.clone() {
        acc += tile_pairs(n, b);
        let goal = total * (ranges.len() as u64 + 1) / parts as u64;
        if acc >= goal && ranges.len() + 1 < parts {
            ranges.push(start..b + 1);
            start = b + 1;
        }
    }
    ranges.push(start..tiles.end);
    while ranges.len() < parts {
        ranges.push(tiles.end..tiles.end);
    }
    ranges
}

/// The pair work of the target tiles `tiles`.
pub(crate) fn pairs_of(n: usize, tiles: Range<usize>) -> u64 {
    tiles.map(|b| tile_pairs(n, b)).sum()
}

/// Adds the forces of every pair (i, j) with i in target tiles `tiles` and j > i to `out`
/// (length n), both ends of each pair.
#[inline(always)]
pub(crate) fn add_tiles<T: Real, L: PairLaw<T>, const D: usize, const PROBE: bool>(
    law: &L,
    state: &State<T, D>,
    tiles: std::ops::Range<usize>,
    out: &mut [&mut [T]; D],
) -> RowSum<T, D> {
    let n = state.len();
    let mut total = RowSum::zero();
    for bi in tiles {
        let (ilo, ihi) = (bi * BLOCK, ((bi + 1) * BLOCK).min(n));
        for bj in bi..blocks(n) {
            let (jlo, jhi) = (bj * BLOCK, ((bj + 1) * BLOCK).min(n));
            for i in ilo..ihi {
                // On the diagonal tile row i meets j > i only. Start the run early enough that
                // it is a whole number of SIMD blocks and mask the sources up to i, instead of
                // finishing every row with a scalar tail.
                let (lo, exclude) = if bi == bj {
                    let len = (jhi - i - 1).next_multiple_of(LANES);
                    match jhi.checked_sub(len).filter(|&lo| lo >= ilo) {
                        Some(lo) => (lo, Exclude::below(i + 1 - lo)),
                        None => (i + 1, Exclude::NONE),
                    }
                } else {
                    (jlo, Exclude::NONE)
                };
                let t = Target {
                    x: state.position(i),
                    s: state.source[i],
                };
                let src = Sources::range(&state.pos, &state.source, lo, jhi);
                let fsrc: [&mut [T]; D] = {
                    let mut it = out.iter_mut();
                    std::array::from_fn(|_| &mut it.next().expect("D components")[lo..jhi])
                };
                let sum = scatter::<T, L, D, PROBE>(law, &t, &src, fsrc, exclude);
                for d in 0..D {
                    out[d][i] += sum.force[d];
                }
                total.energy += sum.energy;
                total.interacting += sum.interacting;
            }
        }
    }
    total
}

impl<T: Real, L: PairLaw<T>, const D: usize> ForceKernel<T, D> for Symmetric<L> {
    fn kind(&self) -> KernelKind {
        KernelKind::Symmetric
    }

    fn compute(
        &mut self,
        state: &State<T, D>,
        forces: &mut Field<T, D>,
        probe: bool,
    ) -> ForceReport {
        let n = state.len();
        let law = &self.law;
        for f in forces.iter_mut() {
            f.fill(T::zero());
        }
        let mut out = forces.each_mut().map(|f| f.as_mut_slice());
        let tiles = 0..blocks(n);
        let total = if probe {
            simd::dispatch(
                #[inline(always)]
                || add_tiles::<T, L, D, true>(law, state, tiles, &mut out),
            )
        } else {
            simd::dispatch(
                #[inline(always)]
                || add_tiles::<T, L, D, false>(law, state, tiles, &mut out),
            )
        };
        ForceReport {
            energy: probe.then(|| total.energy.as_f64()),
            build_s: 0.0,
            work: WorkCounters {
                pair_checks: (n as u64) * (n.saturating_sub(1) as u64) / 2,
                pairs_interacting: total.interacting,
                ..Default::default()
            },
        }
    }

    /// A balanced share of the target tiles, both ends of each of their pairs.
    fn compute_share(
        &mut self,
        state: &State<T, D>,
        share: Share,
        forces: &mut Field<T, D>,
    ) -> ForceReport {
        let n = state.len();
        let law = &self.law;
        let tiles = split_tiles(n, 0..blocks(n), share.count)[share.index].clone();
        for f in forces.iter_mut() {
            f.fill(T::zero());
        }
        let mut out = forces.each_mut().map(|f| f.as_mut_slice());
        let pair_checks = pairs_of(n, tiles.clone());
        simd::dispatch(
            #[inline(always)]
            || add_tiles::<T, L, D, false>(law, state, tiles, &mut out),
        );
        ForceReport {
            work: WorkCounters {
                pair_checks,
                ..Default::default()
            },
            ..Default::default()
        }
    }
}
