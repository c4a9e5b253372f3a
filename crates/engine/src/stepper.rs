//! A running simulation whose precision, pair law and dimension are chosen at run time,
//! behind one interface: what a measurement asks of a system (steps, their phase times and
//! work, energies, a sampled force error).
//!
//! [`stepper`] is not generic on purpose: the kernels are instantiated for every system type
//! here, once, in this crate, and the crates that measure (the harness's sweeps and probes)
//! drive them through [`Stepper`] without compiling any of them again.

use crate::boundary::BoundaryError;
use crate::engine::{Energy, PhaseTimes, Simulation};
use crate::kernels::CompiledKernels;
use crate::kernels::decorator::{KernelDecorator, Plain};
use crate::kernels::{KernelKind, KernelParams, WorkCounters};
use crate::physics::PairLaw;
use crate::real::Real;
use crate::run::RunError;
use crate::scenario::{Setup, SetupError, System, SystemJob};

/// A simulation in progress, whatever its types.
pub trait Stepper: Send {
    /// Particles simulated.
    fn len(&self) -> usize;
    /// Whether there are no particles (a built system always has some).
    fn is_empty(&self) -> bool {
        self.len() == 0
    }
    /// One velocity-Verlet step.
    fn step(&mut self) -> Result<(), BoundaryError>;
    /// Steps taken so far.
    fn steps(&self) -> u64;
    /// Seconds in each phase, summed over the steps taken.
    fn phases(&self) -> PhaseTimes;
    /// Work summed over the steps taken.
    fn work(&self) -> WorkCounters;
    /// Recomputes the forces with energy accounting, untimed, and returns the energies.
    fn probe(&mut self) -> Energy;
    /// Work of the last probe (with the interacting pairs).
    fn probe_work(&self) -> WorkCounters;
    /// Median and largest relative force error of `sample` particles (chosen with `seed`)
    /// against an f64 direct sum.
    fn sampled_force_error(&self, sample: usize, seed: u64) -> (f64, f64);
}

/// The system of `setup` integrated with `kernel`.
pub fn stepper(
    setup: &Setup,
    kernel: KernelKind,
    params: &KernelParams,
) -> Result<Result<Box<dyn Stepper>, RunError>, SetupError> {
    decorated_stepper(setup, kernel, params, Plain)
}

/// [`stepper`] with the kernel passed through `decorator`.
pub fn decorated_stepper<Dc: KernelDecorator>(
    setup: &Setup,
    kernel: KernelKind,
    params: &KernelParams,
    decorator: Dc,
) -> Result<Result<Box<dyn Stepper>, RunError>, SetupError> {
    setup.dispatch(Build {
        kernel,
        params,
        decorator,
    })
}

struct Build<'a, Dc> {
    kernel: KernelKind,
    params: &'a KernelParams,
    decorator: Dc,
}

impl<Dc: KernelDecorator> SystemJob for Build<'_, Dc> {
    type Output = Result<Box<dyn Stepper>, RunError>;

    fn run<T: Real, L: CompiledKernels<T, D>, const D: usize>(
        self,
        system: System<T, L, D>,
    ) -> Self::Output {
        let law = system.law;
        let kernel = system.kernel(self.kernel, self.params)?;
        let kernel = self.decorator.decorate(kernel);
        Ok(Box::new(WithLaw {
            sim: Simulation::new(system, kernel),
            law,
        }))
    }
}

/// A simulation with the law its force error is checked against.
struct WithLaw<T: Real, L, const D: usize> {
    sim: Simulation<T, D>,
    law: L,
}

impl<T: Real, L: PairLaw<T>, const D: usize> Stepper for WithLaw<T, L, D> {
    fn len(&self) -> usize {
        self.sim.state.len()
    }

    fn step(&mut self) -> Result<(), BoundaryError> {
        self.sim.step()
    }

    fn steps(&self) -> u64 {
        self.sim.step
    }

    fn phases(&self) -> PhaseTimes {
        self.sim.phases
    }

    fn work(&self) -> WorkCounters {
        self.sim.work
    }

    fn probe(&mut self) -> Energy {
        self.sim.probe()
    }

    fn probe_work(&self) -> WorkCounters {
        self.sim.probe_work()
    }

    fn sampled_force_error(&self, sample: usize, seed: u64) -> (f64, f64) {
        crate::validate::sampled_force_error(
            &self.law,
            &self.sim.state,
            &self.sim.forces,
            sample,
            seed,
        )
    }
}
