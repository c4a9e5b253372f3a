//! Scenarios: physical set-ups from the source documents, with their defaults.
//!
//! A [`Setup`] (scenario + overrides) becomes a typed [`System`] — state, pair law, boundary,
//! external field and time step — in the scenario's dimension and precision. The one place
//! where runtime choices become compile-time types is [`Setup::dispatch`]: every command hands
//! it a [`SystemJob`] and receives the job's result.

pub mod galaxy;
pub mod initial;
pub mod lj;
pub mod melt;
mod placement;

use crate::boundary::Boundary;
use crate::kernels::CompiledKernels;
use crate::physics::{Coulomb, Gravity, LawKind};
use crate::real::Real;
use crate::state::State;
use rand::SeedableRng;
use rand_pcg::Pcg64Mcg;
use serde::Serialize;
use std::sync::Arc;
use thiserror::Error;

pub use initial::{InitialBodies, InitialError};
pub use lj::{LJ_CUTOFF, LJ_GAS_DENSITY, LjOverrides};
use lj::{LJ_LIQUID_DENSITY, LJ_LIQUID_REDUCED_DENSITY, LJ_SIGMA};
use melt::{LJ_MELT_DENSITY, MELT_DENSITY};
pub use placement::PlacementError;

/// The scenarios a user can pick.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, serde::Deserialize)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
#[serde(rename_all = "kebab-case")]
pub enum ScenarioKind {
    /// 2-D Lennard-Jones gas in a box with reflecting walls and downward gravity (the LJ-box assignment).
    LjBox,
    /// 2-D Lennard-Jones liquid (reduced density 0.8) in a walled box, no field.
    LjLiquid,
    /// 2-D Lennard-Jones gas at lj-box's density in a periodic square, no field: the gas as the
    /// codes of the field run it (no walls).
    LjGas,
    /// 3-D Lennard-Jones melt of LAMMPS's `bench/in.lj`: fcc lattice at reduced density
    /// 0.8442, T0 = 1.44, periodic cube, no field.
    LjMelt,
    /// 3-D charges ±1 at rest in the unit cube, open space (the Coulomb MPI tutorial).
    Coulomb,
    /// 3-D gravitating system: six massive bodies on circular orbits around a Plummer cloud (the Barnes-Hut report).
    Galaxy,
}

impl ScenarioKind {
    /// Every scenario, in the order `list` and `validate` go through them.
    pub const ALL: [ScenarioKind; 6] = [
        ScenarioKind::LjBox,
        ScenarioKind::LjLiquid,
        ScenarioKind::LjGas,
        ScenarioKind::LjMelt,
        ScenarioKind::Coulomb,
        ScenarioKind::Galaxy,
    ];

