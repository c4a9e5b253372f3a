//! One force computation per iteration, for every kernel over a few n.

use super::{SCENARIOS, criterion, kernels_for, pool, setup, sizes, thread_counts};
use criterion::measurement::WallTime;
use criterion::{BenchmarkGroup, BenchmarkId, Criterion, Throughput};
use nbody_bench::kernels::{KernelKind, KernelParams};
use nbody_bench::physics::PairLaw;
use nbody_bench::real::Real;
use nbody_bench::scenario::{System, SystemJob};
use nbody_bench::state::zero_field;

fn force(c: &mut Criterion) {
    for scenario in SCENARIOS {
        for kernel in kernels_for(scenario) {
            let mut group =
                c.benchmark_group(format!("force/{}/{}", scenario.name(), kernel.name()));
            for &n in sizes(kernel) {
                for threads in thread_counts(kernel) {
                    let job = ForceBench {
                        group: &mut group,
                        kernel,
                        threads,
                    };
                    setup(scenario, n).dispatch(job).expect("scenario builds");
                }
            }
            group.finish();
        }
    }
}

struct ForceBench<'a, 'c> {
    group: &'a mut BenchmarkGroup<'c, WallTime>,
    kernel: KernelKind,
    threads: usize,
}

impl SystemJob for ForceBench<'_, '_> {
    type Output = ();

    fn run<T: Real, L: PairLaw<T>, const D: usize>(self, system: System<T, L, D>) {
        let n = system.state.len();
        let mut kernel = self
            .kernel
            .build::<T, L, D>(system.law, &KernelParams::default())
            .expect("kernel applies to the scenario");
        let mut state = system.state;
        let mut forces = zero_field::<T, D>(n);
        // The layout the engine would give the kernel (cell or Morton order).
        if let Some(order) = kernel.spatial_order(&state) {
            state.permute(&order, &mut [&mut forces]);
        }
        let pool = pool(self.threads);
        // The work of a computation once the kernel's structures exist: the Verlet list, built
        // by the first call, is kept by the others (its rebuild is timed by `build/`).
        pool.install(|| kernel.compute(&state, &mut forces, false));
        let pairs = pool.install(|| kernel.compute(&state, &mut forces, false).work.pair_checks);
        self.group.throughput(Throughput::Elements(pairs.max(1)));
        let id = BenchmarkId::new(format!("threads={}", self.threads), n);
        self.group.bench_function(id, |b| {
            pool.install(|| b.iter(|| kernel.compute(&state, &mut forces, false)))
        });
    }
}

criterion::criterion_group! {
    name = benches;
    config = criterion();
    targets = force
}
