//! What the Verlet list decides from the size of its work, as pure functions: whether a list
//! is split over threads, and whether it must be rebuilt.

use super::bins::Bins;
use super::list::Cover;
use crate::kernels::MIN_PARALLEL_PAIRS;
use crate::real::Real;

/// Most parts of a split list, and fewest rows in one: enough parts that the workers of a
/// colour even out parts of unequal density (the gas of lj-box settles under gravity), wide
/// enough that a part's pairs reach no further than the next part's rows (the colouring of
/// [`crate::kernels::teamed`]).
pub(crate) const PARTS: usize = 16;
pub(crate) const MIN_PART_ROWS: usize = 512;

/// Cost of one list entry and of one row (particle) of a step, the rebuild included (spread
/// over the four steps or so it serves at the default skin), in the naive kernel's pair
/// evaluations (the unit of [`MIN_PARALLEL_PAIRS`]). Measured on one thread of the 2-vCPU AMD
/// EPYC under load (CPU time, n = 1e5): a naive LJ pair 0.22 ns; an entry 4.5 ns in the force
/// loop and 8 ns in a rebuild (liquid); a row 45 ns in a rebuild (gas, where a row has half
/// an entry) and under 1 ns in the force loop (the displacement test, zeroing the forces).
pub(crate) const ENTRY_COST: u64 = 25;
pub(crate) const ROW_COST: u64 = 50;

/// The work of one step over a list of `rows` rows and `entries` entries, in naive pair
/// evaluations.
pub fn step_work(rows: usize, entries: u64) -> u64 {
    (rows as u64)
        .saturating_mul(ROW_COST)
        .saturating_add(entries.saturating_mul(ENTRY_COST))
}

/// Parts to build a list of `rows` rows and `work` in: one (the serial loop) unless the step
/// pays for a split (the rule of `worth_parallel`), else up to [`PARTS`]. Never a function of
/// the threads: the parts fix the order in which forces are added, and so their bits.
pub fn parts_for(rows: usize, work: u64) -> usize {
    if work >= MIN_PARALLEL_PAIRS {
        (rows / MIN_PART_ROWS).clamp(1, PARTS)
    } else {
        1
    }
}

/// The first sorted index of layer `z` of `bins` (`n` past the last layer).
pub(crate) fn layer_start<T, const D: usize>(bins: &Bins<T, D>, z: usize) -> usize {
    let g = &bins.grid;
    let per_layer: usize = g.row_len * g.dims[1..D - 1].iter().product::<usize>();
    bins.start[z * per_layer] as usize
}

/// Entries a list of `cover` over `bins` can have at most: the candidates of the stencils
/// (before the first build, when no earlier list tells).
pub(crate) fn expected_entries<T: Real, const D: usize>(bins: &Bins<T, D>, cover: &Cover) -> u64 {
    let n = bins.order.len() as f64;
    let cells: usize = bins.grid.dims.iter().product();
    let stencil = 3f64.powi(D as i32);
    let (rows, per_row) = match cover {
        Cover::Half => (n, (stencil + 1.0) / 2.0),
        Cover::Targets(t) => (t.len() as f64, stencil),
    };
    (rows * (per_row * n / cells.max(1) as f64).min(n)) as u64
}

/// Whether some slot of `now` lies farther than `sqrt(limit)` from its place in `then` (NaN
/// counts as far), in f64. Blocks of slots with an early exit: a rebuild that is due does not
/// wait for the whole scan.
#[inline(always)]
pub(crate) fn moved_beyond<T: Real, const D: usize>(
    now: [&[T]; D],
    then: [&[T]; D],
    limit: f64,
) -> bool {
    const BLOCK: usize = 2048;
    let n = now[0].len();
    let mut start = 0;
    while start < n {
        let end = (start + BLOCK).min(n);
        let len = end - start;
        let mut d2 = [0.0f64; BLOCK];
        for d in 0..D {
            let (a, b) = (&now[d][start..end], &then[d][start..end]);
            for i in 0..len {
                let dx = a[i].as_f64() - b[i].as_f64();
                d2[i] += dx * dx;
            }
        }
        let mut far = false;
        for &x in &d2[..len] {
            far |= x > limit || x.is_nan();
        }
        if far {
            return true;
        }
        start = end;
    }
    false
}
