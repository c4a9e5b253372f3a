//! Splitting a per-particle field into disjoint chunks processed by rayon, without allocating.

use rayon::join;

/// Calls `f(offset, chunk)` on disjoint consecutive chunks of the `D` component slices, in
/// parallel on the current rayon pool, splitting down to `min_len` elements.
pub fn for_chunks<T: Send, const D: usize, F>(
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
pub fn chunk_len(n: usize) -> usize {
    (n / (8 * rayon::current_num_threads())).max(64)
}
