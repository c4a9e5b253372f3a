//! Machine calibration for a sweep: what this machine can do at best, measured the same way
//! every time, so that kernel timings can be read against it.
//!
//! Four measurements, each bounded by a time budget:
//! - **FMA throughput** of one thread: many independent multiply-add chains in the
//!   vectors of the SIMD level the kernels run with.
//! - **Parallel ceiling**: the same loop run by every thread of a rayon pool of `p` threads,
//!   as a throughput ratio against one thread. On 2-vCPU cloud machines the two vCPUs are often
//!   SMT siblings of one core that share its FMA pipes, so this can be ~1.0 rather than 2.0;
//!   speedups of compute-bound kernels are reported relative to it.
//! - **Fork/join cost** of one rayon region in which every pool thread takes part, and beside
//!   it the **team's costs**: one barrier crossing of the engine's worker team, and one of its
//!   regions started after serial work.
//! - **Streaming read bandwidth** of one thread over a buffer much larger than the L3 cache.
//!
//! Nothing here panics on a hostile environment: a missing `/proc/cpuinfo` gives "unknown", a
//! pool or buffer that cannot be created gives a warning in [`Calibration::warnings`].

use std::hint::black_box;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::{Duration, Instant};

use serde::{Deserialize, Serialize};

#[cfg(target_arch = "x86_64")]
use nbody_engine::simd::SimdLevel;
use nbody_engine::simd::{self, LANES};
use nbody_engine::stats::median;

/// What was measured about the machine; see the module documentation.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct Calibration {
    /// "model name" from `/proc/cpuinfo`, or "unknown".
    pub cpu_model: String,
    /// Vendor, family, model and stepping from `/proc/cpuinfo`, e.g. `AuthenticAMD 26/2/1`:
    /// a virtual machine often reports only a generic model name ("AMD EPYC") for processors
    /// of different generations, and this tells them apart. `None` where unknown (and in
    /// files written before it was recorded).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub cpu_signature: Option<String>,
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
    /// Median wall time of one barrier crossing of the engine's worker team (as many workers
    /// as the fork/join's pool), back to back inside one region, in µs; `None` when not
    /// measured (and in files written before it was).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub team_barrier_us: Option<f64>,
    /// Median wall time of one team region (one barrier in it) started after 1 ms of serial
    /// work, the workers parked, in µs: the team's counterpart of `fork_join_us`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub team_region_us: Option<f64>,
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
/// The throughput of `threads` threads on the FMA loop against one thread.
pub struct ThreadRatio {
    /// The threads of the pool that ran the loop.
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
    pub(crate) memory_bytes: usize,
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