    /// The scenario's name on the command line and in results (kebab-case, as serde writes it).
    pub fn name(self) -> &'static str {
        match self {
            ScenarioKind::LjBox => "lj-box",
            ScenarioKind::LjLiquid => "lj-liquid",
            ScenarioKind::LjGas => "lj-gas",
            ScenarioKind::LjMelt => "lj-melt",
            ScenarioKind::Coulomb => "coulomb",
            ScenarioKind::Galaxy => "galaxy",
        }
    }

    /// The pair law its particles interact by.
    pub fn law(self) -> LawKind {
        match self {
            ScenarioKind::LjBox
            | ScenarioKind::LjLiquid
            | ScenarioKind::LjGas
            | ScenarioKind::LjMelt => LawKind::LennardJones,
            ScenarioKind::Coulomb => LawKind::Coulomb,
            ScenarioKind::Galaxy => LawKind::Gravity,
        }
    }

    /// Spatial dimension: 2 for the Lennard-Jones boxes and the gas, 3 for the melt, coulomb
    /// and galaxy.
    pub fn dim(self) -> usize {
        match self {
            ScenarioKind::LjBox | ScenarioKind::LjLiquid | ScenarioKind::LjGas => 2,
            ScenarioKind::LjMelt | ScenarioKind::Coulomb | ScenarioKind::Galaxy => 3,
        }
    }

    /// Particle count, time step, precision and density used where the user gives none.
    pub fn defaults(self) -> Defaults {
        match self {
            ScenarioKind::LjBox | ScenarioKind::LjGas => Defaults {
                n: 500,
                dt: 1e-4,
                precision: Precision::F32,
                density: Some(LJ_GAS_DENSITY),
            },
            ScenarioKind::LjLiquid => Defaults {
                n: 10_000,
                dt: 1e-4,
                precision: Precision::F32,
                density: Some(LJ_LIQUID_DENSITY),
            },
            // in.lj's 32 000 atoms at its time step of 0.005 τ (τ = σ·√(m/ε)).
            ScenarioKind::LjMelt => Defaults {
                n: 32_000,
                dt: 0.005 * LJ_SIGMA,
                precision: Precision::F32,
                density: Some(LJ_MELT_DENSITY),
            },
            ScenarioKind::Coulomb => Defaults {
                n: 1000,
                dt: 1e-5,
                precision: Precision::F64,
                density: None,
            },
            ScenarioKind::Galaxy => Defaults {
                n: 2000,
                dt: 1e-3,
                precision: Precision::F64,
                density: None,
            },
        }
    }

    /// Whether the scenario's box is periodic (pairs meet through nearest images).
    pub fn periodic(self) -> bool {
        matches!(self, ScenarioKind::LjGas | ScenarioKind::LjMelt)
    }

    /// The largest particle count of at most `n` the scenario builds (the melt's lattices hold
    /// 4k³ atoms, from 108 on), for probes that scale a case down; `n` itself for the others.
    pub fn count_at_most(self, n: usize) -> usize {
        match self {
            ScenarioKind::LjMelt => {
                let k = ((n / 4) as f64).cbrt().floor() as usize;
                // The cube root of a perfect cube may round below it.
                let k = if 4 * (k + 1).pow(3) <= n { k + 1 } else { k };
                4 * k.max(3).pow(3)
            }
            _ => n,
        }
    }

    /// One line for `list`.
    pub fn summary(self) -> &'static str {
        match self {
            ScenarioKind::LjBox => {
                "2-D LJ gas, sigma=0.01, rc=2.5 sigma, walls, g=1, T0=1 (the LJ-box assignment)"
            }
            ScenarioKind::LjLiquid => "2-D LJ liquid, reduced density 0.8, walls, no field",
            ScenarioKind::LjGas => {
                "2-D LJ gas at lj-box's density, sigma=0.01, rc=2.5 sigma, periodic, no field, T0=1"
            }
            ScenarioKind::LjMelt => {
                "3-D LJ melt, fcc at reduced density 0.8442, T0=1.44, periodic (LAMMPS's bench/in.lj); n = 4k^3"
            }
            ScenarioKind::Coulomb => {
                "3-D charges +-1 at rest in the unit cube, quench 1e-3, open (the Coulomb MPI tutorial)"
            }
            ScenarioKind::Galaxy => {
                "3-D gravity: 6 planets around a Plummer cloud, softening 0.05, open (the Barnes-Hut report)"
            }
        }
    }
}

/// Largest particle count: particle indices are stored as `u32` in ids and in the cell list,
/// and 2^29 particles already need tens of GB.
pub(crate) const MAX_PARTICLES: usize = 1 << 29;

/// Coulomb force quench distance (the source leaves it unset).
pub(crate) const COULOMB_QUENCH: f64 = 1e-3;

/// A scenario's defaults.
#[derive(Clone, Copy, Debug)]
pub struct Defaults {
    /// Particle count when `-n` is not given.
    pub n: usize,
    /// Time step, in the scenario's simulated time units.
    pub dt: f64,
    /// Precision when `--precision` is not given.
    pub precision: Precision,
    /// Particles per unit area (per unit volume in 3-D), for the scenarios that have a
    /// density parameter.
    pub density: Option<f64>,
}

