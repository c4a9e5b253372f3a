//! The particles of one step counting-sorted by bin and laid out as *strips*.
//!
//! The stencil of a bin is 3 × 3 bins in 2-D. In plain row-major order those are three runs,
//! one per row; a strip instead interleaves three neighbouring rows column by column: strip `y`
//! holds, for each column `x` in turn, the particles of bins `(x, y−1)`, `(x, y)` and `(x, y+1)`.
//! The whole stencil of bin `(x, y)` is then the single contiguous run of columns `x−1 ..= x+1`
//! of strip `y`, so each target needs one call of the SIMD pair loop (in 3-D, one per plane
//! `z−1 ..= z+1`). Each particle is stored in the 3 strips it belongs to, once per step; the
//! force loop then only reads.
//!
//! After each strip come `pad` sentinel particles far outside the box. A run may be lengthened
//! to a whole number of SIMD blocks: what it gains are columns `x+2…` of its strip (at least one
//! bin width, so at least the cutoff, away along axis 0) or sentinels, which contribute zero.

use super::grid::{Grid, sentinel};
use crate::geometry::Bounds;
use crate::kernels::counting_sort::{CountingSort, order_of};
use crate::kernels::rows::LANES;
use crate::par::{Disjoint, chunk_len, for_chunks, worth_forking};
use crate::real::Real;
use crate::simd;
use crate::state::State;

/// Sentinels after each strip: enough to round any run up to a multiple of `LANES`.
const PAD: usize = LANES - 1;

/// Largest particle count whose strip slots (3 per particle, padding) and bins (≤ 4 per
/// particle) fit in `u32`.
pub(crate) const MAX_PARTICLES: usize = 1 << 29;

pub(crate) struct Strips<T, const D: usize> {
    pub grid: Grid<D>,
    /// Sentinel slots after each strip (0 when runs must not be lengthened).
    pub pad: usize,
    /// Strip positions and source strengths, `LANES` spare slots at the end.
    pub pos: [Vec<T>; D],
    pub src: Vec<T>,
    /// First strip slot of each column, indexed like the bins: entry `(x, y, z)` starts
    /// column `x` of strip `(y, z)`; the phantom column ends the strip.
    pub column: Vec<u32>,
    /// Per particle in state order: its slot in its own strip.
    pub own: Vec<u32>,
    /// Per particle in state order: its rank among the particles of its bin.
    pub rank: Vec<u32>,
    /// Whether the last sort ran on one thread: it then left `rank` filled and `place` stale.
    ranked: bool,
    /// First sorted slot of each bin (phantom bins included), then `n`: the counting sort.
    start: Vec<u32>,
    /// Per particle in state order: its place in bin order.
    place: Vec<u32>,
    sorter: CountingSort,
    /// Per particle in state order: its bin, and its bin coordinate along axis 1.
    bin: Vec<u32>,
    row_y: Vec<u32>,
    /// A position at least `rc` from every particle (for the padding), if representable.
    far: Option<[T; D]>,
}

impl<T: Real, const D: usize> Strips<T, D> {
    pub fn new() -> Self {
        Strips {
            grid: Grid::new([0.0; D], [0.0; D], 1.0, 0),
            pad: 0,
            pos: std::array::from_fn(|_| Vec::new()),
            src: Vec::new(),
            column: Vec::new(),
            own: Vec::new(),
            rank: Vec::new(),
            ranked: false,
            start: Vec::new(),
            place: Vec::new(),
            sorter: CountingSort::new(),
            bin: Vec::new(),
            row_y: Vec::new(),
            far: None,
        }
    }

    /// Bins the particles of `state` (the counting sort), on the pool's threads when they are
    /// many. Buffers only grow, so a run of steps of equal size allocates nothing after the
    /// first.
    pub fn sort(&mut self, state: &State<T, D>, rc: f64) {
        let n = state.len();
        assert!(
            n <= MAX_PARTICLES,
            "the cell list handles at most {MAX_PARTICLES} particles (got {n})"
        );
        let Bounds { lo, hi } = simd::dispatch(
            #[inline(always)]
            || state.bounding_box(),
        );
        self.grid = Grid::new(lo.map(|x| x.as_f64()), hi.map(|x| x.as_f64()), rc, n);
        self.far = sentinel(lo, hi, rc);
        self.bin.resize(n, 0);
        self.row_y.resize(n, 0);
        self.rank.resize(n, 0);
        self.ranked = !worth_forking(n * D);
        if self.ranked {
            simd::dispatch(
                #[inline(always)]
                || self.count(state),
            );
            return;
        }
        let pos: [&[T]; D] = std::array::from_fn(|d| &state.pos[d][..n]);
        bin_all(&self.grid, pos, [&mut self.bin[..n], &mut self.row_y[..n]]);
        self.sorter.sort(
            &self.bin,
            self.grid.bins(),
            &mut self.start,
            &mut self.place,
        );
    }

