//! Newtonian gravity with Plummer softening: force on i is `G m_i m_j (x_j − x_i) / (r² + ε²)^{3/2}`.

use super::{LawKind, PairLaw};
use crate::real::Real;

/// Newtonian gravity between masses (the per-particle source strengths), Plummer-softened.
#[derive(Clone, Copy, Debug)]
pub struct Gravity<T> {
    g: T,
    eps2: T,
    /// (G, ε) as given, to rebuild the law in another precision.
    params: (f64, f64),
}

impl<T: Real> Gravity<T> {
    /// The law with gravitational constant `g` and Plummer softening length `softening`.
    pub fn new(g: f64, softening: f64) -> Self {
        Gravity {
            g: T::of(g),
            eps2: T::of(softening * softening),
            params: (g, softening),
        }
    }
}

impl<T: Real> PairLaw<T> for Gravity<T> {
    type Wide = Gravity<f64>;

    fn widen(&self) -> Gravity<f64> {
        Gravity::new(self.params.0, self.params.1)
    }

    fn parameters(&self) -> super::LawParameters {
        super::LawParameters::Gravity {
            g: self.params.0,
            softening: self.params.1,
        }
    }

    fn kind(&self) -> LawKind {
        LawKind::Gravity
    }

    #[inline(always)]
    fn coeff(&self, r2: T, si: T, sj: T) -> T {
        let inv = (r2 + self.eps2).rsqrt();
        self.g * si * sj * inv * inv * inv
    }

    fn reference_coeff(&self, r2: T, si: T, sj: T) -> T {
        let inv = T::one() / (r2 + self.eps2).sqrt();
        self.g * si * sj * inv * inv * inv
    }

    #[inline(always)]
    fn energy(&self, r2: T, si: T, sj: T) -> T {
        -(self.g * si * sj) / (r2 + self.eps2).sqrt()
    }

    #[inline(always)]
    fn interacts(&self, _r2: T) -> bool {
        true
    }

    fn cutoff(&self) -> Option<T> {
        None
    }

    fn softening2(&self) -> T {
        self.eps2
    }

    fn inverse_square(&self) -> Option<super::InverseSquare<T>> {
        Some(super::InverseSquare {
            k: self.g,
            eps2: self.eps2,
            quench2: T::zero(),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::physics::fd;

    #[test]
    fn force_is_minus_gradient_of_energy() {
        for eps in [0.0, 0.05] {
            let g = Gravity::<f64>::new(1.0, eps);
            for r in [0.01, 0.1, 1.0, 7.5] {
                fd::check(&g, r, 2.0, 0.5, 1e-7);
            }
        }
    }

    #[test]
    fn attracts_with_inverse_square() {
        let g = Gravity::<f64>::new(1.0, 0.0);
        // |F| = m_i m_j / r² at r = 2: coeff·r = 1/4.
        assert!((g.coeff(4.0, 1.0, 1.0) * 2.0 - 0.25).abs() < 1e-15);
        // Softening bounds the force at r = 0.
        let soft = Gravity::<f64>::new(1.0, 0.1);
        assert!(soft.coeff(0.0, 1.0, 1.0).is_finite());
    }

    #[test]
    fn kernel_coefficient_matches_the_reference() {
        for eps in [0.0, 0.05] {
            let law = Gravity::<f64>::new(1.0, eps);
            for r2 in [1e-5, 3e-3, 0.2, 1.0, 7.5, 4e4] {
                let (fast, exact) = (law.coeff(r2, 1.5, -0.5), law.reference_coeff(r2, 1.5, -0.5));
                assert!(
                    (fast - exact).abs() <= 1e-15 * exact.abs(),
                    "r2 {r2}: {fast} vs {exact}"
                );
            }
        }
    }
}
