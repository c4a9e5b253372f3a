//! The bins of a list build: the cell list's grid (bins of side ≥ the list radius over the
//! particles' bounding box) and the particles counting-sorted by bin.
//!
//! After a sort, bin `b` holds the sorted indices `start[b]..start[b + 1]`. Bins are numbered
//! row-major with a phantom bin ending each row, so the bins `x−1 ..= x+1` of one row are a
//! single run of sorted indices: the stencil of a bin is `3^(D−1)` runs.

use crate::kernels::cell_list::grid::{Grid, bounding_box};
use crate::kernels::cell_list::strips::position;
use crate::real::Real;
use crate::state::State;

pub struct Bins<T, const D: usize> {
    pub grid: Grid<D>,
    /// First sorted index of every bin (phantom bins included), then `n`.
    pub start: Vec<u32>,
    /// Slot of every sorted index: the particles in bin order.
    pub order: Vec<u32>,
    /// Positions in bin order, so that the search reads its candidates contiguously.
    pub pos: [Vec<T>; D],
    /// Per slot: its bin, and its rank among the particles of its bin (scratch of the sort).
    bin: Vec<u32>,
    rank: Vec<u32>,
}

impl<T: Real, const D: usize> Bins<T, D> {
    pub fn new() -> Self {
        Bins {
            grid: Grid::new([0.0; D], [0.0; D], 1.0, 0),
            start: Vec::new(),
            order: Vec::new(),
            pos: std::array::from_fn(|_| Vec::new()),
            bin: Vec::new(),
            rank: Vec::new(),
        }
    }

    /// Sorts the particles of `state` into bins of side ≥ `radius`. Buffers only grow, so
    /// rebuilds of a run allocate nothing after the first. Inline so that it is compiled inside
    /// `simd::dispatch` with the wide instruction set.
    #[inline(always)]
    pub fn sort(&mut self, state: &State<T, D>, radius: f64) {
        let n = state.len();
        let (lo, hi) = bounding_box(state);
        self.grid = Grid::new(lo.map(|x| x.as_f64()), hi.map(|x| x.as_f64()), radius, n);
        let g = &self.grid;
        self.bin.resize(n, 0);
        self.rank.resize(n, 0);
        self.start.clear();
        self.start.resize(g.bins() + 1, 0);
        let pos: [&[T]; D] = std::array::from_fn(|d| &state.pos[d][..n]);
        let bin = &mut self.bin[..n];
        for i in 0..n {
            bin[i] = g.bin(&g.cell(position(&pos, i))) as u32;
        }
        for (&b, rank) in bin.iter().zip(self.rank.iter_mut()) {
            let count = &mut self.start[b as usize];
            *rank = *count;
            *count += 1;
        }
        let mut next = 0u32;
        for s in self.start.iter_mut() {
            let count = *s;
            *s = next;
            next += count;
        }
        self.order.resize(n, 0);
        for (i, (&b, &k)) in bin.iter().zip(&self.rank).enumerate() {
            self.order[(self.start[b as usize] + k) as usize] = i as u32;
        }
        for d in 0..D {
            self.pos[d].clear();
            self.pos[d].extend(self.order.iter().map(|&i| pos[d][i as usize]));
        }
    }

    /// Takes `state` as sorted already when its positions are exactly the sorted ones (it was
    /// permuted by the order of the last sort, as the engine does with the order
    /// `spatial_order` hands out): the bins stay valid and the order becomes the identity, so
    /// the rebuild after a re-ordering does not bin twice.
    pub fn adopt(&mut self, state: &State<T, D>) -> bool {
        let n = state.len();
        let same = self.order.len() == n && (0..D).all(|d| state.pos[d][..] == self.pos[d][..]);
        if same {
            for (k, o) in self.order.iter_mut().enumerate() {
                *o = k as u32;
            }
        }
        same
    }

    /// Sorted indices of the bins `xa..=xb` of the row holding bin coordinates `(·, y, z)`.
    #[inline(always)]
    pub fn run(&self, xa: usize, xb: usize, y: usize, z: usize) -> (usize, usize) {
        let g = &self.grid;
        let first = (z * g.extent(1) + y) * g.row_len;
        (
            self.start[first + xa] as usize,
            self.start[first + xb + 1] as usize,
        )
    }
}
