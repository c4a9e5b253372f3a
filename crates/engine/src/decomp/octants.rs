//! Domains from the octants of the root cube (quadrants in 2-D), the gravity source's scheme.
//!
//! The root cube is cut into `2^level` cells per axis, numbered in Morton order (the octree's
//! own key order, so a rank's cells are a run of the tree's sorted bodies). Each rank owns a
//! contiguous run of cells:
//!
//! - `p = 2^(D·k)` ranks (8^k in 3-D, 4^k in 2-D, p = 1 included): the level-k cells, one per
//!   rank in Morton order, whatever the bodies do — the source's scheme as it stands;
//! - any other p: the cells of the first level with at least p cells, refined by
//!   [`REFINE`] more levels, dealt out as contiguous runs whose body counts are as close to
//!   `n/p` as cell boundaries allow. A run may hold no body, or no cell at all when there are
//!   more ranks than cells (the finest level is capped at [`MAX_CELLS`]).
//!
//! Cells are half-open `[lo, hi)` and the cube's top walls belong to the last cells, so every
//! point has exactly one owner; the owner test compares against the same cell faces as the
//! boxes, so the two never disagree at a face.

use super::{Aabb, DomainError, Domains};
use crate::geometry::Bounds;
use crate::geometry::{deinterleave, interleave};
use crate::real::Real;
use std::ops::Range;

/// Levels added below the first level with at least p cells when the runs are balanced: 2^(2D)
/// cells per rank on average, so a run's count is within a few per cent of n/p on smooth data.
pub(crate) const REFINE: u32 = 2;

/// The most cells a level may have (2^21: a 16 MiB histogram), which bounds the refinement.
pub(crate) const MAX_CELLS: u64 = 1 << 21;

/// The rank assignment of the cells of one level of the root cube.
#[derive(Clone, Debug, PartialEq)]
pub struct Octants<const D: usize> {
    lo: [f64; D],
    side: f64,
    level: u32,
    /// Rank r owns the Morton cells `starts[r]..starts[r + 1]`; `starts[p]` is the cell count.
    starts: Vec<u64>,
}

/// The bounding cube of the bodies as the octree computes it: the lower corner of their
/// bounding box and its longest side (1 when the bodies coincide or there are none).
pub fn root_cube<T: Real, const D: usize>(pos: &[Vec<T>; D]) -> ([f64; D], f64) {
    let (lo, side) = Bounds::of_columns(pos.each_ref().map(Vec::as_slice))
        .to_f64()
        .cube();
    // Unlike the octree, which lets a non-finite cube put every key at 0, the cells need
    // finite faces: no bodies (an empty box), or a corner or side at infinity, give the unit
    // cube at the origin.
    if !lo.iter().all(|x| x.is_finite()) {
        return ([0.0; D], 1.0);
    }
    (lo, if side.is_finite() { side } else { 1.0 })
}

impl<const D: usize> Octants<D> {
    /// The assignment of the module doc for `ranks` ranks over the cube of corner `lo` and
    /// side `side`, balanced on the bodies `pos` when `ranks` is not a power of 2^D.
    pub fn new<T: Real>(
        lo: [f64; D],
        side: f64,
        ranks: usize,
        pos: &[Vec<T>; D],
    ) -> Result<Self, DomainError> {
        check(lo, side, ranks)?;
        let k = levels_for(ranks, D);
        if cells_at(k, D) == ranks as u64 {
            return Ok(Octants {
                lo,
                side,
                level: k,
                starts: (0..=ranks as u64).collect(),
            });
        }
        Self::balanced(lo, side, ranks, k + REFINE, pos)
    }

    /// Contiguous runs of the cells of `level` (raised to at least p cells, capped at
    /// [`MAX_CELLS`]) whose body counts are closest to `n/p`; equal cell counts without bodies.
    pub fn balanced<T: Real>(
        lo: [f64; D],
        side: f64,
        ranks: usize,
        level: u32,
        pos: &[Vec<T>; D],
    ) -> Result<Self, DomainError> {
        check(lo, side, ranks)?;
        let mut level = level.max(levels_for(ranks, D));
        while level > 0 && cells_at(level, D) > MAX_CELLS {
            level -= 1;
        }
        let mut octants = Octants {
            lo,
            side,
            level,
            starts: Vec::new(),
        };
        let cells = cells_at(level, D);
        // prefix[c] = bodies in the cells before c.
        let mut prefix = vec![0u64; cells as usize + 1];
        let n = pos.first().map_or(0, Vec::len);
        for i in 0..n {
            let key = octants.key(std::array::from_fn(|d| pos[d][i].as_f64()));
            prefix[key as usize + 1] += 1;
        }
        for c in 0..cells as usize {
            prefix[c + 1] += prefix[c];
        }
        let total = prefix[cells as usize];
        let mut starts = vec![0u64; ranks + 1];
        starts[ranks] = cells;
        for j in 1..ranks {
            let prev = starts[j - 1];
            starts[j] = if total == 0 {
                (cells as u128 * j as u128 / ranks as u128) as u64
            } else {
                // The cell boundary whose prefix is nearest the goal (the later one on a tie).
                let goal = total as f64 * j as f64 / ranks as f64;
                let above = prefix.partition_point(|&c| (c as f64) < goal) as u64;
                let below = above.saturating_sub(1).max(prev);
                let gap = |c: u64| (prefix[c as usize] as f64 - goal).abs();
                if gap(below) < gap(above) {
                    below
                } else {
                    above
                }
            }
            .clamp(prev, cells);
        }
        octants.starts = starts;
        Ok(octants)
    }

