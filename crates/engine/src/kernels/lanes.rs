//! The few vector operations the batched pair kernel needs, over the registers of one
//! instruction set and precision: AVX-512 (`zmm`) and AVX2 (`ymm`), f64 and f32.
//!
//! Each method is a thin `#[inline(always)]` wrapper of one or two intrinsics; it must only be
//! reached from code running under the matching `target_feature` ([`crate::simd::run_avx512`],
//! [`crate::simd::run_avx2`]), where the intrinsics inline into straight vector code. A batched
//! kernel is written once, generic over [`Lanes`], and run through [`isa`] and [`same`].

#[cfg(target_arch = "x86_64")]
use crate::physics::LennardJonesTerms;
#[cfg(target_arch = "x86_64")]
use crate::real::Real;
use crate::simd::{SimdLevel, level};
#[cfg(target_arch = "x86_64")]
use num_traits::One;
use std::any::TypeId;
#[cfg(target_arch = "x86_64")]
use std::arch::x86_64::*;

/// The instruction set the batched kernels run with on this machine.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Isa {
    Avx512,
    Avx2,
}

/// The batched kernels' instruction set here; `None` at the baseline (and off x86-64), where
/// the portable loops run instead.
#[inline(always)]
pub(crate) fn isa() -> Option<Isa> {
    match level() {
        SimdLevel::Avx512 if cfg!(target_arch = "x86_64") => Some(Isa::Avx512),
        SimdLevel::Avx2 if cfg!(target_arch = "x86_64") => Some(Isa::Avx2),
        _ => None,
    }
}

/// Every instruction set with batched kernels that this machine can run, for tests that
/// compare each with the portable loops.
#[cfg(test)]
pub(crate) fn isas_here() -> Vec<Isa> {
    match level() {
        SimdLevel::Avx512 => vec![Isa::Avx512, Isa::Avx2],
        SimdLevel::Avx2 => vec![Isa::Avx2],
        SimdLevel::Baseline => vec![],
    }
}

/// Whether the generic `T` is `U` (to pick a kernel's precision).
#[inline(always)]
pub(crate) fn is<T: 'static, U: 'static>() -> bool {
    TypeId::of::<T>() == TypeId::of::<U>()
}

/// `a` as a `B`.
///
/// # Safety
/// `A` and `B` must be the same type (as [`is`] says), differing only in how the caller
/// names them.
#[inline(always)]
pub(crate) unsafe fn same<A, B>(a: &A) -> &B {
    // SAFETY: the same type, so the same layout and validity.
    unsafe { &*(a as *const A).cast::<B>() }
}

/// `a` as a mutable `B`.
///
/// # Safety
/// As [`same`]: `A` and `B` must be the same type.
#[inline(always)]
pub(crate) unsafe fn same_mut<A, B>(a: &mut A) -> &mut B {
    // SAFETY: the same type, so the same layout and validity.
    unsafe { &mut *(a as *mut A).cast::<B>() }
}

