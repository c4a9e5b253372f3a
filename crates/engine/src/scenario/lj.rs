//! The 2-D Lennard-Jones scenarios (`lj-box`, `lj-liquid`, `lj-gas`): their constants, the parameters a run
//! may change (`run --epsilon --sigma --g --t0`), and the system they build.
//!
//! The constants here are the defaults the command line shows: a change to one changes both the
//! scenario and its help.

use super::{ScenarioKind, Setup, SetupError, System, placement};
use crate::boundary::Boundary;
use crate::physics::LennardJones;
use crate::real::Real;
use crate::state::State;
use rand::SeedableRng;
use rand_distr::{Distribution, Normal};
use rand_pcg::Pcg64Mcg;

/// Well depth ε (the LJ-box assignment's energy unit).
pub const LJ_EPSILON: f64 = 1.0;
/// Particle size σ; the physics layer's, where the kernels' distance defaults also read it.
pub use crate::physics::LJ_SIGMA;
/// The cutoff in units of σ.
pub const LJ_CUTOFF_SIGMAS: f64 = 2.5;
/// The cutoff at the default σ.
pub const LJ_CUTOFF: f64 = LJ_CUTOFF_SIGMAS * LJ_SIGMA;
/// The source's 500 particles in the unit square (≈1 neighbour inside rc: a dilute gas).
pub const LJ_GAS_DENSITY: f64 = 500.0;
/// The liquid's reduced density ρσ²: its number density follows σ.
pub const LJ_LIQUID_REDUCED_DENSITY: f64 = 0.8;
/// The liquid's number density at the default σ.
pub(crate) const LJ_LIQUID_DENSITY: f64 = LJ_LIQUID_REDUCED_DENSITY / (LJ_SIGMA * LJ_SIGMA);
/// Initial temperature: velocity components are N(0, √T0) for unit mass (k_B = 1).
pub const LJ_T0: f64 = 1.0;
/// Downward acceleration of the lj-box field (lj-liquid has none).
pub const LJ_GRAVITY: f64 = 1.0;

/// The Lennard-Jones parameters a run changes; `None` keeps the scenario's.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct LjOverrides {
    /// Well depth ε (`--epsilon`); `None`: [`LJ_EPSILON`].
    pub epsilon: Option<f64>,
    /// Particle size σ (`--sigma`), also the minimum spacing of the placement; `None`:
    /// [`LJ_SIGMA`].
    pub sigma: Option<f64>,
    /// Downward acceleration of the external field.
    pub g: Option<f64>,
    /// Temperature of the generated velocities.
    pub t0: Option<f64>,
}

impl LjOverrides {
    /// Well depth ε: the override, else [`LJ_EPSILON`].
    pub fn epsilon(&self) -> f64 {
        self.epsilon.unwrap_or(LJ_EPSILON)
    }

    /// Particle size σ: the override, else [`LJ_SIGMA`].
    pub fn sigma(&self) -> f64 {
        self.sigma.unwrap_or(LJ_SIGMA)
    }

    /// Cutoff radius: [`LJ_CUTOFF_SIGMAS`] times σ.
    pub fn cutoff(&self) -> f64 {
        LJ_CUTOFF_SIGMAS * self.sigma()
    }

    /// Initial temperature: the override, else [`LJ_T0`].
    pub fn t0(&self) -> f64 {
        self.t0.unwrap_or(LJ_T0)
    }

    /// The field of `scenario`: lj-box's [`LJ_GRAVITY`], none in the liquid.
    pub fn g(&self, scenario: ScenarioKind) -> f64 {
        self.g.unwrap_or(default_gravity(scenario))
    }

    /// The options given, as the command line names them, with their values.
    pub(crate) fn given(&self) -> Vec<(&'static str, f64)> {
        [
            ("--epsilon", self.epsilon),
            ("--sigma", self.sigma),
            ("--g", self.g),
            ("--t0", self.t0),
        ]
        .into_iter()
        .filter_map(|(flag, v)| Some((flag, v?)))
        .collect()
    }

    /// Each value given is one the physics can use: ε and σ positive, g finite, T0 ≥ 0.
    pub(crate) fn validate(&self, scenario: ScenarioKind) -> Result<(), SetupError> {
        let given = self.given();
        if let Some((flag, _)) = given.first()
            && scenario.law() != crate::physics::LawKind::LennardJones
        {
            return Err(SetupError::NotLj(flag, scenario.name()));
        }
        for (flag, v) in given {
            let ok = match flag {
                "--g" => v.is_finite(),
                "--t0" => v.is_finite() && v >= 0.0,
                _ => v.is_finite() && v > 0.0,
            };
            if !ok {
                let want = match flag {
                    "--g" => "a finite number",
                    "--t0" => "a finite number, 0 or greater",
                    _ => "a positive finite number",
                };
                return Err(SetupError::BadLj { flag, want, got: v });
            }
        }
        Ok(())
    }
}

