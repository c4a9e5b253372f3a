//! `naive` in a periodic box: every target against the nearest image of every other particle.
//! It is the reference the periodic list kernels are checked against, so it is written
//! plainly: one rounding per pair and coordinate, no image search to share a bug with.

use crate::physics::PairLaw;
use crate::real::Real;
use crate::state::State;

/// The sides of a periodic box and their inverses, in the kernel's precision.
#[derive(Clone, Copy, Debug)]
pub(crate) struct PeriodicBox<T, const D: usize> {
    side: [T; D],
    inverse: [T; D],
}

impl<T: Real, const D: usize> PeriodicBox<T, D> {
    /// The box of sides `side` (each finite and > 0, which the boundary guarantees).
    pub(crate) fn new(side: [T; D]) -> Self {
        PeriodicBox {
            side,
            inverse: side.map(|s| T::one() / s),
        }
    }

    /// The displacement `dx` along axis `d` taken to its nearest image.
    #[inline(always)]
    fn image(&self, dx: T, d: usize) -> T {
        dx - self.side[d] * (dx * self.inverse[d]).round()
    }
}

/// What the rows of some targets add up to: their potential energy (each pair counted from
/// both ends) and the pairs that interact (likewise), when probing.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct Probed {
    pub energy: f64,
    pub interacting: u64,
}

/// Forces on targets `offset..offset + out.len()` from the nearest image of every other
/// particle of `state`.
#[inline(always)]
pub(crate) fn rows<T: Real, L: PairLaw<T>, const D: usize, const PROBE: bool>(
    law: &L,
    state: &State<T, D>,
    pbox: &PeriodicBox<T, D>,
    offset: usize,
    out: [&mut [T]; D],
) -> Probed {
    let n = state.len();
    let mut probed = Probed::default();
    for k in 0..out[0].len() {
        let i = offset + k;
        let xi = state.position(i);
        let si = state.source[i];
        let mut force = [T::zero(); D];
        let mut energy = T::zero();
        // The target's own slot is skipped by running the two sides of it.
        for j in (0..i).chain(i + 1..n) {
            let mut dx = [T::zero(); D];
            let mut r2 = T::zero();
            for d in 0..D {
                let v = pbox.image(state.pos[d][j] - xi[d], d);
                dx[d] = v;
                r2 += v * v;
            }
            let sj = state.source[j];
            let c = law.coeff(r2, si, sj);
            for d in 0..D {
                force[d] += c * dx[d];
            }
            if PROBE {
                energy += law.energy(r2, si, sj);
                probed.interacting += u64::from(law.interacts(r2));
            }
        }
        for d in 0..D {
            out[d][k] = force[d];
        }
        probed.energy += energy.as_f64();
    }
    probed
}
