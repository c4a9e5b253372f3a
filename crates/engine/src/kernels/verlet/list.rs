//! The neighbour list: for each row (a target particle), the slots of its partners within the
//! list radius, found in the stencil of its bin. A list is made of parts, each built and
//! evaluated as a unit (one per chunk of work a thread takes), so that neither the build nor
//! the force loop ever copies entries from one buffer into another.

use super::bins::Bins;
use crate::kernels::cell_list::strips::position;
use crate::kernels::images::{crosses_slowest_axis, no_shift};
use crate::kernels::rows::LANES;
use crate::real::Real;
use std::ops::Range;

/// Which pairs a list holds.
#[derive(Clone, Debug, PartialEq, Eq)]
pub(crate) enum Cover {
    /// Each pair once, for Newton's third law: row `k` is the particle of sorted index `k` and
    /// holds its partners in the forward half of its stencil — later in its own row of bins,
    /// and in the rows of bins after it.
    Half,
    /// Every partner of each target slot of the range; the rows follow the slots.
    Targets(Range<usize>),
}

/// One part of a list: the rows `rows`, their entries, and the slots their pairs touch.
#[derive(Default)]
pub(crate) struct Part {
    pub rows: Range<usize>,
    /// Row `rows.start + r` holds the entries `first[r]..first[r + 1]`.
    pub first: Vec<usize>,
    /// Per row: its target's slot.
    pub target: Vec<u32>,
    /// Per entry: the partner's slot, and its target's slot (for the loop over pairs); then
    /// `LANES` entries of padding (slot `span.start`), so that a SIMD block may run past the
    /// last entry.
    pub partner: Vec<u32>,
    pub owner: Vec<u32>,
    /// In a periodic box, per entry (and its padding): the code of the partner's image
    /// ([`super::images`]); empty otherwise.
    pub shift: Vec<u8>,
    /// The lowest slot the part's pairs touch and one past the highest, but for the partners
    /// met across the faces of the slowest axis, which `wrap` covers (far from the rest in bin
    /// order; empty outside a periodic box).
    pub span: Range<usize>,
    pub wrap: Range<usize>,
}

impl Part {
    pub fn entries(&self) -> usize {
        self.first.last().copied().unwrap_or(0)
    }
}

/// Work of a build: candidate pairs whose distance was computed, bins searched (summed over
/// the rows), lists built.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub(crate) struct BuildWork {
    pub candidates: u64,
    pub bins: u64,
    pub rebuilds: u64,
}

impl std::ops::AddAssign for BuildWork {
    fn add_assign(&mut self, other: BuildWork) {
        self.candidates += other.candidates;
        self.bins += other.bins;
        self.rebuilds += other.rebuilds;
    }
}

/// Fills `part` with the rows `rows` of a list of `cover` in an open box (or between walls):
/// the pairs within `sqrt(radius2)` among `bins`, sorted with a side at least that radius;
/// `slots` are the slots' positions (for the targets' rows). Inline so that it is compiled
/// inside `simd::dispatch` with the wide instruction set.
#[inline(always)]
pub fn build<T: Real, const D: usize>(
    bins: &Bins<T, D>,
    slots: [&[T]; D],
    cover: &Cover,
    radius2: f64,
    rows: Range<usize>,
    part: &mut Part,
) -> BuildWork {
    fill::<D>(
        part,
        rows.clone(),
        false,
        // The search is most of a rebuild: inlined like its callers, so that it is compiled
        // with the wide instruction set of the `simd::dispatch` they run in (a closure is
        // otherwise its own function, compiled for the baseline).
        #[inline(always)]
        |out| match cover {
            Cover::Half => half(bins, radius2, rows, out),
            Cover::Targets(t) => targets(bins, slots, t.start, radius2, rows, out),
        },
    )
}

