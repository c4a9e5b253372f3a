//! Fixtures of the short-range kernels' tests (cell list, Verlet list, cluster pairs): one
//! Lennard-Jones law, the tolerances and the comparison with the naive kernel (the oracle),
//! and the random spaced states each kernel is compared on.

use super::{SEED_1, SEED_2, max_rel_diff, on_threads, spaced_state};
use crate::kernels::{ForceKernel, ForceReport, Naive};
use crate::physics::LennardJones;
use crate::real::Real;
use crate::state::{Field, State, zero_field};

/// σ of the tests' Lennard-Jones law (ε = 1).
pub(crate) const SIGMA: f64 = 0.01;

/// The tests' Lennard-Jones law with cutoff `rc`.
pub(crate) fn lj<T: Real>(rc: f64) -> LennardJones<T> {
    LennardJones::new(1.0, SIGMA, rc)
}

/// Relative force tolerance (of the largest force) for a precision: the kernels sum in
/// another order than the naive one.
pub(crate) fn force_tol<T: Real>() -> f64 {
    if T::EPSILON_F64 > 1e-10 { 1e-4 } else { 1e-10 }
}

/// Relative energy tolerance for a precision (of |E|, at least 1e-3).
fn energy_tol<T: Real>() -> f64 {
    if T::EPSILON_F64 > 1e-10 { 1e-5 } else { 1e-9 }
}

/// One run of a kernel in [`agrees_with_naive`], for the checks a kernel adds of its own.
pub(crate) struct Run<'a, T: Real, const D: usize> {
    /// Threads of the run.
    pub p: usize,
    /// Whether it was the probe path.
    pub probe: bool,
    pub report: &'a ForceReport,
    /// The naive kernel's forces.
    pub want: &'a Field<T, D>,
}

/// Compares the forces, energy and interacting pairs of `kernel` with the naive kernel's on
/// `state`, at 1 and 2 threads, on the timed and the probe path; after each run `also` makes
/// the kernel's own checks (its counters, its other entry points).
pub(crate) fn agrees_with_naive<T: Real, const D: usize, K: ForceKernel<T, D>>(
    kernel: &mut K,
    state: &State<T, D>,
    law: LennardJones<T>,
    mut also: impl FnMut(&mut K, &Run<'_, T, D>),
) {
    let n = state.len();
    let mut want = zero_field::<T, D>(n);
    let oracle = Naive::new(law).compute(state, &mut want, true);
    for p in [1, 2] {
        for probe in [false, true] {
            let mut got = zero_field::<T, D>(n);
            let report = on_threads(p, || kernel.compute(state, &mut got, probe));
            let err = max_rel_diff(&got, &want);
            assert!(
                err <= force_tol::<T>(),
                "{:?} {} D={D} n={n} p={p} probe={probe}: off by {err:e} of the largest force",
                kernel.kind(),
                T::NAME
            );
            if probe {
                let (e, e0) = (report.energy.expect("probe energy"), oracle.energy.unwrap());
                assert!(
                    (e - e0).abs() <= energy_tol::<T>() * e0.abs().max(1e-3),
                    "{:?} {} D={D} n={n}: energy {e} vs naive {e0}",
                    kernel.kind(),
                    T::NAME
                );
                assert_eq!(
                    report.work.pairs_interacting,
                    oracle.work.pairs_interacting,
                    "{:?}: interacting pairs",
                    kernel.kind()
                );
            }
            let run = Run {
                p,
                probe,
                report: &report,
                want: &want,
            };
            also(kernel, &run);
        }
    }
}

/// Random spaced states (no two particles closer than 0.8σ) of 1 to 3000 particles at
/// `density`, each also spread over a box four times as wide (most bins empty, a few
/// interacting pairs), handed to `check` in turn.
pub(crate) fn spaced_states<T: Real, const D: usize>(
    density: f64,
    mut check: impl FnMut(&State<T, D>),
) {
    for (n, seed) in [
        (1, SEED_1),
        (2, SEED_2),
        (7, SEED_1),
        (100, SEED_2),
        (3000, SEED_1),
    ] {
        let side = (n as f64 / density).powf(1.0 / D as f64);
        check(&spaced_state::<T, D>(n, side, 0.8 * SIGMA, seed));
        check(&spaced_state::<T, D>(
            n.min(100),
            4.0 * side,
            0.8 * SIGMA,
            seed,
        ));
    }
}
