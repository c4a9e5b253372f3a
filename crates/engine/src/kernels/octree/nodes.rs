//! The accepted nodes of a group's interaction list at quadrupole order, and the loop that
//! evaluates them on one target.
//!
//! For a 1/r² law, `coeff(r², s_t, s) = κ s_t s / r_s³` with `r_s² = r² + ε²` (Plummer; ε = 0
//! for Coulomb). A node of strength M, centre c and second moments Q, T (see [`super::moments`])
//! at `y = x_t − c` acts on the target with the softened potential expanded to second order,
//! `Φ = M / r_s + ½ (yᵀQy − ε²T) / r_s⁵` (the dipole vanishes about c; the ε²T term is exact for
//! Plummer softening): per unit `c₁ = coeff(r², s_t, 1)`,
//!
//! `F = c₁ [Q y / r_s² − (M + (5/2)(yᵀQy − ε²T) / r_s⁴) y]` and
//! `E = energy(r², s_t, 1) · [M + ½ (yᵀQy − ε²T) / r_s⁴]`,
//!
//! so the law's own `coeff` and `energy` carry κ and the sign convention. The list is SoA and
//! padded to a multiple of `LANES` with zero entries (M = Q = T = 0) outside the bounding cube,
//! which exert no force, so the loop runs whole blocks that LLVM vectorizes like `rows::gather`.

use super::moments::{apply, stride, sym};
use super::tree::Tree;
use crate::kernels::rows::{LANES, RowSum, Target};
use crate::physics::PairLaw;
use crate::real::{Real, select};

/// Accepted nodes: centres, strengths, the components of Q and T; `len` real entries followed
/// by padding up to `padded`.
pub(super) struct NodeList<T, const D: usize> {
    pub(super) pos: [Vec<T>; D],
    pub(super) m: Vec<T>,
    /// Q in the component order of `moments` (the first `sym(D)` arrays in use).
    pub(super) q: [Vec<T>; 6],
    pub(super) trace: Vec<T>,
    pub len: usize,
    pub(super) padded: usize,
}

impl<T: Real, const D: usize> NodeList<T, D> {
    pub fn new() -> Self {
        NodeList {
            pos: std::array::from_fn(|_| Vec::new()),
            m: Vec::new(),
            q: std::array::from_fn(|_| Vec::new()),
            trace: Vec::new(),
            len: 0,
            padded: 0,
        }
    }

    /// Lists the nodes `accepted` (arena indices) of `tree`, padded to whole blocks.
    pub fn fill(&mut self, tree: &Tree<T, D>, accepted: &[u32]) {
        let (len, padded) = (accepted.len(), accepted.len().next_multiple_of(LANES));
        if self.m.len() < padded {
            let cap = padded.max(2 * self.m.len()).max(64);
            for p in &mut self.pos {
                p.resize(cap, T::zero());
            }
            for q in &mut self.q[..sym(D)] {
                q.resize(cap, T::zero());
            }
            self.m.resize(cap, T::zero());
            self.trace.resize(cap, T::zero());
        }
        let width = stride(D);
        let values = &tree.quad.values;
        for (k, &i) in accepted.iter().enumerate() {
            let node = &tree.nodes[i as usize];
            for d in 0..D {
                self.pos[d][k] = node.com[d];
            }
            self.m[k] = node.strength;
            let v = &values[i as usize * width..(i as usize + 1) * width];
            for c in 0..sym(D) {
                self.q[c][k] = v[c];
            }
            self.trace[k] = v[sym(D)];
        }
        for k in len..padded {
            for d in 0..D {
                self.pos[d][k] = tree.dummy[d];
            }
            self.m[k] = T::zero();
            for c in 0..sym(D) {
                self.q[c][k] = T::zero();
            }
            self.trace[k] = T::zero();
        }
        self.len = len;
        self.padded = padded;
    }

    /// Force on `t` from every listed node; with `PROBE`, also the energy and the number of
    /// real entries that interact.
    #[inline(always)]
    pub fn gather<L: PairLaw<T>, const PROBE: bool>(
        &self,
        law: &L,
        t: &Target<T, D>,
    ) -> RowSum<T, D> {
        let eps2 = law.softening2();
        let (one, half, five_halves) = (T::one(), T::of(0.5), T::of(2.5));
        let mut force = [[T::zero(); LANES]; D];
        let mut energy = [T::zero(); LANES];
        let mut interacting = 0;
        for base in (0..self.padded).step_by(LANES) {
            let lanes = |v: &[T]| -> [T; LANES] {
                v[base..base + LANES].try_into().expect("block in range")
            };
            let x: [[T; LANES]; D] = std::array::from_fn(|d| lanes(&self.pos[d]));
            let m = lanes(&self.m);
            let tr = lanes(&self.trace);
            let mut q = [[T::zero(); LANES]; 6];
            for c in 0..sym(D) {
                q[c] = lanes(&self.q[c]);
            }
            let mut y = [[T::zero(); LANES]; D];
            let mut r2 = [T::zero(); LANES];
            for d in 0..D {
                for l in 0..LANES {
                    y[d][l] = t.x[d] - x[d][l];
                    r2[l] += y[d][l] * y[d][l];
                }
            }
            let mut c1 = [T::zero(); LANES];
            let mut inv2 = [T::zero(); LANES];
            for l in 0..LANES {
                c1[l] = law.coeff(r2[l], t.s, one);
                // The same reciprocal square root as the law's (LLVM computes it once).
                let inv = (r2[l] + eps2).rsqrt();
                inv2[l] = inv * inv;
            }
            // Q y, yᵀQy − ε²T, and the scalar factor of y.
            let mut qy = [[T::zero(); LANES]; D];
            let mut quad = [T::zero(); LANES];
            for l in 0..LANES {
                let ql: [T; 6] = std::array::from_fn(|c| q[c][l]);
                let yl: [T; D] = std::array::from_fn(|d| y[d][l]);
                let v = apply(&ql, &yl);
                let mut yqy = T::zero();
                for d in 0..D {
                    qy[d][l] = v[d];
                    yqy += yl[d] * v[d];
                }
                quad[l] = (yqy - eps2 * tr[l]) * inv2[l] * inv2[l];
            }
            for l in 0..LANES {
                let radial = m[l] + five_halves * quad[l];
                for d in 0..D {
                    force[d][l] += c1[l] * (inv2[l] * qy[d][l] - radial * y[d][l]);
                }
            }
            if PROBE {
                for l in 0..LANES {
                    let real = base + l < self.len;
                    let e = law.energy(r2[l], t.s, one) * (m[l] + half * quad[l]);
                    energy[l] += select(real, e, T::zero());
                    interacting += (real && law.interacts(r2[l])) as u64;
                }
            }
        }
        RowSum {
            force: force.map(|lanes| lanes.iter().copied().sum()),
            energy: energy.iter().copied().sum(),
            interacting,
        }
    }
}