/// One register of `WIDTH` lanes of `Elem`.
///
/// # Safety
/// Every method needs the CPU features of its implementation; callers run them only inside a
/// function that enables those features, after `simd::level()` has checked the CPU.
pub(super) unsafe trait Lanes: Copy {
    type Elem: Copy;
    const WIDTH: usize;
    unsafe fn splat(x: Self::Elem) -> Self;
    /// `WIDTH` elements from `p` (no alignment needed).
    unsafe fn load(p: *const Self::Elem) -> Self;
    unsafe fn store(self, p: *mut Self::Elem);
    unsafe fn add(self, b: Self) -> Self;
    unsafe fn sub(self, b: Self) -> Self;
    unsafe fn mul(self, b: Self) -> Self;
    /// `self · b + c`, rounded once.
    unsafe fn mul_add(self, b: Self, c: Self) -> Self;
    /// `c − self · b`, rounded once.
    unsafe fn neg_mul_add(self, b: Self, c: Self) -> Self;
    /// `1/√self` to within a few units in the last place: the hardware estimate, refined by
    /// Newton steps (each squares the relative error and multiplies it by 1.5).
    unsafe fn rsqrt(self) -> Self;
    /// `self`, with zeros in the lanes where `a < b`.
    unsafe fn zero_where_less(self, a: Self, b: Self) -> Self;
    /// `self`, with zeros in the lanes where `a == b`.
    unsafe fn zero_where_equal(self, a: Self, b: Self) -> Self;
    /// `self` in the lanes where `a < b`, zeros elsewhere (also where either is NaN).
    unsafe fn keep_where_less(self, a: Self, b: Self) -> Self;
    /// `self / b`, correctly rounded.
    unsafe fn div(self, b: Self) -> Self;
    /// `x` in every lane.
    unsafe fn constant(x: f64) -> Self;
    /// `scale · self^{−3/2}` to within a few units in the last place: the hardware estimate y
    /// of `1/√self` and, with `e = 1 − self · y²`, the series
    /// `y³ (1 − e)^{−3/2} = y³ (1 + 3/2 e + 15/8 e² + 35/16 e³ + …)` cut where the next term
    /// is below rounding (fewer operations than Newton steps followed by the cube).
    unsafe fn rsqrt_cubed_scaled(self, scale: Self) -> Self;
}

/// Truncated Lennard-Jones over the lanes of `V`: `24ε u (1 − 2u) / r²` with `u = (σ²/r²)³`,
/// zero from the cutoff on (and where `r²` is NaN).
#[cfg(target_arch = "x86_64")]
pub(super) struct LennardJonesLanes<V> {
    epsilon24: V,
    sigma2: V,
    rc2: V,
    one: V,
}

#[cfg(target_arch = "x86_64")]
impl<V: Lanes> LennardJonesLanes<V>
where
    V::Elem: Real,
{
    /// # Safety
    /// The caller must have `V`'s features.
    #[inline(always)]
    pub(super) unsafe fn new(t: &LennardJonesTerms<V::Elem>) -> Self {
        // SAFETY: the caller's features.
        unsafe {
            LennardJonesLanes {
                epsilon24: V::splat(t.epsilon24),
                sigma2: V::splat(t.sigma2),
                rc2: V::splat(t.rc2),
                one: V::splat(V::Elem::one()),
            }
        }
    }

    /// The coefficients at squared distances `r2`: the operations of `LennardJones::coeff`,
    /// in its order, the division correctly rounded.
    ///
    /// # Safety
    /// The caller must have `V`'s features.
    #[inline(always)]
    pub(super) unsafe fn at(&self, r2: V) -> V {
        // SAFETY: the caller's features.
        unsafe {
            let ir2 = self.one.div(r2);
            let s = self.sigma2.mul(ir2);
            let u = s.mul(s).mul(s);
            let c = self.epsilon24.mul(ir2).mul(u).mul(self.one.sub(u.add(u)));
            c.keep_where_less(r2, self.rc2)
        }
    }
}

/// Coefficients of `(1 − e)^{−3/2} = Σ_k C_k e^k`: `C_k = C_{k−1} (2k + 1) / (2k)`.
const CUBE_SERIES: [f64; 6] = [1.0, 1.5, 1.875, 2.1875, 2.4609375, 2.70703125];

/// `scale · x^{−3/2}` from the estimate `y` of `1/√x`, the series cut after `TERMS` powers
/// of `e = 1 − x y²`: the relative error is about `C_{TERMS+1} |e|^{TERMS+1}`.
#[inline(always)]
unsafe fn cube_series<V: Lanes, const TERMS: usize>(x: V, y: V, scale: V) -> V {
    // SAFETY: the caller runs with V's features.
    unsafe {
        let y2 = y.mul(y);
        let e = x.neg_mul_add(y2, V::constant(1.0));
        let y3 = y2.mul(y.mul(scale));
        let mut p = V::constant(CUBE_SERIES[TERMS]);
        for k in (0..TERMS).rev() {
            p = e.mul_add(p, V::constant(CUBE_SERIES[k]));
        }
        y3.mul(p)
    }
}

