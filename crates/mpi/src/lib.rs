//! nbody-mpi: the MPI drivers ([`mpi`], feature `mpi`) and what they share with the harness
//! without MPI ([`ranks`]: the digest of the job the ranks compare, the `mpi-bench` results
//! file). The drivers run the engine's systems over ranks; being a crate of their own, they are
//! compiled beside the harness, not inside it.

// The engine's layers under their own names, as in the harness: `crate::kernels`, ...
use nbody_engine::input;
#[cfg(feature = "mpi")]
use nbody_engine::{
    boundary, decomp, engine, geometry, integrator, kernels, output, physics, real, run, scenario,
    state, stats, validate,
};

#[cfg(feature = "mpi")]
pub mod mpi;
// Its crate-private parts (the digest's wire form, the bench's repetitions) are the drivers'.
#[cfg_attr(not(feature = "mpi"), allow(dead_code))]
pub mod ranks;
