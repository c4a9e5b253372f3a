//! The cluster list's step in a team region, and a part's forces added into shared padded
//! slots (the step's and the rayon pool's).

use super::batched::add_forces;
use super::layout::CLUSTER;
use super::list::Part;
use super::run_cost;
use super::tile::{Clusters, Out};
use crate::kernels::WorkCounters;
use crate::kernels::images::Images;
use crate::kernels::teamed::{Colors, StateView, TeamPlan};
use crate::kernels::verlet::block_kept_in;
use crate::par::team::{SharedSlice, Worker, shared};
use crate::physics::PairLaw;
use crate::real::Real;

use std::ops::Range;

/// Adds the forces of `part` to the padded slots of `out` its runs touch (near it, and across
/// the faces).
///
/// # Safety
/// No other thread touches those slots of `out` meanwhile.
pub(super) unsafe fn add_part<T: Real, L: PairLaw<T>, const D: usize>(
    law: &L,
    clusters: &Clusters<'_, T, D>,
    part: &Part,
    images: Option<&Images<T, D>>,
    out: &[SharedSlice<'_, T>; D],
) {
    let near = part.clusters.start * CLUSTER..part.end * CLUSTER;
    let far = part.far.start * CLUSTER..part.far.end * CLUSTER;
    // SAFETY: the caller's promise; the two spans are apart (the list merges them otherwise).
    let mut out = unsafe {
        Out {
            near_base: near.start,
            near: shared::ranges_mut(out, near),
            far_base: if far.is_empty() {
                usize::MAX
            } else {
                far.start
            },
            far: shared::ranges_mut(out, far),
        }
    };
    add_forces(law, clusters, part, images, &mut out);
}

/// The cluster list's step in a team region: the displacement test on each worker's block,
/// the padded copy and forces by blocks of padded slots, the parts colour by colour, the
/// forces gathered back by blocks of state slots. In a periodic box the padded copy holds
/// each slot's position continued from its place at the build.
pub(super) struct Plan<'k, L, T, const D: usize> {
    pub law: &'k L,
    pub parts: &'k [Part],
    pub colors: &'k Colors,
    pub images: Option<&'k Images<T, D>>,
    pub at_build: [&'k [T]; D],
    pub skin: f64,
    pub runs: u64,
    pub slot_of: &'k [u32],
    pub padded_of: &'k [u32],
    pub pos: [SharedSlice<'k, T>; D],
    pub src: SharedSlice<'k, T>,
    pub force: [SharedSlice<'k, T>; D],
}

impl<T: Real, L: PairLaw<T>, const D: usize> TeamPlan<T, D> for Plan<'_, L, T, D> {
    fn keeps(&self, pos: [&[T]; D], block: Range<usize>) -> bool {
        block_kept_in(self.images, pos, self.at_build, block, self.skin)
    }

    fn colors(&self) -> &Colors {
        self.colors
    }

    unsafe fn prepare(
        &self,
        worker: &Worker,
        state: StateView<'_, T, D>,
        _forces: &[SharedSlice<'_, T>; D],
    ) {
        let block = worker.block(self.slot_of.len());
        let from = &self.slot_of[block.clone()];
        // SAFETY: each worker writes its own block of padded slots, and nobody reads them
        // before the next barrier (the caller's promise for this phase).
        let (pos, src, force) = unsafe {
            (
                shared::ranges_mut(&self.pos, block.clone()),
                self.src.range_mut(block.clone()),
                shared::ranges_mut(&self.force, block),
            )
        };
        // Compiled for the instruction set: the rounding of `continued` is one instruction
        // there and a call per element at the baseline.
        crate::simd::dispatch(
            #[inline(always)]
            || {
                for (d, x) in pos.into_iter().enumerate() {
                    let (now, then) = (state.pos[d], self.at_build[d]);
                    match self.images {
                        Some(images) => {
                            for (x, &i) in x.iter_mut().zip(from) {
                                *x = images.continued(now[i as usize], then[i as usize], d);
                            }
                        }
                        None => {
                            for (x, &i) in x.iter_mut().zip(from) {
                                *x = now[i as usize];
                            }
                        }
                    }
                }
            },
        );
        for (s, &i) in src.iter_mut().zip(from) {
            *s = state.source[i as usize];
        }
        for f in force {
            f.fill(T::zero());
        }
    }

    unsafe fn interact(
        &self,
        part: usize,
        _state: StateView<'_, T, D>,
        _forces: &[SharedSlice<'_, T>; D],
    ) {
        // SAFETY: the padded copy is written only before the previous barrier; no other part
        // running now touches this part's slots (the caller's promise).
        unsafe {
            let clusters = Clusters {
                pos: shared::wholes(&self.pos),
                src: self.src.whole(),
            };
            add_part(
                self.law,
                &clusters,
                &self.parts[part],
                self.images,
                &self.force,
            );
        }
    }

    unsafe fn finish(&self, worker: &Worker, forces: &[SharedSlice<'_, T>; D]) {
        let block = worker.block(self.padded_of.len());
        let from = &self.padded_of[block.clone()];
        // SAFETY: the padded forces are final (every part ran before the last barrier); each
        // worker writes its own block of the output.
        let (force, out) = unsafe {
            (
                shared::wholes(&self.force),
                shared::ranges_mut(forces, block),
            )
        };
        for (d, out) in out.into_iter().enumerate() {
            for (o, &k) in out.iter_mut().zip(from) {
                *o = force[d][k as usize];
            }
        }
    }

    fn work(&self) -> WorkCounters {
        WorkCounters {
            pair_checks: self.runs * run_cost(D),
            list_entries: self.runs,
            ..Default::default()
        }
    }
}
