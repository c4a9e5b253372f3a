use super::*;
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64Mcg;

fn random_points<const D: usize>(n: usize, side: f64, seed: u64) -> Vec<[f64; D]> {
    let mut rng = Pcg64Mcg::seed_from_u64(seed);
    (0..n)
        .map(|_| std::array::from_fn(|_| rng.random::<f64>() * side))
        .collect()
}

/// The owner of a point is the region that contains it, found by brute force.
fn brute_owner<const D: usize>(r: &Regions<D>, x: [f64; D]) -> usize {
    let (_, hi_box) = r.bounds();
    let inside = |rank: usize| {
        let (lo, hi) = r.region(rank);
        (0..D).all(|a| x[a] >= lo[a] && (x[a] < hi[a] || (hi[a] == hi_box[a] && x[a] <= hi[a])))
    };
    let owners: Vec<usize> = (0..r.ranks()).filter(|&k| inside(k)).collect();
    assert_eq!(owners.len(), 1, "{x:?} is in regions {owners:?}");
    owners[0]
}

#[test]
fn regions_tile_the_box_and_owner_finds_the_containing_region() {
    let mut r = Regions::<2>::uniform([0.0; 2], [2.0, 1.0], [3, 2]).unwrap();
    let pts = random_points::<2>(2000, 1.0, crate::testing::SEED_1);
    let pts: Vec<[f64; 2]> = pts.iter().map(|p| [2.0 * p[0], p[1]]).collect();
    for &x in &pts {
        assert_eq!(r.owner(x), brute_owner(&r, x));
    }
    // Walls belong to the regions at the edges.
    assert_eq!(r.owner([0.0, 0.0]), 0);
    assert_eq!(r.owner([2.0, 1.0]), 5);
    // After rebalancing on a skewed cloud, still a tiling.
    let skewed: Vec<[f64; 2]> = pts
        .iter()
        .map(|p| [p[0] * p[0] / 2.0, p[1].powi(3)])
        .collect();
    for axis in 0..2 {
        let h = r.histogram(axis, 512, skewed.iter().copied());
        r.cut_axis(axis, &h);
    }
    for &x in &skewed {
        assert_eq!(r.owner(x), brute_owner(&r, x));
    }
    let area: f64 = (0..r.ranks())
        .map(|k| {
            let (lo, hi) = r.region(k);
            (hi[0] - lo[0]) * (hi[1] - lo[1])
        })
        .sum();
    assert!((area - 2.0).abs() < 1e-12, "{area}");
}

#[test]
fn rebalancing_equalizes_counts_in_2d_and_3d() {
    let pts = random_points::<2>(20_000, 1.0, crate::testing::SEED_2);
    // Dense in the lower left corner.
    let pts: Vec<[f64; 2]> = pts.iter().map(|p| [p[0].powi(2), p[1].powi(3)]).collect();
    for dims in [[4, 1], [2, 2], [3, 2]] {
        let mut r = Regions::<2>::uniform([0.0; 2], [1.0; 2], dims).unwrap();
        let before = counts(&r, &pts);
        for axis in 0..2 {
            let h = r.histogram(axis, 1024, pts.iter().copied());
            r.cut_axis(axis, &h);
        }
        let after = counts(&r, &pts);
        assert!(imbalance(&before) > 1.5, "{dims:?}: {before:?}");
        assert!(imbalance(&after) < 1.03, "{dims:?}: {after:?}");
    }
    let pts3 = random_points::<3>(20_000, 1.0, crate::testing::SEED_1);
    let pts3: Vec<[f64; 3]> = pts3
        .iter()
        .map(|p| [p[0], p[1].powi(2), p[2].powi(4)])
        .collect();
    let mut r = Regions::<3>::uniform([0.0; 3], [1.0; 3], [2, 2, 2]).unwrap();
    for axis in 0..3 {
        let h = r.histogram(axis, 1024, pts3.iter().copied());
        r.cut_axis(axis, &h);
    }
    assert!(imbalance(&counts(&r, &pts3)) < 1.03);
}

