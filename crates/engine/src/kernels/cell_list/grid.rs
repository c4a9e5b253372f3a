//! The bin grid of one step: geometry only.
//!
//! Bins are numbered row-major: axis 0 varies fastest, and a *row* is the run of bins that share
//! their coordinates on the other axes. Each row carries one extra empty *phantom* bin at its end,
//! so that "the end of bin `b`" is always `start[b + 1]`, even for the last bin of a row.
use crate::real::Real;

/// Relative margin of the bin side over the cutoff. The bin of a particle is computed in f64 and
/// the pair distance in `T`; the margin keeps a pair that `T` rounding places just inside the
/// cutoff from landing two bins apart (f32 rounds `r²` by a few parts in 1e7).
pub(super) const SIDE_MARGIN: f64 = 1e-5;

/// Most bins per particle (plus a constant for tiny systems). A dilute gas of side-`rc` bins
/// needs ~3 per particle; a few far-flung particles must not make the grid huge, so beyond this
/// the bins grow (still ≥ rc, so still correct, just more candidates per particle).
const MAX_BINS_PER_PARTICLE: usize = 4;

/// Fewest bins per axis of a periodic grid: with three or more, the 3^D bins around a bin are
/// distinct even through the faces, so a search over them meets every pair once.
pub(crate) const PERIODIC_MIN_BINS: usize = 3;

/// Geometry of the bins for one step.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Grid<const D: usize> {
    lo: [f64; D],
    /// Bins per unit length along each axis (0 on an axis with a single bin).
    inv_side: [f64; D],
    /// Bins along each axis (the phantom bins not included).
    pub dims: [usize; D],
    /// Bins per row including the phantom: `dims[0] + 1`.
    pub(crate) row_len: usize,
    /// Number of rows (product of `dims[1..]`).
    pub rows: usize,
}

impl<const D: usize> Grid<D> {
    /// Bins of side ≥ `rc` over the box `[lo, hi]` holding `n` particles.
    pub fn new(lo: [f64; D], hi: [f64; D], rc: f64, n: usize) -> Self {
        let side_min = rc * (1.0 + SIDE_MARGIN);
        // Bin counts in f64 first: an escaped particle can make extent/side astronomically large.
        let mut want: [f64; D] = std::array::from_fn(|d| {
            let ext = hi[d] - lo[d];
            if ext.is_finite() && ext > 0.0 {
                (ext / side_min).floor().max(1.0)
            } else {
                1.0
            }
        });
        let cap = (MAX_BINS_PER_PARTICLE * n + 64) as f64;
        let total = |w: &[f64; D]| w.iter().product::<f64>() * (w[0] + 1.0) / w[0];
        if total(&want) > cap {
            let shrink = (cap / total(&want)).powf(1.0 / D as f64);
            for w in want.iter_mut() {
                *w = (*w * shrink).floor().max(1.0);
            }
        }
        let mut dims: [usize; D] = want.map(|w| w as usize);
        // The scaling above rounds down, but make the bound exact whatever the rounding did.
        while Self::bins_of(&dims) > cap as usize {
            let big = (0..D).max_by_key(|&d| dims[d]).unwrap_or(0);
            dims[big] = (dims[big] / 2).max(1);
        }
        let inv_side = std::array::from_fn(|d| {
            let ext = hi[d] - lo[d];
            if dims[d] > 1 {
                dims[d] as f64 / ext
            } else {
                0.0
            }
        });
        Grid {
            lo,
            inv_side,
            dims,
            row_len: dims[0] + 1,
            rows: dims[1..].iter().product(),
        }
    }

