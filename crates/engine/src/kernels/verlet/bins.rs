//! The bins of a list build: the cell list's grid (bins of side ≥ the list radius over the
//! particles' bounding box) and the particles counting-sorted by bin.
//!
//! After a sort, bin `b` holds the sorted indices `start[b]..start[b + 1]`. Bins are numbered
//! row-major with a phantom bin ending each row, so the bins `x−1 ..= x+1` of one row are a
//! single run of sorted indices: the stencil of a bin is `3^(D−1)` runs.

use crate::geometry::Bounds;
use crate::kernels::cell_list::grid::Grid;
use crate::kernels::cell_list::strips::bin_all;
use crate::kernels::counting_sort::{CountingSort, order_of};
use crate::kernels::images::Images;
use crate::par::gather;
use crate::real::Real;
use crate::simd;
use crate::state::State;

pub struct Bins<T, const D: usize> {
    pub grid: Grid<D>,
    /// First sorted index of every bin (phantom bins included), then `n`.
    pub start: Vec<u32>,
    /// Slot of every sorted index: the particles in bin order.
    pub order: Vec<u32>,
    /// Positions in bin order, so that the search reads its candidates contiguously.
    pub pos: [Vec<T>; D],
    /// Per slot: its bin, and its place in bin order (scratch of the sort).
    bin: Vec<u32>,
    place: Vec<u32>,
    sorter: CountingSort,
}

impl<T: Real, const D: usize> Bins<T, D> {
    pub fn new() -> Self {
        Bins {
            grid: Grid::new([0.0; D], [0.0; D], 1.0, 0),
            start: Vec::new(),
            order: Vec::new(),
            pos: std::array::from_fn(|_| Vec::new()),
            bin: Vec::new(),
            place: Vec::new(),
            sorter: CountingSort::new(),
        }
    }

    /// Sorts the particles of `state` into bins of side ≥ `radius`, on the pool's threads when
    /// they are many (the order is the same at any thread count). Buffers only grow, so
    /// rebuilds of a run allocate nothing after the first.
    pub fn sort(&mut self, state: &State<T, D>, radius: f64) {
        let n = state.len();
        let Bounds { lo, hi } = simd::dispatch(
            #[inline(always)]
            || state.bounding_box(),
        );
        let grid = Grid::new(lo.map(|x| x.as_f64()), hi.map(|x| x.as_f64()), radius, n);
        self.sort_on(grid, std::array::from_fn(|d| &state.pos[d][..n]));
    }

    /// Sorts the particles at `wrapped` (inside the periodic box of `images`) into bins of
    /// side ≥ `radius` that tile the box.
    pub fn sort_periodic(&mut self, wrapped: [&[T]; D], images: &Images<T, D>, radius: f64) {
        let n = wrapped[0].len();
        let grid = Grid::periodic(images.lo64(), images.side64(), radius, n);
        self.sort_on(grid, wrapped);
    }

    fn sort_on(&mut self, grid: Grid<D>, pos: [&[T]; D]) {
        let n = pos[0].len();
        self.grid = grid;
        self.bin.resize(n, 0);
        bin_all(&self.grid, pos, [&mut self.bin[..n]]);
        let place = &mut self.place;
        self.sorter
            .sort(&self.bin, self.grid.bins(), &mut self.start, place);
        order_of(place, &mut self.order);
        for d in 0..D {
            gather(pos[d], &self.order, &mut self.pos[d]);
        }
    }

    /// Takes `state` as sorted already when its positions are exactly the sorted ones (it was
    /// permuted by the order of the last sort, as the engine does with the order
    /// `spatial_order` hands out): the bins stay valid and the order becomes the identity, so
    /// the rebuild after a re-ordering does not bin twice.
    pub(crate) fn adopt(&mut self, state: &State<T, D>) -> bool {
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
