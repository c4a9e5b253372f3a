//! The criterion benches' cases behind a non-generic interface: a force computation, a kernel's
//! build phase, or a full step, each prepared for one scenario, kernel and n.
//!
//! The systems and kernels are generic over precision, law and dimension; instantiated in the
//! bench crate they would be compiled there again for every combination. Built here, through
//! [`Setup::dispatch`], they are compiled once with the library, and the bench crate holds
//! only criterion's loops.

use crate::engine::Simulation;
use crate::kernels::CompiledKernels;
use crate::kernels::{CellList, Fmm, ForceKernel, KernelKind, KernelParams, Octree, Verlet};
use crate::physics::PairLaw;
use crate::real::Real;
use crate::scenario::{Setup, System, SystemJob};
use crate::state::{Field, State, zero_field};

/// One prepared bench case; [`BenchCase::run`] is the timed work.
pub trait BenchCase: Send {
    /// The particle count.
    fn len(&self) -> usize;
    /// Whether the case has no particles (never, for a valid setup).
    fn is_empty(&self) -> bool {
        self.len() == 0
    }
    /// One unit of the timed work; returns its pair checks (0 where the work counts none).
    fn run(&mut self) -> u64;
}

/// What a case times.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Work {
    /// One force computation, on the layout the engine would give the kernel, after a first
    /// computation has built what the kernel keeps between steps (the Verlet list).
    Force,
    /// The build phase alone: cell-list binning, octree construction, the Verlet list. Only
    /// for kernels that have one ([`KernelKind::CellList`], `Octree`, `Verlet`).
    Build,
    /// One full velocity-Verlet step of the engine.
    Step,
}

/// Why a benchmark case cannot be prepared.
#[derive(Debug, thiserror::Error)]
pub enum BenchCaseError {
    /// The scenario's set-up is invalid.
    #[error(transparent)]
    Setup(#[from] crate::scenario::SetupError),
    /// The kernel does not apply to the system, or has no build phase to time; holds the message.
    #[error("{0}")]
    Kernel(String),
}

/// The case of `work` for `kernel` on the system `setup` describes (default kernel
/// parameters).
pub fn bench_case(
    setup: &Setup,
    kernel: KernelKind,
    work: Work,
) -> Result<Box<dyn BenchCase>, BenchCaseError> {
    setup.dispatch(Prepare { kernel, work })?
}

struct Prepare {
    kernel: KernelKind,
    work: Work,
}

impl SystemJob for Prepare {
    type Output = Result<Box<dyn BenchCase>, BenchCaseError>;

