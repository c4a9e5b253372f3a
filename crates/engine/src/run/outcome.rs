//! The result of a run, serial or distributed, and its one assembly from what was measured.

use crate::decomp::stats::MpiReport;
use crate::engine::{Energy, PhaseTimes};
use crate::kernels::{KernelKind, KernelParams, WorkCounters};
use crate::real::Real;
use crate::scenario::SystemInfo;
use crate::simd;
use crate::stats::{StepHistogram, StepPercentiles};
use serde::Serialize;

/// Schema tag of the `run --json` document.
pub(crate) const RUN_SCHEMA: &str = "nbody-bench/run/v1";

/// The result of a run, as written by `run --json`.
#[derive(Clone, Debug, Serialize)]
pub struct RunOutcome {
    /// Schema tag of the document, `nbody-bench/run/v1`: it changes when the layout does.
    pub schema: &'static str,
    /// Version of the engine crate that ran (`CARGO_PKG_VERSION`).
    pub tool_version: &'static str,
    /// Scenario name (`lj-box`, `galaxy`, ...).
    pub scenario: &'static str,
    /// Kernel name, as `--kernel` takes it.
    pub kernel: &'static str,
    /// Pair law name (`lennard-jones`, `coulomb`, `gravity`).
    pub law: &'static str,
    /// Particles simulated (all ranks together in an MPI run).
    pub n: usize,
    /// Particles asked; more than `n` when `--allow-fewer` let the placement put fewer.
    pub n_requested: usize,
    /// Steps taken and timed.
    pub steps: u64,
    /// Threads per process (the size of the run's thread pool).
    pub threads: usize,
    /// Threads exceed the machine's logical CPUs.
    pub oversubscribed: bool,
    /// Spatial dimension, 2 or 3.
    pub dim: usize,
    /// Floating-point precision, `f32` or `f64`.
    pub precision: &'static str,
    /// Seed of the initial state.
    pub seed: u64,
    /// Time step, in simulated time units.
    pub dt: f64,
    /// Particles per unit area of the Lennard-Jones box; `None` for scenarios without one.
    pub density: Option<f64>,
    /// Side of the reflecting box, √(n/ρ); `None` in open space.
    pub box_side: Option<f64>,
    /// The initial-state file the bodies came from (`run --initial`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub initial: Option<String>,
    /// The kernel parameters the run used (θ, leaf size, skin, order, ...).
    pub kernel_params: KernelParams,
    /// Instruction set the pair loops ran with.
    pub simd: &'static str,
    /// Wall time, per-step percentiles and time per phase.
    pub timing: Timing,
    /// Particle-steps and pair evaluations per second of step time.
    pub throughput: Throughput,
    /// The kernels' work counters.
    pub counters: Counters,
    /// Energies before and after the run, and their relative drift.
    pub energy: EnergyCheck,
    /// Total momentum before and after the run.
    pub momentum: MomentumCheck,
    /// Ranks, decomposition and per-rank statistics of an MPI run (`--decomp`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub mpi: Option<MpiReport>,
}

/// Where a run's time went: the whole loop, each step, each phase.
#[derive(Clone, Debug, Serialize)]
pub struct Timing {
    /// Wall time of the stepping loop, including trajectory output.
    pub total_s: f64,
    /// Sum of the timed steps' times (output excluded), seconds.
    pub steps_s: f64,
    /// Time per step (output excluded), nanoseconds.
    pub per_step_ns: StepPercentiles,
    /// Seconds per phase, summed over the steps.
    pub phases: PhaseTimes,
    /// Mean ns per particle-step: `steps_s / (steps · n)`. The mean, not the median step: the
    /// steps that rebuild a list or a tree are part of the cost, and the median step of a
    /// Verlet list is one without a rebuild.
    pub ns_per_particle_step: f64,
}

/// Rates over the summed step time (output excluded).
#[derive(Clone, Debug, Serialize)]
pub struct Throughput {
    /// n × steps / (sum of step times).
    pub particle_steps_per_s: f64,
    /// Pair distance evaluations per second of step time.
    pub pair_evals_per_s: f64,
}

/// The work a run's force computations did, counted by the kernels.
#[derive(Clone, Debug, Serialize)]
pub struct Counters {
    /// Work summed over the timed steps.
    pub total: WorkCounters,
    /// Pair evaluations per step (mean over the timed steps).
    pub pair_checks_per_step: f64,
    /// Interacting pairs in the final configuration (from the energy probe).
    pub pairs_interacting_final: u64,
}