/// Fills `part` with the rows `rows` that `search` writes (each entry with the code of its
/// partner's image when `periodic`), then sets its spans and pads its entries.
#[inline(always)]
pub(super) fn fill<const D: usize>(
    part: &mut Part,
    rows: Range<usize>,
    periodic: bool,
    search: impl FnOnce(&mut Rows<'_>) -> BuildWork,
) -> BuildWork {
    part.rows = rows;
    part.first.clear();
    part.first.push(0);
    part.target.clear();
    part.owner.clear();
    if !periodic {
        part.shift.clear();
    }
    let mut rows_out = Rows {
        part,
        len: 0,
        span: (usize::MAX, 0),
        wrap: (usize::MAX, 0),
        periodic,
    };
    let work = search(&mut rows_out);
    rows_out.finish::<D>();
    work
}

/// The half list's rows `rows` (sorted indices), bin by bin: the runs of a bin's forward
/// stencil are looked up once for all its particles, and the particles of a bin are
/// consecutive rows.
#[inline(always)]
fn half<T: Real, const D: usize>(
    bins: &Bins<T, D>,
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
    // The bin's coordinates, stepped along with it rather than divided out of its index for
    // every bin (a dilute gas has about one particle per two bins).
    let row = b / g.row_len;
    let (mut x, mut y, mut z) = (b % g.row_len, row % g.extent(1), row / g.extent(1));
    let mut k = rows.start;
    while k < rows.end {
        while bins.start[b + 1] as usize <= k {
            b += 1;
            x += 1;
            if x == g.row_len {
                x = 0;
                y += 1;
                if y == g.extent(1) {
                    y = 0;
                    z += 1;
                }
            }
        }
        let mut c = [0; D];
        for (d, v) in [x, y, z].into_iter().take(D).enumerate() {
            c[d] = v;
        }
        let (xa, xb) = g.span(&c, 0);
        let (ya, yb) = g.span(&c, 1);
        let (za, zb) = g.span(&c, 2);
        // The rows of bins after this one in the stencil: (y + 1, z) and (·, z + 1).
        let mut ahead = [(0, 0); 4];
        let mut count = 0;
        for zz in za..=zb {
            for yy in ya..=yb {
                if zz > z || (zz == z && yy > y) {
                    ahead[count] = bins.run(xa, xb, yy, zz);
                    count += 1;
                }
            }
        }
        // In its own row a particle's search starts after itself: the pairs with the
        // particles before it are in their rows.
        let own_end = bins.run(x, xb, y, z).1;
        let bins_searched = (xb + 1 - x + count * (xb + 1 - xa)) as u64;
        let end = (bins.start[b + 1] as usize).min(rows.end);
        for k in k..end {
            let mut xk = [0.0; D];
            for d in 0..D {
                xk[d] = sorted[d][k].as_f64();
            }
            let before = out.len;
            let mut candidates = scan(bins, &xk, (k + 1, own_end), u32::MAX, radius2, out, None);
            for &run in &ahead[..count] {
                candidates += scan(bins, &xk, run, u32::MAX, radius2, out, None);
            }
            out.row::<D>(bins.order[k] as usize, before);
            work.candidates += candidates as u64;
            work.bins += bins_searched;
        }
        k = end;
    }
    work
}

/// The full lists of the target slots `first + rows`, each from its whole stencil.
#[inline(always)]
fn targets<T: Real, const D: usize>(
    bins: &Bins<T, D>,
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
        let c = g.cell(x);
        let (xa, xb) = g.span(&c, 0);
        let (ya, yb) = g.span(&c, 1);
        let (za, zb) = g.span(&c, 2);
        let before = out.len;
        for zz in za..=zb {
            for yy in ya..=yb {
                let run = bins.run(xa, xb, yy, zz);
                work.candidates += scan(bins, &xi, run, i as u32, radius2, out, None) as u64;
                work.bins += (xb + 1 - xa) as u64;
            }
        }
        out.row::<D>(i, before);
    }
    work
}

