//! Every kernel against the naive sum in f64, on every law it supports, for several n
//! (tiny and odd included), thread counts (2 and 3 oversubscribe a 2-CPU machine) and both
//! precisions; the octree's error shrinks with θ and is exact at θ = 0, at both expansion
//! orders, the quadrupole's below the monopole's; the fmm is exact at θ = 0 and within its
//! tolerance on the scenarios, and `validate` skips it, visibly, at θ ≥ 1.

use nbody_engine::kernels::CompiledKernels;
use nbody_engine::kernels::{KernelKind, KernelParams, Multipole};
use nbody_engine::real::Real;
use nbody_engine::scenario::{Precision, ScenarioKind, Setup, System, SystemJob};
use nbody_engine::state::zero_field;
use nbody_engine::validate::{EXACT_ULPS, reference_forces};

/// Per kernel: the worst |F − F_naive| / Σ|F_ij| (naive in the same precision) and the median
/// |F − F_ref| / |F_ref| against the f64 reference.
struct Compare {
    kinds: Vec<KernelKind>,
    threads: usize,
    theta: f64,
    multipole: Multipole,
    /// The fmm's expansion order (None: the default).
    order: Option<usize>,
    /// Computes with the probe (energy, interacting pairs) on both sides: the path of the first
    /// kick and of every energy check.
    probe: bool,
}

struct Errors {
    kind: KernelKind,
    rounding_ratio: f64,
    median_rel: f64,
    /// |E − E_naive| / |E_naive|, probe runs only.
    energy_rel: f64,
    /// Interacting pairs counted by the kernel and by naive, probe runs only.
    pairs: (u64, u64),
}

impl SystemJob for Compare {
    type Output = (f64, Vec<Errors>);
    fn run<T: Real, L: CompiledKernels<T, D>, const D: usize>(
        self,
        sys: System<T, L, D>,
    ) -> Self::Output {
        let n = sys.state.len();
        let (reference, abs_sum) = reference_forces(&sys.law.widen(), &sys.state.convert::<f64>());
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(self.threads)
            .build()
            .unwrap();
        let params = KernelParams {
            theta: self.theta,
            multipole: self.multipole,
            order: self.order.unwrap_or(KernelParams::default().order),
            ..KernelParams::default()
        };
        // Exact kernels are compared with naive in their own precision (identical pair
        // arithmetic and cutoff decisions); the f64 reference gives the reported error.
        let mut naive = zero_field::<T, D>(n);
        let naive_report = KernelKind::Naive
            .build::<T, L, D>(sys.law, &params)
            .unwrap()
            .compute(&sys.state, &mut naive, self.probe);
        let mut out = Vec::new();
        for kind in self
            .kinds
            .iter()
            .copied()
            .filter(|k| k.supports(sys.law.kind()))
        {
            let mut k = kind.build::<T, L, D>(sys.law, &params).unwrap();
            let mut f = zero_field::<T, D>(n);
            // Twice: the second call runs on reused buffers.
            pool.install(|| k.compute(&sys.state, &mut f, false));
            let report = pool.install(|| k.compute(&sys.state, &mut f, self.probe));
            let (energy_rel, pairs) = if self.probe {
                let (e, e_naive) = (report.energy.unwrap(), naive_report.energy.unwrap());
                (
                    (e - e_naive).abs() / (e_naive.abs() + 1e-300),
                    (
                        report.work.pairs_interacting,
                        naive_report.work.pairs_interacting,
                    ),
                )
            } else {
                (0.0, (0, 0))
            };
            let mut worst = 0.0f64;
            let mut rel = Vec::new();
            for i in 0..n {
                let err: f64 = (0..D)
                    .map(|d| (f[d][i].as_f64() - reference[d][i]).powi(2))
                    .sum::<f64>()
                    .sqrt();
                let norm: f64 = (0..D).map(|d| reference[d][i].powi(2)).sum::<f64>().sqrt();
                let err_naive: f64 = (0..D)
                    .map(|d| (f[d][i].as_f64() - naive[d][i].as_f64()).powi(2))
                    .sum::<f64>()
                    .sqrt();
                if abs_sum[i] > 0.0 {
                    worst = worst.max(err_naive / abs_sum[i]);
                } else {
                    assert_eq!(err, 0.0, "{kind:?}: force on an isolated particle");
                }
                if norm > 0.0 {
                    rel.push(err / norm);
                }
            }
            rel.sort_by(f64::total_cmp);
            let median_rel = rel.get(rel.len() / 2).copied().unwrap_or(0.0);
            out.push(Errors {
                kind,
                rounding_ratio: worst,
                median_rel,
                energy_rel,
                pairs,
            });
        }
        (T::EPSILON_F64, out)
    }
}

