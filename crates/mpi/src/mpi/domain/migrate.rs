//! Particles changing owner: after each drift (to the neighbours, or through an all-to-all when
//! a particle moved beyond them in one step), and when rebalancing moves the boundaries.

use super::{BINS_PER_REGION, Domain};
use crate::boundary::BoundaryError;
use crate::decomp::wire::{bytes_of, pack_particle, unpack_particles};
use crate::mpi::communicator::Comm;
use crate::mpi::driver::TAG_MIGRATE;
use crate::mpi::error::MpiError;
use crate::real::Real;
use crate::state::zero_field;

/// Values of the per-step status every rank shares: error flag, far migrants, owned count.
const STATUS: usize = 3;

impl<T: Real, const D: usize> Domain<T, D> {
    /// Sends the particles that left this rank's region to their new owners and takes in
    /// those that entered it. Every rank shares its status first, so that an error anywhere
    /// stops every rank in this step. Returns every rank's particle count before migrating.
    pub(super) fn migrate(
        &mut self,
        comm: &mut Comm,
        error: Option<BoundaryError>,
        step: u64,
    ) -> Result<Vec<i64>, MpiError> {
        let (lo, hi) = self.regions.region(self.me);
        let mut to_neighbour: Vec<Vec<f64>> = vec![Vec::new(); self.neighbours.len()];
        let mut to_rank: Vec<Vec<f64>> = vec![Vec::new(); comm.size()];
        let mut leaving = Vec::new();
        let mut far = 0;
        for i in 0..self.owned.len() {
            let x = self.owned.position(i).map(|v| v.as_f64());
            // Strictly inside: still ours, without a search.
            if (0..D).all(|d| x[d] > lo[d] && x[d] < hi[d]) {
                continue;
            }
            let owner = self.regions.owner(x);
            if owner == self.me {
                continue;
            }
            leaving.push(i);
            match self.neighbours.iter().position(|&r| r == owner) {
                Some(k) => pack_particle(&self.owned, i, &mut to_neighbour[k]),
                None => {
                    pack_particle(&self.owned, i, &mut to_rank[owner]);
                    far += 1;
                }
            }
        }
        let status = [
            i64::from(error.is_some()),
            far as i64,
            self.owned.len() as i64,
        ];
        let all = comm.all_gather_i64(&status);
        if let Some(error) = error {
            return Err(MpiError::Boundary {
                rank: self.me,
                error,
            });
        }
        if let Some(rank) = (0..comm.size()).find(|&r| all[r * STATUS] != 0) {
            return Err(MpiError::Peer { rank, step });
        }
        let bytes: Vec<Vec<u8>> = to_neighbour.iter().map(|p| bytes_of(p).to_vec()).collect();
        let mut arrived = comm.exchange(&self.neighbours, &bytes, TAG_MIGRATE)?;
        if (0..comm.size()).any(|r| all[r * STATUS + 1] > 0) {
            let bytes: Vec<Vec<u8>> = to_rank.iter().map(|p| bytes_of(p).to_vec()).collect();
            arrived.extend(comm.all_to_all(&bytes)?);
        }
        self.tally.migrated_out += leaving.len() as u64;
        self.tally.far_migrated += far as u64;
        self.replace(&leaving, &arrived);
        Ok((0..comm.size()).map(|r| all[r * STATUS + 2]).collect())
    }

    /// Moves the boundaries so that every rank owns about as many particles, then sends each
    /// particle to its new owner (an all-to-all: particles may move several regions).
    pub(super) fn rebalance(&mut self, comm: &mut Comm) -> Result<(), MpiError> {
        let dims = self.regions.dims();
        for axis in 0..D {
            let owned = &self.owned;
            let positions = (0..owned.len()).map(|i| owned.position(i).map(|x| x.as_f64()));
            let local = self
                .regions
                .histogram(axis, BINS_PER_REGION * dims[axis], positions);
            let global = comm.all_reduce_sum_u64(&local);
            self.regions.cut_axis(axis, &global);
        }
        self.neighbours = self.regions.neighbours(self.me, self.width);
        let mut to_rank: Vec<Vec<f64>> = vec![Vec::new(); comm.size()];
        let mut leaving = Vec::new();
        for i in 0..self.owned.len() {
            let owner = self
                .regions
                .owner(self.owned.position(i).map(|x| x.as_f64()));
            if owner != self.me {
                pack_particle(&self.owned, i, &mut to_rank[owner]);
                leaving.push(i);
            }
        }
        let bytes: Vec<Vec<u8>> = to_rank.iter().map(|p| bytes_of(p).to_vec()).collect();
        let arrived = comm.all_to_all(&bytes)?;
        self.tally.migrated_out += leaving.len() as u64;
        self.replace(&leaving, &arrived);
        self.rebalances += 1;
        Ok(())
    }

    /// Removes the owned particles at the (increasing) slots `leaving` and appends the packed
    /// particles of `arrived`; the forces are recomputed next, so they are only resized.
    fn replace(&mut self, leaving: &[usize], arrived: &[Vec<u8>]) {
        if !leaving.is_empty() {
            let mut keep = vec![true; self.owned.len()];
            for &i in leaving {
                keep[i] = false;
            }
            self.owned.retain(&keep);
        }
        for bytes in arrived {
            unpack_particles(bytes, &mut self.owned);
        }
        if self.forces[0].len() != self.owned.len() {
            self.forces = zero_field(self.owned.len());
        }
    }
}
