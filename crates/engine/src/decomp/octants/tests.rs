//! Octant domains: the source's octants for p = 8^k, one owner per point (also on cell faces),
//! balanced runs for other rank counts, empty ranks.

use super::*;
use crate::testing::{SEED_1, SEED_2, random_state};

/// Whether `x` is in the half-open box, the cube's top walls counting as inside.
fn inside<const D: usize>(b: &Aabb<D>, x: &[f64; D], top: &[f64; D]) -> bool {
    (0..D).all(|a| b.0[a] <= x[a] && (x[a] < b.1[a] || (b.1[a] == top[a] && x[a] == top[a])))
}

/// Every point of `points` lies in the boxes of exactly one rank, the one `owner` names.
fn check_one_owner<const D: usize>(o: &Octants<D>, points: &[[f64; D]]) {
    let (lo, side) = o.cube();
    let top = lo.map(|l| l + side);
    let boxes: Vec<Vec<Aabb<D>>> = (0..o.ranks()).map(|r| o.boxes(r)).collect();
    for x in points {
        let holders: Vec<usize> = (0..o.ranks())
            .filter(|&r| boxes[r].iter().any(|b| inside(b, x, &top)))
            .collect();
        assert_eq!(
            holders,
            vec![o.owner(*x)],
            "point {x:?}, level {}",
            o.level()
        );
    }
}

/// Random points and the corners of every cell (faces and top walls included).
fn probe_points<const D: usize>(o: &Octants<D>, seed: u64) -> Vec<[f64; D]> {
    let (lo, side) = o.cube();
    let s = random_state::<f64, D>(500, 1.0, false, seed);
    let mut pts: Vec<[f64; D]> = (0..s.len())
        .map(|i| std::array::from_fn(|d| lo[d] + side * s.pos[d][i]))
        .collect();
    let per_axis = 1u64 << o.level().min(3);
    let lattice = (per_axis + 1).pow(D as u32);
    for k in 0..lattice {
        let mut rest = k;
        pts.push(std::array::from_fn(|d| {
            let j = rest % (per_axis + 1);
            rest /= per_axis + 1;
            lo[d] + side * j as f64 / per_axis as f64
        }));
    }
    pts
}

#[test]
fn eight_ranks_get_the_eight_octants_and_four_the_quadrants() {
    let s3 = random_state::<f64, 3>(1000, 1.0, false, SEED_1);
    let o = Octants::new([0.0; 3], 1.0, 8, &s3.pos).expect("octants");
    assert_eq!(o.level(), 1);
    for r in 0..8 {
        // Morton order: bit 0 of the rank is x, bit 1 is y, bit 2 is z.
        let lo: [f64; 3] = std::array::from_fn(|d| ((r >> d) & 1) as f64 * 0.5);
        let hi = lo.map(|l| l + 0.5);
        assert_eq!(o.boxes(r), vec![(lo, hi)], "rank {r}");
    }
    assert_eq!(
        o.owner([1.0, 1.0, 1.0]),
        7,
        "the top walls belong to the last octant"
    );
    assert_eq!(
        o.owner([0.5, 0.0, 0.0]),
        1,
        "a face belongs to the cell above it"
    );
    let s2 = random_state::<f64, 2>(1000, 1.0, false, SEED_1);
    let q = Octants::new([0.0; 2], 1.0, 4, &s2.pos).expect("quadrants");
    assert_eq!(q.boxes(2), vec![([0.0, 0.5], [0.5, 1.0])]);
    // 64 ranks: the level-2 cells, one each, whatever the data.
    let o = Octants::new([0.0; 3], 1.0, 64, &s3.pos).expect("level 2");
    assert_eq!(o.level(), 2);
    assert!((0..64).all(|r| o.cells(r) == (r as u64..r as u64 + 1)));
}

#[test]
fn one_rank_owns_the_whole_cube() {
    let s = random_state::<f64, 3>(100, 2.0, false, SEED_1);
    let (lo, side) = root_cube(&s.pos);
    let o = Octants::new(lo, side, 1, &s.pos).expect("one rank");
    assert_eq!(o.boxes(0), vec![(lo, lo.map(|l| l + side))]);
    assert_eq!(o.counts(&s.pos), vec![100]);
}

