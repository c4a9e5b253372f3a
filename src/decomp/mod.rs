//! Decompositions of a simulation over processes, without MPI itself: the spatial regions of
//! the domain decomposition and their rebalancing ([`regions`]), the per-rank statistics and
//! their reduction ([`stats`]), the bytes each decomposition moves ([`model`]), the
//! `mpi-bench` results file ([`bench_file`]), particles as message bytes ([`wire`]) and the
//! comparison of a distributed run with a serial one ([`check`]). The drivers that use them with MPI are in
//! `crate::mpi` (feature `mpi`); everything here builds and is tested without an MPI library.

pub mod bench_file;
pub mod check;
pub mod model;
pub mod regions;
pub mod stats;
pub mod wire;

use crate::kernels::KernelKind;
use serde::{Deserialize, Serialize};
use thiserror::Error;

/// The error every MPI entry point gives in a build without MPI.
pub const WITHOUT_MPI: &str = "built without the `mpi` feature; rebuild with `--features mpi`";

/// How a run is split over MPI ranks.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize, clap::ValueEnum)]
#[serde(rename_all = "kebab-case")]
pub enum Decomposition {
    /// Replicated data (the LJ-box assignment, the Coulomb MPI tutorial): each rank owns a block of particles, computes
    /// their forces against all particles, and every step an Allgatherv shares the positions.
    Allgather,
    /// Spatial decomposition (cell list and Verlet list): each rank owns a region, exchanges
    /// ghosts within the cutoff with its neighbours and migrates particles that cross its border.
    Domain,
}

#[derive(Debug, Error, PartialEq)]
pub enum DecompError {
    #[error(
        "--decomp domain needs --kernel cell-list or verlet (a short-range law with a cutoff); \
         use --decomp allgather with {0}"
    )]
    DomainKernel(&'static str),
}

impl Decomposition {
    pub const ALL: [Decomposition; 2] = [Decomposition::Allgather, Decomposition::Domain];

    pub fn name(self) -> &'static str {
        match self {
            Decomposition::Allgather => "allgather",
            Decomposition::Domain => "domain",
        }
    }

    /// Whether the decomposition can run this kernel.
    pub fn supports(self, kernel: KernelKind) -> bool {
        match self {
            Decomposition::Allgather => true,
            Decomposition::Domain => matches!(kernel, KernelKind::CellList | KernelKind::Verlet),
        }
    }

    /// Refuses kernels the decomposition cannot run, saying what to use instead.
    pub fn check(self, kernel: KernelKind) -> Result<(), DecompError> {
        if self.supports(kernel) {
            Ok(())
        } else {
            Err(DecompError::DomainKernel(kernel.name()))
        }
    }
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
}