    /// The one-thread sort in two passes: the bin of every particle (vectorizable), then its
    /// rank inside its bin while counting (a histogram), and the first slot of each bin. It
    /// leaves ranks rather than places: the strip layout needs only those, and the two-level
    /// sort's extra pass over the particles and the bins measured a tenth of a dilute gas's
    /// step at n = 2000.
    #[inline(always)]
    fn count(&mut self, state: &State<T, D>) {
        let (g, n) = (&self.grid, state.len());
        let bins = g.bins();
        self.start.clear();
        self.start.resize(bins + 1, 0);
        let pos: [&[T]; D] = std::array::from_fn(|d| &state.pos[d][..n]);
        bins_of(g, &pos, 0, [&mut self.bin[..n], &mut self.row_y[..n]]);
        let counts = &mut self.start[..bins];
        for (&b, rank) in self.bin[..n].iter().zip(&mut self.rank[..n]) {
            let count = &mut counts[b as usize];
            *rank = *count;
            *count += 1;
        }
        let mut next = 0u32;
        for s in counts.iter_mut() {
            let count = *s;
            *s = next;
            next += count;
        }
        self.start[bins] = n as u32;
    }

    /// Fills the strips with the particles sorted by `sort`.
    pub fn fill(&mut self, state: &State<T, D>) {
        // Padding costs `PAD` slots per strip; when strips are nearly empty (a line-like
        // configuration) that would dwarf the particles, so runs are left as they are.
        let n = state.len();
        self.pad = if self.far.is_some() && (self.grid.rows + 1) * PAD <= n + 1024 {
            PAD
        } else {
            0
        };
        simd::dispatch(
            #[inline(always)]
            || self.columns(),
        );
        self.place(state);
        if let Some(far) = self.far.filter(|_| self.pad > 0) {
            self.fill_padding(far);
        }
    }

    /// Expected candidate pairs of a step: each particle sees 3^D bins of mean occupancy.
    pub(crate) fn expected_candidates(&self) -> u64 {
        let n = self.bin.len() as f64;
        let bins: usize = self.grid.dims.iter().product();
        (n * (n * 3f64.powi(D as i32) / bins as f64).min(n)) as u64
    }

    /// First strip slot of every column: the strip's base plus, for each of its rows, the
    /// row's particles before that column.
    #[inline(always)]
    fn columns(&mut self) {
        let g = &self.grid;
        let (row_len, ny) = (g.row_len, g.extent(1));
        self.column.resize(g.bins(), 0);
        let start = &self.start;
        let mut base = 0u32;
        for (s, column) in self.column.chunks_exact_mut(row_len).enumerate() {
            let y = s % ny;
            let rows = (s - y + y.saturating_sub(1))..=(s - y + (y + 1).min(ny - 1));
            column.fill(base);
            for r in rows {
                let row = &start[r * row_len..(r + 1) * row_len];
                for (c, &st) in column.iter_mut().zip(row) {
                    *c += st - row[0];
                }
            }
            base = column[row_len - 1] + self.pad as u32;
        }
        let len = base as usize + LANES;
        for d in 0..D {
            self.pos[d].resize(len, T::zero());
        }
        self.src.resize(len, T::zero());
    }

    /// Copies every particle into the strips of its own row and of the rows above and below,
    /// on the pool's threads when the particles are many. Inside a column the particles are
    /// ordered by row, then by rank.
    fn place(&mut self, state: &State<T, D>) {
        let n = state.len();
        self.own.resize(n, 0);
        let to = Layout {
            grid: &self.grid,
            start: &self.start,
            column: &self.column,
            bin: &self.bin[..n],
            // Stale (possibly shorter than `n`) after a one-thread sort, and then unread.
            place: if self.ranked { &[] } else { &self.place[..n] },
            row_y: &self.row_y[..n],
            pos: std::array::from_fn(|d| &state.pos[d][..n]),
            source: &state.source[..n],
            out_pos: self.pos.each_mut().map(|v| Disjoint::new(v.as_mut_slice())),
            out_src: Disjoint::new(self.src.as_mut_slice()),
        };
        let out = [&mut self.own[..n], &mut self.rank[..n]];
        if self.ranked {
            simd::dispatch(
                #[inline(always)]
                || to.place::<true>(0, out),
            );
            return;
        }
        let run = |offset: usize, out: [&mut [u32]; 2]| {
            simd::dispatch(
                #[inline(always)]
                || to.place::<false>(offset, out),
            )
        };
        if worth_forking(n * D) {
            for_chunks(out, 0, chunk_len(n).max(4096), &run);
        } else {
            run(0, out);
        }
    }

    /// Writes sentinels after every strip.
    fn fill_padding(&mut self, far: [T; D]) {
        let row_len = self.grid.row_len;
        for s in 0..self.grid.rows {
            let end = self.column[s * row_len + row_len - 1] as usize;
            for d in 0..D {
                self.pos[d][end..end + self.pad].fill(far[d]);
            }
            self.src[end..end + self.pad].fill(T::zero());
        }
    }

