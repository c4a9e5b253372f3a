//! One force computation per iteration, for every kernel over a few n.

use super::{SCENARIOS, criterion, kernels_for, pool, setup, sizes, thread_counts};
use criterion::{BenchmarkId, Criterion, Throughput};
use nbody_engine::run::bench_cases::{Work, bench_case};

fn force(c: &mut Criterion) {
    for scenario in SCENARIOS {
        for kernel in kernels_for(scenario) {
            let mut group =
                c.benchmark_group(format!("force/{}/{}", scenario.name(), kernel.name()));
            for &n in sizes(kernel) {
                for threads in thread_counts(kernel) {
                    let pool = pool(threads);
                    // Prepared on the pool: the layout the engine would give the kernel, and
                    // a first computation that builds what it keeps (the Verlet list, whose
                    // rebuild is timed by `build/`).
                    let mut case = pool
                        .install(|| bench_case(&setup(scenario, n), kernel, Work::Force))
                        .expect("kernel applies to the scenario");
                    let pairs = pool.install(|| case.run());
                    group.throughput(Throughput::Elements(pairs.max(1)));
                    let id = BenchmarkId::new(format!("threads={threads}"), n);
                    group.bench_function(id, |b| pool.install(|| b.iter(|| case.run())));
                }
            }
            group.finish();
        }
    }
}

criterion::criterion_group! {
    name = benches;
    config = criterion();
    targets = force
}
