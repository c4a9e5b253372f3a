use super::*;

const INF: f64 = f64::INFINITY;

#[test]
fn no_points_give_the_empty_box() {
    let none: [&[f64]; 3] = [&[], &[], &[]];
    let b = Bounds::of_columns(none);
    assert_eq!(b, Bounds::empty());
    assert_eq!(b.lo, [INF; 3]);
    assert_eq!(b.hi, [-INF; 3]);
    assert!(b.is_empty());
    assert_eq!(Bounds::<f32, 2>::of_points([]), Bounds::empty());
    assert_eq!(b.longest_side(), 0.0);
    assert_eq!(b.cube().1, 1.0);
}

#[test]
fn nan_coordinates_are_skipped() {
    let x = [1.0, f64::NAN, -2.0];
    let y = [f64::NAN, 5.0, 3.0];
    let b = Bounds::of_columns([&x[..], &y[..]]);
    assert_eq!(
        b,
        Bounds {
            lo: [-2.0, 3.0],
            hi: [1.0, 5.0]
        }
    );
    let points = [[1.0, f64::NAN], [f64::NAN, 5.0], [-2.0, 3.0]];
    assert_eq!(Bounds::of_points(points), b);
    // An axis with only NaN is empty, like no points at all.
    let b = Bounds::<f32, 2>::of_points([[f32::NAN, 1.0]]);
    assert!(b.is_empty());
    assert_eq!((b.lo[0], b.hi[0]), (f32::INFINITY, f32::NEG_INFINITY));
}

#[test]
fn nan_is_skipped_in_every_lane_of_a_long_column() {
    // Longer than the scan's lanes, with NaN in the remainder and in the full chunks.
    let mut x: Vec<f32> = (0..53).map(|i| i as f32 - 20.0).collect();
    x[0] = f32::NAN;
    x[17] = f32::NAN;
    x[52] = f32::NAN;
    let b = Bounds::of_columns([&x[..]]);
    assert_eq!(
        b,
        Bounds {
            lo: [-19.0],
            hi: [31.0]
        }
    );
    assert_eq!(b, Bounds::of_points(x.iter().map(|&v| [v])));
}

#[test]
fn one_point_is_a_degenerate_box() {
    let b = Bounds::of_points([[1.5, -2.0, 7.0]]);
    assert_eq!(b.lo, b.hi);
    assert!(!b.is_empty());
    assert_eq!(b.center(), [1.5, -2.0, 7.0]);
    assert_eq!(b.longest_side(), 0.0);
    // A single position still gets a cube of positive side.
    assert_eq!(b.cube(), ([1.5, -2.0, 7.0], 1.0));
}

#[test]
fn boxes_in_two_and_three_dimensions() {
    let b2 = Bounds::of_points([[0.0f32, 1.0], [2.0, -1.0], [1.0, 0.5]]);
    assert_eq!(
        b2,
        Bounds {
            lo: [0.0, -1.0],
            hi: [2.0, 1.0]
        }
    );
    assert_eq!(b2.center(), [1.0, 0.0]);
    assert_eq!(b2.longest_side(), 2.0);
    let b3 = Bounds::of_points([[0.0, 0.0, 0.0], [1.0, 4.0, -2.0]]);
    assert_eq!(b3.longest_side(), 4.0);
    assert_eq!(b3.cube(), ([0.0, 0.0, -2.0], 4.0));
    assert_eq!(b3.to_f64(), b3);
    assert_eq!(b2.to_f64().lo, [0.0, -1.0]);
}

#[test]
fn extend_and_union_agree_with_the_box_of_all_points() {
    let points = [[3.0, -1.0], [0.5, 2.0], [-4.0, 0.0], [1.0, 9.0]];
    let (a, b) = points.split_at(2);
    let joined = Bounds::of_points(a.iter().copied()).union(Bounds::of_points(b.iter().copied()));
    assert_eq!(joined, Bounds::of_points(points));
    // The empty box is the identity of the union.
    assert_eq!(joined.union(Bounds::empty()), joined);
    assert_eq!(Bounds::empty().union(joined), joined);
    let mut grown = Bounds::empty();
    for p in points {
        grown.extend(p);
    }
    assert_eq!(grown, joined);
}

#[test]
fn infinite_coordinates_are_kept() {
    let b = Bounds::of_points([[0.0, 1.0], [INF, 2.0]]);
    assert_eq!(b.hi[0], INF);
    assert_eq!(b.longest_side(), INF);
    assert_eq!(b.cube().1, INF);
}

#[test]
fn morton_keys_of_known_cells() {
    assert_eq!(morton_bits(3), 21);
    assert_eq!(morton_bits(2), 31);
    assert_eq!(morton_bits(1), 31);
    assert_eq!(morton_bits(0), 0);
    // 2-D: x in the even bits, y in the odd ones.
    assert_eq!(interleave([0, 0]), 0);
    assert_eq!(interleave([1, 0]), 0b01);
    assert_eq!(interleave([0, 1]), 0b10);
    assert_eq!(interleave([3, 0]), 0b0101);
    assert_eq!(interleave([2, 3]), 0b1110);
    // 3-D: x, y, z in bits 0, 1, 2 of each digit.
    assert_eq!(interleave([1, 0, 0]), 0b001);
    assert_eq!(interleave([0, 1, 0]), 0b010);
    assert_eq!(interleave([0, 0, 1]), 0b100);
    assert_eq!(interleave([1, 1, 1]), 0b111);
    assert_eq!(interleave([2, 0, 1]), 0b001_100);
    // The top digit of a full key is the root's child: the far corner is child 7.
    let top = (1 << 21) - 1;
    assert_eq!(interleave([top, top, top]) >> 60, 0b111);
    assert_eq!(interleave([1 << 20, 0, 0]) >> 60, 0b001);
    // Sorting the keys visits the four quadrants of a 2x2 grid in Z order.
    let mut cells = [[1u64, 1], [0, 1], [1, 0], [0, 0]];
    cells.sort_by_key(|&c| interleave(c));
    assert_eq!(cells, [[0, 0], [1, 0], [0, 1], [1, 1]]);
}

#[test]
fn generic_dimensions_interleave_like_the_fast_paths() {
    // One dimension: the key is the coordinate (all bits its own).
    assert_eq!(interleave([0b1011]), 0b1011);
    // Four dimensions: digit by digit.
    assert_eq!(interleave([1, 0, 0, 1]), 0b1001);
    assert_eq!(interleave([2, 0, 0, 0]), 0b1_0000);
}

#[test]
fn deinterleave_inverts_interleave() {
    for cell in [[0, 0, 0], [5, 3, 7], [1023, 0, 511]] {
        assert_eq!(deinterleave::<3>(interleave(cell), 10), cell);
    }
    for cell in [[0, 0], [6, 9], [(1 << 31) - 1, 12345]] {
        assert_eq!(deinterleave::<2>(interleave(cell), 31), cell);
    }
}
