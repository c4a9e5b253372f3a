//! The cell list against the naive kernel (the oracle), on random, degenerate and reordered
//! states, serial and parallel.

use super::*;
use crate::physics::{Coulomb, LennardJones};
use crate::state::zero_field;
use crate::testing::short_range::{SIGMA, agrees_with_naive, lj, spaced_states};
use crate::testing::{SEED_1, SEED_2, on_threads, random_state, spaced_state};

/// The comparison with the naive kernel, with the list's own check: no more pairs looked at
/// than there are.
fn agrees_with<T: Real, const D: usize>(
    kernel: &mut CellList<LennardJones<T>, T, D>,
    state: &State<T, D>,
    law: LennardJones<T>,
) {
    let n = state.len() as u64;
    agrees_with_naive(kernel, state, law, |_, run| {
        assert!(run.report.work.pair_checks <= n * n.saturating_sub(1));
    });
}

/// Random spaced states (no two particles closer than 0.8σ) at a few sizes and densities.
fn random_states<T: Real, const D: usize>() {
    let law = lj::<T>(2.5 * SIGMA);
    let mut kernel = CellList::new(law).expect("LJ has a cutoff");
    // Liquid-like: ~8 neighbours inside rc = 2.5σ.
    let density = if D == 2 { 4000.0 } else { 1.2e5 };
    spaced_states::<T, D>(density, |state| agrees_with(&mut kernel, state, law));
}

#[test]
fn random_2d_f32() {
    random_states::<f32, 2>();
}

#[test]
fn random_2d_f64() {
    random_states::<f64, 2>();
}

#[test]
fn random_3d_f32() {
    random_states::<f32, 3>();
}

#[test]
fn random_3d_f64() {
    random_states::<f64, 3>();
}

/// A cutoff long enough that the step is worth splitting over threads (exercises the parallel
/// chunks at 2 threads) and that runs span several SIMD blocks.
fn long_cutoff<T: Real, const D: usize>() {
    let law = lj::<T>(8.0 * SIGMA);
    let mut kernel = CellList::new(law).expect("LJ has a cutoff");
    let n = 3000;
    let side = (n as f64 / if D == 2 { 4000.0 } else { 1.2e5 }).powf(1.0 / D as f64);
    let state = spaced_state::<T, D>(n, side, 0.8 * SIGMA, SEED_2);
    agrees_with(&mut kernel, &state, law);
    assert!(kernel.strips.expected_candidates() >= crate::kernels::MIN_PARALLEL_PAIRS);
    // The parallel path counts the same work as the serial one.
    let mut f = zero_field::<T, D>(n);
    let serial = on_threads(1, || kernel.compute(&state, &mut f, false)).work;
    let parallel = on_threads(2, || kernel.compute(&state, &mut f, false)).work;
    assert_eq!(serial, parallel);
}

#[test]
fn long_cutoff_parallel() {
    long_cutoff::<f32, 2>();
    long_cutoff::<f64, 2>();
    long_cutoff::<f32, 3>();
    long_cutoff::<f64, 3>();
}

/// The one-thread sort (ranks counted in place) and the pool's (the two-level counting sort
/// and the parallel layout) give the same strips, order and forces, bit for bit.
fn same_layout_on_one_thread_and_many<T: Real, const D: usize>() {
    let law = lj::<T>(2.5 * SIGMA);
    // Enough particles that the sort and the layout fork.
    let n = 20_000;
    assert!(crate::par::MIN_FORK_ELEMENTS <= n * D);
    let side = (n as f64 / if D == 2 { 4000.0 } else { 1.2e5 }).powf(1.0 / D as f64);
    let state = spaced_state::<T, D>(n, side, 0.8 * SIGMA, SEED_1);
    let run = |threads| {
        on_threads(threads, || {
            let mut kernel = CellList::new(law).expect("LJ has a cutoff");
            let order = kernel.spatial_order(&state).expect("the cell list sorts");
            let mut f = zero_field::<T, D>(n);
            kernel.compute(&state, &mut f, false);
            let s = &kernel.strips;
            let layout = (
                s.pos.clone(),
                s.src.clone(),
                s.column.clone(),
                s.own.clone(),
            );
            (order, layout, s.rank.clone(), f)
        })
    };
    let one = run(1);
    for threads in [2, 3] {
        let many = run(threads);
        assert!(one.0 == many.0, "order at {threads} threads");
        assert!(one.1 == many.1, "strips at {threads} threads");
        assert!(one.2 == many.2, "ranks at {threads} threads");
        assert!(one.3 == many.3, "forces at {threads} threads");
    }
}

