//! The communicator the drivers use: every MPI call goes through it, so that the time inside
//! MPI, the bytes and the messages sent are counted in one place.
//!
//! Counting rules (also in `docs/explanation/mpi.md`): point-to-point messages count their payload and one
//! message each (a size header is a message too); a collective counts one collective call and,
//! as bytes, this rank's contribution times the number of other ranks that receive it.

use super::error::MpiError;
use ::mpi::collective::SystemOperation;
use ::mpi::datatype::{Partition, PartitionMut};
use ::mpi::topology::SimpleCommunicator;
use ::mpi::traits::*;
use ::mpi::{Count, Tag};
use std::time::Instant;

/// What a rank has spent and sent in MPI calls.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(crate) struct CommCounters {
    /// Seconds inside MPI calls.
    pub seconds: f64,
    pub bytes_sent: u64,
    pub messages_sent: u64,
    pub collectives: u64,
}

pub struct Comm {
    world: SimpleCommunicator,
    rank: usize,
    size: usize,
    pub counters: CommCounters,
}

/// An element count as MPI takes it.
fn count(n: usize) -> Result<Count, MpiError> {
    Count::try_from(n).map_err(|_| MpiError::TooLarge { bytes: n })
}

/// Displacements of consecutive blocks of the given sizes.
fn displacements(counts: &[Count]) -> Vec<Count> {
    counts
        .iter()
        .scan(0, |acc, &c| {
            let d = *acc;
            *acc += c;
            Some(d)
        })
        .collect()
}

/// A byte that gives empty buffers a real address: an empty `Vec<u8>` points at address 1,
/// which Open MPI reads as `MPI_IN_PLACE`.
static ANCHOR: [u8; 1] = [0];

/// `buf`, or an empty slice at a real address.
fn anchored(buf: &[u8]) -> &[u8] {
    if buf.is_empty() { &ANCHOR[..0] } else { buf }
}

/// `buf`, or an empty slice of `spare` (a real address).
fn anchored_mut<'a>(buf: &'a mut [u8], spare: &'a mut [u8; 1]) -> &'a mut [u8] {
    if buf.is_empty() { &mut spare[..0] } else { buf }
}

/// Splits `flat` into consecutive blocks of the given sizes.
fn split(flat: &[u8], counts: &[Count]) -> Vec<Vec<u8>> {
    let mut at = 0;
    counts
        .iter()
        .map(|&c| {
            let part = flat[at..at + c as usize].to_vec();
            at += c as usize;
            part
        })
        .collect()
}

impl Comm {
    pub fn new(world: SimpleCommunicator) -> Self {
        let (rank, size) = (world.rank() as usize, world.size() as usize);
        Comm {
            world,
            rank,
            size,
            counters: CommCounters::default(),
        }
    }

    pub fn rank(&self) -> usize {
        self.rank
    }

    pub fn size(&self) -> usize {
        self.size
    }

    pub(crate) fn is_root(&self) -> bool {
        self.rank == 0
    }

    /// Runs `f` (one MPI call) and adds its duration to the counters.
    fn timed<R>(&mut self, f: impl FnOnce(&SimpleCommunicator) -> R) -> R {
        let t = Instant::now();
        let r = f(&self.world);
        self.counters.seconds += t.elapsed().as_secs_f64();
        r
    }

    /// Counts a collective in which this rank contributes `bytes` to every other rank.
    fn collective(&mut self, bytes: usize) {
        self.counters.collectives += 1;
        self.counters.bytes_sent += (bytes * (self.size - 1)) as u64;
    }

    pub(crate) fn barrier(&mut self) {
        self.counters.collectives += 1;
        self.timed(|w| w.barrier());
    }

    /// Every rank's block of bytes, concatenated in rank order into `all`: `counts[r]` bytes
    /// from rank `r` (this rank's block is `mine`).
    pub fn allgatherv(
        &mut self,
        mine: &[u8],
        counts: &[usize],
        all: &mut [u8],
    ) -> Result<(), MpiError> {
        let counts: Vec<Count> = counts.iter().map(|&c| count(c)).collect::<Result<_, _>>()?;
        count(all.len())?;
        let displs = displacements(&counts);
        self.collective(mine.len());
        let mut spare = [0u8; 1];
        let (mine, all) = (anchored(mine), anchored_mut(all, &mut spare));
        self.timed(|w| {
            let mut part = PartitionMut::new(all, &counts[..], &displs[..]);
            w.all_gather_varcount_into(mine, &mut part);
        });
        Ok(())
    }

    /// Every rank's `mine` (all of one length), concatenated in rank order.
    pub(crate) fn all_gather_i64(&mut self, mine: &[i64]) -> Vec<i64> {
        let mut all = vec![0i64; mine.len() * self.size];
        self.collective(std::mem::size_of_val(mine));
        self.timed(|w| w.all_gather_into(mine, &mut all[..]));
        all
    }

