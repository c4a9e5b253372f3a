//! `mpi-bench`: raw timings for the α-β communication model. Ping-pong between ranks 0 and 1
//! (one-way time = half the round trip) and Allgatherv over all ranks, over message sizes
//! 1 B, 4 B, … up to a maximum; every timed repetition is kept.

use super::communicator::Comm;
use super::error::MpiError;
use crate::output::provenance::{git_state, utc_now};
use crate::ranks::bench_file::{
    MPI_BENCH_SCHEMA, MpiBenchFile, Series, SizeTimings, reps_at, sizes,
};
use std::time::Instant;

/// Message sizes and repetitions.
#[derive(Clone, Debug)]
pub struct BenchOptions {
    /// Largest message (bytes per rank for Allgatherv).
    pub max_bytes: u64,
    /// Timed repetitions for messages up to 64 KiB; fewer above (at least 10), in proportion.
    pub reps: usize,
    /// Untimed repetitions before each size.
    pub warmup: usize,
}

const TAG_PING: i32 = 90;

pub fn run(comm: &mut Comm, o: &BenchOptions) -> Result<Option<MpiBenchFile>, MpiError> {
    if comm.size() < 2 {
        return Err(MpiError::Usage(
            "mpi-bench needs at least 2 ranks (a ping-pong between ranks 0 and 1); \
             run it under `mpirun -n 2` or more"
                .into(),
        ));
    }
    let started = utc_now();
    let mut ping_pong = Vec::new();
    let mut allgatherv = Vec::new();
    for bytes in sizes(o.max_bytes) {
        let reps = reps_at(bytes, o.reps);
        let seconds = ping(comm, bytes as usize, o.warmup, reps);
        if comm.is_root() {
            ping_pong.push(SizeTimings { bytes, seconds });
        }
        let seconds = gather(comm, bytes as usize, o.warmup, reps)?;
        if let Some(seconds) = seconds {
            allgatherv.push(SizeTimings { bytes, seconds });
        }
    }
    let name = ::mpi::environment::processor_name().unwrap_or_else(|_| "unknown".into());
    let Some(hosts) = comm.gather_to_root(name.as_bytes())? else {
        return Ok(None);
    };
    let hosts: Vec<String> = hosts
        .iter()
        .map(|h| String::from_utf8_lossy(h).into_owned())
        .collect();
    let (major, minor) = ::mpi::environment::version();
    let logical = crate::run::logical_cpus();
    let here = hosts.iter().filter(|h| **h == hosts[0]).count();
    Ok(Some(MpiBenchFile {
        schema: MPI_BENCH_SCHEMA.into(),
        tool_version: env!("CARGO_PKG_VERSION").into(),
        git_commit: git_state().0,
        started,
        ranks: comm.size(),
        host: hosts[0].clone(),
        hosts,
        mpi_library: ::mpi::environment::library_version()
            .map(|v| v.trim_end_matches('\0').trim().to_string())
            .unwrap_or_else(|_| "unknown".into()),
        mpi_standard: format!("{major}.{minor}"),
        logical_cpus: logical,
        oversubscribed: here > logical,
        transport: crate::ranks::bench_file::transport_from_env(),
        ping_pong: Series {
            definition: "one-way seconds: half the round trip of a message of `bytes` from rank 0 \
                         to rank 1 and back"
                .into(),
            ranks: 2,
            warmup: o.warmup,
            points: ping_pong,
        },
        allgatherv: Series {
            definition: "seconds of one MPI_Allgatherv in which every rank contributes `bytes` \
                         (each rank receives ranks x bytes); the slowest rank's time, all ranks \
                         starting after a barrier"
                .into(),
            ranks: comm.size(),
            warmup: o.warmup,
            points: allgatherv,
        },
    }))
}

/// Ping-pong between ranks 0 and 1; rank 0 returns the one-way times, the others nothing.
fn ping(comm: &mut Comm, bytes: usize, warmup: usize, reps: usize) -> Vec<f64> {
    let mut buf = vec![0u8; bytes];
    let mut out = Vec::with_capacity(reps);
    comm.barrier();
    for r in 0..warmup + reps {
        match comm.rank() {
            0 => {
                let t = Instant::now();
                comm.send(1, &buf, TAG_PING);
                comm.receive(1, &mut buf, TAG_PING);
                if r >= warmup {
                    out.push(t.elapsed().as_secs_f64() / 2.0);
                }
            }
            1 => {
                comm.receive(0, &mut buf, TAG_PING);
                comm.send(0, &buf, TAG_PING);
            }
            _ => {}
        }
    }
    comm.barrier();
    out
}

/// Allgatherv of `bytes` per rank; rank 0 returns the slowest rank's time per repetition.
fn gather(
    comm: &mut Comm,
    bytes: usize,
    warmup: usize,
    reps: usize,
) -> Result<Option<Vec<f64>>, MpiError> {
    let mine = vec![comm.rank() as u8; bytes];
    let mut all = vec![0u8; bytes * comm.size()];
    let counts = vec![bytes; comm.size()];
    let mut times = Vec::with_capacity(reps);
    for r in 0..warmup + reps {
        comm.barrier();
        let t = Instant::now();
        comm.allgatherv(&mine, &counts, &mut all)?;
        if r >= warmup {
            times.push(t.elapsed().as_secs_f64());
        }
    }
    // Check the data arrived: block k holds rank k's byte.
    let ok = (0..comm.size()).all(|k| {
        all[k * bytes..(k + 1) * bytes]
            .iter()
            .all(|&b| b == k as u8)
    });
    assert!(ok, "Allgatherv delivered wrong data");
    Ok(comm.reduce_max_to_root(&times))
}
