//! The top nodes of a rank's tree, as the gravity source's distributed Barnes-Hut shares them
//! (`--decomp octants`): every rank sends every other rank the first levels of its octree, each
//! node as its centre of strength, strength and opening radius. A rank then walks another
//! rank's top nodes for each group of its bodies (the octree's target groups) with the
//! octree's opening test against the group's bounding box: if every branch ends in an accepted
//! node, the group's bodies get that rank's force from those monopoles; if a branch ends in a
//! node that must be opened (the top levels stop there, or it is a leaf), the group is sent to
//! the owner, whose whole tree, walked for the group's box in the same way
//! ([`group_forces`]), gives the group that rank's force instead. Testing whole groups as the
//! kernel does keeps the error that of the serial tree at the same θ; a test per body would
//! accept nodes the serial walk opens.
//!
//! The nodes are flattened breadth first: node k's children are the `children` entries from
//! `first`, so a walk needs no pointers and the list travels as plain values.

use crate::geometry::Bounds;
use crate::kernels::{TreeView, far_from_box};
use crate::physics::{PairLaw, pair_force};
use crate::real::Real;

/// Values per top node on the wire: D coordinates, strength, opening radius², first child,
/// child count.
pub(crate) const fn node_values(dim: usize) -> usize {
    dim + 4
}

/// One rank's top nodes.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct TopNodes<T, const D: usize> {
    nodes: Vec<TopNode<T, D>>,
    /// Nodes without a parent (one per sign class the rank holds).
    roots: usize,
}

#[derive(Clone, Copy, Debug, PartialEq)]
struct TopNode<T, const D: usize> {
    centre: [T; D],
    strength: T,
    /// `(side/θ)²`: the node is accepted for a point farther than this (squared) from its centre.
    open2: T,
    first: u32,
    /// 0 when the node must be opened to go deeper: a leaf, or the last shared level.
    children: u32,
}

/// What a walk of another rank's top nodes gives one group of bodies.
#[derive(Clone, Debug, PartialEq)]
pub enum TopWalk {
    /// Every branch ended in an accepted node: the nodes (indices into the list).
    Accepted(Vec<u32>),
    /// A node had to be opened below the shared levels: the owner must compute the group.
    Open,
}

impl<T: Real, const D: usize> TopNodes<T, D> {
    /// The nodes of `tree` down to `levels` levels below its roots (levels = 0: the roots).
    pub fn of(tree: &TreeView<'_, T, D>, levels: u32) -> Self {
        let mut out = TopNodes {
            nodes: Vec::new(),
            roots: tree.roots().len(),
        };
        // Breadth first: (tree node, depth) in list order; children appended as a family.
        let mut queue: Vec<(u32, u32)> = tree.roots().iter().map(|&r| (r, 0)).collect();
        let mut k = 0;
        while k < queue.len() {
            let (node, depth) = queue[k];
            let expand = depth < levels && !tree.is_leaf(node);
            let first = queue.len() as u32;
            if expand {
                queue.extend(tree.children(node).map(|c| (c, depth + 1)));
            }
            out.nodes.push(TopNode {
                centre: tree.centre(node),
                strength: tree.strength(node),
                open2: tree.open_radius2(node),
                first: if expand { first } else { 0 },
                children: if expand {
                    queue.len() as u32 - first
                } else {
                    0
                },
            });
            k += 1;
        }
        out
    }

    /// Number of top nodes shared.
    pub fn len(&self) -> usize {
        self.nodes.len()
    }

    /// Whether there are no nodes: the rank's tree is empty.
    pub fn is_empty(&self) -> bool {
        self.nodes.is_empty()
    }

    /// The values to send: the root count, then [`node_values`] per node.
    pub fn encode(&self) -> Vec<T> {
        let mut out = Vec::with_capacity(1 + self.nodes.len() * node_values(D));
        out.push(T::of(self.roots as f64));
        for n in &self.nodes {
            out.extend_from_slice(&n.centre);
            out.push(n.strength);
            out.push(n.open2);
            out.push(T::of(n.first as f64));
            out.push(T::of(n.children as f64));
        }
        out
    }

    /// The nodes [`TopNodes::encode`] wrote; `None` if the values are not such a list (a
    /// count or child range out of place), so that a corrupt message is not walked.
    pub fn decode(values: &[T]) -> Option<Self> {
        let (&roots, rest) = values.split_first()?;
        let w = node_values(D);
        if rest.len() % w != 0 {
            return None;
        }
        let count = rest.len() / w;
        let roots = roots.as_f64();
        if !(roots >= 0.0 && roots as usize <= count && roots.fract() == 0.0) {
            return None;
        }
        let mut nodes = Vec::with_capacity(count);
        for v in rest.chunks_exact(w) {
            let (first, children) = (v[D + 2].as_f64(), v[D + 3].as_f64());
            if !(first >= 0.0 && children >= 0.0) || first + children > count as f64 {
                return None;
            }
            nodes.push(TopNode {
                centre: std::array::from_fn(|d| v[d]),
                strength: v[D],
                open2: v[D + 1],
                first: first as u32,
                children: children as u32,
            });
        }
        Some(TopNodes {
            nodes,
            roots: roots as usize,
        })
    }

