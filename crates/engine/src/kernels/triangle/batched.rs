//! The batched Newton-3 loop: a cluster of `K` targets against a vector of sources at a time,
//! written once over [`Lanes`] for AVX-512 and AVX2 in both precisions (the layout of GROMACS's
//! 4xM cluster kernels, on the triangle instead of a pair list).
//!
//! Sources sit in the lanes, loaded straight from the position arrays; each target of the
//! cluster is broadcast. A pair's force goes to two register sums: the target's (one vector
//! per target and component, added across its lanes once per tile) and the sources' (one
//! vector per component, shared by the cluster's targets, added to the sources' forces in
//! memory once per vector of sources). The coefficients are those of the naive kernel's
//! batched loop: fused multiply-adds, the hardware reciprocal-square-root estimate refined by
//! Newton steps for a 1/r² law, a correctly rounded division for Lennard-Jones.
//!
//! Which lanes form pairs is decided by lane number: on the vector that holds the cluster,
//! target i0 + k meets only the sources past it; on the vector where the particles end, the
//! lanes past n are read from a padded copy and dropped. The sums run in a fixed order for a
//! given range of targets, so a range's forces are the same bits whoever computes them.

#[cfg(target_arch = "x86_64")]
use crate::kernels::lanes::{
    Avx2F32, Avx2F64, Avx512F32, Avx512F64, Isa, Lanes, LennardJonesLanes, is, isa, same, same_mut,
};
use crate::physics::{InverseSquare, LennardJonesTerms, PairLaw};
use crate::real::Real;
#[cfg(target_arch = "x86_64")]
use crate::simd::{run_avx2, run_avx512};
use crate::state::State;
use num_traits::Zero;
use std::ops::Range;

/// Adds the force of every pair (i, j) with i in `targets` and j > i to both ends in `out`, as
/// [`super::add`], by this machine's batched loop; `false`, with nothing done, where it has
/// none (the baseline instruction set, a law of another form).
#[inline(always)]
pub(super) fn add<T: Real, L: PairLaw<T>, const D: usize>(
    law: &L,
    state: &State<T, D>,
    targets: Range<usize>,
    out: &mut [&mut [T]; D],
) -> bool {
    #[cfg(target_arch = "x86_64")]
    if let Some(isa) = isa() {
        // SAFETY: `isa()` has checked the CPU for this instruction set.
        return unsafe { add_on(isa, law, state, targets, out) };
    }
    let _ = (law, state, targets, out);
    false
}

/// The forms of law the batched loop evaluates.
#[derive(Clone, Copy)]
enum Form<T> {
    InverseSquare(InverseSquare<T>),
    LennardJones(LennardJonesTerms<T>),
}

impl<T: Real> Form<T> {
    fn of<L: PairLaw<T>>(law: &L) -> Option<Self> {
        (law.inverse_square().map(Form::InverseSquare))
            .or_else(|| law.lennard_jones().map(Form::LennardJones))
    }
}

/// [`add`] with the instruction set given; `false` for a law or precision without a loop.
///
/// # Safety
/// The CPU must have the instruction set's features.
#[cfg(target_arch = "x86_64")]
#[inline(always)]
pub(super) unsafe fn add_on<T: Real, L: PairLaw<T>, const D: usize>(
    isa: Isa,
    law: &L,
    state: &State<T, D>,
    targets: Range<usize>,
    out: &mut [&mut [T]; D],
) -> bool {
    let Some(form) = Form::of(law) else {
        return false;
    };
    let pos: [&[T]; D] = std::array::from_fn(|d| state.pos[d].as_slice());
    let s = state.source.as_slice();
    // SAFETY (both blocks): `is` makes `T` the type the references are cast to, and the
    // caller has checked the CPU for the features `run_*` enables. The closures inline into
    // `run_*`, so that the loop is compiled with the features and its intrinsics inline. Clusters of four targets
    // where the registers hold their sums beside the sources (32 zmm), two in 16 ymm.
    if is::<T, f64>() {
        let (form, pos, s, out) = unsafe { (same(&form), same(&pos), same(&s), same_mut(out)) };
        unsafe {
            match isa {
                Isa::Avx512 => run_avx512(
                    #[inline(always)]
                    || by_form::<Avx512F64, D, 2>(form, pos, s, targets, out),
                ),
                Isa::Avx2 => run_avx2(
                    #[inline(always)]
                    || by_form::<Avx2F64, D, 2>(form, pos, s, targets, out),
                ),
            }
        }
        return true;
    }
    if is::<T, f32>() {
        let (form, pos, s, out) = unsafe { (same(&form), same(&pos), same(&s), same_mut(out)) };
        unsafe {
            match isa {
                Isa::Avx512 => run_avx512(
                    #[inline(always)]
                    || by_form::<Avx512F32, D, 4>(form, pos, s, targets, out),
                ),
                Isa::Avx2 => run_avx2(
                    #[inline(always)]
                    || by_form::<Avx2F32, D, 2>(form, pos, s, targets, out),
                ),
            }
        }
        return true;
    }
    false
}

