//! Shared set-up of the benchmark groups.

pub mod build;
pub mod force;
pub mod step;

use criterion::Criterion;
use nbody_engine::kernels::KernelKind;
use nbody_engine::scenario::{ScenarioKind, Setup};
use std::time::Duration;

/// Short measurements and few samples: the benches cover many kernels and sizes, and a
/// force computation at the largest n takes milliseconds.
pub fn criterion() -> Criterion {
    Criterion::default()
        .sample_size(10)
        .warm_up_time(Duration::from_millis(500))
        .measurement_time(Duration::from_millis(1500))
}

/// The scenarios benchmarked: one short-range 2-D law and one long-range 3-D law.
pub const SCENARIOS: [ScenarioKind; 2] = [ScenarioKind::LjBox, ScenarioKind::Galaxy];

/// Particle counts for a kernel: the O(n²) kernels stay small so that a computation lasts
/// about a millisecond; the O(n) and O(n log n) ones go further.
pub fn sizes(kernel: KernelKind) -> &'static [usize] {
    match kernel {
        KernelKind::CellList
        | KernelKind::Octree
        | KernelKind::Verlet
        | KernelKind::ClusterPair
        | KernelKind::Fmm
        | KernelKind::FmmHarmonic => &[1000, 4000, 16000],
        KernelKind::Naive | KernelKind::Symmetric | KernelKind::PerThread => &[500, 1000, 2000],
    }
}

/// Thread counts for a kernel: one, and every logical CPU for the per-thread kernel, which
/// exists to use them, and for the Verlet list, which chooses between one and several parts.
pub fn thread_counts(kernel: KernelKind) -> Vec<usize> {
    let cpus = std::thread::available_parallelism().map_or(1, |n| n.get());
    if matches!(kernel, KernelKind::PerThread | KernelKind::Verlet) && cpus > 1 {
        vec![1, cpus]
    } else {
        vec![1]
    }
}

/// The kernels that apply to a scenario.
pub fn kernels_for(scenario: ScenarioKind) -> impl Iterator<Item = KernelKind> {
    KernelKind::ALL
        .into_iter()
        .filter(move |k| k.supports(scenario.law()))
}

/// The scenario at `n` particles, seed 1.
pub fn setup(scenario: ScenarioKind, n: usize) -> Setup {
    let mut setup = Setup::new(scenario);
    setup.n = Some(n);
    setup
}

pub fn pool(threads: usize) -> rayon::ThreadPool {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .expect("rayon pool")
}
