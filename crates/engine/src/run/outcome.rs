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
    /// The initial-state file the bodies came from (`run --initial`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub initial: Option<String>,
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
    pub mpi: Option<MpiReport>,
}

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
    pub(crate) lj_potential: &'static str,
}

#[derive(Clone, Debug, Serialize)]
pub struct MomentumCheck {
    pub initial: Vec<f64>,
    #[serde(rename = "final")]
    pub last: Vec<f64>,
}

/// What a run measured, serially or over MPI ranks; [`RunOutcome::new`] derives the rest.
pub struct Measured<'a> {
    pub info: &'a SystemInfo,
    pub law: &'static str,
    pub kernel: KernelKind,
    pub params: KernelParams,
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
    pub pairs_interacting_final: u64,
    /// Energies before the first and after the last step.
    pub energy: [Energy; 2],
    /// Total momentum before and after.
    pub momentum: [Vec<f64>; 2],
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
