//! Single-thread FMA throughput and the p-thread parallel ceiling.

#[allow(unused_imports)]
use super::*;

// ---------------------------------------------------------------------------------------------
// FMA throughput and parallel ceiling

/// Independent multiply-add chains per loop iteration. Each chain depends only on itself, so
/// the loop is bound by the FMA pipes' throughput rather than their latency as long as there
/// are at least latency × pipes chains (4 cycles × 2 pipes on Zen 4/5 and recent Intel), and
/// 12 vector registers plus the two constants still fit the 16 registers of SSE/AVX2.
pub(super) const CHAINS: usize = 12;

/// Runs the multiply-add loop for `iters` rounds at the current SIMD level (the one the
/// kernels run with); returns the flops done, 2 per multiply-add (also on the baseline, where
/// it is a separate multiply and add).
///
/// Why `std::arch` vectors here and not `[f32; 16]` lane arrays like the kernels: with this
/// many loop-carried lane arrays LLVM (rustc 1.95) does not reliably keep each array in one
/// register. At 8, 12 or 16 chains, or at opt-level 2, it vectorized across the chains with
/// gathers/scatters or shuffled lanes through the stack every iteration, which would have
/// measured the compiler, not the machine. Explicit vectors compile to exactly `CHAINS` FMAs
/// per iteration at any optimisation level.
pub(super) fn fma_burst(iters: u64) -> f64 {
    let (lanes, result) = fma_loop(iters);
    black_box(result);
    2.0 * (iters as f64) * (CHAINS * lanes) as f64
}

/// The loop for the selected level: (lanes per vector, value to `black_box`).
#[cfg(target_arch = "x86_64")]
pub(super) fn fma_loop(iters: u64) -> (usize, f32) {
    match simd::level() {
        // SAFETY: `simd::level()` returns these levels only after checking the CPU has them;
        // SSE is part of the x86-64 baseline.
        SimdLevel::Avx512 => (16, unsafe { x86::fma_avx512(iters) }),
        SimdLevel::Avx2 => (8, unsafe { x86::fma_avx2(iters) }),
        SimdLevel::Baseline => (4, unsafe { x86::mul_add_sse(iters) }),
    }
}

#[cfg(not(target_arch = "x86_64"))]
pub(super) fn fma_loop(iters: u64) -> (usize, f32) {
    (LANES, portable::mul_add_lanes(iters))
}

/// The chains start at distinct values the compiler cannot see (`black_box`), so they can be
/// neither merged nor evaluated at compile time; with `m` < 1 and `a` > 0 every value converges
/// to `a / (1 - m)` = 1, so no denormals or infinities slow the loop down. The sum of the
/// chains is returned for the caller to `black_box`, so the work cannot be dropped.
#[cfg(target_arch = "x86_64")]
pub(super) mod x86 {
    use super::CHAINS;
    use std::arch::x86_64::*;
    use std::hint::black_box;

    /// (multiplier, addend, start of the first chain), opaque to the optimiser.
    fn constants() -> (f32, f32, f32) {
        (black_box(0.999), black_box(0.001), black_box(1.0))
    }

    #[target_feature(enable = "avx512f")]
    pub(super) fn fma_avx512(iters: u64) -> f32 {
        let (m, a, base) = constants();
        let (m, a) = (_mm512_set1_ps(m), _mm512_set1_ps(a));
        let mut acc: [__m512; CHAINS] =
            std::array::from_fn(|k| _mm512_set1_ps(base + 0.01 * k as f32));
        for _ in 0..iters {
            for x in acc.iter_mut() {
                *x = _mm512_fmadd_ps(*x, m, a);
            }
        }
        _mm512_reduce_add_ps(
            acc.into_iter()
                .fold(_mm512_setzero_ps(), |s, x| _mm512_add_ps(s, x)),
        )
    }

    #[target_feature(enable = "avx2,fma")]
    pub(super) fn fma_avx2(iters: u64) -> f32 {
        let (m, a, base) = constants();
        let (m, a) = (_mm256_set1_ps(m), _mm256_set1_ps(a));
        let mut acc: [__m256; CHAINS] =
            std::array::from_fn(|k| _mm256_set1_ps(base + 0.01 * k as f32));
        for _ in 0..iters {
            for x in acc.iter_mut() {
                *x = _mm256_fmadd_ps(*x, m, a);
            }
        }
        let s = acc
            .into_iter()
            .fold(_mm256_setzero_ps(), |s, x| _mm256_add_ps(s, x));
        let s = _mm_add_ps(_mm256_castps256_ps128(s), _mm256_extractf128_ps::<1>(s));
        horizontal_sum(s)
    }

