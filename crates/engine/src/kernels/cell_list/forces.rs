//! The force loop: each target gathers from the runs of its stencil in the strips.

use super::strips::{Strips, position};
use crate::kernels::WorkCounters;
use crate::kernels::rows::{Exclude, LANES, RowSum, Sources, Target, gather_excluding};
use crate::physics::PairLaw;
use crate::real::Real;
use crate::state::State;

/// How many targets ahead the source runs are looked up (see [`targets`]).
const AHEAD: usize = 4;

/// Most runs per target: one per plane of the stencil along axis 2.
const MAX_PLANES: usize = 3;

/// One source run of a target: strip slots `lo..end`, without slot `lo + skip` (the target
/// itself; `usize::MAX` for none).
#[derive(Clone, Copy, Default)]
struct Run {
    lo: usize,
    end: usize,
    skip: usize,
}

/// The runs of one target.
#[derive(Clone, Copy, Default)]
struct Runs {
    runs: [Run; MAX_PLANES],
    planes: usize,
}

/// End of the run `lo..hi`, rounded up to whole SIMD blocks if it has at least one: the extra
/// lanes of the last block cost less than its tail run one pair at a time. The lanes added are
/// columns two or more bins away, or the strip's padding, and contribute zero. A run shorter
/// than a block (a dilute gas) is left alone: there a few scalar pairs are cheaper than a block.
#[inline(always)]
fn widen(lo: usize, hi: usize) -> usize {
    if hi - lo >= LANES {
        lo + (hi - lo).next_multiple_of(LANES)
    } else {
        hi
    }
}

/// Looks up the runs of target `i` (at `x`) and counts its work.
#[inline(always)]
fn lookup<T: Real, const D: usize>(
    strips: &Strips<T, D>,
    x: [T; D],
    i: usize,
    work: &mut WorkCounters,
) -> Runs {
    let g = &strips.grid;
    let cell = g.cell(x);
    let (xa, xb) = g.span(&cell, 0);
    let (ya, yb) = g.span(&cell, 1);
    let (za, zb) = g.span(&cell, 2);
    let y = cell.get(1).copied().unwrap_or(0);
    let z = cell.get(2).copied().unwrap_or(0);
    let own = strips.own[i] as usize;
    let mut r = Runs::default();
    let mut candidates = 0;
    // One run per plane z': columns xa..=xb of strip (y, z').
    for zz in za..=zb {
        let first = (zz * g.extent(1) + y) * g.row_len;
        let lo = strips.column[first + xa] as usize;
        let hi = strips.column[first + xb + 1] as usize;
        candidates += hi - lo;
        r.runs[r.planes] = Run {
            lo,
            end: if strips.pad > 0 { widen(lo, hi) } else { hi },
            skip: if zz == z { own - lo } else { usize::MAX },
        };
        r.planes += 1;
    }
    work.pair_checks += (candidates - 1) as u64;
    // Count each (target bin, neighbour bin) visit once: at the bin's first particle.
    if strips.rank[i] == 0 {
        work.cells_visited += ((xb - xa + 1) * (yb - ya + 1) * (zb - za + 1)) as u64;
    }
    r
}

/// The effect of one run on `t`. A function rather than a closure: a closure left out of line
/// would be compiled for the baseline instruction set instead of the caller's.
#[inline(always)]
fn gather_run<T: Real, L: PairLaw<T>, const D: usize, const PROBE: bool>(
    law: &L,
    t: &Target<T, D>,
    strips: &Strips<T, D>,
    run: &Run,
) -> RowSum<T, D> {
    let src = Sources::range(&strips.pos, &strips.src, run.lo, run.end);
    gather_excluding::<T, L, D, PROBE>(law, t, &src, Exclude::index(run.skip))
}

/// Forces on the particles `offset..offset + out.len()` (state order); returns the energy and
/// interaction count (when probing) and the work done.
///
/// The runs of a target are looked up a few targets before its pairs are computed. The pair
/// loop branches on the run length, which is irregular in a gas; looked up ahead, that length
/// is already in a register when the branch is resolved, rather than behind a load from the bin
/// table (this saves a quarter of the time per particle of a dilute gas at n ≥ 1e5).
#[inline(always)]
pub fn targets<T: Real, L: PairLaw<T>, const D: usize, const PROBE: bool>(
    law: &L,
    strips: &Strips<T, D>,
    state: &State<T, D>,
    offset: usize,
    out: [&mut [T]; D],
) -> (RowSum<T, D>, WorkCounters) {
    let pos: [&[T]; D] = std::array::from_fn(|d| &state.pos[d][..]);
    let mut total = RowSum::zero();
    let mut work = WorkCounters::default();
    let len = out[0].len();
    let mut ahead = [Runs::default(); AHEAD];
    for k in 0..len.min(AHEAD) {
        ahead[k] = lookup(strips, position(&pos, offset + k), offset + k, &mut work);
    }
    for k in 0..len {
        let i = offset + k;
        let r = ahead[k % AHEAD];
        if k + AHEAD < len {
            let next = i + AHEAD;
            ahead[k % AHEAD] = lookup(strips, position(&pos, next), next, &mut work);
        }
        let t = Target {
            x: position(&pos, i),
            s: state.source[i],
        };
        // No loop over the planes: with the pair loop inside a loop nest, LLVM no longer
        // vectorizes it (measured: 3× slower).
        let mut sum = gather_run::<T, L, D, PROBE>(law, &t, strips, &r.runs[0]);
        if D > 2 && r.planes > 1 {
            sum.add(&gather_run::<T, L, D, PROBE>(law, &t, strips, &r.runs[1]));
        }
        if D > 2 && r.planes > 2 {
            sum.add(&gather_run::<T, L, D, PROBE>(law, &t, strips, &r.runs[2]));
        }
        for d in 0..D {
            out[d][k] = sum.force[d];
        }
        total.energy += sum.energy;
        total.interacting += sum.interacting;
    }
    (total, work)
}
