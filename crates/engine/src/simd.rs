//! Runtime selection of the instruction set for the hot loops.
//!
//! The binary is built for the portable x86-64 baseline (so it runs anywhere, including under
//! valgrind, and so results from different build hosts stay comparable), while the pair loops
//! are compiled a second time for AVX2+FMA and a third time for AVX-512 and chosen once at run
//! time. The loops are written as plain Rust over fixed-width lane arrays, which LLVM vectorizes
//! for whichever target the enclosing function was compiled for; the batched 1/r² kernels
//! are written with intrinsics instead (`kernels::lanes`), run under [`run_avx512`] and
//! [`run_avx2`].

use std::sync::OnceLock;

/// The instruction-set level the kernels run with.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SimdLevel {
    /// The x86-64 baseline (SSE2) or a non-x86 target.
    Baseline,
    /// x86-64-v3: AVX2 and FMA.
    Avx2,
    /// x86-64-v4: AVX-512 (F, VL, DQ, BW, CD).
    Avx512,
}

impl SimdLevel {
    /// The level's name in results (`baseline`, `avx2+fma`, `avx512`).
    pub fn name(self) -> &'static str {
        match self {
            SimdLevel::Baseline => "baseline",
            SimdLevel::Avx2 => "avx2+fma",
            SimdLevel::Avx512 => "avx512",
        }
    }
}

/// The best level this CPU supports, unless `NBODY_BENCH_SIMD` (baseline|avx2|avx512) caps it.
pub fn level() -> SimdLevel {
    static LEVEL: OnceLock<SimdLevel> = OnceLock::new();
    *LEVEL.get_or_init(|| {
        let detected = detect();
        match std::env::var("NBODY_BENCH_SIMD").as_deref() {
            Ok("baseline") => SimdLevel::Baseline,
            Ok("avx2") if detected != SimdLevel::Baseline => SimdLevel::Avx2,
            _ => detected,
        }
    })
}

#[cfg(target_arch = "x86_64")]
fn detect() -> SimdLevel {
    use std::arch::is_x86_feature_detected as has;
    if has!("avx512f") && has!("avx512vl") && has!("avx512dq") && has!("avx512bw") && has!("fma") {
        SimdLevel::Avx512
    } else if has!("avx2") && has!("fma") {
        SimdLevel::Avx2
    } else {
        SimdLevel::Baseline
    }
}

#[cfg(not(target_arch = "x86_64"))]
fn detect() -> SimdLevel {
    SimdLevel::Baseline
}

/// Runs `f` compiled for AVX-512 (and everything it calls with `#[inline(always)]`).
///
/// # Safety
/// The CPU must have AVX-512 (F, VL, DQ, BW), AVX2 and FMA: `level()` is `Avx512`.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f,avx512vl,avx512dq,avx512bw,avx2,fma,bmi1,bmi2")]
pub(crate) unsafe fn run_avx512<R>(f: impl FnOnce() -> R) -> R {
    f()
}

/// Runs `f` compiled for AVX2 and FMA.
///
/// # Safety
/// The CPU must have AVX2 and FMA: `level()` is `Avx2` or `Avx512`.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma,bmi1,bmi2")]
pub(crate) unsafe fn run_avx2<R>(f: impl FnOnce() -> R) -> R {
    f()
}

/// Runs `f` compiled for the selected instruction set. `f` and everything it calls with
/// `#[inline(always)]` are inlined into a function carrying the matching `target_feature`.
#[inline(always)]
pub fn dispatch<R>(f: impl FnOnce() -> R) -> R {
    match level() {
        // SAFETY: `level()` only returns these levels after checking the CPU supports them.
        #[cfg(target_arch = "x86_64")]
        SimdLevel::Avx512 => unsafe { run_avx512(f) },
        #[cfg(target_arch = "x86_64")]
        SimdLevel::Avx2 => unsafe { run_avx2(f) },
        _ => f(),
    }
}

/// Lanes per block of the pair loops; a multiple of the vector width for both precisions.
pub const LANES: usize = 16;
