//! One measured run: a scenario integrated with one kernel for a number of steps, timed per
//! step and per phase, with work counters and an energy check. Used by `run` and by sweeps.

use crate::clock::Clock;
use crate::engine::{Energy, PhaseTimes, Simulation};
use crate::kernels::{KernelKind, KernelParams, WorkCounters, footprint};
use crate::output::nbview::{self, NbviewFormat};
use crate::output::{AtomicFile, WriteError, dump};
use crate::physics::PairLaw;
use crate::real::Real;
use crate::scenario::{Setup, System, SystemInfo, SystemJob};
use crate::simd;
use crate::stats::StepPercentiles;
use serde::Serialize;
use std::path::PathBuf;

/// Schema tag of the `run --json` document.
pub const RUN_SCHEMA: &str = "nbody-bench/run/v1";

/// What to run, besides the system.
#[derive(Clone, Debug)]
pub struct RunSpec {
    pub kernel: KernelKind,
    pub params: KernelParams,
    pub steps: u64,
    pub threads: usize,
    pub trajectory: Option<TrajectorySpec>,
    pub dump_state: Option<PathBuf>,
}

#[derive(Clone, Debug)]
pub struct TrajectorySpec {
    pub path: PathBuf,
    pub format: NbviewFormat,
    /// A frame every this many steps (and the initial state).
    pub every: u64,
}

#[derive(Debug, thiserror::Error)]
pub enum RunError {
    #[error(transparent)]
    Kernel(#[from] crate::kernels::KernelError),
    #[error(transparent)]
    Boundary(#[from] crate::boundary::BoundaryError),
    #[error(transparent)]
    Write(#[from] WriteError),
    #[error("cannot start a pool of {threads} threads: {source}")]
    Pool {
        threads: usize,
        source: rayon::ThreadPoolBuildError,
    },
    #[error(
        "energy is not finite after step {step} (E = {energy}); the simulation blew up — reduce --dt"
    )]
    EnergyBlowUp { step: u64, energy: f64 },
}

/// The result of a run, as written by `run --json`.
#[derive(Clone, Debug, Serialize)]
pub struct RunOutcome {
    pub schema: &'static str,
    pub tool_version: &'static str,
    pub scenario: &'static str,
    pub kernel: &'static str,
    pub law: &'static str,
    pub n: usize,
    pub n_requested: usize,
    pub steps: u64,
    pub threads: usize,
    /// Threads exceed the machine's logical CPUs.
    pub oversubscribed: bool,
    pub dim: usize,
    pub precision: &'static str,
    pub seed: u64,
    pub dt: f64,
    pub density: Option<f64>,
    pub box_side: Option<f64>,
    pub kernel_params: KernelParams,
    /// Instruction set the pair loops ran with.
    pub simd: &'static str,
    pub timing: Timing,
    pub throughput: Throughput,
    pub counters: Counters,
    pub energy: EnergyCheck,
    pub momentum: MomentumCheck,
    /// Ranks, decomposition and per-rank statistics of an MPI run (`--decomp`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub mpi: Option<crate::decomp::stats::MpiReport>,
}

#[derive(Clone, Debug, Serialize)]
pub struct Timing {
    /// Wall time of the stepping loop, including trajectory output.
    pub total_s: f64,
    /// Time per step (output excluded), nanoseconds.
    pub per_step_ns: StepPercentiles,
    /// Seconds per phase, summed over the steps.
    pub phases: PhaseTimes,
    /// Median ns per particle-step.
    pub ns_per_particle_step: f64,
}

#[derive(Clone, Debug, Serialize)]
pub struct Throughput {
    /// n × steps / (sum of step times).
    pub particle_steps_per_s: f64,
    /// Pair distance evaluations per second of step time.
    pub pair_evals_per_s: f64,
}

#[derive(Clone, Debug, Serialize)]
pub struct Counters {
    /// Work summed over the timed steps.
    pub total: WorkCounters,
    /// Pair evaluations per step (mean over the timed steps).
    pub pair_checks_per_step: f64,
    /// Interacting pairs in the final configuration (from the energy probe).
    pub pairs_interacting_final: u64,
}

#[derive(Clone, Debug, Serialize)]
pub struct EnergyCheck {
    pub initial: Energy,
    #[serde(rename = "final")]
    pub last: Energy,
    /// (E_final − E_initial) / |E_initial|.
    pub rel_drift: f64,
    /// The Lennard-Jones energy is shifted to zero at the cutoff (the force is not).
    pub lj_potential: &'static str,
}

#[derive(Clone, Debug, Serialize)]
pub struct MomentumCheck {
    pub initial: Vec<f64>,
    #[serde(rename = "final")]
    pub last: Vec<f64>,
}

/// Runs `spec` on the system it is given (see [`crate::scenario::Setup::dispatch`]), its
/// steps timed by the clock.
pub struct RunJob<'a, C: Clock>(pub &'a RunSpec, pub &'a C);

impl<C: Clock> SystemJob for RunJob<'_, C> {
    type Output = Result<RunOutcome, RunError>;

