//! The cells of the fast multipole method: the octree's Morton tree (`octree::Tree`, built
//! over all sources in one class) and, for every node of it, an expansion centre, a radius,
//! the multipole and the local expansion; the upward pass (P2M at the leaves, M2M up the
//! tree) and the downward pass (L2L down the tree, L2P at the particles).
//!
//! The expansion centre is the centre of the strengths' magnitudes, `z = Σ|s| x / Σ|s|`. For
//! gravity (all masses positive) that is the centre of mass, where the dipole vanishes. For
//! Coulomb's charges of both signs the centre of charge `Σ s x / Σ s` is no use (the net
//! charge of a cell is often near zero, which throws it far outside the cell); the |s|-centre
//! stays inside the cell, near where most charge is. Against the centre of the particles' box
//! (which gives the smallest radii, so the most accepted pairs), measured at θ 0.5, p 4 on the
//! Intel Xeon 6/167/1: on `coulomb` the box centre had 6 % fewer particle pairs and 7 % fewer
//! cell pairs at n = 1e5 but an 11 % larger median error at n = 2e4 (7.6e-4 against 6.8e-4),
//! about even at equal error; on `galaxy` 14 % and 20 % fewer, but a 50 % larger error
//! (2.5e-4 against 1.7e-4: the dipole no longer vanishes). So one rule serves both laws.
//!
//! The radius `r` bounds the distance of every particle of the cell from its centre: exact at
//! a leaf, and at an internal node the smaller of the bound through the children
//! (`max |z_c − z| + r_c`) and the distance to the farthest corner of the particles' box.

use super::family::{Family, Scratch};
use super::point;
use crate::geometry::Bounds;
use crate::kernels::octree::Tree;
use crate::real::Real;
use rayon::prelude::*;

/// Per-node data, indexed like the tree's arena; reused across steps.
pub(super) struct Cells {
    pub centre: Vec<[f64; 3]>,
    pub radius: Vec<f64>,
    /// `len` multipole coefficients per node (see `expansion`).
    pub multipole: Vec<f64>,
    /// `len` local coefficients per node.
    pub local: Vec<f64>,
    /// The leaves in the order of their particles: their slot ranges tile the sorted slots.
    pub leaves: Vec<u32>,
    /// Σ|s| and Σ|s| x of every node, and the box of its particles.
    weight: Vec<f64>,
    weighted: Vec<[f64; 3]>,
    bounds: Vec<Bounds<f64, 3>>,
    /// The leaves' sums and multipoles in `leaves` order, as the parallel pass writes them.
    leaf_sums: Vec<LeafSums>,
    leaf_multipoles: Vec<f64>,
}

/// What a leaf's particles give its node.
#[derive(Clone, Copy, Default)]
struct LeafSums {
    weight: f64,
    weighted: [f64; 3],
    bounds: Bounds<f64, 3>,
    centre: [f64; 3],
    radius: f64,
}

/// Leaves per parallel task of the per-leaf passes.
const LEAF_CHUNK: usize = 16;

impl Cells {
    pub fn new() -> Self {
        Cells {
            centre: Vec::new(),
            radius: Vec::new(),
            multipole: Vec::new(),
            local: Vec::new(),
            leaves: Vec::new(),
            weight: Vec::new(),
            weighted: Vec::new(),
            bounds: Vec::new(),
            leaf_sums: Vec::new(),
            leaf_multipoles: Vec::new(),
        }
    }

    /// Centres, radii and multipoles of every node of `tree`, the leaves on the pool's
    /// threads when `parallel`; the locals zeroed.
    pub(crate) fn upward<T: Real, const D: usize>(
        &mut self,
        tree: &Tree<T, D>,
        exp: &Family,
        parallel: bool,
    ) {
        let nodes = &tree.nodes;
        let count = nodes.len();
        let len = exp.len();
        self.leaves.clear();
        self.leaves
            .extend((0..count as u32).filter(|&i| nodes[i as usize].children == 0));
        self.leaves
            .sort_unstable_by_key(|&i| nodes[i as usize].start);

        // The leaves from their particles, each into its own entries.
        let leaf = |scratch: &mut Scratch, (&i, m): (&u32, &mut [f64])| {
            leaf_sums(tree, exp, i as usize, m, scratch)
        };
        self.leaf_multipoles.clear();
        self.leaf_multipoles.resize(self.leaves.len() * len, 0.0);
        if parallel {
            self.leaves
                .par_iter()
                .zip(self.leaf_multipoles.par_chunks_mut(len))
                .with_min_len(LEAF_CHUNK)
                .map_init(|| exp.scratch(), leaf)
                .collect_into_vec(&mut self.leaf_sums);
        } else {
            let mut scratch = exp.scratch();
            self.leaf_sums.clear();
            self.leaf_sums.extend(
                self.leaves
                    .iter()
                    .zip(self.leaf_multipoles.chunks_mut(len))
                    .map(|item| leaf(&mut scratch, item)),
            );
        }

        self.centre.resize(count, [0.0; 3]);
        self.radius.resize(count, 0.0);
        self.weight.resize(count, 0.0);
        self.weighted.resize(count, [0.0; 3]);
        self.bounds.resize(count, Bounds::empty());
        self.multipole.clear();
        self.multipole.resize(count * len, 0.0);
        for (k, (&i, sums)) in self.leaves.iter().zip(&self.leaf_sums).enumerate() {
            let i = i as usize;
            self.centre[i] = sums.centre;
            self.radius[i] = sums.radius;
            self.weight[i] = sums.weight;
            self.weighted[i] = sums.weighted;
            self.bounds[i] = sums.bounds;
            self.multipole[i * len..(i + 1) * len]
                .copy_from_slice(&self.leaf_multipoles[k * len..(k + 1) * len]);
        }

        // Internal nodes from their children: a family is allocated after its parent, so a
        // reverse pass over the arena meets every child before its parent.
        let mut scratch = exp.scratch();
        for i in (0..count).rev() {
            let node = &nodes[i];
            if node.children == 0 {
                continue;
            }
            let kids = node.first as usize..(node.first + node.children) as usize;
            let (mut w, mut wx) = (0.0, [0.0; 3]);
            let mut bounds = Bounds::empty();
            for c in kids.clone() {
                w += self.weight[c];
                for d in 0..3 {
                    wx[d] += self.weighted[c][d];
                }
                bounds = bounds.union(self.bounds[c]);
            }
            let z = centre_of(w, wx, &bounds);
            let Bounds { lo: l, hi: h } = bounds;
            let mut through_children: f64 = 0.0;
            let (parent, below) = self.multipole.split_at_mut(kids.start * len);
            let m = &mut parent[i * len..(i + 1) * len];
            for c in kids.clone() {
                let zc = self.centre[c];
                let d = [z[0] - zc[0], z[1] - zc[1], z[2] - zc[2]];
                let dist = d.iter().map(|x| x * x).sum::<f64>().sqrt();
                through_children = through_children.max(dist + self.radius[c]);
                let off = (c - kids.start) * len;
                exp.m2m(d, &below[off..off + len], m, &mut scratch);
            }
            let corner: f64 = (0..3)
                .map(|d| (z[d] - l[d]).abs().max((h[d] - z[d]).abs()).powi(2))
                .sum::<f64>()
                .sqrt();
            self.centre[i] = z;
            self.radius[i] = through_children.min(corner);
            self.weight[i] = w;
            self.weighted[i] = wx;
            self.bounds[i] = bounds;
        }
        self.local.clear();
        self.local.resize(count * len, 0.0);
    }

