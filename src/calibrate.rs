//! Machine calibration for a sweep: what this machine can do at best, measured the same way
//! every time, so that kernel timings can be read against it (SPEC §3).
//!
//! Four measurements, each bounded by a time budget:
//! - **FMA throughput** of one thread: many independent multiply-add chains in the
//!   vectors of the SIMD level the kernels run with.
//! - **Parallel ceiling**: the same loop run by every thread of a rayon pool of `p` threads,
//!   as a throughput ratio against one thread. On 2-vCPU cloud machines the two vCPUs are often
//!   SMT siblings of one core that share its FMA pipes, so this can be ~1.0 rather than 2.0;
//!   speedups of compute-bound kernels are reported relative to it.
//! - **Fork/join cost** of one rayon region in which every pool thread takes part.
//! - **Streaming read bandwidth** of one thread over a buffer much larger than the L3 cache.
//!
//! Nothing here panics on a hostile environment: a missing `/proc/cpuinfo` gives "unknown", a
//! pool or buffer that cannot be created gives a warning in [`Calibration::warnings`].

use std::hint::black_box;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::{Duration, Instant};

use serde::{Deserialize, Serialize};

#[cfg(target_arch = "x86_64")]
use crate::simd::SimdLevel;
use crate::simd::{self, LANES};
use crate::stats::median;

/// What was measured about the machine; see the module documentation.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct Calibration {
    /// "model name" from `/proc/cpuinfo`, or "unknown".
    pub cpu_model: String,
    /// `std::thread::available_parallelism()` (1 if it cannot be determined).
    pub logical_cpus: usize,
    /// The SIMD level the kernels (and these loops) run with.
    pub simd: String,
    /// Single-thread FP32 multiply-add throughput, 2 flops per multiply-add, in GFLOP/s.
    pub fma_gflops_1t: f64,
    /// Throughput ratio of `p` threads to one thread on the FMA loop, one entry per requested
    /// thread count that could be measured, in the order requested.
    pub parallel_ceiling: Vec<ThreadRatio>,
    /// Median wall time of one rayon fork/join region on [`Self::fork_join_threads`] threads
    /// whose workers were idle (asleep) beforehand, as at the start of a step, in µs.
    pub fork_join_us: f64,
    /// The same with the workers still awake from the previous region (back-to-back regions).
    pub fork_join_hot_us: f64,
    /// Pool size the fork/join costs were measured with.
    pub fork_join_threads: usize,
    /// Single-thread streaming read bandwidth from memory, in GB/s (10⁹ bytes per second);
    /// 0 if the buffer could not be allocated (see `warnings`).
    pub memory_bandwidth_gbs: f64,
    /// Wall time of the whole calibration, in seconds.
    pub duration_s: f64,
    /// CPUs' worth of time that other processes (or the hypervisor, as steal time) used while
    /// calibrating, from `/proc/stat`; `None` where that is unavailable. Anything well above 0
    /// means the figures, the parallel ceiling first, are understated.
    pub background_cpus: Option<f64>,
    /// Things that could not be measured, or were measured under doubtful conditions.
    pub warnings: Vec<String>,
}

/// The parallel ceiling at one thread count.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct ThreadRatio {
    pub threads: usize,
    /// Total work rate with `threads` threads over the rate with one thread.
    pub ratio: f64,
    /// More threads than logical CPUs.
    pub oversubscribed: bool,
}

/// How long each measurement may take, and how big the memory buffer is.
#[derive(Clone, Debug, PartialEq)]
pub struct CalibrationOptions {
    /// Time budget of each measurement (FMA, each thread count, fork/join, bandwidth). A
    /// measurement always runs a few repetitions, so with tiny budgets it overruns them.
    pub budget: Duration,
    /// Size of the buffer streamed for the read bandwidth; must be well beyond the last-level
    /// cache for the figure to mean memory bandwidth.
    pub memory_bytes: usize,
}

impl Default for CalibrationOptions {
    fn default() -> Self {
        CalibrationOptions {
            budget: Duration::from_millis(200),
            memory_bytes: 256 << 20,
        }
    }
}