    /// Bins of side ≥ `rc` that tile the periodic box `[lo, lo + side)` exactly, `n` particles
    /// in it: as many per axis as fit, fewer when a dilute box would have more than
    /// [`MAX_BINS_PER_PARTICLE`] per particle, but never fewer than [`PERIODIC_MIN_BINS`] (the
    /// caller checked that they fit), so that a bin's neighbours through the faces are distinct
    /// bins.
    pub fn periodic(lo: [f64; D], side: [f64; D], rc: f64, n: usize) -> Self {
        let fit = Self::periodic_fit(side, rc);
        let cap = (MAX_BINS_PER_PARTICLE * n + 64) as f64;
        let total: f64 = fit.iter().map(|&w| w as f64).product();
        let shrink = (cap / total).powf(1.0 / D as f64).min(1.0);
        let dims: [usize; D] = std::array::from_fn(|d| {
            ((fit[d] as f64 * shrink).floor() as usize).clamp(PERIODIC_MIN_BINS.min(fit[d]), fit[d])
        });
        Grid {
            lo,
            inv_side: std::array::from_fn(|d| dims[d] as f64 / side[d]),
            dims,
            row_len: dims[0] + 1,
            rows: dims[1..].iter().product(),
        }
    }

    /// Bins of side ≥ `rc` that fit along each side of a periodic box.
    pub fn periodic_fit(side: [f64; D], rc: f64) -> [usize; D] {
        let side_min = rc * (1.0 + SIDE_MARGIN);
        side.map(|s| {
            let w = (s / side_min).floor();
            if w.is_finite() && w >= 1.0 {
                w.min(u32::MAX as f64) as usize
            } else {
                1
            }
        })
    }

    fn bins_of(dims: &[usize; D]) -> usize {
        dims[1..].iter().product::<usize>() * (dims[0] + 1)
    }

    /// Number of bins including the phantom bin of each row.
    pub fn bins(&self) -> usize {
        self.rows * self.row_len
    }

    /// Bin coordinates of a position. The float-to-int cast saturates (negative and NaN give 0)
    /// and the clamp keeps the box maximum inside the last bin.
    #[inline(always)]
    pub fn cell<T: Real>(&self, x: [T; D]) -> [usize; D] {
        // A loop rather than `array::from_fn`, whose closure may stay out of line and so be
        // compiled without the caller's instruction set.
        let mut c = [0; D];
        for d in 0..D {
            let k = ((x[d].as_f64() - self.lo[d]) * self.inv_side[d]) as usize;
            c[d] = k.min(self.dims[d] - 1);
        }
        c
    }

    /// Bins along `axis`, 1 beyond the grid's dimension.
    #[inline(always)]
    pub fn extent(&self, axis: usize) -> usize {
        if axis < D { self.dims[axis] } else { 1 }
    }

    /// Bins `lo..=hi` adjacent to `cell` (itself included) along `axis`; `0..=0` beyond D.
    #[inline(always)]
    pub fn span(&self, cell: &[usize; D], axis: usize) -> (usize, usize) {
        if axis < D {
            let c = cell[axis];
            (c.saturating_sub(1), (c + 1).min(self.dims[axis] - 1))
        } else {
            (0, 0)
        }
    }

    /// Row index of bin coordinates.
    #[inline(always)]
    pub fn row(&self, c: &[usize; D]) -> usize {
        let mut r = 0;
        for d in (1..D).rev() {
            r = r * self.dims[d] + c[d];
        }
        r
    }

    /// Bin index of bin coordinates.
    #[inline(always)]
    pub fn bin(&self, c: &[usize; D]) -> usize {
        self.row(c) * self.row_len + c[0]
    }
}

/// A position at least `rc` from every point of the box `[lo, hi]`, finite so that a zero force
/// coefficient times the separation stays zero; `None` near overflow. Along axis 0 it sits at
/// `|sentinel − x| ≥ |l| + |h| + 4rc`, far above rounding errors; on other axes at `lo`.
pub(crate) fn sentinel<T: Real, const D: usize>(lo: [T; D], hi: [T; D], rc: f64) -> Option<[T; D]> {
    let (l, h) = (lo[0].as_f64(), hi[0].as_f64());
    let far = T::of(l - (2.0 * (l.abs() + h.abs()) + 4.0 * rc));
    let finite = far.is_finite() && lo.iter().all(|x| x.is_finite());
    finite.then(|| std::array::from_fn(|d| if d == 0 { far } else { lo[d] }))
}
