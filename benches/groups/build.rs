//! The build phase alone: cell-list binning and strip layout, the octree (Morton keys, sort,
//! nodes, groups) and the Verlet list (binning and the half list), over a few n.

use super::{SCENARIOS, criterion, kernels_for, setup, sizes};
use criterion::measurement::WallTime;
use criterion::{BenchmarkGroup, BenchmarkId, Criterion, Throughput};
use nbody_bench::kernels::{CellList, KernelKind, KernelParams, Octree, Verlet};
use nbody_bench::physics::PairLaw;
use nbody_bench::real::Real;
use nbody_bench::scenario::{System, SystemJob};

fn build(c: &mut Criterion) {
    for scenario in SCENARIOS {
        for kernel in kernels_for(scenario).filter(|k| {
            matches!(
                k,
                KernelKind::CellList | KernelKind::Octree | KernelKind::Verlet
            )
        }) {
            let mut group =
                c.benchmark_group(format!("build/{}/{}", scenario.name(), kernel.name()));
            for &n in sizes(kernel) {
                let job = BuildBench {
                    group: &mut group,
                    kernel,
                };
                setup(scenario, n).dispatch(job).expect("scenario builds");
            }
            group.finish();
        }
    }
}

struct BuildBench<'a, 'c> {
    group: &'a mut BenchmarkGroup<'c, WallTime>,
    kernel: KernelKind,
}

impl SystemJob for BuildBench<'_, '_> {
    type Output = ();

    fn run<T: Real, L: PairLaw<T>, const D: usize>(self, system: System<T, L, D>) {
        let n = system.state.len();
        let state = system.state;
        self.group.throughput(Throughput::Elements(n as u64));
        let id = BenchmarkId::from_parameter(n);
        match self.kernel {
            KernelKind::CellList => {
                let mut cells = CellList::new(system.law).expect("the law has a cutoff");
                self.group
                    .bench_function(id, |b| b.iter(|| cells.build(&state)));
            }
            KernelKind::Octree => {
                let params = KernelParams::default();
                let mut tree = Octree::new(system.law, params.theta, params.leaf_size);
                self.group
                    .bench_function(id, |b| b.iter(|| tree.build(&state)));
            }
            KernelKind::Verlet => {
                let mut list = Verlet::new(system.law, KernelParams::default().skin)
                    .expect("the law has a cutoff");
                self.group
                    .bench_function(id, |b| b.iter(|| list.build(&state)));
            }
            other => unreachable!("{} has no build phase", other.name()),
        }
    }
}

criterion::criterion_group! {
    name = benches;
    config = criterion();
    targets = build
}
