//! The cluster-pair list: for each i-cluster, runs of `GROUP` consecutive clusters that cover
//! every j-cluster at or after it whose box comes within the list radius of its own. The
//! clusters of a column are sorted along the last axis, so in each column the j-clusters within
//! reach are consecutive: the window of the column is found by two binary searches on the
//! boxes, and narrowed by the column's distance along the other axes. A run's clusters outside
//! the window are masked out, so no pair is evaluated twice; pairs inside the window but beyond
//! the cutoff are zeroed by the law.

use super::layout::{CLUSTER, GROUP, Layout};
use crate::real::Real;
use std::ops::Range;

/// The list of a range of i-clusters, built and evaluated as a unit (one per chunk of work a
/// thread takes).
#[derive(Default)]
pub(crate) struct Part {
    pub clusters: Range<usize>,
    /// i-cluster `clusters.start + k` has the runs `first[k]..first[k + 1]`: run `r` is the
    /// clusters `start[r]..start[r] + GROUP`.
    pub first: Vec<u32>,
    pub start: Vec<u32>,
    /// Per run, for each particle `a` of the i-cluster, the lanes that act (lane `l` is
    /// particle `l % CLUSTER` of cluster `start + l / CLUSTER`).
    pub(crate) masks: Vec<[u16; CLUSTER]>,
    /// One past the highest cluster the part's runs touch (the lowest is `clusters.start`).
    pub end: usize,
}

impl Part {
    pub fn runs(&self) -> usize {
        self.start.len()
    }
}

/// The lanes of a run from cluster `j0` that act for particle `a` of i-cluster `c`: clusters
/// below `end`, their real particles, and in the i-cluster itself only the particles after `a`.
pub(crate) fn run_masks(count: &[u8], c: usize, j0: usize, end: usize) -> [u16; CLUSTER] {
    let mut valid = 0u16;
    for q in 0..GROUP {
        let j = j0 + q;
        if j < end {
            valid |= ((1u16 << count[j]) - 1) << (CLUSTER * q);
        }
    }
    std::array::from_fn(|a| {
        if a >= count[c] as usize {
            return 0;
        }
        if (j0..j0 + GROUP).contains(&c) {
            // In the i-cluster's own lanes, particles `b <= a` do not act.
            let upto_a = (2u16 << a) - 1;
            valid & !(upto_a << (CLUSTER * (c - j0)))
        } else {
            valid
        }
    })
}

/// Fills `part` with the runs of the i-clusters `clusters`; returns the windows searched.
#[inline(always)]
pub fn build<T: Real, const D: usize>(
    layout: &Layout<T, D>,
    radius: f64,
    radius2: f64,
    clusters: Range<usize>,
    part: &mut Part,
) -> u64 {
    part.clusters = clusters.clone();
    part.first.clear();
    part.first.push(0);
    part.start.clear();
    part.masks.clear();
    part.end = clusters.start;
    let last = D - 1;
    let (lo, hi) = (&layout.lo, &layout.hi);
    let starts = &layout.column_start;
    let mut searched = 0;
    let emit = |c: usize, from: usize, end: usize, part: &mut Part| {
        let mut j0 = from;
        while j0 < end {
            part.start.push(j0 as u32);
            part.masks.push(run_masks(&layout.count, c, j0, end));
            part.end = part.end.max(j0 + GROUP);
            j0 += GROUP;
        }
    };
    // The column of the first i-cluster, then stepped along with it.
    let mut own = starts.partition_point(|&s| s as usize <= clusters.start) - 1;
    // Per column searched from the current column: its window for the last i-cluster.
    let mut cursors: Vec<(usize, usize, usize)> = Vec::new();
    for c in clusters {
        while starts[own + 1] as usize <= c {
            own += 1;
            cursors.clear();
        }
        let lo_i: [f64; D] = std::array::from_fn(|d| lo[d][c]);
        let hi_i: [f64; D] = std::array::from_fn(|d| hi[d][c]);
        // Columns along the (at most two) axes before the last.
        let span = |d: usize| {
            if d < last {
                layout.column_range(d, lo_i[d] - radius, hi_i[d] + radius)
            } else {
                (0, 0)
            }
        };
        let ((a0, b0), (a1, b1)) = (span(0), span(1));
        let stride = layout.columns[0];
        for k1 in a1..=b1 {
            for k0 in a0..=b0 {
                let column = k1 * stride + k0;
                if column < own {
                    continue;
                }
                // The reach along the last axis left by the column's distance along the others.
                let mut gap2 = 0.0;
                for d in 0..last {
                    let gap = (layout.column_lo[d][column] - hi_i[d])
                        .max(lo_i[d] - layout.column_hi[d][column])
                        .max(0.0);
                    gap2 += gap * gap;
                }
                if gap2 > radius2 {
                    continue;
                }
                let reach = (radius2 - gap2).sqrt();
                let (s, e) = (starts[column] as usize, starts[column + 1] as usize);
                let (below, above) = (lo_i[last] - reach, hi_i[last] + reach);
                // The window of the last i-cluster of this column in `column`, moved to this
                // one's: the i-clusters of a column come in order along the last axis, so the
                // windows move a few clusters at a time.
                let at = cursors.iter().position(|w| w.0 == column);
                let (mut from, mut end) = match at {
                    Some(k) => (cursors[k].1, cursors[k].2),
                    None => {
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
                match at {
                    Some(k) => cursors[k] = (column, from, end),
                    None => cursors.push((column, from, end)),
                }
                if column == own {
                    from = from.max(c);
                    end = end.max(from);
                }
                searched += 1;
                emit(c, from, end, part);
            }
        }
        part.first.push(part.start.len() as u32);
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
        let m = run_masks(&count, 0, 0, 4);
        for a in 0..CLUSTER {
            for l in 0..LANES {
                let (j, b) = (l / CLUSTER, l % CLUSTER);
                let want = (j != 0 || b > a) && b < count[j] as usize;
                assert_eq!((m[a] >> l) & 1 == 1, want, "a {a} lane {l}");
            }
        }
        // A window ending at cluster 2: clusters 2.. do not act.
        let m = run_masks(&count, 4, 1, 2);
        assert_eq!(
            m[0], 0b1111,
            "only cluster 1 acts, for particle 0 of cluster 4"
        );
        assert_eq!(m[1], 0, "cluster 4 has one particle");
        // Padding of cluster 2 (3 particles) does not act.
        let m = run_masks(&count, 5, 2, 6);
        assert_eq!(m[0] & 0b1111, 0b0111);
    }
}
