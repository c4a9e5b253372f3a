//! Pair laws: the only place where the physics of an interaction is written.
//!
//! Every kernel calls [`PairLaw::coeff`] (and [`PairLaw::energy`] when it is asked for the
//! potential energy); kernels differ only in which pairs they visit. The laws work on the squared
//! distance so that the cutoff test and Lennard-Jones need no square root, and they express
//! "no interaction" (beyond the cutoff, inside the quench radius) as a select, so that the pair
//! loops have no data-dependent branch and vectorize.

mod coulomb;
mod gravity;
mod lj;

pub use coulomb::Coulomb;
pub use gravity::Gravity;
pub use lj::LJ_SIGMA;
pub use lj::LennardJones;

use crate::real::Real;
use serde::Serialize;

/// The family a pair law belongs to; decides which kernels apply.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum LawKind {
    /// Lennard-Jones 12-6, truncated at a cutoff: short-ranged (cell list, Verlet list, cluster
    /// pairs).
    LennardJones,
    /// Quenched Coulomb between charges: inverse-square, long-ranged (trees, fmm).
    Coulomb,
    /// Plummer-softened Newtonian gravity between masses: inverse-square, long-ranged.
    Gravity,
}

impl LawKind {
    /// The law's name in results and dump headers.
    pub fn name(self) -> &'static str {
        match self {
            LawKind::LennardJones => "lennard-jones",
            LawKind::Coulomb => "coulomb",
            LawKind::Gravity => "gravity",
        }
    }

    /// Whether the law is short-ranged (has a cutoff), which the cell list needs.
    pub(crate) fn has_cutoff(self) -> bool {
        matches!(self, LawKind::LennardJones)
    }

    /// Whether distant sources can be lumped into a monopole (a 1/r² law), which Barnes-Hut needs.
    pub(crate) fn is_inverse_square(self) -> bool {
        matches!(self, LawKind::Coulomb | LawKind::Gravity)
    }

    /// Nominal floating-point operations per pair evaluation in our pair loops (a square root
    /// and a division count as one each), to express pair rates as a share of the FMA peak.
    pub fn flops_per_pair(self) -> f64 {
        match self {
            LawKind::LennardJones => 18.0,
            LawKind::Gravity => 20.0,
            LawKind::Coulomb => 21.0,
        }
    }
}

/// A law's parameters as given, so that another code can recompute every force (export
/// and dump headers: `law lennard-jones epsilon 1 sigma 0.01 rc 0.025`).
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
#[serde(tag = "law", rename_all = "kebab-case")]
pub enum LawParameters {
    /// Force truncated at `rc`, not shifted.
    LennardJones {
        /// Well depth ε (energy unit).
        epsilon: f64,
        /// Particle size σ, where the potential crosses zero (length unit).
        sigma: f64,
        /// Cutoff radius beyond which the force is zero.
        rc: f64,
    },
    /// Force zeroed below `quench`.
    Coulomb {
        /// Distance below which the force is zero.
        quench: f64,
    },
    /// Plummer softening.
    Gravity {
        /// Gravitational constant G.
        g: f64,
        /// Plummer softening length ε.
        softening: f64,
    },
}

impl std::fmt::Display for LawParameters {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            LawParameters::LennardJones { epsilon, sigma, rc } => write!(
                f,
                "law lennard-jones epsilon {epsilon} sigma {sigma} rc {rc} force truncated"
            ),
            LawParameters::Coulomb { quench } => {
                write!(
                    f,
                    "law coulomb quench {quench} force q_i q_j (x_i - x_j) / r^3"
                )
            }
            LawParameters::Gravity { g, softening } => write!(
                f,
                "law gravity G {g} softening {softening} force G m_i m_j (x_j - x_i) / (r^2 + softening^2)^1.5"
            ),
        }
    }
}