#[test]
fn the_layout_is_the_same_at_every_thread_count() {
    same_layout_on_one_thread_and_many::<f32, 2>();
    same_layout_on_one_thread_and_many::<f64, 3>();
}

/// Particles on a line (a flat bounding box) along `axis`, spaced 0.9σ.
fn line<T: Real, const D: usize>(n: usize, axis: usize) -> State<T, D> {
    let mut s = State::new(n);
    for i in 0..n {
        for d in 0..D {
            s.pos[d][i] = T::of(if d == axis {
                0.9 * SIGMA * i as f64
            } else {
                0.5
            });
        }
    }
    s
}

fn degenerate<T: Real, const D: usize>() {
    let law = lj::<T>(2.5 * SIGMA);
    let mut kernel = CellList::new(law).expect("LJ has a cutoff");
    for axis in 0..D {
        // A long line: one bin across, many along; then 3 particles, all in a single bin.
        agrees_with(&mut kernel, &line::<T, D>(200, axis), law);
        agrees_with(&mut kernel, &line::<T, D>(3, axis), law);
    }
    // So many rows that padding them is not worth it: runs are not lengthened.
    agrees_with(&mut kernel, &line::<T, D>(2000, D - 1), law);
    if D > 1 {
        assert_eq!(kernel.strips.pad, 0);
    }
}

#[test]
fn degenerate_boxes() {
    degenerate::<f32, 2>();
    degenerate::<f64, 2>();
    degenerate::<f32, 3>();
    degenerate::<f64, 3>();
}

#[test]
fn one_dimension() {
    let law = lj::<f64>(2.5 * SIGMA);
    let mut kernel = CellList::<_, f64, 1>::new(law).expect("LJ has a cutoff");
    for n in [1, 2, 50] {
        let state = spaced_state::<f64, 1>(n, 3.0 * n as f64 * SIGMA, 0.8 * SIGMA, SEED_1);
        agrees_with(&mut kernel, &state, law);
    }
}

#[test]
fn buffers_follow_size_and_box_changes() {
    let law = lj::<f64>(2.5 * SIGMA);
    let mut kernel = CellList::<_, f64, 2>::new(law).expect("LJ has a cutoff");
    let small = spaced_state::<f64, 2>(50, 0.1, 0.8 * SIGMA, SEED_1);
    let big = spaced_state::<f64, 2>(800, 0.5, 0.8 * SIGMA, SEED_2);
    let mut far = small.clone();
    far.pos[0][0] = 40.0; // an escaped particle: the box grows 400-fold
    for state in [&small, &big, &far, &small] {
        agrees_with(&mut kernel, state, law);
    }
}

