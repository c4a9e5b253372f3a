//! `--decomp octants`: the gravity source's distributed Barnes-Hut, as it describes it.
//!
//! The domains are the octants of the root cube (`decomp::octants`: one level-k cell per rank
//! for 8^k ranks, 4^k in 2-D; other counts get balanced runs of finer Morton cells), fixed at
//! the start: this scheme does not rebalance, which is where its load imbalance comes from.
//! A step: kick, drift, walls; the status Allgather; bodies that left their domain go to its
//! owner (all-to-all); the octree of the owned bodies gives their own forces; every rank's top
//! nodes ([`TOP_LEVELS`] levels of its tree) go to every rank in an Allgatherv; each group of
//! owned bodies (the octree's target groups) walks every other rank's top nodes with the
//! opening test against its bounding box (`decomp::top_nodes`), and takes their monopoles
//! where every branch was accepted, or else is sent to that rank; the owners walk their whole
//! trees for the groups they were sent (accepted nodes as monopoles) and send the forces back:
//! two more all-to-all rounds.

use super::Local;
use crate::decomp::Domains;
use crate::decomp::octants::{Octants, root_cube};
use crate::decomp::top_nodes::{TopNodes, TopWalk, group_forces};
use crate::decomp::wire::{bytes_of, floats_of};
use crate::geometry::Bounds;
use crate::kernels::{ForceKernel, ForceReport, KernelParams, WorkCounters};
use crate::mpi::communicator::Comm;
use crate::mpi::driver::{Driver, Tally};
use crate::mpi::error::MpiError;
use crate::physics::PairLaw;
use crate::real::Real;
use crate::scenario::System;
use crate::state::{Field, State};
use rayon::prelude::*;
use std::time::Instant;

/// Levels of each rank's tree shared as its top nodes (at most 1 + 8 + 64 + 512 nodes in 3-D).
pub const TOP_LEVELS: u32 = 3;

pub(crate) struct OctantTree<T: Real, L, const D: usize> {
    local: Local<T, L, D>,
    octants: Octants<D>,
}

impl<T: Real, L: PairLaw<T>, const D: usize> OctantTree<T, L, D> {
    /// Cuts the root cube of `system` (built identically on every rank), takes this rank's
    /// bodies and computes their first forces.
    pub fn new(
        system: System<T, L, D>,
        params: &KernelParams,
        comm: &mut Comm,
    ) -> Result<Self, MpiError> {
        let pos = &system.state.pos;
        let (lo, side) = root_cube(pos);
        let octants = Octants::new(lo, side, comm.size(), pos)?;
        let owners = octants.assign(pos);
        let me = comm.rank();
        let local = Local::new(&system, params, |i| owners[i] == me);
        let mut driver = OctantTree { local, octants };
        driver.compute_forces(comm)?;
        Ok(driver)
    }

    /// The forces on the owned bodies: their own tree, then every other rank's top nodes
    /// (taken as monopoles or asking that rank), then the forces other ranks asked of this
    /// rank's tree and the answers to this rank's own requests. Only the computation between
    /// the exchanges counts as force time.
    fn compute_forces(&mut self, comm: &mut Comm) -> Result<(), MpiError> {
        let started = Instant::now();
        let (me, size) = (comm.rank(), comm.size());
        let local = &mut self.local;
        let n = local.owned.len();
        let mut report = ForceReport::default();
        let top = if n > 0 {
            report = local.tree.compute(&local.owned, &mut local.forces, false);
            TopNodes::of(&local.tree.view(), TOP_LEVELS)
        } else {
            TopNodes::default()
        };
        let mine = top.encode();
        let mut force_s = started.elapsed().as_secs_f64();

        let (counts, all) = share_top_nodes(comm, &mine)?;
        let started = Instant::now();
        let tops = decode_top_nodes::<T, D>(&counts, &all)?;
        let requests = walk_top_nodes(local, &tops, me, size);
        force_s += started.elapsed().as_secs_f64();

        let send: Vec<Vec<u8>> = requests
            .bodies
            .iter()
            .map(|v| bytes_of(v).to_vec())
            .collect();
        let received = comm.all_to_all(&send)?;
        let started = Instant::now();
        let answers = answer_requests(local, &received)?;
        force_s += started.elapsed().as_secs_f64();

        let answered = comm.all_to_all(&answers.replies)?;
        let started = Instant::now();
        add_answers(&mut local.forces, &answered, &requests.asked);
        force_s += started.elapsed().as_secs_f64();
        report.work += WorkCounters {
            pair_checks: requests.accepted + answers.interactions,
            ..Default::default()
        };
        local.record(&report, 0.0, force_s, answers.bodies);
        Ok(())
    }
}