fn setup(scenario: ScenarioKind, n: usize, precision: Precision, seed: u64) -> Setup {
    let mut s = Setup::new(scenario);
    s.n = Some(n);
    s.precision = Some(precision);
    s.seed = seed;
    s.allow_fewer = true;
    s
}

#[test]
fn exact_kernels_agree_with_the_reference() {
    let exact = vec![
        KernelKind::Naive,
        KernelKind::Symmetric,
        KernelKind::PerThread,
        KernelKind::CellList,
        KernelKind::Verlet,
    ];
    // The periodic melt: only naive has a periodic form so far, checked against the
    // nearest-image reference in the engine's validate::periodic tests.
    for scenario in ScenarioKind::ALL.into_iter().filter(|s| !s.periodic()) {
        for precision in [Precision::F32, Precision::F64] {
            for n in [1, 2, 7, 100, 1500, 3001] {
                for threads in [1, 2, 3] {
                    let job = Compare {
                        kinds: exact.clone(),
                        threads,
                        theta: 0.5,
                        multipole: Multipole::Monopole,
                        order: None,
                        probe: false,
                    };
                    let (eps, errs) = setup(scenario, n, precision, 7).dispatch(job).unwrap();
                    assert!(errs.len() >= 3);
                    for e in errs {
                        assert!(
                            e.rounding_ratio <= EXACT_ULPS * eps,
                            "{scenario:?} {precision:?} n={n} p={threads} {:?}: |dF|/sum|F_ij| = {:e}",
                            e.kind,
                            e.rounding_ratio
                        );
                    }
                }
            }
        }
    }
}

/// The probe path (forces with the energy and the interacting pairs, used by the first kick and
/// every energy check) of each exact kernel against naive's probe: the same forces to
/// rounding, the same energy to rounding, the same pairs counted.
#[test]
fn probe_paths_agree_with_naive() {
    let exact = vec![
        KernelKind::Symmetric,
        KernelKind::PerThread,
        KernelKind::CellList,
        KernelKind::Verlet,
    ];
    // The periodic melt: only naive has a periodic form so far, checked against the
    // nearest-image reference in the engine's validate::periodic tests.
    for scenario in ScenarioKind::ALL.into_iter().filter(|s| !s.periodic()) {
        for precision in [Precision::F32, Precision::F64] {
            for n in [2, 7, 1500] {
                for threads in [1, 2] {
                    let job = Compare {
                        kinds: exact.clone(),
                        threads,
                        theta: 0.5,
                        multipole: Multipole::Monopole,
                        order: None,
                        probe: true,
                    };
                    let (eps, errs) = setup(scenario, n, precision, 11).dispatch(job).unwrap();
                    assert!(!errs.is_empty());
                    for e in errs {
                        let at =
                            format!("{scenario:?} {precision:?} n={n} p={threads} {:?}", e.kind);
                        assert!(
                            e.rounding_ratio <= EXACT_ULPS * eps,
                            "{at}: |dF|/sum|F_ij| = {:e}",
                            e.rounding_ratio
                        );
                        // Energies are summed in f64 from pair terms of the run's precision.
                        assert!(
                            e.energy_rel <= EXACT_ULPS * eps,
                            "{at}: energy differs from naive's by {:e} (relative)",
                            e.energy_rel
                        );
                        assert_eq!(e.pairs.0, e.pairs.1, "{at}: interacting pairs");
                    }
                }
            }
        }
    }
}

#[test]
fn octree_is_exact_at_theta_zero() {
    for scenario in [ScenarioKind::Galaxy, ScenarioKind::Coulomb] {
        for n in [1, 3, 17, 600] {
            for threads in [1, 2] {
                for multipole in Multipole::ALL {
                    let job = Compare {
                        kinds: vec![KernelKind::Octree],
                        threads,
                        theta: 0.0,
                        multipole,
                        order: None,
                        probe: false,
                    };
                    let (eps, errs) = setup(scenario, n, Precision::F64, 3).dispatch(job).unwrap();
                    assert!(
                        errs[0].rounding_ratio <= EXACT_ULPS * eps,
                        "{scenario:?} n={n} {multipole:?}: {:e}",
                        errs[0].rounding_ratio
                    );
                }
            }
        }
    }
}

/// Median relative force error of the octree on a scenario of 3000 particles.
fn octree_error(scenario: ScenarioKind, theta: f64, multipole: Multipole, threads: usize) -> f64 {
    let job = Compare {
        kinds: vec![KernelKind::Octree],
        threads,
        theta,
        multipole,
        order: None,
        probe: false,
    };
    setup(scenario, 3000, Precision::F64, 5)
        .dispatch(job)
        .unwrap()
        .1[0]
        .median_rel
}