#[test]
fn every_point_has_exactly_one_owner() {
    for p in [1, 2, 3, 5, 7, 8, 9, 64, 100] {
        let s = random_state::<f64, 3>(2000, 3.0, false, SEED_1);
        let (lo, side) = root_cube(&s.pos);
        let o = Octants::new(lo, side, p, &s.pos).expect("3-D");
        check_one_owner(&o, &probe_points(&o, SEED_2));
    }
    for p in [2, 3, 4, 6, 16, 17] {
        let s = random_state::<f64, 2>(2000, 3.0, false, SEED_1);
        let (lo, side) = root_cube(&s.pos);
        let o = Octants::new(lo, side, p, &s.pos).expect("2-D");
        check_one_owner(&o, &probe_points(&o, SEED_2));
    }
}

#[test]
fn counts_balance_on_uniform_data() {
    let n = 20_000;
    let s3 = random_state::<f64, 3>(n, 1.0, false, SEED_1);
    let s2 = random_state::<f64, 2>(n, 1.0, false, SEED_1);
    for p in [2, 3, 5, 6, 7, 12] {
        let (lo, side) = root_cube(&s3.pos);
        let c3 = Octants::new(lo, side, p, &s3.pos)
            .expect("3-D")
            .counts(&s3.pos);
        let (lo, side) = root_cube(&s2.pos);
        let c2 = Octants::new(lo, side, p, &s2.pos)
            .expect("2-D")
            .counts(&s2.pos);
        for c in [c3, c2] {
            assert_eq!(c.iter().sum::<usize>(), n);
            let max = *c.iter().max().expect("ranks") as f64;
            assert!(max / (n as f64 / p as f64) < 1.05, "p = {p}: {c:?}");
        }
    }
}

#[test]
fn ranks_without_bodies_or_cells_are_allowed() {
    // All bodies at one point: one rank holds them all, the others none.
    let mut s = random_state::<f64, 3>(300, 1.0, false, SEED_1);
    for d in 0..3 {
        s.pos[d].iter_mut().for_each(|x| *x = 0.25);
    }
    let (lo, side) = root_cube(&s.pos);
    let o = Octants::new(lo, side, 5, &s.pos).expect("coincident");
    let c = o.counts(&s.pos);
    assert_eq!(c.iter().sum::<usize>(), 300);
    assert_eq!(c.iter().filter(|&&k| k > 0).count(), 1, "{c:?}");
    check_one_owner(&o, &probe_points(&o, SEED_2));
    // No bodies: equal runs of cells.
    let empty: [Vec<f64>; 3] = std::array::from_fn(|_| Vec::new());
    let o = Octants::new([0.0; 3], 1.0, 3, &empty).expect("no bodies");
    let lens: Vec<u64> = (0..3).map(|r| o.cells(r).end - o.cells(r).start).collect();
    assert!(lens.iter().all(|&l| l == 170 || l == 171), "{lens:?}");
    // More ranks than the finest level has cells (8^7 = MAX_CELLS): three ranks own no space.
    let p = MAX_CELLS as usize + 3;
    let o = Octants::new([0.0; 3], 1.0, p, &empty).expect("many ranks");
    assert_eq!((o.level(), o.cells(p - 1).end), (7, MAX_CELLS));
    let without = (0..p).filter(|&r| o.boxes(r).is_empty()).count();
    assert_eq!(without, 3);
    assert!(o.owner([1.0; 3]) < p);
}

#[test]
fn bad_inputs_are_errors() {
    let empty: [Vec<f64>; 2] = std::array::from_fn(|_| Vec::new());
    assert_eq!(
        Octants::new([0.0; 2], 1.0, 0, &empty),
        Err(DomainError::NoRanks)
    );
    assert!(matches!(
        Octants::new([0.0; 2], f64::NAN, 2, &empty),
        Err(DomainError::BadBox { .. })
    ));
    assert_eq!(root_cube(&empty), ([0.0; 2], 1.0));
}

#[test]
fn cell_coordinates_invert_the_tree_keys() {
    let empty: [Vec<f64>; 3] = std::array::from_fn(|_| Vec::new());
    let o = Octants::balanced([0.0; 3], 1.0, 2, 4, &empty).expect("level 4");
    for key in 0..cells_at(4, 3) {
        assert_eq!(interleave::<3>(o.cell_of(key)), key);
    }
}
