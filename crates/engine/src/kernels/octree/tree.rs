//! Building the Barnes-Hut tree: Morton keys over the current bounding cube, one sort, and a
//! compressed tree in a flat arena.
//!
//! Sorting by key puts every node's particles in one contiguous run of the sorted arrays, so a
//! node is just a range. The tree is *compressed*: a node is the smallest Morton cell that holds
//! its particles (the common prefix of its first and last key), so a lone outlier of an
//! expanding system, or a cluster far from the centre, costs one node rather than a chain of
//! single-child cells. The children of a node sit next to each other in the arena, so the walk
//! tests a whole family in one branch-free loop.
//!
//! Sources of both signs (Coulomb) get separate trees: a monopole of mixed-sign charges has no
//! meaningful centre. The sign is the key's top bit, so the one sort also separates the trees.
//! The fast multipole kernel (`kernels::fmm`) builds the same tree over all its sources in one
//! class ([`Tree::one_class`]): its expansions carry charges of both signs.

use super::moments::Quadrupoles;
pub(in crate::kernels) use super::node::Node;
use crate::geometry::{interleave, morton_bits};
use crate::real::Real;
use crate::state::State;

/// Top key bit: set for negative sources, so they sort after the non-negative ones.
const NEGATIVE: u64 = 1 << 63;

/// Levels of the tree below the root: the Morton bits per dimension, 21 in 3-D, 31 in 2-D.
/// A cell at this depth is a leaf whatever its count (many coincident particles).
pub(super) const fn max_depth(d: usize) -> u32 {
    morton_bits(d)
}

/// A target group: a run of sibling subtrees whose particles share one interaction list.
#[derive(Clone, Copy, Debug)]
pub(in crate::kernels) struct Group {
    pub start: u32,
    pub end: u32,
}

/// Sums over a node's particles, accumulated in f64 and combined up the tree.
#[derive(Clone, Copy)]
struct Moments<const D: usize> {
    strength: f64,
    weighted: [f64; D],
    plain: [f64; D],
}

impl<const D: usize> Moments<D> {
    fn empty() -> Self {
        Moments {
            strength: 0.0,
            weighted: [0.0; D],
            plain: [0.0; D],
        }
    }
}

/// The tree and the particles in tree (sorted) order. Every buffer is reused across steps.
pub(in crate::kernels) struct Tree<T, const D: usize> {
    /// (key, original index) pairs, sorted by key; the index breaks ties deterministically.
    keys: Vec<(u64, u32)>,
    /// `order[sorted slot] = original index`.
    pub order: Vec<u32>,
    /// Positions and strengths in sorted order.
    pub pos: [Vec<T>; D],
    pub src: Vec<T>,
    pub nodes: Vec<Node<T, D>>,
    /// One root per sign class present (non-negative, negative).
    pub(crate) roots: Vec<u32>,
    /// Target groups in sorted order; their ranges tile `0..n`.
    pub groups: Vec<Group>,
    /// A point outside the bounding cube, where zero-strength padding sources sit.
    pub(crate) dummy: [T; D],
    /// Second moments of every node, computed only for the quadrupole order (else empty).
    pub quad: Quadrupoles<T>,
    quadrupole: bool,
    /// Whether negative sources get a tree of their own (see the module docs).
    split_signs: bool,
    theta: f64,
    leaf_size: usize,
    group_size: usize,
    /// Bounding cube of the current step: lower corner and side.
    lo: [f64; D],
    side: f64,
}

impl<T: Real, const D: usize> Tree<T, D> {
    /// With `quadrupole`, every build also computes the nodes' second moments.
    pub fn new(theta: f64, leaf_size: usize, group_size: usize, quadrupole: bool) -> Self {
        Tree {
            keys: Vec::new(),
            order: Vec::new(),
            pos: std::array::from_fn(|_| Vec::new()),
            src: Vec::new(),
            nodes: Vec::new(),
            roots: Vec::new(),
            groups: Vec::new(),
            dummy: [T::zero(); D],
            quad: Quadrupoles::new(),
            quadrupole,
            split_signs: true,
            theta,
            leaf_size: leaf_size.max(1),
            group_size: group_size.max(1),
            lo: [0.0; D],
            side: 1.0,
        }
    }

