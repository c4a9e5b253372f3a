//! What one round of a case measured, as the results file keeps it: every raw value (samples,
//! phases, work, the physics checks), and for external programs and MPI runs their own records.

use nbody_engine::engine::PhaseTimes;
use nbody_engine::kernels::WorkCounters;
use serde::{Deserialize, Serialize};

/// What one round measured. Times are per step.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RoundOutcome {
    /// Steps each sample's time is the mean of (an external program: the steps of one run).
    pub steps_per_sample: u64,
    /// Mean step time of each sample, seconds.
    pub samples_s: Vec<f64>,
    /// Every timed step, nanoseconds.
    #[serde(skip)]
    pub step_ns: Vec<u64>,
    /// Steps timed in the round (at least samples × steps per sample; an MPI run may time more).
    pub steps: u64,
    /// Untimed warm-up steps before the samples.
    pub warmup_steps: u64,
    /// Seconds per step in each phase (means over the timed steps); `None` (`null`) where no
    /// timer of ours ran: an external program, a job that ended without its round.
    pub phases: Option<PhaseTimes>,
    /// Work over the timed steps; `None` (`null`) where nothing of ours counted it.
    pub work: Option<WorkCounters>,
    /// Interacting pairs in the final configuration; `None` (`null`) where nothing of ours
    /// counted them.
    pub pairs_interacting: Option<u64>,
    /// Relative energy drift from the start of the warm-up to the end of the samples (an
    /// external program with an `energy` pattern: the largest of its runs' drifts); `None`
    /// (`null`) where nothing measured it: an external program without one, a job that ended
    /// without its round, a system whose initial energy is zero.
    pub energy_drift: Option<f64>,
    /// Median and max relative force error against an f64 direct sum, when asked.
    pub force_error: Option<[f64; 2]>,
    /// Particles actually simulated (fewer than asked only with `allow_fewer`).
    pub n: usize,
    /// Cost of one clock reading relative to the median step (the timing overhead).
    pub clock_overhead: f64,
    /// Mean wall time of one repetition of the reference workload on the case's threads, timed
    /// right before each sample (one value per sample, in the same order), seconds; empty when
    /// not asked.
    #[serde(default)]
    pub reference_s: Vec<f64>,
    /// Work of one force computation on the initial state (built from the seed, before the
    /// warm-up): the same in every run of the same code, whatever the timing.
    #[serde(default)]
    pub initial_work: Option<WorkCounters>,
    /// Ranks, decomposition and per-rank statistics of a case run under an MPI launcher.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mpi: Option<nbody_engine::decomp::stats::MpiReport>,
    /// Every run of an external program (`[[external]]`) with its times or its error.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub external: Option<super::external::ExternalRound>,
    /// The batch job that ran the round (`[scheduler]`), or that ended without measuring it:
    /// then the round has no samples.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub job: Option<super::scheduler::JobRecord>,
}

impl RoundOutcome {
    /// Forgets the phases, work and pair counts of an external program's round: none of our
    /// timers or counters ran in it, and a file written before they were `null` holds zeros
    /// there, which would read as measured.
    pub fn forget_unmeasured(&mut self) {
        if self.external.is_some() {
            self.phases = None;
            self.work = None;
            self.pairs_interacting = None;
        }
    }
}
