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

    fn of(x: f64) -> Self;
    fn as_f64(self) -> f64;
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
}

/// Selects `a` where `cond` holds, else `b`, written so that LLVM emits a blend, not a branch.
#[inline(always)]
pub fn select<T: Real>(cond: bool, a: T, b: T) -> T {
    if cond { a } else { b }
}
