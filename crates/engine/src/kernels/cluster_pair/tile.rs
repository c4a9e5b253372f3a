//! The force loop: each i-cluster against runs of `GROUP` consecutive clusters, whose
//! `LANES` particles are one contiguous block of every array (no gather). Each particle of the
//! i-cluster, broadcast, meets the whole run in one block; its force stays in registers across
//! the i-cluster's list, and the reactions of the four i-particles add up lane by lane into
//! one contiguous update of the run. Lanes that must not act (outside the run's window,
//! padding, and in the i-cluster itself each pair's second copy and a particle with itself)
//! are zeroed with a select, never a branch.

use super::layout::{CLUSTER, Layout};
use super::list::Part;
use crate::kernels::rows::lane_sum;
use crate::physics::PairLaw;
use crate::real::{Real, select};
use crate::simd::LANES;

/// What the tiles of a part add up when probing: energy and pairs inside the cutoff.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct TileSum {
    pub energy: f64,
    pub interacting: u64,
}

/// The cluster arrays a force loop reads: positions and strengths per padded slot, `CLUSTER`
/// slots per cluster.
pub(crate) struct Clusters<'a, T, const D: usize> {
    pub pos: [&'a [T]; D],
    pub src: &'a [T],
}

impl<'a, T: Real, const D: usize> Clusters<'a, T, D> {
    pub fn of(layout: &'a Layout<T, D>) -> Self {
        Clusters {
            pos: std::array::from_fn(|d| &layout.pos[d][..]),
            src: &layout.src,
        }
    }
}

/// Adds the forces of the runs of `part` to `out`, where padded slot `s` is at
/// `out[d][s - base]`: both ends of every pair, each pair once.
#[inline(always)]
pub(crate) fn part_forces<T: Real, L: PairLaw<T>, const D: usize, const PROBE: bool>(
    law: &L,
    clusters: &Clusters<'_, T, D>,
    part: &Part,
    out: &mut [&mut [T]; D],
    base: usize,
) -> TileSum {
    let (pos, src) = (&clusters.pos, clusters.src);
    let mut energy = [T::zero(); LANES];
    let mut interacting = [0u32; LANES];
    for (k, c) in part.clusters.clone().enumerate() {
        let ic = c * CLUSTER;
        let xi: [[T; CLUSTER]; D] = std::array::from_fn(|d| {
            pos[d][ic..ic + CLUSTER]
                .try_into()
                .expect("clusters are whole")
        });
        let si: &[T; CLUSTER] = src[ic..ic + CLUSTER]
            .try_into()
            .expect("clusters are whole");
        let mut fi = [[[T::zero(); LANES]; D]; CLUSTER];
        for r in part.first[k] as usize..part.first[k + 1] as usize {
            let js = part.start[r] as usize * CLUSTER;
            let masks = &part.masks[r];
            let xj: [&[T; LANES]; D] =
                std::array::from_fn(|d| pos[d][js..js + LANES].try_into().expect("runs are whole"));
            let sj: &[T; LANES] = src[js..js + LANES].try_into().expect("runs are whole");
            let mut fj = [[T::zero(); LANES]; D];
            for a in 0..CLUSTER {
                let mut dx = [[T::zero(); LANES]; D];
                let mut r2 = [T::zero(); LANES];
                for d in 0..D {
                    for l in 0..LANES {
                        dx[d][l] = xj[d][l] - xi[d][a];
                        r2[l] += dx[d][l] * dx[d][l];
                    }
                }
                let mut coeff = [T::zero(); LANES];
                for l in 0..LANES {
                    let keep = (masks[a] >> l) & 1 != 0;
                    coeff[l] = select(keep, law.coeff(r2[l], si[a], sj[l]), T::zero());
                }
                for d in 0..D {
                    for l in 0..LANES {
                        let f = coeff[l] * dx[d][l];
                        fi[a][d][l] += f;
                        fj[d][l] += f;
                    }
                }
                if PROBE {
                    for l in 0..LANES {
                        let keep = (masks[a] >> l) & 1 != 0;
                        energy[l] += select(keep, law.energy(r2[l], si[a], sj[l]), T::zero());
                        interacting[l] += u32::from(keep && law.interacts(r2[l]));
                    }
                }
            }
            for d in 0..D {
                let dst: &mut [T; LANES] = (&mut out[d][js - base..js - base + LANES])
                    .try_into()
                    .expect("runs are whole");
                for l in 0..LANES {
                    dst[l] -= fj[d][l];
                }
            }
        }
        for a in 0..CLUSTER {
            for d in 0..D {
                out[d][ic - base + a] += lane_sum(fi[a][d]);
            }
        }
    }
    TileSum {
        energy: energy.iter().map(|e| e.as_f64()).sum(),
        interacting: interacting.iter().map(|&c| c as u64).sum(),
    }
}
