//! `naive`: every target against every other particle, n(n−1) pair evaluations (the form of the
//! MPI source code). Targets are independent, so it parallelizes over them without races.

mod periodic;

use super::broadcast::{Tile, tile_forces};
use super::rows::{Exclude, LANES, RowSum, Sources, Target, gather_excluding};
use super::{ForceKernel, ForceReport, KernelError, KernelKind, WorkCounters, worth_parallel};
use crate::par::{chunk_len, for_chunks};
use crate::physics::PairLaw;
use crate::real::Real;
use crate::simd;
use crate::state::{Field, State};
use periodic::PeriodicBox;
use std::ops::Range;

/// The `naive` kernel: every particle against every other, parallel over targets.
pub struct Naive<L> {
    law: L,
    /// The sides of the periodic box the pairs meet through (their nearest images), or
    /// `None` for walls and open space.
    periodic: Option<Vec<f64>>,
}

impl<L> Naive<L> {
    /// The kernel for `law`.
    pub fn new(law: L) -> Self {
        Naive {
            law,
            periodic: None,
        }
    }

    fn periodic_box<T: Real, const D: usize>(&self) -> Option<PeriodicBox<T, D>> {
        let side = self.periodic.as_ref()?;
        Some(PeriodicBox::new(std::array::from_fn(|d| T::of(side[d]))))
    }
}

/// Forces on targets `offset..offset + out.len()` from all other particles.
#[inline(always)]
fn rows<T: Real, L: PairLaw<T>, const D: usize, const PROBE: bool>(
    law: &L,
    state: &State<T, D>,
    offset: usize,
    out: [&mut [T]; D],
) -> RowSum<T, D> {
    let n = state.len();
    let mut total = RowSum::zero();
    for k in 0..out[0].len() {
        let i = offset + k;
        let t = Target {
            x: state.position(i),
            s: state.source[i],
        };
        // One run over all particles with the target's own slot masked: no scalar tails
        // around the diagonal.
        let all = Sources::range(&state.pos, &state.source, 0, n);
        let sum = gather_excluding::<T, L, D, PROBE>(law, &t, &all, Exclude::index(i));
        for d in 0..D {
            out[d][k] = sum.force[d];
        }
        total.energy += sum.energy;
        total.interacting += sum.interacting;
    }
    total
}

/// The timed path of [`rows`]: the targets `offset..offset + out.len()` in tiles of `LANES`,
/// each against every particle.
#[inline(always)]
fn tiles<T: Real, L: PairLaw<T>, const D: usize>(
    law: &L,
    state: &State<T, D>,
    offset: usize,
    out: [&mut [T]; D],
) {
    let all = Sources::range(&state.pos, &state.source, 0, state.len());
    for lo in (0..out[0].len()).step_by(LANES) {
        let len = LANES.min(out[0].len() - lo);
        let i = offset + lo;
        let tile = Tile::load(&state.pos, &state.source, i, i + len);
        let force = tile_forces(law, &tile, &all, i);
        for d in 0..D {
            out[d][lo..lo + len].copy_from_slice(&force[d][..len]);
        }
    }
}

impl<T: Real, L: PairLaw<T>, const D: usize> ForceKernel<T, D> for Naive<L> {
    fn kind(&self) -> KernelKind {
        KernelKind::Naive
    }

    fn compute(
        &mut self,
        state: &State<T, D>,
        forces: &mut Field<T, D>,
        probe: bool,
    ) -> ForceReport {
        let n = state.len();
        let out = forces.each_mut().map(|f| f.as_mut_slice());
        if let (true, Some(pbox)) = (probe, self.periodic_box()) {
            let probed = periodic::rows::<T, L, D, true>(&self.law, state, &pbox, 0, out);
            return ForceReport {
                energy: Some(0.5 * probed.energy),
                build_s: 0.0,
                work: WorkCounters {
                    pair_checks: (n as u64) * (n.saturating_sub(1) as u64),
                    pairs_interacting: probed.interacting / 2,
                    ..Default::default()
                },
            };
        }
        if probe {
            let law = &self.law;
            let total = simd::dispatch(
                #[inline(always)]
                || rows::<T, L, D, true>(law, state, 0, out),
            );
            ForceReport {
                // Each pair was seen from both ends.
                energy: Some(0.5 * total.energy.as_f64()),
                build_s: 0.0,
                work: WorkCounters {
                    pair_checks: (n as u64) * (n.saturating_sub(1) as u64),
                    pairs_interacting: total.interacting / 2,
                    ..Default::default()
                },
            }
        } else {
            self.compute_targets(state, 0..n, out)
        }
    }

    /// Each target is an independent row, so only the targets' rows are evaluated.
    fn compute_targets(
        &mut self,
        state: &State<T, D>,
        targets: Range<usize>,
        out: [&mut [T]; D],
    ) -> ForceReport {
        let n = state.len();
        let law = &self.law;
        let pair_checks = (targets.len() as u64) * (n.saturating_sub(1) as u64);
        let report = ForceReport {
            work: WorkCounters {
                pair_checks,
                ..Default::default()
            },
            ..Default::default()
        };
        if let Some(pbox) = self.periodic_box() {
            if worth_parallel(pair_checks) {
                for_chunks(
                    out,
                    targets.start,
                    chunk_len(targets.len()),
                    &|offset, chunk: [&mut [T]; D]| {
                        periodic::rows::<T, L, D, false>(law, state, &pbox, offset, chunk);
                    },
                );
            } else {
                periodic::rows::<T, L, D, false>(law, state, &pbox, targets.start, out);
            }
            return report;
        }
        if worth_parallel(pair_checks) {
            for_chunks(
                out,
                targets.start,
                chunk_len(targets.len()),
                &|offset, chunk| {
                    simd::dispatch(
                        #[inline(always)]
                        || tiles(law, state, offset, chunk),
                    );
                },
            );
        } else {
            simd::dispatch(
                #[inline(always)]
                || tiles(law, state, targets.start, out),
            );
        }
        report
    }

    fn set_periodic(&mut self, lo: [T; D], hi: [T; D]) -> Result<(), KernelError> {
        self.periodic = Some((0..D).map(|d| (hi[d] - lo[d]).as_f64()).collect());
        Ok(())
    }
}
