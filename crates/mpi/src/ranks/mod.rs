//! What the MPI drivers need that is not MPI, so that it builds and is tested without an MPI
//! library: the digest of the job the ranks compare before their first collective ([`job`]) and
//! the `mpi-bench` results file ([`bench_file`]) the communication models are fitted to.

pub mod bench_file;
pub mod job;
