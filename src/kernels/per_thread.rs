//! `per-thread`: the symmetric pair work split over the rayon pool's threads, each scattering
//! into its own force buffer, then a parallel reduction (the form of the OpenMP source code).
//!
//! Memory: one buffer of n × D values per thread, allocated on the first step and reused.
//! Steps too small to pay for a fork/join run the serial symmetric path instead.

use super::par::{chunk_len, for_chunks};
use super::symmetric::{add_tiles, blocks, tile_pairs};
use super::{ForceKernel, ForceReport, KernelKind, WorkCounters, worth_parallel};
use crate::physics::PairLaw;
use crate::real::Real;
use crate::simd;
use crate::state::{Field, State, zero_field};
use rayon::prelude::*;
use std::ops::Range;

pub struct PerThread<L, T: Real, const D: usize> {
    law: L,
    buffers: Vec<Field<T, D>>,
    partition: Vec<Range<usize>>,
    partition_key: (usize, usize),
}

impl<L, T: Real, const D: usize> PerThread<L, T, D> {
    pub fn new(law: L) -> Self {
        PerThread {
            law,
            buffers: Vec::new(),
            partition: Vec::new(),
            partition_key: (0, 0),
        }
    }

    /// Splits the target tiles into `parts` contiguous ranges of near-equal pair work.
    fn partition(&mut self, n: usize, parts: usize) {
        if self.partition_key == (n, parts) {
            return;
        }
        let tiles = blocks(n);
        let total: u64 = (0..tiles).map(|b| tile_pairs(n, b)).sum();
        let mut ranges = Vec::with_capacity(parts);
        let (mut start, mut acc) = (0, 0u64);
        for b in 0..tiles {
            acc += tile_pairs(n, b);
            let goal = total * (ranges.len() as u64 + 1) / parts as u64;
            if acc >= goal && ranges.len() + 1 < parts {
                ranges.push(start..b + 1);
                start = b + 1;
            }
        }
        ranges.push(start..tiles);
        self.partition = ranges;
        if self.buffers.len() != self.partition.len() || self.buffers[0][0].len() != n {
            self.buffers = (0..self.partition.len()).map(|_| zero_field(n)).collect();
        }
        self.partition_key = (n, parts);
    }
}

impl<T: Real, L: PairLaw<T>, const D: usize> ForceKernel<T, D> for PerThread<L, T, D> {
    fn kind(&self) -> KernelKind {
        KernelKind::PerThread
    }

    fn compute(
        &mut self,
        state: &State<T, D>,
        forces: &mut Field<T, D>,
        probe: bool,
    ) -> ForceReport {
        let n = state.len();
        let pair_checks = (n as u64) * (n.saturating_sub(1) as u64) / 2;
        let mut report = ForceReport {
            work: WorkCounters {
                pair_checks,
                ..Default::default()
            },
            ..Default::default()
        };
        let law = &self.law;
        if probe || !worth_parallel(pair_checks) || blocks(n) < 2 {
            // Serial path: the probe runs outside the timed steps; small steps lose to fork/join.
            for f in forces.iter_mut() {
                f.fill(T::zero());
            }
            let mut out = forces.each_mut().map(|f| f.as_mut_slice());
            let tiles = 0..blocks(n);
            let total = if probe {
                simd::dispatch(
                    #[inline(always)]
                    || add_tiles::<T, L, D, true>(law, state, tiles, &mut out),
                )
            } else {
                simd::dispatch(
                    #[inline(always)]
                    || add_tiles::<T, L, D, false>(law, state, tiles, &mut out),
                )
            };
            report.energy = probe.then(|| total.energy.as_f64());
            report.work.pairs_interacting = total.interacting;
            return report;
        }
        self.partition(n, rayon::current_num_threads());
        let law = &self.law;
        self.buffers
            .par_iter_mut()
            .zip(self.partition.par_iter())
            .for_each(|(buf, tiles)| {
                for f in buf.iter_mut() {
                    f.fill(T::zero());
                }
                let mut out = buf.each_mut().map(|f| f.as_mut_slice());
                simd::dispatch(
                    #[inline(always)]
                    || add_tiles::<T, L, D, false>(law, state, tiles.clone(), &mut out),
                );
            });
        let buffers = &self.buffers;
        let out = forces.each_mut().map(|f| f.as_mut_slice());
        for_chunks(out, 0, chunk_len(n).max(4096), &|offset, chunk| {
            for d in 0..D {
                let dst = &mut *chunk[d];
                dst.copy_from_slice(&buffers[0][d][offset..offset + dst.len()]);
                for b in &buffers[1..] {
                    for (x, y) in dst.iter_mut().zip(&b[d][offset..]) {
                        *x += *y;
                    }
                }
            }
        });
        report
    }
}