/// One Newton step towards `1/√x` from `y`, with `half = x/2`: `y · (3/2 − half · y²)`.
#[inline(always)]
unsafe fn newton<V: Lanes>(y: V, half: V, three_halves: V) -> V {
    // SAFETY: the caller runs with V's features.
    unsafe { y.mul(half.neg_mul_add(y.mul(y), three_halves)) }
}

macro_rules! lanes {
    ($name:ident, $reg:ty, $elem:ty, $width:expr,
     splat $splat:ident, load $load:ident, store $store:ident, add $add:ident, sub $sub:ident, mul $mul:ident,
     fma $fma:ident, fnma $fnma:ident, rsqrt |$x:ident| $rsqrt:expr, newton_steps $steps:expr,
     less |$a:ident, $b:ident, $v:ident| $less:expr, equal |$ea:ident, $eb:ident, $ev:ident| $equal:expr,
     keep_less |$ka:ident, $kb:ident, $kv:ident| $keep_less:expr, div $div:ident,
     cube_terms $terms:expr) => {
        #[cfg(target_arch = "x86_64")]
        #[derive(Clone, Copy)]
        pub(super) struct $name(pub(super) $reg);

        // SAFETY: every method is an intrinsic of the features named in the entry point that
        // instantiates this type.
        #[cfg(target_arch = "x86_64")]
        unsafe impl Lanes for $name {
            type Elem = $elem;
            const WIDTH: usize = $width;
            #[inline(always)]
            unsafe fn splat(x: $elem) -> Self {
                unsafe { $name($splat(x)) }
            }
            #[inline(always)]
            unsafe fn load(p: *const $elem) -> Self {
                unsafe { $name($load(p)) }
            }
            #[inline(always)]
            unsafe fn store(self, p: *mut $elem) {
                unsafe { $store(p, self.0) }
            }
            #[inline(always)]
            unsafe fn add(self, b: Self) -> Self {
                unsafe { $name($add(self.0, b.0)) }
            }
            #[inline(always)]
            unsafe fn sub(self, b: Self) -> Self {
                unsafe { $name($sub(self.0, b.0)) }
            }
            #[inline(always)]
            unsafe fn mul(self, b: Self) -> Self {
                unsafe { $name($mul(self.0, b.0)) }
            }
            #[inline(always)]
            unsafe fn mul_add(self, b: Self, c: Self) -> Self {
                unsafe { $name($fma(self.0, b.0, c.0)) }
            }
            #[inline(always)]
            unsafe fn neg_mul_add(self, b: Self, c: Self) -> Self {
                unsafe { $name($fnma(self.0, b.0, c.0)) }
            }
            #[inline(always)]
            unsafe fn rsqrt(self) -> Self {
                unsafe {
                    let $x = self.0;
                    let mut y: Self = $name($rsqrt);
                    let half = self.mul(Self::splat(0.5));
                    let three_halves = Self::splat(1.5);
                    for _ in 0..$steps {
                        y = newton(y, half, three_halves);
                    }
                    y
                }
            }
            #[inline(always)]
            unsafe fn zero_where_less(self, a: Self, b: Self) -> Self {
                unsafe {
                    let ($a, $b, $v) = (a.0, b.0, self.0);
                    $name($less)
                }
            }
            #[inline(always)]
            unsafe fn zero_where_equal(self, a: Self, b: Self) -> Self {
                unsafe {
                    let ($ea, $eb, $ev) = (a.0, b.0, self.0);
                    $name($equal)
                }
            }
            #[inline(always)]
            unsafe fn keep_where_less(self, a: Self, b: Self) -> Self {
                unsafe {
                    let ($ka, $kb, $kv) = (a.0, b.0, self.0);
                    $name($keep_less)
                }
            }
            #[inline(always)]
            unsafe fn div(self, b: Self) -> Self {
                unsafe { $name($div(self.0, b.0)) }
            }
            #[inline(always)]
            unsafe fn constant(x: f64) -> Self {
                unsafe { Self::splat(x as $elem) }
            }
            #[inline(always)]
            unsafe fn rsqrt_cubed_scaled(self, scale: Self) -> Self {
                unsafe {
                    let $x = self.0;
                    cube_series::<Self, $terms>(self, $name($rsqrt), scale)
                }
            }
        }
    };
}