/// Energy conservation of a run: the energies before and after, and the drift.
#[derive(Clone, Debug, Serialize)]
pub struct EnergyCheck {
    /// Energies before the first step.
    pub initial: Energy,
    /// Energies after the last step (`final` in the JSON).
    #[serde(rename = "final")]
    pub last: Energy,
    /// (E_final − E_initial) / |E_initial|.
    pub rel_drift: f64,
    /// The Lennard-Jones energy is shifted to zero at the cutoff (the force is not).
    pub(crate) lj_potential: &'static str,
}

/// Total momentum Σ m·v (in f64, one component per dimension) before and after a run.
#[derive(Clone, Debug, Serialize)]
pub struct MomentumCheck {
    /// Before the first step.
    pub initial: Vec<f64>,
    /// After the last step (`final` in the JSON).
    #[serde(rename = "final")]
    pub last: Vec<f64>,
}

/// What a run measured, serially or over MPI ranks; [`RunOutcome::new`] derives the rest.
pub struct Measured<'a> {
    /// Facts about the system (scenario, n asked, seed, time step, box).
    pub info: &'a SystemInfo,
    /// Pair law name (`lennard-jones`, `coulomb`, `gravity`).
    pub law: &'static str,
    /// The kernel that computed the forces.
    pub kernel: KernelKind,
    /// The kernel parameters used.
    pub params: KernelParams,
    /// Particles simulated (all ranks together in an MPI run).
    pub n: usize,
    /// Timed steps (warm-up excluded).
    pub steps: u64,
    /// Threads per process.
    pub threads: usize,
    /// Threads on this machine, over every process of the run that shares it.
    pub threads_here: usize,
    /// Wall time of the stepping loop.
    pub total_s: f64,
    /// Time of each timed step (for MPI, the slowest rank's).
    pub step_ns: &'a StepHistogram,
    /// Seconds per phase, summed over the steps.
    pub phases: PhaseTimes,
    /// Work summed over the timed steps.
    pub work: WorkCounters,
    /// Pairs within interaction range in the final state (from the energy probe).
    pub pairs_interacting_final: u64,
    /// Energies before the first and after the last step.
    pub energy: [Energy; 2],
    /// Total momentum before and after.
    pub momentum: [Vec<f64>; 2],
    /// The ranks' report of an MPI run; `None` for a serial run.
    pub mpi: Option<MpiReport>,
}

impl RunOutcome {
    /// The result of a run of `T` particles in `D` dimensions.
    pub fn new<T: Real, const D: usize>(m: Measured) -> RunOutcome {
        let per_step_ns = m.step_ns.percentiles().unwrap_or_default();
        let step_sum_s = m.step_ns.sum_s();
        let per_second = |x: f64| {
            if step_sum_s > 0.0 {
                x / step_sum_s
            } else {
                0.0
            }
        };
        let [e0, e1] = m.energy;
        let [p0, p1] = m.momentum;
        let n = m.n;
        RunOutcome {
            schema: RUN_SCHEMA,
            tool_version: env!("CARGO_PKG_VERSION"),
            scenario: m.info.scenario.name(),
            kernel: m.kernel.name(),
            law: m.law,
            n,
            n_requested: m.info.n_requested,
            steps: m.steps,
            threads: m.threads,
            oversubscribed: m.threads_here > super::logical_cpus(),
            dim: D,
            precision: T::NAME,
            seed: m.info.seed,
            dt: m.info.dt,
            density: m.info.density,
            box_side: m.info.box_side,
            initial: m.info.initial.clone(),
            kernel_params: m.params,
            simd: simd::level().name(),
            timing: Timing {
                total_s: m.total_s,
                steps_s: step_sum_s,
                per_step_ns,
                phases: m.phases,
                ns_per_particle_step: step_sum_s * 1e9 / (m.steps.max(1) as f64 * n.max(1) as f64),
            },
            throughput: Throughput {
                particle_steps_per_s: per_second(n as f64 * m.steps.max(1) as f64),
                pair_evals_per_s: per_second(m.work.pair_checks as f64),
            },
            counters: Counters {
                total: m.work,
                pair_checks_per_step: m.work.pair_checks as f64 / m.steps.max(1) as f64,
                pairs_interacting_final: m.pairs_interacting_final,
            },
            energy: EnergyCheck {
                initial: e0,
                last: e1,
                rel_drift: (e1.total() - e0.total()) / e0.total().abs(),
                lj_potential: "shifted",
            },
            momentum: MomentumCheck {
                initial: p0,
                last: p1,
            },
            mpi: m.mpi,
        }
    }
}
