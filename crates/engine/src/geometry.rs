//! Axis-aligned bounding boxes and Morton keys: the geometry the state, the boundary phase, the
//! kernels and the decompositions share.
//!
//! One rule for NaN and for no input, everywhere: a NaN coordinate is skipped, so the box of
//! points some of which are NaN is the box of the others, and the box of no points is the
//! *empty* box, `lo = +∞` and `hi = −∞` on every axis (an axis whose coordinates are all NaN is
//! empty in the same way). The empty box is the identity of [`Bounds::union`], which is what
//! lets a box be reduced over chunks on any number of threads. Infinite coordinates are kept:
//! detecting a blown-up system is the boundary phase's job, not the box's. A caller that wants
//! something else for an empty or non-finite box (a unit box, a unit cube) says so where it
//! calls.
//!
//! Minima and maxima are written as compare-and-select rather than `min`/`max`: NaN fails every
//! comparison, so it is skipped for free, and the loops compile to vector compares.

use crate::real::Real;

/// An axis-aligned box `[lo, hi]`, possibly empty (see the module doc).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Bounds<T, const D: usize> {
    /// Lower corner: the smallest coordinate on each axis.
    pub lo: [T; D],
    /// Upper corner: the largest coordinate on each axis.
    pub hi: [T; D],
}

/// The empty box, the identity of [`Bounds::union`].
impl<T: Real, const D: usize> Default for Bounds<T, D> {
    fn default() -> Self {
        Self::empty()
    }
}

/// Independent minima per axis in [`Bounds::of_columns`], so that the scan vectorizes.
const LANES: usize = 16;

impl<T: Real, const D: usize> Bounds<T, D> {
    /// The box of no points: `lo = +∞`, `hi = −∞`.
    #[inline(always)]
    pub fn empty() -> Self {
        Bounds {
            lo: [T::infinity(); D],
            hi: [T::neg_infinity(); D],
        }
    }

    /// The box of points given as one column of coordinates per axis (a state's layout).
    #[inline(always)]
    pub(crate) fn of_columns(columns: [&[T]; D]) -> Self {
        let mut b = Self::empty();
        for (d, xs) in columns.into_iter().enumerate() {
            (b.lo[d], b.hi[d]) = range_of(xs);
        }
        b
    }

    /// The box of points given one by one.
    #[inline(always)]
    pub fn of_points(points: impl IntoIterator<Item = [T; D]>) -> Self {
        let mut b = Self::empty();
        for p in points {
            b.extend(p);
        }
        b
    }

    /// Grows the box to hold `p` (NaN coordinates are skipped).
    #[inline(always)]
    pub fn extend(&mut self, p: [T; D]) {
        for d in 0..D {
            self.lo[d] = smaller(p[d], self.lo[d]);
            self.hi[d] = larger(p[d], self.hi[d]);
        }
    }

    /// The smallest box holding both.
    #[inline(always)]
    pub(crate) fn union(self, other: Self) -> Self {
        Bounds {
            lo: std::array::from_fn(|d| smaller(other.lo[d], self.lo[d])),
            hi: std::array::from_fn(|d| larger(other.hi[d], self.hi[d])),
        }
    }

    /// Whether some axis holds no point (`lo > hi` there).
    pub fn is_empty(&self) -> bool {
        (0..D).any(|d| self.lo[d] > self.hi[d])
    }

    /// The same box in f64 (exact: f32 widens without rounding).
    pub(crate) fn to_f64(self) -> Bounds<f64, D> {
        Bounds {
            lo: self.lo.map(T::as_f64),
            hi: self.hi.map(T::as_f64),
        }
    }

    /// The midpoint of each axis.
    pub(crate) fn center(&self) -> [T; D] {
        let half = T::of(0.5);
        std::array::from_fn(|d| half * (self.lo[d] + self.hi[d]))
    }

    /// The longest extent `hi − lo` over the axes; 0 for a point or an empty box.
    pub(crate) fn longest_side(&self) -> T {
        (0..D)
            .map(|d| self.hi[d] - self.lo[d])
            .fold(T::zero(), |a, b| larger(b, a))
    }

    /// The cube a tree is built over: the lower corner and the longest side, or a side of 1
    /// when the box is a point or empty (any positive side serves one position). An infinite
    /// side stays infinite.
    pub fn cube(&self) -> ([T; D], T) {
        let side = self.longest_side();
        (self.lo, if side > T::zero() { side } else { T::one() })
    }
}

