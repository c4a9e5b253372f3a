//! `per-thread`: the symmetric pair work split into parts over the rayon pool's threads, each
//! part scattering into its own force buffer, then a parallel reduction (the form of the
//! OpenMP source code).
//!
//! The triangle's rows are uneven, so a step is cut into [`PARTS`] parts of equal pair work,
//! several per thread, which the pool hands out one at a time. The cut depends on n alone, never
//! on the thread count, and the buffers are added in part order: the forces are the same bits
//! on any number of threads. A part writes only its own targets and the particles after them,
//! so its buffer is cleared and reduced over that stretch alone.
//!
//! Memory: one buffer of n × D values per part, allocated on the first step that forks and
//! reused. Steps too small to pay for a fork/join run as one part, straight into the forces.

use super::triangle::{self, pair_work, split};
use super::{ForceKernel, ForceReport, KernelKind, MIN_PARALLEL_PAIRS, Share, WorkCounters};
use crate::par::{chunk_len, for_chunks};
use crate::physics::PairLaw;
use crate::real::Real;
use crate::state::{Field, State, zero_field};
use rayon::prelude::*;
use std::ops::Range;

/// Parts of a step that forks: four per thread on two, handed out one at a time, so that the
/// last part to finish costs the other thread little waiting; more parts cost more clearing
/// and reduction than they save in balance at a few thousand particles.
pub const PARTS: usize = 8;

/// Fewest elements a thread reduces: below it the fork costs more than the additions.
const MIN_REDUCE: usize = 1024;

/// The `per-thread` kernel: symmetric pairs in parts over the pool's threads, one force
/// buffer each.
pub struct PerThread<L, T: Real, const D: usize> {
    law: L,
    buffers: Vec<Field<T, D>>,
    /// The targets of each part, for `split_key`.
    parts: Vec<Range<usize>>,
    /// (n, targets) of the cached parts.
    split_key: (usize, Range<usize>),
}

/// Whether the targets `targets` of n particles are cut into parts (the step forks when the
/// pool has more than one thread): the rule of [`super::worth_parallel`] on the pair work,
/// without the thread count.
pub fn splits(n: usize, targets: Range<usize>) -> bool {
    pair_work(n, targets) >= MIN_PARALLEL_PAIRS
}

impl<L, T: Real, const D: usize> PerThread<L, T, D> {
    /// The kernel for `law`; its buffers are allocated on the first step that forks.
    pub fn new(law: L) -> Self {
        PerThread {
            law,
            buffers: Vec::new(),
            parts: Vec::new(),
            split_key: (0, 0..0),
        }
    }

    /// Cuts `targets` into [`PARTS`] parts of equal pair work, with a buffer each.
    fn split(&mut self, n: usize, targets: Range<usize>) {
        let key = (n, targets.clone());
        if self.split_key == key {
            return;
        }
        self.parts = split(n, targets, PARTS);
        if self.buffers.len() != PARTS || self.buffers[0][0].len() != n {
            self.buffers = (0..PARTS).map(|_| zero_field(n)).collect();
        }
        self.split_key = key;
    }
}

impl<T: Real, L: PairLaw<T>, const D: usize> PerThread<L, T, D> {
    /// Overwrites `forces` with the forces of the pairs of `targets` (both ends), in parts on
    /// the pool's threads when the step is large enough; returns the pair work.
    fn forces_of(
        &mut self,
        state: &State<T, D>,
        targets: Range<usize>,
        forces: &mut Field<T, D>,
    ) -> u64 {
        let n = state.len();
        for f in forces.iter_mut() {
            f.fill(T::zero());
        }
        if !splits(n, targets.clone()) {
            let mut out = forces.each_mut().map(|f| f.as_mut_slice());
            triangle::add::<T, L, D, false>(&self.law, state, targets.clone(), &mut out);
            return pair_work(n, targets);
        }
        self.split(n, targets.clone());
        let law = &self.law;
        let part = |(buf, part): (&mut Field<T, D>, &Range<usize>)| {
            if part.is_empty() {
                return;
            }
            let mut out = buf.each_mut().map(|f| &mut f[..]);
            for f in out.iter_mut() {
                f[part.start..].fill(T::zero());
            }
            triangle::add::<T, L, D, false>(law, state, part.clone(), &mut out);
        };
        let forked = rayon::current_num_threads() > 1;
        if forked {
            // One part per task: rayon's adaptive split would hand out runs of parts, and a
            // thread left with the last run idles the other for a quarter of the step.
            self.buffers
                .par_iter_mut()
                .zip(self.parts.par_iter())
                .with_max_len(1)
                .for_each(part);
        } else {
            self.buffers
                .iter_mut()
                .zip(self.parts.iter())
                .for_each(part);
        }
        self.reduce(targets.start, forces, forked);
        pair_work(n, targets)
    }