/// The loop for the law's form. Runs `V`'s intrinsics: only under `V`'s features (a safe
/// function, so that it inlines into the closures of [`add_on`]).
#[cfg(target_arch = "x86_64")]
#[inline(always)]
fn by_form<V: Lanes, const D: usize, const K: usize>(
    form: &Form<V::Elem>,
    pos: &[&[V::Elem]; D],
    s: &&[V::Elem],
    targets: Range<usize>,
    out: &mut [&mut [V::Elem]; D],
) where
    V::Elem: Real,
{
    // SAFETY: the caller runs under `V`'s features.
    unsafe {
        match *form {
            Form::InverseSquare(p) if p.quench2 > V::Elem::zero() => {
                let law = InverseSquareLanes::<V, true>::new(&p);
                triangle::<V, _, D, K>(&law, pos, s, targets, out)
            }
            Form::InverseSquare(p) => {
                let law = InverseSquareLanes::<V, false>::new(&p);
                triangle::<V, _, D, K>(&law, pos, s, targets, out)
            }
            Form::LennardJones(t) => {
                let law = LennardJonesLanes::<V>::new(&t);
                triangle::<V, _, D, K>(&law, pos, s, targets, out)
            }
        }
    }
}

/// A pair law's coefficient over the lanes of `V`.
///
/// # Safety
/// Every method runs `V`'s intrinsics: the caller must have `V`'s features.
#[cfg(target_arch = "x86_64")]
unsafe trait Coefficient<V: Lanes> {
    /// Where the squared distance starts (ε² of a softened law, else zero).
    unsafe fn r2_start(&self) -> V;
    /// What target `i` brings to each of its pairs (k · s_i for a 1/r² law).
    unsafe fn target(&self, si: V::Elem) -> V;
    /// The coefficients at squared distances `r2` (from [`Coefficient::r2_start`]) of the
    /// sources `sj` with a target of term `ti`.
    unsafe fn coeff(&self, r2: V, sj: V, ti: V) -> V;
}

/// `k s_i s_j (r² + ε²)^{−3/2}`, with `QUENCH` zero where `r² + ε²` is below the quench
/// radius's square.
#[cfg(target_arch = "x86_64")]
struct InverseSquareLanes<V: Lanes, const QUENCH: bool> {
    k: V::Elem,
    eps2: V,
    quench2: V,
}

#[cfg(target_arch = "x86_64")]
impl<V: Lanes, const QUENCH: bool> InverseSquareLanes<V, QUENCH>
where
    V::Elem: Real,
{
    /// # Safety
    /// The caller must have `V`'s features.
    #[inline(always)]
    unsafe fn new(p: &InverseSquare<V::Elem>) -> Self {
        // SAFETY: the caller's features.
        unsafe {
            InverseSquareLanes {
                k: p.k,
                eps2: V::splat(p.eps2),
                quench2: V::splat(p.quench2),
            }
        }
    }
}