/// Lowest and highest value of `xs` skipping NaN, `(+∞, −∞)` when none.
#[inline(always)]
fn range_of<T: Real>(xs: &[T]) -> (T, T) {
    let mut l = [T::infinity(); LANES];
    let mut h = [T::neg_infinity(); LANES];
    let chunks = xs.chunks_exact(LANES);
    for &x in chunks.remainder() {
        l[0] = smaller(x, l[0]);
        h[0] = larger(x, h[0]);
    }
    for c in chunks {
        for k in 0..LANES {
            l[k] = smaller(c[k], l[k]);
            h[k] = larger(c[k], h[k]);
        }
    }
    let (mut lo, mut hi) = (T::infinity(), T::neg_infinity());
    for k in 0..LANES {
        lo = smaller(l[k], lo);
        hi = larger(h[k], hi);
    }
    (lo, hi)
}

/// `x` if it is below `than`, else `than` (so a NaN `x` is skipped).
#[inline(always)]
fn smaller<T: Real>(x: T, than: T) -> T {
    if x < than { x } else { than }
}

/// `x` if it is above `than`, else `than` (so a NaN `x` is skipped).
#[inline(always)]
fn larger<T: Real>(x: T, than: T) -> T {
    if x > than { x } else { than }
}

/// Bits of a Morton key per axis in `dim` dimensions: as many as fit in 63 bits, at most 31
/// (21 in 3-D, 31 in 2-D); 0 for `dim = 0`.
pub(crate) const fn morton_bits(dim: usize) -> u32 {
    match 63usize.checked_div(dim) {
        Some(bits) if bits < 31 => bits as u32,
        Some(_) => 31,
        None => 0,
    }
}

/// Interleaves cell coordinates into a Morton key: bit `b` of axis `d` goes to bit `D·b + d`,
/// so that the top `D` bits of a `morton_bits(D)`-level key are the root's child index. Bits of
/// a coordinate beyond `morton_bits(D)` are dropped.
#[inline(always)]
pub(crate) fn interleave<const D: usize>(cell: [u64; D]) -> u64 {
    match D {
        2 => spread2(cell[0]) | spread2(cell[1]) << 1,
        3 => spread3(cell[0]) | spread3(cell[1]) << 1 | spread3(cell[2]) << 2,
        _ => {
            let mut key = 0;
            for b in 0..morton_bits(D) {
                for (d, &c) in cell.iter().enumerate() {
                    key |= ((c >> b) & 1) << (D as u32 * b + d as u32);
                }
            }
            key
        }
    }
}

/// The cell coordinates of the low `levels` Morton digits of `key` (the inverse of
/// [`interleave`] for cells below `2^levels` per axis).
pub(crate) fn deinterleave<const D: usize>(key: u64, levels: u32) -> [u64; D] {
    let mut cell = [0u64; D];
    for b in 0..levels {
        for (d, c) in cell.iter_mut().enumerate() {
            *c |= ((key >> (D as u32 * b + d as u32)) & 1) << b;
        }
    }
    cell
}

/// Spreads the low 31 bits of `x` to the even bits.
#[inline(always)]
fn spread2(x: u64) -> u64 {
    let mut x = x & 0x7fff_ffff;
    x = (x | x << 16) & 0x0000_ffff_0000_ffff;
    x = (x | x << 8) & 0x00ff_00ff_00ff_00ff;
    x = (x | x << 4) & 0x0f0f_0f0f_0f0f_0f0f;
    x = (x | x << 2) & 0x3333_3333_3333_3333;
    (x | x << 1) & 0x5555_5555_5555_5555
}

/// Spreads the low 21 bits of `x` to every third bit.
#[inline(always)]
fn spread3(x: u64) -> u64 {
    let mut x = x & 0x1f_ffff;
    x = (x | x << 32) & 0x001f_0000_0000_ffff;
    x = (x | x << 16) & 0x001f_0000_ff00_00ff;
    x = (x | x << 8) & 0x100f_00f0_0f00_f00f;
    x = (x | x << 4) & 0x10c3_0c30_c30c_30c3;
    (x | x << 2) & 0x1249_2492_4924_9249
}

#[cfg(test)]
mod tests;
