//! Shared fixtures for tests and benches: seeded random configurations.

use crate::real::Real;
use crate::state::State;
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64Mcg;

pub const SEED_1: u64 = 0x5eed_0001;
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
