//! The two families of expansions the fmm runs on, behind one set of operators: Cartesian
//! tensors ([`expansion`], orders 1 to 8, any softening, the translations O(p⁶) at most) and
//! complex solid harmonics ([`harmonic`], orders 1 to 20, the unsoftened 1/r only, the
//! translations O(p³) by rotation). A cell's coefficients are f64 either way (a harmonic one
//! as real and imaginary parts), so the tree, the walk and the passes are shared.

use super::expansion::Expansion;
use super::harmonic::solid::{complex, complex_mut};
use super::harmonic::{self, Harmonic};

/// An fmm's expansions.
pub(crate) enum Family {
    Cartesian(Expansion),
    /// The harmonics, with the law's constant κ of `ψ = κ Σ s / r`.
    Harmonic(Box<Harmonic>, f64),
}

/// Per-thread scratch of a family's operators.
pub(crate) enum Scratch {
    Cartesian(Vec<f64>),
    Harmonic(Box<harmonic::Scratch>),
}

impl Family {
    /// f64 values per cell expansion.
    pub fn len(&self) -> usize {
        match self {
            Family::Cartesian(e) => e.len,
            Family::Harmonic(h, _) => 2 * h.len,
        }
    }

    pub fn scratch(&self) -> Scratch {
        match self {
            Family::Cartesian(e) => Scratch::Cartesian(vec![0.0; e.len]),
            Family::Harmonic(h, _) => Scratch::Harmonic(Box::new(h.scratch())),
        }
    }

    /// About what one cell–cell interaction costs, in particle pairs: the terms of the
    /// Cartesian contraction, or the harmonic translation's multiply-adds (two rotations and
    /// a shift, complex) over the 20 or so flops of a pair.
    pub fn m2l_work(&self) -> usize {
        match self {
            Family::Cartesian(e) => e.m2l_terms(),
            Family::Harmonic(h, _) => {
                let p = h.p;
                (2 * (p + 1) * (p + 2) * (4 * p + 3) / 3 + p * p * p / 3) / 5
            }
        }
    }

    /// P2M: adds the source `s` at offset `w = z − x` from the centre z to `m`.
    pub fn p2m(&self, w: [f64; 3], s: f64, m: &mut [f64], scratch: &mut Scratch) {
        match (self, scratch) {
            (Family::Cartesian(e), Scratch::Cartesian(mono)) => e.p2m(w, s, m, mono),
            (Family::Harmonic(h, _), Scratch::Harmonic(sc)) => {
                h.p2m(w.map(|x| -x), s, complex_mut(m), sc)
            }
            _ => unreachable!("scratch of another family"),
        }
    }

    /// M2M: adds `child` to `parent`, `d = z_parent − z_child`.
    pub fn m2m(&self, d: [f64; 3], child: &[f64], parent: &mut [f64], scratch: &mut Scratch) {
        match (self, scratch) {
            (Family::Cartesian(e), Scratch::Cartesian(mono)) => e.m2m(d, child, parent, mono),
            (Family::Harmonic(h, _), Scratch::Harmonic(sc)) => {
                h.m2m(d.map(|x| -x), complex(child), complex_mut(parent), sc)
            }
            _ => unreachable!("scratch of another family"),
        }
    }

    /// L2L: adds `parent` moved to the child's centre to `child`, `d = z_child − z_parent`.
    pub fn l2l(&self, d: [f64; 3], parent: &[f64], child: &mut [f64], scratch: &mut Scratch) {
        match (self, scratch) {
            (Family::Cartesian(e), Scratch::Cartesian(mono)) => e.l2l(d, parent, child, mono),
            (Family::Harmonic(h, _), Scratch::Harmonic(sc)) => {
                h.l2l(d, complex(parent), complex_mut(child), sc)
            }
            _ => unreachable!("scratch of another family"),
        }
    }

    /// L2P at `r = x − z`: ∇ψ and, with `potential`, ψ (else 0).
    pub fn l2p(
        &self,
        r: [f64; 3],
        local: &[f64],
        potential: bool,
        scratch: &mut Scratch,
    ) -> ([f64; 3], f64) {
        match (self, scratch) {
            (Family::Cartesian(e), Scratch::Cartesian(mono)) => e.l2p(r, local, potential, mono),
            (Family::Harmonic(h, _), Scratch::Harmonic(sc)) => {
                h.l2p(r, complex(local), potential, sc)
            }
            _ => unreachable!("scratch of another family"),
        }
    }
}
