//! Decompositions of a simulation over processes, without MPI itself: the spatial regions of
//! the domain decomposition and their rebalancing ([`regions`]), the per-rank statistics and
//! their reduction ([`stats`]), the bytes each decomposition moves ([`model`]), particles as
//! message bytes ([`wire`]) and the comparison of a distributed run with a serial one
//! ([`check`]). The drivers that use them with MPI are the harness's (`nbody_bench::mpi`,
//! feature `mpi`); everything here builds and is tested without an MPI library.
//!
//! The geometry of a distributed Barnes-Hut, also MPI-free: the domains of the ranks, either
//! the octants of the root cube in Morton order ([`octants`], the gravity source's scheme) or a
//! weighted orthogonal recursive bisection for any rank count ([`orb`]), both behind
//! [`Domains`]; and the locally essential tree ([`essential`]): the nodes and bodies of one
//! rank's octree that another rank's domain needs, selected with the octree's own opening test;
//! and the top nodes a rank shares in the source's scheme ([`top_nodes`]).

pub mod check;
pub mod essential;
pub mod model;
pub mod octants;
pub mod orb;
pub mod regions;
pub mod stats;
pub mod top_nodes;
pub mod wire;

use crate::kernels::KernelKind;
use crate::real::Real;
use serde::{Deserialize, Serialize};
use thiserror::Error;

/// The error every MPI entry point gives in a build without MPI.
pub const WITHOUT_MPI: &str = "built without the `mpi` feature; rebuild with `--features mpi`";

/// How a run is split over MPI ranks.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
#[serde(rename_all = "kebab-case")]
pub enum Decomposition {
    /// Replicated data (the LJ-box assignment, the Coulomb MPI tutorial): each rank owns a block of particles, computes
    /// their forces against all particles, and every step an Allgatherv shares the positions.
    Allgather,
    /// Spatial decomposition (cell list and Verlet list): each rank owns a region, exchanges
    /// ghosts within the cutoff with its neighbours and migrates particles that cross its border.
    Domain,
    /// The gravity source's distributed Barnes-Hut (octree): domains from the octants of the
    /// root cube, local trees, top nodes shared with an Allgather, and the groups of bodies that
    /// fail the opening test against a remote domain sent to its owner for their forces.
    Octants,
    /// Distributed Barnes-Hut (octree) with locally essential trees over a cost-balanced
    /// orthogonal recursive bisection: each rank sends each other rank the part of its tree
    /// that rank's domain needs, in one round, and the domains move when the load drifts.
    Tree,
}

/// Why a decomposition cannot run a kernel.
#[derive(Debug, Error, PartialEq)]
pub enum DecompError {
    /// `--decomp domain` with a kernel other than the cell list or the Verlet list; holds the
    /// kernel's name.
    #[error(
        "--decomp domain needs --kernel cell-list or verlet (a short-range law with a cutoff); \
         use --decomp allgather with {0}"
    )]
    DomainKernel(&'static str),
    /// A tree decomposition (`octants`, `tree`) with a kernel other than the octree.
    #[error(
        "--decomp {decomp} distributes the Barnes-Hut tree and needs --kernel octree; use \
         --decomp allgather with {kernel}"
    )]
    TreeKernel {
        /// The decomposition's name.
        decomp: &'static str,
        /// The kernel's name.
        kernel: &'static str,
    },
    /// A tree decomposition with the fmm kernel, which has no distributed walk; holds the
    /// decomposition's name.
    #[error(
        "--decomp {0} distributes the octree's Barnes-Hut tree; the fmm kernel has no distributed \
         walk (its cell pairs would cross ranks both ways): run it with --decomp allgather, where \
         each rank computes the whole step, or use --kernel octree"
    )]
    FmmTree(&'static str),
}

impl Decomposition {
    /// Every decomposition, in the order the command line lists them.
    pub const ALL: [Decomposition; 4] = [
        Decomposition::Allgather,
        Decomposition::Domain,
        Decomposition::Octants,
        Decomposition::Tree,
    ];