    /// Rank 0's `buf` on every rank (every rank passes a buffer of the same length).
    pub(crate) fn broadcast_from_root(&mut self, buf: &mut [u8]) {
        self.collective(if self.rank == 0 { buf.len() } else { 0 });
        self.timed(|w| w.process_at_rank(0).broadcast_into(buf));
    }

    /// Element-wise sum over the ranks.
    pub(crate) fn all_reduce_sum_f64(&mut self, mine: &[f64], out: &mut [f64]) {
        self.collective(std::mem::size_of_val(mine));
        self.timed(|w| w.all_reduce_into(mine, out, SystemOperation::sum()));
    }

    /// Element-wise sum over the ranks.
    pub(crate) fn all_reduce_sum_u64(&mut self, mine: &[u64]) -> Vec<u64> {
        let mut out = vec![0u64; mine.len()];
        self.collective(std::mem::size_of_val(mine));
        self.timed(|w| w.all_reduce_into(mine, &mut out[..], SystemOperation::sum()));
        out
    }

    /// Exchanges one message with each of `peers` (a symmetric relation: every peer calls
    /// this with this rank among its peers): `send[k]` goes to `peers[k]`, and the result's
    /// `k`-th entry came from it. See [`Comm::exchange_overlapped`].
    pub fn exchange(
        &mut self,
        peers: &[usize],
        send: &[Vec<u8>],
        tag: Tag,
    ) -> Result<Vec<Vec<u8>>, MpiError> {
        Ok(self.exchange_overlapped(peers, send, tag, || ())?.0)
    }

    /// Like [`Comm::exchange`], running `work` while the payloads are in flight: sizes are
    /// exchanged first (blocking, one small message each way), then the payloads are posted as
    /// nonblocking sends and receives, `work` runs, and the requests are completed. The time
    /// of `work` is not communication time.
    pub(crate) fn exchange_overlapped<R>(
        &mut self,
        peers: &[usize],
        send: &[Vec<u8>],
        tag: Tag,
        work: impl FnOnce() -> R,
    ) -> Result<(Vec<Vec<u8>>, R), MpiError> {
        for s in send {
            count(s.len())?;
        }
        let t = Instant::now();
        let sizes: Vec<u64> = send.iter().map(|s| s.len() as u64).collect();
        let mut recv_sizes = vec![0u64; peers.len()];
        let world = &self.world;
        ::mpi::request::scope(|scope| {
            let mut requests = Vec::with_capacity(2 * peers.len());
            for (size, &p) in recv_sizes.iter_mut().zip(peers) {
                let from = world.process_at_rank(p as i32);
                requests.push(from.immediate_receive_into_with_tag(scope, size, tag));
            }
            for (size, &p) in sizes.iter().zip(peers) {
                let to = world.process_at_rank(p as i32);
                requests.push(to.immediate_send_with_tag(scope, size, tag));
            }
            for r in requests {
                r.wait_without_status();
            }
        });
        let mut recv: Vec<Vec<u8>> = recv_sizes.iter().map(|&c| vec![0u8; c as usize]).collect();
        let mut seconds = t.elapsed().as_secs_f64();
        let mut result = None;
        ::mpi::request::scope(|scope| {
            let t = Instant::now();
            let mut requests = Vec::with_capacity(2 * peers.len());
            for (buf, &p) in recv.iter_mut().zip(peers) {
                if !buf.is_empty() {
                    let from = world.process_at_rank(p as i32);
                    requests.push(from.immediate_receive_into_with_tag(
                        scope,
                        &mut buf[..],
                        tag + 1,
                    ));
                }
            }
            for (buf, &p) in send.iter().zip(peers) {
                if !buf.is_empty() {
                    let to = world.process_at_rank(p as i32);
                    requests.push(to.immediate_send_with_tag(scope, &buf[..], tag + 1));
                }
            }
            seconds += t.elapsed().as_secs_f64();
            result = Some(work());
            let t = Instant::now();
            for r in requests {
                r.wait_without_status();
            }
            seconds += t.elapsed().as_secs_f64();
        });
        self.counters.seconds += seconds;
        self.counters.messages_sent +=
            (peers.len() + send.iter().filter(|s| !s.is_empty()).count()) as u64;
        self.counters.bytes_sent +=
            (8 * peers.len() + send.iter().map(Vec::len).sum::<usize>()) as u64;
        Ok((recv, result.expect("work ran inside the scope")))
    }