    /// Adds the parts' buffers into `forces` from slot `from` on, each over the slots its part
    /// wrote, in part order; on the pool's threads when `forked`.
    fn reduce(&self, from: usize, forces: &mut Field<T, D>, forked: bool) {
        let (buffers, parts) = (&self.buffers, &self.parts);
        let add = |offset: usize, chunk: [&mut [T]; D]| {
            let end = offset + chunk[0].len();
            for (d, dst) in chunk.into_iter().enumerate() {
                for (buf, part) in buffers.iter().zip(parts).filter(|(_, p)| !p.is_empty()) {
                    let lo = part.start.max(offset);
                    if lo >= end {
                        // Later parts start later still.
                        break;
                    }
                    for (x, y) in dst[lo - offset..].iter_mut().zip(&buf[d][lo..end]) {
                        *x += *y;
                    }
                }
            }
        };
        let out = forces.each_mut().map(|f| &mut f[from..]);
        if forked {
            let len = chunk_len(out[0].len()).max(MIN_REDUCE);
            for_chunks(out, from, len, &add);
        } else {
            add(from, out);
        }
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
        if probe {
            // The probe runs outside the timed steps, on one thread.
            for f in forces.iter_mut() {
                f.fill(T::zero());
            }
            let mut out = forces.each_mut().map(|f| f.as_mut_slice());
            let total = triangle::add::<T, L, D, true>(&self.law, state, 0..n, &mut out);
            return ForceReport {
                energy: Some(total.energy.as_f64()),
                build_s: 0.0,
                work: WorkCounters {
                    pair_checks: pair_work(n, 0..n),
                    pairs_interacting: total.interacting,
                    ..Default::default()
                },
            };
        }
        let pair_checks = self.forces_of(state, 0..n, forces);
        ForceReport {
            work: WorkCounters {
                pair_checks,
                ..Default::default()
            },
            ..Default::default()
        }
    }

    /// A balanced share of the targets, cut again into parts over the pool's threads.
    fn compute_share(
        &mut self,
        state: &State<T, D>,
        share: Share,
        forces: &mut Field<T, D>,
    ) -> ForceReport {
        let n = state.len();
        let targets = split(n, 0..n, share.count)[share.index].clone();
        let pair_checks = self.forces_of(state, targets, forces);
        ForceReport {
            work: WorkCounters {
                pair_checks,
                ..Default::default()
            },
            ..Default::default()
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::physics::{Coulomb, Gravity, LennardJones};
    use crate::testing::SEED_1;
    use rand::{Rng, SeedableRng};
    use rand_pcg::Pcg64Mcg;

    /// A state of `n` particles in a cube of side `side`, strengths of both signs.
    fn state<T: Real>(n: usize, side: f64) -> State<T, 3> {
        let mut rng = Pcg64Mcg::seed_from_u64(SEED_1);
        let mut state = State::<T, 3>::new(n);
        for i in 0..n {
            for d in 0..3 {
                state.pos[d][i] = T::of(side * rng.random::<f64>());
            }
            state.source[i] = T::of(if i % 3 == 0 { -1.0 } else { 1.0 });
        }
        state
    }

    /// The forces of a step that forks, on a pool of `threads`.
    fn forces_on<T: Real, L: PairLaw<T>>(
        law: L,
        state: &State<T, 3>,
        threads: usize,
    ) -> Field<T, 3> {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .expect("a pool");
        let mut forces = zero_field(state.len());
        pool.install(|| PerThread::new(law).compute(state, &mut forces, false));
        forces
    }

    /// Bitwise the same forces on 1, 2 and 3 threads, in every law and both precisions, at
    /// an n that is cut into parts and ends inside a vector.
    #[test]
    fn forces_are_the_same_bits_at_every_thread_count() {
        let n = 1203;
        assert!(splits(n, 0..n));
        fn same<T: Real, L: PairLaw<T>>(law: L, state: &State<T, 3>) {
            let one = forces_on(law, state, 1);
            for threads in [2, 3] {
                let many = forces_on(law, state, threads);
                for d in 0..3 {
                    for (a, b) in one[d].iter().zip(&many[d]) {
                        assert_eq!(
                            a.as_f64().to_bits(),
                            b.as_f64().to_bits(),
                            "{threads} threads"
                        );
                    }
                }
            }
        }
        same(Gravity::<f64>::new(1.0, 0.01), &state(n, 1.0));
        same(Coulomb::<f64>::new(1e-3), &state(n, 1.0));
        same(Gravity::<f32>::new(1.0, 0.01), &state(n, 1.0));
        same(LennardJones::<f32>::new(1.0, 0.01, 0.025), &state(n, 0.3));
        same(LennardJones::<f64>::new(1.0, 0.01, 0.025), &state(n, 0.3));
    }
}