/// Floating-point precision of positions, velocities and forces.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, serde::Deserialize)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
#[serde(rename_all = "kebab-case")]
pub enum Precision {
    /// 32-bit floats: the Lennard-Jones scenarios' default.
    F32,
    /// 64-bit floats: the default of coulomb and galaxy.
    F64,
}

impl Precision {
    /// Bytes of one number.
    pub fn bytes(self) -> usize {
        match self {
            Precision::F32 => 4,
            Precision::F64 => 8,
        }
    }

    /// `f32` or `f64`, as the command line and the results write it.
    pub fn name(self) -> &'static str {
        match self {
            Precision::F32 => "f32",
            Precision::F64 => "f64",
        }
    }
}

/// A scenario with the user's overrides; `None` means the scenario's default.
#[derive(Clone, Debug)]
pub struct Setup {
    /// The physical set-up to build.
    pub scenario: ScenarioKind,
    /// Particle count asked (`-n`); `None`: the scenario's default (an initial-state file sets it
    /// instead).
    pub n: Option<usize>,
    /// Seed of the random placement and velocities: the same seed builds the same state.
    pub seed: u64,
    /// Time step in simulated time units; `None`: the scenario's default.
    pub dt: Option<f64>,
    /// Particles per unit area (Lennard-Jones scenarios only; the box side becomes √(n/ρ)).
    pub density: Option<f64>,
    /// Precision to run in; `None`: the scenario's default (f32 for LJ, f64 otherwise).
    pub precision: Option<Precision>,
    /// Accept fewer particles than asked when the box cannot hold `n` at minimum spacing.
    pub allow_fewer: bool,
    /// Start from these bodies instead of the scenario's placement (`run --initial`); they
    /// set n. Shared: a set-up is cloned per case and per probe.
    pub initial: Option<Arc<InitialBodies>>,
    /// Lennard-Jones parameters changed from the scenario's.
    pub lj: LjOverrides,
}