/// The rows of a part being written: entries so far, and the spans of the slots they touch
/// (the partners across the slowest axis's faces apart, in a periodic box).
pub(super) struct Rows<'a> {
    part: &'a mut Part,
    len: usize,
    span: (usize, usize),
    wrap: (usize, usize),
    periodic: bool,
}

/// Widens the range `(lo, hi)` to hold slot `j`.
#[inline(always)]
fn widen((lo, hi): &mut (usize, usize), j: usize) {
    *lo = (*lo).min(j);
    *hi = (*hi).max(j + 1);
}

impl Rows<'_> {
    /// Entries written so far.
    #[inline(always)]
    pub(super) fn len(&self) -> usize {
        self.len
    }

    /// Ends the row of target slot `i`, whose entries start at `before`.
    #[inline(always)]
    pub(super) fn row<const D: usize>(&mut self, i: usize, before: usize) {
        let p = &mut *self.part;
        if self.len > before {
            widen(&mut self.span, i);
            let partners = &p.partner[before..self.len];
            if self.periodic {
                for (&j, &code) in partners.iter().zip(&p.shift[before..self.len]) {
                    let far = crosses_slowest_axis::<D>(code);
                    widen(
                        if far { &mut self.wrap } else { &mut self.span },
                        j as usize,
                    );
                }
            } else {
                for &j in partners {
                    widen(&mut self.span, j as usize);
                }
            }
        }
        p.target.push(i as u32);
        p.owner.resize(self.len, i as u32);
        p.first.push(self.len);
    }

    /// Sets the spans and pads the entries.
    fn finish<const D: usize>(self) {
        let p = self.part;
        let range = |(lo, hi): (usize, usize)| if lo < hi { lo..hi } else { 0..0 };
        p.span = range(self.span);
        p.wrap = range(self.wrap);
        let pad = p.span.start as u32;
        p.partner.truncate(self.len);
        p.partner.resize(self.len + LANES, pad);
        p.owner.resize(self.len + LANES, pad);
        if self.periodic {
            p.shift.truncate(self.len);
            p.shift.resize(self.len + LANES, no_shift::<D>());
        }
    }
}

/// Appends to the row being written the slots of the sorted particles `lo..hi` within
/// `sqrt(radius2)` of `x`, except slot `skip`; returns the candidates examined. Branch-free:
/// every candidate is written, and the length only advances over those kept. In a periodic
/// box, `x` is the target moved against the image searched, whose `code` every entry records.
#[inline(always)]
pub(super) fn scan<T: Real, const D: usize>(
    bins: &Bins<T, D>,
    x: &[f64; D],
    (lo, hi): (usize, usize),
    skip: u32,
    radius2: f64,
    rows: &mut Rows<'_>,
    code: Option<u8>,
) -> usize {
    if hi <= lo {
        return 0;
    }
    let len = rows.len;
    if let Some(code) = code {
        let shift = &mut rows.part.shift;
        if shift.len() < len + (hi - lo) {
            shift.resize((2 * shift.len()).max(len + hi - lo), 0);
        }
        shift[len..len + (hi - lo)].fill(code);
    }
    let out = &mut rows.part.partner;
    let mut len = rows.len;
    if out.len() < len + (hi - lo) {
        out.resize((2 * out.len()).max(len + hi - lo), 0);
    }
    let order = &bins.order[lo..hi];
    let mut pos: [&[T]; D] = [&[]; D];
    for d in 0..D {
        pos[d] = &bins.pos[d][lo..hi];
    }
    for (m, &j) in order.iter().enumerate() {
        let mut r2 = 0.0;
        for d in 0..D {
            let dx = pos[d][m].as_f64() - x[d];
            r2 += dx * dx;
        }
        out[len] = j;
        len += usize::from(r2 <= radius2 && j != skip);
    }
    rows.len = len;
    hi - lo
}
