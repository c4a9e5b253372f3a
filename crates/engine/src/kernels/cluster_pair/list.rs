//! The cluster-pair list: for each i-cluster, runs of consecutive clusters (`group_of(D)`) that cover
//! every j-cluster at or after it whose box comes within the list radius of its own. The
//! clusters of a column are sorted along the last axis, so in each column the j-clusters within
//! reach are consecutive: the window of the column is found by two binary searches on the
//! boxes, and narrowed by the column's distance along the other axes. A run's clusters outside
//! the window are masked out, so no pair is evaluated twice; pairs inside the window but beyond
//! the cutoff are zeroed by the law.
//!
//! In a periodic box the columns beyond a face are those of the other side, shifted by one
//! side, and along the last axis each column is searched three times (unshifted and shifted
//! by one side either way). A run records its shift (the code of [`crate::kernels::images`]),
//! which the force loop adds to the i-cluster. Each pair of images is listed once: from the
//! lower cluster; between a cluster and its own images, for the shifts of code above the
//! unshifted one only.

use super::layout::{CLUSTER, Layout, group_of};
use crate::kernels::images::{Images, code_of, no_shift};
use crate::real::Real;
use std::ops::Range;

/// The list of a range of i-clusters, built and evaluated as a unit (one per chunk of work a
/// thread takes).
#[derive(Default)]
pub(crate) struct Part {
    pub clusters: Range<usize>,
    /// i-cluster `clusters.start + k` has the runs `first[k]..first[k + 1]`: run `r` is the
    /// clusters `start[r]..start[r] + group_of(D)`, met through the image of code `shift[r]`.
    pub first: Vec<u32>,
    pub start: Vec<u32>,
    pub shift: Vec<u8>,
    /// Per run, for each particle `a` of the i-cluster, the lanes that act (lane `l` is
    /// particle `l % CLUSTER` of cluster `start + l / CLUSTER`).
    pub(crate) masks: Vec<[u16; CLUSTER]>,
    /// One past the highest cluster the part's runs touch near it (the lowest is
    /// `clusters.start`).
    pub end: usize,
    /// In a periodic box, the clusters the runs reach across the faces of the slowest column
    /// axis, when apart from the others (else empty): the last layers, far in cluster order.
    pub far: Range<usize>,
}

impl Part {
    pub fn runs(&self) -> usize {
        self.start.len()
    }
}

/// The lanes of a run from cluster `j0` that act for particle `a` of i-cluster `c` (with
/// `count[c]` particles): clusters below `end`, their real particles, and where the run holds
/// the i-cluster itself unshifted (`diagonal`), only the particles after `a`.
pub(crate) fn run_masks<const D: usize>(
    count: &[u8],
    c: usize,
    j0: usize,
    end: usize,
    diagonal: bool,
) -> [u16; CLUSTER] {
    let group = group_of(D);
    let mut valid = 0u16;
    for q in 0..group {
        let j = j0 + q;
        if j < end {
            valid |= ((1u16 << count[j]) - 1) << (CLUSTER * q);
        }
    }
    std::array::from_fn(|a| {
        if a >= count[c] as usize {
            return 0;
        }
        if diagonal && (j0..j0 + group).contains(&c) {
            // In the i-cluster's own lanes, particles `b <= a` do not act.
            let upto_a = (2u16 << a) - 1;
            valid & !(upto_a << (CLUSTER * (c - j0)))
        } else {
            valid
        }
    })
}

/// The columns along axis `d` that a search for `lo..=hi` visits, each with its wrap (sides
/// shifted) in a periodic box; the one column of an axis without columns (the last, and those
/// past it).
fn axis_columns<T: Real, const D: usize>(
    layout: &Layout<T, D>,
    periodic: bool,
    d: usize,
    lo: f64,
    hi: f64,
) -> impl Iterator<Item = (usize, i8)> + use<T, D> {
    let (n, a, b) = if d + 1 >= D {
        (1, 0, 0)
    } else if periodic {
        let (a, b) = layout.column_span(d, lo, hi);
        (layout.columns[d] as i64, a, b)
    } else {
        let (a, b) = layout.column_range(d, lo, hi);
        (layout.columns[d] as i64, a as i64, b as i64)
    };
    (a..=b).map(move |k| (k.rem_euclid(n) as usize, k.div_euclid(n) as i8))
}