// SAFETY: each method is intrinsics of `V`, run under the caller's features.
#[cfg(target_arch = "x86_64")]
unsafe impl<V: Lanes, const QUENCH: bool> Coefficient<V> for InverseSquareLanes<V, QUENCH>
where
    V::Elem: Real,
{
    #[inline(always)]
    unsafe fn r2_start(&self) -> V {
        self.eps2
    }
    #[inline(always)]
    unsafe fn target(&self, si: V::Elem) -> V {
        unsafe { V::splat(self.k * si) }
    }
    #[inline(always)]
    unsafe fn coeff(&self, r2: V, sj: V, ti: V) -> V {
        unsafe {
            let c = r2.rsqrt_cubed_scaled(sj.mul(ti));
            if QUENCH {
                c.zero_where_less(r2, self.quench2)
            } else {
                c
            }
        }
    }
}

// SAFETY: each method is intrinsics of `V`, run under the caller's features.
#[cfg(target_arch = "x86_64")]
unsafe impl<V: Lanes> Coefficient<V> for LennardJonesLanes<V>
where
    V::Elem: Real,
{
    #[inline(always)]
    unsafe fn r2_start(&self) -> V {
        unsafe { V::splat(V::Elem::zero()) }
    }
    #[inline(always)]
    unsafe fn target(&self, _si: V::Elem) -> V {
        unsafe { V::splat(V::Elem::zero()) }
    }
    #[inline(always)]
    unsafe fn coeff(&self, r2: V, _sj: V, _ti: V) -> V {
        unsafe { self.at(r2) }
    }
}

/// Sources per tile: the sums of a cluster's targets are added across their lanes once per
/// tile, and a tile's positions and reaction sums (229 KB in f64 3-D) stay in L2.
#[cfg(target_arch = "x86_64")]
const TILE: usize = 4096;

/// Widest vector of any [`Lanes`] (16 f32 in a zmm): the size of the padded copies.
#[cfg(target_arch = "x86_64")]
const MAX_WIDTH: usize = 16;

/// The targets of a cluster, broadcast: positions and terms.
#[cfg(target_arch = "x86_64")]
struct Cluster<V, const D: usize, const K: usize> {
    x: [[V; D]; K],
    t: [V; K],
    /// Each lane's number within a vector of sources.
    lane: V,
}

/// Every pair of the targets `targets` with a later particle, tile by tile of sources.
///
/// # Safety
/// The caller must have `V`'s features; every array of `pos` and `out` has `s.len()` elements,
/// `targets` lies within them and starts at a multiple of `V::WIDTH`, and `K` divides
/// `V::WIDTH`.
#[cfg(target_arch = "x86_64")]
#[inline(always)]
unsafe fn triangle<V: Lanes, C: Coefficient<V>, const D: usize, const K: usize>(
    law: &C,
    pos: &[&[V::Elem]; D],
    s: &[V::Elem],
    targets: Range<usize>,
    out: &mut [&mut [V::Elem]; D],
) where
    V::Elem: Real,
{
    let n = s.len();
    debug_assert!(targets.start.is_multiple_of(V::WIDTH) && V::WIDTH.is_multiple_of(K));
    debug_assert!(targets.end <= n && (0..D).all(|d| pos[d].len() == n && out[d].len() == n));
    let mut numbers = [V::Elem::zero(); MAX_WIDTH];
    for (l, x) in numbers.iter_mut().enumerate() {
        *x = V::Elem::of(l as f64);
    }
    // SAFETY: the features are the caller's; `numbers` holds MAX_WIDTH ≥ WIDTH elements.
    let lane = unsafe { V::load(numbers.as_ptr()) };
    for jlo in (targets.start / TILE * TILE..n).step_by(TILE) {
        let tile = jlo..(jlo + TILE).min(n);
        for i0 in (targets.start..targets.end.min(tile.end)).step_by(K) {
            // SAFETY: as this function's.
            unsafe { cluster::<V, C, D, K>(law, pos, s, i0, tile.clone(), lane, out) };
        }
    }
}

