//! The MPI drivers (cargo feature `mpi`): the replicated-data and the spatial decomposition
//! of a run over MPI ranks, the two distributed Barnes-Hut trees ([`tree`]: the source's
//! octants and the locally essential trees), the comparison with a serial run, and the
//! communication benchmark.
//! The physics, kernels and integrator are the engine's; this module only decides which
//! particles each rank integrates and moves data between ranks. What does not need MPI
//! (regions, statistics, byte counts, file formats) is in [`crate::decomp`].

mod allgather;
mod bench;
mod communicator;
mod domain;
mod driver;
mod error;
mod job;
mod same_job;
mod tree;

pub use crate::decomp::check::CheckReport;
pub use bench::BenchOptions;
pub use domain::DomainOptions;
pub use error::MpiError;
pub use job::MpiSpec;
pub(crate) use job::RootResult;

use crate::ranks::bench_file::MpiBenchFile;
use crate::ranks::job::Job;
use crate::scenario::Setup;
use ::mpi::Threading;
use ::mpi::environment::Universe;
use communicator::Comm;

/// The MPI environment of this process: initialized by [`Mpi::init`], finalized on drop.
pub struct Mpi {
    comm: Comm,
    // Dropped last: finalizes MPI.
    _universe: Universe,
}

impl Mpi {
    /// Initializes MPI (at most once per process) with thread level `serialized` (the drivers
    /// run on a rayon thread while the kernels use the rest of the pool), then checks that
    /// every rank was started with `job` by the same build, before any other collective: a
    /// rank that differs makes every rank return [`MpiError::JobMismatch`]. Every MPI entry
    /// point starts here.
    ///
    /// A mismatch is printed here (on rank 0 and on the ranks that differ), before MPI is
    /// finalized: a launcher ends the whole job when the first rank exits with an error, and a
    /// rank that printed only after finalizing could be killed before it did.
    pub fn init(job: &Job) -> Result<Mpi, MpiError> {
        let (universe, level) =
            ::mpi::initialize_with_threading(Threading::Serialized).ok_or(MpiError::Init)?;
        if level < Threading::Serialized {
            return Err(MpiError::Threading(format!("{level:?}").to_lowercase()));
        }
        let mut mpi = Mpi {
            comm: Comm::new(universe.world()),
            _universe: universe,
        };
        if let Err(err) = same_job::check(&mut mpi.comm, job) {
            if let MpiError::JobMismatch(m) = &err
                && m.printed()
            {
                // As the harness's `console::print_error`: a failed write to stderr is ignored.
                let line = format!("error: {m}\n");
                let _ = std::io::Write::write_all(&mut std::io::stderr().lock(), line.as_bytes());
            }
            // Dropping `mpi` finalizes MPI, on every rank together.
            return Err(err);
        }
        Ok(mpi)
    }

    /// This process's rank in the world communicator, 0-based (rank 0 gathers the results).
    pub fn rank(&self) -> usize {
        self.comm.rank()
    }

    /// The number of ranks in the job.
    pub fn size(&self) -> usize {
        self.comm.size()
    }

    /// Runs `spec` on the system of `setup` on every rank; rank 0 gets the result.
    pub fn run(&mut self, setup: &Setup, spec: &MpiSpec) -> Result<Option<RootResult>, MpiError> {
        let job = job::MpiJob {
            spec,
            comm: &mut self.comm,
        };
        setup.dispatch(job)?
    }

    /// Measures point-to-point and Allgatherv timings; rank 0 gets the file contents.
    pub fn bench(&mut self, options: &BenchOptions) -> Result<Option<MpiBenchFile>, MpiError> {
        bench::run(&mut self.comm, options)
    }
}
