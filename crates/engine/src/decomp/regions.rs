//! The spatial regions of a domain decomposition: which rank owns which part of the box.
//!
//! The box is cut into `dims[0]` columns along axis 0; each column into `dims[1]` blocks along
//! axis 1, with its own cuts; in 3-D each of those into `dims[2]` along axis 2 (a *staggered*
//! grid, as k-d tree codes use). With one cut list per column, rebalancing can give every
//! rank the same particle count, which a plain rectilinear grid cannot when the density
//! varies in two directions at once. `dims = [p, 1]` gives slabs.
//!
//! Regions are half-open boxes `[lo, hi)` (the top wall belongs to the last region), so each
//! point has exactly one owner. Two ranks are *neighbours* when their regions are closer than
//! the ghost width: they exchange ghosts and migrating particles directly. A region may be
//! empty or thinner than the cutoff; ghosts then come from every region within reach, not only
//! the adjacent ones, which the neighbour relation covers because it is geometric.
//!
//! Ranks are numbered in row-major order of their grid coordinates, axis 0 slowest.

use thiserror::Error;

/// Why the regions of a domain decomposition cannot be built.
#[derive(Debug, Error, PartialEq)]
pub enum RegionsError {
    /// The `--rank-grid` factors do not multiply to the number of ranks.
    #[error(
        "rank grid {grid} has {got} regions for {ranks} ranks; give --rank-grid factors whose product is the rank count"
    )]
    GridMismatch {
        /// The grid as given.
        grid: String,
        /// Regions the grid makes.
        got: usize,
        /// Ranks of the run.
        ranks: usize,
    },
    /// A `--rank-grid` that is not `AxB` or `AxBxC` with factors of at least 1; holds the text.
    #[error("rank grid `{0}` is not of the form AxB (2-D) or AxBxC (3-D) with factors >= 1")]
    BadGrid(String),
    /// The box has a non-finite wall or `hi < lo` on some axis.
    #[error("the domain decomposition needs a box with finite walls (got [{lo:?}, {hi:?}])")]
    BadBox {
        /// Lower corner given.
        lo: Vec<f64>,
        /// Upper corner given.
        hi: Vec<f64>,
    },
}

/// The regions of `p = Π dims` ranks over the box `[lo, hi]`.
#[derive(Clone, Debug, PartialEq)]
pub struct Regions<const D: usize> {
    lo: [f64; D],
    hi: [f64; D],
    dims: [usize; D],
    /// Per axis `a`: one list of `dims[a] + 1` cuts for each of the `Π dims[..a]` columns,
    /// concatenated in column order.
    cuts: [Vec<f64>; D],
}

impl<const D: usize> Regions<D> {
    /// Equal-width regions over `[lo, hi]` on the grid `dims`.
    pub fn uniform(lo: [f64; D], hi: [f64; D], dims: [usize; D]) -> Result<Self, RegionsError> {
        let finite = (0..D).all(|a| lo[a].is_finite() && hi[a].is_finite() && hi[a] >= lo[a]);
        if !finite {
            return Err(RegionsError::BadBox {
                lo: lo.to_vec(),
                hi: hi.to_vec(),
            });
        }
        let cuts = std::array::from_fn(|a| {
            let lists: usize = dims[..a].iter().product();
            let one: Vec<f64> = (0..=dims[a])
                .map(|k| {
                    if k == dims[a] {
                        hi[a]
                    } else {
                        lo[a] + (hi[a] - lo[a]) * k as f64 / dims[a] as f64
                    }
                })
                .collect();
            one.repeat(lists)
        });
        Ok(Regions { lo, hi, dims, cuts })
    }

    /// Number of regions, one per rank: the product of the grid's factors.
    pub fn ranks(&self) -> usize {
        self.dims.iter().product()
    }

    /// Regions per axis (the rank grid).
    pub fn dims(&self) -> [usize; D] {
        self.dims
    }

    /// The whole box.
    pub fn bounds(&self) -> ([f64; D], [f64; D]) {
        (self.lo, self.hi)
    }