#[test]
fn spatial_order_sorts_by_bin_and_keeps_forces() {
    let law = lj::<f64>(2.5 * SIGMA);
    let mut kernel = CellList::<_, f64, 2>::new(law).expect("LJ has a cutoff");
    let mut state = spaced_state::<f64, 2>(1000, 0.5, 0.8 * SIGMA, SEED_1);
    let mut before = zero_field::<f64, 2>(1000);
    kernel.compute(&state, &mut before, false);

    let order = kernel.spatial_order(&state).expect("the cell list sorts");
    let mut seen = vec![false; order.len()];
    for &k in &order {
        assert!(!std::mem::replace(&mut seen[k as usize], true), "{k} twice");
    }
    assert!(seen.iter().all(|&s| s), "not a permutation");
    state.permute(&order, &mut []);
    // Bin indices are non-decreasing in the new order, so the sort is now the identity.
    let g = kernel.strips.grid;
    let bins: Vec<usize> = (0..1000)
        .map(|i| g.bin(&g.cell(state.position(i))))
        .collect();
    assert!(bins.windows(2).all(|w| w[0] <= w[1]), "not in bin order");

    let mut after = zero_field::<f64, 2>(1000);
    kernel.compute(&state, &mut after, false);
    for (new, &old) in order.iter().enumerate() {
        for d in 0..2 {
            let (a, b) = (after[d][new], before[d][old as usize]);
            assert!((a - b).abs() <= 1e-12 * b.abs().max(1.0), "{a} vs {b}");
        }
    }
    agrees_with(&mut kernel, &state, law);
}

#[test]
fn counts_work() {
    // A 7 × 7 grid over [0, 0.2]² (bins of side 0.2/7 > rc): A and B interact across the
    // boundary of bins (0, 0) and (1, 0); C and D sit alone in two corners.
    let law = lj::<f64>(2.5 * SIGMA);
    let mut kernel = CellList::<_, f64, 2>::new(law).expect("LJ has a cutoff");
    let mut state = State::<f64, 2>::new(4);
    state.pos[0] = vec![0.02, 0.03, 0.0, 0.2];
    state.pos[1] = vec![0.0, 0.0, 0.2, 0.2];
    let mut f = zero_field::<f64, 2>(4);
    let report = kernel.compute(&state, &mut f, true);
    assert_eq!(kernel.strips.grid.dims, [7, 7]);
    assert_eq!(report.work.pair_checks, 2);
    assert_eq!(report.work.pairs_interacting, 1);
    // Stencils of 2×2 (A), 3×2 (B), 2×2 (C) and 2×2 (D) bins.
    assert_eq!(report.work.cells_visited, 4 + 6 + 4 + 4);
    assert!(report.build_s >= 0.0);
    // A is pushed away from B (repulsion at 1σ), C and D feel nothing.
    assert!(f[0][0] < 0.0 && f[0][1] == -f[0][0], "{f:?}");
    assert!(f[0][2] == 0.0 && f[1][3] == 0.0, "{f:?}");
}

#[test]
fn refuses_laws_without_cutoff() {
    let made = CellList::<_, f64, 3>::new(Coulomb::<f64>::new(1e-3));
    assert!(matches!(made, Err(KernelError::BadParam(_))));
}

#[test]
fn unspaced_random_state_is_finite() {
    // Uniform placement (the timing fixture): forces can be huge but must match naive.
    let law = lj::<f64>(2.5 * SIGMA);
    let mut kernel = CellList::<_, f64, 2>::new(law).expect("LJ has a cutoff");
    let state = random_state::<f64, 2>(500, 1.0, false, SEED_2);
    agrees_with(&mut kernel, &state, law);
}

/// The fork decision weighs the particles, not only the pairs: a dilute gas of 1e5 particles
/// with ~2.7 candidates each forks, a few hundred particles do not.
#[test]
fn the_step_work_counts_particles_and_pairs() {
    use crate::kernels::MIN_PARALLEL_PAIRS;
    let candidates = |n: u64| n * 27 / 10;
    let gas = |n: u64| step_work(n as usize, candidates(n));
    assert!(gas(100_000) >= MIN_PARALLEL_PAIRS);
    assert!(
        candidates(100_000) < MIN_PARALLEL_PAIRS,
        "the pairs alone would not fork"
    );
    assert!(gas(500) < MIN_PARALLEL_PAIRS);
    assert_eq!(step_work(10, 7), 10 * ROW_COST + 7);
    assert_eq!(step_work(usize::MAX, u64::MAX), u64::MAX);
}
