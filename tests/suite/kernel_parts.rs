//! The parts of a force computation that distributed drivers use, against the whole:
//! `compute_targets` over the blocks of a partition gives the forces of `compute` exactly (the
//! same arithmetic per target; to rounding for the Verlet list, whose whole uses Newton's third
//! law and whose targets gather from full lists), and `compute_share` summed over the shares
//! gives them to rounding (the symmetric kernels split the pair work, so the sums are grouped
//! differently).

use nbody_engine::kernels::CompiledKernels;
use nbody_engine::kernels::{KernelKind, KernelParams, Share};
use nbody_engine::real::Real;
use nbody_engine::scenario::{ScenarioKind, Setup, System, SystemJob};
use nbody_engine::state::zero_field;
use nbody_engine::validate::{EXACT_ULPS, reference_forces};

struct Parts {
    threads: usize,
    kernels: Vec<KernelKind>,
    counts: Vec<usize>,
}

impl SystemJob for Parts {
    type Output = ();
    fn run<T: Real, L: CompiledKernels<T, D>, const D: usize>(
        self,
        sys: System<T, L, D>,
    ) -> Self::Output {
        let n = sys.state.len();
        let (_, abs_sum) = reference_forces(&sys.law.widen(), &sys.state.convert::<f64>());
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(self.threads)
            .build()
            .unwrap();
        let params = KernelParams::default();
        for kind in self
            .kernels
            .iter()
            .copied()
            .filter(|k| k.supports(sys.law.kind()))
        {
            let mut kernel = kind.build::<T, L, D>(sys.law, &params).unwrap();
            let mut whole = zero_field::<T, D>(n);
            pool.install(|| kernel.compute(&sys.state, &mut whole, false));
            for &count in &self.counts {
                let mut sum = zero_field::<f64, D>(n);
                let mut checks = 0;
                for index in 0..count {
                    let share = Share::new(index, count).unwrap();
                    let block = share.block(n);
                    let mut part = zero_field::<T, D>(block.len());
                    let out = part.each_mut().map(|f| f.as_mut_slice());
                    pool.install(|| kernel.compute_targets(&sys.state, block.clone(), out));
                    for d in 0..D {
                        if kind == KernelKind::Verlet {
                            for (k, i) in block.clone().enumerate() {
                                let err = (part[d][k].as_f64() - whole[d][i].as_f64()).abs();
                                assert!(
                                    err <= EXACT_ULPS * T::EPSILON_F64 * abs_sum[i],
                                    "{kind:?} n={n} share {index}/{count}: particle {i} off by {err:e}"
                                );
                            }
                        } else {
                            assert_eq!(
                                part[d][..],
                                whole[d][block.clone()],
                                "{kind:?} n={n} share {index}/{count}: targets differ from the whole"
                            );
                        }
                    }
                    let mut f = zero_field::<T, D>(n);
                    let report = pool.install(|| kernel.compute_share(&sys.state, share, &mut f));
                    checks += report.work.pair_checks;
                    for d in 0..D {
                        for i in 0..n {
                            sum[d][i] += f[d][i].as_f64();
                        }
                    }
                }
                for i in 0..n {
                    let err: f64 = (0..D)
                        .map(|d| (sum[d][i] - whole[d][i].as_f64()).powi(2))
                        .sum::<f64>()
                        .sqrt();
                    assert!(
                        err <= EXACT_ULPS * T::EPSILON_F64 * abs_sum[i],
                        "{kind:?} n={n} {count} shares: particle {i} off by {err:e}"
                    );
                }
                if kind.is_exact()
                    && !matches!(
                        kind,
                        KernelKind::CellList | KernelKind::Verlet | KernelKind::ClusterPair
                    )
                {
                    let pairs = (n * n.saturating_sub(1)) as u64;
                    let want = match kind {
                        KernelKind::Naive => pairs,
                        _ => pairs / 2,
                    };
                    assert_eq!(checks, want, "{kind:?} n={n} {count} shares: pair work");
                }
            }
        }
    }
}

#[test]
fn parts_add_up_to_the_whole() {
    // The periodic melt: only naive has a periodic form so far, checked against the
    // nearest-image reference in the engine's validate::periodic tests.
    for scenario in ScenarioKind::ALL.into_iter().filter(|s| !s.periodic()) {
        for n in [1, 5, 301, 1200] {
            for threads in [1, 2] {
                let mut setup = Setup::new(scenario);
                setup.n = Some(n);
                setup.allow_fewer = true;
                let parts = Parts {
                    threads,
                    kernels: KernelKind::ALL.to_vec(),
                    counts: vec![1, 2, 3, 4, 7],
                };
                setup.dispatch(parts).unwrap();
            }
        }
    }
}

/// Blocks large enough that the octree walks their groups in parallel, with gaps between
/// the selected groups.
#[test]
fn octree_targets_in_parallel() {
    let mut setup = Setup::new(ScenarioKind::Galaxy);
    setup.n = Some(6000);
    let parts = Parts {
        threads: 2,
        kernels: vec![KernelKind::Octree],
        counts: vec![3],
    };
    setup.dispatch(parts).unwrap();
}
