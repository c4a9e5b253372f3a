//! The Verlet list against the naive kernel (the oracle): random and degenerate states, serial
//! and split over threads, the half list and the targets' full lists, the rebuild rule at
//! exactly half the skin, the re-ordering handshake and the work estimate.

use super::*;
use crate::kernels::{MIN_PARALLEL_PAIRS, Naive};
use crate::physics::{Coulomb, LennardJones};
use crate::state::zero_field;
use crate::testing::short_range::{SIGMA, agrees_with_naive, force_tol, lj, spaced_states};
use crate::testing::{SEED_1, SEED_2, max_rel_diff, on_threads, random_state, spaced_state};

const SKIN: f64 = 0.3 * SIGMA;

/// The comparison with the naive kernel, with the list's own checks: its entries counted, and
/// after the probe run the forces on the targets of two blocks (`compute_targets`).
fn agrees_with<T: Real, const D: usize>(
    kernel: &mut Verlet<LennardJones<T>, T, D>,
    state: &State<T, D>,
    law: LennardJones<T>,
) {
    let n = state.len();
    agrees_with_naive(kernel, state, law, |kernel, run| {
        assert_eq!(run.report.work.list_entries, kernel.entries());
        if !run.probe {
            return;
        }
        let half = n / 2;
        for block in [0..half, half..n] {
            let mut part = zero_field::<T, D>(block.len());
            let out = part.each_mut().map(|f| f.as_mut_slice());
            on_threads(run.p, || kernel.compute_targets(state, block.clone(), out));
            let want: Field<T, D> = std::array::from_fn(|d| run.want[d][block.clone()].to_vec());
            let err = max_rel_diff(&part, &want);
            assert!(
                err <= force_tol::<T>(),
                "{} D={D} n={n} p={} targets {block:?}: off by {err:e}",
                T::NAME,
                run.p
            );
        }
    });
}

