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

/// Per particle, how much its force may change when each of its pairs' distances is off by up
/// to `delta`: the sum over its pairs within the cutoff (and `delta`) of the larger change of
/// the pair force at `r ± delta`, in f64.
///
/// In a box of side L a pair through a face is summed from coordinates near L: the image's
/// position (or the displacement before its wrap) is rounded to the precision's ulp of L, not
/// of the pair's distance. Kernels that shift the partner (lists, ghosts) and naive, which
/// wraps the displacement, round differently, so in f32 a box many cutoffs wide separates them
/// by more than the summation order does: by this much at most, for `delta` the two roundings'
/// bound ([`image_rounding_delta`]).
pub fn image_rounding<L: PairLaw<f64>, const D: usize>(
    law: &L,
    state: &State<f64, D>,
    side: [f64; D],
    delta: f64,
) -> Vec<f64> {
    let n = state.len();
    let mut out = vec![0.0; n];
    let Some(rc) = law.cutoff() else { return out };
    let reach2 = (rc + delta) * (rc + delta);
    for i in 0..n {
        let xi = state.position(i);
        for j in i + 1..n {
            let dx = nearest_image(std::array::from_fn(|d| state.pos[d][j] - xi[d]), side);
            let r2: f64 = dx.iter().map(|x| x * x).sum();
            if r2 >= reach2 || r2 == 0.0 {
                continue;
            }
            let (si, sj) = (state.source[i], state.source[j]);
            let f = pair_force(law, dx, si, sj);
            let r = r2.sqrt();
            let change = |scale: f64| {
                let g = pair_force(law, dx.map(|x| x * scale), si, sj);
                (0..D).map(|d| (g[d] - f[d]).powi(2)).sum::<f64>().sqrt()
            };
            let worst = change((r + delta) / r).max(change(((r - delta) / r).max(0.5)));
            out[i] += worst;
            out[j] += worst;
        }
    }
    out
}

/// The bound on the two roundings of a pair's displacement through a face, in a precision of
/// machine epsilon `epsilon`, in the box `[lo, hi)`: per axis, the partner's image (at most the
/// largest coordinate plus a side) rounded by one kernel and the unwrapped displacement (at most
/// a side) by naive, half an ulp each; over the `D` axes.
pub fn image_rounding_delta<const D: usize>(epsilon: f64, lo: [f64; D], hi: [f64; D]) -> f64 {
    let largest = (0..D)
        .map(|d| lo[d].abs().max(hi[d].abs()) + (hi[d] - lo[d]))
        .fold(0.0, f64::max);
    (D as f64).sqrt() * epsilon * largest
}

#[cfg(test)]
mod tests;