    /// Grid coordinates of a rank.
    pub(crate) fn coords(&self, rank: usize) -> [usize; D] {
        let mut c = [0; D];
        let mut r = rank;
        for a in (0..D).rev() {
            c[a] = r % self.dims[a];
            r /= self.dims[a];
        }
        c
    }

    /// Index of the column (cut list) that coordinates `c[..axis]` select on `axis`.
    fn column(&self, c: &[usize; D], axis: usize) -> usize {
        (0..axis).fold(0, |acc, a| acc * self.dims[a] + c[a])
    }

    /// The cut list of `axis` in the column of `c`.
    fn cut_list(&self, c: &[usize; D], axis: usize) -> &[f64] {
        let len = self.dims[axis] + 1;
        let col = self.column(c, axis);
        &self.cuts[axis][col * len..(col + 1) * len]
    }

    /// The region of `rank` as (lo, hi).
    pub fn region(&self, rank: usize) -> ([f64; D], [f64; D]) {
        let c = self.coords(rank);
        let mut lo = [0.0; D];
        let mut hi = [0.0; D];
        for a in 0..D {
            let cuts = self.cut_list(&c, a);
            lo[a] = cuts[c[a]];
            hi[a] = cuts[c[a] + 1];
        }
        (lo, hi)
    }

    /// The rank that owns position `x` (points outside the box go to the nearest region).
    pub fn owner(&self, x: [f64; D]) -> usize {
        let mut c = [0; D];
        for a in 0..D {
            let cuts = self.cut_list(&c, a);
            // The last cut not above x: empty regions (equal cuts) are skipped.
            let k = cuts[1..cuts.len() - 1].partition_point(|&cut| cut <= x[a]);
            c[a] = k;
        }
        c.iter()
            .zip(&self.dims)
            .fold(0, |acc, (&ci, &di)| acc * di + ci)
    }

    /// The ranks other than `rank` whose regions are closer than `width` to its region.
    pub fn neighbours(&self, rank: usize, width: f64) -> Vec<usize> {
        let (lo, hi) = self.region(rank);
        (0..self.ranks())
            .filter(|&r| r != rank)
            .filter(|&r| {
                let (l, h) = self.region(r);
                box_distance2(&lo, &hi, &l, &h) < width * width
            })
            .collect()
    }

    /// Particle counts along `axis` in each column (selected by the cuts of the earlier axes),
    /// in `bins` equal bins over the box: `columns × bins` counts, for [`Regions::cut_axis`].
    pub fn histogram<'a>(
        &self,
        axis: usize,
        bins: usize,
        positions: impl Iterator<Item = [f64; D]> + 'a,
    ) -> Vec<u64> {
        let columns: usize = self.dims[..axis].iter().product();
        let mut h = vec![0u64; columns * bins];
        let (lo, ext) = (self.lo[axis], self.hi[axis] - self.lo[axis]);
        for x in positions {
            let owner = self.coords(self.owner(x));
            let col = self.column(&owner, axis);
            let b = if ext > 0.0 {
                (((x[axis] - lo) / ext * bins as f64) as usize).min(bins - 1)
            } else {
                0
            };
            h[col * bins + b] += 1;
        }
        h
    }

    /// Moves the cuts of `axis` so that, in every column, the regions along the axis hold
    /// equal shares of the counts of `histogram` (from [`Regions::histogram`] over all
    /// particles), interpolating inside bins. Call it for axis 0, 1, … in turn, each with a
    /// histogram taken after the previous axis moved.
    pub fn cut_axis(&mut self, axis: usize, histogram: &[u64]) {
        let columns: usize = self.dims[..axis].iter().product();
        let bins = histogram.len() / columns.max(1);
        let k = self.dims[axis];
        let (lo, hi) = (self.lo[axis], self.hi[axis]);
        let width = (hi - lo) / bins.max(1) as f64;
        for col in 0..columns {
            let h = &histogram[col * bins..(col + 1) * bins];
            let total: u64 = h.iter().sum();
            let cuts = &mut self.cuts[axis][col * (k + 1)..(col + 1) * (k + 1)];
            if total == 0 {
                // An empty column: equal widths.
                for (j, c) in cuts.iter_mut().enumerate().take(k).skip(1) {
                    *c = lo + (hi - lo) * j as f64 / k as f64;
                }
                continue;
            }
            let (mut b, mut below) = (0, 0u64);
            for (j, cut) in cuts.iter_mut().enumerate().take(k).skip(1) {
                let goal = total as f64 * j as f64 / k as f64;
                while b < bins && (below + h[b]) as f64 <= goal {
                    below += h[b];
                    b += 1;
                }
                let inside = if b < bins && h[b] > 0 {
                    (goal - below as f64) / h[b] as f64
                } else {
                    0.0
                };
                *cut = (lo + (b as f64 + inside) * width).clamp(lo, hi);
            }
            cuts[0] = lo;
            cuts[k] = hi;
        }
    }
}

