//! The cluster-pair list against the naive kernel (the oracle): random and degenerate states,
//! serial and split over threads, a run of moving particles that crosses rebuilds and
//! re-orderings, the rebuild rule at exactly half the skin and a pair at exactly the cutoff.

use super::*;
use crate::kernels::Naive;
use crate::physics::LennardJones;
use crate::state::zero_field;
use crate::testing::short_range::{SIGMA, agrees_with_naive, lj, spaced_states};
use crate::testing::{SEED_1, SEED_2, max_rel_diff, on_threads, spaced_state};

const SKIN: f64 = 0.3 * SIGMA;

/// The comparison with the naive kernel, with the list's own check: its runs counted.
fn agrees_with<T: Real, const D: usize>(
    kernel: &mut ClusterPair<LennardJones<T>, T, D>,
    state: &State<T, D>,
    law: LennardJones<T>,
) {
    agrees_with_naive(kernel, state, law, |kernel, run| {
        assert_eq!(run.report.work.list_entries, kernel.runs());
    });
}

/// Random spaced states (no two particles closer than 0.8σ), dense and dilute.
fn random_states<T: Real, const D: usize>() {
    let law = lj::<T>(2.5 * SIGMA);
    let mut kernel = ClusterPair::new(law, SKIN).expect("LJ has a cutoff");
    let density = if D == 2 { 8000.0 } else { 6e5 };
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
    let mut kernel = ClusterPair::<_, f64, 1>::new(law, SKIN).expect("LJ has a cutoff");
    for n in [1, 2, 50] {
        let state = spaced_state::<f64, 1>(n, 3.0 * n as f64 * SIGMA, 0.8 * SIGMA, SEED_1);
        agrees_with(&mut kernel, &state, law);
    }
    // Particles 0.9σ apart on a line along the last axis: one column, every cluster in it.
    let mut kernel = ClusterPair::<_, f64, 3>::new(law, SKIN).expect("LJ has a cutoff");
    let mut s = State::<f64, 3>::new(300);
    for i in 0..300 {
        s.pos[0][i] = 0.5;
        s.pos[1][i] = 0.5;
        s.pos[2][i] = 0.9 * SIGMA * i as f64;
    }
    agrees_with(&mut kernel, &s, law);
    // The same line along the first axis: a column per cluster or so.
    s.pos.swap(0, 2);
    agrees_with(&mut kernel, &s, law);
}

/// A list long enough to be cut into parts: the same parts, runs and force bits on one
/// thread and on two.
#[test]
fn split_over_threads() {
    let law = lj::<f32>(2.5 * SIGMA);
    let n = 20_000;
    let side = (n as f64 / 8000.0).sqrt();
    let state = spaced_state::<f32, 2>(n, side, 0.8 * SIGMA, SEED_2);
    let mut serial = ClusterPair::<_, f32, 2>::new(law, SKIN).unwrap();
    let mut f = zero_field::<f32, 2>(n);
    serial.compute(&state, &mut f, false);
    let mut split = ClusterPair::<_, f32, 2>::new(law, SKIN).unwrap();
    let mut g = zero_field::<f32, 2>(n);
    on_threads(2, || {
        split.compute(&state, &mut g, false);
        split.built = false;
        split.compute(&state, &mut g, false)
    });
    assert!(split.parts.len() > 1);
    assert!(split.colors.disjoint());
    assert_eq!(split.parts.len(), serial.parts.len());
    assert_eq!(split.runs(), serial.runs());
    assert!(f == g, "the same bits on one thread and on two");
    agrees_with(&mut split, &state, law);
}

/// A run of particles moving at random, re-ordered whenever the kernel asks as the engine
/// does, compared with the oracle at every step: rebuilds, kept lists and re-orderings.
#[test]
fn a_moving_run_agrees_at_every_step() {
    let law = lj::<f64>(2.5 * SIGMA);
    let n = 2000;
    let side = (n as f64 / 8000.0).sqrt();
    let mut state = spaced_state::<f64, 2>(n, side, 0.8 * SIGMA, SEED_1);
    let mut kernel = ClusterPair::<_, f64, 2>::new(law, SKIN).unwrap();
    let mut rebuilds = 0;
    let mut rng = 0x9e37_79b9_7f4a_7c15u64;
    for step in 0..40 {
        if let Some(order) = kernel.spatial_order(&state) {
            state.permute(&order, &mut []);
        }
        let mut got = zero_field::<f64, 2>(n);
        let p = 1 + step % 2;
        let report = on_threads(p, || kernel.compute(&state, &mut got, false));
        rebuilds += report.work.rebuilds;
        let mut want = zero_field::<f64, 2>(n);
        Naive::new(law).compute(&state, &mut want, false);
        let err = max_rel_diff(&got, &want);
        assert!(err <= 1e-10, "step {step}: off by {err:e}");
        for d in 0..2 {
            for x in state.pos[d].iter_mut() {
                rng ^= rng << 13;
                rng ^= rng >> 7;
                rng ^= rng << 17;
                *x += 0.2 * SKIN * ((rng >> 11) as f64 / (1u64 << 53) as f64 - 0.5);
            }
        }
    }
    assert!((2..40).contains(&rebuilds), "{rebuilds} rebuilds");
}

