use nbody_engine::kernels::KernelKind;
use nbody_engine::scenario::ScenarioKind;

pub fn list() -> anyhow::Result<i32> {
    outln!("Kernels:");
    for k in KernelKind::ALL {
        let what = match k {
            KernelKind::Naive => {
                "every pair from both ends, n(n-1) evaluations; parallel over targets"
            }
            KernelKind::Symmetric => "each pair once (Newton's third law), n(n-1)/2; one thread",
            KernelKind::PerThread => {
                "symmetric, split over threads with private force buffers + reduction"
            }
            KernelKind::CellList => {
                "bins of side >= cutoff, sorted by bin; O(n); parallel over bins"
            }
            KernelKind::Octree => {
                "Barnes-Hut tree (quadtree in 2-D), opening angle --theta, --multipole \
                 monopole|quadrupole; O(n log n)"
            }
            KernelKind::Verlet => {
                "half neighbour list, cutoff + --skin, rebuilt when a particle moved skin/2; O(n)"
            }
            KernelKind::ClusterPair => {
                "Verlet list of 4-particle clusters against 16-particle runs, one SIMD block \
                 each, for dense systems; --skin as verlet; O(n)"
            }
            KernelKind::Fmm => {
                "fast multipole (3-D): mutual cell-cell expansions of --order 1..8 between \
                 cells with r1 + r2 < --theta x distance, near leaves directly; O(n)"
            }
            KernelKind::FmmHarmonic => {
                "the fmm on solid harmonics of --order 1..20, each translation O(p^3) by \
                 rotation to the z-axis; the unsoftened 1/r law (coulomb); O(n)"
            }
        };
        outln!("  {:<12} {what}", k.name());
    }
    outln!("\nScenarios:");
    outln!(
        "  {:<10} {:>3} {:>9} {:>6} {:>8}  description",
        "name",
        "dim",
        "precision",
        "n",
        "dt"
    );
    for s in ScenarioKind::ALL {
        let d = s.defaults();
        outln!(
            "  {:<10} {:>3} {:>9} {:>6} {:>8}  {}",
            s.name(),
            s.dim(),
            d.precision.name(),
            d.n,
            d.dt,
            s.summary()
        );
    }
    outln!("\nSupported combinations (law: kernels):");
    for s in ScenarioKind::ALL {
        let kernels = if s.periodic() {
            // A periodic box takes the kernels with a periodic form only.
            let names: Vec<&str> = KernelKind::ALL
                .into_iter()
                .filter(|k| k.supports(s.law()) && k.periodic_form())
                .map(KernelKind::name)
                .collect();
            format!("{} (periodic box)", names.join(", "))
        } else {
            nbody_engine::kernels::supported_for(s.law())
        };
        outln!("  {:<10} ({}): {}", s.name(), s.law().name(), kernels);
    }
    Ok(0)
}