impl Calibration {
    /// The parallel ceiling at `threads` threads, if it was measured. One thread is its own
    /// reference, so `ceiling(1)` is 1.0 when it was not measured.
    pub fn ceiling(&self, threads: usize) -> Option<f64> {
        self.parallel_ceiling
            .iter()
            .find(|r| r.threads == threads)
            .map(|r| r.ratio)
            .or((threads == 1).then_some(1.0))
    }

    /// One human line (two if there were warnings), e.g. "AMD EPYC (2 logical CPUs, avx512):
    /// FMA 108 GFLOP/s/thread, 2-thread ceiling 1.05x, fork/join 19 us, read bandwidth 20.1 GB/s".
    pub fn summary(&self) -> String {
        let mut s = format!(
            "{} ({} logical CPUs, {}): FMA {:.0} GFLOP/s/thread",
            self.cpu_model, self.logical_cpus, self.simd, self.fma_gflops_1t
        );
        for r in self.parallel_ceiling.iter().filter(|r| r.threads != 1) {
            s += &format!(", {}-thread ceiling {:.2}x", r.threads, r.ratio);
            if r.oversubscribed {
                s += " (oversubscribed)";
            }
        }
        s += &format!(
            ", fork/join {:.0} us ({:.0} us hot, {} threads), read bandwidth {:.1} GB/s",
            self.fork_join_us,
            self.fork_join_hot_us,
            self.fork_join_threads,
            self.memory_bandwidth_gbs
        );
        if !self.warnings.is_empty() {
            s += &format!("\nwarnings: {}", self.warnings.join("; "));
        }
        s
    }
}

/// Calibrates with the default budgets (about 0.2 s per measurement).
pub fn calibrate(threads: &[usize]) -> Calibration {
    calibrate_with(&CalibrationOptions::default(), threads)
}

/// Calibrates, measuring the parallel ceiling at each of `threads`.
pub fn calibrate_with(opts: &CalibrationOptions, threads: &[usize]) -> Calibration {
    let start = Instant::now();
    let ticks_before = cpu_ticks();
    let budget = opts.budget.as_secs_f64();
    let logical_cpus = std::thread::available_parallelism().map_or(1, |n| n.get());
    let mut warnings = Vec::new();

    // One repetition of the FMA loop lasts about a tenth of the budget: long enough that timer
    // resolution, thread wake-up and the ~20 µs fork/join are negligible, short enough for
    // several repetitions (the median and best need a few) to fit in the budget.
    let iters = size_iters(budget / 10.0, |n| time(|| fma_burst(n)).0);
    let fma_gflops_1t = measure_fma(iters, budget);

    let parallel_ceiling = measure_ceiling(threads, iters, budget, logical_cpus, &mut warnings);

    let fork_join_threads = threads.iter().copied().max().unwrap_or(2).max(2);
    let (fork_join_us, fork_join_hot_us) =
        measure_fork_join(fork_join_threads, budget, &mut warnings);

    let memory_bandwidth_gbs = measure_bandwidth(opts.memory_bytes, budget, &mut warnings);

    let background_cpus = ticks_before
        .zip(cpu_ticks())
        .and_then(|(before, after)| before.background_cpus(&after));
    if let Some(b) = background_cpus.filter(|&b| b >= BACKGROUND_WARNING_CPUS) {
        warnings.push(format!(
            "other processes used {b:.2} CPUs during calibration: throughputs and the parallel \
             ceiling are likely understated"
        ));
    }

    Calibration {
        cpu_model: cpu_model(),
        logical_cpus,
        simd: simd::level().name().to_string(),
        fma_gflops_1t,
        parallel_ceiling,
        fork_join_us,
        fork_join_hot_us,
        fork_join_threads,
        memory_bandwidth_gbs,
        duration_s: start.elapsed().as_secs_f64(),
        background_cpus,
        warnings,
    }
}