/// lj-box's downward acceleration; the liquid has no field.
pub fn default_gravity(scenario: ScenarioKind) -> f64 {
    if scenario == ScenarioKind::LjBox {
        LJ_GRAVITY
    } else {
        0.0
    }
}

/// The Lennard-Jones system of `setup`: the bodies of its initial file, or a seeded placement at
/// minimum spacing σ with velocities at temperature T0, in the box of side √(n/ρ): walled, or
/// periodic for the gas.
pub(super) fn build<T: Real>(setup: &Setup) -> Result<System<T, LennardJones<T>, 2>, SetupError> {
    let lj = setup.lj;
    let density = setup.density().expect("LJ scenarios have a density");
    let side = (setup.n() as f64 / density).sqrt();
    let state = match &setup.initial {
        Some(bodies) => bodies.state::<T, 2>(),
        None => generated::<T>(setup, side)?,
    };
    let n = state.len();
    Ok(System {
        state,
        law: LennardJones::new(lj.epsilon(), lj.sigma(), lj.cutoff()),
        boundary: if setup.scenario.periodic() {
            Boundary::Periodic {
                lo: [T::zero(); 2],
                hi: [T::of(side); 2],
            }
        } else {
            Boundary::Reflecting {
                lo: [T::zero(); 2],
                hi: [T::of(side); 2],
            }
        },
        external: [T::zero(), T::of(-lj.g(setup.scenario))],
        dt: T::of(setup.dt()),
        info: setup.info(n, Some(side)),
    })
}

/// Seeded positions at minimum spacing σ and velocity components N(0, √T0).
fn generated<T: Real>(setup: &Setup, side: f64) -> Result<State<T, 2>, SetupError> {
    let sigma = setup.lj.sigma();
    let mut rng = Pcg64Mcg::seed_from_u64(setup.seed);
    let positions = match setup.scenario {
        // Random sequential placement jams near packing fraction 0.55; the liquid
        // (0.63) starts from a jittered lattice instead.
        ScenarioKind::LjLiquid => placement::jittered_lattice(setup.n(), side, sigma, &mut rng),
        kind => placement::spaced_uniform(
            setup.n(),
            side,
            sigma,
            setup.allow_fewer,
            kind.periodic(),
            &mut rng,
        )?,
    };
    let mut state = State::<T, 2>::new(positions.len());
    let normal = Normal::new(0.0, setup.lj.t0().sqrt()).expect("T0 was validated");
    for (i, p) in positions.iter().enumerate() {
        for d in 0..2 {
            state.pos[d][i] = T::of(p[d]);
            state.vel[d][i] = T::of(normal.sample(&mut rng));
        }
    }
    Ok(state)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::physics::{LawParameters, PairLaw};

    #[test]
    fn overrides_reach_the_law_the_field_and_the_velocities() {
        let mut setup = Setup::new(ScenarioKind::LjBox);
        setup.n = Some(200);
        let plain = build::<f64>(&setup).unwrap();
        setup.lj = LjOverrides {
            epsilon: Some(2.0),
            sigma: Some(0.02),
            g: Some(-3.0),
            t0: Some(0.0),
        };
        let s = build::<f64>(&setup).unwrap();
        assert!(matches!(
            s.law.parameters(),
            LawParameters::LennardJones { epsilon: 2.0, sigma: 0.02, rc } if rc == 2.5 * 0.02
        ));
        assert_eq!(s.external, [0.0, 3.0]);
        assert!(s.state.vel.iter().flatten().all(|&v| v == 0.0));
        assert_eq!(plain.external, [0.0, -LJ_GRAVITY]);
        assert!(plain.state.vel.iter().flatten().any(|&v| v != 0.0));
    }

    #[test]
    fn the_liquid_keeps_its_reduced_density_when_sigma_changes() {
        let mut setup = Setup::new(ScenarioKind::LjLiquid);
        setup.lj.sigma = Some(0.1);
        assert_eq!(
            setup.density(),
            Some(LJ_LIQUID_REDUCED_DENSITY / (0.1 * 0.1))
        );
        setup.density = Some(3.0);
        assert_eq!(setup.density(), Some(3.0));
    }

    #[test]
    fn bad_values_and_other_scenarios_are_refused() {
        let bad = |lj: LjOverrides, scenario| lj.validate(scenario).unwrap_err().to_string();
        let sigma = LjOverrides {
            sigma: Some(0.0),
            ..Default::default()
        };
        assert!(bad(sigma, ScenarioKind::LjBox).contains("--sigma"));
        let t0 = LjOverrides {
            t0: Some(-1.0),
            ..Default::default()
        };
        assert!(bad(t0, ScenarioKind::LjLiquid).contains("--t0"));
        let g = LjOverrides {
            g: Some(2.0),
            ..Default::default()
        };
        assert!(g.validate(ScenarioKind::LjLiquid).is_ok());
        let e = bad(g, ScenarioKind::Galaxy);
        assert!(e.contains("--g") && e.contains("galaxy"), "{e}");
    }
}