    /// A tree of one class whatever the signs of the sources, for the fast multipole kernel:
    /// leaves of at most `leaf_size` particles, no θ (the kernel tests its own criterion), no
    /// second moments.
    pub(crate) fn one_class(leaf_size: usize) -> Self {
        Tree {
            split_signs: false,
            ..Tree::new(0.0, leaf_size, leaf_size, false)
        }
    }

    /// Computes the keys of the current positions and sorts them (tree order).
    pub fn sort(&mut self, state: &State<T, D>) {
        let n = state.len();
        assert!(
            n <= u32::MAX as usize,
            "the octree indexes particles with u32"
        );
        // The bounding cube, recomputed every step: the system is open and may expand.
        // All particles coincident (or n ≤ 1) give a side of 1. A non-finite side (infinite
        // positions) gives keys of 0 and one big leaf, never a panic. The cube is in f64, as
        // the keys are computed.
        (self.lo, self.side) = state.bounding_box().to_f64().cube();
        for d in 0..D {
            // Far enough outside the cube that it never coincides with a particle, even when
            // the offset is small next to the coordinate.
            let off = self.side + self.lo[d].abs() + 1.0;
            self.dummy[d] = T::of(self.lo[d] - off);
        }
        let depth = max_depth(D);
        let cells = (1u64 << depth) as f64;
        let scale = cells / self.side;
        let top = (1u64 << depth) - 1;
        let lo = self.lo;
        self.keys.clear();
        self.keys.extend((0..n).map(|i| {
            let cell: [u64; D] = std::array::from_fn(|d| {
                // `as` saturates (NaN → 0); the clamp keeps the particle on the upper faces.
                (((state.pos[d][i].as_f64() - lo[d]) * scale) as u64).min(top)
            });
            let sign = if self.split_signs && state.source[i] < T::zero() {
                NEGATIVE
            } else {
                0
            };
            (interleave::<D>(cell) | sign, i as u32)
        }));
        // Unique (key, index) pairs: the order is fully determined by the state.
        self.keys.sort_unstable();
    }

    /// Builds the tree of the current state into the reused buffers.
    pub fn build(&mut self, state: &State<T, D>) {
        self.sort(state);
        self.order.clear();
        self.order.extend(self.keys.iter().map(|k| k.1));
        for d in 0..D {
            let src = &state.pos[d];
            self.pos[d].clear();
            self.pos[d].extend(self.order.iter().map(|&i| src[i as usize]));
        }
        self.src.clear();
        self.src
            .extend(self.order.iter().map(|&i| state.source[i as usize]));
        self.nodes.clear();
        self.roots.clear();
        self.groups.clear();
        let n = self.keys.len();
        let mut lo = 0;
        while lo < n {
            let class = self.keys[lo].0 & NEGATIVE;
            let hi = lo + self.keys[lo..].partition_point(|k| k.0 & NEGATIVE == class);
            let root = self.nodes.len();
            self.nodes.push(placeholder(lo, hi));
            self.build_node(root, lo, hi);
            self.roots.push(root as u32);
            self.make_groups(root);
            lo = hi;
        }
        if self.quadrupole {
            self.quad.compute(&self.nodes, &self.pos, &self.src);
        } else {
            self.quad.clear();
        }
    }

    pub fn quadrupole(&self) -> bool {
        self.quadrupole
    }

