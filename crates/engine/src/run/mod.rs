//! One measured run: a scenario integrated with one kernel for a number of steps, timed per
//! step and per phase, with work counters and an energy check. Used by `run` and by sweeps.

use crate::clock::Clock;
use crate::engine::Simulation;
use crate::geometry::Bounds;
use crate::kernels::CompiledKernels;
use crate::kernels::{KernelKind, KernelParams, footprint};
use crate::output::nbview::{self, NbviewFormat};
use crate::output::{AtomicFile, WriteError, dump};
use crate::real::Real;
use crate::scenario::{Setup, System, SystemInfo, SystemJob};
use std::path::PathBuf;

pub mod bench_cases;
mod outcome;

pub use outcome::{Counters, EnergyCheck, Measured, MomentumCheck, RunOutcome, Throughput, Timing};

/// What to run, besides the system.
#[derive(Clone, Debug)]
pub struct RunSpec {
    /// The kernel that computes the forces.
    pub kernel: KernelKind,
    /// Its parameters (θ, leaf size, skin, order, ...).
    pub params: KernelParams,
    /// Steps to take, all timed.
    pub steps: u64,
    /// Threads of the run's pool.
    pub threads: usize,
    /// Where to write an NBView trajectory; `None`: no trajectory.
    pub trajectory: Option<TrajectorySpec>,
    /// Where to write the final state (`--dump-state`); `None`: no dump.
    pub dump_state: Option<PathBuf>,
}

/// An NBView trajectory to write during a run (`--trajectory`).
#[derive(Clone, Debug)]
pub struct TrajectorySpec {
    /// The file, written atomically when the run ends.
    pub path: PathBuf,
    /// Text or binary NBView.
    pub format: NbviewFormat,
    /// A frame every this many steps (and the initial state).
    pub every: u64,
}

