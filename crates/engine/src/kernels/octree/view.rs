//! A read-only view of the last tree an [`Octree`] built, for code outside the kernel that walks
//! it: the locally essential tree of a distributed run (`decomp::essential`) selects the nodes
//! another rank needs with the kernel's own opening test ([`TreeView::far_from_box`]), so the
//! criterion and the moments exist once.
//!
//! Nodes are arena indices (`u32`), bodies are slots of the tree's sorted order.

use super::Octree;
use super::moments::stride;
use super::tree::Tree;
use crate::real::Real;
use std::ops::Range;

/// The nodes, moments and sorted bodies of a built tree.
#[derive(Clone, Copy)]
pub struct TreeView<'a, T, const D: usize> {
    tree: &'a Tree<T, D>,
}

impl<L, T: Real, const D: usize> Octree<L, T, D> {
    /// The tree of the last [`Octree::build`] (or force computation); empty before the first.
    pub fn view(&self) -> TreeView<'_, T, D> {
        TreeView { tree: &self.tree }
    }
}

impl<T: Real, const D: usize> TreeView<'_, T, D> {
    /// One root per sign class of sources present (one for gravity, none without bodies).
    pub(crate) fn roots(&self) -> &[u32] {
        &self.tree.roots
    }

    /// The children of `node` (contiguous in the arena); empty for a leaf.
    pub fn children(&self, node: u32) -> Range<u32> {
        let n = &self.tree.nodes[node as usize];
        n.first..n.first + n.children
    }

    pub(crate) fn is_leaf(&self, node: u32) -> bool {
        self.tree.nodes[node as usize].children == 0
    }

    /// Centre of strength of `node`.
    pub fn centre(&self, node: u32) -> [T; D] {
        self.tree.nodes[node as usize].com
    }

    /// Total source strength of `node`.
    pub fn strength(&self, node: u32) -> T {
        self.tree.nodes[node as usize].strength
    }

    /// The sorted slots of the bodies inside `node`.
    pub fn bodies(&self, node: u32) -> Range<usize> {
        let n = &self.tree.nodes[node as usize];
        n.start as usize..n.end as usize
    }

    /// The kernel's target groups: runs of sorted slots of neighbouring bodies (up to
    /// `GROUP_SIZE`) that share one interaction list; they tile the sorted bodies.
    pub fn groups(&self) -> impl Iterator<Item = Range<usize>> + '_ {
        self.tree
            .groups
            .iter()
            .map(|g| g.start as usize..g.end as usize)
    }

    /// Number of bodies in the tree.
    pub(crate) fn body_count(&self) -> usize {
        self.tree.src.len()
    }

    #[cfg(test)]
    /// Number of nodes in the arena.
    pub(crate) fn node_count(&self) -> usize {
        self.tree.nodes.len()
    }

    /// Position of the body at sorted `slot`.
    pub fn position(&self, slot: usize) -> [T; D] {
        std::array::from_fn(|d| self.tree.pos[d][slot])
    }

    /// Source strength of the body at sorted `slot`.
    pub fn source(&self, slot: usize) -> T {
        self.tree.src[slot]
    }

    /// The original index (in the state the tree was built from) of sorted `slot`.
    pub fn original_index(&self, slot: usize) -> usize {
        self.tree.order[slot] as usize
    }

    /// Values per node beyond the monopole: the components of Q and the trace T at quadrupole
    /// order (`D(D+1)/2 + 1`), 0 at monopole order.
    pub(crate) fn moment_values(&self) -> usize {
        if self.tree.quadrupole() { stride(D) } else { 0 }
    }

    /// The second moments of `node` (Q in the order of `moments`, then T); empty at monopole
    /// order.
    pub(crate) fn moments(&self, node: u32) -> &[T] {
        let w = self.moment_values();
        &self.tree.quad.values[node as usize * w..(node as usize + 1) * w]
    }

    /// `(side/θ)²` of `node`: the node may act as a multipole on a point whose squared
    /// distance from its centre exceeds this (infinite at θ = 0), the test of
    /// [`TreeView::far_from_box`] for one point.
    pub(crate) fn open_radius2(&self, node: u32) -> T {
        self.tree.nodes[node as usize].crit2
    }

    /// The kernel's opening test: whether `node` may act as a multipole on every point of the
    /// box `[lo, hi]` (see `Node::far_from_box`).
    pub(crate) fn far_from_box(&self, node: u32, lo: &[T; D], hi: &[T; D]) -> bool {
        self.tree.nodes[node as usize].far_from_box(lo, hi)
    }
}