/// Shares this rank's encoded top nodes with every rank (Allgatherv, after an Allgather of
/// the sizes); returns each rank's byte count and all of their bytes, in rank order.
fn share_top_nodes<T: Real>(
    comm: &mut Comm,
    mine: &[T],
) -> Result<(Vec<usize>, Vec<u8>), MpiError> {
    let sizes = comm.all_gather_i64(&[std::mem::size_of_val(mine) as i64]);
    let counts: Vec<usize> = sizes.iter().map(|&b| b as usize).collect();
    let mut all = vec![0u8; counts.iter().sum()];
    comm.allgatherv(bytes_of(mine), &counts, &mut all)?;
    Ok((counts, all))
}

/// Every rank's top nodes from the bytes [`share_top_nodes`] gathered.
fn decode_top_nodes<T: Real, const D: usize>(
    counts: &[usize],
    all: &[u8],
) -> Result<Vec<TopNodes<T, D>>, MpiError> {
    let mut tops = Vec::with_capacity(counts.len());
    let mut at = 0;
    for (r, &c) in counts.iter().enumerate() {
        let values = floats_of::<T>(&all[at..at + c]);
        at += c;
        let nodes = TopNodes::decode(&values).ok_or_else(|| {
            MpiError::Serialize(format!("rank {r} sent top nodes that do not decode"))
        })?;
        tops.push(nodes);
    }
    Ok(tops)
}

/// What the walk of the other ranks' top nodes leaves to ask of them.
struct Requests<T> {
    /// Per rank, the groups of bodies sent to it (each a count, then position and strength
    /// per body).
    bodies: Vec<Vec<T>>,
    /// Per rank, the original index of each body sent to it, in the order sent.
    asked: Vec<Vec<usize>>,
    /// Body-node interactions taken from accepted top nodes.
    accepted: u64,
}

/// Each group of owned bodies against every other rank's top nodes: where every branch is
/// accepted their monopoles are added to the forces, else the group is put in a request to
/// that rank.
fn walk_top_nodes<T: Real, L: PairLaw<T>, const D: usize>(
    local: &mut Local<T, L, D>,
    tops: &[TopNodes<T, D>],
    me: usize,
    size: usize,
) -> Requests<T> {
    let law = local.law;
    let mut requests: Vec<Vec<T>> = vec![Vec::new(); size];
    let mut asked: Vec<Vec<usize>> = vec![Vec::new(); size];
    let mut accepted = 0u64;
    if !local.owned.is_empty() {
        let view = local.tree.view();
        let forces = &mut local.forces;
        for group in view.groups() {
            let points: Vec<[T; D]> = group.clone().map(|k| view.position(k)).collect();
            let Bounds { lo, hi } = Bounds::of_points(points.iter().copied());
            for (r, top) in tops.iter().enumerate() {
                if r == me || top.is_empty() {
                    continue;
                }
                match top.walk(&lo, &hi) {
                    TopWalk::Accepted(nodes) => {
                        for (k, &x) in group.clone().zip(&points) {
                            let i = view.original_index(k);
                            let f = top.force(&law, &nodes, x, view.source(k));
                            for d in 0..D {
                                forces[d][i] += f[d];
                            }
                        }
                        accepted += (nodes.len() * points.len()) as u64;
                    }
                    TopWalk::Open => {
                        requests[r].push(T::of(points.len() as f64));
                        for (k, x) in group.clone().zip(&points) {
                            requests[r].extend_from_slice(x);
                            requests[r].push(view.source(k));
                            asked[r].push(view.original_index(k));
                        }
                    }
                }
            }
        }
    }
    Requests {
        bodies: requests,
        asked,
        accepted,
    }
}

