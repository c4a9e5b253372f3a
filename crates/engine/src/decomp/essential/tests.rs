//! The export set against per-target walks of the sender's tree: it partitions the sender's
//! bodies, every exported node passes the opening test at every point of the receiver's
//! domain, so it refines the interaction list of every target there; forces from it match
//! the direct sum at θ = 0 and are at least as accurate as the per-target walk at θ = 0.5.

use super::*;
use crate::decomp::Domains;
use crate::decomp::model::bodies_of;
use crate::decomp::octants::{Octants, root_cube};
use crate::decomp::orb::Orb;
use crate::kernels::{Multipole, Octree};
use crate::physics::{Gravity, pair_force};
use crate::state::State;
use crate::testing::{SEED_1, SEED_2, plummer_state, random_state};
use std::ops::Range;

const LEAF: usize = 8;

fn tree_of<const D: usize>(
    s: &State<f64, D>,
    theta: f64,
    multipole: Multipole,
) -> Octree<Gravity<f64>, f64, D> {
    let mut k = Octree::with_multipole(Gravity::new(1.0, 1e-3), theta, LEAF, multipole);
    k.build(s);
    k
}

/// Random points in each box of the domain, and the boxes' corners.
fn targets<const D: usize>(domain: &[Aabb<D>], seed: u64) -> Vec<[f64; D]> {
    let u = random_state::<f64, D>(200, 1.0, false, seed);
    let mut out = Vec::new();
    for (lo, hi) in domain {
        for i in 0..u.len() {
            out.push(std::array::from_fn(|d| {
                lo[d] + (hi[d] - lo[d]) * u.pos[d][i]
            }));
        }
        out.push(*lo);
        out.push(*hi);
    }
    out
}

/// A plain per-target walk of the sender's tree with the kernel's test: the accepted nodes
/// and the opened leaves.
fn point_walk<const D: usize>(tree: &TreeView<'_, f64, D>, t: &[f64; D]) -> (Vec<u32>, Vec<u32>) {
    let (mut accepted, mut opened) = (Vec::new(), Vec::new());
    let mut stack: Vec<u32> = tree.roots().to_vec();
    while let Some(node) = stack.pop() {
        if tree.far_from_box(node, t, t) {
            accepted.push(node);
        } else if tree.is_leaf(node) {
            opened.push(node);
        } else {
            stack.extend(tree.children(node));
        }
    }
    (accepted, opened)
}

/// The body ranges of `nodes`, sorted.
fn ranges<const D: usize>(tree: &TreeView<'_, f64, D>, nodes: &[u32]) -> Vec<Range<usize>> {
    let mut r: Vec<Range<usize>> = nodes.iter().map(|&n| tree.bodies(n)).collect();
    r.sort_by_key(|r| r.start);
    r
}

/// Force at `t` from the given nodes (as monopoles) and leaves (their bodies).
fn force<const D: usize>(
    tree: &TreeView<'_, f64, D>,
    t: &[f64; D],
    nodes: &[u32],
    leaves: &[u32],
) -> [f64; D] {
    let law = Gravity::new(1.0, 1e-3);
    let mut f = [0.0; D];
    let mut add = |x: [f64; D], s: f64| {
        let dx: [f64; D] = std::array::from_fn(|d| x[d] - t[d]);
        let g = pair_force(&law, dx, 1.0, s);
        (0..D).for_each(|d| f[d] += g[d]);
    };
    for &n in nodes {
        add(tree.centre(n), tree.strength(n));
    }
    for slot in leaves.iter().flat_map(|&l| tree.bodies(l)) {
        add(tree.position(slot), tree.source(slot));
    }
    f
}