/// Why a [`Setup`] cannot be built.
#[derive(Debug, Error)]
pub enum SetupError {
    /// The particle count is 0.
    #[error("n must be at least 1 (got 0)")]
    ZeroParticles,
    /// The particle count is above 2^29, the most particle ids (`u32`) and memory allow.
    #[error("n = {0} is more than this tool handles (at most {MAX_PARTICLES} particles)")]
    TooManyParticles(usize),
    /// The time step is zero, negative or not finite.
    #[error("--dt must be a positive finite number (got {0})")]
    BadDt(f64),
    /// The density given is zero, negative or not finite.
    #[error("--density must be a positive finite number (got {0})")]
    BadDensity(f64),
    /// A density was given to a scenario that has none (coulomb, galaxy); holds its name.
    #[error("scenario `{0}` has no density parameter; drop --density")]
    NoDensity(&'static str),
    /// The box side √(n/ρ) is so large that positions in this precision cannot resolve σ near the
    /// far wall.
    #[error(
        "a box of side {side:.3e} ({n} particles at density {density:e}) is too large for {precision} \
         positions to resolve the particle size σ = {sigma}: raise --density, lower -n, or use \
         --precision f64"
    )]
    BoxTooLarge {
        /// Side of the box, √(n/ρ).
        side: f64,
        /// Particle count.
        n: usize,
        /// Particles per unit area.
        density: f64,
        /// Precision name, `f32` or `f64`.
        precision: &'static str,
        /// Particle size σ that positions must resolve.
        sigma: f64,
    },
    /// lj-melt was asked for a count that is not 4k³, the atoms of an fcc lattice of k³ cells.
    #[error(
        "lj-melt places its atoms on an fcc lattice of k^3 cells, 4 atoms each: n must be 4k^3 \
         (4000, 32000, 256000, ...), not {0}"
    )]
    NotFcc(usize),
    /// The periodic box is not more than twice the cutoff wide, so a pair would interact
    /// through two images.
    #[error(
        "the periodic box of side {side:.4} is not more than twice the cutoff {rc}: a pair would \
         meet through two images: give more atoms (lj-melt: n = 108 or more) or a lower --density"
    )]
    PeriodicTooSmall {
        /// The box's side.
        side: f64,
        /// The cutoff.
        rc: f64,
    },
    /// The seeded placement could not fit the particles at minimum spacing σ.
    #[error(transparent)]
    Placement(#[from] PlacementError),
    /// A Lennard-Jones option was given to a scenario of another law: the flag and the scenario's
    /// name.
    #[error(
        "{flag} applies to the Lennard-Jones scenarios (lj-box, lj-liquid, lj-gas, lj-melt) only; \
         scenario `{1}` \
         has no such parameter: drop it", flag = .0
    )]
    NotLj(&'static str, &'static str),
    /// A Lennard-Jones option has a value the physics cannot use (ε or σ not positive, g or T0 not
    /// finite, T0 < 0).
    #[error("{flag} must be {want} (got {got})")]
    BadLj {
        /// The option, as the command line names it (`--sigma`, ...).
        flag: &'static str,
        /// What it accepts, in words.
        want: &'static str,
        /// The value given.
        got: f64,
    },
    /// `-n` differs from the number of bodies in the initial-state file.
    #[error(
        "n = {n} was asked but the initial state {} holds {bodies} bodies: drop -n (the file \
         sets n) or give -n {bodies}", path.display()
    )]
    InitialCount {
        /// The initial-state file.
        path: std::path::PathBuf,
        /// The count asked with `-n`.
        n: usize,
        /// Bodies in the file.
        bodies: usize,
    },
    /// `--t0` was given with an initial-state file, whose bodies carry their own velocities.
    #[error(
        "--t0 sets the velocities of generated particles; the bodies of the initial state {} \
         carry their own: drop --t0", .0.display()
    )]
    T0WithInitial(std::path::PathBuf),
    /// The initial-state file could not be read, or its bodies do not fit the scenario.
    #[error(transparent)]
    Initial(#[from] InitialError),
}

impl Setup {
    /// The scenario with no overrides: its defaults, seed 1.
    pub fn new(scenario: ScenarioKind) -> Self {
        Setup {
            scenario,
            n: None,
            seed: 1,
            dt: None,
            density: None,
            precision: None,
            allow_fewer: false,
            initial: None,
            lj: LjOverrides::default(),
        }
    }

    /// The bodies of the initial state, else `-n`, else the scenario's default.
    pub fn n(&self) -> usize {
        match &self.initial {
            Some(bodies) => bodies.len(),
            None => self.n.unwrap_or(self.scenario.defaults().n),
        }
    }

    /// The time step in simulated time units: the override, else the scenario's default.
    pub fn dt(&self) -> f64 {
        self.dt.unwrap_or(self.scenario.defaults().dt)
    }

    /// The precision: the override, else the scenario's default.
    pub fn precision(&self) -> Precision {
        self.precision.unwrap_or(self.scenario.defaults().precision)
    }

    /// The density given, else the scenario's: the liquid's follows σ (reduced density 0.8).
    pub fn density(&self) -> Option<f64> {
        match (self.density, self.scenario) {
            (Some(rho), _) => Some(rho),
            (None, ScenarioKind::LjLiquid) if self.lj.sigma.is_some() => {
                let sigma = self.lj.sigma();
                Some(LJ_LIQUID_REDUCED_DENSITY / (sigma * sigma))
            }
            (None, ScenarioKind::LjMelt) if self.lj.sigma.is_some() => {
                Some(MELT_DENSITY / self.lj.sigma().powi(3))
            }
            (None, _) => self.scenario.defaults().density,
        }
    }