fn counts<const D: usize>(r: &Regions<D>, pts: &[[f64; D]]) -> Vec<usize> {
    let mut c = vec![0; r.ranks()];
    for &x in pts {
        c[r.owner(x)] += 1;
    }
    c
}

fn imbalance(c: &[usize]) -> f64 {
    let mean = c.iter().sum::<usize>() as f64 / c.len() as f64;
    *c.iter().max().unwrap() as f64 / mean
}

#[test]
fn neighbours_are_the_regions_within_reach_and_symmetric() {
    let r = Regions::<2>::uniform([0.0; 2], [1.0; 2], [4, 1]).unwrap();
    assert_eq!(r.neighbours(0, 0.1), vec![1]);
    assert_eq!(r.neighbours(1, 0.1), vec![0, 2]);
    // Slabs thinner than the reach: ghosts come from two regions away.
    assert_eq!(r.neighbours(0, 0.3), vec![1, 2]);
    let mut r = Regions::<2>::uniform([0.0; 2], [1.0; 2], [3, 3]).unwrap();
    let pts = random_points::<2>(3000, 1.0, 9);
    let pts: Vec<[f64; 2]> = pts.iter().map(|p| [p[0].sqrt(), p[1] * p[0]]).collect();
    for axis in 0..2 {
        let h = r.histogram(axis, 256, pts.iter().copied());
        r.cut_axis(axis, &h);
    }
    // The centre region touches all eight others on a uniform grid; staggered, at least its
    // four faces.
    let centre = 4;
    assert!(r.neighbours(centre, 1e-9).len() >= 4);
    for a in 0..9 {
        for b in r.neighbours(a, 0.05) {
            assert!(
                r.neighbours(b, 0.05).contains(&a),
                "{a} -> {b} not symmetric"
            );
        }
    }
}

#[test]
fn empty_regions_own_nothing() {
    let mut r = Regions::<2>::uniform([0.0; 2], [1.0; 2], [4, 1]).unwrap();
    // All particles at one point: three regions must be empty.
    let pts = vec![[0.25, 0.5]; 100];
    let h = r.histogram(0, 64, pts.iter().copied());
    r.cut_axis(0, &h);
    let c = counts(&r, &pts);
    assert_eq!(c.iter().sum::<usize>(), 100);
    for &x in &random_points::<2>(500, 1.0, 3) {
        assert_eq!(r.owner(x), brute_owner(&r, x));
    }
}

#[test]
fn grid_dims_minimize_cut_area() {
    assert_eq!(grid_dims::<2>(1, [1.0, 1.0]), [1, 1]);
    assert_eq!(grid_dims::<2>(2, [1.0, 1.0]), [2, 1]);
    assert_eq!(grid_dims::<2>(3, [1.0, 1.0]), [3, 1]);
    assert_eq!(grid_dims::<2>(4, [1.0, 1.0]), [2, 2]);
    assert_eq!(grid_dims::<2>(6, [1.0, 1.0]), [3, 2]);
    assert_eq!(grid_dims::<2>(4, [1.0, 4.0]), [1, 4]);
    assert_eq!(grid_dims::<3>(8, [1.0; 3]), [2, 2, 2]);
    assert_eq!(grid_dims::<3>(12, [1.0; 3]), [3, 2, 2]);
}

#[test]
fn grids_parse_with_clear_errors() {
    assert_eq!(parse_grid::<2>("4x1", 4), Ok([4, 1]));
    assert_eq!(parse_grid::<3>("2x1x2", 4), Ok([2, 1, 2]));
    assert!(matches!(
        parse_grid::<2>("3x1", 4),
        Err(RegionsError::GridMismatch { got: 3, .. })
    ));
    assert!(matches!(
        parse_grid::<2>("4", 4),
        Err(RegionsError::BadGrid(_))
    ));
    assert!(matches!(
        parse_grid::<2>("0x4", 0),
        Err(RegionsError::BadGrid(_))
    ));
    assert!(
        Regions::<2>::uniform([0.0; 2], [f64::INFINITY, 1.0], [1, 1]).is_err(),
        "an open box has no regions"
    );
}