    /// The decomposition's name on the command line and in results.
    pub fn name(self) -> &'static str {
        match self {
            Decomposition::Allgather => "allgather",
            Decomposition::Domain => "domain",
            Decomposition::Octants => "octants",
            Decomposition::Tree => "tree",
        }
    }

    /// Whether the decomposition can run this kernel.
    pub fn supports(self, kernel: KernelKind) -> bool {
        match self {
            Decomposition::Allgather => true,
            Decomposition::Domain => matches!(kernel, KernelKind::CellList | KernelKind::Verlet),
            Decomposition::Octants | Decomposition::Tree => kernel == KernelKind::Octree,
        }
    }

    /// Whether the decomposition distributes the Barnes-Hut tree (its forces then differ from
    /// the serial tree's within the opening-angle tolerance, not to rounding).
    pub fn distributes_the_tree(self) -> bool {
        matches!(self, Decomposition::Octants | Decomposition::Tree)
    }

    /// Refuses kernels the decomposition cannot run, saying what to use instead.
    pub fn check(self, kernel: KernelKind) -> Result<(), DecompError> {
        if self.supports(kernel) {
            Ok(())
        } else if self == Decomposition::Domain {
            Err(DecompError::DomainKernel(kernel.name()))
        } else if kernel == KernelKind::Fmm {
            Err(DecompError::FmmTree(self.name()))
        } else {
            Err(DecompError::TreeKernel {
                decomp: self.name(),
                kernel: kernel.name(),
            })
        }
    }
}

/// A half-open box `[lo, hi)`.
pub type Aabb<const D: usize> = ([f64; D], [f64; D]);

/// The spatial domains of the ranks of a tree decomposition: who owns a point, and the boxes
/// that make up each rank's domain (what the locally essential tree is selected against).
pub trait Domains<const D: usize> {
    /// Number of ranks the space is split among.
    fn ranks(&self) -> usize;

    /// The rank that owns `x`; points outside the root box go to a rank whose domain touches
    /// the nearest wall.
    fn owner(&self, x: [f64; D]) -> usize;

    /// Disjoint half-open boxes whose union is the domain of `rank` (the root box's top walls
    /// belong to the boxes that touch them); empty when the rank owns no space.
    fn boxes(&self, rank: usize) -> Vec<Aabb<D>>;

    /// The rank of every body of `pos` (one array per coordinate, as in `State::pos`).
    fn assign<T: Real>(&self, pos: &[Vec<T>; D]) -> Vec<usize> {
        let n = pos.first().map_or(0, Vec::len);
        (0..n)
            .map(|i| self.owner(std::array::from_fn(|d| pos[d][i].as_f64())))
            .collect()
    }

    /// Bodies per rank.
    fn counts<T: Real>(&self, pos: &[Vec<T>; D]) -> Vec<usize> {
        let mut counts = vec![0; self.ranks()];
        for r in self.assign(pos) {
            counts[r] += 1;
        }
        counts
    }
}

/// Why a tree decomposition could not be built.
#[derive(Debug, Error, PartialEq)]
pub enum DomainError {
    /// No rank to split the space among.
    #[error("a decomposition needs at least one rank")]
    NoRanks,
    /// The root box has a non-finite corner or `hi < lo` on some axis.
    #[error("the root box must be finite with hi >= lo (got [{lo:?}, {hi:?}])")]
    BadBox {
        /// Lower corner given.
        lo: Vec<f64>,
        /// Upper corner given.
        hi: Vec<f64>,
    },
    /// The number of weights differs from the number of bodies.
    #[error("{weights} weights for {bodies} bodies; give one weight per body")]
    WeightCount {
        /// Weights given.
        weights: usize,
        /// Bodies to split.
        bodies: usize,
    },
    /// A body's weight is negative or not finite.
    #[error("weight {value} of body {body} is not a finite number >= 0")]
    BadWeight {
        /// Index of the body.
        body: usize,
        /// Its weight.
        value: f64,
    },
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn domain_runs_the_short_range_kernels_only() {
        for k in KernelKind::ALL {
            assert!(Decomposition::Allgather.check(k).is_ok());
            assert_eq!(
                Decomposition::Domain.check(k).is_ok(),
                matches!(k, KernelKind::CellList | KernelKind::Verlet)
            );
        }
        let msg = Decomposition::Domain
            .check(KernelKind::Naive)
            .unwrap_err()
            .to_string();
        assert!(
            msg.contains("cell-list") && msg.contains("allgather"),
            "{msg}"
        );
    }

    #[test]
    fn the_tree_decompositions_run_the_octree_only() {
        for decomp in [Decomposition::Octants, Decomposition::Tree] {
            for k in KernelKind::ALL {
                assert_eq!(decomp.check(k).is_ok(), k == KernelKind::Octree);
            }
            let msg = decomp.check(KernelKind::Naive).unwrap_err().to_string();
            assert!(msg.contains("--kernel octree"), "{msg}");
            assert!(msg.contains(decomp.name()), "{msg}");
            let msg = decomp.check(KernelKind::Fmm).unwrap_err().to_string();
            assert!(msg.contains("fmm") && msg.contains("allgather"), "{msg}");
        }
    }
}
