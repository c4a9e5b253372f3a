//! The i-parallel pair loop: a tile of up to `LANES` targets held in SIMD lanes, and every
//! source broadcast to all of them (the layout of GRAPE-style CPU kernels).
//!
//! Against the gather form of [`rows`](super::rows) (one target, sources in lanes) it needs no
//! sum across lanes, no block masks and no scalar tail: each source is four broadcast loads,
//! and the targets' positions and forces stay in registers for the whole run. Each target's
//! force is summed over the sources in order, so a target gets the same bits whichever lane
//! or tile it is in, and so at every thread count. Timed steps only: the probe keeps the
//! gather form, which also sums energies and counts interactions.

mod batched;

use super::rows::{LANES, Sources};
use crate::physics::PairLaw;
use crate::real::{Real, select};

/// Up to `LANES` targets: positions and strengths by lane. Lanes past the real targets repeat
/// the first target's position with zero strength, so they stay finite and are ignored.
pub(crate) struct Tile<T, const D: usize> {
    pub x: [[T; LANES]; D],
    pub s: [T; LANES],
}

impl<T: Real, const D: usize> Tile<T, D> {
    /// Targets `lo..hi` (at most `LANES`, at least one) of the given arrays.
    #[inline(always)]
    pub fn load(pos: &[Vec<T>; D], s: &[T], lo: usize, hi: usize) -> Self {
        let len = hi - lo;
        debug_assert!(len > 0 && len <= LANES);
        Tile {
            x: std::array::from_fn(|d| {
                std::array::from_fn(|l| pos[d][if l < len { lo + l } else { lo }])
            }),
            s: std::array::from_fn(|l| if l < len { s[lo + l] } else { T::zero() }),
        }
    }
}

/// The force on each of the tile's targets from every source of `src`, except that lane `l`
/// skips source `own + l` (its own slot, when the targets are also sources; `usize::MAX` when
/// none is).
#[inline(always)]
pub(crate) fn tile_forces<T: Real, L: PairLaw<T>, const D: usize>(
    law: &L,
    tile: &Tile<T, D>,
    src: &Sources<'_, T, D>,
    own: usize,
) -> [[T; LANES]; D] {
    if let Some(p) = law.inverse_square()
        && let Some(force) = batched::forces(&p, tile, src, own)
    {
        return force;
    }
    let n = src.len();
    // Any `own` at or past the run means no lane's slot is in it; clamped, `j − own` wraps to
    // far past the lanes for every j (unclamped, `usize::MAX` would wrap to j + 1).
    let own = own.min(n);
    let pos: [&[T]; D] = std::array::from_fn(|d| &src.pos[d][..n]);
    let s = &src.s[..n];
    let mut force = [[T::zero(); LANES]; D];
    for j in 0..n {
        let xj: [T; D] = std::array::from_fn(|d| pos[d][j]);
        let sj = s[j];
        // Lane `j − own` is the one whose own slot this is (none when it is ≥ LANES).
        let self_lane = j.wrapping_sub(own);
        let mut dx = [[T::zero(); LANES]; D];
        let mut r2 = [T::zero(); LANES];
        for d in 0..D {
            for l in 0..LANES {
                dx[d][l] = xj[d] - tile.x[d][l];
                r2[l] += dx[d][l] * dx[d][l];
            }
        }
        for l in 0..LANES {
            let c = select(l != self_lane, law.coeff(r2[l], tile.s[l], sj), T::zero());
            for d in 0..D {
                force[d][l] += c * dx[d][l];
            }
        }
    }
    force
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::physics::{Coulomb, Gravity, pair_force};

    /// Every lane's force equals the sum over its sources but its own slot, for partial tiles
    /// and tiles overlapping the sources' start and end, in both laws; and the sum over every
    /// source when the targets are not among them (`own` = `usize::MAX`).
    #[test]
    fn tile_matches_the_pair_sum() {
        let n = 2 * LANES + 5;
        let pos: [Vec<f64>; 3] = std::array::from_fn(|d| {
            (0..n)
                .map(|j| ((j * (d + 3)) as f64 * 0.61).sin() * (1.0 + d as f64))
                .collect()
        });
        let s: Vec<f64> = (0..n)
            .map(|j| if j % 3 == 0 { -1.0 } else { 1.5 })
            .collect();
        let src = Sources::range(&pos, &s, 0, n);
        let check =
            |law: &dyn Fn([f64; 3], f64, f64) -> [f64; 3], got: [[f64; LANES]; 3], lo, len| {
                for l in 0..len {
                    let i: usize = lo + l;
                    let mut want = [0.0; 3];
                    for j in (0..n).filter(|&j| j != i) {
                        let dx = std::array::from_fn(|d| pos[d][j] - pos[d][i]);
                        let f = law(dx, s[i], s[j]);
                        (0..3).for_each(|d| want[d] += f[d]);
                    }
                    for d in 0..3 {
                        let scale = want.iter().map(|w| w.abs()).sum::<f64>();
                        assert!((got[d][l] - want[d]).abs() <= 1e-13 * scale, "target {i}");
                    }
                }
            };
        let gravity = Gravity::<f64>::new(1.0, 0.0);
        let coulomb = Coulomb::<f64>::new(1e-3);
        for (lo, hi) in [(0, LANES), (3, 3 + LANES), (n - 7, n), (LANES, LANES + 1)] {
            let tile = Tile::load(&pos, &s, lo, hi);
            let g = tile_forces(&gravity, &tile, &src, lo);
            check(&|dx, a, b| pair_force(&gravity, dx, a, b), g, lo, hi - lo);
            let c = tile_forces(&coulomb, &tile, &src, lo);
            check(&|dx, a, b| pair_force(&coulomb, dx, a, b), c, lo, hi - lo);
        }
        // Targets that are not sources: every source acts on every lane.
        let far: [Vec<f64>; 3] = std::array::from_fn(|d| pos[d].iter().map(|x| x + 7.0).collect());
        let tile = Tile::load(&far, &s, 0, LANES);
        let got = tile_forces(&gravity, &tile, &src, usize::MAX);
        for l in 0..LANES {
            let mut want = [0.0; 3];
            for j in 0..n {
                let dx: [f64; 3] = std::array::from_fn(|d| pos[d][j] - far[d][l]);
                let f = pair_force(&gravity, dx, s[l], s[j]);
                (0..3).for_each(|d| want[d] += f[d]);
            }
            let scale = want.iter().map(|w| w.abs()).sum::<f64>();
            for d in 0..3 {
                assert!((got[d][l] - want[d]).abs() <= 1e-13 * scale, "lane {l}");
            }
        }
    }
}
