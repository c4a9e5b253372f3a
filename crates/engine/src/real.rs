//! The floating-point precision a simulation runs in.
//!
//! Kernels are generic over `Real` so that one source serves both `f32` (the LJ source's
//! precision, twice the SIMD lanes) and `f64` (the gravity and Coulomb sources').

use num_traits::Float;
use std::fmt::{Debug, Display};
use std::iter::Sum;
use std::ops::{AddAssign, MulAssign, SubAssign};

/// A floating-point type the engine can run in: `f32` or `f64`.
pub trait Real:
    Float
    + AddAssign
    + SubAssign
    + MulAssign
    + Sum
    + Debug
    + Display
    + std::fmt::LowerExp
    + Default
    + Send
    + Sync
    + 'static
{
    /// The name used in results and on the command line.
    const NAME: &'static str;
    /// Machine epsilon, as `f64`, for rounding-aware tolerances.
    const EPSILON_F64: f64;

    /// The nearest value of this type to `x` (rounds to nearest in f32).
    fn of(x: f64) -> Self;
    /// The value widened to f64 (exact).
    fn as_f64(self) -> f64;

    /// `1/√x` for `x > 0` to within a few units in the last place, from an integer estimate
    /// refined by Newton steps: multiplies and adds only, which vectorize at full width, where
    /// a square root and a division occupy the divider for tens of cycles per vector. The same
    /// operations at every instruction set, so every SIMD level gives the same bits (the
    /// batched 1/r² kernels, written with intrinsics, use the hardware's estimate instead).
    fn rsqrt(self) -> Self;
}

/// One Newton step towards `1/√x` from `y`, with `half = x/2`: the relative error e becomes
/// about 1.5·e².
#[inline(always)]
fn newton<T: Real>(y: T, half: T) -> T {
    y * (T::of(1.5) - half * y * y)
}

impl Real for f32 {
    const NAME: &'static str = "f32";
    const EPSILON_F64: f64 = f32::EPSILON as f64;
    #[inline(always)]
    fn of(x: f64) -> Self {
        x as f32
    }
    #[inline(always)]
    fn as_f64(self) -> f64 {
        self as f64
    }
    #[inline(always)]
    fn rsqrt(self) -> Self {
        // The classic estimate (relative error ≤ 3.5 %): 3.5e-2 → 1.8e-3 → 4.7e-6 → rounding.
        let half = 0.5 * self;
        let y = f32::from_bits(0x5f37_5a86 - (self.to_bits() >> 1));
        newton(newton(newton(y, half), half), half)
    }
}

impl Real for f64 {
    const NAME: &'static str = "f64";
    const EPSILON_F64: f64 = f64::EPSILON;
    #[inline(always)]
    fn of(x: f64) -> Self {
        x
    }
    #[inline(always)]
    fn as_f64(self) -> f64 {
        self
    }
    #[inline(always)]
    fn rsqrt(self) -> Self {
        // 3.5e-2 → 1.8e-3 → 4.7e-6 → 3.3e-11 → rounding.
        let half = 0.5 * self;
        let y = f64::from_bits(0x5fe6_eb50_c7b5_37a9 - (self.to_bits() >> 1));
        newton(newton(newton(newton(y, half), half), half), half)
    }
}

/// Selects `a` where `cond` holds, else `b`, written so that LLVM emits a blend, not a branch.
#[inline(always)]
pub fn select<T: Real>(cond: bool, a: T, b: T) -> T {
    if cond { a } else { b }
}

#[cfg(test)]
mod tests {
    use super::Real;

    /// Relative error of the reciprocal square root over many binades, in both precisions.
    fn check<T: Real>(ulps: f64) {
        let mut x = 1e-30_f64;
        while x < 1e30 {
            for k in 0..97 {
                let v = x * (1.0 + k as f64 / 97.0);
                let t = T::of(v);
                let want = 1.0 / t.as_f64().sqrt();
                let err = (t.rsqrt().as_f64() - want).abs() / want;
                assert!(
                    err <= ulps * T::EPSILON_F64,
                    "{} rsqrt({v}): {err:e}",
                    T::NAME
                );
            }
            x *= 10.0;
        }
    }

    #[test]
    fn reciprocal_square_root_is_accurate() {
        check::<f64>(2.0);
        check::<f32>(2.0);
    }
}
