//! The clusters: particles counting-sorted into columns (a grid over every axis but the last),
//! sorted along the last axis within each column, and cut into clusters of `CLUSTER`
//! consecutive particles. Columns are as wide as a cluster is long at the mean density, so a
//! cluster is about as wide as it is tall. Each column starts a new cluster; the slots a short
//! last cluster leaves are padding, which repeats the column's last particle and never acts
//! (the tiles mask it out).
//!
//! Memory, kept between builds: per padded slot its particle and a copy of its position and
//! strength; per particle its padded slot and the sort's scratch; per cluster its bounding box.

use crate::kernels::counting_sort::{CountingSort, order_of};
use crate::par::{Disjoint, gather, pass_chunk, worth_forking};
use crate::real::Real;
use crate::simd::LANES;
use crate::state::State;
use rayon::prelude::*;

/// Particles per cluster.
pub(crate) const CLUSTER: usize = 4;
/// Clusters of a run of the list in `D` dimensions, whose particles are the lanes of one block
/// of the force loop: four (`LANES`) in the plane; in space, where a column's window of
/// clusters within reach is short (about five), two, which leave fewer lanes idle past the
/// window's end.
pub(crate) const fn group_of(d: usize) -> usize {
    if d >= 3 { 2 } else { LANES / CLUSTER }
}
/// The most clusters of a run: the empty clusters after the last are one fewer.
pub(crate) const MAX_GROUP: usize = LANES / CLUSTER;
const _: () = assert!(MAX_GROUP * CLUSTER == LANES && group_of(3) <= MAX_GROUP);

/// The region the columns tile: the particles' bounding box, or a periodic box, whose sides
/// the columns then divide exactly.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Region<const D: usize> {
    pub lo: [f64; D],
    pub hi: [f64; D],
    pub periodic: bool,
}

pub struct Layout<T, const D: usize> {
    /// The grid of columns: origin, widths (along the last axis, the nominal width the sort's
    /// cells are cut from), and columns along each axis but the last.
    origin: [f64; D],
    pub width: [f64; D],
    /// The box's extent along the last axis.
    extent_last: f64,
    pub columns: [usize; D],
    /// First cluster of every column, then the number of clusters.
    pub(crate) column_start: Vec<u32>,
    /// The particles in cluster order (`order[k]` = state slot), padding left out: the order
    /// `spatial_order` hands out.
    pub order: Vec<u32>,
    /// Per padded slot, its particle's state slot; per state slot, its padded slot.
    pub(crate) slot_of: Vec<u32>,
    pub(crate) padded_of: Vec<u32>,
    /// Per column, the extent of its particles along each axis (in f64).
    pub(crate) column_lo: [Vec<f64>; D],
    pub(crate) column_hi: [Vec<f64>; D],
    /// Per cluster: real particles (`CLUSTER` at most; 0 for the empty ones at the end), and
    /// bounding box (in f64).
    pub count: Vec<u8>,
    pub lo: [Vec<f64>; D],
    pub hi: [Vec<f64>; D],
    /// Positions and strengths per padded slot, as of the last refresh.
    pub pos: [Vec<T>; D],
    pub src: Vec<T>,
    column: Vec<u32>,
    place: Vec<u32>,
    start: Vec<u32>,
    sorter: CountingSort,
}

impl<T: Real, const D: usize> Layout<T, D> {
    pub fn new() -> Self {
        Layout {
            origin: [0.0; D],
            width: [1.0; D],
            extent_last: 0.0,
            columns: [1; D],
            column_start: Vec::new(),
            order: Vec::new(),
            slot_of: Vec::new(),
            padded_of: Vec::new(),
            count: Vec::new(),
            column_lo: std::array::from_fn(|_| Vec::new()),
            column_hi: std::array::from_fn(|_| Vec::new()),
            lo: std::array::from_fn(|_| Vec::new()),
            hi: std::array::from_fn(|_| Vec::new()),
            pos: std::array::from_fn(|_| Vec::new()),
            src: Vec::new(),
            column: Vec::new(),
            place: Vec::new(),
            start: Vec::new(),
            sorter: CountingSort::new(),
        }
    }

    pub fn clusters(&self) -> usize {
        self.count.len()
    }

    /// Column of a position: its grid cell over the axes but the last.
    #[inline(always)]
    fn column_of(&self, x: [f64; D]) -> usize {
        let mut c = 0;
        for d in (0..D.saturating_sub(1)).rev() {
            let k = ((x[d] - self.origin[d]) / self.width[d]).max(0.0) as usize;
            c = c * self.columns[d] + k.min(self.columns[d] - 1);
        }
        c
    }

