//! Parts of one force computation, for drivers that split it between processes (MPI ranks):
//! a contiguous block of targets, or a share of the pair work.

use std::ops::Range;

/// Share `index` of `count` equal shares of a computation.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Share {
    /// Which share, from 0; always below `count`.
    pub index: usize,
    /// Shares the computation is split into (the MPI ranks).
    pub count: usize,
}

impl Share {
    /// The share `index` of `count`; `None` unless `index < count`.
    pub fn new(index: usize, count: usize) -> Option<Share> {
        (index < count).then_some(Share { index, count })
    }

    /// This share's block of `0..n`: contiguous blocks whose sizes differ by at most one, the
    /// first `n % count` blocks one larger (the LJ-box assignment's `partition_problem`). Blocks are empty
    /// when `n < count`.
    pub fn block(&self, n: usize) -> Range<usize> {
        let (each, left) = (n / self.count, n % self.count);
        let start = self.index * each + self.index.min(left);
        start..start + each + usize::from(self.index < left)
    }

    /// Every share's block of `0..n`, in order.
    pub fn blocks(n: usize, count: usize) -> Vec<Range<usize>> {
        (0..count)
            .map(|index| Share { index, count }.block(n))
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn blocks_tile_the_range_and_differ_by_at_most_one() {
        for n in [0, 1, 3, 7, 10, 1001] {
            for count in 1..=6 {
                let blocks = Share::blocks(n, count);
                assert_eq!(blocks.len(), count);
                assert_eq!(blocks[0].start, 0);
                assert_eq!(blocks[count - 1].end, n);
                for w in blocks.windows(2) {
                    assert_eq!(w[0].end, w[1].start);
                }
                let sizes: Vec<usize> = blocks.iter().map(|b| b.len()).collect();
                let (lo, hi) = (sizes.iter().min().unwrap(), sizes.iter().max().unwrap());
                assert!(hi - lo <= 1, "n={n} count={count}: {sizes:?}");
                // The larger blocks come first.
                assert!(sizes.windows(2).all(|w| w[0] >= w[1]), "{sizes:?}");
            }
        }
        assert_eq!(Share::blocks(3, 4)[3], 3..3);
        assert_eq!(Share::new(4, 4), None);
    }
}
