//! Replicated data (the MPI driver of the LJ-box assignment, the program of the Coulomb MPI tutorial): every rank holds
//! every particle's position; it owns a contiguous block of particles (sizes differing by at
//! most one), integrates them, and every step an Allgatherv shares the new positions.
//!
//! Forces: kernels that visit each target's own pairs (naive, cell list, octree, and the Verlet
//! list through full lists of the block's targets, kept between steps) compute the block's
//! targets against all particles. The symmetric kernels (symmetric, per-thread) would
//! lose Newton's third law that way, so each rank evaluates a balanced share of the pair tiles,
//! adding each force to both ends, and an Allreduce sums the shares (in f64).
//!
//! Each rank's Allgatherv block starts with a status value (0, or 1 after an error such as a
//! particle stuck outside a wall), so every rank learns of an error in the same step without
//! another collective.

use super::communicator::Comm;
use super::driver::{Driver, Tally};
use super::error::MpiError;
use crate::boundary::{Boundary, BoundaryError};
use crate::decomp::wire::{bytes_of, bytes_of_mut};
use crate::integrator::{kick, kick_drift};
use crate::kernels::{ForceKernel, KernelKind, Share};
use crate::real::Real;
use crate::scenario::System;
use crate::state::{Field, State, zero_field};
use std::ops::Range;
use std::time::Instant;

pub struct Allgather<T: Real, const D: usize> {
    kernel: Box<dyn ForceKernel<T, D>>,
    /// Each rank evaluates a share of the pairs and the forces are summed over the ranks.
    split_pairs: bool,
    share: Share,
    /// Every particle: positions replicated every step, strengths fixed.
    global: State<T, D>,
    /// This rank's slots of `global`.
    block: Range<usize>,
    /// Values (`T`) each rank contributes to the Allgatherv: status + positions.
    block_values: Vec<usize>,
    /// The owned particles (slots `block` of `global`) and their forces.
    local: State<T, D>,
    forces: Field<T, D>,
    /// Buffers: this rank's share of the pair forces and the sums, the Allgatherv message.
    pair_forces: Field<T, D>,
    sum_in: Vec<f64>,
    sum_out: Vec<f64>,
    send: Vec<T>,
    recv: Vec<T>,
    boundary: Boundary<T, D>,
    external: [T; D],
    dt: T,
    tally: Tally,
}

impl<T: Real, const D: usize> Allgather<T, D> {
    /// Takes this rank's block of `system` (built identically on every rank) and computes
    /// the initial forces.
    pub fn new<L>(
        system: System<T, L, D>,
        kind: KernelKind,
        mut kernel: Box<dyn ForceKernel<T, D>>,
        comm: &mut Comm,
    ) -> Result<Self, MpiError> {
        let mut global = system.state;
        // A spatial order makes each rank's block compact, which the cell list and the
        // octree turn into fewer cells and tree groups to visit.
        if let Some(order) = kernel.spatial_order(&global) {
            global.permute(&order, &mut []);
        }
        let n = global.len();
        let share = Share::new(comm.rank(), comm.size()).expect("rank < size");
        let block = share.block(n);
        let local = State {
            pos: std::array::from_fn(|d| global.pos[d][block.clone()].to_vec()),
            vel: std::array::from_fn(|d| global.vel[d][block.clone()].to_vec()),
            mass: global.mass[block.clone()].to_vec(),
            source: global.source[block.clone()].to_vec(),
            id: global.id[block.clone()].to_vec(),
        };
        let block_values: Vec<usize> = Share::blocks(n, comm.size())
            .iter()
            .map(|b| 1 + D * b.len())
            .collect();
        let split_pairs = matches!(kind, KernelKind::Symmetric | KernelKind::PerThread);
        let mut driver = Allgather {
            kernel,
            split_pairs,
            share,
            global,
            forces: zero_field(block.len()),
            block,
            recv: vec![T::zero(); block_values.iter().sum()],
            block_values,
            local,
            pair_forces: if split_pairs {
                zero_field(n)
            } else {
                zero_field(0)
            },
            sum_in: Vec::new(),
            sum_out: Vec::new(),
            send: Vec::new(),
            boundary: system.boundary,
            external: system.external,
            dt: system.dt,
            tally: Tally::default(),
        };
        driver.compute_forces(comm)?;
        Ok(driver)
    }