/// Checks the export set of `tree` for `domain` against the walks of its targets; returns the
/// median relative force errors (export set, per-target walk) against the direct sum.
fn check_export<const D: usize>(
    tree: &TreeView<'_, f64, D>,
    domain: &[Aabb<D>],
    what: &str,
) -> (f64, f64) {
    let set = select(tree, domain);
    // The entries partition the sender's bodies.
    let mut entries = ranges(tree, &set.nodes);
    entries.extend(ranges(tree, &set.leaves));
    entries.sort_by_key(|r| r.start);
    let mut next = 0;
    for r in &entries {
        assert_eq!(r.start, next, "{what}: entries overlap or leave a gap");
        next = r.end;
    }
    assert_eq!(next, tree.body_count(), "{what}: bodies missing");
    assert_eq!(
        set.bodies,
        ranges(tree, &set.leaves)
            .iter()
            .map(|r| r.len())
            .sum::<usize>()
    );
    let all_leaves: Vec<u32> = (0..tree.node_count() as u32)
        .filter(|&n| tree.is_leaf(n))
        .collect();
    let (mut err_set, mut err_walk) = (Vec::new(), Vec::new());
    for t in targets(domain, SEED_2) {
        // Every exported node passes at the target, so the walk never opens it ...
        for &n in &set.nodes {
            assert!(
                tree.far_from_box(n, &t, &t),
                "{what}: node {n} fails at {t:?}"
            );
        }
        // ... and each entry lies inside one node the walk accepts or one leaf it opens.
        let (accepted, opened) = point_walk(tree, &t);
        let mut walk = ranges(tree, &accepted);
        walk.extend(ranges(tree, &opened));
        walk.sort_by_key(|r| r.start);
        for e in &entries {
            let k = walk.partition_point(|w| w.start <= e.start) - 1;
            assert!(
                e.end <= walk[k].end,
                "{what}: entry {e:?} straddles {:?}",
                walk[k]
            );
        }
        let exact = force(tree, &t, &[], &all_leaves);
        let norm = exact.iter().map(|x| x * x).sum::<f64>().sqrt();
        let err = |f: [f64; D]| {
            (0..D)
                .map(|d| (f[d] - exact[d]).powi(2))
                .sum::<f64>()
                .sqrt()
                / norm
        };
        err_set.push(err(force(tree, &t, &set.nodes, &set.leaves)));
        err_walk.push(err(force(tree, &t, &accepted, &opened)));
    }
    let median = |mut v: Vec<f64>| {
        v.sort_by(f64::total_cmp);
        v[v.len() / 2]
    };
    (median(err_set), median(err_walk))
}

#[test]
fn export_sets_refine_every_target_walk_orb() {
    for (cloud, what) in [
        (random_state::<f64, 3>(6000, 1.0, false, SEED_1), "uniform"),
        (plummer_state::<f64, 3>(6000, SEED_1), "Plummer"),
    ] {
        let orb = Orb::over(4, &cloud.pos, &vec![1.0; cloud.len()]).expect("orb");
        let owners = orb.assign(&cloud.pos);
        let sender = bodies_of(&cloud, &owners, 0);
        let k = tree_of(&sender, 0.5, Multipole::Monopole);
        for receiver in 1..4 {
            let (e_set, e_walk) = check_export(&k.view(), &orb.boxes(receiver), what);
            assert!(
                e_set <= e_walk * 1.05 + 1e-15,
                "{what}: {e_set:e} vs walk {e_walk:e}"
            );
            assert!(e_set < 1e-3, "{what}: median error {e_set:e}");
        }
    }
}

#[test]
fn export_sets_refine_every_target_walk_octants() {
    // Three ranks: each domain is a run of Morton cells, several boxes.
    let cloud = random_state::<f64, 2>(4000, 1.0, false, SEED_2);
    let (lo, side) = root_cube(&cloud.pos);
    let oct = Octants::new(lo, side, 3, &cloud.pos).expect("octants");
    let owners = oct.assign(&cloud.pos);
    let sender = bodies_of(&cloud, &owners, 1);
    let k = tree_of(&sender, 0.5, Multipole::Monopole);
    for receiver in [0, 2] {
        assert!(oct.boxes(receiver).len() > 1);
        let (e_set, e_walk) = check_export(&k.view(), &oct.boxes(receiver), "octants");
        assert!(
            e_set <= e_walk * 1.05 + 1e-15,
            "{e_set:e} vs walk {e_walk:e}"
        );
    }
}

#[test]
fn theta_zero_exports_every_body() {
    let cloud = random_state::<f64, 3>(2000, 1.0, false, SEED_1);
    let orb = Orb::over(2, &cloud.pos, &vec![1.0; 2000]).expect("orb");
    let sender = bodies_of(&cloud, &orb.assign(&cloud.pos), 0);
    let k = tree_of(&sender, 0.0, Multipole::Monopole);
    let set = select(&k.view(), &orb.boxes(1));
    assert!(set.nodes.is_empty());
    assert_eq!(set.bodies, sender.len());
    let (e_set, _) = check_export(&k.view(), &orb.boxes(1), "θ = 0");
    assert!(e_set < 1e-12, "{e_set:e}");
}

