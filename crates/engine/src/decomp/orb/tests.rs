//! ORB: weights balanced to within one body's weight on uniform and concentrated clouds, for
//! any rank count; regions that tile the root box; degenerate inputs.

use super::*;
use crate::state::State;
use crate::testing::{SEED_1, SEED_2, plummer_state, random_state};
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64Mcg;

/// Interaction-count-like weights: integers 1..=40.
fn random_weights(n: usize, seed: u64) -> Vec<f64> {
    let mut rng = Pcg64Mcg::seed_from_u64(seed);
    (0..n).map(|_| rng.random_range(1..=40) as f64).collect()
}

/// Every rank's weight is within one body's (largest) weight of the mean.
fn check_balance<const D: usize>(s: &State<f64, D>, weights: &[f64], p: usize, what: &str) {
    let orb = Orb::over(p, &s.pos, weights).expect("orb");
    let per_rank = orb.weights_per_rank(&s.pos, weights);
    let total: f64 = weights.iter().sum();
    assert!((per_rank.iter().sum::<f64>() - total).abs() < 1e-9 * total);
    let mean = total / p as f64;
    let heaviest = weights.iter().copied().fold(0.0, f64::max);
    for (r, w) in per_rank.iter().enumerate() {
        assert!(
            (w - mean).abs() <= heaviest * (1.0 + 1e-9),
            "{what}, p = {p}: rank {r} has {w}, mean {mean}, body weight ≤ {heaviest}"
        );
    }
    check_tiling(&orb, &s.pos, what);
}

/// The regions lie in the root box, their volumes add up to it, and each probe point (the
/// bodies and the regions' corners) lies in exactly the region of its owner.
fn check_tiling<const D: usize>(orb: &Orb<D>, pos: &[Vec<f64>; D], what: &str) {
    let (lo, hi) = root_box(pos);
    let volume = |b: &Aabb<D>| (0..D).map(|a| b.1[a] - b.0[a]).product::<f64>();
    let sum: f64 = (0..orb.ranks()).map(|r| volume(&orb.region(r))).sum();
    let root = volume(&(lo, hi));
    assert!(
        (sum - root).abs() <= 1e-12 * root.max(1.0),
        "{what}: {sum} vs {root}"
    );
    let inside = |b: &Aabb<D>, x: &[f64; D]| {
        (0..D).all(|a| b.0[a] <= x[a] && (x[a] < b.1[a] || (b.1[a] == hi[a] && x[a] == hi[a])))
    };
    let n = pos[0].len();
    let mut points: Vec<[f64; D]> = (0..n).map(|i| std::array::from_fn(|d| pos[d][i])).collect();
    for r in 0..orb.ranks() {
        let (l, h) = orb.region(r);
        points.push(l);
        points.push(std::array::from_fn(|d| 0.5 * (l[d] + h[d])));
    }
    for x in &points {
        let holders: Vec<usize> = (0..orb.ranks())
            .filter(|&r| inside(&orb.region(r), x))
            .collect();
        assert_eq!(holders, vec![orb.owner(*x)], "{what}: point {x:?}");
    }
}

#[test]
fn splits_balance_the_weights_on_uniform_and_concentrated_clouds() {
    let n = 4000;
    let ones = vec![1.0; n];
    let counts = random_weights(n, SEED_2);
    let uniform3 = random_state::<f64, 3>(n, 1.0, false, SEED_1);
    let plummer3 = plummer_state::<f64, 3>(n, SEED_1);
    let uniform2 = random_state::<f64, 2>(n, 1.0, false, SEED_1);
    let plummer2 = plummer_state::<f64, 2>(n, SEED_2);
    for p in [1, 2, 3, 5, 7, 8, 13] {
        for (w, which) in [(&ones, "ones"), (&counts, "counts")] {
            check_balance(&uniform3, w, p, &format!("uniform 3-D, {which}"));
            check_balance(&plummer3, w, p, &format!("Plummer 3-D, {which}"));
            check_balance(&uniform2, w, p, &format!("uniform 2-D, {which}"));
            check_balance(&plummer2, w, p, &format!("Plummer 2-D, {which}"));
        }
    }
}

#[test]
fn one_rank_owns_the_root_box() {
    let s = plummer_state::<f64, 3>(500, SEED_1);
    let orb = Orb::over(1, &s.pos, &vec![1.0; 500]).expect("orb");
    assert_eq!(orb.region(0), root_box(&s.pos));
    assert_eq!(orb.counts(&s.pos), vec![500]);
    assert_eq!(orb.owner([1e9; 3]), 0);
}

#[test]
fn zero_bodies_give_equal_geometric_regions() {
    let empty: [Vec<f64>; 3] = std::array::from_fn(|_| Vec::new());
    for p in [1, 2, 3, 5, 8] {
        let orb = Orb::new([0.0; 3], [2.0, 1.0, 1.0], p, &empty, &[]).expect("orb");
        for r in 0..p {
            let (l, h) = orb.region(r);
            let v: f64 = (0..3).map(|a| h[a] - l[a]).product();
            assert!((v - 2.0 / p as f64).abs() < 1e-12, "p = {p}, rank {r}: {v}");
        }
        assert_eq!(Orb::over(p, &empty, &[]).expect("unit box").ranks(), p);
    }
}