// AVX-512: a 14-bit estimate (relative error below 2^-14); f64 takes two Newton steps
// (6.1e-5 → 5.6e-9 → 4.7e-17, rounding), f32 one (→ 5.6e-9, below its rounding). For the
// cube |e| < 2^-13: f64 cuts the series after e³ (2.5 e⁴ = 5.5e-16, two units in the last
// place), f32 after e (1.9 e² = 2.8e-8, below its rounding).
lanes!(Avx512F64, __m512d, f64, 8, 
    splat _mm512_set1_pd, load _mm512_loadu_pd, store _mm512_storeu_pd, add _mm512_add_pd, sub _mm512_sub_pd,
    mul _mm512_mul_pd, fma _mm512_fmadd_pd, fnma _mm512_fnmadd_pd, rsqrt |x| _mm512_rsqrt14_pd(x), newton_steps 2,
    less |a, b, v| _mm512_maskz_mov_pd(!_mm512_cmp_pd_mask::<_CMP_LT_OQ>(a, b), v),
    equal |a, b, v| _mm512_maskz_mov_pd(!_mm512_cmp_pd_mask::<_CMP_EQ_OQ>(a, b), v),
    keep_less |a, b, v| _mm512_maskz_mov_pd(_mm512_cmp_pd_mask::<_CMP_LT_OQ>(a, b), v), div _mm512_div_pd, cube_terms 3);
lanes!(Avx512F32, __m512, f32, 16, 
    splat _mm512_set1_ps, load _mm512_loadu_ps, store _mm512_storeu_ps, add _mm512_add_ps, sub _mm512_sub_ps,
    mul _mm512_mul_ps, fma _mm512_fmadd_ps, fnma _mm512_fnmadd_ps, rsqrt |x| _mm512_rsqrt14_ps(x), newton_steps 1,
    less |a, b, v| _mm512_maskz_mov_ps(!_mm512_cmp_ps_mask::<_CMP_LT_OQ>(a, b), v),
    equal |a, b, v| _mm512_maskz_mov_ps(!_mm512_cmp_ps_mask::<_CMP_EQ_OQ>(a, b), v),
    keep_less |a, b, v| _mm512_maskz_mov_ps(_mm512_cmp_ps_mask::<_CMP_LT_OQ>(a, b), v), div _mm512_div_ps, cube_terms 1);
// AVX2: the 12-bit f32 estimate (relative error below 1.5 · 2^-12 = 3.7e-4); f64 converts to
// f32 and back around it and takes three steps (→ 2.0e-7 → 6.0e-14 → rounding), f32 two
// (→ 2.0e-7 → rounding). The f32 estimate needs x in f32's normal range (1.2e-38 to 3.4e38).
// For the cube |e| < 7.4e-4: f64 cuts the series after e⁵ (2.9 e⁶ = 4.5e-19), f32 after e²
// (2.2 e³ = 8.8e-10).
lanes!(Avx2F64, __m256d, f64, 4, 
    splat _mm256_set1_pd, load _mm256_loadu_pd, store _mm256_storeu_pd, add _mm256_add_pd, sub _mm256_sub_pd,
    mul _mm256_mul_pd, fma _mm256_fmadd_pd, fnma _mm256_fnmadd_pd,
    rsqrt |x| _mm256_cvtps_pd(_mm_rsqrt_ps(_mm256_cvtpd_ps(x))), newton_steps 3,
    less |a, b, v| _mm256_andnot_pd(_mm256_cmp_pd::<_CMP_LT_OQ>(a, b), v),
    equal |a, b, v| _mm256_andnot_pd(_mm256_cmp_pd::<_CMP_EQ_OQ>(a, b), v),
    keep_less |a, b, v| _mm256_and_pd(_mm256_cmp_pd::<_CMP_LT_OQ>(a, b), v), div _mm256_div_pd, cube_terms 5);
