//! Velocity Verlet (kick-drift-kick), shared by every scenario:
//! `v += a·dt/2; x += v·dt; (boundary); a = F(x)/m + g; v += a·dt/2`.
//!
//! Each pass runs over chunks of particles on the pool's threads when the particles are many,
//! each chunk compiled for the selected instruction set. Every particle's arithmetic is the
//! same whatever the chunks, so the state is bitwise the same at any thread count.

use crate::par::{chunks_of, pass_chunk, worth_forking};
use crate::real::Real;
use crate::simd;
use crate::state::{Field, State};
use rayon::prelude::*;

/// Half kick: `v += (F/m + external)·dt/2`.
pub fn kick<T: Real, const D: usize>(
    state: &mut State<T, D>,
    forces: &Field<T, D>,
    external: [T; D],
    half_dt: T,
) {
    let n = state.len();
    let mass = &state.mass[..n];
    let vel = state.vel.each_mut().map(|v| &mut v[..n]);
    let pass = |offset: usize, v: [&mut [T]; D]| {
        let f = forces.each_ref().map(|f| &f[offset..offset + v[0].len()]);
        simd::dispatch(
            #[inline(always)]
            || kick_chunk(v, f, &mass[offset..], external, half_dt),
        )
    };
    if worth_forking(n * D) {
        let c = pass_chunk(n);
        chunks_of(vel, c)
            .into_par_iter()
            .enumerate()
            .for_each(|(k, v)| pass(k * c, v));
    } else {
        pass(0, vel);
    }
}

/// Half kick and drift in one pass: `v += (F/m + external)·dt/2; x += v·dt`.
pub fn kick_drift<T: Real, const D: usize>(
    state: &mut State<T, D>,
    forces: &Field<T, D>,
    external: [T; D],
    half_dt: T,
    dt: T,
) {
    let n = state.len();
    let mass = &state.mass[..n];
    let vel = state.vel.each_mut().map(|v| &mut v[..n]);
    let pos = state.pos.each_mut().map(|x| &mut x[..n]);
    let pass = |offset: usize, v: [&mut [T]; D], x: [&mut [T]; D]| {
        let f = forces.each_ref().map(|f| &f[offset..offset + v[0].len()]);
        kick_drift_block(x, v, f, &mass[offset..], external, half_dt, dt);
    };
    if worth_forking(n * D) {
        let c = pass_chunk(n);
        chunks_of(vel, c)
            .into_par_iter()
            .zip(chunks_of(pos, c))
            .enumerate()
            .for_each(|(k, (v, x))| pass(k * c, v, x));
    } else {
        pass(0, vel, pos);
    }
}

/// The fused half kick and drift of one block of particles: `x`, `v`, `f` its positions,
/// velocities and forces, `mass` starting with its masses.
pub(crate) fn kick_drift_block<T: Real, const D: usize>(
    x: [&mut [T]; D],
    v: [&mut [T]; D],
    f: [&[T]; D],
    mass: &[T],
    external: [T; D],
    half_dt: T,
    dt: T,
) {
    simd::dispatch(
        #[inline(always)]
        || {
            let mut v = v;
            kick_chunk(v.each_mut().map(|v| &mut **v), f, mass, external, half_dt);
            drift_chunk(x, v.each_ref().map(|v| &**v), dt);
        },
    )
}

/// The half kick of one block of particles (see [`kick_drift_block`]).
pub(crate) fn kick_block<T: Real, const D: usize>(
    v: [&mut [T]; D],
    f: [&[T]; D],
    mass: &[T],
    external: [T; D],
    half_dt: T,
) {
    simd::dispatch(
        #[inline(always)]
        || kick_chunk(v, f, mass, external, half_dt),
    )
}

/// Drift: `x += v·dt` (the fused pass's reference in tests).
#[cfg(test)]
fn drift<T: Real, const D: usize>(state: &mut State<T, D>, dt: T) {
    let vel = state.vel.each_ref().map(|v| v.as_slice());
    drift_chunk(state.pos.each_mut().map(|x| x.as_mut_slice()), vel, dt);
}

/// The kick of a block of particles: `v`, `f` their velocities and forces, `mass` starting
/// with their masses.
#[inline(always)]
fn kick_chunk<T: Real, const D: usize>(
    v: [&mut [T]; D],
    f: [&[T]; D],
    mass: &[T],
    external: [T; D],
    half_dt: T,
) {
    for (d, v) in v.into_iter().enumerate() {
        let (g, f) = (external[d], &f[d][..v.len()]);
        for ((v, &f), &m) in v.iter_mut().zip(f).zip(mass) {
            *v += (f / m + g) * half_dt;
        }
    }
}

#[inline(always)]
fn drift_chunk<T: Real, const D: usize>(x: [&mut [T]; D], v: [&[T]; D], dt: T) {
    for (x, v) in x.into_iter().zip(v) {
        for (x, &v) in x.iter_mut().zip(v) {
            *x += v * dt;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::state::zero_field;

    #[test]
    fn free_fall_in_a_constant_field_is_exact() {
        // With constant acceleration velocity Verlet is exact: x = x0 + v0 t + g t²/2.
        let mut s = State::<f64, 2>::new(1);
        s.vel[0][0] = 1.0;
        let f = zero_field::<f64, 2>(1);
        let (g, dt) = ([0.0, -9.81], 0.01);
        for _ in 0..100 {
            kick_drift(&mut s, &f, g, dt / 2.0, dt);
            kick(&mut s, &f, g, dt / 2.0);
        }
        assert!((s.pos[0][0] - 1.0).abs() < 1e-12);
        assert!((s.pos[1][0] + 0.5 * 9.81).abs() < 1e-10);
        assert!((s.vel[1][0] + 9.81).abs() < 1e-10);
    }

    #[test]
    fn the_fused_pass_is_the_two_passes_bitwise_at_any_thread_count() {
        let n = 50_000;
        let mut s = State::<f32, 3>::new(n);
        let mut f = zero_field::<f32, 3>(n);
        for i in 0..n {
            for d in 0..3 {
                s.pos[d][i] = (i * (d + 3)) as f32 * 1e-3;
                s.vel[d][i] = ((i * 7 + d) % 13) as f32 - 6.0;
                f[d][i] = ((i * 11 + d) % 17) as f32 * 0.37;
            }
            s.mass[i] = 1.0 + (i % 5) as f32;
        }
        let (g, half, dt) = ([0.0, -0.3, 0.1], 0.005f32, 0.01f32);
        let mut two = s.clone();
        kick(&mut two, &f, g, half);
        drift(&mut two, dt);
        kick(&mut two, &f, g, half);
        for threads in [1, 2, 3] {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            let mut one = s.clone();
            pool.install(|| {
                kick_drift(&mut one, &f, g, half, dt);
                kick(&mut one, &f, g, half);
            });
            assert_eq!((&one.pos, &one.vel), (&two.pos, &two.vel), "{threads}");
        }
    }
}
