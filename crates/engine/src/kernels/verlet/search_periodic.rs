//! The search of a Verlet list in a periodic box. The bins tile the box exactly, at least
//! three along each axis ([`crate::kernels::cell_list::grid::Grid::periodic`]), so the 3^D
//! bins around a bin, taken through the faces where the grid ends, are distinct bins: each
//! pair of neighbouring bins is met once. A bin beyond a face is searched as the image of the
//! bin on the opposite side: the target is moved against that image's shift, and every entry
//! found records it.
//!
//! The half list searches each pair of neighbouring bins from the one of lower index. Inside
//! the grid that is the forward stencil of the open box; across the faces of the slowest axis
//! it makes the bins of its first layer the ones that reach into its last, so that a part of
//! the list touches, besides the slots near its rows, at most that last layer (`Part::wrap`).

use super::bins::Bins;
use super::list::{BuildWork, Cover, Part, Rows, fill, scan};
use crate::kernels::cell_list::grid::Grid;
use crate::kernels::cell_list::strips::position;
use crate::kernels::images::{Images, code_of, no_shift};
use crate::real::Real;
use std::ops::Range;

/// A run of bins searched from a bin: the sorted indices `lo..hi` of adjacent bins of one row,
/// the target moved against their image (`-shift`), and the image's code.
#[derive(Clone, Copy)]
struct Run<const D: usize> {
    lo: usize,
    hi: usize,
    against: [f64; D],
    code: u8,
}

/// The runs around one bin, gathered once for all its particles.
struct Around<const D: usize> {
    runs: [Run<D>; 27],
    count: usize,
    /// Bins the runs cover (the search's work counter).
    bins: u64,
}

/// The neighbour of coordinate `c` at offset `o` on an axis of `dims` bins, and the wrap taken
/// (−1 across the lower face, +1 across the upper one).
#[inline(always)]
fn step(c: usize, o: isize, dims: usize) -> (usize, i8) {
    let v = c as isize + o;
    if v < 0 {
        (dims - 1, -1)
    } else if v as usize >= dims {
        (0, 1)
    } else {
        (v as usize, 0)
    }
}

/// The runs of bins around bin `c`: with `half`, those of higher index than `c` (whose pairs
/// with `c` the lower bin owns), else every one of the 3^D, `c` included.
#[inline(always)]
fn around<T: Real, const D: usize>(
    bins: &Bins<T, D>,
    images: &Images<T, D>,
    c: &[usize; D],
    half: bool,
) -> Around<D> {
    let g: &Grid<D> = &bins.grid;
    let own = g.bin(c);
    let empty = Run {
        lo: 0,
        hi: 0,
        against: [0.0; D],
        code: 0,
    };
    let mut out = Around {
        runs: [empty; 27],
        count: 0,
        bins: 0,
    };
    for r in 0..3usize.pow(D as u32 - 1) {
        let mut cc = *c;
        let mut wraps = [0i8; D];
        let mut rest = r;
        for d in 1..D {
            (cc[d], wraps[d]) = step(c[d], (rest % 3) as isize - 1, g.dims[d]);
            rest /= 3;
        }
        let (y, z) = (
            cc.get(1).copied().unwrap_or(0),
            cc.get(2).copied().unwrap_or(0),
        );
        // Along axis 0, bins x−1, x, x+1 of this row, merged where adjacent with one image.
        let mut open: Option<(usize, usize, [i8; D])> = None;
        let close = |(xa, xb, wraps): (usize, usize, [i8; D]), out: &mut Around<D>| {
            let (lo, hi) = bins.run(xa, xb, y, z);
            let shift = images.shift64(wraps);
            out.runs[out.count] = Run {
                lo,
                hi,
                against: shift.map(|s| -s),
                code: code_of(wraps),
            };
            out.count += 1;
            out.bins += (xb + 1 - xa) as u64;
        };
        for o in -1..=1 {
            (cc[0], wraps[0]) = step(c[0], o, g.dims[0]);
            if half && g.bin(&cc) <= own {
                continue;
            }
            open = match open {
                Some((xa, xb, w)) if xb + 1 == cc[0] && w == wraps => Some((xa, cc[0], w)),
                Some(run) => {
                    close(run, &mut out);
                    Some((cc[0], cc[0], wraps))
                }
                None => Some((cc[0], cc[0], wraps)),
            };
        }
        if let Some(run) = open {
            close(run, &mut out);
        }
    }
    out
}