#[test]
fn octree_error_grows_with_theta_and_meets_the_target() {
    for scenario in [ScenarioKind::Galaxy, ScenarioKind::Coulomb] {
        let errors: Vec<f64> = [0.2, 0.4, 0.6, 0.9]
            .iter()
            .map(|&theta| octree_error(scenario, theta, Multipole::Monopole, 2))
            .collect();
        assert!(
            errors.windows(2).all(|w| w[0] < w[1]),
            "{scenario:?}: {errors:?}"
        );
        let at_half = octree_error(scenario, 0.5, Multipole::Monopole, 1);
        let bound = nbody_engine::validate::octree_tolerance(scenario.law(), 0.5);
        assert!(
            at_half <= bound,
            "{scenario:?}: median error {at_half:e} > {bound:e} at theta 0.5"
        );
    }
}

#[test]
fn quadrupole_octree_error_is_below_the_monopoles() {
    for scenario in [ScenarioKind::Galaxy, ScenarioKind::Coulomb] {
        let mut last = 0.0;
        for theta in [0.3, 0.5, 0.7] {
            let mono = octree_error(scenario, theta, Multipole::Monopole, 1);
            let quad = octree_error(scenario, theta, Multipole::Quadrupole, 2);
            assert!(
                quad < mono && quad > last,
                "{scenario:?} theta {theta}: quadrupole {quad:e}, monopole {mono:e}"
            );
            last = quad;
        }
    }
}

/// The fmm on the long-range scenarios: the direct sum at θ = 0 (every pair in the near
/// field), and within its tolerance at θ = 0.5 for several orders, on any thread count.
#[test]
fn fmm_is_exact_at_theta_zero_and_within_its_tolerance() {
    for scenario in [ScenarioKind::Galaxy, ScenarioKind::Coulomb] {
        for n in [1, 3, 17, 600] {
            for threads in [1, 2] {
                let job = Compare {
                    kinds: vec![KernelKind::Fmm],
                    threads,
                    theta: 0.0,
                    multipole: Multipole::Monopole,
                    order: None,
                    probe: false,
                };
                let (eps, errs) = setup(scenario, n, Precision::F64, 3).dispatch(job).unwrap();
                assert!(
                    errs[0].rounding_ratio <= EXACT_ULPS * eps,
                    "{scenario:?} n={n}: {:e}",
                    errs[0].rounding_ratio
                );
            }
        }
        for order in [2, 4, 6] {
            let job = Compare {
                kinds: vec![KernelKind::Fmm],
                threads: 2,
                theta: 0.5,
                multipole: Multipole::Monopole,
                order: Some(order),
                probe: true,
            };
            let errs = setup(scenario, 3000, Precision::F64, 5)
                .dispatch(job)
                .unwrap()
                .1;
            let bound = nbody_engine::validate::fmm_tolerance(0.5, order);
            assert!(
                errs[0].median_rel <= bound,
                "{scenario:?} p={order}: median error {:e} > {bound:e}",
                errs[0].median_rel
            );
            // The probe's energy: within the force error's order of magnitude.
            assert!(
                errs[0].energy_rel <= bound,
                "{scenario:?} p={order}: energy"
            );
        }
    }
}

/// At θ = 1 the fmm refuses to run (its expansions diverge there) but the octree does not:
/// `validate` checks the other kernels, shows the fmm as skipped on each long-range scenario,
/// and passes.
#[test]
fn validate_at_theta_one_skips_the_fmm_and_passes() {
    let o = crate::bin()
        .args(["validate", "-n", "300", "--theta", "1"])
        .output()
        .unwrap();
    let out = crate::text(&o.stdout);
    assert_eq!(
        o.status.code(),
        Some(0),
        "{out}\n{}",
        crate::text(&o.stderr)
    );
    let skips: Vec<&str> = out.lines().filter(|l| l.contains("skip")).collect();
    // The melt's verlet (a lattice of 300 atoms or fewer is too small a box for its bins),
    // one row per fmm on each long-range scenario (the harmonic one on Coulomb only), and the
    // closing line.
    assert_eq!(skips.len(), 5, "{out}");
    assert!(skips[0].trim_start().starts_with("verlet"), "{}", skips[0]);
    for row in &skips[1..4] {
        assert!(row.trim_start().starts_with("fmm"), "{row}");
        assert!(
            row.contains("skipped (the fmm needs theta below 1)"),
            "{row}"
        );
    }
    assert!(
        out.contains("skipped: lj-melt/verlet, coulomb/fmm, coulomb/fmm-harmonic, galaxy/fmm")
            && !out.contains("FAIL"),
        "{out}"
    );
    // The octree still ran at θ = 1.
    assert!(
        out.lines().any(|l| l.trim_start().starts_with("octree")),
        "{out}"
    );
}
