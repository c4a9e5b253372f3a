//! Streaming read bandwidth.

#[allow(unused_imports)]
use super::*;

// ---------------------------------------------------------------------------------------------
// Memory bandwidth

/// Sum of `data`, with 4 × `LANES` independent accumulators so the adds keep up with the loads
/// (a single running sum would be bound by the add latency, not by memory).
#[inline(always)]
pub(super) fn stream_sum(data: &[f32]) -> f32 {
    const ACCS: usize = 4;
    let (blocks, tail) = data.as_chunks::<{ ACCS * LANES }>();
    let mut acc = [[0.0_f32; LANES]; ACCS];
    for block in blocks {
        for k in 0..ACCS {
            for l in 0..LANES {
                acc[k][l] += block[k * LANES + l];
            }
        }
    }
    acc.iter().flatten().sum::<f32>() + tail.iter().sum::<f32>()
}

/// Single-thread read bandwidth in GB/s over a buffer of `bytes` bytes, **best** of the
/// repetitions (as for the FMA rate, interference only lowers a throughput).
pub(super) fn measure_bandwidth(bytes: usize, budget_s: f64, warnings: &mut Vec<String>) -> f64 {
    let n = (bytes / size_of::<f32>()).max(LANES);
    let mut data: Vec<f32> = Vec::new();
    if let Err(e) = data.try_reserve_exact(n) {
        warnings.push(format!(
            "read bandwidth not measured: cannot allocate {bytes} bytes: {e}"
        ));
        return 0.0;
    }
    // Written, not just allocated: untouched pages all map the kernel's one zero page, which
    // would be read from cache. Nonzero values, so no zero-page sharing either way.
    data.resize(n, 1.0);
    let data = black_box(data.as_slice());
    let bytes = size_of_val(data) as f64;
    repeat(budget_s, 3, 1000, || {
        let (t, sum) = time(|| {
            simd::dispatch(
                #[inline(always)]
                || stream_sum(data),
            )
        });
        black_box(sum);
        bytes / t / 1e9
    })
    .into_iter()
    .fold(0.0, f64::max)
}
