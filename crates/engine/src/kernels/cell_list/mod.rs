//! `cell-list`: bins of side ≥ rc over the particles' bounding box, particles counting-sorted by
//! bin, and each particle's force gathered from its own and the adjacent bins only: O(n) pair
//! checks at fixed density.
//!
//! Every particle gathers from the full stencil (no Newton's third law), so targets are
//! independent and the force loop parallelizes over chunks of particles without races. Targets
//! are visited in state order and write their force in place; after
//! [`ForceKernel::spatial_order`] the state is in bin order, so consecutive targets read
//! neighbouring sources.
//!
//! The sources are laid out in [`strips`]: rows of bins interleaved three at a time, so that the
//! whole stencil of a bin is one contiguous run in 2-D (one per plane in 3-D). One call of the
//! SIMD pair loop per target matters: a call has a fixed cost (summing its SIMD lanes, ~10 ns)
//! comparable to all the pairs of a dilute gas, where a particle has ~3 candidates.
//!
//! In a periodic box ([`ForceKernel::set_periodic`]) the particles near the faces are copied
//! across them ([`ghosts`]) and the same bins and loop run over the particles and their copies.
//!
//! Memory, allocated on first use and reused: 3 copies of positions and strengths (plus
//! padding), 16 bytes per particle and 8 bytes per bin (at most 4 bins per particle); in a
//! periodic box, the ghosts' too.

mod forces;
mod ghosts;
pub(super) mod grid;
#[cfg(test)]
mod periodic_tests;
pub(super) mod strips;
#[cfg(test)]
mod tests;

use super::{ForceKernel, ForceReport, KernelError, KernelKind, WorkCounters, worth_parallel};
use crate::par::{chunk_len, for_chunks};
use crate::physics::PairLaw;
use crate::real::Real;
use crate::simd;
use crate::state::{Field, State};
use forces::targets as gather_targets;
use ghosts::Ghosts;
use std::ops::Range;
use std::sync::atomic::{AtomicU64, Ordering};
use std::time::Instant;
use strips::Strips;

/// The `cell-list` kernel for the short-range law `L` (see the module doc).
pub struct CellList<L, T: Real, const D: usize> {
    law: L,
    /// The cutoff, in f64 for the bin geometry.
    rc: f64,
    strips: Strips<T, D>,
    /// The periodic box and the particles' copies across its faces, when periodic.
    periodic: Option<Ghosts<T, D>>,
}

impl<L: PairLaw<T>, T: Real, const D: usize> CellList<L, T, D> {
    /// The kernel for `law`; refused when the law has no finite positive cutoff.
    pub fn new(law: L) -> Result<Self, KernelError> {
        let rc = match law.cutoff() {
            Some(rc) if rc.is_finite() && rc > T::zero() => rc.as_f64(),
            Some(rc) => {
                return Err(KernelError::BadParam(format!(
                    "the cell list needs a finite positive cutoff (got {rc})"
                )));
            }
            None => {
                return Err(KernelError::BadParam(format!(
                    "the cell list needs a law with a cutoff; {} has none",
                    law.kind().name()
                )));
            }
        };
        if !(1..=3).contains(&D) {
            return Err(KernelError::BadParam(format!(
                "the cell list works in 1 to 3 dimensions (got {D})"
            )));
        }
        Ok(CellList {
            law,
            rc,
            strips: Strips::new(),
            periodic: None,
        })
    }

    /// Bins `state` and lays out the source strips without computing any force: the build
    /// phase of [`ForceKernel::compute`] alone, for benchmarks. Per particle, in parallel over
    /// chunks of particles when they are many.
    pub fn build(&mut self, state: &State<T, D>) {
        self.built(state);
    }

    /// Builds the step's structure (in a periodic box, the ghosts first) and lends what the
    /// force loop reads: the law, the strips and the sources, whose first slots are `state`'s
    /// particles.
    fn built<'a>(
        &'a mut self,
        state: &'a State<T, D>,
    ) -> (&'a L, &'a Strips<T, D>, &'a State<T, D>) {
        let CellList {
            law,
            rc,
            strips,
            periodic,
        } = self;
        let sources = match periodic {
            Some(ghosts) => {
                ghosts.fill(state);
                &ghosts.sources
            }
            None => state,
        };
        strips.sort(sources, *rc);
        strips.fill(sources);
        (law, strips, sources)
    }
}