#[test]
fn coincident_bodies_go_to_one_rank() {
    let mut s = random_state::<f64, 2>(100, 1.0, false, SEED_1);
    for d in 0..2 {
        s.pos[d].iter_mut().for_each(|x| *x = 0.5);
    }
    let orb = Orb::over(4, &s.pos, &vec![1.0; 100]).expect("orb");
    let c = orb.counts(&s.pos);
    assert_eq!(c[orb.owner([0.5, 0.5])], 100, "{c:?}");
    // Half the bodies at another point: two ranks share them.
    for i in 0..50 {
        s.pos[0][i] = 0.75;
    }
    let orb = Orb::over(2, &s.pos, &vec![1.0; 100]).expect("orb");
    assert_eq!(orb.counts(&s.pos), vec![50, 50]);
    check_tiling(&orb, &s.pos, "two clusters");
}

#[test]
fn ranks_may_own_no_bodies() {
    let s = random_state::<f64, 3>(3, 1.0, false, SEED_1);
    let orb = Orb::over(8, &s.pos, &[1.0; 3]).expect("orb");
    let c = orb.counts(&s.pos);
    assert_eq!(c.iter().sum::<usize>(), 3);
    assert!(c.iter().filter(|&&k| k == 0).count() >= 5, "{c:?}");
    check_tiling(&orb, &s.pos, "3 bodies, 8 ranks");
    // Weightless bodies: cut geometrically.
    let orb = Orb::over(3, &s.pos, &[0.0; 3]).expect("weightless");
    check_tiling(&orb, &s.pos, "weightless");
}

#[test]
fn bad_inputs_are_errors() {
    let s = random_state::<f64, 2>(3, 1.0, false, SEED_1);
    assert_eq!(Orb::over(0, &s.pos, &[1.0; 3]), Err(DomainError::NoRanks));
    assert_eq!(
        Orb::over(2, &s.pos, &[1.0; 2]),
        Err(DomainError::WeightCount {
            weights: 2,
            bodies: 3
        })
    );
    assert!(matches!(
        Orb::over(2, &s.pos, &[1.0, -1.0, 1.0]),
        Err(DomainError::BadWeight { body: 1, .. })
    ));
    assert!(matches!(
        Orb::over(2, &s.pos, &[1.0, 1.0, f64::NAN]),
        Err(DomainError::BadWeight { body: 2, .. })
    ));
    assert!(matches!(
        Orb::new([0.0, 0.0], [1.0, f64::INFINITY], 2, &s.pos, &[1.0; 3]),
        Err(DomainError::BadBox { .. })
    ));
}

#[test]
fn a_sampled_body_weighs_what_the_bodies_it_stands_for_cost() {
    let costs = [5, 0, 7, 2, 9, 1, 4];
    // Every third body: 0 stands for 0..3, 3 for 3..6, 6 for itself; a zero counts as 1.
    assert_eq!(sample_weights(7, 3, Some(&costs), 0.0), [13.0, 12.0, 4.0]);
    assert_eq!(sample_weights(7, 3, None, 2.5), [7.5, 7.5, 2.5]);
    assert_eq!(
        sample_weights(3, 1, Some(&costs[..3]), 0.0),
        [5.0, 1.0, 7.0]
    );
    assert!(sample_weights(0, 4, None, 1.0).is_empty());
    // Either way the sample carries the rank's whole cost.
    let sum = |w: Vec<f64>| w.iter().sum::<f64>();
    assert_eq!(sum(sample_weights(7, 2, Some(&costs), 0.0)), 29.0);
    assert_eq!(sum(sample_weights(7, 4, None, 3.0)), 21.0);
}

#[test]
fn per_body_costs_balance_the_cost_where_even_weights_do_not() {
    // A Plummer cloud whose central bodies cost more (as in a tree code): cut on even
    // weights, the rank holding the centre does more than its share; cut on the costs, every
    // rank is within one body's cost of the mean.
    let s: State<f64, 3> = plummer_state(4000, SEED_1);
    let cost: Vec<f64> = (0..s.len())
        .map(|i| {
            let r2: f64 = (0..3).map(|d| s.pos[d][i] * s.pos[d][i]).sum();
            1.0 + 100.0 / (1.0 + 10.0 * r2)
        })
        .collect();
    let imbalance = |weights: &[f64]| {
        let orb = Orb::over(3, &s.pos, weights).expect("orb");
        let per_rank = orb.weights_per_rank(&s.pos, &cost);
        let mean = per_rank.iter().sum::<f64>() / 3.0;
        per_rank.iter().copied().fold(0.0, f64::max) / mean
    };
    let even = imbalance(&vec![1.0; s.len()]);
    let weighed = imbalance(&cost);
    assert!(even > 1.05, "even weights: {even}");
    assert!(weighed < 1.01, "costs: {weighed}");
}
