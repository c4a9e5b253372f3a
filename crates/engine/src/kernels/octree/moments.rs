//! Second moments of the tree nodes, for the quadrupole order.
//!
//! For a node of total strength M and centre of strength c, with `d_k = x_k − c` over its
//! particles, the walk needs `Q = Σ s_k (3 d_k d_kᵀ − |d_k|² I)` (symmetric; traceless only in
//! 3-D) and `T = Σ s_k |d_k|²` (the Plummer-softening term). Both follow from the raw second
//! moment `S = Σ s_k d_k d_kᵀ`: `Q = 3S − tr(S) I`, `T = tr(S)`.
//!
//! `S` is accumulated in f64, bottom-up in one reverse pass over the arena (a family is always
//! allocated after its parent, so every child has a larger index): a leaf sums over its
//! particles about its own centre, an internal node combines its children with the
//! parallel-axis theorem `S = Σ_c [S_c + M_c (c_c − c)(c_c − c)ᵀ]`, which holds because the
//! first moment of a child about its own centre of strength vanishes (all strengths of one tree
//! have one sign; a child of zero strength adds nothing). The pass runs only for the quadrupole
//! order, so monopole runs pay for none of it.

use super::node::Node;
use crate::real::Real;

/// Components of a symmetric D×D tensor: D(D+1)/2 (6 in 3-D, 3 in 2-D).
pub(super) const fn sym(d: usize) -> usize {
    d * (d + 1) / 2
}

/// Stored values per node: the components of `Q` (the diagonal, then `(a, b)` for `a < b` in
/// row order: xx yy zz xy xz yz in 3-D, xx yy xy in 2-D), then `T`.
pub(super) const fn stride(d: usize) -> usize {
    sym(d) + 1
}

/// `Q y` for the components of `q` stored as above (the diagonal first).
#[inline(always)]
pub(super) fn apply<T: Real, const D: usize>(q: &[T], y: &[T; D]) -> [T; D] {
    let mut out: [T; D] = std::array::from_fn(|a| q[a] * y[a]);
    let mut c = D;
    for a in 0..D {
        for b in a + 1..D {
            out[a] += q[c] * y[b];
            out[b] += q[c] * y[a];
            c += 1;
        }
    }
    out
}

/// Per-node sums of the pass, in f64 (the first D entries of each array in use; D ≤ 3).
#[derive(Clone, Copy)]
struct Sums {
    strength: f64,
    /// Centre of strength (the mean position if the strength is zero), as the build computes it.
    centre: [f64; 3],
    /// `S` in the component order of [`stride`], without `T`.
    second: [f64; 6],
}

const EMPTY: Sums = Sums {
    strength: 0.0,
    centre: [0.0; 3],
    second: [0.0; 6],
};

/// Reused buffers of the pass.
pub(in crate::kernels) struct Quadrupoles<T> {
    /// `stride(D)` values per node, in arena order.
    pub values: Vec<T>,
    sums: Vec<Sums>,
}

impl<T: Real> Quadrupoles<T> {
    pub fn new() -> Self {
        Quadrupoles {
            values: Vec::new(),
            sums: Vec::new(),
        }
    }

    pub fn clear(&mut self) {
        self.values.clear();
    }

    /// Computes `Q` and `T` of every node of `nodes` (sorted positions `pos`, strengths `src`).
    pub fn compute<const D: usize>(&mut self, nodes: &[Node<T, D>], pos: &[Vec<T>; D], src: &[T]) {
        assert!(D <= 3, "quadrupoles are implemented for 2-D and 3-D trees");
        let sums = &mut self.sums;
        sums.clear();
        sums.resize(nodes.len(), EMPTY);
        for i in (0..nodes.len()).rev() {
            let node = &nodes[i];
            let (lo, hi) = (node.start as usize, node.end as usize);
            let mut m = EMPTY;
            let mut weighted = [0.0; 3];
            let mut plain = [0.0; 3];
            if node.children == 0 {
                for k in lo..hi {
                    let s = src[k].as_f64();
                    m.strength += s;
                    for d in 0..D {
                        let x = pos[d][k].as_f64();
                        weighted[d] += s * x;
                        plain[d] += x;
                    }
                }
                m.centre = centre::<D>(m.strength, &weighted, &plain, hi - lo);
                for k in lo..hi {
                    let dx: [f64; D] = std::array::from_fn(|d| pos[d][k].as_f64() - m.centre[d]);
                    add_outer(&mut m.second, src[k].as_f64(), &dx);
                }
            } else {
                let children = node.first as usize..(node.first + node.children) as usize;
                for c in children.clone() {
                    let cm = &sums[c];
                    let count = (nodes[c].end - nodes[c].start) as f64;
                    m.strength += cm.strength;
                    for d in 0..D {
                        weighted[d] += cm.strength * cm.centre[d];
                        plain[d] += count * cm.centre[d];
                    }
                }
                // A zero-strength node's children all have zero strength: their mean
                // positions, weighted by count, give the node's mean position.
                m.centre = centre::<D>(m.strength, &weighted, &plain, hi - lo);
                for c in children {
                    let cm = sums[c];
                    for (a, b) in m.second.iter_mut().zip(cm.second) {
                        *a += b;
                    }
                    let dc: [f64; D] = std::array::from_fn(|d| cm.centre[d] - m.centre[d]);
                    add_outer(&mut m.second, cm.strength, &dc);
                }
            }
            sums[i] = m;
        }
        let width = stride(D);
        self.values.clear();
        self.values.resize(nodes.len() * width, T::zero());
        for (m, out) in sums.iter().zip(self.values.chunks_exact_mut(width)) {
            let trace: f64 = m.second[..D].iter().sum();
            for (c, o) in out[..sym(D)].iter_mut().enumerate() {
                let diagonal = if c < D { trace } else { 0.0 };
                *o = T::of(3.0 * m.second[c] - diagonal);
            }
            out[sym(D)] = T::of(trace);
        }
    }
}

fn centre<const D: usize>(
    strength: f64,
    weighted: &[f64; 3],
    plain: &[f64; 3],
    n: usize,
) -> [f64; 3] {
    std::array::from_fn(|d| match d < D {
        true if strength != 0.0 => weighted[d] / strength,
        true => plain[d] / n as f64,
        false => 0.0,
    })
}

/// `second += s · d dᵀ` in the stored component order.
fn add_outer<const D: usize>(second: &mut [f64; 6], s: f64, d: &[f64; D]) {
    for a in 0..D {
        second[a] += s * d[a] * d[a];
    }
    let mut c = D;
    for a in 0..D {
        for b in a + 1..D {
            second[c] += s * d[a] * d[b];
            c += 1;
        }
    }
}
