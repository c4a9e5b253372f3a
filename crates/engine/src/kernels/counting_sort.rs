//! A stable counting sort of particles by bin, on the pool's threads when the particles are
//! many: the binning of the cell list and of the Verlet list's rebuilds.
//!
//! In parallel it sorts in two levels. The bins are cut into as many consecutive *bands* as
//! the pool has threads. First the particles are partitioned by band, stably: each chunk of
//! particles counts its particles per band, and the counts, summed band by band and chunk by
//! chunk, give every chunk where its particles of each band go. Then each band, on a thread of
//! its own, counting-sorts its particles over its own bins. Both levels keep the particles'
//! index order, so the result is the serial sort's at any thread count; and every pass over
//! the bins (there are more bins than particles in a dilute gas) is split over the threads.

use crate::par::{Disjoint, worth_forking};
use rayon::prelude::*;
use std::ops::Range;

/// Scratch of the sort, kept between calls so that a run of equal sizes allocates once.
#[derive(Default)]
pub(crate) struct CountingSort {
    /// The particles in band order.
    by_band: Vec<u32>,
    /// Per band: its particles' count in each of its bins, then the next place to hand out.
    counts: Vec<Vec<u32>>,
}

impl CountingSort {
    pub fn new() -> Self {
        Self::default()
    }

    /// Sorts the particles `0..bin.len()` by `bin` (every value below `bins`). Fills
    /// `start` with the first place of each bin, then `n` (`bins + 1` values), and `place`
    /// with each particle's place in the sorted order.
    pub fn sort(&mut self, bin: &[u32], bins: usize, start: &mut Vec<u32>, place: &mut Vec<u32>) {
        let n = bin.len();
        assert!(
            n < u32::MAX as usize,
            "{n} particles do not fit 32-bit places"
        );
        place.resize(n, 0);
        start.clear();
        start.resize(bins + 1, 0);
        start[bins] = n as u32;
        let bands = if worth_forking(n) && bins > 1 {
            rayon::current_num_threads().min(bins)
        } else {
            1
        };
        self.counts.resize_with(bands, Vec::new);
        if bands == 1 {
            let out = Disjoint::new(place.as_mut_slice());
            sort_band(
                bin,
                None,
                0..bins,
                0,
                &mut self.counts[0],
                &mut start[..bins],
                &out,
            );
            return;
        }
        let first_bin = |q: usize| q * bins / bands;
        // A band's index counts the bands that start at or before the bin (compares, not a
        // division per particle).
        let firsts: Vec<u32> = (1..bands).map(|q| first_bin(q) as u32).collect();
        let band_of = |b: u32| firsts.iter().map(|&f| usize::from(b >= f)).sum::<usize>();
        // The partition by band: chunk c counts its particles per band ...
        let chunk = |c: usize| c * n / bands..(c + 1) * n / bands;
        let per_chunk: Vec<Vec<u32>> = (0..bands)
            .into_par_iter()
            .map(|c| {
                let mut count = vec![0u32; bands];
                for &b in &bin[chunk(c)] {
                    count[band_of(b)] += 1;
                }
                count
            })
            .collect();
        // ... band q's particles start at `band_start[q]`, chunk c's of them at `next[c][q]` ...
        let mut band_start = vec![0u32; bands + 1];
        let mut next = vec![vec![0u32; bands]; bands];
        let mut at = 0u32;
        for q in 0..bands {
            band_start[q] = at;
            for c in 0..bands {
                next[c][q] = at;
                at += per_chunk[c][q];
            }
        }
        band_start[bands] = at;
        // ... and each chunk writes its particles there in index order.
        self.by_band.resize(n, 0);
        let by_band = Disjoint::new(self.by_band.as_mut_slice());
        next.par_iter_mut().enumerate().for_each(|(c, next)| {
            let r = chunk(c);
            for (i, &b) in r.clone().zip(&bin[r]) {
                let q = band_of(b);
                // SAFETY: the places of band q handed to chunk c follow each other from
                // `next[c][q]` up to the first place of the next chunk's particles of band q.
                unsafe { by_band.write(next[q] as usize, i as u32) };
                next[q] += 1;
            }
        });
        // Each band sorts its particles over its own bins.
        let mut starts = Vec::with_capacity(bands);
        let mut rest = &mut start[..bins];
        for q in 0..bands {
            let (head, tail) = rest.split_at_mut(first_bin(q + 1) - first_bin(q));
            starts.push(head);
            rest = tail;
        }
        let out = Disjoint::new(place.as_mut_slice());
        let by_band = &self.by_band;
        self.counts
            .par_iter_mut()
            .zip(starts.par_iter_mut())
            .enumerate()
            .for_each(|(q, (counts, starts))| {
                let mine = &by_band[band_start[q] as usize..band_start[q + 1] as usize];
                let bins = first_bin(q)..first_bin(q + 1);
                sort_band(bin, Some(mine), bins, band_start[q], counts, starts, &out);
            });
    }
}

