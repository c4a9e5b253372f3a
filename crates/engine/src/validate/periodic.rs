//! The reference of the periodic kernels: the direct pair sum in f64 through each pair's
//! nearest image, written apart from every kernel's image search so that it checks them.

use crate::physics::{PairLaw, pair_force};
use crate::state::{Field, State, zero_field};

/// Why a periodic reference cannot be summed by nearest images.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum PeriodicReferenceError {
    /// The law has no cutoff: every image interacts, which takes a lattice sum (Ewald), not a
    /// nearest-image one.
    #[error("the law has no cutoff: a periodic sum of it needs every image, not the nearest")]
    NoCutoff,
    /// A side is not more than twice the cutoff, so a pair can interact through two images.
    #[error(
        "side {side} of the periodic box is not more than twice the cutoff {rc}: a pair would \
         interact through more than one image; use more particles or a larger box"
    )]
    BoxTooSmall {
        /// The side at fault.
        side: f64,
        /// The law's cutoff.
        rc: f64,
    },
}

/// The displacement `dx` taken to its nearest image in a periodic box of sides `side`.
#[inline]
pub fn nearest_image<const D: usize>(dx: [f64; D], side: [f64; D]) -> [f64; D] {
    std::array::from_fn(|d| dx[d] - side[d] * (dx[d] / side[d]).round())
}

/// The forces, the potential energy and, per particle, the sum of its pair forces' magnitudes
/// (the scale of the rounding error any summation order makes) of `state` in the periodic box
/// of sides `side`: each pair once, through its nearest image, in f64. Exact when every side is
/// more than twice the law's cutoff, which it checks.
pub fn periodic_reference_forces<L: PairLaw<f64>, const D: usize>(
    law: &L,
    state: &State<f64, D>,
    side: [f64; D],
) -> Result<(Field<f64, D>, f64, Vec<f64>), PeriodicReferenceError> {
    let rc = law.cutoff().ok_or(PeriodicReferenceError::NoCutoff)?;
    if let Some(&s) = side.iter().find(|&&s| s.is_nan() || s <= 2.0 * rc) {
        return Err(PeriodicReferenceError::BoxTooSmall { side: s, rc });
    }
    let n = state.len();
    let mut forces = zero_field::<f64, D>(n);
    let mut abs_sum = vec![0.0; n];
    let mut energy = 0.0;
    for i in 0..n {
        let xi = state.position(i);
        for j in i + 1..n {
            let dx = nearest_image(std::array::from_fn(|d| state.pos[d][j] - xi[d]), side);
            let (si, sj) = (state.source[i], state.source[j]);
            let f = pair_force(law, dx, si, sj);
            let r2: f64 = dx.iter().map(|x| x * x).sum();
            energy += law.energy(r2, si, sj);
            let magnitude = f.iter().map(|c| c * c).sum::<f64>().sqrt();
            abs_sum[i] += magnitude;
            abs_sum[j] += magnitude;
            for d in 0..D {
                forces[d][i] += f[d];
                forces[d][j] -= f[d];
            }
        }
    }
    Ok((forces, energy, abs_sum))
}

#[cfg(test)]
mod tests;
