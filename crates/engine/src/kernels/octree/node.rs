//! One node of the tree: what the build writes, the walk tests and the moments read, and the
//! opening test itself ([`Node::far_from_box`]), written once for the grouped walk and for the
//! locally essential tree of `decomp::essential`.

use crate::real::Real;

/// One tree node: a Morton cell and the particles `start..end` (sorted order) inside it.
#[derive(Clone, Copy, Debug)]
pub(in crate::kernels) struct Node<T, const D: usize> {
    /// Centre of strength (mass-weighted centre); the mean position if the strength is zero.
    pub(crate) com: [T; D],
    /// Total source strength.
    pub strength: T,
    /// `(side/θ)²`: the node is accepted as a monopole when `d² > crit2` (i.e. `side/d < θ`);
    /// infinite for θ = 0, so that nothing is ever accepted.
    pub(crate) crit2: T,
    pub start: u32,
    pub end: u32,
    /// Index of the first child; the children are contiguous in the arena.
    pub first: u32,
    /// Number of children; 0 for a leaf.
    pub children: u32,
}

impl<T: Real, const D: usize> Node<T, D> {
    /// The opening test: whether the node may act as a multipole on every point of the box
    /// `[lo, hi]`, i.e. `side/d < θ` with `d` the distance from its centre of strength to the
    /// nearest point of the box (`d² > crit2`). A point is the box `[x, x]`. Branch-free, as the
    /// walk tests whole families with it; a NaN distance fails the test, so the node is opened.
    #[inline(always)]
    pub(crate) fn far_from_box(&self, lo: &[T; D], hi: &[T; D]) -> bool {
        far_from_box(&self.com, self.crit2, lo, hi)
    }
}

/// The opening test of a node given by its centre of strength and `crit2 = (side/θ)²` (see
/// [`Node::far_from_box`]), for nodes that travel without their tree (`decomp::top_nodes`).
#[inline(always)]
pub(crate) fn far_from_box<T: Real, const D: usize>(
    com: &[T; D],
    crit2: T,
    lo: &[T; D],
    hi: &[T; D],
) -> bool {
    let mut d2 = T::zero();
    for d in 0..D {
        let x = com[d];
        let e = max(max(lo[d] - x, x - hi[d]), T::zero());
        d2 += e * e;
    }
    d2 > crit2
}

/// The larger of two values as a plain compare-and-select (a NaN gives `b`): `Float::max`
/// adds NaN fix-ups that double the cost of the node test.
#[inline(always)]
fn max<T: Real>(a: T, b: T) -> T {
    if a > b { a } else { b }
}
