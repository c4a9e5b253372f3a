//! Spatial decomposition for the short-range kernels, the cell list and the Verlet list
//! (the LJ-box assignment's second task): each rank owns a region of the box ([`Regions`]) and the
//! particles in it.
//!
//! A step: kick, drift and walls on the owned particles; a status exchange (one small
//! Allgather: errors, far migrants, particle counts); particles that left the region go to its
//! owner — the neighbours directly, any rank further away through one all-to-all; when the
//! busiest rank owns too many more particles than the mean, the boundaries move
//! ([`migrate`]); then the forces ([`forces`]): the particles within the cutoff of a
//! neighbour's region are sent to it as ghosts with nonblocking messages while the forces from
//! the owned particles are computed, and once the ghosts are in, the few particles near a
//! border get their forces again with the ghosts.
//!
//! A Verlet list over the owned particles re-sorts them at its rebuilds (it asks for an order
//! every step, [`ForceKernel::sort_every`]) and is rebuilt in every step that changed the
//! number of particles a rank owns (a particle migrated in or out); its slot test keeps it
//! exact whatever the migration did to the slots.

mod forces;
mod migrate;

use super::communicator::Comm;
use super::driver::{Driver, Tally};
use super::error::MpiError;
use crate::boundary::Boundary;
use crate::decomp::regions::{Regions, grid_dims, parse_grid};
use crate::integrator::{kick, kick_drift};
use crate::kernels::ForceKernel;
use crate::physics::PairLaw;
use crate::real::Real;
use crate::scenario::System;
use crate::state::{Field, State, zero_field};

/// Relative margin of the ghost width over the cutoff: pair distances are rounded in `T`,
/// region distances computed in f64 (as the cell list's bins).
const GHOST_MARGIN: f64 = 1e-4;

/// Bins per region along an axis in the histograms that place the boundaries.
const BINS_PER_REGION: usize = 256;

/// Fewest steps between two rebalancings.
const REBALANCE_GAP: u64 = 10;

/// Domain decomposition settings.
#[derive(Clone, Debug, Default)]
pub struct DomainOptions {
    /// Regions per axis, such as `4x1` (slabs); default: the least cut area.
    pub rank_grid: Option<String>,
    /// Rebalance when the busiest rank owns more than this times the mean (> 1); `None`:
    /// never, and the regions start equal instead of balanced.
    pub rebalance_above: Option<f64>,
}

pub struct Domain<T: Real, const D: usize> {
    /// The kernel over the owned particles (cell list or Verlet list), and a cell list over
    /// the particles near the borders.
    interior: Box<dyn ForceKernel<T, D>>,
    border: Box<dyn ForceKernel<T, D>>,
    regions: Regions<D>,
    me: usize,
    /// Ghost width: the cutoff with a margin.
    width: f64,
    neighbours: Vec<usize>,
    owned: State<T, D>,
    forces: Field<T, D>,
    /// Scratch of the border pass: its particles, targets' slots and forces.
    shell: State<T, D>,
    border_slots: Vec<usize>,
    shell_slots: Vec<usize>,
    border_forces: Field<T, D>,
    boundary: Boundary<T, D>,
    external: [T; D],
    dt: T,
    rebalance_above: Option<f64>,
    rebalances: u64,
    last_rebalance: u64,
    tally: Tally,
}