/// The coordinates of bin `b` (phantom bins included: axis 0 runs to `dims[0]`).
fn coordinates<const D: usize>(g: &Grid<D>, b: usize) -> [usize; D] {
    let mut c = [0; D];
    c[0] = b % g.row_len;
    let mut row = b / g.row_len;
    for d in 1..D {
        c[d] = row % g.dims[d];
        row /= g.dims[d];
    }
    c
}

/// Fills `part` with the rows `rows` of a list of `cover` in the periodic box of `images`:
/// [`super::list::build`] through the faces, `slots` the positions of the build wrapped into
/// the box.
#[inline(always)]
pub(super) fn build<T: Real, const D: usize>(
    bins: &Bins<T, D>,
    images: &Images<T, D>,
    slots: [&[T]; D],
    cover: &Cover,
    radius2: f64,
    rows: Range<usize>,
    part: &mut Part,
) -> BuildWork {
    fill::<D>(
        part,
        rows.clone(),
        true,
        // The search is most of a rebuild: inlined like its callers, so that it is compiled
        // with the wide instruction set of the `simd::dispatch` they run in (a closure is
        // otherwise its own function, compiled for the baseline).
        #[inline(always)]
        |out| match cover {
            Cover::Half => half(bins, images, radius2, rows, out),
            Cover::Targets(t) => targets(bins, images, slots, t.start, radius2, rows, out),
        },
    )
}

/// The half list's rows `rows` (sorted indices) in a periodic box, bin by bin: a particle's
/// partners later in its own bin, then in the bins of higher index around it.
#[inline(always)]
fn half<T: Real, const D: usize>(
    bins: &Bins<T, D>,
    images: &Images<T, D>,
    radius2: f64,
    rows: Range<usize>,
    out: &mut Rows<'_>,
) -> BuildWork {
    let mut work = BuildWork::default();
    if rows.is_empty() {
        return work;
    }
    let g = &bins.grid;
    let sorted: [&[T]; D] = std::array::from_fn(|d| &bins.pos[d][..]);
    let mut b = g.bin(&g.cell(position(&sorted, rows.start)));
    let own_code = Some(no_shift::<D>());
    let mut k = rows.start;
    while k < rows.end {
        while bins.start[b + 1] as usize <= k {
            b += 1;
        }
        let c = coordinates(g, b);
        let near = around(bins, images, &c, true);
        let own_end = bins.start[b + 1] as usize;
        let end = own_end.min(rows.end);
        for k in k..end {
            let mut xk = [0.0; D];
            for d in 0..D {
                xk[d] = sorted[d][k].as_f64();
            }
            let before = out.len();
            let mut candidates = scan(
                bins,
                &xk,
                (k + 1, own_end),
                u32::MAX,
                radius2,
                out,
                own_code,
            );
            for run in &near.runs[..near.count] {
                let x: [f64; D] = std::array::from_fn(|d| xk[d] + run.against[d]);
                let span = (run.lo, run.hi);
                candidates += scan(bins, &x, span, u32::MAX, radius2, out, Some(run.code));
            }
            out.row::<D>(bins.order[k] as usize, before);
            work.candidates += candidates as u64;
            work.bins += near.bins + 1;
        }
        k = end;
    }
    work
}

/// The full lists of the target slots `first + rows` (at `slots`, wrapped into the box) in a
/// periodic box, each from the 3^D bins around it.
#[inline(always)]
fn targets<T: Real, const D: usize>(
    bins: &Bins<T, D>,
    images: &Images<T, D>,
    slots: [&[T]; D],
    first: usize,
    radius2: f64,
    rows: Range<usize>,
    out: &mut Rows<'_>,
) -> BuildWork {
    let mut work = BuildWork::default();
    let g = &bins.grid;
    for r in rows {
        let i = first + r;
        let x = position(&slots, i);
        let xi: [f64; D] = x.map(|v| v.as_f64());
        let all = around(bins, images, &g.cell(x), false);
        let before = out.len();
        for run in &all.runs[..all.count] {
            let x: [f64; D] = std::array::from_fn(|d| xi[d] + run.against[d]);
            let span = (run.lo, run.hi);
            work.candidates += scan(bins, &x, span, i as u32, radius2, out, Some(run.code)) as u64;
        }
        work.bins += all.bins;
        out.row::<D>(i, before);
    }
    work
}
