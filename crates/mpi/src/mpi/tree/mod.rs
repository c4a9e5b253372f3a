//! Distributed Barnes-Hut: each rank owns the bodies of its spatial domain and builds the octree
//! of its own bodies. Two ways of getting the other ranks' forces:
//!
//! - [`octants`] (`--decomp octants`), the gravity source's scheme: domains from the octants of
//!   the root cube, the top nodes of every tree shared with an Allgather, each body walking the
//!   other ranks' top nodes and, where a node must be opened, sent to its owner, who walks its
//!   whole tree for it and sends the force back (two all-to-all rounds);
//! - [`essential`] (`--decomp tree`): a cost-weighted orthogonal recursive bisection, and each
//!   rank sending each other rank its locally essential tree, the nodes and bodies that rank's
//!   domain needs under the opening test (one all-to-all round), then one tree walk over the
//!   owned bodies and everything imported; the domains move when the load drifts.
//!
//! What both share is here: the owned bodies and their integration, the status every rank
//! shares each step (errors, counts, last step's cost), and migration to new owners.

mod essential;
mod octants;

pub(crate) use essential::EssentialTree;
pub(crate) use octants::OctantTree;

use super::communicator::Comm;
use super::driver::Tally;
use super::error::MpiError;
use crate::boundary::{Boundary, BoundaryError};
use crate::decomp::orb::sample_weights;
use crate::decomp::stats::MinMeanMax;
use crate::decomp::wire::{bytes_of, bytes_of_mut, pack_particle, unpack_particles};
use crate::integrator::{kick, kick_drift};
use crate::kernels::{ForceReport, KernelParams, Octree};
use crate::physics::PairLaw;
use crate::real::Real;
use crate::scenario::System;
use crate::state::{Field, State, zero_field};

/// Fewest steps between two rebalancings of the tree decomposition.
const REBALANCE_GAP: u64 = 10;

/// Most bodies a rank puts into the sample a new bisection is cut on.
const SAMPLE_PER_RANK: u64 = 2048;

/// What every rank tells every other at the start of a step.
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct Status {
    pub failed: bool,
    pub bodies: u64,
    /// Force nanoseconds and interactions of the previous step.
    pub(crate) force_ns: u64,
    pub interactions: u64,
}

const STATUS_VALUES: usize = 4;

/// Max over mean of the ranks' force time of the previous step (1 when nothing was timed).
pub(super) fn imbalance(all: &[Status]) -> f64 {
    MinMeanMax::of(all.iter().map(|s| s.force_ns as f64)).imbalance()
}

/// A rank's bodies, their forces, the integrator's parameters and the octree of its bodies.
pub(super) struct Local<T: Real, L, const D: usize> {
    pub law: L,
    pub owned: State<T, D>,
    pub forces: Field<T, D>,
    /// The tree of the owned bodies alone.
    pub tree: Octree<L, T, D>,
    boundary: Boundary<T, D>,
    external: [T; D],
    dt: T,
    pub(crate) tally: Tally,
    /// This rank's force time and interactions in the last step, for the next status.
    pub(crate) last_force_ns: u64,
    pub(crate) last_interactions: u64,
    /// Each owned body's interaction count in the last force computation, when the driver
    /// records them (empty otherwise, and after migration until the next computation).
    pub costs: Vec<u32>,
}

impl<T: Real, L: PairLaw<T>, const D: usize> Local<T, L, D> {
    /// The bodies of `system` (built identically on every rank) for which `mine` holds, and
    /// an octree with the run's parameters.
    pub fn new(
        system: &System<T, L, D>,
        params: &KernelParams,
        mine: impl Fn(usize) -> bool,
    ) -> Self {
        let s = &system.state;
        let keep: Vec<bool> = (0..s.len()).map(mine).collect();
        let mut owned = s.clone();
        owned.retain(&keep);
        Local {
            law: system.law,
            forces: zero_field(owned.len()),
            owned,
            tree: new_tree(system.law, params),
            boundary: system.boundary,
            external: system.external,
            dt: system.dt,
            tally: Tally::default(),
            last_force_ns: 0,
            last_interactions: 0,
            costs: Vec::new(),
        }
    }

    /// Half kick, drift and the walls; the wall error, if any, to be shared with every rank.
    pub(crate) fn first_half(&mut self, step: u64) -> Option<BoundaryError> {
        let half = self.dt * T::of(0.5);
        kick_drift(&mut self.owned, &self.forces, self.external, half, self.dt);
        self.boundary.apply(&mut self.owned, step).err()
    }

    pub(crate) fn second_half(&mut self) {
        let half = self.dt * T::of(0.5);
        kick(&mut self.owned, &self.forces, self.external, half);
    }