/// Fills `part` with the runs of the i-clusters `clusters`, through the images of `images`
/// when the box is periodic; returns the windows searched.
#[inline(always)]
pub fn build<T: Real, const D: usize>(
    layout: &Layout<T, D>,
    images: Option<&Images<T, D>>,
    radius: f64,
    radius2: f64,
    clusters: Range<usize>,
    part: &mut Part,
) -> u64 {
    part.clusters = clusters.clone();
    part.first.clear();
    part.first.push(0);
    part.start.clear();
    part.shift.clear();
    part.masks.clear();
    part.end = clusters.start;
    // No far run yet: empty, and below every start.
    part.far = Range {
        start: usize::MAX,
        end: 0,
    };
    let last = D - 1;
    let (lo, hi) = (&layout.lo, &layout.hi);
    let starts = &layout.column_start;
    let unshifted = no_shift::<D>();
    let side = images.map_or([0.0; D], |im| im.side64());
    // Shifts along the last axis: none in an open box.
    let along_last: &[i8] = match images {
        Some(_) => &[-1, 0, 1],
        None => &[0],
    };
    let mut searched = 0;
    let emit = |c: usize, from: usize, end: usize, code: u8, far: bool, part: &mut Part| {
        let diagonal = code == unshifted;
        let mut j0 = from;
        while j0 < end {
            part.start.push(j0 as u32);
            part.shift.push(code);
            part.masks
                .push(run_masks::<D>(&layout.count, c, j0, end, diagonal));
            if far {
                part.far.start = part.far.start.min(j0);
                part.far.end = part.far.end.max(j0 + group_of(D));
            } else {
                part.end = part.end.max(j0 + group_of(D));
            }
            j0 += group_of(D);
        }
    };
    // The column of the first i-cluster, then stepped along with it.
    let mut own = starts.partition_point(|&s| s as usize <= clusters.start) - 1;
    // Per column and image searched from the current column: its window for the last
    // i-cluster, at the column's offset from the current one (within `around` columns along
    // each axis) and shift along the last axis.
    let around = (0..last)
        .map(|d| (radius / layout.width[d]).ceil() as i64 + 2)
        .max()
        .unwrap_or(0);
    let across = (2 * around + 1) as usize;
    let unset = (usize::MAX, usize::MAX);
    let mut cursors = vec![unset; across * across * along_last.len()];
    let stride = layout.columns[0];
    let cursor_of = |own: usize, k: [(usize, i8); 2], w_last: usize| {
        let offset = |d: usize| {
            let n = layout.columns[d.min(last)] as i64;
            let at = (own / [1, stride][d] % n as usize) as i64;
            (k[d].0 as i64 + i64::from(k[d].1) * n - at + around) as usize
        };
        let (o0, o1) = (
            offset(0),
            if last > 1 { offset(1) } else { around as usize },
        );
        (o0 < across && o1 < across).then(|| (o1 * across + o0) * along_last.len() + w_last)
    };
    for c in clusters {
        while starts[own + 1] as usize <= c {
            own += 1;
            cursors.fill(unset);
        }
        let lo_i: [f64; D] = std::array::from_fn(|d| lo[d][c]);
        let hi_i: [f64; D] = std::array::from_fn(|d| hi[d][c]);
        // Columns along the (at most two) axes before the last.
        let span = |d: usize| {
            let (a, b) = match d < last {
                true => (lo_i[d] - radius, hi_i[d] + radius),
                false => (0.0, 0.0),
            };
            axis_columns(layout, images.is_some(), d, a, b)
        };
        for (k1, w1) in span(1) {
            for (k0, w0) in span(0) {
                let column = k1 * stride + k0;
                if column < own {
                    continue;
                }
                let wraps = [w0, w1];
                // The reach along the last axis left by the column's distance along the others.
                let mut gap2 = 0.0;
                for d in 0..last {
                    let shift = f64::from(wraps[d]) * side[d];
                    let gap = (layout.column_lo[d][column] + shift - hi_i[d])
                        .max(lo_i[d] - layout.column_hi[d][column] - shift)
                        .max(0.0);
                    gap2 += gap * gap;
                }
                if gap2 > radius2 {
                    continue;
                }
                let reach = (radius2 - gap2).sqrt();
                let (s, e) = (starts[column] as usize, starts[column + 1] as usize);
                // Crossing the faces of the slowest column axis reaches the far layers.
                let far = D >= 2 && wraps[D.saturating_sub(2).min(1)] != 0;
                for (z, &w_last) in along_last.iter().enumerate() {
                    let wrap: [i8; D] = std::array::from_fn(|d| match d {
                        d if d == last => w_last,
                        d => wraps[d],
                    });
                    let code = code_of(wrap);
                    let shift = f64::from(w_last) * side[last];
                    let (below, above) = (lo_i[last] - reach - shift, hi_i[last] + reach - shift);
                    if w_last != 0 && (s == e || above < lo[last][s] || below > hi[last][e - 1]) {
                        // An image along the last axis that the column's clusters do not
                        // reach: most i-clusters, away from the two faces.
                        continue;
                    }
                    // The window of the last i-cluster of this column in `column`, moved to
                    // this one's: the i-clusters of a column come in order along the last
                    // axis, so the windows move a few clusters at a time.
                    let at = cursor_of(own, [(k0, w0), (k1, w1)], z);
                    let (mut from, mut end) = match at.map(|k| cursors[k]) {
                        Some(w) if w != unset => w,
                        _ => {
                            let from = s + hi[last][s..e].partition_point(|&h| h < below);
                            (from, from)
                        }
                    };
                    while from > s && hi[last][from - 1] >= below {
                        from -= 1;
                    }
                    while from < e && hi[last][from] < below {
                        from += 1;
                    }
                    end = end.max(from);
                    while end > from && lo[last][end - 1] > above {
                        end -= 1;
                    }
                    while end < e && lo[last][end] <= above {
                        end += 1;
                    }
                    if let Some(k) = at {
                        cursors[k] = (from, end);
                    }
                    if column == own {
                        // The i-cluster meets itself unshifted (each pair once, by the
                        // masks) and through half of its images.
                        let first = if code >= unshifted { c } else { c + 1 };
                        from = from.max(first);
                        end = end.max(from);
                    }
                    // The window's ends whose own boxes lie beyond the radius: the column's
                    // extent bounded them only along the other axes, and loosely.
                    let offset: [f64; D] = std::array::from_fn(|d| f64::from(wrap[d]) * side[d]);
                    let beyond = |j: usize| {
                        let mut g2 = 0.0;
                        for d in 0..D {
                            let g = (lo[d][j] + offset[d] - hi_i[d])
                                .max(lo_i[d] - hi[d][j] - offset[d])
                                .max(0.0);
                            g2 += g * g;
                        }
                        g2 > radius2
                    };
                    while from < end && beyond(from) {
                        from += 1;
                    }
                    while end > from && beyond(end - 1) {
                        end -= 1;
                    }
                    searched += 1;
                    emit(c, from, end, code, far, part);
                }
            }
        }
        part.first.push(part.start.len() as u32);
    }
    if part.far.is_empty() {
        part.far = 0..0;
    } else if part.far.start <= part.end {
        // Not apart: one span holds both.
        part.end = part.end.max(part.far.end);
        part.far = 0..0;
    }
    searched
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::simd::LANES;

    #[test]
    fn a_run_keeps_its_window_real_particles_and_each_pair_once() {
        // Clusters 0..6 with 4, 4, 3, 4, 1, 4 particles.
        let count = [4, 4, 3, 4, 1, 4];
        // i-cluster 0 with itself and the next three: the diagonal keeps b > a.
        let m = run_masks::<2>(&count, 0, 0, 4, true);
        for a in 0..CLUSTER {
            for l in 0..LANES {
                let (j, b) = (l / CLUSTER, l % CLUSTER);
                let want = (j != 0 || b > a) && b < count[j] as usize;
                assert_eq!((m[a] >> l) & 1 == 1, want, "a {a} lane {l}");
            }
        }
        // A window ending at cluster 2: clusters 2.. do not act.
        let m = run_masks::<2>(&count, 4, 1, 2, true);
        assert_eq!(
            m[0], 0b1111,
            "only cluster 1 acts, for particle 0 of cluster 4"
        );
        assert_eq!(m[1], 0, "cluster 4 has one particle");
        // Padding of cluster 2 (3 particles) does not act.
        let m = run_masks::<2>(&count, 5, 2, 6, true);
        assert_eq!(m[0] & 0b1111, 0b0111);
    }
}
