//! The gravitating test system of the Barnes-Hut report: six massive bodies on circular orbits around the
//! origin plus a centrally concentrated random cloud of light bodies.
//!
//! Units: AU, 10⁻³ solar masses, G = 1 (time unit √(AU³ / (G·10⁻³ M☉))). The cloud is a Plummer
//! sphere of total mass 1000 (one solar mass) and scale radius 1 AU, sampled from its
//! equilibrium distribution function, so it stays centrally concentrated over the run; the six
//! bodies of mass 1 (about one Jupiter each) orbit at 3–8 AU, outside most of the cloud.

use crate::real::Real;
use crate::state::State;
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64Mcg;
use std::f64::consts::PI;

/// Gravitational constant of the galaxy scenario, in its units (AU, 10⁻³ M☉): 1.
pub const G: f64 = 1.0;
/// Plummer softening: small against the cloud's scale radius, large enough that close
/// encounters of light bodies are resolved at dt = 1e-3.
pub(crate) const SOFTENING: f64 = 0.05;
pub(crate) const CLOUD_MASS: f64 = 1000.0;
pub(crate) const CLOUD_SCALE: f64 = 1.0;
/// The cloud is truncated at this many scale radii (99% of the Plummer mass lies inside).
const CLOUD_TRUNCATION: f64 = 10.0;
pub(crate) const PLANETS: usize = 6;
pub(crate) const PLANET_MASS: f64 = 1.0;
const PLANET_RADII: [f64; PLANETS] = [3.0, 4.0, 5.0, 6.0, 7.0, 8.0];

/// Builds the system with `n` bodies (the first min(n, 6) are the massive ones).
pub fn galaxy<T: Real>(n: usize, seed: u64) -> State<T, 3> {
    let mut rng = Pcg64Mcg::seed_from_u64(seed);
    let planets = n.min(PLANETS);
    let cloud = n - planets;
    let mut pos = Vec::with_capacity(n);
    let mut vel = Vec::with_capacity(n);
    let mut mass = Vec::with_capacity(n);
    // Planets: circular speed from the mass enclosed by each orbit (cloud + inner planets).
    let phase0 = rng.random::<f64>() * 2.0 * PI;
    for k in 0..planets {
        let r = PLANET_RADII[k];
        let enclosed = plummer_enclosed(r) * (cloud > 0) as u8 as f64 + PLANET_MASS * k as f64;
        let v = (G * enclosed.max(PLANET_MASS) / r).sqrt();
        let phi = phase0 + 2.0 * PI * k as f64 / PLANETS as f64;
        pos.push([r * phi.cos(), r * phi.sin(), 0.0]);
        vel.push([-v * phi.sin(), v * phi.cos(), 0.0]);
        mass.push(PLANET_MASS);
    }
    let m_light = if cloud > 0 {
        CLOUD_MASS / cloud as f64
    } else {
        0.0
    };
    for _ in 0..cloud {
        let (x, v) = plummer_body(&mut rng);
        pos.push(x);
        vel.push(v);
        mass.push(m_light);
    }
    // Put the centre of mass at rest at the origin.
    let total: f64 = mass.iter().sum();
    for d in 0..3 {
        let cm: f64 = pos.iter().zip(&mass).map(|(p, m)| p[d] * m).sum::<f64>() / total;
        let cv: f64 = vel.iter().zip(&mass).map(|(v, m)| v[d] * m).sum::<f64>() / total;
        pos.iter_mut().for_each(|p| p[d] -= cm);
        vel.iter_mut().for_each(|v| v[d] -= cv);
    }
    let mut s = State::new(n);
    for i in 0..n {
        for d in 0..3 {
            s.pos[d][i] = T::of(pos[i][d]);
            s.vel[d][i] = T::of(vel[i][d]);
        }
        s.mass[i] = T::of(mass[i]);
        s.source[i] = T::of(mass[i]);
    }
    s
}

/// Plummer mass inside radius r.
fn plummer_enclosed(r: f64) -> f64 {
    CLOUD_MASS * r.powi(3) / (r * r + CLOUD_SCALE * CLOUD_SCALE).powf(1.5)
}

/// One body drawn from the Plummer distribution function (Aarseth, Hénon & Wielen 1974).
fn plummer_body(rng: &mut impl Rng) -> ([f64; 3], [f64; 3]) {
    let r = loop {
        // Invert M(r)/M = r³/(r²+a²)^{3/2}.
        let m: f64 = rng.random_range(1e-10..1.0);
        let r = CLOUD_SCALE / (m.powf(-2.0 / 3.0) - 1.0).sqrt();
        if r < CLOUD_TRUNCATION * CLOUD_SCALE {
            break r;
        }
    };
    // Speed as a fraction q of the escape speed, from g(q) ∝ q²(1 − q²)^{7/2} by rejection.
    let q = loop {
        let q: f64 = rng.random();
        let g: f64 = rng.random::<f64>() * 0.1;
        if g < q * q * (1.0 - q * q).powf(3.5) {
            break q;
        }
    };
    let v_esc = (2.0 * G * CLOUD_MASS / (r * r + CLOUD_SCALE * CLOUD_SCALE).sqrt()).sqrt();
    (isotropic(rng, r), isotropic(rng, q * v_esc))
}

/// A vector of length `len` in a uniformly random direction.
fn isotropic(rng: &mut impl Rng, len: f64) -> [f64; 3] {
    let z: f64 = rng.random_range(-1.0..1.0);
    let phi: f64 = rng.random::<f64>() * 2.0 * PI;
    let s = (1.0 - z * z).sqrt();
    [len * s * phi.cos(), len * s * phi.sin(), len * z]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn planets_orbit_and_cloud_is_concentrated() {
        let s = galaxy::<f64>(2006, 1);
        // Centre of mass at rest.
        let p = s.momentum();
        assert!(p.iter().all(|x| x.abs() < 1e-9), "{p:?}");
        // The cloud's median radius is near the Plummer half-mass radius (1.305 a).
        let mut r: Vec<f64> = (PLANETS..s.len())
            .map(|i| (0..3).map(|d| s.pos[d][i].powi(2)).sum::<f64>().sqrt())
            .collect();
        r.sort_by(f64::total_cmp);
        let median = r[r.len() / 2];
        assert!((median - 1.305).abs() < 0.15, "median radius {median}");
        // Total mass: cloud + planets.
        let m: f64 = s.mass.iter().sum();
        assert!((m - (CLOUD_MASS + 6.0 * PLANET_MASS)).abs() < 1e-9);
    }

    #[test]
    fn tiny_systems_are_valid() {
        for n in 1..=8 {
            let s = galaxy::<f32>(n, 3);
            assert_eq!(s.len(), n);
            assert!(s.pos.iter().flatten().all(|x| x.is_finite()));
            assert!(s.vel.iter().flatten().all(|x| x.is_finite()));
        }
    }
}