/// Two particles that each move exactly half the skin toward each other, from the cutoff plus
/// the skin to exactly the cutoff, and two more that end exactly at the cutoff: no rebuild,
/// and the forces are the oracle's.
#[test]
fn exactly_half_the_skin_and_exactly_the_cutoff() {
    // Dyadic numbers throughout, so that every position and displacement is exact.
    let law = LennardJones::<f64>::new(1.0, 0.5, 1.0);
    let skin = 0.25;
    let mut kernel = ClusterPair::<_, f64, 2>::new(law, skin).expect("LJ has a cutoff");
    let mut s = State::<f64, 2>::new(4);
    let gap = 1.0 + skin - 1.0 / 1024.0;
    s.pos = [vec![4.0, 4.0 + gap, 8.0, 8.0], vec![4.0, 4.0, 4.0, 5.25]];
    let mut f = zero_field::<f64, 2>(4);
    assert_eq!(kernel.compute(&s, &mut f, false).work.rebuilds, 1);
    s.pos[0][0] += skin / 2.0;
    s.pos[0][1] -= skin / 2.0;
    s.pos[1][2] += skin / 2.0;
    s.pos[1][3] -= skin / 2.0;
    assert_eq!(
        s.pos[1][3] - s.pos[1][2],
        1.0,
        "C and D exactly at the cutoff"
    );
    let report = kernel.compute(&s, &mut f, true);
    assert_eq!(report.work.rebuilds, 0, "half the skin keeps the list");
    let mut want = zero_field::<f64, 2>(4);
    let oracle = Naive::new(law).compute(&s, &mut want, true);
    assert_eq!(report.work.pairs_interacting, oracle.work.pairs_interacting);
    assert!(want[0][0] != 0.0);
    for d in 0..2 {
        for i in 0..4 {
            assert!((f[d][i] - want[d][i]).abs() <= 1e-12 * want[d][i].abs());
        }
    }
    assert_eq!(kernel.spatial_order(&s), None);
    s.pos[0][0] += 1.0 / (1u64 << 30) as f64;
    assert_eq!(kernel.compute(&s, &mut f, false).work.rebuilds, 1);
}

/// Slots refilled by other particles or a changed count rebuild when needed and give the
/// oracle's forces either way.
#[test]
fn slots_not_particles_decide() {
    let law = lj::<f32>(2.5 * SIGMA);
    let mut kernel = ClusterPair::<_, f32, 2>::new(law, SKIN).expect("LJ has a cutoff");
    let a = spaced_state::<f32, 2>(400, 0.2, 0.8 * SIGMA, SEED_1);
    agrees_with(&mut kernel, &a, law);
    let mut swapped = a.clone();
    swapped.permute(&(0..400u32).rev().collect::<Vec<_>>(), &mut []);
    agrees_with(&mut kernel, &swapped, law);
    let b = spaced_state::<f32, 2>(401, 0.2, 0.8 * SIGMA, SEED_2);
    agrees_with(&mut kernel, &b, law);
}

/// The order handed out is a permutation, the permuted state is adopted without a new sort,
/// and the clusters then follow the state's slots.
#[test]
fn the_order_handed_out_is_adopted() {
    let law = lj::<f64>(2.5 * SIGMA);
    let mut kernel = ClusterPair::<_, f64, 2>::new(law, SKIN).unwrap();
    let mut state = spaced_state::<f64, 2>(1000, 0.35, 0.8 * SIGMA, SEED_2);
    let order = kernel.spatial_order(&state).expect("no list yet");
    let mut seen = vec![false; order.len()];
    for &k in &order {
        assert!(!std::mem::replace(&mut seen[k as usize], true), "{k} twice");
    }
    state.permute(&order, &mut []);
    assert!(kernel.layout.adopt(&state));
    let real: Vec<u32> = (0..kernel.layout.filled() * CLUSTER)
        .filter(|&p| (p % CLUSTER) < kernel.layout.count[p / CLUSTER] as usize)
        .map(|p| kernel.layout.slot_of[p])
        .collect();
    assert_eq!(
        real,
        (0..1000).collect::<Vec<u32>>(),
        "slots in cluster order"
    );
    kernel.handed_out = false;
    kernel.built = false;
    agrees_with(&mut kernel, &state, law);
}

#[test]
fn refuses_laws_without_cutoff_and_bad_skins() {
    let coulomb = crate::physics::Coulomb::<f64>::new(0.0);
    assert!(ClusterPair::<_, f64, 3>::new(coulomb, SKIN).is_err());
    for skin in [0.0, -1.0, f64::NAN] {
        assert!(ClusterPair::<_, f64, 2>::new(lj::<f64>(2.5 * SIGMA), skin).is_err());
    }
}