    /// The columns along axis `d` that the interval `lo..=hi` overlaps, clamped to the grid.
    pub(crate) fn column_range(&self, d: usize, lo: f64, hi: f64) -> (usize, usize) {
        let last = self.columns[d] - 1;
        let a = ((lo - self.origin[d]) / self.width[d]).max(0.0) as usize;
        let b = ((hi - self.origin[d]) / self.width[d]).max(0.0) as usize;
        (a.min(last), b.min(last))
    }

    /// The columns along axis `d` of a periodic box that the interval `lo..=hi` overlaps,
    /// counted on past the faces (below 0 and from `columns[d]` on: images).
    pub(crate) fn column_span(&self, d: usize, lo: f64, hi: f64) -> (i64, i64) {
        let at = |x: f64| ((x - self.origin[d]) / self.width[d]).floor() as i64;
        (at(lo), at(hi))
    }

    /// Sorts the particles at `pos` (with strengths `src`) into clusters over columns that
    /// tile `region`, no narrower than a quarter of `radius` (so a search spans a few columns
    /// at most), and fills the padded copy.
    pub fn build(&mut self, pos: [&[T]; D], src: &[T], region: Region<D>, radius: f64) {
        self.grid(region, radius, src.len());
        self.sort(pos);
        self.cut();
        self.refresh(pos, src);
        self.boxes();
        self.column_extents();
    }

    /// Chooses the columns: as wide as a cluster is long at the box's mean density, and at most
    /// a few per particle (an elongated box or a sparse one widens them). In a periodic box as
    /// many whole columns as fit along each side, stretched to tile it.
    fn grid(&mut self, region: Region<D>, radius: f64, n: usize) {
        let Region { lo, hi, periodic } = region;
        let extent: [f64; D] = std::array::from_fn(|d| (hi[d] - lo[d]).max(0.0));
        let volume: f64 = extent.iter().map(|e| e.max(radius * 1e-3)).product();
        let mut width = (CLUSTER as f64 * volume / n.max(1) as f64)
            .powf(1.0 / D as f64)
            .max(0.25 * radius);
        if !width.is_finite() {
            width = radius;
        }
        let cap = 4 * n + 64;
        loop {
            let mut total = 1usize;
            for d in 0..D {
                self.columns[d] = match (d + 1 < D, periodic) {
                    (false, _) => 1,
                    (true, false) => (extent[d] / width) as usize + 1,
                    (true, true) => ((extent[d] / width) as usize).max(1),
                };
                total = total.saturating_mul(self.columns[d]);
            }
            if total <= cap {
                break;
            }
            width *= 2.0;
        }
        self.origin = lo;
        self.width = std::array::from_fn(|d| match d + 1 < D && periodic {
            true => extent[d] / self.columns[d] as f64,
            false => width,
        });
        self.extent_last = extent[D - 1];
    }