/// "model name" of the first processor in `/proc/cpuinfo` (Linux), else "unknown".
fn cpu_model() -> String {
    std::fs::read_to_string("/proc/cpuinfo")
        .ok()
        .and_then(|text| {
            text.lines().find_map(|line| {
                let (key, value) = line.split_once(':')?;
                (key.trim() == "model name").then(|| value.trim().to_string())
            })
        })
        .filter(|model| !model.is_empty())
        .unwrap_or_else(|| "unknown".to_string())
}

// ---------------------------------------------------------------------------------------------
// Background load

/// Background load (in CPUs) from which a calibration is flagged. Calibrating on a machine
/// where another process keeps a CPU busy is the commonest way to get a wrong ceiling: with
/// 2 vCPUs and one busy, 2 threads measure ~1.0x even when the vCPUs are independent cores.
const BACKGROUND_WARNING_CPUS: f64 = 0.25;

/// CPU time counters, in clock ticks (Linux `/proc`).
#[derive(Clone, Copy, Debug, PartialEq)]
struct CpuTicks {
    /// Non-idle time of all CPUs (including time stolen by the hypervisor).
    busy: u64,
    /// All time of all CPUs.
    total: u64,
    /// CPUs counted.
    cpus: usize,
    /// User and system time of this process, all threads.
    own: u64,
}

impl CpuTicks {
    /// CPUs' worth of non-idle time not spent by this process between `self` and `later`.
    fn background_cpus(&self, later: &CpuTicks) -> Option<f64> {
        let total = later.total.checked_sub(self.total).filter(|&t| t > 0)?;
        let busy = later.busy.saturating_sub(self.busy);
        let own = later.own.saturating_sub(self.own);
        Some(busy.saturating_sub(own) as f64 / total as f64 * self.cpus as f64)
    }
}

fn cpu_ticks() -> Option<CpuTicks> {
    let (busy, total, cpus) = parse_proc_stat(&std::fs::read_to_string("/proc/stat").ok()?)?;
    let own = parse_own_ticks(&std::fs::read_to_string("/proc/self/stat").ok()?)?;
    Some(CpuTicks {
        busy,
        total,
        cpus,
        own,
    })
}

/// (busy, total, CPUs) from `/proc/stat`: the aggregate "cpu" line is user, nice, system,
/// idle, iowait, irq, softirq, steal, then guest times already counted in user and nice.
fn parse_proc_stat(text: &str) -> Option<(u64, u64, usize)> {
    let line = text.lines().find(|l| l.starts_with("cpu "))?;
    let fields: Vec<u64> = line
        .split_whitespace()
        .skip(1)
        .take(8)
        .map(|f| f.parse().ok())
        .collect::<Option<_>>()?;
    if fields.len() < 5 {
        return None;
    }
    let total: u64 = fields.iter().sum();
    let busy = total - fields[3] - fields[4];
    let cpus = text
        .lines()
        .filter(|l| l.starts_with("cpu") && l.as_bytes().get(3).is_some_and(u8::is_ascii_digit))
        .count();
    (cpus > 0).then_some((busy, total, cpus))
}

/// utime + stime from `/proc/self/stat`: fields 14 and 15, counted after the command name,
/// which is in parentheses and may itself contain spaces and parentheses.
fn parse_own_ticks(text: &str) -> Option<u64> {
    let fields: Vec<&str> = text.rsplit_once(')')?.1.split_whitespace().collect();
    let utime: u64 = fields.get(11)?.parse().ok()?;
    let stime: u64 = fields.get(12)?.parse().ok()?;
    Some(utime + stime)
}

// ---------------------------------------------------------------------------------------------
// Timing helpers

/// Runs `f`, returning its wall time in seconds and its result.
fn time<R>(f: impl FnOnce() -> R) -> (f64, R) {
    let t = Instant::now();
    let r = f();
    (t.elapsed().as_secs_f64(), r)
}

/// Repetitions of `once`: at least `min_reps`, then more while the total stays within
/// `budget_s` seconds, at most `max_reps`.
fn repeat<T>(
    budget_s: f64,
    min_reps: usize,
    max_reps: usize,
    mut once: impl FnMut() -> T,
) -> Vec<T> {
    let start = Instant::now();
    let mut out = Vec::new();
    while out.len() < min_reps || (out.len() < max_reps && start.elapsed().as_secs_f64() < budget_s)
    {
        out.push(once());
    }
    out
}

