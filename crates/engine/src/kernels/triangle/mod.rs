//! The Newton-3 triangle: each pair (i, j) with i < j once, its force added to both ends (the
//! loop of the serial and OpenMP source codes), for the `symmetric` and `per-thread` kernels.
//!
//! The work is given as a range of targets i: each meets every source j > i. Ranges start at
//! multiples of [`GROUP`] (or end at n), so that a range's pairs and its writes are its own:
//! forces of its targets and of every later particle, nothing before its first target. Sources
//! are visited in tiles, every target of the range against one tile before the next, so that
//! the tile's positions and reaction sums stay in cache.
//!
//! The timed path runs the batched loop of [`batched`] (intrinsics, both ends of each pair
//! accumulated in registers) where the law and the CPU have one, and the portable scatter
//! rows of [`rows`](super::rows) otherwise; the probe always runs the rows, which also sum
//! energies and count interactions.

mod batched;

use super::rows::{Exclude, LANES, RowSum, Sources, Target, scatter};
use crate::physics::PairLaw;
use crate::real::Real;
use crate::simd;
use crate::state::State;
use std::ops::Range;

/// Targets per group: target ranges start at multiples of it, a multiple of every vector
/// width and cluster of the batched loop.
pub(crate) const GROUP: usize = 16;

/// Sources per tile of the portable rows: positions, strengths and reaction sums of a tile
/// stay inside L1 (the rows scatter into them one target at a time).
pub(crate) const TILE: usize = 512;

/// Pairs among `k` particles.
fn triangle(k: usize) -> u64 {
    let k = k as u64;
    k * k.saturating_sub(1) / 2
}

/// Pair evaluations of the targets `targets` among `n` particles: each target i meets every
/// j > i.
pub(crate) fn pair_work(n: usize, targets: Range<usize>) -> u64 {
    triangle(n - targets.start) - triangle(n - targets.end)
}

/// Splits `targets` into `parts` consecutive ranges of near-equal pair work, each starting at
/// a multiple of [`GROUP`] (some empty when there are fewer groups than parts). A function of
/// its arguments only, so that the split, and with it every sum, is the same whatever runs it.
pub(crate) fn split(n: usize, targets: Range<usize>, parts: usize) -> Vec<Range<usize>> {
    debug_assert!(targets.start.is_multiple_of(GROUP) || targets.is_empty());
    let parts = parts.max(1);
    let total = pair_work(n, targets.clone());
    let mut ranges = Vec::with_capacity(parts);
    let mut start = targets.start;
    let mut end = start;
    for p in 1..parts {
        let goal = total * p as u64 / parts as u64;
        while end < targets.end && pair_work(n, targets.start..end) < goal {
            end = (end + GROUP).min(targets.end);
        }
        ranges.push(start..end);
        start = end;
    }
    ranges.push(start..targets.end);
    ranges
}

/// Adds the force of every pair (i, j) with i in `targets` and j > i to both ends in `out`
/// (length n each); writes no slot before `targets.start`. The energy and interaction count
/// of the sum come back with `PROBE`.
#[inline(always)]
pub(crate) fn add<T: Real, L: PairLaw<T>, const D: usize, const PROBE: bool>(
    law: &L,
    state: &State<T, D>,
    targets: Range<usize>,
    out: &mut [&mut [T]; D],
) -> RowSum<T, D> {
    if !PROBE && batched::add(law, state, targets.clone(), out) {
        return RowSum::zero();
    }
    simd::dispatch(
        #[inline(always)]
        || rows::<T, L, D, PROBE>(law, state, targets, out),
    )
}

/// [`add`] by the portable scatter rows: one target at a time against a tile's sources.
#[inline(always)]
fn rows<T: Real, L: PairLaw<T>, const D: usize, const PROBE: bool>(
    law: &L,
    state: &State<T, D>,
    targets: Range<usize>,
    out: &mut [&mut [T]; D],
) -> RowSum<T, D> {
    let n = state.len();
    let mut total = RowSum::zero();
    for jlo in (targets.start / TILE * TILE..n).step_by(TILE) {
        let jhi = (jlo + TILE).min(n);
        for i in targets.start..targets.end.min(jhi) {
            // In the tile that holds i, row i meets j > i only. Start the run early enough
            // that it is a whole number of SIMD blocks and mask the sources up to i, instead
            // of finishing every row with a scalar tail (never before the range's first slot,
            // which another range may own).
            let (lo, exclude) = if i >= jlo {
                let len = (jhi - i - 1).next_multiple_of(LANES);
                match jhi
                    .checked_sub(len)
                    .filter(|&lo| lo >= jlo.max(targets.start))
                {
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
    total
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The split covers the targets in order, starts every part at a group, and balances the
    /// pair work to within a group's work.
    #[test]
    fn split_balances_the_triangle() {
        for (n, parts) in [(2000, 16), (2000, 2), (100, 16), (16, 3), (0, 4), (8003, 7)] {
            let ranges = split(n, 0..n, parts);
            assert_eq!(ranges.len(), parts);
            assert_eq!(ranges[0].start, 0);
            assert_eq!(ranges[parts - 1].end, n);
            for w in ranges.windows(2) {
                assert_eq!(w[0].end, w[1].start);
            }
            let total = pair_work(n, 0..n);
            assert_eq!(
                ranges.iter().map(|r| pair_work(n, r.clone())).sum::<u64>(),
                total
            );
            for r in &ranges {
                assert!(r.start.is_multiple_of(GROUP) || r.start == n, "{n} {r:?}");
                let group = pair_work(n, 0..GROUP.min(n));
                assert!(
                    pair_work(n, r.clone()) <= total / parts as u64 + group,
                    "{n} {r:?}"
                );
            }
        }
        assert_eq!(pair_work(5, 0..5), 10);
        assert_eq!(pair_work(5, 3..5), 1);
    }
}