    /// No FMA on the baseline: a separate multiply and add per step (`mul_add` would be a
    /// libm call here), still counted as 2 flops.
    #[target_feature(enable = "sse")]
    pub(super) fn mul_add_sse(iters: u64) -> f32 {
        let (m, a, base) = constants();
        let (m, a) = (_mm_set1_ps(m), _mm_set1_ps(a));
        let mut acc: [__m128; CHAINS] =
            std::array::from_fn(|k| _mm_set1_ps(base + 0.01 * k as f32));
        for _ in 0..iters {
            for x in acc.iter_mut() {
                *x = _mm_add_ps(_mm_mul_ps(*x, m), a);
            }
        }
        horizontal_sum(
            acc.into_iter()
                .fold(_mm_setzero_ps(), |s, x| _mm_add_ps(s, x)),
        )
    }

    #[target_feature(enable = "sse")]
    fn horizontal_sum(v: __m128) -> f32 {
        let mut lanes = [0.0_f32; 4];
        // SAFETY: `lanes` is 4 writable f32s; `storeu` has no alignment requirement.
        unsafe { _mm_storeu_ps(lanes.as_mut_ptr(), v) };
        lanes.iter().sum()
    }
}

/// Lane arrays for other architectures: best effort, as LLVM may or may not keep them in
/// registers (see [`fma_burst`]); a separate multiply and add, as FMA may be a library call.
#[cfg(not(target_arch = "x86_64"))]
pub(super) mod portable {
    use super::{CHAINS, LANES};
    use std::hint::black_box;

    pub(super) fn mul_add_lanes(iters: u64) -> f32 {
        let (m, a, base) = (
            black_box(0.999_f32),
            black_box(0.001_f32),
            black_box(1.0_f32),
        );
        let mut acc: [[f32; LANES]; CHAINS] =
            std::array::from_fn(|k| std::array::from_fn(|l| base + 0.01 * (k * LANES + l) as f32));
        for _ in 0..iters {
            for chain in acc.iter_mut() {
                for x in chain.iter_mut() {
                    *x = *x * m + a;
                }
            }
        }
        acc.iter().flatten().sum()
    }
}

/// Single-thread GFLOP/s. Keeps the **best** repetition: on a shared machine interference
/// (other processes, preemption, frequency dips) only ever slows a compute loop down, so the
/// fastest repetition is the closest to what the core can do.
pub(super) fn measure_fma(iters: u64, budget_s: f64) -> f64 {
    repeat(budget_s, 3, 64, || {
        let (t, flops) = time(|| fma_burst(iters));
        flops / t / 1e9
    })
    .into_iter()
    .fold(0.0, f64::max)
}

/// The parallel ceiling at `p` threads, or why a `p`-thread pool could not be built.
///
/// Each repetition is a pair of runs, the reference on the 1-thread pool `reference` and then
/// the same per-thread work on every thread of a `p`-thread pool (`ThreadPool::broadcast`),
/// both started the same way so they pay the same overheads. The ratio of a pair's rates is
/// taken and the **median** ratio kept: unlike a single-thread rate, the ceiling legitimately
/// varies from run to run (where the hypervisor places the vCPUs), and the median is what a
/// benchmark run is most likely to see; pairing adjacent runs cancels slow drifts (clock speed,
/// load) common to both.
pub(super) fn measure_ceiling(
    reference: &rayon::ThreadPool,
    p: usize,
    iters: u64,
    budget_s: f64,
) -> Result<f64, String> {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(p)
        .build()
        .map_err(|e| e.to_string())?;
    // Wake the new pool's threads once so their start-up is not timed.
    pool.broadcast(|_| fma_burst(1));
    let ratios = repeat(budget_s, 3, 64, || {
        let (t1, _) = time(|| reference.broadcast(|_| fma_burst(iters)));
        let (tp, _) = time(|| pool.broadcast(|_| fma_burst(iters)));
        // p times the work in tp against the work in t1.
        p as f64 * t1 / tp
    });
    // `repeat` runs at least 3 times, so there is a median.
    Ok(median(&ratios).unwrap_or(0.0))
}