/// Squared distance between two boxes (0 when they touch or overlap).
pub(crate) fn box_distance2<const D: usize>(
    lo_a: &[f64; D],
    hi_a: &[f64; D],
    lo_b: &[f64; D],
    hi_b: &[f64; D],
) -> f64 {
    (0..D)
        .map(|d| (lo_b[d] - hi_a[d]).max(lo_a[d] - hi_b[d]).max(0.0).powi(2))
        .sum()
}

/// Squared distance from a point to a box (0 inside).
pub fn point_box_distance2<const D: usize>(x: &[f64; D], lo: &[f64; D], hi: &[f64; D]) -> f64 {
    (0..D)
        .map(|d| (lo[d] - x[d]).max(x[d] - hi[d]).max(0.0).powi(2))
        .sum()
}

/// The rank grid for `ranks` regions of a box with sides `extent`: the factorization with the
/// least total cut area (so the least ghost traffic), more cuts on lower axes on a tie.
pub fn grid_dims<const D: usize>(ranks: usize, extent: [f64; D]) -> [usize; D] {
    let mut best = [1; D];
    best[0] = ranks.max(1);
    let mut best_area = f64::INFINITY;
    for dims in factorizations::<D>(ranks.max(1)) {
        let area: f64 = (0..D)
            .map(|a| {
                let face: f64 = (0..D).filter(|&b| b != a).map(|b| extent[b]).product();
                (dims[a] - 1) as f64 * face
            })
            .sum();
        if area < best_area * (1.0 - 1e-12) {
            best = dims;
            best_area = area;
        }
    }
    best
}

/// Every ordered way of writing `p` as a product of `D` factors, lower axes' factors first
/// largest.
fn factorizations<const D: usize>(p: usize) -> Vec<[usize; D]> {
    fn rec<const D: usize>(p: usize, axis: usize, cur: &mut [usize; D], out: &mut Vec<[usize; D]>) {
        if axis == D - 1 {
            cur[axis] = p;
            out.push(*cur);
            return;
        }
        for f in (1..=p).rev().filter(|f| p.is_multiple_of(*f)) {
            cur[axis] = f;
            rec(p / f, axis + 1, cur, out);
        }
    }
    let mut out = Vec::new();
    rec(p, 0, &mut [1; D], &mut out);
    out
}

/// Parses a rank grid such as `4x1` or `2x2x1` for `D` dimensions and `ranks` ranks.
pub fn parse_grid<const D: usize>(text: &str, ranks: usize) -> Result<[usize; D], RegionsError> {
    let parts: Vec<usize> = text
        .split('x')
        .map(|s| s.trim().parse::<usize>())
        .collect::<Result<_, _>>()
        .map_err(|_| RegionsError::BadGrid(text.into()))?;
    if parts.len() != D || parts.contains(&0) {
        return Err(RegionsError::BadGrid(text.into()));
    }
    let dims: [usize; D] = std::array::from_fn(|a| parts[a]);
    let got = dims.iter().product();
    if got != ranks {
        return Err(RegionsError::GridMismatch {
            grid: text.into(),
            got,
            ranks,
        });
    }
    Ok(dims)
}

#[cfg(test)]
mod tests;