/// Cost of one particle of a step (binning, strip layout, run lookup, one gather call with its
/// lane reduction), in the naive kernel's pair evaluations (the unit of `worth_parallel`): in
/// a dilute gas a particle has ~3 candidates, and this fixed cost is most of its step. From
/// the one-thread profile of lj-box at n = 1e5 on the 2-vCPU AMD EPYC: ~63 ns per particle-
/// step, of which ~1 ns is pair arithmetic, against 0.22 ns per naive pair.
pub(crate) const ROW_COST: u64 = 250;

/// The work of a step of `n` particles and `candidates` candidate pairs, in naive pair
/// evaluations: what decides whether the step forks.
pub fn step_work(n: usize, candidates: u64) -> u64 {
    (n as u64)
        .saturating_mul(ROW_COST)
        .saturating_add(candidates)
}

impl<T: Real, L: PairLaw<T>, const D: usize> ForceKernel<T, D> for CellList<L, T, D> {
    fn kind(&self) -> KernelKind {
        KernelKind::CellList
    }

    fn compute(
        &mut self,
        state: &State<T, D>,
        forces: &mut Field<T, D>,
        probe: bool,
    ) -> ForceReport {
        let n = state.len();
        let out = forces.each_mut().map(|f| f.as_mut_slice());
        if !probe {
            return self.compute_targets(state, 0..n, out);
        }
        if n == 0 {
            return ForceReport {
                energy: Some(0.0),
                ..Default::default()
            };
        }
        let clock = Instant::now();
        let (law, strips, sources) = self.built(state);
        let build_s = clock.elapsed().as_secs_f64();
        let (total, work) = simd::dispatch(
            #[inline(always)]
            || gather_targets::<T, L, D, true>(law, strips, sources, 0, out),
        );
        ForceReport {
            // Each pair was seen from both ends.
            energy: Some(0.5 * total.energy.as_f64()),
            build_s,
            work: WorkCounters {
                pairs_interacting: total.interacting / 2,
                ..work
            },
        }
    }

    /// The bins hold every particle; only the targets gather from their stencils.
    fn compute_targets(
        &mut self,
        state: &State<T, D>,
        targets: Range<usize>,
        out: [&mut [T]; D],
    ) -> ForceReport {
        let n = state.len();
        let mut report = ForceReport::default();
        if n == 0 {
            return report;
        }
        let clock = Instant::now();
        let (law, strips, sources) = self.built(state);
        report.build_s = clock.elapsed().as_secs_f64();

        let candidates = strips.expected_candidates() / sources.len() as u64 * targets.len() as u64;
        if worth_parallel(step_work(targets.len(), candidates)) {
            let pair_checks = AtomicU64::new(0);
            let cells_visited = AtomicU64::new(0);
            let chunk = chunk_len(targets.len());
            for_chunks(out, targets.start, chunk, &|offset, chunk| {
                let (_, work) = simd::dispatch(
                    #[inline(always)]
                    || gather_targets::<T, L, D, false>(law, strips, sources, offset, chunk),
                );
                pair_checks.fetch_add(work.pair_checks, Ordering::Relaxed);
                cells_visited.fetch_add(work.cells_visited, Ordering::Relaxed);
            });
            report.work = WorkCounters {
                pair_checks: pair_checks.into_inner(),
                cells_visited: cells_visited.into_inner(),
                ..Default::default()
            };
        } else {
            let (_, work) = simd::dispatch(
                #[inline(always)]
                || gather_targets::<T, L, D, false>(law, strips, sources, targets.start, out),
            );
            report.work = work;
        }
        report
    }

    fn spatial_order(&mut self, state: &State<T, D>) -> Option<Vec<u32>> {
        self.strips.sort(state, self.rc);
        Some(self.strips.order())
    }

    fn set_periodic(&mut self, lo: [T; D], hi: [T; D]) -> Result<(), KernelError> {
        let ghosts = Ghosts::new(lo, hi, self.rc).map_err(|(d, least)| {
            KernelError::PeriodicBoxTooSmall(format!(
                "cell-list in a periodic box needs every side longer than twice the cutoff \
                 ({least:.6}); side {d} is {:.6}: use more particles or a lower density",
                (hi[d] - lo[d]).as_f64()
            ))
        })?;
        self.periodic = Some(ghosts);
        Ok(())
    }
}