/// The cluster of targets from `i0` against the sources of `tile` past them: both ends of
/// each pair.
///
/// # Safety
/// As [`triangle`]'s, with `i0 < n` a multiple of `K` and `tile` within `0..n`, starting at a
/// multiple of `V::WIDTH`.
#[cfg(target_arch = "x86_64")]
#[inline(always)]
unsafe fn cluster<V: Lanes, C: Coefficient<V>, const D: usize, const K: usize>(
    law: &C,
    pos: &[&[V::Elem]; D],
    s: &[V::Elem],
    i0: usize,
    tile: Range<usize>,
    lane: V,
    out: &mut [&mut [V::Elem]; D],
) where
    V::Elem: Real,
{
    let (n, w) = (s.len(), V::WIDTH);
    // SAFETY: indices below n; the features are the caller's. Plain loops, not
    // `array::from_fn`: its closures are functions of their own, compiled without the
    // features, where the intrinsics would not inline.
    unsafe {
        let zero = V::splat(V::Elem::zero());
        let mut c = Cluster::<V, D, K> {
            x: [[zero; D]; K],
            t: [zero; K],
            lane,
        };
        for k in 0..K {
            // Targets past n copy the first one, with no pairs (their lanes are all past n).
            let i = if i0 + k < n { i0 + k } else { i0 };
            for d in 0..D {
                c.x[k][d] = V::splat(*pos[d].get_unchecked(i));
            }
            c.t[k] = law.target(*s.get_unchecked(i));
        }
        let mut acc = [[zero; D]; K];
        let diagonal = i0 / w * w;
        let mut v = tile.start.max(diagonal);
        if v == diagonal {
            // Lane l is source v + l: target i0 + k meets only the lanes past i0 + k − v.
            let mut past = [zero; K];
            for (k, p) in past.iter_mut().enumerate() {
                *p = V::splat(V::Elem::of((i0 + k - v + 1) as f64));
            }
            sources::<V, C, D, K, true>(law, &c, pos, s, v, tile.end, &past, &mut acc, out);
            v += w;
        }
        while v + w <= tile.end {
            sources::<V, C, D, K, false>(law, &c, pos, s, v, tile.end, &[zero; K], &mut acc, out);
            v += w;
        }
        if v < tile.end {
            sources::<V, C, D, K, true>(law, &c, pos, s, v, tile.end, &[zero; K], &mut acc, out);
        }
        for k in 0..K.min(n - i0) {
            for d in 0..D {
                *out[d].get_unchecked_mut(i0 + k) += lane_sum(acc[k][d]);
            }
        }
    }
}

/// The cluster against the vector of sources from `v` (up to `end`): adds each pair's force
/// to the targets' sums `acc` and its reaction to the sources' forces in `out`. With `MASKED`,
/// target k meets only the lanes from `past[k]` on and below `end − v`; a vector that runs
/// past `end` (only a `MASKED` one, at n) is read and written through padded copies.
///
/// # Safety
/// As [`cluster`]'s, with `v < end ≤ n`, and `v + WIDTH ≤ end` unless `MASKED`.
#[cfg(target_arch = "x86_64")]
#[inline(always)]
#[allow(clippy::too_many_arguments)]
unsafe fn sources<V: Lanes, C: Coefficient<V>, const D: usize, const K: usize, const MASKED: bool>(
    law: &C,
    c: &Cluster<V, D, K>,
    pos: &[&[V::Elem]; D],
    s: &[V::Elem],
    v: usize,
    end: usize,
    past: &[V; K],
    acc: &mut [[V; D]; K],
    out: &mut [&mut [V::Elem]; D],
) where
    V::Elem: Real,
{
    let w = V::WIDTH;
    let m = (end - v).min(w);
    let zero = V::Elem::zero();
    // SAFETY: full vectors lie within 0..n (v + WIDTH ≤ end ≤ n); a partial one is copied
    // element by element below `end`; the features are the caller's.
    unsafe {
        let below = V::splat(V::Elem::of(m as f64));
        if MASKED && m < w {
            let mut xs = [[zero; MAX_WIDTH]; D];
            let mut ss = [zero; MAX_WIDTH];
            for l in 0..w {
                // Lanes past `end` repeat the last source, with no strength and no pairs.
                let j = v + l.min(m - 1);
                for d in 0..D {
                    xs[d][l] = *pos[d].get_unchecked(j);
                }
                ss[l] = if l < m { *s.get_unchecked(j) } else { zero };
            }
            let mut xj = [V::splat(zero); D];
            for d in 0..D {
                xj[d] = V::load(xs[d].as_ptr());
            }
            let fj =
                pairs::<V, C, D, K, MASKED>(law, c, &xj, V::load(ss.as_ptr()), past, below, acc);
            for d in 0..D {
                fj[d].store(xs[d].as_mut_ptr());
                for l in 0..m {
                    *out[d].get_unchecked_mut(v + l) += xs[d][l];
                }
            }
        } else {
            let mut xj = [V::splat(zero); D];
            for d in 0..D {
                xj[d] = V::load(pos[d].as_ptr().add(v));
            }
            let sj = V::load(s.as_ptr().add(v));
            let fj = pairs::<V, C, D, K, MASKED>(law, c, &xj, sj, past, below, acc);
            for d in 0..D {
                let f = out[d].as_mut_ptr().add(v);
                V::load(f).add(fj[d]).store(f);
            }
        }
    }
}