    /// L2L: moves every internal node's local expansion to its children's centres and adds
    /// it there, top-down (a parent's arena index is below its children's).
    pub(crate) fn downward<T, const D: usize>(&mut self, tree: &Tree<T, D>, exp: &Family) {
        let len = exp.len();
        let mut scratch = exp.scratch();
        for (i, node) in tree.nodes.iter().enumerate() {
            if node.children == 0 {
                continue;
            }
            let first = node.first as usize;
            let (parent, below) = self.local.split_at_mut(first * len);
            let l = &parent[i * len..(i + 1) * len];
            let z = self.centre[i];
            for c in first..first + node.children as usize {
                let zc = self.centre[c];
                let d = [zc[0] - z[0], zc[1] - z[1], zc[2] - z[2]];
                let off = (c - first) * len;
                exp.l2l(d, l, &mut below[off..off + len], &mut scratch);
            }
        }
    }
}

/// Centre, radius, box and multipole (into `m`) of leaf `i` from its particles.
fn leaf_sums<T: Real, const D: usize>(
    tree: &Tree<T, D>,
    exp: &Family,
    i: usize,
    m: &mut [f64],
    scratch: &mut Scratch,
) -> LeafSums {
    let node = &tree.nodes[i];
    let (start, end) = (node.start as usize, node.end as usize);
    let mut sums = LeafSums::default();
    for k in start..end {
        let (x, s) = (point(&tree.pos, k), tree.src[k].as_f64().abs());
        sums.weight += s;
        for d in 0..3 {
            sums.weighted[d] += s * x[d];
        }
        sums.bounds.extend(x);
    }
    let z = centre_of(sums.weight, sums.weighted, &sums.bounds);
    let mut r2: f64 = 0.0;
    for k in start..end {
        let x = point(&tree.pos, k);
        let off = [z[0] - x[0], z[1] - x[1], z[2] - x[2]];
        r2 = r2.max(off.iter().map(|o| o * o).sum());
        exp.p2m(off, tree.src[k].as_f64(), m, scratch);
    }
    sums.centre = z;
    sums.radius = r2.sqrt();
    sums
}

/// L2P of leaf `i`: adds the far field's force `−s ∇ψ` to each of its particles (`out`, the
/// leaf's slots); with `potential`, returns Σ s ψ over them (else 0).
pub(super) fn evaluate<T: Real, const D: usize>(
    exp: &Family,
    cells: &Cells,
    tree: &Tree<T, D>,
    i: usize,
    potential: bool,
    out: &mut [&mut [T]; D],
    scratch: &mut Scratch,
) -> f64 {
    let len = exp.len();
    let node = &tree.nodes[i];
    let (z, l) = (cells.centre[i], &cells.local[i * len..(i + 1) * len]);
    let mut sum = 0.0;
    for (k, slot) in (node.start as usize..node.end as usize).enumerate() {
        let x = point(&tree.pos, slot);
        let r = [x[0] - z[0], x[1] - z[1], x[2] - z[2]];
        let (grad, psi) = exp.l2p(r, l, potential, scratch);
        let s = tree.src[slot].as_f64();
        for d in 0..D {
            out[d][k] += T::of(-s * grad[d]);
        }
        sum += s * psi;
    }
    sum
}

/// The |s|-weighted centre, or the centre of the box when every strength is zero.
fn centre_of(w: f64, wx: [f64; 3], bounds: &Bounds<f64, 3>) -> [f64; 3] {
    if w > 0.0 {
        wx.map(|x| x / w)
    } else {
        bounds.center()
    }
}
