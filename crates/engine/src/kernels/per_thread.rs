//! `per-thread`: the symmetric pair work split over the rayon pool's threads, each scattering
//! into its own force buffer, then a parallel reduction (the form of the OpenMP source code).
//!
//! Memory: one buffer of n × D values per thread, allocated on the first step and reused.
//! Steps too small to pay for a fork/join run the serial symmetric path instead.

use super::symmetric::{add_tiles, blocks, pairs_of, split_tiles};
use super::{ForceKernel, ForceReport, KernelKind, Share, WorkCounters, worth_parallel};
use crate::par::{chunk_len, for_chunks};
use crate::physics::PairLaw;
use crate::real::Real;
use crate::simd;
use crate::state::{Field, State, zero_field};
use rayon::prelude::*;
use std::ops::Range;

/// The `per-thread` kernel: symmetric pairs over the pool's threads, one force buffer each.
pub struct PerThread<L, T: Real, const D: usize> {
    law: L,
    buffers: Vec<Field<T, D>>,
    partition: Vec<Range<usize>>,
    /// (n, tiles, parts) of the cached partition.
    partition_key: (usize, Range<usize>, usize),
}

impl<L, T: Real, const D: usize> PerThread<L, T, D> {
    /// The kernel for `law`; its buffers are allocated on the first step.
    pub fn new(law: L) -> Self {
        PerThread {
            law,
            buffers: Vec::new(),
            partition: Vec::new(),
            partition_key: (0, 0..0, 0),
        }
    }

    /// Splits the target tiles `tiles` into `parts` contiguous ranges of near-equal pair work.
    fn partition(&mut self, n: usize, tiles: Range<usize>, parts: usize) {
        let key = (n, tiles.clone(), parts);
        if self.partition_key == key {
            return;
        }
        self.partition = split_tiles(n, tiles, parts);
        if self.buffers.len() != self.partition.len() || self.buffers[0][0].len() != n {
            self.buffers = (0..self.partition.len()).map(|_| zero_field(n)).collect();
        }
        self.partition_key = key;
    }
}

impl<T: Real, L: PairLaw<T>, const D: usize> PerThread<L, T, D> {
    /// Overwrites `forces` with the forces of the pairs of target tiles `tiles` (both ends),
    /// on one thread.
    fn serial_tiles<const PROBE: bool>(
        &self,
        state: &State<T, D>,
        tiles: Range<usize>,
        forces: &mut Field<T, D>,
    ) -> (f64, u64) {
        let law = &self.law;
        for f in forces.iter_mut() {
            f.fill(T::zero());
        }
        let mut out = forces.each_mut().map(|f| f.as_mut_slice());
        let total = simd::dispatch(
            #[inline(always)]
            || add_tiles::<T, L, D, PROBE>(law, state, tiles, &mut out),
        );
        (total.energy.as_f64(), total.interacting)
    }

    /// Overwrites `forces` with the forces of the pairs of target tiles `tiles` (both ends),
    /// the tiles split over the pool's threads, each into its own buffer, then reduced.
    fn parallel_tiles(
        &mut self,
        state: &State<T, D>,
        tiles: Range<usize>,
        forces: &mut Field<T, D>,
    ) {
        let n = state.len();
        self.partition(n, tiles, rayon::current_num_threads());
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
    }

    /// Forces of the pairs of target tiles `tiles`, in parallel when it pays.
    fn tiles(&mut self, state: &State<T, D>, tiles: Range<usize>, forces: &mut Field<T, D>) -> u64 {
        let pair_checks = pairs_of(state.len(), tiles.clone());
        if !worth_parallel(pair_checks) || tiles.len() < 2 {
            // Small steps lose to fork/join.
            self.serial_tiles::<false>(state, tiles, forces);
        } else {
            self.parallel_tiles(state, tiles, forces);
        }
        pair_checks
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
        let tiles = 0..blocks(state.len());
        if probe {
            // The probe runs outside the timed steps, on one thread.
            let (energy, interacting) = self.serial_tiles::<true>(state, tiles.clone(), forces);
            return ForceReport {
                energy: Some(energy),
                build_s: 0.0,
                work: WorkCounters {
                    pair_checks: pairs_of(state.len(), tiles),
                    pairs_interacting: interacting,
                    ..Default::default()
                },
            };
        }
        let pair_checks = self.tiles(state, tiles, forces);
        ForceReport {
            work: WorkCounters {
                pair_checks,
                ..Default::default()
            },
            ..Default::default()
        }
    }

    /// A balanced share of the target tiles, split again over the pool's threads.
    fn compute_share(
        &mut self,
        state: &State<T, D>,
        share: Share,
        forces: &mut Field<T, D>,
    ) -> ForceReport {
        let n = state.len();
        let tiles = split_tiles(n, 0..blocks(n), share.count)[share.index].clone();
        let pair_checks = self.tiles(state, tiles, forces);
        ForceReport {
            work: WorkCounters {
                pair_checks,
                ..Default::default()
            },
            ..Default::default()
        }
    }
}
