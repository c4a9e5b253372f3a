//! Coulomb: force on i is `q_i q_j (x_i − x_j) / r³`, zeroed (quenched) below `r = ε_q`.

use super::{LawKind, PairLaw};
use crate::real::{Real, select};

/// The Coulomb pair law between charges (the per-particle source strengths), quenched at short
/// range.
#[derive(Clone, Copy, Debug)]
pub struct Coulomb<T> {
    quench2: T,
    quench: f64,
}

impl<T: Real> Coulomb<T> {
    /// `quench` is the distance below which the force is zeroed, as in the source code.
    pub fn new(quench: f64) -> Self {
        Coulomb {
            quench2: T::of(quench * quench),
            quench,
        }
    }
}

impl<T: Real> PairLaw<T> for Coulomb<T> {
    type Wide = Coulomb<f64>;

    fn widen(&self) -> Coulomb<f64> {
        Coulomb::new(self.quench)
    }

    fn parameters(&self) -> super::LawParameters {
        super::LawParameters::Coulomb {
            quench: self.quench,
        }
    }

    fn kind(&self) -> LawKind {
        LawKind::Coulomb
    }

    #[inline(always)]
    fn coeff(&self, r2: T, si: T, sj: T) -> T {
        let inv = r2.rsqrt();
        // Like charges repel: the force points from j to i, i.e. a negative coefficient.
        select(r2 < self.quench2, T::zero(), -(si * sj) * inv * inv * inv)
    }

    fn reference_coeff(&self, r2: T, si: T, sj: T) -> T {
        let inv = T::one() / r2.sqrt();
        select(r2 < self.quench2, T::zero(), -(si * sj) * inv * inv * inv)
    }

    #[inline(always)]
    fn energy(&self, r2: T, si: T, sj: T) -> T {
        select(r2 < self.quench2, T::zero(), si * sj / r2.sqrt())
    }

    #[inline(always)]
    fn interacts(&self, r2: T) -> bool {
        r2 >= self.quench2
    }

    fn cutoff(&self) -> Option<T> {
        None
    }

    fn softening2(&self) -> T {
        T::zero()
    }

    fn inverse_square(&self) -> Option<super::InverseSquare<T>> {
        Some(super::InverseSquare {
            k: -T::one(),
            eps2: T::zero(),
            quench2: self.quench2,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::physics::fd;

    #[test]
    fn force_is_minus_gradient_of_energy() {
        let c = Coulomb::<f64>::new(1e-3);
        for r in [2e-3, 0.01, 0.3, 1.7] {
            fd::check(&c, r, 1.0, 1.0, 1e-7);
            fd::check(&c, r, 1.0, -1.0, 1e-7);
        }
    }

    #[test]
    fn like_charges_repel_and_quench_zeroes() {
        let c = Coulomb::<f64>::new(1e-3);
        assert!(c.coeff(0.25, 1.0, 1.0) < 0.0);
        assert!(c.coeff(0.25, 1.0, -1.0) > 0.0);
        assert_eq!(c.coeff(1e-7, 1.0, 1.0), 0.0);
        assert_eq!(c.coeff(0.0, 1.0, 1.0), 0.0);
        assert!((c.coeff(4.0, 1.0, 1.0) + 1.0 / 8.0).abs() < 1e-15);
    }

    #[test]
    fn kernel_coefficient_matches_the_reference() {
        let law = Coulomb::<f64>::new(1e-3);
        for r2 in [1e-5, 3e-3, 0.2, 1.0, 7.5, 4e4] {
            let (fast, exact) = (law.coeff(r2, 1.5, -0.5), law.reference_coeff(r2, 1.5, -0.5));
            assert!(
                (fast - exact).abs() <= 1e-15 * exact.abs(),
                "r2 {r2}: {fast} vs {exact}"
            );
        }
    }
}