    /// This calibration with each parallel ceiling the larger of its own and `other`'s at the
    /// same thread count (a ceiling only `other` measured is not added).
    pub fn with_larger_ceilings(mut self, other: &Calibration) -> Calibration {
        for r in &mut self.parallel_ceiling {
            if let Some(o) = other
                .parallel_ceiling
                .iter()
                .find(|o| o.threads == r.threads)
            {
                r.ratio = r.ratio.max(o.ratio);
            }
        }
        self
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
        if let (Some(barrier), Some(region)) = (self.team_barrier_us, self.team_region_us) {
            s += &format!(", team barrier {barrier:.2} us (region {region:.0} us)");
        }
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
    let logical_cpus = std::thread::available_parallelism().map_or(1, |n| n.get());
    let mut calibration = assemble(&mut Machine::new(opts), threads, logical_cpus);
    let background_cpus = ticks_before
        .zip(cpu_ticks())
        .and_then(|(before, after)| before.background_cpus(&after));
    if let Some(b) = background_cpus.filter(|&b| b >= SHARED_MACHINE_CPUS) {
        calibration.warnings.push(format!(
            "other processes used {b:.2} CPUs during calibration: throughputs and the parallel \
             ceiling are likely understated"
        ));
    }
    calibration.background_cpus = background_cpus;
    calibration.duration_s = start.elapsed().as_secs_f64();
    calibration
}

/// The four measurements a calibration is made of: [`Machine`] takes them here; the tests
/// give fixed figures, so that the assembly is tested without timing anything.
trait Meter {
    /// Single-thread FMA throughput, GFLOP/s.
    fn fma_gflops(&mut self) -> f64;
    /// The throughput ratio of `threads` threads to one, or why it could not be measured.
    fn ceiling(&mut self, threads: usize) -> Result<f64, String>;
    /// Fork/join cost `(cold, hot)` in µs on a `threads`-thread pool.
    fn fork_join_us(&mut self, threads: usize, warnings: &mut Vec<String>) -> (f64, f64);
    /// The worker team's `(barrier, region)` costs in µs with `threads` workers.
    fn team_us(&mut self, threads: usize, warnings: &mut Vec<String>)
    -> (Option<f64>, Option<f64>);
    /// Streaming read bandwidth, GB/s (0 with a warning when it cannot be measured).
    fn bandwidth_gbs(&mut self, warnings: &mut Vec<String>) -> f64;
}

/// A calibration from `meter`'s figures (its duration and the background load are the
/// caller's to fill in).
fn assemble(meter: &mut impl Meter, threads: &[usize], logical_cpus: usize) -> Calibration {
    let mut warnings = Vec::new();
    let fma_gflops_1t = meter.fma_gflops();
    let mut parallel_ceiling = Vec::new();
    for &p in threads {
        if p == 0 {
            warnings.push("parallel ceiling: 0 threads requested, skipped".to_string());
            continue;
        }
        match meter.ceiling(p) {
            Ok(ratio) => parallel_ceiling.push(ThreadRatio {
                threads: p,
                ratio,
                oversubscribed: p > logical_cpus,
            }),
            Err(why) => warnings.push(format!(
                "parallel ceiling at {p} threads not measured: {why}"
            )),
        }
    }
    let fork_join_threads = threads.iter().copied().max().unwrap_or(2).max(2);
    let (fork_join_us, fork_join_hot_us) = meter.fork_join_us(fork_join_threads, &mut warnings);
    let (team_barrier_us, team_region_us) = meter.team_us(fork_join_threads, &mut warnings);
    let memory_bandwidth_gbs = meter.bandwidth_gbs(&mut warnings);
    Calibration {
        cpu_model: cpu_model(),
        cpu_signature: cpu_signature(),
        logical_cpus,
        simd: simd::level().name().to_string(),
        fma_gflops_1t,
        parallel_ceiling,
        fork_join_us,
        fork_join_hot_us,
        fork_join_threads,
        team_barrier_us,
        team_region_us,
        memory_bandwidth_gbs,
        duration_s: 0.0,
        background_cpus: None,
        warnings,
    }
}

/// The measurements taken on this machine, each within the options' budget.
struct Machine {
    budget_s: f64,
    memory_bytes: usize,
    /// FMA iterations of one repetition, sized once (a tenth of the budget).
    iters: u64,
    /// The 1-thread pool each ceiling's reference run uses.
    reference: Option<rayon::ThreadPool>,
}

impl Machine {
    fn new(opts: &CalibrationOptions) -> Machine {
        let budget_s = opts.budget.as_secs_f64();
        // One repetition of the FMA loop lasts about a tenth of the budget: long enough that
        // timer resolution, thread wake-up and the ~20 µs fork/join are negligible, short
        // enough for several repetitions (the median and best need a few) to fit in the budget.
        let iters = size_iters(budget_s / 10.0, |n| time(|| fma_burst(n)).0);
        Machine {
            budget_s,
            memory_bytes: opts.memory_bytes,
            iters,
            reference: None,
        }
    }
}

impl Meter for Machine {
    fn fma_gflops(&mut self) -> f64 {
        measure_fma(self.iters, self.budget_s)
    }

    fn ceiling(&mut self, threads: usize) -> Result<f64, String> {
        if self.reference.is_none() {
            let pool = rayon::ThreadPoolBuilder::new().num_threads(1).build();
            self.reference = Some(pool.map_err(|e| format!("1-thread rayon pool: {e}"))?);
        }
        let reference = self.reference.as_ref().expect("built above");
        measure_ceiling(reference, threads, self.iters, self.budget_s)
    }

    fn fork_join_us(&mut self, threads: usize, warnings: &mut Vec<String>) -> (f64, f64) {
        measure_fork_join(threads, self.budget_s, warnings)
    }

    fn team_us(
        &mut self,
        threads: usize,
        warnings: &mut Vec<String>,
    ) -> (Option<f64>, Option<f64>) {
        measure_team(threads, self.budget_s, warnings)
    }

    fn bandwidth_gbs(&mut self, warnings: &mut Vec<String>) -> f64 {
        measure_bandwidth(self.memory_bytes, self.budget_s, warnings)
    }
}

/// "model name" of the first processor in `/proc/cpuinfo` (Linux), else "unknown".
pub fn cpu_model() -> String {
    std::fs::read_to_string("/proc/cpuinfo")
        .ok()
        .and_then(|text| model_of(&text))
        .unwrap_or_else(|| "unknown".to_string())
}

/// The first non-empty "model name" of a `/proc/cpuinfo` text.
fn model_of(cpuinfo: &str) -> Option<String> {
    cpuinfo.lines().find_map(|line| {
        let (key, value) = line.split_once(':')?;
        (key.trim() == "model name" && !value.trim().is_empty()).then(|| value.trim().to_string())
    })
}

/// Vendor, family, model and stepping of the first processor in `/proc/cpuinfo` (Linux).
pub fn cpu_signature() -> Option<String> {
    let text = std::fs::read_to_string("/proc/cpuinfo").ok()?;
    signature_of(&text)
}

fn signature_of(cpuinfo: &str) -> Option<String> {
    let field = |name: &str| {
        cpuinfo.lines().find_map(|line| {
            let (key, value) = line.split_once(':')?;
            (key.trim() == name).then(|| value.trim().to_string())
        })
    };
    let vendor = field("vendor_id")?;
    Some(format!(
        "{vendor} {}/{}/{}",
        field("cpu family")?,
        field("model")?,
        field("stepping").unwrap_or_else(|| "?".into())
    ))
}

mod compute;
mod fork_join;
mod load;
mod memory;
mod team;

use compute::*;
use fork_join::*;
pub use load::SHARED_MACHINE_CPUS;
use load::*;
use memory::*;
use team::*;

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

#[cfg(test)]
mod tests {
    use super::*;
    use nbody_engine::simd::SimdLevel;

