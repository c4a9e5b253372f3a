//! What the decompositions have in common: a rank's part of the simulation steps, and the loop
//! that times its steps.

use super::communicator::{Comm, CommCounters};
use super::error::MpiError;
use crate::decomp::wire::pack_particle;
use crate::kernels::WorkCounters;
use crate::real::Real;
use crate::state::{Field, State};
use std::time::Instant;

/// Tag bases of the point-to-point exchanges (each uses the tag and the next one).
pub(crate) const TAG_MIGRATE: i32 = 10;
pub(crate) const TAG_GHOSTS: i32 = 20;

/// Counters a driver keeps for the steps since the last reset.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct Tally {
    /// Seconds computing forces (part of the compute time).
    pub force_s: f64,
    /// Of `force_s`, building cells or trees.
    pub build_s: f64,
    pub work: WorkCounters,
    pub ghosts_received: u64,
    pub migrated_out: u64,
    /// Of `migrated_out`, particles that moved beyond the neighbouring regions in one step.
    pub far_migrated: u64,
}

/// One rank's part of a distributed simulation.
pub(crate) trait Driver<T: Real, const D: usize> {
    /// One velocity-Verlet step (number `step`, from 1) of this rank's particles, with the
    /// communication it needs. Every rank calls it for every step; an error on any rank stops
    /// all of them in the same step.
    fn step(&mut self, comm: &mut Comm, step: u64) -> Result<(), MpiError>;

    /// The particles this rank owns and their forces.
    fn owned(&self) -> (&State<T, D>, &Field<T, D>);

    fn tally(&self) -> &Tally;

    fn reset_tally(&mut self);

    /// Regions per axis, for decompositions that have them.
    fn rank_grid(&self) -> Option<Vec<usize>> {
        None
    }

    /// Times the decomposition was rebalanced.
    fn rebalances(&self) -> u64 {
        0
    }
}

/// The owned particles and their forces as f64 records (a particle, then its force), for
/// gathering the final state.
pub(crate) fn pack_owned<T: Real, const D: usize>(
    state: &State<T, D>,
    forces: &Field<T, D>,
) -> Vec<f64> {
    let mut out = Vec::with_capacity(state.len() * (crate::decomp::wire::particle_values(D) + D));
    for i in 0..state.len() {
        pack_particle(state, i, &mut out);
        for f in forces.iter() {
            out.push(f[i].as_f64());
        }
    }
    out
}

/// What one rank measured over the timed steps.
#[derive(Clone, Debug, Default)]
pub(crate) struct Timeline {
    /// Wall time of each timed step, nanoseconds.
    pub(crate) wall_ns: Vec<u64>,
    /// Compute seconds of each timed step (wall time minus time inside MPI).
    pub compute_s: Vec<f64>,
    /// MPI counters over the timed steps.
    pub comm: CommCounters,
    /// Wall time of the timed steps.
    pub total_s: f64,
    /// Mean particles owned over the timed steps.
    pub particles_mean: f64,
}

/// Runs `warmup` untimed steps, then `steps` timed ones.
pub fn drive<T: Real, const D: usize>(
    driver: &mut dyn Driver<T, D>,
    comm: &mut Comm,
    warmup: u64,
    steps: u64,
) -> Result<Timeline, MpiError> {
    for s in 1..=warmup {
        driver.step(comm, s)?;
    }
    driver.reset_tally();
    let before = comm.counters;
    let mut line = Timeline::default();
    let mut owned = 0.0;
    let start = Instant::now();
    for s in 1..=steps {
        let t = Instant::now();
        let c0 = comm.counters.seconds;
        driver.step(comm, warmup + s)?;
        let wall = t.elapsed();
        line.wall_ns.push(wall.as_nanos() as u64);
        line.compute_s
            .push((wall.as_secs_f64() - (comm.counters.seconds - c0)).max(0.0));
        owned += driver.owned().0.len() as f64;
    }
    line.total_s = start.elapsed().as_secs_f64();
    let after = comm.counters;
    line.comm = CommCounters {
        seconds: after.seconds - before.seconds,
        bytes_sent: after.bytes_sent - before.bytes_sent,
        messages_sent: after.messages_sent - before.messages_sent,
        collectives: after.collectives - before.collectives,
    };
    line.particles_mean = owned / steps.max(1) as f64;
    Ok(line)
}
