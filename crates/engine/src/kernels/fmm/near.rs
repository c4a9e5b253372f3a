//! The near field: each leaf's particles against the particles of its near leaves (itself
//! included), which the walk listed as pairs of leaves too close for their expansions.
//!
//! The walk finds each pair of near leaves once; both leaves get it in their lists, and each
//! leaf sums the forces on its own particles only, so leaves run on any threads in any order
//! and every particle's force is summed in its leaf's list order: the same bits at every
//! thread count, with no schedule. Each pair of particles is evaluated from both ends, by the
//! law's own coefficient; a mutual loop (each pair once, the reaction scattered to the
//! source) measured 3.7 ns per pair on the Intel Xeon 6/167/1 (AVX-512), where this loop
//! takes 1.4–1.8 ns for each of the two ends, so halving the evaluations does not pay.
//!
//! The timed path takes a leaf's particles in tiles of `LANES` targets and broadcasts every
//! source of a near leaf to the whole tile (`broadcast::tile_forces`, the octree's loop), the
//! sources read in place (a leaf is a run of the sorted arrays); in its own leaf, lane l skips
//! its own slot. The probe takes one target at a time with the gather form, which also sums
//! the energy (each pair from both ends) and counts the interacting pairs.

use crate::kernels::broadcast::{Tile, tile_forces};
use crate::kernels::rows::{Exclude, LANES, RowSum, Sources, Target, gather_excluding};
use crate::physics::PairLaw;
use crate::real::Real;
use std::ops::Range;

/// The near-field forces on the particles `leaf` (sorted slots) from the particles of each
/// range of `near` (which holds `leaf` itself once), written to `out` (slots of `leaf`).
#[inline(always)]
pub(super) fn leaf_forces<T: Real, L: PairLaw<T>, const D: usize>(
    law: &L,
    pos: &[Vec<T>; D],
    src: &[T],
    leaf: Range<usize>,
    near: &[Range<usize>],
    out: &mut [&mut [T]; D],
) {
    for lo in (leaf.start..leaf.end).step_by(LANES) {
        let hi = (lo + LANES).min(leaf.end);
        let tile = Tile::load(pos, src, lo, hi);
        let mut force = [[T::zero(); LANES]; D];
        for b in near {
            let sources = Sources::range(pos, src, b.start, b.end);
            // In its own leaf, lane l's own slot is source `lo − start + l` of the run.
            let own = if *b == leaf { lo - b.start } else { usize::MAX };
            let f = tile_forces(law, &tile, &sources, own);
            for d in 0..D {
                for l in 0..LANES {
                    force[d][l] += f[d][l];
                }
            }
        }
        for d in 0..D {
            out[d][lo - leaf.start..hi - leaf.start].copy_from_slice(&force[d][..hi - lo]);
        }
    }
}

/// The probe's [`leaf_forces`]: one target at a time in the gather form, skipping its own
/// slot; returns the energy of the leaf's particles with their near sources (each pair from
/// both ends) and the interacting pairs seen from this leaf.
#[inline(always)]
pub(super) fn probe_leaf<T: Real, L: PairLaw<T>, const D: usize>(
    law: &L,
    pos: &[Vec<T>; D],
    src: &[T],
    leaf: Range<usize>,
    near: &[Range<usize>],
    out: &mut [&mut [T]; D],
) -> (f64, u64) {
    let (mut energy, mut interacting) = (0.0, 0);
    for i in leaf.clone() {
        let t = Target {
            x: std::array::from_fn(|d| pos[d][i]),
            s: src[i],
        };
        let mut sum = RowSum::zero();
        for b in near {
            let exclude = if b.contains(&i) {
                Exclude::index(i - b.start)
            } else {
                Exclude::NONE
            };
            let sources = Sources::range(pos, src, b.start, b.end);
            sum.add(&gather_excluding::<T, L, D, true>(
                law, &t, &sources, exclude,
            ));
        }
        for d in 0..D {
            out[d][i - leaf.start] = sum.force[d];
        }
        energy += sum.energy.as_f64();
        interacting += sum.interacting;
    }
    (energy, interacting)
}