    fn run<T: Real, L: PairLaw<T>, const D: usize>(self, system: System<T, L, D>) -> Self::Output {
        let spec = self.0;
        let kernel = spec.kernel.build::<T, L, D>(system.law, &spec.params)?;
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(spec.threads)
            .build()
            .map_err(|source| RunError::Pool {
                threads: spec.threads,
                source,
            })?;
        let info = system.info.clone();
        let law = system.law.kind().name();
        let clock = self.1;
        pool.install(|| measure(spec, clock, &info, law, Simulation::new(system, kernel)))
    }
}

fn measure<T: Real, const D: usize, C: Clock>(
    spec: &RunSpec,
    clock: &C,
    info: &SystemInfo,
    law: &'static str,
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
    let e1 = sim.probe();
    if !e1.total().is_finite() {
        return Err(RunError::EnergyBlowUp {
            step: sim.step,
            energy: e1.total(),
        });
    }
    if let Some(mut tr) = trajectory {
        // The final state is always in the trajectory, also when --steps is not a multiple of
        // --every.
        if !sim.step.is_multiple_of(tr.every) {
            tr.frame(&sim)?;
        }
        tr.file.commit()?;
    }
    if let Some(path) = &spec.dump_state {
        let header = format!(
            "scenario {} dim {D} precision {} n {n} seed {} steps {} dt {}",
            info.scenario.name(),
            T::NAME,
            info.seed,
            sim.step,
            info.dt
        );
        crate::output::write_atomic(
            path,
            dump::state_dump(&header, &sim.state, &sim.forces).as_bytes(),
        )?;
    }
    let step_sum_s = step_ns.sum_s();
    let per_step_ns = step_ns.percentiles().unwrap_or_default();
    let steps = sim.step.max(1) as f64;
    Ok(RunOutcome {
        schema: RUN_SCHEMA,
        tool_version: env!("CARGO_PKG_VERSION"),
        scenario: info.scenario.name(),
        kernel: spec.kernel.name(),
        law,
        n,
        n_requested: info.n_requested,
        steps: sim.step,
        threads: spec.threads,
        oversubscribed: spec.threads > logical_cpus(),
        dim: D,
        precision: T::NAME,
        seed: info.seed,
        dt: info.dt,
        density: info.density,
        box_side: info.box_side,
        kernel_params: spec.params,
        simd: simd::level().name(),
        timing: Timing {
            total_s,
            per_step_ns,
            phases: sim.phases,
            ns_per_particle_step: per_step_ns.p50 as f64 / n as f64,
        },
        throughput: Throughput {
            particle_steps_per_s: if step_sum_s > 0.0 {
                n as f64 * steps / step_sum_s
            } else {
                0.0
            },
            pair_evals_per_s: if step_sum_s > 0.0 {
                sim.work.pair_checks as f64 / step_sum_s
            } else {
                0.0
            },
        },
        counters: Counters {
            total: sim.work,
            pair_checks_per_step: sim.work.pair_checks as f64 / steps,
            pairs_interacting_final: sim.probe_work().pairs_interacting,
        },
        energy: EnergyCheck {
            initial: e0,
            last: e1,
            rel_drift: (e1.total() - e0.total()) / e0.total().abs(),
            lj_potential: "shifted",
        },
        momentum: MomentumCheck {
            initial: p0,
            last: sim.state.momentum().to_vec(),
        },
        mpi: None,
    })
}

/// Most threads a run's pool may have: far beyond any oversubscription study on the machines
/// this runs on, and far below what would exhaust memory with thread stacks.
pub const MAX_THREADS: usize = 1024;

/// Refuses a run the machine cannot hold (see `kernels::footprint`), before anything is
/// built; `processes` is the number of copies on this machine (MPI ranks each holding all n).
pub fn check_memory(
    setup: &Setup,
    kernel: KernelKind,
    threads: usize,
    processes: usize,
) -> Result<(), footprint::TooLarge> {
    footprint::check(
        kernel,
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
        let (lo, hi) = sim.state.bounding_box();
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