    /// Checks the overrides before anything is built.
    pub fn validate(&self) -> Result<(), SetupError> {
        self.lj.validate(self.scenario)?;
        if let Some(bodies) = &self.initial {
            if let Some(n) = self.n.filter(|&n| n != bodies.len()) {
                return Err(SetupError::InitialCount {
                    path: bodies.path.clone(),
                    n,
                    bodies: bodies.len(),
                });
            }
            if self.lj.t0.is_some() {
                return Err(SetupError::T0WithInitial(bodies.path.clone()));
            }
        }
        if self.n() == 0 {
            return Err(SetupError::ZeroParticles);
        }
        if self.n() > MAX_PARTICLES {
            return Err(SetupError::TooManyParticles(self.n()));
        }
        if self.scenario == ScenarioKind::LjMelt
            && self.initial.is_none()
            && melt::fcc_cells(self.n()).is_none()
        {
            return Err(SetupError::NotFcc(self.n()));
        }
        let dt = self.dt();
        if !(dt.is_finite() && dt > 0.0) {
            return Err(SetupError::BadDt(dt));
        }
        if let Some(rho) = self.density {
            if self.scenario.defaults().density.is_none() {
                return Err(SetupError::NoDensity(self.scenario.name()));
            }
            if !(rho.is_finite() && rho > 0.0) {
                return Err(SetupError::BadDensity(rho));
            }
        }
        if let Some(density) = self.density() {
            // A finite geometry the precision can resolve: positions near the far wall must
            // still tell apart points σ apart (and the side itself must be finite).
            let side = self.box_side(density);
            let epsilon = match self.precision() {
                Precision::F32 => f32::EPSILON as f64,
                Precision::F64 => f64::EPSILON,
            };
            let sigma = self.lj.sigma();
            if !side.is_finite() || side * epsilon * 16.0 > sigma {
                return Err(SetupError::BoxTooLarge {
                    side,
                    n: self.n(),
                    density,
                    precision: self.precision().name(),
                    sigma,
                });
            }
        }
        if let (true, Some(density)) = (self.scenario.periodic(), self.density()) {
            // Every pair meets through its nearest image only: no two images of a particle
            // may both lie within the cutoff.
            let (side, rc) = (self.box_side(density), self.lj.cutoff());
            if side <= 2.0 * rc {
                return Err(SetupError::PeriodicTooSmall { side, rc });
            }
        }
        if let Some(bodies) = &self.initial {
            let side = self.density().map(|rho| self.box_side(rho));
            bodies.check(self.scenario, side)?;
        }
        Ok(())
    }

    /// The side of the scenario's box at number `density`: (n/ρ)^(1/D).
    pub(crate) fn box_side(&self, density: f64) -> f64 {
        (self.n() as f64 / density).powf(1.0 / self.scenario.dim() as f64)
    }

    /// Builds the system in the scenario's dimension, law and precision and runs `job` on it.
    pub fn dispatch<J: SystemJob>(&self, job: J) -> Result<J::Output, SetupError> {
        self.validate()?;
        Ok(match (self.scenario, self.precision()) {
            (
                ScenarioKind::LjBox | ScenarioKind::LjLiquid | ScenarioKind::LjGas,
                Precision::F32,
            ) => job.run(lj::build::<f32>(self)?),
            (
                ScenarioKind::LjBox | ScenarioKind::LjLiquid | ScenarioKind::LjGas,
                Precision::F64,
            ) => job.run(lj::build::<f64>(self)?),
            (ScenarioKind::LjMelt, Precision::F32) => job.run(melt::build::<f32>(self)?),
            (ScenarioKind::LjMelt, Precision::F64) => job.run(melt::build::<f64>(self)?),
            (ScenarioKind::Coulomb, Precision::F32) => job.run(self.coulomb::<f32>()),
            (ScenarioKind::Coulomb, Precision::F64) => job.run(self.coulomb::<f64>()),
            (ScenarioKind::Galaxy, Precision::F32) => job.run(self.galaxy::<f32>()),
            (ScenarioKind::Galaxy, Precision::F64) => job.run(self.galaxy::<f64>()),
        })
    }

