//! `naive`: every target against every other particle, n(n−1) pair evaluations (the form of the
//! MPI source code). Targets are independent, so it parallelizes over them without races.

use super::par::{chunk_len, for_chunks};
use super::rows::{Exclude, RowSum, Sources, Target, gather_excluding};
use super::{ForceKernel, ForceReport, KernelKind, WorkCounters, worth_parallel};
use crate::physics::PairLaw;
use crate::real::Real;
use crate::simd;
use crate::state::{Field, State};

pub struct Naive<L> {
    law: L,
}

impl<L> Naive<L> {
    pub fn new(law: L) -> Self {
        Naive { law }
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
        let law = &self.law;
        let pair_checks = (n as u64) * (n.saturating_sub(1) as u64);
        let out = forces.each_mut().map(|f| f.as_mut_slice());
        let mut report = ForceReport {
            work: WorkCounters {
                pair_checks,
                ..Default::default()
            },
            ..Default::default()
        };
        if probe {
            let total = simd::dispatch(
                #[inline(always)]
                || rows::<T, L, D, true>(law, state, 0, out),
            );
            // Each pair was seen from both ends.
            report.energy = Some(0.5 * total.energy.as_f64());
            report.work.pairs_interacting = total.interacting / 2;
        } else if worth_parallel(pair_checks) {
            for_chunks(out, 0, chunk_len(n), &|offset, chunk| {
                simd::dispatch(
                    #[inline(always)]
                    || rows::<T, L, D, false>(law, state, offset, chunk),
                );
            });
        } else {
            simd::dispatch(
                #[inline(always)]
                || rows::<T, L, D, false>(law, state, 0, out),
            );
        }
        report
    }
}