    /// Cells per axis are `2^level`.
    pub fn level(&self) -> u32 {
        self.level
    }

    /// The root cube: lower corner and side.
    pub fn cube(&self) -> ([f64; D], f64) {
        (self.lo, self.side)
    }

    /// The Morton indices of the cells of `rank`.
    pub fn cells(&self, rank: usize) -> Range<u64> {
        self.starts[rank]..self.starts[rank + 1]
    }

    /// Lower face of cell row `j` along `axis` (j = 2^level is the top wall).
    fn face(&self, axis: usize, j: u64) -> f64 {
        let per_axis = 1u64 << self.level;
        if j >= per_axis {
            self.lo[axis] + self.side
        } else {
            self.lo[axis] + self.side * j as f64 / per_axis as f64
        }
    }

    /// Morton index of the cell holding `x`, clamped into the cube.
    fn key(&self, x: [f64; D]) -> u64 {
        let per_axis = 1u64 << self.level;
        let scale = per_axis as f64 / self.side;
        let cell: [u64; D] = std::array::from_fn(|a| {
            // `as` saturates (NaN and negatives → 0); the faces then settle rounding.
            let mut j = (((x[a] - self.lo[a]) * scale) as u64).min(per_axis - 1);
            while j > 0 && x[a] < self.face(a, j) {
                j -= 1;
            }
            while j + 1 < per_axis && x[a] >= self.face(a, j + 1) {
                j += 1;
            }
            j
        });
        interleave::<D>(cell)
    }

    /// The cell coordinates of a Morton index (the inverse of `interleave`).
    fn cell_of(&self, key: u64) -> [u64; D] {
        deinterleave::<D>(key, self.level)
    }
}

impl<const D: usize> Domains<D> for Octants<D> {
    fn ranks(&self) -> usize {
        self.starts.len() - 1
    }

    fn owner(&self, x: [f64; D]) -> usize {
        let key = self.key(x);
        // The last rank whose run starts at or before the key: empty runs are skipped.
        self.starts[1..self.starts.len() - 1].partition_point(|&s| s <= key)
    }

    /// The run of cells as its maximal aligned Morton blocks, each a cube of cells.
    fn boxes(&self, rank: usize) -> Vec<Aabb<D>> {
        let Range { mut start, end } = self.cells(rank);
        let mut out = Vec::new();
        while start < end {
            // The largest block 2^(D·j) cells long that starts at `start` and fits the run.
            let mut j = 0;
            while j < self.level
                && start % cells_at(j + 1, D) == 0
                && start + cells_at(j + 1, D) <= end
            {
                j += 1;
            }
            let corner = self.cell_of(start);
            let lo = std::array::from_fn(|a| self.face(a, corner[a]));
            let hi = std::array::from_fn(|a| self.face(a, corner[a] + (1 << j)));
            out.push((lo, hi));
            start += cells_at(j, D);
        }
        out
    }
}

fn check<const D: usize>(lo: [f64; D], side: f64, ranks: usize) -> Result<(), DomainError> {
    if ranks == 0 {
        return Err(DomainError::NoRanks);
    }
    if !(lo.iter().all(|x| x.is_finite()) && side.is_finite() && side > 0.0) {
        return Err(DomainError::BadBox {
            lo: lo.to_vec(),
            hi: lo.iter().map(|x| x + side).collect(),
        });
    }
    Ok(())
}

/// `2^(d·level)` cells.
fn cells_at(level: u32, d: usize) -> u64 {
    1u64 << (d as u32 * level)
}

/// The first level with at least `ranks` cells, capped at [`MAX_CELLS`].
fn levels_for(ranks: usize, d: usize) -> u32 {
    let mut k = 0;
    while cells_at(k, d) < ranks as u64 && cells_at(k + 1, d) <= MAX_CELLS {
        k += 1;
    }
    k
}

#[cfg(test)]
mod tests;