    /// The particles in bin order, as `order[new_slot] = old_slot` (valid after `sort`).
    pub fn order(&self) -> Vec<u32> {
        let mut order = Vec::new();
        if self.ranked {
            order.resize(self.bin.len(), 0);
            for (i, (&b, &k)) in self.bin.iter().zip(&self.rank).enumerate() {
                order[(self.start[b as usize] + k) as usize] = i as u32;
            }
        } else {
            order_of(&self.place, &mut order);
        }
        order
    }
}

/// What placing the particles in the strips reads, and the strips it writes.
struct Layout<'a, T, const D: usize> {
    grid: &'a Grid<D>,
    start: &'a [u32],
    column: &'a [u32],
    bin: &'a [u32],
    place: &'a [u32],
    row_y: &'a [u32],
    pos: [&'a [T]; D],
    source: &'a [T],
    out_pos: [Disjoint<'a, T>; D],
    out_src: Disjoint<'a, T>,
}

impl<T: Real, const D: usize> Layout<'_, T, D> {
    /// Places the particles `offset..offset + own.len()`: their own slot goes to `own`, their
    /// copies to the strips. Their ranks are read from `rank` when `RANKED`, else computed
    /// from their places and written there.
    #[inline(always)]
    fn place<const RANKED: bool>(&self, offset: usize, [own, rank]: [&mut [u32]; 2]) {
        let (g, start, column) = (self.grid, self.start, self.column);
        let (row_len, ny) = (g.row_len, g.extent(1));
        for k in 0..own.len() {
            let i = offset + k;
            let x = position(&self.pos, i);
            let s = self.source[i];
            let y = self.row_y[i] as usize;
            let b = self.bin[i] as usize;
            let r = if RANKED {
                rank[k]
            } else {
                let r = self.place[i] - start[b];
                rank[k] = r;
                r
            };
            // Particles of the rows below in the same column of the same strip.
            let below1 = if y >= 1 { count(start, b - row_len) } else { 0 };
            let below2 = if y >= 2 {
                count(start, b - 2 * row_len)
            } else {
                0
            };
            let slot = column[b] + below1 + r;
            own[k] = slot;
            self.put(slot, &x, s);
            if y + 1 < ny {
                // The lowest row of strip y + 1.
                self.put(column[b + row_len] + r, &x, s);
            }
            if y >= 1 {
                // The highest row of strip y − 1.
                self.put(column[b - row_len] + below1 + below2 + r, &x, s);
            }
        }
    }

    /// Stores a particle in strip slot `slot`.
    #[inline(always)]
    fn put(&self, slot: u32, x: &[T; D], s: T) {
        let slot = slot as usize;
        // SAFETY: every particle has its own slot in each of its three strips (the bins'
        // counts leave room for exactly their particles, and a particle's rank is its own),
        // so no slot is written twice.
        unsafe {
            for d in 0..D {
                self.out_pos[d].write(slot, x[d]);
            }
            self.out_src.write(slot, s);
        }
    }
}

/// Particles in bin `b`.
#[inline(always)]
fn count(start: &[u32], b: usize) -> u32 {
    start[b + 1] - start[b]
}

/// Writes the bin of every particle of `pos` into `out[0]`, and with two outputs its bin
/// coordinate along axis 1 into `out[1]`; on the pool's threads when the particles are many,
/// each chunk compiled for the selected instruction set.
pub(crate) fn bin_all<T: Real, const D: usize, const K: usize>(
    g: &Grid<D>,
    pos: [&[T]; D],
    out: [&mut [u32]; K],
) {
    let n = out[0].len();
    let run = |offset: usize, out: [&mut [u32]; K]| {
        simd::dispatch(
            #[inline(always)]
            || bins_of(g, &pos, offset, out),
        )
    };
    if worth_forking(n * D) {
        for_chunks(out, 0, chunk_len(n).max(4096), &run);
    } else {
        run(0, out);
    }
}

#[inline(always)]
fn bins_of<T: Real, const D: usize, const K: usize>(
    g: &Grid<D>,
    pos: &[&[T]; D],
    offset: usize,
    out: [&mut [u32]; K],
) {
    for k in 0..out[0].len() {
        let c = g.cell(position(pos, offset + k));
        out[0][k] = g.bin(&c) as u32;
        if K > 1 {
            out[1][k] = c.get(1).copied().unwrap_or(0) as u32;
        }
    }
}

/// Position of particle `i` (a loop rather than `State::position`'s `array::from_fn`, whose
/// closure may stay out of line and so miss the caller's instruction set).
#[inline(always)]
pub fn position<T: Real, const D: usize>(pos: &[&[T]; D], i: usize) -> [T; D] {
    let mut x = [T::zero(); D];
    for d in 0..D {
        x[d] = pos[d][i];
    }
    x
}