/// Iteration count for which `run(iters)` takes about `target_s` seconds: grows the count
/// until a run is long enough to time reliably, then scales it linearly.
fn size_iters(target_s: f64, mut run: impl FnMut(u64) -> f64) -> u64 {
    let target_s = target_s.max(1e-4);
    let mut iters: u64 = 256;
    loop {
        let t = run(iters);
        if t >= target_s / 4.0 || iters >= 1 << 40 {
            let scaled = iters as f64 * target_s / t.max(1e-9);
            return (scaled.ceil() as u64).clamp(1, 1 << 40);
        }
        iters *= 4;
    }
}

// ---------------------------------------------------------------------------------------------
// FMA throughput and parallel ceiling

/// Independent multiply-add chains per loop iteration. Each chain depends only on itself, so
/// the loop is bound by the FMA pipes' throughput rather than their latency as long as there
/// are at least latency × pipes chains (4 cycles × 2 pipes on Zen 4/5 and recent Intel), and
/// 12 vector registers plus the two constants still fit the 16 registers of SSE/AVX2.
const CHAINS: usize = 12;

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
fn fma_burst(iters: u64) -> f64 {
    let (lanes, result) = fma_loop(iters);
    black_box(result);
    2.0 * (iters as f64) * (CHAINS * lanes) as f64
}

/// The loop for the selected level: (lanes per vector, value to `black_box`).
#[cfg(target_arch = "x86_64")]
fn fma_loop(iters: u64) -> (usize, f32) {
    match simd::level() {
        // SAFETY: `simd::level()` returns these levels only after checking the CPU has them;
        // SSE is part of the x86-64 baseline.
        SimdLevel::Avx512 => (16, unsafe { x86::fma_avx512(iters) }),
        SimdLevel::Avx2 => (8, unsafe { x86::fma_avx2(iters) }),
        SimdLevel::Baseline => (4, unsafe { x86::mul_add_sse(iters) }),
    }
}

#[cfg(not(target_arch = "x86_64"))]
fn fma_loop(iters: u64) -> (usize, f32) {
    (LANES, portable::mul_add_lanes(iters))
}

