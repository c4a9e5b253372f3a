//! Errors of the MPI drivers, and which rank reports them.

use crate::boundary::BoundaryError;
use crate::decomp::DecompError;
use crate::decomp::regions::RegionsError;
use crate::kernels::KernelError;
use crate::output::WriteError;
use crate::scenario::SetupError;
use thiserror::Error;

/// Why an MPI run, check or bench stopped; [`MpiError::printed_by`] says which rank reports it.
#[derive(Debug, Error)]
pub enum MpiError {
    /// `MPI_Init` failed: MPI was initialized before in this process, or there is no runtime.
    #[error("MPI could not be initialized (it was initialized before, or there is no MPI runtime)")]
    Init,
    #[error(
        "the MPI library supports threads at level {0}; the drivers need at least `serialized` \
         (MPI called from one thread at a time); use an MPI built with thread support"
    )]
    /// The MPI library grants a thread level below `serialized` (the level it gave, lowercase).
    Threading(String),
    /// The scenario's system could not be built (bad scenario options, initial file).
    #[error(transparent)]
    Setup(#[from] SetupError),
    /// The kernel could not be built for this law and these parameters.
    #[error(transparent)]
    Kernel(#[from] KernelError),
    /// The decomposition does not run this kernel (`--decomp domain` with the octree, say).
    #[error(transparent)]
    Decomp(#[from] DecompError),
    /// The domain decomposition's rank grid or box is unusable (`--rank-grid` not matching
    /// the rank count, a box without finite walls).
    #[error(transparent)]
    Regions(#[from] RegionsError),
    /// The distributed tree's split of the bodies over the ranks could not be built.
    #[error(transparent)]
    Domains(#[from] crate::decomp::DomainError),
    /// This rank's particles broke the boundary (a particle still outside after a reflection).
    #[error("rank {rank}: {error}")]
    Boundary {
        /// The rank whose particle it was (0 for rank 0's serial check).
        rank: usize,
        /// What the boundary found.
        error: BoundaryError,
    },
    /// Another rank failed during a step; that rank prints its own error.
    #[error("rank {rank} stopped at step {step}; its error is printed above")]
    Peer {
        /// The first rank that reported a failure.
        rank: usize,
        /// The step it failed at.
        step: u64,
    },
    /// One message is larger than an MPI count (an `i32`) can describe.
    #[error(
        "a message of {bytes} bytes exceeds MPI's count limit of 2^31 - 1; \
         use more ranks or fewer particles"
    )]
    TooLarge {
        /// The message's size, bytes.
        bytes: usize,
    },
    /// The total energy became non-finite: the time step is too large.
    #[error(transparent)]
    EnergyBlowUp(#[from] crate::engine::EnergyBlowUp),
    /// The final state could not be written to the spec's `dump_state` file.
    #[error(transparent)]
    Write(#[from] WriteError),
    /// A rank's record or bodies could not be encoded, or what a peer sent does not decode.
    #[error("cannot serialize the result: {0}")]
    Serialize(String),
    /// The rayon pool of the rank's threads could not be started.
    #[error("cannot start a pool of {threads} threads: {source}")]
    Pool {
        /// Threads asked for (per rank).
        threads: usize,
        /// Rayon's reason.
        source: rayon::ThreadPoolBuildError,
    },
    /// Arguments that do not fit together or with the scenario (`--rank-grid` without
    /// `--decomp domain`, a domain decomposition of a law without a cutoff), as a message.
    #[error("{0}")]
    Usage(String),
    /// The ranks were not all started with the same arguments by the same build.
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