lanes!(Avx2F32, __m256, f32, 8, 
    splat _mm256_set1_ps, load _mm256_loadu_ps, store _mm256_storeu_ps, add _mm256_add_ps, sub _mm256_sub_ps,
    mul _mm256_mul_ps, fma _mm256_fmadd_ps, fnma _mm256_fnmadd_ps, rsqrt |x| _mm256_rsqrt_ps(x), newton_steps 2,
    less |a, b, v| _mm256_andnot_ps(_mm256_cmp_ps::<_CMP_LT_OQ>(a, b), v),
    equal |a, b, v| _mm256_andnot_ps(_mm256_cmp_ps::<_CMP_EQ_OQ>(a, b), v),
    keep_less |a, b, v| _mm256_and_ps(_mm256_cmp_ps::<_CMP_LT_OQ>(a, b), v), div _mm256_div_ps, cube_terms 2);

/// One f64 in a "register": the portable form of a kernel written over [`Lanes`], for the
/// baseline instruction set (and other architectures). `mul_add` rounds once, as the vector
/// forms do (`f64::mul_add`).
#[derive(Clone, Copy)]
pub(super) struct Scalar(f64);

// SAFETY: plain f64 arithmetic, which every CPU runs.
unsafe impl Lanes for Scalar {
    type Elem = f64;
    const WIDTH: usize = 1;
    #[inline(always)]
    unsafe fn splat(x: f64) -> Self {
        Scalar(x)
    }
    #[inline(always)]
    unsafe fn load(p: *const f64) -> Self {
        // SAFETY: the caller passes a pointer to one readable f64.
        Scalar(unsafe { *p })
    }
    #[inline(always)]
    unsafe fn store(self, p: *mut f64) {
        // SAFETY: the caller passes a pointer to one writable f64.
        unsafe { *p = self.0 }
    }
    #[inline(always)]
    unsafe fn add(self, b: Self) -> Self {
        Scalar(self.0 + b.0)
    }
    #[inline(always)]
    unsafe fn sub(self, b: Self) -> Self {
        Scalar(self.0 - b.0)
    }
    #[inline(always)]
    unsafe fn mul(self, b: Self) -> Self {
        Scalar(self.0 * b.0)
    }
    #[inline(always)]
    unsafe fn mul_add(self, b: Self, c: Self) -> Self {
        Scalar(self.0.mul_add(b.0, c.0))
    }
    #[inline(always)]
    unsafe fn neg_mul_add(self, b: Self, c: Self) -> Self {
        Scalar((-self.0).mul_add(b.0, c.0))
    }
    #[inline(always)]
    unsafe fn rsqrt(self) -> Self {
        Scalar(1.0 / self.0.sqrt())
    }
    #[inline(always)]
    unsafe fn zero_where_less(self, a: Self, b: Self) -> Self {
        Scalar(if a.0 < b.0 { 0.0 } else { self.0 })
    }
    #[inline(always)]
    unsafe fn zero_where_equal(self, a: Self, b: Self) -> Self {
        Scalar(if a.0 == b.0 { 0.0 } else { self.0 })
    }
    #[inline(always)]
    unsafe fn keep_where_less(self, a: Self, b: Self) -> Self {
        Scalar(if a.0 < b.0 { self.0 } else { 0.0 })
    }
    #[inline(always)]
    unsafe fn div(self, b: Self) -> Self {
        Scalar(self.0 / b.0)
    }
    #[inline(always)]
    unsafe fn constant(x: f64) -> Self {
        Scalar(x)
    }
    #[inline(always)]
    unsafe fn rsqrt_cubed_scaled(self, scale: Self) -> Self {
        Scalar(scale.0 / (self.0 * self.0.sqrt()))
    }
}
