//! `symmetric`: each pair once (i < j) with Newton's third law, n(n−1)/2 pair evaluations (the
//! form of the serial source code), single-threaded: the triangle of [`super::triangle`] over
//! every target.

use super::triangle::{self, pair_work, split};
use super::{ForceKernel, ForceReport, KernelKind, Share, WorkCounters};
use crate::physics::PairLaw;
use crate::real::Real;
use crate::state::{Field, State};

/// The `symmetric` kernel: each pair once with Newton's third law, on one thread.
pub struct Symmetric<L> {
    law: L,
}

impl<L> Symmetric<L> {
    /// The kernel for `law`.
    pub fn new(law: L) -> Self {
        Symmetric { law }
    }
}

impl<T: Real, L: PairLaw<T>, const D: usize> ForceKernel<T, D> for Symmetric<L> {
    fn kind(&self) -> KernelKind {
        KernelKind::Symmetric
    }

    fn compute(
        &mut self,
        state: &State<T, D>,
        forces: &mut Field<T, D>,
        probe: bool,
    ) -> ForceReport {
        let n = state.len();
        let law = &self.law;
        for f in forces.iter_mut() {
            f.fill(T::zero());
        }
        let mut out = forces.each_mut().map(|f| f.as_mut_slice());
        let total = if probe {
            triangle::add::<T, L, D, true>(law, state, 0..n, &mut out)
        } else {
            triangle::add::<T, L, D, false>(law, state, 0..n, &mut out)
        };
        ForceReport {
            energy: probe.then(|| total.energy.as_f64()),
            build_s: 0.0,
            work: WorkCounters {
                pair_checks: pair_work(n, 0..n),
                pairs_interacting: total.interacting,
                ..Default::default()
            },
        }
    }

    /// A balanced share of the targets, both ends of each of their pairs.
    fn compute_share(
        &mut self,
        state: &State<T, D>,
        share: Share,
        forces: &mut Field<T, D>,
    ) -> ForceReport {
        let n = state.len();
        let law = &self.law;
        let targets = split(n, 0..n, share.count)[share.index].clone();
        for f in forces.iter_mut() {
            f.fill(T::zero());
        }
        let mut out = forces.each_mut().map(|f| f.as_mut_slice());
        let pair_checks = pair_work(n, targets.clone());
        triangle::add::<T, L, D, false>(law, state, targets, &mut out);
        ForceReport {
            work: WorkCounters {
                pair_checks,
                ..Default::default()
            },
            ..Default::default()
        }
    }
}
