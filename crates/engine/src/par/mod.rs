//! Per-particle work on the rayon pool: disjoint chunks of a field, when a pass is worth a fork,
//! gathers by a permutation, and writes at distinct places from several threads; and a
//! [`team`] of workers that lives for a whole run and meets at barriers.

pub mod team;

use rayon::join;

/// Calls `f(offset, chunk)` on disjoint consecutive chunks of the `D` component slices, in
/// parallel on the current rayon pool, splitting down to `min_len` elements.
pub(crate) fn for_chunks<T: Send, const D: usize, F>(
    parts: [&mut [T]; D],
    offset: usize,
    min_len: usize,
    f: &F,
) where
    F: Fn(usize, [&mut [T]; D]) + Sync,
{
    let len = parts[0].len();
    if len <= min_len.max(1) {
        f(offset, parts);
        return;
    }
    let mid = len / 2;
    let mut halves = parts.map(|p| {
        let (a, b) = p.split_at_mut(mid);
        (Some(a), Some(b))
    });
    let lo: [&mut [T]; D] = std::array::from_fn(|d| halves[d].0.take().expect("split once"));
    let hi: [&mut [T]; D] = std::array::from_fn(|d| halves[d].1.take().expect("split once"));
    join(
        || for_chunks(lo, offset, min_len, f),
        || for_chunks(hi, offset + mid, min_len, f),
    );
}

/// Chunk length that gives each of the pool's threads several chunks to balance load.
pub(crate) fn chunk_len(n: usize) -> usize {
    (n / (8 * rayon::current_num_threads())).max(64)
}

/// Fewest per-particle elements (one value of one array: a bin, a coordinate) that a pass
/// over them forks for. Chosen against the calibrated fork/join of the pool (3 µs with its
/// threads awake, 11 µs asleep, on the 2-vCPU AMD EPYC 25/17/1), not swept.
pub const MIN_FORK_ELEMENTS: usize = 16_384;

/// Whether a pass over `elements` per-particle values should run on the pool's threads.
pub(crate) fn worth_forking(elements: usize) -> bool {
    elements >= MIN_FORK_ELEMENTS && rayon::current_num_threads() > 1
}

/// Copies `src[order[k]]` into `dst[k]` for every `k`, on the pool's threads when worth it.
pub fn gather<V: Copy + Send + Sync>(src: &[V], order: &[u32], dst: &mut Vec<V>) {
    use rayon::prelude::*;
    dst.clear();
    if worth_forking(order.len()) {
        order
            .par_iter()
            .with_min_len(4096)
            .map(|&k| src[k as usize])
            .collect_into_vec(dst);
    } else {
        dst.extend(order.iter().map(|&k| src[k as usize]));
    }
}

/// A slice written from several threads at places that the caller guarantees distinct.
pub(crate) struct Disjoint<'a, V> {
    ptr: *mut V,
    len: usize,
    _slice: std::marker::PhantomData<&'a mut [V]>,
}

// SAFETY: the writers promise distinct places (see `write`), so no place is written twice;
// values are only written, never read, through it.
unsafe impl<V: Send> Sync for Disjoint<'_, V> {}
unsafe impl<V: Send> Send for Disjoint<'_, V> {}

impl<'a, V: Copy> Disjoint<'a, V> {
    pub fn new(slice: &'a mut [V]) -> Self {
        Disjoint {
            ptr: slice.as_mut_ptr(),
            len: slice.len(),
            _slice: std::marker::PhantomData,
        }
    }

    /// Writes `value` at `index` (checked against the length).
    ///
    /// # Safety
    /// No other call of the same `Disjoint`, on any thread, writes `index`.
    #[inline(always)]
    pub unsafe fn write(&self, index: usize, value: V) {
        assert!(index < self.len, "place {index} outside 0..{}", self.len);
        // SAFETY: in bounds (checked), and no other thread writes this place (the caller's
        // promise), so this is the only access.
        unsafe { self.ptr.add(index).write(value) }
    }
}

/// The `D` slices cut into consecutive chunks of `len` elements (the last one shorter), each
/// chunk the same range of every slice.
pub(crate) fn chunks_of<T, const D: usize>(parts: [&mut [T]; D], len: usize) -> Vec<[&mut [T]; D]> {
    let n = parts[0].len();
    let len = len.max(1);
    let mut chunks = Vec::with_capacity(n.div_ceil(len));
    let mut rest = parts;
    while !rest[0].is_empty() {
        let take = len.min(rest[0].len());
        let mut cut = rest.map(|r| {
            let (a, b) = r.split_at_mut(take);
            (Some(a), Some(b))
        });
        chunks.push(std::array::from_fn(|d| cut[d].0.take().expect("cut once")));
        rest = std::array::from_fn(|d| cut[d].1.take().expect("cut once"));
    }
    chunks
}

/// Chunk length of a per-particle pass over `n` particles that forks: a few chunks per thread,
/// none below a few thousand particles.
pub(crate) fn pass_chunk(n: usize) -> usize {
    chunk_len(n).max(4096)
}
