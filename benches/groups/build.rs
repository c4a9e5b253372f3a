//! The build phase alone: cell-list binning and strip layout, the octree (Morton keys, sort,
//! nodes, groups), the fmm (the same tree, centres, radii and multipoles) and the Verlet list
//! (binning and the half list), over a few n.

use super::{SCENARIOS, criterion, kernels_for, setup, sizes};
use criterion::{BenchmarkId, Criterion, Throughput};
use nbody_engine::kernels::KernelKind;
use nbody_engine::run::bench_cases::{Work, bench_case};

fn build(c: &mut Criterion) {
    for scenario in SCENARIOS {
        for kernel in kernels_for(scenario).filter(|k| {
            matches!(
                k,
                KernelKind::CellList | KernelKind::Octree | KernelKind::Verlet | KernelKind::Fmm
            )
        }) {
            let mut group =
                c.benchmark_group(format!("build/{}/{}", scenario.name(), kernel.name()));
            for &n in sizes(kernel) {
                let mut case = bench_case(&setup(scenario, n), kernel, Work::Build)
                    .expect("the kernel has a build phase");
                group.throughput(Throughput::Elements(n as u64));
                group.bench_function(BenchmarkId::from_parameter(n), |b| b.iter(|| case.run()));
            }
            group.finish();
        }
    }
}

criterion::criterion_group! {
    name = benches;
    config = criterion();
    targets = build
}