/// Why a run stopped before giving a result.
#[derive(Debug, thiserror::Error)]
pub enum RunError {
    /// The kernel does not fit the law, the dimension or its parameters.
    #[error(transparent)]
    Kernel(#[from] crate::kernels::KernelError),
    /// A particle left the box (too large a time step) or its position stopped being finite.
    #[error(transparent)]
    Boundary(#[from] crate::boundary::BoundaryError),
    /// A trajectory or state dump could not be written.
    #[error(transparent)]
    Write(#[from] WriteError),
    /// The thread pool could not be started.
    #[error("cannot start a pool of {threads} threads: {source}")]
    Pool {
        /// Threads asked.
        threads: usize,
        /// Rayon's error.
        source: rayon::ThreadPoolBuildError,
    },
    /// The total energy stopped being finite.
    #[error(transparent)]
    EnergyBlowUp(#[from] crate::engine::EnergyBlowUp),
}

/// Runs `spec` on the system it is given (see [`crate::scenario::Setup::dispatch`]), its
/// steps timed by the clock.
pub struct RunJob<'a, C: Clock>(pub &'a RunSpec, pub &'a C);

/// `spec` on the system of `setup`, timed by the wall clock: what `nbody-bench run` does.
///
/// Not generic on purpose: the system types are instantiated here, once, in this crate, and
/// not again in each crate that runs a simulation (the binary, tests), which keeps them quick
/// to compile.
pub fn run_setup(
    setup: &crate::scenario::Setup,
    spec: &RunSpec,
) -> Result<Result<RunOutcome, RunError>, crate::scenario::SetupError> {
    setup.dispatch(RunJob(spec, &crate::clock::WallClock::new()))
}

impl<C: Clock> SystemJob for RunJob<'_, C> {
    type Output = Result<RunOutcome, RunError>;

    fn run<T: Real, L: CompiledKernels<T, D>, const D: usize>(
        self,
        system: System<T, L, D>,
    ) -> Self::Output {
        let spec = self.0;
        let kernel = system.kernel(spec.kernel, &spec.params)?;
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(spec.threads)
            .build()
            .map_err(|source| RunError::Pool {
                threads: spec.threads,
                source,
            })?;
        let info = system.info.clone();
        let law = system.law.kind().name();
        let parameters = system.law.parameters();
        let clock = self.1;
        pool.install(|| {
            let sim = Simulation::new(system, kernel);
            measure(spec, clock, &info, (law, &parameters), sim)
        })
    }
}

fn measure<T: Real, const D: usize, C: Clock>(
    spec: &RunSpec,
    clock: &C,
    info: &SystemInfo,
    (law, parameters): (&'static str, &crate::physics::LawParameters),
    mut sim: Simulation<T, D>,
) -> Result<RunOutcome, RunError> {
    let n = sim.state.len();
    let e0 = sim.probe();
    let p0 = sim.state.momentum().to_vec();
    let mut trajectory = match &spec.trajectory {
        Some(t) => Some(Trajectory::start(t, &sim, info.box_side)?),
        None => None,
    };
    // A histogram, not a vector: memory must not grow with --steps.
    let mut step_ns = crate::stats::StepHistogram::new();
    let start = clock.now();
    for _ in 0..spec.steps {
        let t = clock.now();
        sim.step()?;
        step_ns.record((clock.now() - t).as_nanos() as u64);
        if let Some(tr) = trajectory
            .as_mut()
            .filter(|tr| sim.step.is_multiple_of(tr.every))
        {
            let t = clock.now();
            tr.frame(&sim)?;
            sim.phases.output += (clock.now() - t).as_secs_f64();
        }
    }
    let total_s = (clock.now() - start).as_secs_f64();
    let e1 = sim.probe().finite_after(sim.step)?;
    if let Some(mut tr) = trajectory {
        // The final state is always in the trajectory, also when --steps is not a multiple of
        // --every.
        if !sim.step.is_multiple_of(tr.every) {
            tr.frame(&sim)?;
        }
        tr.file.commit()?;
    }
    if let Some(path) = &spec.dump_state {
        let header = dump::run_header::<T, D>(info, n, sim.step);
        crate::output::write_atomic(
            path,
            dump::state_dump(&header, parameters, &sim.state, &sim.forces).as_bytes(),
        )?;
    }
    Ok(RunOutcome::new::<T, D>(Measured {
        info,
        law,
        kernel: spec.kernel,
        params: spec.params,
        n,
        steps: sim.step,
        threads: spec.threads,
        threads_here: spec.threads,
        total_s,
        step_ns: &step_ns,
        phases: sim.phases,
        work: sim.work,
        pairs_interacting_final: sim.probe_work().pairs_interacting,
        energy: [e0, e1],
        momentum: [p0, sim.state.momentum().to_vec()],
        mpi: None,
    }))
}

/// Most threads a run's pool may have: far beyond any oversubscription study on the machines
/// this runs on, and far below what would exhaust memory with thread stacks.
pub const MAX_THREADS: usize = 1024;

/// Refuses a run the machine cannot hold (see `kernels::footprint`), before anything is
/// built; `processes` is the number of copies on this machine (MPI ranks each holding all n).
pub fn check_memory(
    setup: &Setup,
    kernel: KernelKind,
    params: &KernelParams,
    threads: usize,
    processes: usize,
) -> Result<(), footprint::TooLarge> {
    footprint::check(
        kernel,
        params,
        setup.n(),
        setup.scenario.dim(),
        setup.precision().bytes(),
        threads,
        processes,
    )
}

/// Logical CPUs available to this process.
pub fn logical_cpus() -> usize {
    std::thread::available_parallelism()
        .map(|n| n.get())
        .unwrap_or(1)
}

/// An NBView trajectory being written.
struct Trajectory {
    file: AtomicFile,
    format: NbviewFormat,
    every: u64,
    frame: Vec<[f32; 2]>,
}

impl Trajectory {
    fn start<T: Real, const D: usize>(
        spec: &TrajectorySpec,
        sim: &Simulation<T, D>,
        box_side: Option<f64>,
    ) -> Result<Self, WriteError> {
        let mut file = AtomicFile::create(&spec.path)?;
        // The viewer shows [0, scale]²: the box side, or the initial extent of an open system.
        let Bounds { lo, hi } = sim.state.bounding_box();
        let extent = (0..D.min(2))
            .map(|d| hi[d].as_f64().abs().max(lo[d].as_f64().abs()))
            .fold(0.0, f64::max);
        let scale = box_side.unwrap_or(extent);
        let n = sim.state.len();
        nbview::write_header(file.writer(), spec.format, n as u32, scale as f32)
            .map_err(|e| file.error(e))?;
        let mut t = Trajectory {
            file,
            format: spec.format,
            every: spec.every.max(1),
            frame: vec![[0.0; 2]; n],
        };
        t.frame(sim)?;
        Ok(t)
    }

    fn frame<T: Real, const D: usize>(&mut self, sim: &Simulation<T, D>) -> Result<(), WriteError> {
        let s = &sim.state;
        for (slot, &id) in s.id.iter().enumerate() {
            self.frame[id as usize] = [
                s.pos[0][slot].as_f64() as f32,
                s.pos[1.min(D - 1)][slot].as_f64() as f32,
            ];
        }
        let out = self.file.writer();
        nbview::write_frame(out, self.format, &self.frame).map_err(|e| self.file.error(e))
    }
}
