//! Truncated Lennard-Jones: `V(r) = 4ε[(σ/r)¹² − (σ/r)⁶] = 4ε·u(u − 1)` with `u = (σ/r)⁶`, for `r < rc`.

use super::{LawKind, PairLaw};
use crate::real::{Real, select};

/// σ of the LJ scenarios (the LJ-box assignment's length unit), and the scale of the kernels'
/// distance defaults (the Verlet skin).
pub const LJ_SIGMA: f64 = 0.01;

/// Lennard-Jones with a cutoff. The force is truncated (not shifted); the energy used for
/// monitoring is shifted by `V(rc)` so that it stays continuous when pairs cross the cutoff.
#[derive(Clone, Copy, Debug)]
pub struct LennardJones<T> {
    epsilon24: T,
    epsilon4: T,
    sigma2: T,
    rc: T,
    rc2: T,
    /// `u(u − 1)` at the cutoff, for the energy shift.
    shift: T,
    /// (ε, σ, rc) as given, to rebuild the law in another precision.
    params: (f64, f64, f64),
}

impl<T: Real> LennardJones<T> {
    /// The law with well depth `epsilon`, particle size `sigma` and cutoff radius `rc` (length
    /// units).
    pub fn new(epsilon: f64, sigma: f64, rc: f64) -> Self {
        let uc = (sigma * sigma / (rc * rc)).powi(3);
        LennardJones {
            epsilon24: T::of(24.0 * epsilon),
            epsilon4: T::of(4.0 * epsilon),
            sigma2: T::of(sigma * sigma),
            rc: T::of(rc),
            rc2: T::of(rc * rc),
            shift: T::of(uc * (uc - 1.0)),
            params: (epsilon, sigma, rc),
        }
    }
}

impl<T: Real> PairLaw<T> for LennardJones<T> {
    type Wide = LennardJones<f64>;

    fn widen(&self) -> LennardJones<f64> {
        let (e, s, rc) = self.params;
        LennardJones::new(e, s, rc)
    }

    fn parameters(&self) -> super::LawParameters {
        let (epsilon, sigma, rc) = self.params;
        super::LawParameters::LennardJones { epsilon, sigma, rc }
    }

    fn kind(&self) -> LawKind {
        LawKind::LennardJones
    }

    #[inline(always)]
    fn coeff(&self, r2: T, _si: T, _sj: T) -> T {
        let ir2 = T::one() / r2;
        let s = self.sigma2 * ir2;
        let u = s * s * s;
        let c = self.epsilon24 * ir2 * u * (T::one() - (u + u));
        select(r2 < self.rc2, c, T::zero())
    }

    #[inline(always)]
    fn energy(&self, r2: T, _si: T, _sj: T) -> T {
        let s = self.sigma2 / r2;
        let u = s * s * s;
        select(
            r2 < self.rc2,
            self.epsilon4 * (u * (u - T::one()) - self.shift),
            T::zero(),
        )
    }

    #[inline(always)]
    fn interacts(&self, r2: T) -> bool {
        r2 < self.rc2
    }

    fn cutoff(&self) -> Option<T> {
        Some(self.rc)
    }

    fn softening2(&self) -> T {
        T::zero()
    }

    fn lennard_jones(&self) -> Option<super::LennardJonesTerms<T>> {
        Some(super::LennardJonesTerms {
            epsilon24: self.epsilon24,
            sigma2: self.sigma2,
            rc2: self.rc2,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::physics::fd;

    #[test]
    fn force_is_minus_gradient_of_energy() {
        let lj = LennardJones::<f64>::new(1.0, 0.01, 0.025);
        for r in [0.009, 0.0105, 0.0112, 0.015, 0.02, 0.0249] {
            fd::check(&lj, r, 1.0, 1.0, 1e-6);
        }
    }

    #[test]
    fn closed_form_values() {
        let lj = LennardJones::<f64>::new(1.0, 1.0, 2.5);
        // Force vanishes at the minimum r = 2^(1/6) σ and is repulsive inside it.
        let rmin = 2f64.powf(1.0 / 6.0);
        assert!(lj.coeff(rmin * rmin, 1.0, 1.0).abs() < 1e-12);
        assert!(lj.coeff(0.9, 1.0, 1.0) < 0.0);
        assert!(lj.coeff(1.5 * 1.5, 1.0, 1.0) > 0.0);
        // Unshifted V(σ) = 0, so the shifted energy at σ is minus the shift; V(r_min) = −ε.
        let uc = 2.5f64.powi(-6);
        assert!((lj.energy(1.0, 1.0, 1.0) + 4.0 * uc * (uc - 1.0)).abs() < 1e-15);
        assert!((lj.energy(rmin * rmin, 1.0, 1.0) + 1.0 + 4.0 * uc * (uc - 1.0)).abs() < 1e-12);
        // Nothing at or beyond the cutoff.
        assert_eq!(lj.coeff(2.5 * 2.5, 1.0, 1.0), 0.0);
        assert_eq!(lj.energy(3.0 * 3.0, 1.0, 1.0), 0.0);
        assert!(lj.energy(2.4999 * 2.4999, 1.0, 1.0).abs() < 1e-5);
    }

    #[test]
    fn f32_matches_f64() {
        let a = LennardJones::<f32>::new(1.0, 0.01, 0.025);
        let b = LennardJones::<f64>::new(1.0, 0.01, 0.025);
        let r2 = 0.0121f64 * 0.0121;
        let (ca, cb) = (a.coeff(r2 as f32, 1.0, 1.0) as f64, b.coeff(r2, 1.0, 1.0));
        assert!((ca - cb).abs() / cb.abs() < 1e-5);
    }
}