    /// Forces on the owned particles from the replicated positions.
    fn compute_forces(&mut self, comm: &mut Comm) -> Result<(), MpiError> {
        let t = Instant::now();
        if !self.split_pairs {
            let out = self.forces.each_mut().map(|f| f.as_mut_slice());
            let report = self
                .kernel
                .compute_targets(&self.global, self.block.clone(), out);
            self.tally.work += report.work;
            self.tally.build_s += report.build_s;
            self.tally.force_s += t.elapsed().as_secs_f64();
            return Ok(());
        }
        let n = self.global.len();
        let report = self
            .kernel
            .compute_share(&self.global, self.share, &mut self.pair_forces);
        self.tally.work += report.work;
        self.tally.build_s += report.build_s;
        self.sum_in.clear();
        for f in &self.pair_forces {
            self.sum_in.extend(f.iter().map(|x| x.as_f64()));
        }
        self.sum_out.resize(self.sum_in.len(), 0.0);
        self.tally.force_s += t.elapsed().as_secs_f64();
        comm.all_reduce_sum_f64(&self.sum_in, &mut self.sum_out);
        let t = Instant::now();
        for d in 0..D {
            let sums = &self.sum_out[d * n + self.block.start..d * n + self.block.end];
            for (f, &s) in self.forces[d].iter_mut().zip(sums) {
                *f = T::of(s);
            }
        }
        self.tally.force_s += t.elapsed().as_secs_f64();
        Ok(())
    }

    /// Shares the owned positions (after a status value) with every rank and copies every
    /// rank's into `global`; stops on any rank's error.
    fn share_positions(
        &mut self,
        comm: &mut Comm,
        error: Option<BoundaryError>,
        step: u64,
    ) -> Result<(), MpiError> {
        self.send.clear();
        self.send
            .push(T::of(if error.is_some() { 1.0 } else { 0.0 }));
        for i in 0..self.local.len() {
            for d in 0..D {
                self.send.push(self.local.pos[d][i]);
            }
        }
        let size = std::mem::size_of::<T>();
        let counts: Vec<usize> = self.block_values.iter().map(|&v| v * size).collect();
        comm.allgatherv(bytes_of(&self.send), &counts, bytes_of_mut(&mut self.recv))?;
        if let Some(error) = error {
            return Err(MpiError::Boundary {
                rank: comm.rank(),
                error,
            });
        }
        let blocks = Share::blocks(self.global.len(), comm.size());
        let mut at = 0;
        for (rank, b) in blocks.iter().enumerate() {
            if self.recv[at] != T::zero() {
                return Err(MpiError::Peer { rank, step });
            }
            at += 1;
            for i in b.clone() {
                for d in 0..D {
                    self.global.pos[d][i] = self.recv[at];
                    at += 1;
                }
            }
        }
        Ok(())
    }
}

impl<T: Real, const D: usize> Driver<T, D> for Allgather<T, D> {
    fn step(&mut self, comm: &mut Comm, step: u64) -> Result<(), MpiError> {
        let half = self.dt * T::of(0.5);
        kick_drift(&mut self.local, &self.forces, self.external, half, self.dt);
        let error = self.boundary.apply(&mut self.local, step).err();
        self.share_positions(comm, error, step)?;
        self.compute_forces(comm)?;
        kick(&mut self.local, &self.forces, self.external, half);
        Ok(())
    }

    fn owned(&self) -> (&State<T, D>, &Field<T, D>) {
        (&self.local, &self.forces)
    }

    fn tally(&self) -> &Tally {
        &self.tally
    }

    fn reset_tally(&mut self) {
        self.tally = Tally::default();
    }
}
