//! One full velocity-Verlet step (kicks, drift, walls, periodic re-ordering, forces) per
//! iteration, for every kernel at one mid-sized n.

use super::{SCENARIOS, criterion, kernels_for, pool, setup, sizes};
use criterion::{BenchmarkId, Criterion, Throughput};
use nbody_engine::run::bench_cases::{Work, bench_case};

fn step(c: &mut Criterion) {
    for scenario in SCENARIOS {
        let mut group = c.benchmark_group(format!("step/{}", scenario.name()));
        for kernel in kernels_for(scenario) {
            let n = sizes(kernel)[1];
            let pool = pool(1);
            let mut case = pool
                .install(|| bench_case(&setup(scenario, n), kernel, Work::Step))
                .expect("kernel applies to the scenario");
            group.throughput(Throughput::Elements(n as u64));
            let id = BenchmarkId::new(kernel.name(), n);
            group.bench_function(id, |b| pool.install(|| b.iter(|| case.run())));
        }
        group.finish();
    }
}

criterion::criterion_group! {
    name = benches;
    config = criterion();
    targets = step
}