/// The chains start at distinct values the compiler cannot see (`black_box`), so they can be
/// neither merged nor evaluated at compile time; with `m` < 1 and `a` > 0 every value converges
/// to `a / (1 - m)` = 1, so no denormals or infinities slow the loop down. The sum of the
/// chains is returned for the caller to `black_box`, so the work cannot be dropped.
#[cfg(target_arch = "x86_64")]
mod x86 {
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
mod portable {
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
fn measure_fma(iters: u64, budget_s: f64) -> f64 {
    repeat(budget_s, 3, 64, || {
        let (t, flops) = time(|| fma_burst(iters));
        flops / t / 1e9
    })
    .into_iter()
    .fold(0.0, f64::max)
}

/// The parallel ceiling at each of `threads`.
///
/// Each repetition is a pair of runs, the reference on a 1-thread pool and then the same
/// per-thread work on every thread of a `p`-thread pool (`ThreadPool::broadcast`), both
/// started the same way so they pay the same overheads. The ratio of a pair's rates is taken
/// and the **median** ratio kept: unlike a single-thread rate, the ceiling legitimately varies
/// from run to run (where the hypervisor places the vCPUs), and the median is what a benchmark
/// run is most likely to see; pairing adjacent runs cancels slow drifts (clock speed, load)
/// common to both.
fn measure_ceiling(
    threads: &[usize],
    iters: u64,
    budget_s: f64,
    logical_cpus: usize,
    warnings: &mut Vec<String>,
) -> Vec<ThreadRatio> {
    let reference = match rayon::ThreadPoolBuilder::new().num_threads(1).build() {
        Ok(pool) => pool,
        Err(e) => {
            warnings.push(format!(
                "parallel ceiling not measured: 1-thread rayon pool: {e}"
            ));
            return Vec::new();
        }
    };
    let mut out = Vec::new();
    for &p in threads {
        if p == 0 {
            warnings.push("parallel ceiling: 0 threads requested, skipped".to_string());
            continue;
        }
        let pool = match rayon::ThreadPoolBuilder::new().num_threads(p).build() {
            Ok(pool) => pool,
            Err(e) => {
                warnings.push(format!("parallel ceiling at {p} threads not measured: {e}"));
                continue;
            }
        };
        // Wake the new pool's threads once so their start-up is not timed.
        pool.broadcast(|_| fma_burst(1));
        let ratios = repeat(budget_s, 3, 64, || {
            let (t1, _) = time(|| reference.broadcast(|_| fma_burst(iters)));
            let (tp, _) = time(|| pool.broadcast(|_| fma_burst(iters)));
            // p times the work in tp against the work in t1.
            p as f64 * t1 / tp
        });
        out.push(ThreadRatio {
            threads: p,
            // `repeat` runs at least 3 times, so there is a median.
            ratio: median(&ratios).unwrap_or(0.0),
            oversubscribed: p > logical_cpus,
        });
    }
    out
}

// ---------------------------------------------------------------------------------------------
// Fork/join

/// How long a region's leaf waits for the other threads before giving up (a leaf can only
/// give up when some pool thread never got to it: an oversubscribed or very busy machine).
const FORK_JOIN_TIMEOUT: Duration = Duration::from_millis(2);

/// A fork/join region as the kernels build them (a binary tree of `rayon::join`), split into
/// `leaves` leaves, each waiting until all `total` leaves have started. The wait makes every
/// pool thread take part: without it an empty region is usually run entirely by the calling
/// thread before any worker wakes up, which measures nothing a real region pays. Returns
/// whether every leaf saw all the others.
fn region(leaves: usize, total: usize, arrived: &AtomicUsize, deadline: Instant) -> bool {
    if leaves <= 1 {
        arrived.fetch_add(1, Ordering::AcqRel);
        while arrived.load(Ordering::Acquire) < total {
            if Instant::now() >= deadline {
                return false;
            }
            // Yield rather than only spin: if the pool has more threads than CPUs, the threads
            // still to arrive need this CPU.
            std::thread::yield_now();
        }
        true
    } else {
        let half = leaves / 2;
        let (a, b) = rayon::join(
            || region(half, total, arrived, deadline),
            || region(leaves - half, total, arrived, deadline),
        );
        a && b
    }
}

/// Median wall time in µs of one fork/join region on a `p`-thread pool: `(cold, hot)`.
///
/// Cold: before each region the calling thread sleeps 1 ms, long enough for rayon's idle
/// workers to stop spinning and go to sleep, so the region pays for waking them; this is what
/// a step's parallel region costs after serial work. Hot: regions back to back, workers still
/// spinning. The median, not the minimum, because a cost (unlike a throughput) is best
/// described by its typical value, and wake-up latency has a long tail.
fn measure_fork_join(p: usize, budget_s: f64, warnings: &mut Vec<String>) -> (f64, f64) {
    let pool = match rayon::ThreadPoolBuilder::new().num_threads(p).build() {
        Ok(pool) => pool,
        Err(e) => {
            warnings.push(format!(
                "fork/join not measured: {p}-thread rayon pool: {e}"
            ));
            return (0.0, 0.0);
        }
    };
    let timed_out = AtomicUsize::new(0);
    let once = || {
        let arrived = AtomicUsize::new(0);
        let t = Instant::now();
        let complete = region(p, p, &arrived, t + FORK_JOIN_TIMEOUT);
        let us = t.elapsed().as_secs_f64() * 1e6;
        if !complete {
            timed_out.fetch_add(1, Ordering::Relaxed);
        }
        us
    };
    let (cold, hot) = pool.install(|| {
        // Warm up: threads started, code and stacks touched.
        for _ in 0..10 {
            once();
        }
        timed_out.store(0, Ordering::Relaxed);
        let cold = repeat(budget_s / 2.0, 5, 1000, || {
            std::thread::sleep(Duration::from_millis(1));
            once()
        });
        let hot = repeat(budget_s / 2.0, 5, 10_000, once);
        (cold, hot)
    });
    // A few stragglers (another process held a CPU for a time slice) do not move the
    // medians; from 1% on they may, and from half on the figures are the timeout itself.
    let timed_out = timed_out.into_inner();
    let regions = cold.len() + hot.len();
    if timed_out * 100 >= regions {
        warnings.push(format!(
            "fork/join: {timed_out} of {regions} regions timed out after {} ms waiting for all \
             {p} threads (busy or oversubscribed machine)",
            FORK_JOIN_TIMEOUT.as_millis()
        ));
    }
    // `repeat` runs at least 5 times each, so there are medians.
    (median(&cold).unwrap_or(0.0), median(&hot).unwrap_or(0.0))
}

// ---------------------------------------------------------------------------------------------
// Memory bandwidth

/// Sum of `data`, with 4 × `LANES` independent accumulators so the adds keep up with the loads
/// (a single running sum would be bound by the add latency, not by memory).
#[inline(always)]
fn stream_sum(data: &[f32]) -> f32 {
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
fn measure_bandwidth(bytes: usize, budget_s: f64, warnings: &mut Vec<String>) -> f64 {
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::simd::SimdLevel;

    fn tiny() -> CalibrationOptions {
        CalibrationOptions {
            budget: Duration::from_millis(5),
            memory_bytes: 4 << 20,
        }
    }

    fn finite_positive(x: f64) -> bool {
        x.is_finite() && x > 0.0
    }

    #[test]
    fn tiny_calibration_is_complete_and_sane() {
        let cpus = std::thread::available_parallelism().map_or(1, |n| n.get());
        let threads = [1, 2, cpus + 1];
        let c = calibrate_with(&tiny(), &threads);
        assert!(!c.cpu_model.is_empty());
        assert!(c.logical_cpus >= 1);
        assert_eq!(c.simd, simd::level().name());
        for x in [
            c.fma_gflops_1t,
            c.fork_join_us,
            c.fork_join_hot_us,
            c.memory_bandwidth_gbs,
            c.duration_s,
        ] {
            assert!(finite_positive(x), "{x} in {c:?}");
        }
        assert_eq!(c.fork_join_threads, cpus + 1);
        let measured: Vec<usize> = c.parallel_ceiling.iter().map(|r| r.threads).collect();
        assert_eq!(measured, threads);
        for r in &c.parallel_ceiling {
            assert!(finite_positive(r.ratio), "{r:?}");
            assert_eq!(r.oversubscribed, r.threads > c.logical_cpus, "{r:?}");
        }
        assert!(c.parallel_ceiling.last().is_some_and(|r| r.oversubscribed));
        assert!(
            c.background_cpus.is_none_or(|b| b.is_finite() && b >= 0.0),
            "{c:?}"
        );
        assert!(c.summary().starts_with(&c.cpu_model));
    }

    #[test]
    fn zero_threads_is_skipped_with_a_warning() {
        let c = calibrate_with(&tiny(), &[0, 1]);
        let measured: Vec<usize> = c.parallel_ceiling.iter().map(|r| r.threads).collect();
        assert_eq!(measured, [1]);
        assert!(c.warnings.iter().any(|w| w.contains("0 threads")));
        assert_eq!(c.fork_join_threads, 2);
    }

    fn sample() -> Calibration {
        Calibration {
            cpu_model: "AMD EPYC 9R14".to_string(),
            logical_cpus: 2,
            simd: "avx512".to_string(),
            fma_gflops_1t: 108.3,
            parallel_ceiling: vec![
                ThreadRatio {
                    threads: 2,
                    ratio: 1.05,
                    oversubscribed: false,
                },
                ThreadRatio {
                    threads: 4,
                    ratio: 0.98,
                    oversubscribed: true,
                },
            ],
            fork_join_us: 19.2,
            fork_join_hot_us: 3.1,
            fork_join_threads: 4,
            memory_bandwidth_gbs: 20.1,
            duration_s: 2.4,
            background_cpus: Some(0.03),
            warnings: vec!["something".to_string()],
        }
    }

    #[test]
    fn serde_round_trip() {
        let c = sample();
        let json = serde_json::to_string(&c).expect("serializes");
        let back: Calibration = serde_json::from_str(&json).expect("deserializes");
        assert_eq!(back, c);
    }

    #[test]
    fn ceiling_lookup() {
        let c = sample();
        assert_eq!(c.ceiling(2), Some(1.05));
        assert_eq!(c.ceiling(4), Some(0.98));
        assert_eq!(c.ceiling(3), None);
        assert_eq!(c.ceiling(1), Some(1.0));
        let mut measured_one = c.clone();
        measured_one.parallel_ceiling.push(ThreadRatio {
            threads: 1,
            ratio: 0.99,
            oversubscribed: false,
        });
        assert_eq!(measured_one.ceiling(1), Some(0.99));
    }

    #[test]
    fn summary_mentions_every_figure() {
        let s = sample().summary();
        assert!(
            s.starts_with("AMD EPYC 9R14 (2 logical CPUs, avx512): FMA 108 GFLOP/s/thread"),
            "{s}"
        );
        assert!(s.contains("2-thread ceiling 1.05x"), "{s}");
        assert!(s.contains("4-thread ceiling 0.98x (oversubscribed)"), "{s}");
        assert!(s.contains("fork/join 19 us"), "{s}");
        assert!(s.contains("read bandwidth 20.1 GB/s"), "{s}");
        assert!(s.contains("\nwarnings: something"), "{s}");
    }

    #[test]
    fn proc_parsing() {
        let stat = "cpu  666875 0 28288 346215 700 0 137 371 0 0\n\
                    cpu0 333000 0 14000 173000 350 0 70 180 0 0\n\
                    cpu1 333875 0 14288 173215 350 0 67 191 0 0\n\
                    intr 1 2 3\n";
        let total = 666875 + 28288 + 346215 + 700 + 137 + 371;
        assert_eq!(
            parse_proc_stat(stat),
            Some((total - 346215 - 700, total, 2))
        );
        assert_eq!(parse_proc_stat("intr 1 2\n"), None);
        let own = "17990 (a (weird) name) R 17987 17987 32117 0 -1 4194304 101 0 0 0 57 13 0 0 20";
        assert_eq!(parse_own_ticks(own), Some(70));
        assert_eq!(parse_own_ticks("17990 (cut) R 1 2"), None);
        let before = CpuTicks {
            busy: 100,
            total: 1000,
            cpus: 2,
            own: 50,
        };
        let after = CpuTicks {
            busy: 400,
            total: 1400,
            cpus: 2,
            own: 250,
        };
        // 100 of 400 ticks busy with other work, on 2 CPUs: half a CPU.
        assert_eq!(before.background_cpus(&after), Some(0.5));
        assert_eq!(before.background_cpus(&before), None);
    }

    #[test]
    fn cpu_model_is_never_empty() {
        assert!(!cpu_model().is_empty());
    }

    #[test]
    fn kernels_compute_what_they_claim() {
        // The chains converge to a / (1 - m) = 1 from their starting values near 1.
        let (lanes, sum) = fma_loop(20_000);
        let n = (CHAINS * lanes) as f32;
        assert!((sum - n).abs() < 1e-2 * n, "{sum} for {n} lanes");
        assert_eq!(lanes * 32, simd_bits());
        assert_eq!(fma_burst(10), 10.0 * fma_burst(1));
        let data: Vec<f32> = (0..1000).map(|i| i as f32).collect();
        assert_eq!(stream_sum(&data), 999.0 * 1000.0 / 2.0);
    }

    /// Vector width the FMA loop should use at the selected level.
    fn simd_bits() -> usize {
        match simd::level() {
            _ if !cfg!(target_arch = "x86_64") => 32 * LANES,
            SimdLevel::Avx512 => 512,
            SimdLevel::Avx2 => 256,
            SimdLevel::Baseline => 128,
        }
    }
}