    /// Fixed figures: a ceiling of 0.9·p up to two threads, a pool of more than 8 refused.
    struct Fixed {
        asked: Vec<usize>,
    }

    impl Meter for Fixed {
        fn fma_gflops(&mut self) -> f64 {
            150.0
        }
        fn ceiling(&mut self, threads: usize) -> Result<f64, String> {
            self.asked.push(threads);
            match threads {
                t if t > 8 => Err("cannot spawn".to_string()),
                t => Ok(0.9 * t.min(2) as f64),
            }
        }
        fn fork_join_us(&mut self, threads: usize, _: &mut Vec<String>) -> (f64, f64) {
            (10.0 * threads as f64, 1.0)
        }
        fn team_us(&mut self, threads: usize, _: &mut Vec<String>) -> (Option<f64>, Option<f64>) {
            (Some(0.5 * threads as f64), Some(4.0))
        }
        fn bandwidth_gbs(&mut self, warnings: &mut Vec<String>) -> f64 {
            warnings.push("bandwidth: fixed".to_string());
            12.5
        }
    }

    #[test]
    fn the_assembly_keeps_each_figure_and_warns_for_what_it_skips() {
        let mut meter = Fixed { asked: Vec::new() };
        let c = assemble(&mut meter, &[0, 1, 2, 3, 16], 2);
        assert_eq!(meter.asked, [1, 2, 3, 16], "0 threads is never measured");
        assert_eq!(c.fma_gflops_1t, 150.0);
        let ceiling: Vec<(usize, f64, bool)> = c
            .parallel_ceiling
            .iter()
            .map(|r| (r.threads, r.ratio, r.oversubscribed))
            .collect();
        assert_eq!(ceiling, [(1, 0.9, false), (2, 1.8, false), (3, 1.8, true)]);
        assert_eq!(c.ceiling(3), Some(1.8));
        assert_eq!(c.ceiling(16), None);
        // Fork/join on the largest pool asked for, refused or not.
        assert_eq!(
            (c.fork_join_threads, c.fork_join_us, c.fork_join_hot_us),
            (16, 160.0, 1.0)
        );
        // The team beside it, with as many workers.
        assert_eq!(
            (c.team_barrier_us, c.team_region_us),
            (Some(8.0), Some(4.0))
        );
        assert_eq!(c.memory_bandwidth_gbs, 12.5);
        assert_eq!(
            c.warnings,
            [
                "parallel ceiling: 0 threads requested, skipped",
                "parallel ceiling at 16 threads not measured: cannot spawn",
                "bandwidth: fixed",
            ]
        );
        assert_eq!(c.logical_cpus, 2);
        assert_eq!(c.simd, simd::level().name());
        // No thread count at all: fork/join still measured, on two threads.
        let none = assemble(&mut Fixed { asked: Vec::new() }, &[], 2);
        assert!(none.parallel_ceiling.is_empty());
        assert_eq!(none.fork_join_threads, 2);
    }

    fn sample() -> Calibration {
        Calibration {
            cpu_model: "AMD EPYC 9R14".to_string(),
            cpu_signature: Some("AuthenticAMD 25/17/1".to_string()),
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
            team_barrier_us: Some(0.4),
            team_region_us: Some(6.5),
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
    fn signature_from_cpuinfo() {
        let text = "processor\t: 0\nvendor_id\t: GenuineIntel\ncpu family\t: 6\n\
                    model\t\t: 143\nmodel name\t: Intel(R) Xeon(R)\nstepping\t: 8\n";
        assert_eq!(signature_of(text).as_deref(), Some("GenuineIntel 6/143/8"));
        assert_eq!(signature_of("model name : x\n"), None);
    }

    #[test]
    fn model_from_cpuinfo() {
        let text = "processor\t: 0\nvendor_id\t: AuthenticAMD\nmodel name\t: AMD EPYC 9R14\n\
                    processor\t: 1\nmodel name\t: AMD EPYC 9R14\n";
        assert_eq!(model_of(text).as_deref(), Some("AMD EPYC 9R14"));
        // An ARM kernel's cpuinfo has no model name; an empty one is no model either.
        assert_eq!(model_of("processor\t: 0\nBogoMIPS\t: 50.00\n"), None);
        assert_eq!(
            model_of("model name\t:   \nmodel name\t: B\n").as_deref(),
            Some("B")
        );
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
