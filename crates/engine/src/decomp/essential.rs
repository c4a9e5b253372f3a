//! The locally essential tree (LET): what one rank's octree must send another rank so that the
//! receiver can compute the force of the sender's bodies on every body of its domain.
//!
//! The sender walks its tree (built by the octree kernel over its own bodies) from the roots. A
//! node that passes the kernel's opening test against the receiver's whole domain — the
//! distance from its centre of strength to the *nearest* point of every box of the domain
//! (`TreeView::far_from_box`) — is exported as a pseudo-particle: its strength and centre, and
//! at quadrupole order its second moments. Otherwise its children are tested, and a leaf that
//! must be opened exports its bodies. Because the test uses the nearest point, an exported node
//! passes for every target in the domain; so a per-target walk of the sender's tree, from any
//! point of the domain, accepts that node or one of its ancestors. The export set therefore
//! *refines* every target's interaction list: each node a target's walk accepts (and each leaf
//! it opens) is exactly the union of some exported entries. The receiver never needs to open
//! what it got, and its forces are those of a walk at least as fine as the serial one.
//!
//! The LET of a domain grows like the domain's surface (the bodies and small nodes within a few
//! leaf sizes over θ of its boundary), not like n (the test model `model::tree_bytes_per_rank`).

use super::Aabb;
use crate::kernels::TreeView;
use crate::real::Real;

/// Values per exported node: D coordinates, the strength and `moment_values` second moments.
pub fn node_entry_values(dim: usize, moment_values: usize) -> usize {
    dim + 1 + moment_values
}

/// Values per exported body: D coordinates and the strength.
pub fn body_entry_values(dim: usize) -> usize {
    dim + 1
}

/// The nodes and leaves of a sender's tree that a receiver's domain needs.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct EssentialSet {
    /// Arena indices of the nodes exported as pseudo-particles, in tree (Morton) order.
    pub nodes: Vec<u32>,
    /// Arena indices of the opened leaves whose bodies are exported, in tree order.
    pub leaves: Vec<u32>,
    /// Bodies in `leaves`.
    pub bodies: usize,
    /// Values per node beyond the monopole (0 at monopole order).
    pub moment_values: usize,
}

/// The entries of an [`EssentialSet`] as they would be sent: the nodes first, then the bodies.
#[derive(Clone, Debug, PartialEq)]
pub struct Payload<T, const D: usize> {
    /// Centres of the nodes, then positions of the bodies.
    pub pos: [Vec<T>; D],
    /// Strengths, in the same order.
    pub strength: Vec<T>,
    /// `moment_values` values per node (Q, then T; see `kernels::octree` moments), nodes only.
    pub moments: Vec<T>,
    /// The first `nodes` entries are nodes.
    pub nodes: usize,
}

/// Selects the essential set of `tree` for a receiver whose domain is the union of `domain`
/// (half-open boxes, as `Domains::boxes` gives). A receiver without a domain (no boxes) can
/// hold no body, and every root passes vacuously: it gets one pseudo-particle per root.
pub fn select<T: Real, const D: usize>(
    tree: &TreeView<'_, T, D>,
    domain: &[Aabb<D>],
) -> EssentialSet {
    // In the tree's precision: rounding to nearest is monotone, so a target of that precision
    // inside a box is also inside the rounded box, and the test stays conservative.
    let boxes: Vec<([T; D], [T; D])> = domain
        .iter()
        .map(|(lo, hi)| (lo.map(T::of), hi.map(T::of)))
        .collect();
    let mut set = EssentialSet {
        moment_values: tree.moment_values(),
        ..Default::default()
    };
    let mut stack: Vec<u32> = tree.roots().iter().rev().copied().collect();
    // Every node is pushed once, so this ends (NaN distances open nodes down to the leaves).
    while let Some(node) = stack.pop() {
        if boxes.iter().all(|(lo, hi)| tree.far_from_box(node, lo, hi)) {
            set.nodes.push(node);
        } else if tree.is_leaf(node) {
            set.leaves.push(node);
            set.bodies += tree.bodies(node).len();
        } else {
            // Reversed, so that the entries come out in tree order.
            stack.extend(tree.children(node).rev());
        }
    }
    set
}

/// `domain`'s boxes with every face that lies on a face of `root` moved out to infinity. A body
/// that leaves the root box still belongs to the rank whose box touched that wall (as
/// `Domains::owner` places it), so the selection must hold out there too; the open boxes are
/// exactly the points the owner test gives the rank.
pub fn open_at_walls<const D: usize>(domain: &[Aabb<D>], root: &Aabb<D>) -> Vec<Aabb<D>> {
    domain
        .iter()
        .map(|(lo, hi)| {
            let lo = std::array::from_fn(|d| {
                if lo[d] <= root.0[d] {
                    f64::NEG_INFINITY
                } else {
                    lo[d]
                }
            });
            let hi = std::array::from_fn(|d| {
                if hi[d] >= root.1[d] {
                    f64::INFINITY
                } else {
                    hi[d]
                }
            });
            (lo, hi)
        })
        .collect()
}

impl EssentialSet {
    /// Exported entries: nodes plus bodies.
    pub fn entries(&self) -> usize {
        self.nodes.len() + self.bodies
    }

    /// Bytes on the wire for values of `value_bytes` bytes (4 for f32, 8 for f64), `dim`
    /// coordinates: every node with its moments, every body with its strength.
    pub fn bytes(&self, dim: usize, value_bytes: usize) -> usize {
        (self.nodes.len() * node_entry_values(dim, self.moment_values)
            + self.bodies * body_entry_values(dim))
            * value_bytes
    }

    /// The values to send, read from the tree the set was selected from.
    pub fn payload<T: Real, const D: usize>(&self, tree: &TreeView<'_, T, D>) -> Payload<T, D> {
        let len = self.entries();
        let mut p = Payload {
            pos: std::array::from_fn(|_| Vec::with_capacity(len)),
            strength: Vec::with_capacity(len),
            moments: Vec::with_capacity(self.nodes.len() * self.moment_values),
            nodes: self.nodes.len(),
        };
        for &node in &self.nodes {
            let c = tree.centre(node);
            for d in 0..D {
                p.pos[d].push(c[d]);
            }
            p.strength.push(tree.strength(node));
            p.moments.extend_from_slice(tree.moments(node));
        }
        for slot in self.leaves.iter().flat_map(|&leaf| tree.bodies(leaf)) {
            let x = tree.position(slot);
            for d in 0..D {
                p.pos[d].push(x[d]);
            }
            p.strength.push(tree.source(slot));
        }
        p
    }
}

#[cfg(test)]
mod tests;
