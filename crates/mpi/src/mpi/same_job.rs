//! The check every MPI entry point makes right after MPI starts, before any other collective:
//! rank 0 broadcasts the digest of its job ([`JobDigest`], fixed size, so this broadcast
//! matches on every rank whatever their arguments), each rank compares it with its own, and an
//! all-gather of the results (one integer per rank) lets every rank stop together when any
//! differs: rank 0 names the ranks that differ, and each of them says what it ran.

use super::communicator::Comm;
use super::communicator::CommCounters;
use super::error::MpiError;
use crate::ranks::job::{Job, JobDigest, Mismatch, build_identity};

pub fn check(comm: &mut Comm, job: &Job) -> Result<(), MpiError> {
    if comm.size() == 1 {
        return Ok(());
    }
    let build = build_identity();
    let mine = JobDigest::of(job, &build);
    let mut root = mine.to_bytes();
    comm.broadcast_from_root(&mut root);
    let differs = mine.differences(&JobDigest::from_bytes(root));
    let all = comm.all_gather_i64(&[differs as i64]);
    // The check is not part of what a run measures.
    comm.counters = CommCounters::default();
    if all.iter().all(|&d| d == 0) {
        return Ok(());
    }
    Err(MpiError::JobMismatch(Mismatch {
        rank: comm.rank(),
        differences: all.iter().map(|&d| d as u8).collect(),
        typed: job.typed.clone(),
        build,
    }))
}