    fn coulomb<T: Real>(&self) -> System<T, Coulomb<T>, 3> {
        let n = self.n();
        let state = match &self.initial {
            Some(bodies) => bodies.state(),
            None => {
                let mut rng = Pcg64Mcg::seed_from_u64(self.seed);
                let mut state = State::<T, 3>::new(n);
                for i in 0..n {
                    for d in 0..3 {
                        state.pos[d][i] = T::of(rand::Rng::random::<f64>(&mut rng));
                    }
                    state.source[i] = if i % 2 == 0 { T::one() } else { -T::one() };
                }
                state
            }
        };
        System {
            state,
            law: Coulomb::new(COULOMB_QUENCH),
            boundary: Boundary::Open,
            external: [T::zero(); 3],
            dt: T::of(self.dt()),
            info: self.info(n, None),
        }
    }

    fn galaxy<T: Real>(&self) -> System<T, Gravity<T>, 3> {
        let n = self.n();
        let state = match &self.initial {
            Some(bodies) => bodies.state(),
            None => galaxy::galaxy::<T>(n, self.seed),
        };
        System {
            state,
            law: Gravity::new(galaxy::G, galaxy::SOFTENING),
            boundary: Boundary::Open,
            external: [T::zero(); 3],
            dt: T::of(self.dt()),
            info: self.info(n, None),
        }
    }

    fn info(&self, n: usize, side: Option<f64>) -> SystemInfo {
        SystemInfo {
            scenario: self.scenario,
            n,
            n_requested: self.n(),
            seed: self.seed,
            dt: self.dt(),
            precision: self.precision(),
            density: self.density(),
            box_side: side,
            initial: self.initial.as_ref().map(|b| b.path.display().to_string()),
        }
    }
}

/// Facts about a built system, for summaries and results.
#[derive(Clone, Debug, Serialize)]
pub struct SystemInfo {
    /// The scenario built.
    pub scenario: ScenarioKind,
    /// Particles actually placed.
    pub n: usize,
    /// Particles asked; more than `n` when `--allow-fewer` let the placement put fewer.
    pub n_requested: usize,
    /// Seed of the placement and velocities.
    pub seed: u64,
    /// Time step, in simulated time units.
    pub dt: f64,
    /// Precision the system runs in.
    pub precision: Precision,
    /// Particles per unit area of the Lennard-Jones box; `None` for scenarios without one.
    pub density: Option<f64>,
    /// Side of the reflecting box, √(n/ρ); `None` in open space.
    pub box_side: Option<f64>,
    /// The file the bodies came from (`run --initial`), else none: the seed placed them.
    pub initial: Option<String>,
}

/// A ready-to-run system in concrete types.
#[derive(Clone, Debug)]
pub struct System<T: Real, L, const D: usize> {
    /// Positions, velocities, masses and source strengths of the particles.
    pub state: State<T, D>,
    /// The pair law, with the scenario's parameters.
    pub law: L,
    /// Reflecting walls, a periodic box or open space.
    pub boundary: Boundary<T, D>,
    /// Constant external acceleration on every particle (the lj-box field).
    pub external: [T; D],
    /// Time step in simulated time units, in the system's precision.
    pub dt: T,
    /// What was built, for summaries and results.
    pub info: SystemInfo,
}

