//! `--decomp tree`: locally essential trees over a cost-weighted orthogonal recursive bisection.
//!
//! A step: kick, drift, walls; the status Allgather; when the force times of the previous step
//! are too uneven (max/mean above `--rebalance-above`, at most every [`REBALANCE_GAP`] steps)
//! a new bisection of a sample of the bodies, each weighing the interactions of the bodies it
//! stands for in the previous step; every body whose position left its rank's domain goes to
//! its owner (all-to-all); then
//! the octree of the owned bodies, and for every other rank the essential set of that tree
//! against the rank's domain (`decomp::essential::select`), its entries sent in one
//! all-to-all; finally one octree over the owned bodies and every imported entry, walked for the
//! owned bodies only.
//!
//! Imported entries are points with a strength (D + 1 values each): a node the sender's test
//! accepted acts as a monopole at both expansion orders; the receiver's own tree groups it with
//! its neighbours as it would any body. Because every exported node passes the opening test
//! from every point of the receiver's domain, the receiver never needs what lies below it.
//!
//! The bisection's outer faces are open to infinity for the selection (`open_at_walls`), so a
//! body that leaves the first bounding box is still covered by what its owner imports.

use super::{Local, REBALANCE_GAP, Status, imbalance, new_tree};
use crate::decomp::Aabb;
use crate::decomp::Domains;
use crate::decomp::essential::{open_at_walls, select};
use crate::decomp::orb::{Orb, root_box};
use crate::decomp::wire::{bytes_of, unpack_sources};
use crate::kernels::{ForceKernel, KernelParams, Octree};
use crate::mpi::communicator::Comm;
use crate::mpi::driver::{Driver, Tally};
use crate::mpi::error::MpiError;
use crate::physics::PairLaw;
use crate::real::Real;
use crate::scenario::System;
use crate::state::{Field, State};
use std::time::Instant;

pub(crate) struct EssentialTree<T: Real, L, const D: usize> {
    local: Local<T, L, D>,
    orb: Orb<D>,
    /// The box the bisection cut; faces on it are open in the selection.
    root: Aabb<D>,
    /// The owned bodies followed by the imported entries, and the tree over them all.
    combined: State<T, D>,
    combined_tree: Octree<L, T, D>,
    rebalance_above: Option<f64>,
    rebalances: u64,
    last_rebalance: u64,
}

impl<T: Real, L: PairLaw<T>, const D: usize> EssentialTree<T, L, D> {
    /// Bisects `system`'s bodies (built identically on every rank) with unit weights, takes
    /// this rank's and computes their first forces.
    pub fn new(
        system: System<T, L, D>,
        params: &KernelParams,
        rebalance_above: Option<f64>,
        comm: &mut Comm,
    ) -> Result<Self, MpiError> {
        let pos = &system.state.pos;
        let ones = vec![1.0; system.state.len()];
        let orb = Orb::over(comm.size(), pos, &ones)?;
        let root = root_box(pos);
        let owners = orb.assign(pos);
        let me = comm.rank();
        let local = Local::new(&system, params, |i| owners[i] == me);
        let mut combined_tree = new_tree(system.law, params);
        combined_tree.record_target_costs();
        let mut driver = EssentialTree {
            local,
            orb,
            root,
            combined: State::new(0),
            combined_tree,
            rebalance_above,
            rebalances: 0,
            last_rebalance: 0,
        };
        driver.compute_forces(comm)?;
        Ok(driver)
    }

    /// A new bisection of a sample of every rank's bodies, weighted by the interactions each
    /// body had in the previous step (`Local::gather_sample`).
    fn rebalance(&mut self, comm: &mut Comm, all: &[Status]) -> Result<(), MpiError> {
        let (pos, weights) = self.local.gather_sample(comm, all)?;
        self.orb = Orb::over(comm.size(), &pos, &weights)?;
        self.root = root_box(&pos);
        self.rebalances += 1;
        Ok(())
    }

    /// The owned bodies' forces: export the essential sets, import the others', one walk.
    fn compute_forces(&mut self, comm: &mut Comm) -> Result<(), MpiError> {
        let started = Instant::now();
        let (me, size) = (comm.rank(), comm.size());
        let local = &mut self.local;
        let mut send: Vec<Vec<u8>> = vec![Vec::new(); size];
        let mut build_s = 0.0;
        if !local.owned.is_empty() {
            let b = Instant::now();
            local.tree.build(&local.owned);
            build_s += b.elapsed().as_secs_f64();
            let view = local.tree.view();
            for (r, out) in send.iter_mut().enumerate().filter(|&(r, _)| r != me) {
                let domain = open_at_walls(&self.orb.boxes(r), &self.root);
                let payload = select(&view, &domain).payload(&view);
                let mut values = Vec::with_capacity(payload.strength.len() * (D + 1));
                for (k, &s) in payload.strength.iter().enumerate() {
                    values.extend((0..D).map(|d| payload.pos[d][k]));
                    values.push(s);
                }
                *out = bytes_of(&values).to_vec();
            }
        }
        let mut force_s = started.elapsed().as_secs_f64();
        let received = comm.all_to_all(&send)?;
        let started = Instant::now();
        let n = local.owned.len();
        let combined = &mut self.combined;
        *combined = local.owned.clone();
        let mut imported = 0;
        for bytes in received
            .iter()
            .enumerate()
            .filter(|&(r, _)| r != me)
            .map(|(_, b)| b)
        {
            imported += unpack_sources(bytes, combined) as u64;
        }
        let mut report = Default::default();
        local.costs.clear();
        if n > 0 {
            let out = local.forces.each_mut().map(|f| f.as_mut_slice());
            report = self.combined_tree.compute_targets(combined, 0..n, out);
            if let Some(costs) = self.combined_tree.target_costs() {
                local.costs.extend_from_slice(costs);
            }
        }
        force_s += started.elapsed().as_secs_f64();
        local.record(&report, build_s, force_s, imported);
        Ok(())
    }
}

impl<T: Real, L: PairLaw<T>, const D: usize> Driver<T, D> for EssentialTree<T, L, D> {
    fn step(&mut self, comm: &mut Comm, step: u64) -> Result<(), MpiError> {
        let error = self.local.first_half(step);
        let all = self.local.share_status(comm, error, step)?;
        let due = step >= self.last_rebalance + REBALANCE_GAP
            && self
                .rebalance_above
                .is_some_and(|above| imbalance(&all) > above);
        if due {
            self.rebalance(comm, &all)?;
            self.last_rebalance = step;
        }
        let orb = &self.orb;
        self.local.send_to_owners(comm, |x| orb.owner(x))?;
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

    fn rebalances(&self) -> u64 {
        self.rebalances
    }
}
