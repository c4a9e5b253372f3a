//! The mutual dual-tree walk (Dehnen's falcON) and the per-cell lists built from it.
//!
//! The walk starts from the root interacting with itself. A cell with itself splits into its
//! children, each with itself and every pair of them once. A pair of distinct cells A, B is
//! *well separated* when `r_A + r_B < θ |z_A − z_B|` (radii about the expansion centres, so
//! that the expansions converge for θ < 1): it becomes one cell–cell interaction (M2L), which
//! acts on both cells. Otherwise two leaves become a near-field interaction (P2P, also on
//! both), and any other pair is split at the cell of larger radius. Every pair of particles
//! is thus covered exactly once, by one P2P or one M2L, and every interaction acts on both of
//! its cells alike (Newton's third law for cells); θ = 0 accepts nothing and gives the
//! direct sum.
//!
//! Each interaction is then entered in the lists of both its cells ([`Lists`]), in walk
//! order, and each cell sums what acts on it in its list's order. A mutual interaction
//! applied once to both cells would have two threads write to one cell unless scheduled
//! (in rounds with every cell at most once per round); summing per cell needs no schedule,
//! keeps a cell's expansion in registers while its partners stream by, and gives every cell
//! its terms in a fixed order, so the forces are the same bits at every thread count.

use super::tree::Cells;
use crate::kernels::octree::Tree;
use crate::physics::PairLaw;
use crate::real::Real;

/// Work of one walk.
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct WalkCounts {
    /// Pairs of distinct cells split because they were too close.
    pub opened: u64,
    /// Cell–cell interactions (each pair of cells once).
    pub(crate) m2l: u64,
}

enum Task {
    /// A cell with itself.
    Own(u32),
    /// Two distinct cells.
    Pair(u32, u32),
}

/// The interactions of one configuration; buffers reused across steps.
pub(super) struct Walk {
    /// Per cell, the cells it interacts with through expansions.
    pub far: Lists,
    /// Per leaf, the leaves whose particles act on its particles directly (itself included).
    pub near: Lists,
    m2l: Vec<[u32; 2]>,
    p2p: Vec<[u32; 2]>,
    stack: Vec<Task>,
}

impl Walk {
    pub fn new() -> Self {
        Walk {
            far: Lists::default(),
            near: Lists::default(),
            m2l: Vec::new(),
            p2p: Vec::new(),
            stack: Vec::new(),
        }
    }

    /// Lists the interactions of the built tree, per cell.
    pub fn run<T: Real, L: PairLaw<f64>, const D: usize>(
        &mut self,
        tree: &Tree<T, D>,
        cells: &Cells,
        theta: f64,
        law: &L,
    ) -> WalkCounts {
        self.m2l.clear();
        self.p2p.clear();
        self.stack.clear();
        let mut counts = WalkCounts::default();
        let nodes = &tree.nodes;
        let leaf = |a: u32| nodes[a as usize].children == 0;
        let children = |a: u32| {
            let n = &nodes[a as usize];
            n.first..n.first + n.children
        };
        for &root in &tree.roots {
            self.stack.push(Task::Own(root));
        }
        let theta2 = theta * theta;
        // Every task is a pair of cells at most as deep as the tree, each split into strictly
        // smaller ones, so the walk ends whatever the values (NaN distances split to leaves).
        while let Some(task) = self.stack.pop() {
            match task {
                Task::Own(a) if leaf(a) => self.p2p.push([a, a]),
                Task::Own(a) => {
                    let kids = children(a);
                    for c in kids.clone() {
                        self.stack.push(Task::Own(c));
                        for e in c + 1..kids.end {
                            self.stack.push(Task::Pair(c, e));
                        }
                    }
                }
                Task::Pair(a, b) => {
                    if separated(cells, a as usize, b as usize, theta2, law) {
                        self.m2l.push([a, b]);
                    } else if leaf(a) && leaf(b) {
                        self.p2p.push([a, b]);
                    } else {
                        counts.opened += 1;
                        let split_a = !leaf(a)
                            && (leaf(b) || cells.radius[a as usize] >= cells.radius[b as usize]);
                        if split_a {
                            for c in children(a) {
                                self.stack.push(Task::Pair(c, b));
                            }
                        } else {
                            for c in children(b) {
                                self.stack.push(Task::Pair(a, c));
                            }
                        }
                    }
                }
            }
        }
        counts.m2l = self.m2l.len() as u64;
        self.far.fill(&self.m2l, nodes.len());
        self.near.fill(&self.p2p, nodes.len());
        counts
    }
}

/// The acceptance test: `r_A + r_B < θ |z_A − z_B|`, and no pair of particles of the two
/// cells may be closer than where the law stops interacting (Coulomb's quench radius: there
/// the field is not the smooth one the expansion stands for).
#[inline(always)]
fn separated<L: PairLaw<f64>>(cells: &Cells, a: usize, b: usize, theta2: f64, law: &L) -> bool {
    let (za, zb) = (cells.centre[a], cells.centre[b]);
    let r2: f64 = (0..3).map(|d| (za[d] - zb[d]).powi(2)).sum();
    let reach = cells.radius[a] + cells.radius[b];
    // A NaN distance fails the test, so the pair is split.
    let close = reach * reach < theta2 * r2;
    if !close {
        return false;
    }
    let gap = r2.sqrt() - reach;
    law.interacts(gap * gap)
}

/// For every cell, the cells of the interactions it takes part in: `of(c)`, in walk order.
/// The cells are u32 like the tree's nodes; the positions in the lists are usize, as twice
/// the pairs of cells or leaves can pass u32 where the cells do not.
#[derive(Default)]
pub(super) struct Lists {
    start: Vec<usize>,
    items: Vec<u32>,
}

impl Lists {
    /// The lists of `pairs` over `cells` cells: each pair `[a, b]` enters a's list (as b) and
    /// b's (as a), a pair `[a, a]` a's list once.
    fn fill(&mut self, pairs: &[[u32; 2]], cells: usize) {
        self.start.clear();
        self.start.resize(cells + 1, 0);
        for &[a, b] in pairs {
            self.start[a as usize + 1] += 1;
            if a != b {
                self.start[b as usize + 1] += 1;
            }
        }
        for c in 0..cells {
            self.start[c + 1] += self.start[c];
        }
        self.items.clear();
        self.items.resize(self.start[cells], 0);
        let mut next = self.start.clone();
        for &[a, b] in pairs {
            self.items[next[a as usize]] = b;
            next[a as usize] += 1;
            if a != b {
                self.items[next[b as usize]] = a;
                next[b as usize] += 1;
            }
        }
    }

    /// The partners of cell `c`.
    pub fn of(&self, c: usize) -> &[u32] {
        &self.items[self.start[c]..self.start[c + 1]]
    }
}