#[test]
fn entries_and_bytes_count_the_payload() {
    let cloud = plummer_state::<f64, 3>(5000, SEED_2);
    let orb = Orb::over(3, &cloud.pos, &vec![1.0; 5000]).expect("orb");
    let sender = bodies_of(&cloud, &orb.assign(&cloud.pos), 2);
    let mono = tree_of(&sender, 0.6, Multipole::Monopole);
    let quad = tree_of(&sender, 0.6, Multipole::Quadrupole);
    let a = select(&mono.view(), &orb.boxes(0));
    let b = select(&quad.view(), &orb.boxes(0));
    // The same nodes pass at either order; quadrupoles add 6 + 1 values per node in 3-D.
    assert_eq!((&a.nodes, &a.leaves), (&b.nodes, &b.leaves));
    assert!(!a.nodes.is_empty() && a.bodies > 0 && a.entries() < sender.len());
    assert_eq!(a.bytes(3, 8), (a.nodes.len() * 4 + a.bodies * 4) * 8);
    assert_eq!(b.bytes(3, 8), (b.nodes.len() * 11 + b.bodies * 4) * 8);
    let p = b.payload(&quad.view());
    assert_eq!((p.nodes, p.strength.len()), (b.nodes.len(), b.entries()));
    assert_eq!(p.moments.len(), b.nodes.len() * 7);
    assert!(p.pos.iter().all(|c| c.len() == b.entries()));
    // Strength is conserved: the entries hold the sender's whole mass.
    let total: f64 = p.strength.iter().sum();
    assert!((total - sender.source.iter().sum::<f64>()).abs() < 1e-12);
    // A receiver without a domain gets the root as one pseudo-particle.
    let none = select(&mono.view(), &[]);
    assert_eq!((none.nodes.len(), none.bodies), (1, 0));
    // An empty sender exports nothing.
    let empty = tree_of(&State::<f64, 3>::new(0), 0.5, Multipole::Monopole);
    assert_eq!(select(&empty.view(), &orb.boxes(0)).entries(), 0);
}

#[test]
fn faces_on_the_root_walls_open_to_infinity_and_the_export_still_holds_beyond_them() {
    let cloud = plummer_state::<f64, 3>(3000, SEED_1);
    let orb = Orb::over(2, &cloud.pos, &vec![1.0; 3000]).expect("orb");
    let root = crate::decomp::orb::root_box(&cloud.pos);
    let open = open_at_walls(&orb.boxes(1), &root);
    assert_eq!(open.len(), 1);
    let (lo, hi) = open[0];
    // Two ranks: one cut; every other face lies on a wall.
    let inner = (0..3)
        .filter(|&d| lo[d].is_finite() || hi[d].is_finite())
        .count();
    assert_eq!(inner, 1, "{open:?}");
    // A point far outside the root box on rank 1's side: owned by rank 1, and every exported
    // node passes the test there.
    let sender = bodies_of(&cloud, &orb.assign(&cloud.pos), 0);
    let k = tree_of(&sender, 0.5, Multipole::Monopole);
    let view = k.view();
    let set = select(&view, &open);
    // Rank 1 is the upper side of the cut: beyond the top wall of that axis and below the
    // bottom walls of the others.
    let axis = (0..3).find(|&d| lo[d].is_finite()).expect("the cut");
    let extent = (0..3).map(|d| root.1[d] - root.0[d]).fold(0.0, f64::max);
    let far: [f64; 3] = std::array::from_fn(|d| {
        if d == axis {
            root.1[d] + 100.0 * extent
        } else {
            root.0[d] - 100.0 * extent
        }
    });
    assert_eq!(orb.owner(far), 1);
    for &node in &set.nodes {
        assert!(
            view.far_from_box(node, &far, &far),
            "node {node} fails at {far:?}"
        );
    }
    // The finite box is the easier test: its export is a coarsening, never larger.
    assert!(select(&view, &orb.boxes(1)).entries() <= set.entries());
}
