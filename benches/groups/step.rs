//! One full velocity-Verlet step (kicks, drift, walls, periodic re-ordering, forces) per
//! iteration, for every kernel at one mid-sized n.

use super::{SCENARIOS, criterion, kernels_for, pool, setup, sizes};
use criterion::measurement::WallTime;
use criterion::{BenchmarkGroup, BenchmarkId, Criterion, Throughput};
use nbody_bench::engine::Simulation;
use nbody_bench::kernels::{KernelKind, KernelParams};
use nbody_bench::physics::PairLaw;
use nbody_bench::real::Real;
use nbody_bench::scenario::{System, SystemJob};

fn step(c: &mut Criterion) {
    for scenario in SCENARIOS {
        let mut group = c.benchmark_group(format!("step/{}", scenario.name()));
        for kernel in kernels_for(scenario) {
            let n = sizes(kernel)[1];
            let job = StepBench {
                group: &mut group,
                kernel,
            };
            setup(scenario, n).dispatch(job).expect("scenario builds");
        }
        group.finish();
    }
}

struct StepBench<'a, 'c> {
    group: &'a mut BenchmarkGroup<'c, WallTime>,
    kernel: KernelKind,
}

impl SystemJob for StepBench<'_, '_> {
    type Output = ();

    fn run<T: Real, L: PairLaw<T>, const D: usize>(self, system: System<T, L, D>) {
        let n = system.state.len();
        let kernel = self
            .kernel
            .build::<T, L, D>(system.law, &KernelParams::default())
            .expect("kernel applies to the scenario");
        let pool = pool(1);
        let mut sim = pool.install(|| Simulation::new(system, kernel));
        self.group.throughput(Throughput::Elements(n as u64));
        let id = BenchmarkId::new(self.kernel.name(), n);
        self.group.bench_function(id, |b| {
            pool.install(|| {
                b.iter(|| {
                    sim.step()
                        .expect("the scenario's dt keeps particles inside")
                })
            })
        });
    }
}

criterion::criterion_group! {
    name = benches;
    config = criterion();
    targets = step
}
