//! The force loop: each i-cluster against runs of consecutive clusters (`group_of(D)`), whose
//! particles (the `R` lanes of a block) are one contiguous block of every array (no gather). Each particle of the
//! i-cluster, broadcast, meets the whole run in one block; its force stays in registers across
//! the i-cluster's list, and the reactions of the four i-particles add up lane by lane into
//! one contiguous update of the run. Lanes that must not act (outside the run's window,
//! padding, and in the i-cluster itself each pair's second copy and a particle with itself)
//! are zeroed with a select, never a branch. In a periodic box a run met through an image
//! shifts the i-cluster instead: `CLUSTER · D` subtractions per run, none per pair.

use super::layout::{CLUSTER, Layout, group_of};
use super::list::Part;
use crate::kernels::images::{Images, no_shift};
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

/// Where the forces of a part go: padded slot `s` at `near[d][s - near_base]`, or from
/// `far_base` on (the clusters a part reaches across the faces, see [`Part::far`]) at
/// `far[d][s - far_base]`.
pub(crate) struct Out<'a, T, const D: usize> {
    pub near: [&'a mut [T]; D],
    pub near_base: usize,
    pub far: [&'a mut [T]; D],
    pub far_base: usize,
}

impl<'a, T, const D: usize> Out<'a, T, D> {
    /// Every padded slot, `out[d][s]`.
    pub fn whole(out: [&'a mut [T]; D]) -> Self {
        Out {
            near: out,
            near_base: 0,
            far: std::array::from_fn(|_| &mut [][..]),
            far_base: usize::MAX,
        }
    }

    /// The `R` forces along axis `d` of the run from padded slot `js`.
    #[inline(always)]
    pub(super) fn run<const R: usize>(&mut self, d: usize, js: usize) -> &mut [T; R] {
        let (out, at) = match js >= self.far_base {
            true => (&mut self.far[d], js - self.far_base),
            false => (&mut self.near[d], js - self.near_base),
        };
        (&mut out[at..at + R]).try_into().expect("runs are whole")
    }
}

/// [`part_forces`] with the runs of `D` dimensions.
#[inline(always)]
pub(crate) fn run_forces<T: Real, L: PairLaw<T>, const D: usize, const PROBE: bool>(
    law: &L,
    clusters: &Clusters<'_, T, D>,
    part: &Part,
    images: Option<&Images<T, D>>,
    out: &mut Out<'_, T, D>,
) -> TileSum {
    match group_of(D) * CLUSTER {
        8 => part_forces::<T, L, D, PROBE, 8>(law, clusters, part, images, out),
        _ => part_forces::<T, L, D, PROBE, LANES>(law, clusters, part, images, out),
    }
}

/// Adds the forces of the runs of `part` to `out`, each run through its image of `images` in
/// a periodic box: both ends of every pair, each pair once.
#[inline(always)]
pub(crate) fn part_forces<
    T: Real,
    L: PairLaw<T>,
    const D: usize,
    const PROBE: bool,
    const R: usize,
>(
    law: &L,
    clusters: &Clusters<'_, T, D>,
    part: &Part,
    images: Option<&Images<T, D>>,
    out: &mut Out<'_, T, D>,
) -> TileSum {
    let (pos, src) = (&clusters.pos, clusters.src);
    let unshifted = no_shift::<D>();
    let mut energy = [T::zero(); R];
    let mut interacting = [0u32; R];
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
        let mut fi = [[[T::zero(); R]; D]; CLUSTER];
        for r in part.first[k] as usize..part.first[k + 1] as usize {
            let js = part.start[r] as usize * CLUSTER;
            let masks = &part.masks[r];
            let xj: [&[T; R]; D] =
                std::array::from_fn(|d| pos[d][js..js + R].try_into().expect("runs are whole"));
            let sj: &[T; R] = src[js..js + R].try_into().expect("runs are whole");
            // The i-cluster moved by minus the run's shift: each pair's difference is then
            // the partner's image's.
            let xs: [[T; CLUSTER]; D] = match images {
                Some(im) if part.shift[r] != unshifted => {
                    let s = im.shift_of(part.shift[r]);
                    std::array::from_fn(|d| xi[d].map(|x| x - s[d]))
                }
                _ => xi,
            };
            let mut fj = [[T::zero(); R]; D];
            for a in 0..CLUSTER {
                let mut dx = [[T::zero(); R]; D];
                let mut r2 = [T::zero(); R];
                for d in 0..D {
                    for l in 0..R {
                        dx[d][l] = xj[d][l] - xs[d][a];
                        r2[l] += dx[d][l] * dx[d][l];
                    }
                }
                let mut coeff = [T::zero(); R];
                for l in 0..R {
                    let keep = (masks[a] >> l) & 1 != 0;
                    coeff[l] = select(keep, law.coeff(r2[l], si[a], sj[l]), T::zero());
                }
                for d in 0..D {
                    for l in 0..R {
                        let f = coeff[l] * dx[d][l];
                        fi[a][d][l] += f;
                        fj[d][l] += f;
                    }
                }
                if PROBE {
                    for l in 0..R {
                        let keep = (masks[a] >> l) & 1 != 0;
                        energy[l] += select(keep, law.energy(r2[l], si[a], sj[l]), T::zero());
                        interacting[l] += u32::from(keep && law.interacts(r2[l]));
                    }
                }
            }
            for d in 0..D {
                let dst = out.run::<R>(d, js);
                for l in 0..R {
                    dst[l] -= fj[d][l];
                }
            }
        }
        for a in 0..CLUSTER {
            for d in 0..D {
                out.near[d][ic - out.near_base + a] += lane_sum(fi[a][d]);
            }
        }
    }
    TileSum {
        energy: energy.iter().map(|e| e.as_f64()).sum(),
        interacting: interacting.iter().map(|&c| c as u64).sum(),
    }
}