    /// Walks the nodes for a group of bodies inside the box `[lo, hi]` with the octree's
    /// opening test.
    pub fn walk(&self, lo: &[T; D], hi: &[T; D]) -> TopWalk {
        let mut accepted = Vec::new();
        let mut stack: Vec<u32> = (0..self.roots as u32).collect();
        // Children always come after their parent in breadth-first order, so this ends.
        while let Some(k) = stack.pop() {
            let node = &self.nodes[k as usize];
            if far_from_box(&node.centre, node.open2, lo, hi) {
                accepted.push(k);
            } else if node.children == 0 {
                return TopWalk::Open;
            } else {
                stack.extend(node.first..node.first + node.children);
            }
        }
        TopWalk::Accepted(accepted)
    }

    /// The force of the `accepted` nodes, as monopoles, on a body at `x` of strength `s`.
    pub fn force<L: PairLaw<T>>(&self, law: &L, accepted: &[u32], x: [T; D], s: T) -> [T; D] {
        let mut force = [T::zero(); D];
        for &k in accepted {
            let node = &self.nodes[k as usize];
            let dx: [T; D] = std::array::from_fn(|d| node.centre[d] - x[d]);
            let f = pair_force(law, dx, s, node.strength);
            for d in 0..D {
                force[d] += f[d];
            }
        }
        force
    }
}

