//! Shared fixtures for tests and benches: seeded random configurations, and the comparisons
//! of force fields that the kernels' tests make against the direct sum ([`short_range`] has
//! the short-range kernels' own).

#[cfg(test)]
pub(crate) mod periodic;
#[cfg(test)]
pub(crate) mod short_range;

#[cfg(test)]
use crate::kernels::{ForceKernel, ForceReport};
use crate::real::Real;
#[cfg(test)]
use crate::state::zero_field;
use crate::state::{Field, State};
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64Mcg;

/// Runs `f` on a fresh rayon pool of `p` threads.
#[cfg(test)]
pub(crate) fn on_threads<R: Send>(p: usize, f: impl FnOnce() -> R + Send) -> R {
    rayon::ThreadPoolBuilder::new()
        .num_threads(p)
        .build()
        .expect("thread pool")
        .install(f)
}

/// A named seed of the tests' random states, so that two tests share a state on purpose.
pub const SEED_1: u64 = 0x5eed_0001;
/// A second named seed, for a state independent of [`SEED_1`]'s.
pub const SEED_2: u64 = 0x5eed_0002;

/// `n` particles uniform in the box `[0, side)^D` with small random velocities, unit mass and
/// source strength +1 / −1 alternating when `charged` (else +1).
pub fn random_state<T: Real, const D: usize>(
    n: usize,
    side: f64,
    charged: bool,
    seed: u64,
) -> State<T, D> {
    let mut rng = Pcg64Mcg::seed_from_u64(seed);
    let mut s = State::new(n);
    for i in 0..n {
        for d in 0..D {
            s.pos[d][i] = T::of(rng.random::<f64>() * side);
            s.vel[d][i] = T::of(rng.random::<f64>() - 0.5);
        }
        if charged {
            s.source[i] = if i % 2 == 0 { T::one() } else { -T::one() };
        }
    }
    s
}

/// `n` particles uniform in `[0, side)^D` but no two closer than `min_dist` (O(n²) rejection;
/// for small test systems only).
pub fn spaced_state<T: Real, const D: usize>(
    n: usize,
    side: f64,
    min_dist: f64,
    seed: u64,
) -> State<T, D> {
    let mut rng = Pcg64Mcg::seed_from_u64(seed);
    let mut pts: Vec<[f64; D]> = Vec::with_capacity(n);
    while pts.len() < n {
        let p: [f64; D] = std::array::from_fn(|_| rng.random::<f64>() * side);
        if pts
            .iter()
            .all(|q| (0..D).map(|d| (p[d] - q[d]).powi(2)).sum::<f64>() >= min_dist * min_dist)
        {
            pts.push(p);
        }
    }
    let mut s = State::new(n);
    for (i, p) in pts.iter().enumerate() {
        for d in 0..D {
            s.pos[d][i] = T::of(p[d]);
        }
    }
    s
}

/// A Plummer sphere (scale radius 1, total mass 1), clustered: the centre is ~10⁴× denser than
/// r = 5. In 2-D, the projected Plummer disc (surface density ∝ (1 + R²)⁻²), which is as
/// centrally concentrated; radii of the 3-D profile with 2-D directions would leave a hole.
#[cfg(test)]
pub(crate) fn plummer_state<T: Real, const D: usize>(n: usize, seed: u64) -> State<T, D> {
    let mut rng = Pcg64Mcg::seed_from_u64(seed);
    let mut s = State::new(n);
    for i in 0..n {
        let r = loop {
            let u: f64 = rng.random_range(1e-9..1.0);
            // Inverse of the enclosed-mass fraction: m(r) = r³/(1+r²)^{3/2}, m(R) = R²/(1+R²).
            let r = if D == 3 {
                1.0 / (u.powf(-2.0 / 3.0) - 1.0).sqrt()
            } else {
                (u / (1.0 - u)).sqrt()
            };
            if r < 50.0 {
                break r;
            }
        };
        let dir: [f64; D] = loop {
            let v: [f64; D] = std::array::from_fn(|_| rng.random_range(-1.0..1.0));
            let l2: f64 = v.iter().map(|x| x * x).sum();
            if l2 > 1e-6 && l2 <= 1.0 {
                break v.map(|x| x / l2.sqrt());
            }
        };
        for d in 0..D {
            s.pos[d][i] = T::of(r * dir[d]);
        }
        s.source[i] = T::of(1.0 / n as f64);
        s.mass[i] = s.source[i];
    }
    s
}

/// Forces (and the report, with the energy when `probe`) of a kernel on a state.
#[cfg(test)]
pub(crate) fn forces_of<T: Real, const D: usize>(
    k: &mut dyn ForceKernel<T, D>,
    s: &State<T, D>,
    probe: bool,
) -> (Field<T, D>, ForceReport) {
    let mut f = zero_field(s.len());
    let r = k.compute(s, &mut f, probe);
    (f, r)
}

/// |f_i|.
pub fn norm<T: Real, const D: usize>(f: &Field<T, D>, i: usize) -> f64 {
    (0..D).map(|d| f[d][i].as_f64().powi(2)).sum::<f64>().sqrt()
}

/// |a_i − b_i|.
pub fn diff<T: Real, const D: usize>(a: &Field<T, D>, b: &Field<T, D>, i: usize) -> f64 {
    (0..D)
        .map(|d| (a[d][i].as_f64() - b[d][i].as_f64()).powi(2))
        .sum::<f64>()
        .sqrt()
}

/// max_i |a_i − b_i| / max_i |b_i|.
#[cfg(test)]
pub(crate) fn max_rel_diff<T: Real, const D: usize>(a: &Field<T, D>, b: &Field<T, D>) -> f64 {
    let n = a[0].len();
    let scale = (0..n).map(|i| norm(b, i)).fold(0.0, f64::max).max(1e-300);
    (0..n).map(|i| diff(a, b, i)).fold(0.0, f64::max) / scale
}

/// Median over particles of |a_i − b_i| / |b_i|.
#[cfg(test)]
pub(crate) fn median_rel_err<T: Real, const D: usize>(a: &Field<T, D>, b: &Field<T, D>) -> f64 {
    let n = a[0].len();
    let mut errs: Vec<f64> = (0..n)
        .map(|i| diff(a, b, i) / norm(b, i).max(1e-300))
        .collect();
    errs.sort_by(f64::total_cmp);
    errs[n / 2]
}