/// The pairs of the cluster with one vector of sources: the targets' sums grow in `acc`, the
/// sources' reaction comes back. With `MASKED`, target k keeps the lanes from `past[k]` on
/// and below `below`.
///
/// # Safety
/// The caller must have `V`'s features.
#[cfg(target_arch = "x86_64")]
#[inline(always)]
unsafe fn pairs<V: Lanes, C: Coefficient<V>, const D: usize, const K: usize, const MASKED: bool>(
    law: &C,
    c: &Cluster<V, D, K>,
    xj: &[V; D],
    sj: V,
    past: &[V; K],
    below: V,
    acc: &mut [[V; D]; K],
) -> [V; D]
where
    V::Elem: Real,
{
    // SAFETY: the caller's features.
    unsafe {
        let mut fj = [V::splat(V::Elem::zero()); D];
        for k in 0..K {
            let mut r2 = law.r2_start();
            let mut dx = [r2; D];
            for d in 0..D {
                dx[d] = xj[d].sub(c.x[k][d]);
                r2 = dx[d].mul_add(dx[d], r2);
            }
            let mut coeff = law.coeff(r2, sj, c.t[k]);
            if MASKED {
                coeff = coeff
                    .zero_where_less(c.lane, past[k])
                    .keep_where_less(c.lane, below);
            }
            for d in 0..D {
                acc[k][d] = coeff.mul_add(dx[d], acc[k][d]);
                fj[d] = coeff.neg_mul_add(dx[d], fj[d]);
            }
        }
        fj
    }
}

/// The sum of the lanes of `v`, as a tree.
///
/// # Safety
/// The caller must have `V`'s features.
#[cfg(target_arch = "x86_64")]
#[inline(always)]
unsafe fn lane_sum<V: Lanes>(v: V) -> V::Elem
where
    V::Elem: Real,
{
    let mut x = [V::Elem::zero(); MAX_WIDTH];
    // SAFETY: `x` holds MAX_WIDTH ≥ WIDTH elements; the caller's features.
    unsafe { v.store(x.as_mut_ptr()) };
    let mut width = V::WIDTH / 2;
    while width > 0 {
        for l in 0..width {
            x[l] += x[l + width];
        }
        width /= 2;
    }
    x[0]
}

#[cfg(all(test, target_arch = "x86_64"))]
mod tests {
    use super::*;
    use crate::kernels::lanes::isas_here;
    use crate::kernels::triangle::{GROUP, split};
    use crate::physics::{Coulomb, Gravity, LennardJones, pair_force};
    use crate::testing::{SEED_1, random_state, spaced_state};