    /// Sends `send[r]` to every rank `r` (an all-to-all with a size round first); returns what
    /// each rank sent to this one. Every rank must call it.
    pub fn all_to_all(&mut self, send: &[Vec<u8>]) -> Result<Vec<Vec<u8>>, MpiError> {
        assert_eq!(send.len(), self.size, "one message per rank");
        let counts: Vec<Count> = send
            .iter()
            .map(|s| count(s.len()))
            .collect::<Result<_, _>>()?;
        let mut recv_counts = vec![0 as Count; self.size];
        self.counters.collectives += 2;
        self.counters.bytes_sent += send
            .iter()
            .enumerate()
            .filter(|&(r, _)| r != self.rank)
            .map(|(_, s)| s.len() as u64)
            .sum::<u64>();
        self.timed(|w| w.all_to_all_into(&counts[..], &mut recv_counts[..]));
        let total: usize = recv_counts.iter().map(|&c| c as usize).sum();
        count(total)?;
        let flat: Vec<u8> = send.concat();
        let mut recv = vec![0u8; total];
        let (sd, rd) = (displacements(&counts), displacements(&recv_counts));
        let mut spare = [0u8; 1];
        let (out, into) = (anchored(&flat), anchored_mut(&mut recv, &mut spare));
        self.timed(|w| {
            let out = Partition::new(out, &counts[..], &sd[..]);
            let mut into = PartitionMut::new(into, &recv_counts[..], &rd[..]);
            w.all_to_all_varcount_into(&out, &mut into);
        });
        Ok(split(&recv, &recv_counts))
    }

    /// Gathers every rank's bytes on rank 0, which receives them per rank; `None` elsewhere.
    pub(crate) fn gather_to_root(&mut self, mine: &[u8]) -> Result<Option<Vec<Vec<u8>>>, MpiError> {
        let n = count(mine.len())?;
        self.counters.collectives += 2;
        if self.rank != 0 {
            self.counters.bytes_sent += mine.len() as u64;
        }
        let size = self.size;
        let root_rank = self.rank == 0;
        let mut counts = vec![0 as Count; size];
        self.timed(|w| {
            let root = w.process_at_rank(0);
            if root_rank {
                root.gather_into_root(&n, &mut counts[..]);
            } else {
                root.gather_into(&n);
            }
        });
        let mine = anchored(mine);
        if !root_rank {
            self.timed(|w| w.process_at_rank(0).gather_varcount_into(mine));
            return Ok(None);
        }
        let total: usize = counts.iter().map(|&c| c as usize).sum();
        count(total)?;
        let mut flat = vec![0u8; total];
        let displs = displacements(&counts);
        let mut spare = [0u8; 1];
        let into = anchored_mut(&mut flat, &mut spare);
        self.timed(|w| {
            let mut part = PartitionMut::new(into, &counts[..], &displs[..]);
            w.process_at_rank(0)
                .gather_varcount_into_root(mine, &mut part);
        });
        Ok(Some(split(&flat, &counts)))
    }
}

/// The communicator lent to the rayon thread that runs a driver (`ThreadPool::install` runs
/// its closure on a pool thread and needs it to be `Send`; an MPI handle is not).
///
/// Sound because MPI is initialized at `MPI_THREAD_SERIALIZED` or above (checked in
/// [`super::Mpi::init`]), which allows calls from any thread as long as they never overlap:
/// the lending thread waits inside `install` until the closure returns, so only one thread
/// uses the communicator at a time.
pub(crate) struct Lent<'a>(&'a mut Comm);

// SAFETY: see the type's documentation: one thread at a time, at a thread level that allows it.
unsafe impl Send for Lent<'_> {}

impl<'a> Lent<'a> {
    pub fn new(comm: &'a mut Comm) -> Self {
        Lent(comm)
    }

    pub fn get(&mut self) -> &mut Comm {
        self.0
    }
}

/// Raw point-to-point and reductions for the communication benchmark (counted like the rest).
impl Comm {
    pub fn send(&mut self, to: usize, buf: &[u8], tag: Tag) {
        self.counters.messages_sent += 1;
        self.counters.bytes_sent += buf.len() as u64;
        self.timed(|w| w.process_at_rank(to as i32).send_with_tag(buf, tag));
    }

    pub(crate) fn receive(&mut self, from: usize, buf: &mut [u8], tag: Tag) {
        self.timed(|w| {
            w.process_at_rank(from as i32)
                .receive_into_with_tag(buf, tag);
        });
    }

    /// Element-wise maximum over the ranks, on rank 0; `None` elsewhere.
    pub(crate) fn reduce_max_to_root(&mut self, mine: &[f64]) -> Option<Vec<f64>> {
        self.counters.collectives += 1;
        let root_rank = self.rank == 0;
        self.timed(|w| {
            let root = w.process_at_rank(0);
            if root_rank {
                let mut out = vec![0.0; mine.len()];
                root.reduce_into_root(mine, &mut out[..], SystemOperation::max());
                Some(out)
            } else {
                root.reduce_into(mine, SystemOperation::max());
                None
            }
        })
    }
}