impl<T: Real, L: CompiledKernels<T, D>, const D: usize> System<T, L, D> {
    /// The kernel `kind` for this system's law and box: in a periodic box it sums every pair
    /// through its nearest image, or is refused when it has no periodic form.
    pub fn kernel(
        &self,
        kind: crate::kernels::KernelKind,
        params: &crate::kernels::KernelParams,
    ) -> Result<Box<dyn crate::kernels::ForceKernel<T, D>>, crate::kernels::KernelError> {
        let mut kernel = kind.build::<T, L, D>(self.law, params)?;
        if let Boundary::Periodic { lo, hi } = self.boundary {
            kernel.set_periodic(lo, hi)?;
        }
        Ok(kernel)
    }
}

/// Work that runs on a system whatever its types (the visitor of [`Setup::dispatch`]).
pub trait SystemJob {
    /// What the job gives back, the same type whatever the system's.
    type Output;
    /// Runs the job on `system`, compiled for its precision, pair law and dimension.
    fn run<T: Real, L: CompiledKernels<T, D>, const D: usize>(
        self,
        system: System<T, L, D>,
    ) -> Self::Output;
}

#[cfg(test)]
mod tests {
    use super::*;

    struct Snapshot;
    impl SystemJob for Snapshot {
        type Output = (usize, Vec<f64>, Vec<f64>);
        fn run<T: Real, L: CompiledKernels<T, D>, const D: usize>(
            self,
            s: System<T, L, D>,
        ) -> Self::Output {
            // Positions and velocities: the melt's lattice is the same at every seed, its
            // velocities are not.
            let pos = (0..s.state.len())
                .flat_map(|i| s.state.position(i))
                .chain(s.state.vel.iter().flatten().copied())
                .map(|x| x.as_f64())
                .collect();
            let src = s.state.source.iter().map(|x| x.as_f64()).collect();
            (D, pos, src)
        }
    }

    #[test]
    fn same_seed_same_state_different_seed_different_state() {
        for kind in ScenarioKind::ALL {
            let mut setup = Setup::new(kind);
            setup.n = Some(kind.count_at_most(300));
            let a = setup.dispatch(Snapshot).unwrap();
            let b = setup.dispatch(Snapshot).unwrap();
            assert_eq!(a, b, "{kind:?}");
            assert_eq!(a.0, kind.dim());
            setup.seed = 2;
            assert_ne!(a.1, setup.dispatch(Snapshot).unwrap().1, "{kind:?}");
        }
    }

    #[test]
    fn a_scaled_down_melt_is_still_a_lattice() {
        let melt = ScenarioKind::LjMelt;
        assert_eq!(melt.count_at_most(2000), 1372);
        assert_eq!(melt.count_at_most(32_000), 32_000);
        assert_eq!(melt.count_at_most(31_999), 27_436);
        assert_eq!(melt.count_at_most(10), 108);
        assert_eq!(ScenarioKind::LjBox.count_at_most(2000), 2000);
    }

    #[test]
    fn coulomb_charges_alternate() {
        let mut setup = Setup::new(ScenarioKind::Coulomb);
        setup.n = Some(5);
        let (_, _, q) = setup.dispatch(Snapshot).unwrap();
        assert_eq!(q, vec![1.0, -1.0, 1.0, -1.0, 1.0]);
    }

    #[test]
    fn bad_overrides_are_refused() {
        let mut s = Setup::new(ScenarioKind::LjBox);
        s.n = Some(0);
        assert!(matches!(s.validate(), Err(SetupError::ZeroParticles)));
        let mut s = Setup::new(ScenarioKind::LjBox);
        s.dt = Some(f64::NAN);
        assert!(matches!(s.validate(), Err(SetupError::BadDt(_))));
        s.dt = Some(-1.0);
        assert!(matches!(s.validate(), Err(SetupError::BadDt(_))));
        let mut s = Setup::new(ScenarioKind::LjBox);
        s.density = Some(0.0);
        assert!(matches!(s.validate(), Err(SetupError::BadDensity(_))));
        let mut s = Setup::new(ScenarioKind::Galaxy);
        s.density = Some(1.0);
        assert!(matches!(s.validate(), Err(SetupError::NoDensity("galaxy"))));
    }
}