    /// For every particle, |F − F_ref| ≤ `tol` · Σ_j |F_ij|, the reference summed in f64 with
    /// the law's textbook coefficient over every other particle; the triangle given whole and
    /// cut into parts (each part's forces added up).
    fn check<T: Real, L: PairLaw<T>, const D: usize>(law: &L, state: &State<T, D>, tol: f64)
    where
        L::Wide: PairLaw<f64>,
    {
        let n = state.len();
        let wide = law.widen();
        for isa in isas_here() {
            for parts in [1, 3] {
                let mut got: [Vec<T>; D] = std::array::from_fn(|_| vec![T::zero(); n]);
                for targets in split(n, 0..n, parts) {
                    let mut part: [Vec<T>; D] = std::array::from_fn(|_| vec![T::zero(); n]);
                    let mut out = part.each_mut().map(|f| f.as_mut_slice());
                    // SAFETY: `isas_here` lists only what this CPU runs.
                    assert!(unsafe { add_on(isa, law, state, targets.clone(), &mut out) });
                    for d in 0..D {
                        assert!(part[d][..targets.start].iter().all(|&f| f == T::zero()));
                        for (g, p) in got[d].iter_mut().zip(&part[d]) {
                            *g += *p;
                        }
                    }
                }
                for i in 0..n {
                    let (mut want, mut scale) = ([0.0; D], 0.0);
                    for j in (0..n).filter(|&j| j != i) {
                        let dx: [f64; D] = std::array::from_fn(|d| {
                            state.pos[d][j].as_f64() - state.pos[d][i].as_f64()
                        });
                        let (si, sj) = (state.source[i].as_f64(), state.source[j].as_f64());
                        let f = pair_force(&wide, dx, si, sj);
                        for d in 0..D {
                            want[d] += f[d];
                            scale += f[d].abs();
                        }
                    }
                    for d in 0..D {
                        let err = (got[d][i].as_f64() - want[d]).abs();
                        assert!(
                            err <= tol * scale && got[d][i].is_finite(),
                            "{isa:?} {} {:?}, {parts} parts: n {n}, particle {i}, component \
                             {d}: {} against {} (scale {scale})",
                            T::NAME,
                            law.kind(),
                            got[d][i],
                            want[d]
                        );
                    }
                }
            }
        }
    }

    /// Charges and masses of both signs, particle 3 on particle 0 (a coincident pair: softened
    /// in gravity, quenched in Coulomb).
    fn long_range<T: Real>(n: usize) -> State<T, 3> {
        let mut state = random_state::<T, 3>(n, 1.0, true, SEED_1);
        for (i, s) in state.source.iter_mut().enumerate() {
            *s *= T::of(1.0 + (i % 5) as f64 * 0.25);
        }
        if n > 3 {
            for d in 0..3 {
                state.pos[d][3] = state.pos[d][0];
            }
        }
        state
    }

    /// Every law and precision at every instruction set here, against the f64 reference sum:
    /// one particle, a partial vector, a group, n ending inside a vector, and the ends of a
    /// source tile. f64 to 1e-13 of the summed magnitudes; f32 to
    /// 2e-5 (its rounding over a few hundred terms).
    #[test]
    fn the_triangle_matches_the_reference_sum() {
        let gravity = Gravity::<f64>::new(1.0, 0.01);
        let coulomb = Coulomb::<f64>::new(1e-3);
        let (gravity32, coulomb32) = (Gravity::<f32>::new(1.0, 0.01), Coulomb::<f32>::new(1e-3));
        let (lj, lj32) = (
            LennardJones::<f64>::new(1.0, 0.01, 0.025),
            LennardJones::<f32>::new(1.0, 0.01, 0.025),
        );
        for n in [1, 2, 5, GROUP, GROUP + 1, 37, 1100] {
            check(&gravity, &long_range::<f64>(n), 1e-13);
            check(&coulomb, &long_range::<f64>(n), 1e-13);
            check(&gravity32, &long_range::<f32>(n), 2e-5);
            check(&coulomb32, &long_range::<f32>(n), 2e-5);
            // Lennard-Jones in 2-D and 3-D, no two particles closer than 0.8σ.
            let side = 0.012 * (n as f64).sqrt();
            check(&lj, &spaced_state::<f64, 2>(n, side, 0.008, SEED_1), 1e-13);
            check(&lj32, &spaced_state::<f32, 2>(n, side, 0.008, SEED_1), 2e-5);
            let side3 = 0.012 * (n as f64).cbrt();
            check(&lj, &spaced_state::<f64, 3>(n, side3, 0.008, SEED_1), 1e-13);
        }
        // The ends of a source tile, in both precisions.
        for n in [TILE - 1, TILE + 1] {
            check(&coulomb, &long_range::<f64>(n), 1e-13);
            let side = 0.012 * (n as f64).sqrt();
            check(&lj32, &spaced_state::<f32, 2>(n, side, 0.008, SEED_1), 2e-5);
        }
    }
}