impl<T: Real, const D: usize> Domain<T, D> {
    /// Takes this rank's particles of `system` (built identically on every rank) and
    /// computes the initial forces.
    pub fn new<L: PairLaw<T>>(
        system: System<T, L, D>,
        interior: Box<dyn ForceKernel<T, D>>,
        border: Box<dyn ForceKernel<T, D>>,
        options: &DomainOptions,
        comm: &mut Comm,
    ) -> Result<Self, MpiError> {
        let Boundary::Reflecting { lo, hi } = system.boundary else {
            return Err(MpiError::Usage(
                "--decomp domain needs a box with walls (lj-box, lj-liquid)".into(),
            ));
        };
        let rc = match system.law.cutoff() {
            Some(rc) => rc.as_f64(),
            None => {
                return Err(MpiError::Usage(
                    "--decomp domain needs a law with a cutoff (lj-box, lj-liquid)".into(),
                ));
            }
        };
        if let Some(x) = options
            .rebalance_above
            .filter(|x| !(x.is_finite() && *x > 1.0))
        {
            return Err(MpiError::Usage(format!(
                "--rebalance-above must be a number above 1 (got {x}); 1.1 rebalances at 10% excess"
            )));
        }
        let (lo, hi) = (lo.map(|x| x.as_f64()), hi.map(|x| x.as_f64()));
        let dims = match &options.rank_grid {
            Some(text) => parse_grid::<D>(text, comm.size())?,
            None => grid_dims::<D>(comm.size(), std::array::from_fn(|d| hi[d] - lo[d])),
        };
        let mut regions = Regions::uniform(lo, hi, dims)?;
        let state = system.state;
        if options.rebalance_above.is_some() {
            let positions = || (0..state.len()).map(|i| state.position(i).map(|x| x.as_f64()));
            for axis in 0..D {
                let h = regions.histogram(axis, BINS_PER_REGION * dims[axis], positions());
                regions.cut_axis(axis, &h);
            }
        }
        let me = comm.rank();
        let mine: Vec<u32> = (0..state.len() as u32)
            .filter(|&i| regions.owner(state.position(i as usize).map(|x| x.as_f64())) == me)
            .collect();
        let owned = State {
            pos: std::array::from_fn(|d| mine.iter().map(|&i| state.pos[d][i as usize]).collect()),
            vel: std::array::from_fn(|d| mine.iter().map(|&i| state.vel[d][i as usize]).collect()),
            mass: mine.iter().map(|&i| state.mass[i as usize]).collect(),
            source: mine.iter().map(|&i| state.source[i as usize]).collect(),
            id: mine.iter().map(|&i| state.id[i as usize]).collect(),
        };
        let width = rc * (1.0 + GHOST_MARGIN);
        let mut domain = Domain {
            interior,
            border,
            neighbours: regions.neighbours(me, width),
            regions,
            me,
            width,
            forces: zero_field(owned.len()),
            owned,
            shell: State::new(0),
            border_slots: Vec::new(),
            shell_slots: Vec::new(),
            border_forces: zero_field(0),
            boundary: system.boundary,
            external: system.external,
            dt: system.dt,
            rebalance_above: options.rebalance_above,
            rebalances: 0,
            last_rebalance: 0,
            tally: Tally::default(),
        };
        domain.sort();
        domain.compute_forces(comm)?;
        Ok(domain)
    }

    /// Puts the owned particles in the kernel's bin order (locality of the force loop).
    fn sort(&mut self) {
        if let Some(order) = self.interior.spatial_order(&self.owned) {
            self.owned.permute(&order, &mut [&mut self.forces]);
        }
    }

    /// Whether the counts (one per rank) are unbalanced enough to move the boundaries.
    fn should_rebalance(&self, counts: &[i64], step: u64) -> bool {
        let Some(limit) = self.rebalance_above else {
            return false;
        };
        let total: i64 = counts.iter().sum();
        let max = counts.iter().copied().max().unwrap_or(0);
        total > 0
            && step >= self.last_rebalance + REBALANCE_GAP
            && max as f64 > limit * total as f64 / counts.len() as f64
    }
}

impl<T: Real, const D: usize> Driver<T, D> for Domain<T, D> {
    fn step(&mut self, comm: &mut Comm, step: u64) -> Result<(), MpiError> {
        let half = self.dt * T::of(0.5);
        kick_drift(&mut self.owned, &self.forces, self.external, half, self.dt);
        let error = self.boundary.apply(&mut self.owned, step).err();
        let counts = self.migrate(comm, error, step)?;
        if self.should_rebalance(&counts, step) {
            self.rebalance(comm)?;
            self.last_rebalance = step;
        }
        if step.is_multiple_of(self.interior.sort_every()) {
            self.sort();
        }
        self.compute_forces(comm)?;
        kick(&mut self.owned, &self.forces, self.external, half);
        Ok(())
    }

    fn owned(&self) -> (&State<T, D>, &Field<T, D>) {
        (&self.owned, &self.forces)
    }

    fn tally(&self) -> &Tally {
        &self.tally
    }

    fn reset_tally(&mut self) {
        self.tally = Tally::default();
    }

    fn rank_grid(&self) -> Option<Vec<usize>> {
        Some(self.regions.dims().to_vec())
    }

    fn rebalances(&self) -> u64 {
        self.rebalances
    }
}