    /// Counting sort by cell (a column cut along the last axis into cells half as long as the
    /// column is wide), then each column sorted along the last axis by insertion, which moves
    /// a particle only within its cell (ties by slot, so the order does not depend on the
    /// thread count).
    fn sort(&mut self, pos: [&[T]; D]) {
        let n = pos[0].len();
        let columns: usize = self.columns.iter().product();
        let cell = 0.5 * self.width[D - 1];
        let (base, extent) = (self.origin[D - 1], self.extent_last);
        let cells = ((extent / cell) as usize + 1)
            .min((4 * n + 64) / columns.max(1))
            .max(1);
        let mut key = std::mem::take(&mut self.column);
        key.resize(n, 0);
        let fill = |offset: usize, out: &mut [u32]| {
            for (k, c) in out.iter_mut().enumerate() {
                let x: [f64; D] = std::array::from_fn(|d| pos[d][offset + k].as_f64());
                let along = (((x[D - 1] - base) / cell).max(0.0) as usize).min(cells - 1);
                *c = (self.column_of(x) * cells + along) as u32;
            }
        };
        if worth_forking(n * D) {
            let chunk = pass_chunk(n);
            key.par_chunks_mut(chunk)
                .enumerate()
                .for_each(|(k, out)| fill(k * chunk, out));
        } else {
            fill(0, &mut key);
        }
        self.column = key;
        self.sorter.sort(
            &self.column,
            columns * cells,
            &mut self.start,
            &mut self.place,
        );
        order_of(&self.place, &mut self.order);
        // Column `c` is the cells `c * cells..(c + 1) * cells`.
        let bounds: Vec<u32> = (0..=columns).map(|c| self.start[c * cells]).collect();
        self.start.clear();
        self.start.extend_from_slice(&bounds);
        let last = pos[D - 1];
        let by_last = |run: &mut [u32]| {
            let key = |s: u32| (last[s as usize].as_f64(), s);
            for i in 1..run.len() {
                let v = run[i];
                let kv = key(v);
                let mut j = i;
                while j > 0
                    && kv
                        .0
                        .total_cmp(&key(run[j - 1]).0)
                        .then(kv.1.cmp(&run[j - 1]))
                        .is_lt()
                {
                    run[j] = run[j - 1];
                    j -= 1;
                }
                run[j] = v;
            }
        };
        let mut runs = Vec::with_capacity(columns);
        let mut rest = &mut self.order[..];
        for c in 0..columns {
            let len = (self.start[c + 1] - self.start[c]) as usize;
            let (run, tail) = rest.split_at_mut(len);
            runs.push(run);
            rest = tail;
        }
        if worth_forking(n) {
            runs.into_par_iter().for_each(by_last);
        } else {
            runs.into_iter().for_each(by_last);
        }
    }

    /// Cuts each column into clusters: the padded slots, their particles and counts; then
    /// `GROUP - 1` empty clusters, so that a run of `GROUP` clusters may start at any one.
    fn cut(&mut self) {
        let n = self.order.len();
        let columns: usize = self.columns.iter().product();
        self.column_start.clear();
        let mut clusters = 0;
        for c in 0..columns {
            self.column_start.push(clusters as u32);
            clusters += ((self.start[c + 1] - self.start[c]) as usize).div_ceil(CLUSTER);
        }
        self.column_start.push(clusters as u32);
        self.slot_of.resize((clusters + MAX_GROUP - 1) * CLUSTER, 0);
        self.count.resize(clusters + MAX_GROUP - 1, 0);
        self.padded_of.resize(n, 0);
        // Each column's clusters, as their own slices, filled on the pool's threads.
        let mut pieces = Vec::with_capacity(columns);
        let mut slots = &mut self.slot_of[..clusters * CLUSTER];
        let mut counts = &mut self.count[..clusters];
        for c in 0..columns {
            let m = (self.column_start[c + 1] - self.column_start[c]) as usize;
            let (s, rest) = std::mem::take(&mut slots).split_at_mut(m * CLUSTER);
            slots = rest;
            let (k, rest) = std::mem::take(&mut counts).split_at_mut(m);
            counts = rest;
            pieces.push((c, s, k));
        }
        let padded_of = Disjoint::new(&mut self.padded_of);
        let (order, start, column_start) = (&self.order, &self.start, &self.column_start);
        let fill = |(c, slots, counts): (usize, &mut [u32], &mut [u8])| {
            let run = &order[start[c] as usize..start[c + 1] as usize];
            let base = column_start[c] as usize * CLUSTER;
            for (q, cluster) in run.chunks(CLUSTER).enumerate() {
                let at = q * CLUSTER;
                for (m, &s) in cluster.iter().enumerate() {
                    slots[at + m] = s;
                    // SAFETY: every particle is in one cluster of one column.
                    unsafe { padded_of.write(s as usize, (base + at + m) as u32) };
                }
                let last = *cluster.last().expect("chunks are not empty");
                slots[at + cluster.len()..at + CLUSTER].fill(last);
                counts[q] = cluster.len() as u8;
            }
        };
        if worth_forking(n) {
            pieces.into_par_iter().for_each(fill);
        } else {
            pieces.into_iter().for_each(fill);
        }
        let last = match clusters {
            0 => 0,
            _ => self.slot_of[clusters * CLUSTER - 1],
        };
        self.slot_of[clusters * CLUSTER..].fill(last);
        self.count[clusters..].fill(0);
    }

    /// The clusters that hold particles (the empty ones after them left out).
    pub fn filled(&self) -> usize {
        self.column_start.last().map_or(0, |&c| c as usize)
    }

    /// Copies the positions `pos` and strengths `src` of the state's slots into the padded
    /// slots.
    pub fn refresh(&mut self, pos: [&[T]; D], src: &[T]) {
        for d in 0..D {
            gather(pos[d], &self.slot_of, &mut self.pos[d]);
        }
        gather(src, &self.slot_of, &mut self.src);
    }