/// Random spaced states (no two particles closer than 0.8σ) at a few sizes and densities.
fn random_states<T: Real, const D: usize>() {
    let law = lj::<T>(2.5 * SIGMA);
    let mut kernel = Verlet::new(law, SKIN).expect("LJ has a cutoff");
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

#[test]
fn one_dimension_and_lines() {
    let law = lj::<f64>(2.5 * SIGMA);
    let mut kernel = Verlet::<_, f64, 1>::new(law, SKIN).expect("LJ has a cutoff");
    for n in [1, 2, 50] {
        let state = spaced_state::<f64, 1>(n, 3.0 * n as f64 * SIGMA, 0.8 * SIGMA, SEED_1);
        agrees_with(&mut kernel, &state, law);
    }
    // Particles 0.9σ apart on a line: one bin across, many along.
    let mut kernel = Verlet::<_, f64, 3>::new(law, SKIN).expect("LJ has a cutoff");
    let mut s = State::<f64, 3>::new(300);
    for i in 0..300 {
        s.pos = [s.pos[0].clone(), s.pos[1].clone(), s.pos[2].clone()];
        s.pos[1][i] = 0.9 * SIGMA * i as f64;
        s.pos[0][i] = 0.5;
        s.pos[2][i] = 0.5;
    }
    agrees_with(&mut kernel, &s, law);
}

/// A list long enough to be cut into parts, whose rows span several SIMD blocks: the same
/// parts and the same force bits on one thread and on two.
#[test]
fn split_over_threads() {
    let law = lj::<f64>(8.0 * SIGMA);
    let mut kernel = Verlet::<_, f64, 2>::new(law, 2.0 * SIGMA).expect("LJ has a cutoff");
    let n = 3000;
    let side = (n as f64 / 4000.0).sqrt();
    let state = spaced_state::<f64, 2>(n, side, 0.8 * SIGMA, SEED_2);
    let mut f = zero_field::<f64, 2>(n);
    kernel.compute(&state, &mut f, false);
    assert!(step_work(n, kernel.entries()) >= MIN_PARALLEL_PAIRS);
    let parts = kernel.parts.len();
    assert_eq!(parts, parts_for(n, step_work(n, kernel.entries())));
    assert!(parts > 1);
    let mut g = zero_field::<f64, 2>(n);
    on_threads(2, || kernel.compute(&state, &mut g, false));
    assert!(f == g, "the same bits on one thread and on two");
    // Rebuilt on the 2-thread pool: the same parts.
    on_threads(2, || kernel.build(&state));
    assert_eq!(kernel.parts.len(), parts);
    agrees_with(&mut kernel, &state, law);
    // The split list holds the same pairs as the list in one part.
    on_threads(2, || kernel.build(&state));
    let serial_entries = {
        let mut k = Verlet::<_, f64, 2>::new(law, 2.0 * SIGMA).unwrap();
        k.build(&state);
        k.entries()
    };
    assert_eq!(kernel.entries(), serial_entries);
}

/// Two particles that each move exactly half the skin toward each other, from just beyond
/// the cutoff plus the skin to just inside the cutoff: no rebuild, and the pair interacts.
#[test]
fn exactly_half_the_skin_keeps_the_list_and_the_forces() {
    // Dyadic numbers throughout, so that every position and displacement is exact.
    let law = LennardJones::<f64>::new(1.0, 0.5, 1.0);
    let skin = 0.25;
    let mut kernel = Verlet::<_, f64, 2>::new(law, skin).expect("LJ has a cutoff");
    let mut s = State::<f64, 2>::new(4);
    let gap = 1.0 + skin - 1.0 / 1024.0;
    // A and B a gap apart along x; C and D exactly the cutoff plus the skin apart along y.
    s.pos = [vec![4.0, 4.0 + gap, 8.0, 8.0], vec![4.0, 4.0, 4.0, 5.25]];
    let mut f = zero_field::<f64, 2>(4);
    let first = kernel.compute(&s, &mut f, false);
    assert_eq!(first.work.rebuilds, 1);
    assert_eq!(f[0][0], 0.0, "A and B start beyond the cutoff");
    // Every particle moves exactly half the skin toward its partner.
    s.pos[0][0] += skin / 2.0;
    s.pos[0][1] -= skin / 2.0;
    s.pos[1][2] += skin / 2.0;
    s.pos[1][3] -= skin / 2.0;
    assert_eq!(s.pos[0][1] - s.pos[0][0], 1.0 - 1.0 / 1024.0);
    let report = kernel.compute(&s, &mut f, true);
    assert_eq!(
        report.work.rebuilds, 0,
        "exactly half the skin keeps the list"
    );
    assert_eq!(report.work.pairs_interacting, 1, "A and B now interact");
    let mut want = zero_field::<f64, 2>(4);
    Naive::new(law).compute(&s, &mut want, false);
    assert!(want[0][0] != 0.0);
    for d in 0..2 {
        for i in 0..4 {
            assert!(
                (f[d][i] - want[d][i]).abs() <= 1e-12 * want[d][i].abs(),
                "{f:?} vs {want:?}"
            );
        }
    }
    assert_eq!(
        kernel.spatial_order(&s),
        None,
        "no re-ordering between rebuilds"
    );
    // A hair more, and the list is rebuilt.
    s.pos[0][0] += 1.0 / (1u64 << 30) as f64;
    let report = kernel.compute(&s, &mut f, false);
    assert_eq!(report.work.rebuilds, 1);
    let report = kernel.compute(&s, &mut f, false);
    assert_eq!(report.work.rebuilds, 0);
}

fn view(f: &Field<f64, 2>) -> [&[f64]; 2] {
    [&f[0][..], &f[1][..]]
}

#[test]
fn the_displacement_test_is_strict_and_fails_safe() {
    let then: Field<f64, 2> = [vec![0.0; 5000], vec![1.0; 5000]];
    let mut now = then.clone();
    now[0][4321] = 0.5;
    assert!(!work::moved_beyond(view(&now), view(&then), 0.25));
    now[1][4321] = 1.0 + 1e-6;
    assert!(work::moved_beyond(view(&now), view(&then), 0.25));
    let mut nan = then.clone();
    nan[1][17] = f64::NAN;
    assert!(work::moved_beyond(view(&nan), view(&then), 0.25));
    assert!(!work::moved_beyond(view(&then), view(&then), 0.0));
}

/// The engine's handshake: an order exactly when a rebuild is due, then a rebuild on the
/// permuted state that reuses the sort; forces follow the particles.
#[test]
fn spatial_order_at_rebuilds_only() {
    let law = lj::<f64>(2.5 * SIGMA);
    let mut kernel = Verlet::<_, f64, 2>::new(law, SKIN).expect("LJ has a cutoff");
    let mut state = spaced_state::<f64, 2>(1000, 0.5, 0.8 * SIGMA, SEED_1);
    let order = kernel.spatial_order(&state).expect("no list yet: sort");
    let mut seen = vec![false; order.len()];
    for &k in &order {
        assert!(!std::mem::replace(&mut seen[k as usize], true), "{k} twice");
    }
    state.permute(&order, &mut []);
    assert!(
        kernel.bins.adopt(&state),
        "the permuted state is the sorted one"
    );
    let g = kernel.bins.grid;
    let bins: Vec<usize> = (0..1000)
        .map(|i| g.bin(&g.cell(state.position(i))))
        .collect();
    assert!(bins.windows(2).all(|w| w[0] <= w[1]), "not in bin order");
    let mut f = zero_field::<f64, 2>(1000);
    assert_eq!(kernel.compute(&state, &mut f, false).work.rebuilds, 1);
    assert_eq!(kernel.spatial_order(&state), None);
    agrees_with(&mut kernel, &state, law);
    // Far enough moved: an order again, and a rebuild after it even if it is not applied.
    state.pos[0][10] += SKIN;
    assert!(kernel.spatial_order(&state).is_some());
    assert_eq!(kernel.compute(&state, &mut f, false).work.rebuilds, 1);
    agrees_with(&mut kernel, &state, law);
}

/// Slots refilled by other particles (as an MPI driver does) or a changed count rebuild when
/// needed and give the oracle's forces either way.
#[test]
fn slots_not_particles_decide() {
    let law = lj::<f32>(2.5 * SIGMA);
    let mut kernel = Verlet::<_, f32, 2>::new(law, SKIN).expect("LJ has a cutoff");
    let a = spaced_state::<f32, 2>(400, 0.3, 0.8 * SIGMA, SEED_1);
    agrees_with(&mut kernel, &a, law);
    let mut swapped = a.clone();
    swapped.permute(&(0..400u32).rev().collect::<Vec<_>>(), &mut []);
    agrees_with(&mut kernel, &swapped, law);
    let b = spaced_state::<f32, 2>(401, 0.3, 0.8 * SIGMA, SEED_2);
    agrees_with(&mut kernel, &b, law);
    let mut far = b.clone();
    far.pos[0][0] = 40.0;
    agrees_with(&mut kernel, &far, law);
}

#[test]
fn counts_work() {
    // A and B interact; C sits alone: one list entry, one rebuild, then none.
    let law = lj::<f64>(2.5 * SIGMA);
    let mut kernel = Verlet::<_, f64, 2>::new(law, SKIN).expect("LJ has a cutoff");
    let mut state = State::<f64, 2>::new(3);
    state.pos = [vec![0.02, 0.03, 0.2], vec![0.0, 0.0, 0.2]];
    let mut f = zero_field::<f64, 2>(3);
    let first = kernel.compute(&state, &mut f, true);
    assert_eq!((first.work.rebuilds, first.work.list_entries), (1, 1));
    assert_eq!(first.work.pairs_interacting, 1);
    assert!(first.work.pair_checks > 1 && first.work.cells_visited > 0);
    let next = kernel.compute(&state, &mut f, false);
    assert_eq!(next.work.rebuilds, 0);
    assert_eq!((next.work.pair_checks, next.work.cells_visited), (1, 0));
    assert!(
        f[0][0] < 0.0 && f[0][1] == -f[0][0] && f[0][2] == 0.0,
        "{f:?}"
    );
}

#[test]
fn refuses_laws_without_cutoff_and_bad_skins() {
    let made = Verlet::<_, f64, 3>::new(Coulomb::<f64>::new(1e-3), SKIN);
    assert!(matches!(made, Err(KernelError::BadParam(_))));
    for skin in [0.0, -1.0, f64::NAN, f64::INFINITY] {
        assert!(
            Verlet::<_, f64, 2>::new(lj::<f64>(0.025), skin).is_err(),
            "{skin}"
        );
    }
}

#[test]
fn unspaced_random_state_is_finite() {
    let law = lj::<f64>(2.5 * SIGMA);
    let mut kernel = Verlet::<_, f64, 2>::new(law, SKIN).expect("LJ has a cutoff");
    let state = random_state::<f64, 2>(500, 1.0, false, SEED_2);
    agrees_with(&mut kernel, &state, law);
}

/// The parallel decisions, on the work estimate alone.
#[test]
fn work_estimate_decides_the_split() {
    assert_eq!(step_work(0, 0), 0);
    assert_eq!(
        step_work(1000, 500),
        1000 * work::ROW_COST + 500 * work::ENTRY_COST
    );
    assert_eq!(step_work(usize::MAX, u64::MAX), u64::MAX, "saturates");
    // A list splits exactly from the fork/join threshold on, into parts of at least
    // MIN_PART_ROWS rows, at most PARTS of them.
    for work in [0, MIN_PARALLEL_PAIRS - 1] {
        assert_eq!(parts_for(100_000, work), 1);
    }
    assert_eq!(parts_for(100_000, MIN_PARALLEL_PAIRS), work::PARTS);
    assert_eq!(parts_for(4 * work::MIN_PART_ROWS, u64::MAX), 4);
    assert_eq!(parts_for(work::MIN_PART_ROWS - 1, u64::MAX), 1);
    // The scenarios at default skin: the gas (0.6 entries per particle) splits from about
    // 6000 particles, the liquid (10) from about 1300.
    let gas = |n: usize| step_work(n, 6 * n as u64 / 10);
    let liquid = |n: usize| step_work(n, 10 * n as u64);
    assert_eq!(parts_for(2000, gas(2000)), 1);
    assert!(parts_for(20_000, gas(20_000)) > 1);
    assert_eq!(parts_for(1000, liquid(1000)), 1);
    assert!(parts_for(2000, liquid(2000)) > 1);
    assert!(gas(10_000) < liquid(10_000));
}

#[test]
fn the_estimate_before_a_first_build_bounds_the_list() {
    let law = lj::<f64>(2.5 * SIGMA);
    let state = spaced_state::<f64, 2>(2000, 0.7, 0.8 * SIGMA, SEED_1);
    let mut kernel = Verlet::<_, f64, 2>::new(law, SKIN).expect("LJ has a cutoff");
    kernel.build(&state);
    let bound = work::expected_entries(&kernel.bins, &Cover::Half);
    assert!(bound >= kernel.entries(), "{bound} < {}", kernel.entries());
    let targets = work::expected_entries(&kernel.bins, &Cover::Targets(0..2000));
    assert!(targets >= 2 * kernel.entries());
}

/// The sort of a rebuild forks when the particles are many; its order must not depend on the
/// thread count.
#[test]
fn the_order_is_the_same_at_any_thread_count() {
    let law = lj::<f32>(2.5 * SIGMA);
    let state = spaced_state::<f32, 2>(30_000, 2.5, 0.8 * SIGMA, SEED_2);
    let order = |p| {
        on_threads(p, || {
            let mut kernel = Verlet::<_, f32, 2>::new(law, SKIN).expect("LJ has a cutoff");
            kernel.spatial_order(&state).expect("no list yet: sort")
        })
    };
    let one = order(1);
    assert_eq!(order(2), one);
    assert_eq!(order(3), one);
}