    /// Fills node `index` (a placeholder over sorted particles `lo..hi`, all of one sign class)
    /// and its subtree, and returns its moments. Each node's children are allocated together,
    /// so a family is one contiguous run of the arena. Recursion depth is bounded by
    /// `max_depth(D)` levels.
    fn build_node(&mut self, index: usize, lo: usize, hi: usize) -> Moments<D> {
        let depth = max_depth(D);
        let level = common_level::<D>(self.keys[lo].0, self.keys[hi - 1].0);
        let count = hi - lo;
        let moments = if count <= self.leaf_size || level >= depth {
            self.leaf_moments(lo, hi)
        } else {
            // Keys in `lo..hi` share their first `level` digits and differ in the next one,
            // which is nondecreasing along the run: split the run at each digit value.
            let shift = D as u32 * (depth - level - 1);
            let digit = |k: u64| ((k >> shift) as usize) & ((1 << D) - 1);
            let first = self.nodes.len();
            let mut start = lo;
            while start < hi {
                let c = digit(self.keys[start].0);
                let end = start + self.keys[start..hi].partition_point(|k| digit(k.0) == c);
                self.nodes.push(placeholder(start, end));
                start = end;
            }
            let children = self.nodes.len() - first;
            self.nodes[index].first = first as u32;
            self.nodes[index].children = children as u32;
            let mut m = Moments::empty();
            for child in first..first + children {
                let (s, e) = (self.nodes[child].start, self.nodes[child].end);
                let cm = self.build_node(child, s as usize, e as usize);
                m.strength += cm.strength;
                for d in 0..D {
                    m.weighted[d] += cm.weighted[d];
                    m.plain[d] += cm.plain[d];
                }
            }
            m
        };
        let side = self.side * 0.5f64.powi(level as i32);
        let node = &mut self.nodes[index];
        for d in 0..D {
            node.com[d] = T::of(if moments.strength != 0.0 {
                moments.weighted[d] / moments.strength
            } else {
                moments.plain[d] / count as f64
            });
        }
        node.strength = T::of(moments.strength);
        node.crit2 = if self.theta > 0.0 {
            T::of((side / self.theta).powi(2))
        } else {
            T::infinity()
        };
        moments
    }

    /// Splits the subtree of `index` into target groups: runs of consecutive siblings of at
    /// most `group_size` particles in all (sibling cells are neighbours, so the run's box
    /// stays compact), or single leaves that hold more (coincident particles).
    fn make_groups(&mut self, index: usize) {
        let node = self.nodes[index];
        let size = |n: &Node<T, D>| (n.end - n.start) as usize;
        if node.children == 0 || size(&node) <= self.group_size {
            self.groups.push(Group {
                start: node.start,
                end: node.end,
            });
            return;
        }
        let mut run: Option<Group> = None;
        for child in node.first as usize..(node.first + node.children) as usize {
            let c = self.nodes[child];
            if c.children != 0 && size(&c) > self.group_size {
                self.groups.extend(run.take());
                self.make_groups(child);
            } else if let Some(g) = run
                .as_mut()
                .filter(|g| (c.end - g.start) as usize <= self.group_size)
            {
                g.end = c.end;
            } else {
                self.groups.extend(run.take());
                run = Some(Group {
                    start: c.start,
                    end: c.end,
                });
            }
        }
        self.groups.extend(run);
    }

    fn leaf_moments(&self, lo: usize, hi: usize) -> Moments<D> {
        let mut m = Moments::empty();
        for i in lo..hi {
            let s = self.src[i].as_f64();
            m.strength += s;
            for d in 0..D {
                let x = self.pos[d][i].as_f64();
                m.weighted[d] += s * x;
                m.plain[d] += x;
            }
        }
        m
    }

    /// The sorted order of the last `sort`, as `order[new_slot] = old_slot`.
    pub(crate) fn sorted_order(&self) -> Vec<u32> {
        self.keys.iter().map(|k| k.1).collect()
    }
}

fn placeholder<T: Real, const D: usize>(lo: usize, hi: usize) -> Node<T, D> {
    Node {
        com: [T::zero(); D],
        strength: T::zero(),
        crit2: T::zero(),
        start: lo as u32,
        end: hi as u32,
        first: 0,
        children: 0,
    }
}

/// Number of leading Morton digits (tree levels) that two keys of one class share.
fn common_level<const D: usize>(a: u64, b: u64) -> u32 {
    let depth = max_depth(D);
    let bits = D as u32 * depth;
    let diff = (a ^ b) & ((1u64 << bits) - 1);
    if diff == 0 {
        depth
    } else {
        (diff.leading_zeros() - (64 - bits)) / D as u32
    }
}