/// Counting-sorts the particles `mine` (all of `bin` when `None`), whose bins all lie in
/// `bins`, from place `first` on: `starts` (one per bin of `bins`) receives each bin's first
/// place, `place` each particle's place.
fn sort_band(
    bin: &[u32],
    mine: Option<&[u32]>,
    bins: Range<usize>,
    first: u32,
    counts: &mut Vec<u32>,
    starts: &mut [u32],
    place: &Disjoint<'_, u32>,
) {
    let base = bins.start;
    counts.clear();
    counts.resize(bins.len(), 0);
    match mine {
        Some(mine) => {
            for &i in mine {
                counts[bin[i as usize] as usize - base] += 1;
            }
        }
        None => {
            for &b in bin {
                counts[b as usize - base] += 1;
            }
        }
    }
    let mut next = first;
    for (count, s) in counts.iter_mut().zip(starts.iter_mut()) {
        let c = *count;
        *s = next;
        *count = next;
        next += c;
    }
    let mut put = |i: usize| {
        let slot = &mut counts[bin[i] as usize - base];
        // SAFETY: each particle is given the next place of its bin, and the places of a bin
        // run up to the first place of the next bin: no place is handed out twice (the bands
        // own disjoint ranges of places).
        unsafe { place.write(i, *slot) };
        *slot += 1;
    };
    match mine {
        Some(mine) => mine.iter().for_each(|&i| put(i as usize)),
        None => (0..bin.len()).for_each(put),
    }
}

/// The order of a sort, as `order[place] = particle`, on the pool's threads when worth it.
pub(crate) fn order_of(place: &[u32], order: &mut Vec<u32>) {
    let n = place.len();
    order.resize(n, 0);
    if worth_forking(n) {
        let out = Disjoint::new(order.as_mut_slice());
        place
            .par_iter()
            .enumerate()
            .with_min_len(4096)
            .for_each(|(i, &k)| {
                // SAFETY: the places of a sort are a permutation of 0..n: each is written once.
                unsafe { out.write(k as usize, i as u32) }
            });
    } else {
        for (i, &k) in place.iter().enumerate() {
            order[k as usize] = i as u32;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn serial(bin: &[u32], bins: usize) -> (Vec<u32>, Vec<u32>) {
        let mut start = vec![0u32; bins + 1];
        for &b in bin {
            start[b as usize + 1] += 1;
        }
        for b in 0..bins {
            start[b + 1] += start[b];
        }
        let mut next = start.clone();
        let place = bin
            .iter()
            .map(|&b| {
                next[b as usize] += 1;
                next[b as usize] - 1
            })
            .collect();
        (start, place)
    }

    #[test]
    fn the_sort_is_the_serial_one_at_every_thread_count() {
        let n = 300_000;
        let bins = 70_001;
        // Clustered and empty bins, in a scrambled order.
        let bin: Vec<u32> = (0..n as u64)
            .map(|i| ((i * 2_654_435_761 % 1_000_003) % (bins as u64 / 3) * 2) as u32)
            .collect();
        let (start, place) = serial(&bin, bins);
        for threads in [1, 2, 3, 8] {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            let (mut s, mut p, mut order) = (Vec::new(), Vec::new(), Vec::new());
            pool.install(|| {
                let mut sort = CountingSort::new();
                sort.sort(&bin, bins, &mut s, &mut p);
                order_of(&p, &mut order);
            });
            assert_eq!(s, start, "{threads} threads");
            assert_eq!(p, place, "{threads} threads");
            assert!(
                order
                    .iter()
                    .enumerate()
                    .all(|(k, &i)| p[i as usize] == k as u32)
            );
        }
    }

    #[test]
    fn empty_and_tiny_inputs() {
        let mut sort = CountingSort::new();
        let (mut s, mut p) = (Vec::new(), Vec::new());
        sort.sort(&[], 3, &mut s, &mut p);
        assert_eq!((s, p), (vec![0, 0, 0, 0], vec![]));
        let (mut s, mut p) = (Vec::new(), Vec::new());
        sort.sort(&[2, 0, 2], 3, &mut s, &mut p);
        assert_eq!((s, p), (vec![0, 1, 1, 3], vec![1, 0, 2]));
    }
}