    /// Every rank's status (one small Allgather); an error anywhere stops every rank here.
    pub(crate) fn share_status(
        &mut self,
        comm: &mut Comm,
        error: Option<BoundaryError>,
        step: u64,
    ) -> Result<Vec<Status>, MpiError> {
        let mine = [
            i64::from(error.is_some()),
            self.owned.len() as i64,
            self.last_force_ns as i64,
            self.last_interactions as i64,
        ];
        let all = comm.all_gather_i64(&mine);
        if let Some(error) = error {
            return Err(MpiError::Boundary {
                rank: comm.rank(),
                error,
            });
        }
        let all: Vec<Status> = all
            .chunks_exact(STATUS_VALUES)
            .map(|v| Status {
                failed: v[0] != 0,
                bodies: v[1] as u64,
                force_ns: v[2] as u64,
                interactions: v[3] as u64,
            })
            .collect();
        if let Some(rank) = all.iter().position(|s| s.failed) {
            return Err(MpiError::Peer { rank, step });
        }
        Ok(all)
    }

    /// Sends every owned body whose owner is another rank to it (an all-to-all, as bodies may
    /// move to any rank) and takes in those sent here.
    pub(crate) fn send_to_owners(
        &mut self,
        comm: &mut Comm,
        owner: impl Fn([f64; D]) -> usize,
    ) -> Result<(), MpiError> {
        let me = comm.rank();
        let mut to_rank: Vec<Vec<f64>> = vec![Vec::new(); comm.size()];
        let mut keep = vec![true; self.owned.len()];
        let mut leaving = 0;
        for (i, kept) in keep.iter_mut().enumerate() {
            let r = owner(self.owned.position(i).map(|x| x.as_f64()));
            if r != me {
                pack_particle(&self.owned, i, &mut to_rank[r]);
                *kept = false;
                leaving += 1;
            }
        }
        let bytes: Vec<Vec<u8>> = to_rank.iter().map(|p| bytes_of(p).to_vec()).collect();
        let arrived = comm.all_to_all(&bytes)?;
        if leaving > 0 {
            self.owned.retain(&keep);
        }
        if leaving > 0 || arrived.iter().any(|b| !b.is_empty()) {
            // The costs were per body of the old set.
            self.costs.clear();
        }
        for b in &arrived {
            unpack_particles(b, &mut self.owned);
        }
        if self.forces[0].len() != self.owned.len() {
            self.forces = zero_field(self.owned.len());
        }
        self.tally.migrated_out += leaving;
        Ok(())
    }

    /// Adds one force computation to the tally and keeps its cost for the next status.
    pub fn record(&mut self, report: &ForceReport, build_s: f64, force_s: f64, imported: u64) {
        self.tally.work += report.work;
        self.tally.build_s += build_s + report.build_s;
        self.tally.force_s += force_s;
        self.tally.ghosts_received += imported;
        self.last_force_ns = (force_s * 1e9) as u64;
        self.last_interactions = report.work.pair_checks;
    }

    /// A sample of every rank's bodies for a new bisection (every k-th body, at most
    /// [`SAMPLE_PER_RANK`] per rank, so that a rebalancing moves O(p) values, not O(n)), in
    /// rank order, and each sampled body's weight: the interaction counts of the k bodies it
    /// stands for in the previous step (`decomp::orb::sample_weights`), or, where a rank has
    /// no per-body counts, its interactions per body times k.
    pub(crate) fn gather_sample(
        &mut self,
        comm: &mut Comm,
        all: &[Status],
    ) -> Result<([Vec<f64>; D], Vec<f64>), MpiError> {
        let stride = |bodies: u64| bodies.div_ceil(SAMPLE_PER_RANK).max(1);
        let me = comm.rank();
        let n = self.owned.len();
        let k = stride(n as u64) as usize;
        let costs = (self.costs.len() == n).then_some(&self.costs[..]);
        let per_body = match all[me] {
            s if s.bodies > 0 && s.interactions > 0 => s.interactions as f64 / s.bodies as f64,
            _ => 1.0,
        };
        let weights = sample_weights(n, k, costs, per_body);
        // Per sampled body: its position, then its weight.
        let mut mine = Vec::with_capacity(weights.len() * (D + 1));
        for (i, w) in (0..n).step_by(k).zip(&weights) {
            mine.extend(self.owned.position(i).map(|x| x.as_f64()));
            mine.push(*w);
        }
        let samples: Vec<u64> = all
            .iter()
            .map(|s| s.bodies.div_ceil(stride(s.bodies)))
            .collect();
        let bytes: Vec<usize> = samples.iter().map(|&c| c as usize * (D + 1) * 8).collect();
        let mut flat = vec![0.0f64; samples.iter().sum::<u64>() as usize * (D + 1)];
        comm.allgatherv(bytes_of(&mine), &bytes, bytes_of_mut(&mut flat))?;
        let pos = std::array::from_fn(|d| flat.iter().skip(d).step_by(D + 1).copied().collect());
        let weights = flat.iter().skip(D).step_by(D + 1).copied().collect();
        Ok((pos, weights))
    }
}

/// The octree of the run's parameters (already validated by `KernelKind::build`).
pub(super) fn new_tree<T: Real, L: PairLaw<T>, const D: usize>(
    law: L,
    params: &KernelParams,
) -> Octree<L, T, D> {
    Octree::with_multipole(law, params.theta, params.leaf_size, params.multipole)
}
