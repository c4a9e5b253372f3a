//! Errors of the MPI drivers, and which rank reports them.

use crate::boundary::BoundaryError;
use crate::decomp::DecompError;
use crate::decomp::regions::RegionsError;
use crate::kernels::KernelError;
use crate::output::WriteError;
use crate::scenario::SetupError;
use thiserror::Error;

#[derive(Debug, Error)]
pub enum MpiError {
    #[error("MPI could not be initialized (it was initialized before, or there is no MPI runtime)")]
    Init,
    #[error(
        "the MPI library supports threads at level {0}; the drivers need at least `serialized` \
         (MPI called from one thread at a time); use an MPI built with thread support"
    )]
    Threading(String),
    #[error(transparent)]
    Setup(#[from] SetupError),
    #[error(transparent)]
    Kernel(#[from] KernelError),
    #[error(transparent)]
    Decomp(#[from] DecompError),
    #[error(transparent)]
    Regions(#[from] RegionsError),
    #[error(transparent)]
    Domains(#[from] crate::decomp::DomainError),
    #[error("rank {rank}: {error}")]
    Boundary { rank: usize, error: BoundaryError },
    #[error("rank {rank} stopped at step {step}; its error is printed above")]
    Peer { rank: usize, step: u64 },
    #[error(
        "a message of {bytes} bytes exceeds MPI's count limit of 2^31 - 1; \
         use more ranks or fewer particles"
    )]
    TooLarge { bytes: usize },
    #[error(transparent)]
    EnergyBlowUp(#[from] crate::engine::EnergyBlowUp),
    #[error(transparent)]
    Write(#[from] WriteError),
    #[error("cannot serialize the result: {0}")]
    Serialize(String),
    #[error("cannot start a pool of {threads} threads: {source}")]
    Pool {
        threads: usize,
        source: rayon::ThreadPoolBuildError,
    },
    #[error("{0}")]
    Usage(String),
    #[error("{0}")]
    JobMismatch(crate::ranks::job::Mismatch),
}

impl MpiError {
    /// Whether every rank meets this error at the same point (bad input, a blown-up energy
    /// computed from gathered data): then only rank 0 prints it. Errors of one rank (its
    /// particles, its files) are printed by that rank; a `Peer` error by rank 0 as a pointer.
    /// MPI that could not start is reported by every process (none knows its peers yet); a
    /// job mismatch was printed by `Mpi::init` already, before MPI was finalized.
    pub fn printed_by(&self, rank: usize) -> bool {
        match self {
            MpiError::Init | MpiError::Threading(_) => true,
            MpiError::JobMismatch(_) => false,
            MpiError::Boundary { .. } | MpiError::Pool { .. } => true,
            MpiError::Write(_) | MpiError::Serialize(_) => true,
            _ => rank == 0,
        }
    }
}