    fn run<T: Real, L: CompiledKernels<T, D>, const D: usize>(
        self,
        system: System<T, L, D>,
    ) -> Self::Output {
        let params = KernelParams::default();
        let kernel_error = |e: &dyn std::fmt::Display| BenchCaseError::Kernel(e.to_string());
        let build = || {
            system
                .kernel(self.kernel, &params)
                .map_err(|e| kernel_error(&e))
        };
        Ok(match self.work {
            Work::Force => {
                let mut kernel = build()?;
                let mut state = system.state;
                let mut forces = zero_field::<T, D>(state.len());
                if let Some(order) = kernel.spatial_order(&state) {
                    state.permute(&order, &mut [&mut forces]);
                }
                kernel.compute(&state, &mut forces, false);
                Box::new(ForceCase {
                    kernel,
                    state,
                    forces,
                })
            }
            Work::Build => {
                let builder: Box<dyn Builder<T, D>> = match self.kernel {
                    KernelKind::CellList => {
                        Box::new(CellList::new(system.law).map_err(|e| kernel_error(&e))?)
                    }
                    KernelKind::Octree => Box::new(Octree::with_multipole(
                        system.law,
                        params.theta,
                        params.leaf_size,
                        params.multipole,
                    )),
                    KernelKind::Verlet => Box::new(
                        Verlet::new(system.law, params.skin).map_err(|e| kernel_error(&e))?,
                    ),
                    KernelKind::Fmm => {
                        // Checks θ, the order and the dimension as a run would.
                        build()?;
                        Box::new(Fmm::new(
                            system.law,
                            params.theta,
                            params.order,
                            params.fmm_leaf_size,
                        ))
                    }
                    KernelKind::FmmHarmonic => {
                        // Checks θ, the order, the dimension and the law as a run would.
                        build()?;
                        let kernel = Fmm::harmonic(
                            system.law,
                            params.theta,
                            params.order,
                            params.fmm_leaf_size,
                        );
                        Box::new(kernel.expect("built above, so the law is 1/r"))
                    }
                    other => {
                        return Err(BenchCaseError::Kernel(format!(
                            "{} has no build phase",
                            other.name()
                        )));
                    }
                };
                Box::new(BuildCase {
                    builder,
                    state: system.state,
                })
            }
            Work::Step => {
                let kernel = build()?;
                Box::new(StepCase {
                    sim: Simulation::new(system, kernel),
                })
            }
        })
    }
}

struct ForceCase<T: Real, const D: usize> {
    kernel: Box<dyn ForceKernel<T, D>>,
    state: State<T, D>,
    forces: Field<T, D>,
}

impl<T: Real, const D: usize> BenchCase for ForceCase<T, D> {
    fn len(&self) -> usize {
        self.state.len()
    }
    fn run(&mut self) -> u64 {
        let report = self.kernel.compute(&self.state, &mut self.forces, false);
        report.work.pair_checks
    }
}

/// A kernel's build phase.
trait Builder<T: Real, const D: usize>: Send {
    fn build_phase(&mut self, state: &State<T, D>);
}

impl<T: Real, L: PairLaw<T>, const D: usize> Builder<T, D> for CellList<L, T, D> {
    fn build_phase(&mut self, state: &State<T, D>) {
        self.build(state);
    }
}

impl<T: Real, L: PairLaw<T>, const D: usize> Builder<T, D> for Octree<L, T, D> {
    fn build_phase(&mut self, state: &State<T, D>) {
        self.build(state);
    }
}

impl<T: Real, L: PairLaw<T>, const D: usize> Builder<T, D> for Fmm<L, T, D> {
    fn build_phase(&mut self, state: &State<T, D>) {
        self.build(state);
    }
}

impl<T: Real, L: PairLaw<T>, const D: usize> Builder<T, D> for Verlet<L, T, D> {
    fn build_phase(&mut self, state: &State<T, D>) {
        self.build(state);
    }
}

struct BuildCase<T: Real, const D: usize> {
    builder: Box<dyn Builder<T, D>>,
    state: State<T, D>,
}

impl<T: Real, const D: usize> BenchCase for BuildCase<T, D> {
    fn len(&self) -> usize {
        self.state.len()
    }
    fn run(&mut self) -> u64 {
        self.builder.build_phase(&self.state);
        0
    }
}

struct StepCase<T: Real, const D: usize> {
    sim: Simulation<T, D>,
}

impl<T: Real, const D: usize> BenchCase for StepCase<T, D> {
    fn len(&self) -> usize {
        self.sim.state.len()
    }
    fn run(&mut self) -> u64 {
        // The scenarios' dt keeps every particle inside its walls.
        if let Err(e) = self.sim.step() {
            panic!("bench step left the box: {e}");
        }
        0
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scenario::ScenarioKind;

    fn setup(scenario: ScenarioKind, n: usize) -> Setup {
        let mut s = Setup::new(scenario);
        s.n = Some(n);
        s
    }

    #[test]
    fn every_case_prepares_and_runs() {
        for scenario in [ScenarioKind::LjBox, ScenarioKind::Galaxy] {
            for kernel in KernelKind::ALL
                .into_iter()
                .filter(|k| k.supports(scenario.law()))
            {
                let mut force = bench_case(&setup(scenario, 300), kernel, Work::Force).unwrap();
                assert_eq!(force.len(), 300);
                assert!(force.run() > 0, "{kernel:?} on {scenario:?} checks pairs");
                let mut step = bench_case(&setup(scenario, 300), kernel, Work::Step).unwrap();
                step.run();
                let build = bench_case(&setup(scenario, 300), kernel, Work::Build);
                match kernel {
                    KernelKind::CellList
                    | KernelKind::Octree
                    | KernelKind::Verlet
                    | KernelKind::Fmm
                    | KernelKind::FmmHarmonic => {
                        build.unwrap().run();
                    }
                    _ => assert!(build.is_err(), "{kernel:?} has no build phase"),
                }
            }
        }
    }
}