    /// The layers of columns across the slowest column axis (the columns of axis `D - 2`, in
    /// the order of the clusters), and the clusters of one layer's columns.
    pub(crate) fn layers(&self) -> usize {
        self.columns[D.saturating_sub(2)]
    }

    /// The first cluster of layer `k` (the number of filled clusters from `layers()` on).
    pub(crate) fn layer_start(&self, k: usize) -> usize {
        let per_layer: usize = self.columns[..D.saturating_sub(2)].iter().product();
        self.column_start[k * per_layer] as usize
    }

    /// Each cluster's bounding box, from the padded copy (padding repeats a real particle).
    fn boxes(&mut self) {
        let m = self.clusters();
        for d in 0..D {
            let pos = &self.pos[d];
            let corner = |c: usize, pick: fn(f64, f64) -> f64| {
                let p = &pos[c * CLUSTER..(c + 1) * CLUSTER];
                p.iter().map(|x| x.as_f64()).reduce(pick).unwrap_or(0.0)
            };
            self.lo[d].clear();
            self.hi[d].clear();
            if worth_forking(m * CLUSTER) {
                (0..m)
                    .into_par_iter()
                    .map(|c| corner(c, f64::min))
                    .collect_into_vec(&mut self.lo[d]);
                (0..m)
                    .into_par_iter()
                    .map(|c| corner(c, f64::max))
                    .collect_into_vec(&mut self.hi[d]);
            } else {
                self.lo[d].extend((0..m).map(|c| corner(c, f64::min)));
                self.hi[d].extend((0..m).map(|c| corner(c, f64::max)));
            }
        }
    }

    /// Each column's extent, from its clusters' boxes.
    fn column_extents(&mut self) {
        let columns = self.column_start.len() - 1;
        for d in 0..D {
            let (lo, hi) = (&self.lo[d], &self.hi[d]);
            self.column_lo[d].clear();
            self.column_hi[d].clear();
            for c in 0..columns {
                let r = self.column_start[c] as usize..self.column_start[c + 1] as usize;
                self.column_lo[d].push(lo[r.clone()].iter().copied().fold(f64::INFINITY, f64::min));
                self.column_hi[d].push(hi[r].iter().copied().fold(f64::NEG_INFINITY, f64::max));
            }
        }
    }

    /// Rewrites the layout for a state permuted by `order` (`state'[k] = state[order[k]]`), as
    /// the engine does with the order `spatial_order` hands out: the clusters stay, their
    /// particles' slots change. Returns false (nothing changed) unless the positions of
    /// `state` are exactly those the layout expects. On the pool's threads when worth it.
    pub(crate) fn adopt(&mut self, state: &State<T, D>) -> bool {
        let n = state.len();
        if self.order.len() != n {
            return false;
        }
        let (order, padded_of, pos) = (&self.order, &self.padded_of, &self.pos);
        let same = |k: usize| {
            let p = padded_of[order[k] as usize] as usize;
            (0..D).all(|d| state.pos[d][k] == pos[d][p])
        };
        let matches = if worth_forking(n * D) {
            (0..n).into_par_iter().with_min_len(4096).all(same)
        } else {
            (0..n).all(same)
        };
        if !matches {
            return false;
        }
        // Slot `k` now holds the particle of the old slot `order[k]`. The padding keeps its
        // old slots: any particle serves it, its lanes never act.
        let mut moved = Vec::new();
        gather(&self.padded_of, &self.order, &mut moved);
        self.padded_of = moved;
        let slot_of = Disjoint::new(&mut self.slot_of);
        let write = |k: usize, &p: &u32| {
            // SAFETY: every particle has its own padded slot.
            unsafe { slot_of.write(p as usize, k as u32) }
        };
        let identity = |(k, o): (usize, &mut u32)| *o = k as u32;
        if worth_forking(n) {
            self.padded_of
                .par_iter()
                .enumerate()
                .with_min_len(4096)
                .for_each(|(k, p)| write(k, p));
            self.order
                .par_iter_mut()
                .enumerate()
                .with_min_len(4096)
                .for_each(identity);
        } else {
            self.padded_of
                .iter()
                .enumerate()
                .for_each(|(k, p)| write(k, p));
            self.order.iter_mut().enumerate().for_each(identity);
        }
        true
    }
}