/// This rank's answers to the groups other ranks sent it.
struct Answers {
    /// Per rank, the forces on the bodies it sent, in its order.
    replies: Vec<Vec<u8>>,
    /// Interactions of the walks for them.
    interactions: u64,
    /// Bodies asked for.
    bodies: u64,
}

/// The groups others sent here: this rank's whole tree, walked for each group's box (zero
/// forces when this rank owns no bodies).
fn answer_requests<T: Real, L: PairLaw<T>, const D: usize>(
    local: &Local<T, L, D>,
    received: &[Vec<u8>],
) -> Result<Answers, MpiError> {
    let (n, law) = (local.owned.len(), local.law);
    let view = local.tree.view();
    let mut remote = 0u64;
    let mut requested = 0u64;
    let mut replies: Vec<Vec<u8>> = Vec::with_capacity(received.len());
    for (r, bytes) in received.iter().enumerate() {
        let groups = split_groups::<T, D>(&floats_of::<T>(bytes)).ok_or_else(|| {
            MpiError::Serialize(format!("rank {r} sent bodies that do not decode"))
        })?;
        let answers: Vec<(Vec<[T; D]>, u64)> = groups
            .par_iter()
            .map(|g| {
                if n == 0 {
                    (vec![[T::zero(); D]; g.len()], 0)
                } else {
                    group_forces(&view, &law, g)
                }
            })
            .collect();
        remote += answers.iter().map(|a| a.1).sum::<u64>();
        requested += groups.iter().map(|g| g.len() as u64).sum::<u64>();
        let flat: Vec<T> = answers
            .iter()
            .flat_map(|a| a.0.iter().flatten().copied())
            .collect();
        replies.push(bytes_of(&flat).to_vec());
    }
    Ok(Answers {
        replies,
        interactions: remote,
        bodies: requested,
    })
}

/// Adds the forces other ranks answered to the bodies this rank asked them about.
fn add_answers<T: Real, const D: usize>(
    forces: &mut Field<T, D>,
    answered: &[Vec<u8>],
    asked: &[Vec<usize>],
) {
    for (r, bytes) in answered.iter().enumerate() {
        let values = floats_of::<T>(bytes);
        for (k, f) in values.chunks_exact(D).enumerate() {
            let i = asked[r][k];
            for d in 0..D {
                forces[d][i] += f[d];
            }
        }
    }
}

/// A group of bodies sent for their forces: position and strength each.
type Group<T, const D: usize> = Vec<([T; D], T)>;

/// The groups of a request message: each a count, then that many bodies (position and
/// strength); `None` if the values do not split that way.
fn split_groups<T: Real, const D: usize>(values: &[T]) -> Option<Vec<Group<T, D>>> {
    let mut groups = Vec::new();
    let mut at = 0;
    while at < values.len() {
        let count = values[at].as_f64();
        if !(count >= 1.0 && count.fract() == 0.0) {
            return None;
        }
        let end = at + 1 + count as usize * (D + 1);
        let body = values.get(at + 1..end)?;
        groups.push(
            body.chunks_exact(D + 1)
                .map(|b| (std::array::from_fn(|d| b[d]), b[D]))
                .collect(),
        );
        at = end;
    }
    Some(groups)
}

impl<T: Real, L: PairLaw<T>, const D: usize> Driver<T, D> for OctantTree<T, L, D> {
    fn step(&mut self, comm: &mut Comm, step: u64) -> Result<(), MpiError> {
        let error = self.local.first_half(step);
        self.local.share_status(comm, error, step)?;
        let octants = &self.octants;
        self.local.send_to_owners(comm, |x| octants.owner(x))?;
        self.compute_forces(comm)?;
        self.local.second_half();
        Ok(())
    }

    fn owned(&self) -> (&State<T, D>, &Field<T, D>) {
        (&self.local.owned, &self.local.forces)
    }

    fn tally(&self) -> &Tally {
        &self.local.tally
    }

    fn reset_tally(&mut self) {
        self.local.tally = Tally::default();
    }
}
