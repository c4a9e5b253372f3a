//! One node of the tree: what the build writes, the walk tests and the moments read.

/// One tree node: a Morton cell and the particles `start..end` (sorted order) inside it.
#[derive(Clone, Copy, Debug)]
pub(super) struct Node<T, const D: usize> {
    /// Centre of strength (mass-weighted centre); the mean position if the strength is zero.
    pub com: [T; D],
    /// Total source strength.
    pub strength: T,
    /// `(side/θ)²`: the node is accepted as a monopole when `d² > crit2` (i.e. `side/d < θ`);
    /// infinite for θ = 0, so that nothing is ever accepted.
    pub crit2: T,
    pub start: u32,
    pub end: u32,
    /// Index of the first child; the children are contiguous in the arena.
    pub first: u32,
    /// Number of children; 0 for a leaf.
    pub children: u32,
}