/// A central pair interaction.
///
/// The force on particle `i` from particle `j` is `coeff(r², s_i, s_j) · (x_j − x_i)`, where
/// `s` is the per-particle source strength (charge, mass; ignored by Lennard-Jones).
/// A negative coefficient is a repulsion.
pub trait PairLaw<T: Real>: Copy + Send + Sync + 'static {
    /// The same law in f64, for reference computations.
    type Wide: PairLaw<f64>;

    /// Which family the law belongs to.
    fn kind(&self) -> LawKind;

    /// The parameters the law was made with.
    fn parameters(&self) -> LawParameters;

    /// The same law with the same parameters in f64.
    fn widen(&self) -> Self::Wide;

    /// Force coefficient at squared distance `r2`; zero for pairs that do not interact.
    fn coeff(&self, r2: T, si: T, sj: T) -> T;

    /// [`PairLaw::coeff`] as the textbook writes it (a square root and a division where the
    /// kernels use [`Real::rsqrt`]): what the f64 reference sum computes, so that the kernels
    /// are checked against a formula they do not share.
    fn reference_coeff(&self, r2: T, si: T, sj: T) -> T {
        self.coeff(r2, si, sj)
    }

    /// Potential energy of the pair at squared distance `r2`; zero for pairs that do not interact.
    fn energy(&self, r2: T, si: T, sj: T) -> T;

    /// Whether the pair at squared distance `r2` interacts at all (inside the cutoff, outside
    /// the quench radius). The kernels count work with it, and the fmm accepts a pair of cells
    /// only where it holds at the least distance their particles can have: so for a law
    /// without cutoff it must hold at every distance beyond one where it holds (the force
    /// there is the smooth field the expansions stand for).
    fn interacts(&self, r2: T) -> bool;

    /// The cutoff radius, for short-ranged laws.
    fn cutoff(&self) -> Option<T>;

    /// ε² of a Plummer-softened law (`coeff ∝ 1/(r² + ε²)^{3/2}`), 0 for an unsoftened one:
    /// the tree's quadrupole expansion of a 1/r² law needs it. Unused for short-ranged laws.
    fn softening2(&self) -> T;

    /// The law as an [`InverseSquare`], for the batched SIMD pair kernels; `None` for a law
    /// of another form.
    fn inverse_square(&self) -> Option<InverseSquare<T>> {
        None
    }

    /// The law as [`LennardJonesTerms`], for the batched SIMD pair kernels; `None` for a law
    /// of another form.
    fn lennard_jones(&self) -> Option<LennardJonesTerms<T>> {
        None
    }
}

/// A truncated Lennard-Jones law as the batched kernels evaluate it: the coefficient is
/// `24ε · u (1 − 2u) / r²` with `u = (σ²/r²)³`, zero where `r² ≥ rc²` (the form of
/// [`LennardJones`]'s `coeff`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LennardJonesTerms<T> {
    /// 24 times the well depth ε.
    pub epsilon24: T,
    /// σ², the squared particle size.
    pub sigma2: T,
    /// The squared cutoff radius.
    pub rc2: T,
}

/// A law whose coefficient is `k · s_i · s_j · (r² + ε²)^{−3/2}`, zero where `r² + ε²` is
/// below `quench2` (gravity: k = G; Coulomb: k = −1, ε = 0, quenched).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct InverseSquare<T> {
    /// Coupling constant: G for gravity, −1 for Coulomb (like charges repel).
    pub k: T,
    /// Squared softening length ε² (0 for Coulomb).
    pub eps2: T,
    /// Zero for a law that is never quenched.
    pub quench2: T,
}

/// The force of source `j` on target `i` given the separation `dx = x_j − x_i`, returned: the
/// law's pair interaction written out plainly, for the f64 reference sum of `validate` and the
/// tests of the SIMD rows (the kernels themselves go through `kernels::rows`).
#[inline(always)]
pub(crate) fn pair_force<T: Real, L: PairLaw<T>, const D: usize>(
    law: &L,
    dx: [T; D],
    si: T,
    sj: T,
) -> [T; D] {
    let mut r2 = T::zero();
    for d in 0..D {
        r2 += dx[d] * dx[d];
    }
    let c = law.reference_coeff(r2, si, sj);
    std::array::from_fn(|d| c * dx[d])
}

#[cfg(test)]
pub(crate) mod fd {
    //! Finite-difference check shared by the laws' tests: F(r) = −dU/dr.
    use super::PairLaw;

    /// Checks that the radial force from `coeff` matches −dU/dr by central differences at `r`.
    pub fn check<L: PairLaw<f64>>(law: &L, r: f64, si: f64, sj: f64, tol: f64) {
        let h = 1e-6 * r;
        let u = |r: f64| law.energy(r * r, si, sj);
        let du_dr = (u(r + h) - u(r - h)) / (2.0 * h);
        // Force on i along (x_j − x_i) is coeff·r; the radial force pushing i away is −coeff·r.
        let f_radial = -law.coeff(r * r, si, sj) * r;
        let scale = f_radial.abs().max(du_dr.abs()).max(1e-300);
        assert!(
            (f_radial + du_dr).abs() / scale < tol,
            "{:?} at r={r}: force {f_radial} vs -dU/dr {}",
            law.kind(),
            -du_dr
        );
    }
}