/// The forces of the bodies of `tree` on a group of bodies that are not among them (position
/// and strength each), from one walk for the group's bounding box with the kernel's opening
/// test (accepted nodes as monopoles, opened leaves body by body), as the kernel walks its own
/// groups: what an owner returns for a group another rank sent it. Also the interactions
/// evaluated.
pub fn group_forces<T: Real, L: PairLaw<T>, const D: usize>(
    tree: &TreeView<'_, T, D>,
    law: &L,
    group: &[([T; D], T)],
) -> (Vec<[T; D]>, u64) {
    let Bounds { lo, hi } = Bounds::of_points(group.iter().map(|g| g.0));
    let mut sources: Vec<([T; D], T)> = Vec::new();
    let mut stack: Vec<u32> = tree.roots().to_vec();
    while let Some(node) = stack.pop() {
        if tree.far_from_box(node, &lo, &hi) {
            sources.push((tree.centre(node), tree.strength(node)));
        } else if tree.is_leaf(node) {
            sources.extend(
                tree.bodies(node)
                    .map(|k| (tree.position(k), tree.source(k))),
            );
        } else {
            stack.extend(tree.children(node));
        }
    }
    let forces = group
        .iter()
        .map(|&(x, s)| {
            let mut force = [T::zero(); D];
            for &(at, strength) in &sources {
                let dx: [T; D] = std::array::from_fn(|d| at[d] - x[d]);
                let f = pair_force(law, dx, s, strength);
                for d in 0..D {
                    force[d] += f[d];
                }
            }
            force
        })
        .collect();
    (forces, (sources.len() * group.len()) as u64)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::kernels::Octree;
    use crate::physics::Gravity;
    use crate::testing::{SEED_1, plummer_state};

    fn tree(theta: f64) -> (crate::state::State<f64, 3>, Octree<Gravity<f64>, f64, 3>) {
        let s = plummer_state::<f64, 3>(2000, SEED_1);
        let mut k = Octree::new(Gravity::new(1.0, 1e-3), theta, 8);
        k.build(&s);
        (s, k)
    }

    #[test]
    fn encode_and_decode_give_the_same_nodes_and_corrupt_lists_are_refused() {
        let (_, k) = tree(0.5);
        let top = TopNodes::of(&k.view(), 2);
        assert!(top.len() > 8 && top.len() <= 1 + 8 + 64, "{}", top.len());
        let values = top.encode();
        assert_eq!(TopNodes::<f64, 3>::decode(&values), Some(top));
        assert_eq!(
            TopNodes::<f64, 3>::decode(&values[..values.len() - 1]),
            None
        );
        let mut bad = values.clone();
        bad[1 + 3 + 2] = 1e9; // the root's first child, far beyond the list
        assert_eq!(TopNodes::<f64, 3>::decode(&bad), None);
        assert_eq!(TopNodes::<f64, 3>::decode(&[]), None);
    }

    /// The direct sum of the tree's bodies on a body at `x` of strength `s`.
    fn direct(s: &crate::state::State<f64, 3>, x: [f64; 3], strength: f64) -> [f64; 3] {
        let law = Gravity::new(1.0, 1e-3);
        (0..s.len()).fold([0.0; 3], |mut acc, j| {
            let dx: [f64; 3] = std::array::from_fn(|d| s.pos[d][j] - x[d]);
            let f = pair_force(&law, dx, strength, s.source[j]);
            for d in 0..3 {
                acc[d] += f[d];
            }
            acc
        })
    }

    fn rel(a: [f64; 3], b: [f64; 3]) -> f64 {
        let norm = |v: [f64; 3]| v.iter().map(|c| c * c).sum::<f64>().sqrt();
        norm(std::array::from_fn(|d| a[d] - b[d])) / norm(b)
    }

    #[test]
    fn a_far_group_gets_the_monopoles_and_a_near_one_is_sent_to_the_owner() {
        let (s, k) = tree(0.5);
        let law = Gravity::new(1.0, 1e-3);
        let top = TopNodes::of(&k.view(), 2);
        // Far away, the root alone passes: the force of the total mass at the centre.
        let far = [500.0, -300.0, 200.0];
        let TopWalk::Accepted(nodes) = top.walk(&far, &far) else {
            panic!("a body at distance ~600 must accept the root");
        };
        assert_eq!(nodes, vec![0]);
        let err = rel(top.force(&law, &nodes, far, 1.0), direct(&s, far, 1.0));
        assert!(err < 1e-4, "{err}");
        // At the centre of the cloud, nothing passes.
        assert_eq!(top.walk(&[0.0; 3], &[0.1; 3]), TopWalk::Open);
        // θ = 0 accepts nothing anywhere.
        let (_, exact) = tree(0.0);
        let top0 = TopNodes::of(&exact.view(), 3);
        assert_eq!(top0.walk(&far, &far), TopWalk::Open);
    }

    #[test]
    fn the_group_walk_is_the_direct_sum_at_theta_zero_and_close_at_half() {
        let law = Gravity::new(1.0, 1e-3);
        let group: Vec<([f64; 3], f64)> = vec![
            ([0.1, -0.2, 0.05], 2.0),
            ([0.15, -0.1, 0.0], 1.0),
            ([1.5, 0.3, -0.7], 0.5),
            ([4.0, 4.0, 4.0], 3.0),
        ];
        // At θ = 0.5 one body's error may reach a few per cent (the median is ~1e-3).
        for (theta, tol) in [(0.0, 1e-12), (0.5, 3e-2)] {
            let (s, k) = tree(theta);
            for g in [&group[..2], &group[2..3], &group[3..]] {
                let (f, count) = group_forces(&k.view(), &law, g);
                for (i, &(x, strength)) in g.iter().enumerate() {
                    let err = rel(f[i], direct(&s, x, strength));
                    assert!(err <= tol, "theta {theta} at {x:?}: {err}");
                }
                if theta == 0.0 {
                    assert_eq!(count, (s.len() * g.len()) as u64);
                } else {
                    assert!(count < (s.len() * g.len()) as u64, "{count}");
                }
            }
        }
    }

    #[test]
    fn a_larger_box_accepts_no_more_than_its_points() {
        let (_, k) = tree(0.7);
        let top = TopNodes::of(&k.view(), 3);
        let root = top.nodes[0];
        // Between the reach of the root and half of it, the root fails and its children may
        // pass: the walk goes down the shared levels.
        let reach = root.open2.sqrt();
        let mut deeper = 0;
        for f in [0.55, 0.7, 0.85, 0.95] {
            let x = [root.centre[0] + f * reach, root.centre[1], root.centre[2]];
            let point = top.walk(&x, &x);
            let h = 0.02 * reach;
            let wide = top.walk(
                &[x[0] - h, x[1] - h, x[2] - h],
                &[x[0] + h, x[1] + h, x[2] + h],
            );
            if let TopWalk::Accepted(nodes) = &point {
                deeper += usize::from(nodes.len() > 1);
                assert!(!nodes.contains(&0), "the root cannot pass inside its reach");
            }
            // A box holding the point opens at least what the point opens.
            if let TopWalk::Accepted(wide) = wide {
                let TopWalk::Accepted(nodes) = point else {
                    panic!("the box passed where its point did not");
                };
                assert!(wide.len() >= nodes.len(), "{wide:?} vs {nodes:?}");
            }
        }
        assert!(deeper > 0, "no walk accepted children below the root");
    }
}
