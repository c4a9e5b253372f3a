//! The initial state of the field's Lennard-Jones benchmark (LAMMPS's `bench/in.lj`): atoms on
//! an fcc lattice at reduced density 0.8442 in a periodic cube, with velocities drawn at
//! temperature 1.44, the centre of mass at rest, in reduced units (σ = ε = m = k_B = 1).
//!
//! The benchmark's own generator is LAMMPS's random stream, which no other code reproduces;
//! a peer is given this state through `export` instead, so both start from the same atoms.

use super::{Setup, SetupError, System};
use crate::boundary::Boundary;
use crate::physics::{LJ_SIGMA, LennardJones};
use crate::real::Real;
use crate::state::State;
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64Mcg;

/// The benchmark's reduced number density ρσ³.
pub const MELT_DENSITY: f64 = 0.8442;
/// The melt's number density at the default σ (lengths are in the same unit as the other
/// Lennard-Jones scenarios', σ = [`LJ_SIGMA`]).
pub(crate) const LJ_MELT_DENSITY: f64 = MELT_DENSITY / (LJ_SIGMA * LJ_SIGMA * LJ_SIGMA);
/// The benchmark's initial reduced temperature k_B·T/ε.
pub const MELT_T0: f64 = 1.44;
/// The fcc cell's four sites, in units of the lattice constant.
const FCC_BASIS: [[f64; 3]; 4] = [
    [0.0, 0.0, 0.0],
    [0.5, 0.5, 0.0],
    [0.5, 0.0, 0.5],
    [0.0, 0.5, 0.5],
];

/// An fcc lattice of `cells`³ cubic cells (4 atoms each) at number `density`: the side of the
/// periodic cube and the sites, each cell's four in turn, x fastest.
pub fn fcc_lattice(cells: usize, density: f64) -> (f64, Vec<[f64; 3]>) {
    let a = (4.0 / density).cbrt();
    let mut sites = Vec::with_capacity(4 * cells.pow(3));
    for z in 0..cells {
        for y in 0..cells {
            for x in 0..cells {
                for b in FCC_BASIS {
                    let cell = [x, y, z];
                    sites.push(std::array::from_fn(|d| (cell[d] as f64 + b[d]) * a));
                }
            }
        }
    }
    (cells as f64 * a, sites)
}

/// The number of fcc cells per side that holds `n` atoms, when `n` is 4k³.
pub fn fcc_cells(n: usize) -> Option<usize> {
    let k = ((n / 4) as f64).cbrt().round() as usize;
    (k > 0 && 4 * k.pow(3) == n).then_some(k)
}

/// Velocities of `n` unit masses at temperature `t` exactly, with zero total momentum, as
/// LAMMPS's `velocity create` makes them by default: components uniform in a symmetric
/// interval, the mean removed, then scaled so that Σv²/(3n − 3) = t (three degrees of
/// freedom go to the centre of mass).
pub fn thermal_velocities(n: usize, t: f64, seed: u64) -> Vec<[f64; 3]> {
    let mut rng = Pcg64Mcg::seed_from_u64(seed);
    let mut v: Vec<[f64; 3]> = (0..n)
        .map(|_| std::array::from_fn(|_| rng.random::<f64>() - 0.5))
        .collect();
    if n < 2 {
        return vec![[0.0; 3]; n];
    }
    let mean: [f64; 3] = std::array::from_fn(|d| v.iter().map(|v| v[d]).sum::<f64>() / n as f64);
    for v in &mut v {
        for d in 0..3 {
            v[d] -= mean[d];
        }
    }
    let sum2: f64 = v.iter().flatten().map(|x| x * x).sum();
    let scale = (t * (3 * n - 3) as f64 / sum2).sqrt();
    for v in &mut v {
        for x in v.iter_mut() {
            *x *= scale;
        }
    }
    v
}

/// The melt of `setup`: the bodies of its initial file, or the fcc lattice of n = 4k³ atoms
/// with velocities at T0 (in units of ε), in the periodic cube of side (n/ρ)^(1/3).
pub(super) fn build<T: Real>(setup: &Setup) -> Result<System<T, LennardJones<T>, 3>, SetupError> {
    let lj = setup.lj;
    let density = setup.density().expect("lj-melt has a density");
    let side = setup.box_side(density);
    let state = match &setup.initial {
        Some(bodies) => bodies.state::<T, 3>(),
        None => {
            let n = setup.n();
            let cells = fcc_cells(n).ok_or(SetupError::NotFcc(n))?;
            let (_, sites) = fcc_lattice(cells, density);
            let t0 = lj.t0.unwrap_or(MELT_T0) * lj.epsilon();
            let velocities = thermal_velocities(n, t0, setup.seed);
            let mut state = State::<T, 3>::new(n);
            for (i, (p, v)) in sites.iter().zip(&velocities).enumerate() {
                for d in 0..3 {
                    state.pos[d][i] = T::of(p[d]);
                    state.vel[d][i] = T::of(v[d]);
                }
            }
            state
        }
    };
    let n = state.len();
    Ok(System {
        state,
        law: LennardJones::new(lj.epsilon(), lj.sigma(), lj.cutoff()),
        boundary: Boundary::Periodic {
            lo: [T::zero(); 3],
            hi: [T::of(side); 3],
        },
        external: [T::zero(), T::zero(), T::of(-lj.g(setup.scenario))],
        dt: T::of(setup.dt()),
        info: setup.info(n, Some(side)),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_lattice_has_four_atoms_a_cell_at_the_density_and_nearest_neighbours_apart() {
        let (side, sites) = fcc_lattice(5, MELT_DENSITY);
        assert_eq!(sites.len(), 500);
        let density = sites.len() as f64 / side.powi(3);
        assert!((density - MELT_DENSITY).abs() < 1e-12, "{density}");
        assert!(sites.iter().flatten().all(|&x| (0.0..side).contains(&x)));
        // Every site has twelve nearest neighbours at a/√2 (through the periodic faces too).
        let a = side / 5.0;
        let image = |dx: f64| dx - side * (dx / side).round();
        for p in [&sites[0], &sites[137], &sites[499]] {
            let near = sites
                .iter()
                .filter(|q| {
                    let r2: f64 = (0..3).map(|d| image(q[d] - p[d]).powi(2)).sum();
                    (r2.sqrt() - a / 2f64.sqrt()).abs() < 1e-9
                })
                .count();
            assert_eq!(near, 12);
        }
    }

    #[test]
    fn only_four_k_cubed_atoms_make_a_lattice() {
        assert_eq!(fcc_cells(32_000), Some(20));
        assert_eq!(fcc_cells(256_000), Some(40));
        assert_eq!(fcc_cells(4), Some(1));
        assert_eq!(fcc_cells(31_999), None);
        assert_eq!(fcc_cells(0), None);
    }

    #[test]
    fn velocities_have_the_temperature_exactly_and_no_momentum() {
        let n = 4000;
        let v = thermal_velocities(n, MELT_T0, 87287);
        for d in 0..3 {
            let p: f64 = v.iter().map(|v| v[d]).sum();
            assert!(p.abs() < 1e-10, "momentum {p}");
        }
        let t = v.iter().flatten().map(|x| x * x).sum::<f64>() / (3 * n - 3) as f64;
        assert!((t - MELT_T0).abs() < 1e-12, "{t}");
        assert_eq!(v, thermal_velocities(n, MELT_T0, 87287));
        assert_ne!(v, thermal_velocities(n, MELT_T0, 87288));
    }
}
