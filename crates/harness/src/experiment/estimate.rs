//! Estimates a sweep's wall time before it runs, for `sweep --dry-run` and for the guard that
//! asks before starting a sweep of more than an hour.
//!
//! Each distinct kernel set-up of the sweep (scenario, kernel, precision, θ) is probed once, on
//! one thread, at a small n (at most [`PROBE_MAX_N`], a few steps), and the probe is carried to
//! every case's n with the kernel's complexity class and to its threads with an expected
//! speedup. The time of a case then follows what `measure` and `launcher` really do per round
//! (build, energy probes, warm-up, samples of whole steps, reference, force error, or one MPI
//! launch), plus the calibrations at the start and end. Everything but [`probe`] is pure, so
//! the model is unit-tested on made-up probes.
//!
//! It is an estimate for planning, not a measurement: the probe runs at a small n where caches
//! are warmer than at a large one, and the speedup is a rule of thumb (the calibrated ceiling
//! of a 2-vCPU machine whose vCPUs are SMT siblings can be 1.0, not 1.9).

use super::measure::samples_in_round;
use nbody_engine::kernels::{Complexity, KernelKind, Multipole};
use nbody_engine::run::RunError;
use nbody_engine::scenario::{Precision, ScenarioKind, Setup, SetupError};
use nbody_engine::stepper::{Stepper, stepper};
use nbody_records::config::{MpiLaunch, SweepConfig};
use nbody_records::plan::Case;
use std::collections::HashMap;
use std::time::Instant;
use thiserror::Error;

/// Largest n a kernel set-up is probed at: a step of the slowest kernel (naive, f64) then takes
/// a few milliseconds, so probing every set-up of the quick sweep adds well under a second.
pub const PROBE_MAX_N: usize = 2000;
/// Timed steps of a probe, and the time after which it stops taking more (at least one).
const PROBE_STEPS: usize = 5;
const PROBE_STEP_BUDGET_S: f64 = 0.02;
/// Most particles the probe checks the force error on (the case's count scales it).
const PROBE_ERROR_SAMPLE: usize = 64;

/// Speedup each thread beyond the first adds, as a fraction of one thread: forks, joins and
/// reductions take the rest.
pub const EXTRA_THREAD_GAIN: f64 = 0.9;
/// Starting an MPI job (launcher, ranks, MPI initialization) and reading its result, seconds.
pub(crate) const MPI_LAUNCH_S: f64 = 0.5;
/// Per round of a case: its thread pool, the results file saved after it, the progress line
/// and its share of the analysis at the end: a rough allowance, not measured separately.
const ROUND_OVERHEAD_S: f64 = 0.01;
/// A calibration runs four measurements plus one per thread count, each for the calibration
/// budget, and sizes its loops and allocates its streaming buffer (256 MiB) first.
const CALIBRATION_SETUP_S: f64 = 0.15;
/// The reference workload runs at least three repetitions of about 0.15 ms.
const REFERENCE_MIN_S: f64 = 5e-4;

/// One kernel set-up measured on one thread at `n` particles (times in seconds).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Probe {
    /// The particle count the times are for (the probe's, or the case's after [`Probe::at`]).
    pub n: usize,
    /// Building the system and the simulation (placement, spatial order), without the energy
    /// probe the simulation starts with.
    pub build_s: f64,
    /// One force computation with energy accounting (a round takes three).
    pub(crate) energy_s: f64,
    /// The force phase of a step.
    pub force_s: f64,
    /// The rest of a step: integration, walls, reordering.
    pub(crate) other_s: f64,
    /// Candidate pairs examined per step (decides whether a step forks threads).
    pub pair_checks: f64,
    /// Seconds per sampled particle and source of the f64 force-error check, when the sweep
    /// measures it.
    pub(crate) error_pair_s: Option<f64>,
}

impl Probe {
    /// The probe carried to `n` particles: force work by the kernel's complexity class, the
    /// rest (placement, integration, walls) linearly.
    pub fn at(&self, kernel: KernelKind, n: usize) -> Probe {
        let force = kernel.complexity().ratio(self.n, n);
        let linear = Complexity::Linear.ratio(self.n, n);
        Probe {
            n,
            build_s: self.build_s * linear,
            energy_s: self.energy_s * force,
            force_s: self.force_s * force,
            other_s: self.other_s * linear,
            pair_checks: self.pair_checks * force,
            error_pair_s: self.error_pair_s,
        }
    }
}

/// Expected speedup of a step over one thread: each worker beyond the first adds
/// [`EXTRA_THREAD_GAIN`], workers beyond the logical CPUs add nothing. Threads count only for a
/// kernel that uses them and a step large enough to fork (`KernelKind::forks_at`, on the
/// pair checks: for the kernels that weigh more than those, a rule of thumb); MPI ranks are
/// processes and always share the work.
pub fn speedup(
    kernel: KernelKind,
    threads: usize,
    ranks: usize,
    pair_checks: f64,
    logical_cpus: usize,
) -> f64 {
    let ranks = ranks.max(1);
    let forks = kernel.forks_at(pair_checks / ranks as f64);
    let workers = ranks * if forks { threads.max(1) } else { 1 };
    let p = workers.min(logical_cpus.max(1));
    1.0 + EXTRA_THREAD_GAIN * (p - 1) as f64
}

/// What an existing results file already holds, when a sweep is resumed.
#[derive(Clone, Debug, Default)]
pub struct Done {
    /// Rounds measured, by case key.
    pub rounds: HashMap<String, usize>,
    /// The start calibration is in the file (a resumed sweep does not repeat it).
    pub calibrated: bool,
}

/// The estimate of one case's remaining rounds.
#[derive(Clone, Debug, PartialEq)]
pub struct CaseEstimate {
    /// The case estimated.
    pub case: Case,
    /// Rounds and samples still to measure.
    pub rounds: usize,
    /// Samples still to measure over those rounds, each a timing of whole steps.
    pub samples: usize,
    /// Expected time of one step at the case's n, threads and ranks.
    pub step_s: f64,
    /// Wall time of its remaining rounds.
    pub wall_s: f64,
}

/// The estimate of a whole sweep.
#[derive(Clone, Debug, PartialEq)]
pub struct Estimate {
    /// Each built-in kernel's case, in plan order.
    pub cases: Vec<CaseEstimate>,
    /// Each case of an external program tried once ([`with_trials`]), in plan order; empty
    /// when none was.
    pub external: Vec<CaseEstimate>,
    /// The calibrations still to run (start and end).
    pub calibration_s: f64,
    /// Expected wall time of the whole sweep, seconds: the calibrations plus every case.
    pub total_s: f64,
}

/// Estimates every case from its probe (at the probe's n) and adds the calibrations.
pub fn estimate(
    config: &SweepConfig,
    probed: &[(Case, Probe)],
    done: &Done,
    calibrate: bool,
    logical_cpus: usize,
) -> Estimate {
    // Only the built-in kernels are probed: an external program's time is its own.
    let cases: Vec<CaseEstimate> = probed
        .iter()
        .filter_map(|(case, probe)| {
            let kernel = case.kernel.kernel()?;
            let first = done.rounds.get(&case.key()).copied().unwrap_or(0);
            Some(case_estimate(
                config,
                case,
                kernel,
                &probe.at(kernel, case.n),
                first,
                logical_cpus,
            ))
        })
        .collect();
    let mut threads: Vec<usize> = probed.iter().map(|(c, _)| c.threads).collect();
    threads.sort_unstable();
    threads.dedup();
    let calibrations = match (calibrate, done.calibrated) {
        (false, _) => 0,
        (true, true) => 1,
        (true, false) => 2,
    };
    let calibration_s = calibrations as f64 * calibration_s(threads.len());
    let total_s = calibration_s + cases.iter().map(|c| c.wall_s).sum::<f64>();
    Estimate {
        cases,
        external: Vec::new(),
        calibration_s,
        total_s,
    }
}

/// `est` with the cases of every external program that was tried once (the dry run's
/// [`trial`](super::external::trial)), each carried from its trial run to the case.
pub fn with_trials(
    mut est: Estimate,
    config: &SweepConfig,
    planned: &[Case],
    trials: &[super::external::trial::Trial],
    done: &Done,
) -> Estimate {
    let m = &config.measure;
    for case in planned.iter().filter(|c| c.kernel.is_external()) {
        let name = case.kernel.name();
        let (Some(ext), Some(trial)) = (
            config.external.iter().find(|e| e.name == name),
            trials.iter().find(|t| t.case.kernel.name() == name),
        ) else {
            continue;
        };
        let first = done.rounds.get(&case.key()).copied().unwrap_or(0);
        let wall_s = super::external::trial::case_s(config, ext, trial, case, first);
        let steps = super::external::run::steps(ext, case).max(1) as f64;
        let rounds = m.rounds - first.min(m.rounds);
        est.external.push(CaseEstimate {
            case: case.clone(),
            rounds,
            samples: (first.min(m.rounds)..m.rounds)
                .map(|r| samples_in_round(m.samples, m.rounds, r))
                .sum(),
            step_s: super::external::trial::run_s(ext, trial, case) / steps,
            wall_s,
        });
        est.total_s += wall_s;
    }
    est
}

/// Wall time of one calibration with this many thread counts (`calibrate::calibrate`).
pub fn calibration_s(thread_counts: usize) -> f64 {
    let budget = nbody_calibrate::CalibrationOptions::default()
        .budget
        .as_secs_f64();
    budget * (3 + thread_counts) as f64 + CALIBRATION_SETUP_S
}

/// Rounds `first..rounds` of `case`, whose probe is already at the case's n.
fn case_estimate(
    config: &SweepConfig,
    case: &Case,
    kernel: KernelKind,
    at_n: &Probe,
    first: usize,
    logical_cpus: usize,
) -> CaseEstimate {
    let m = &config.measure;
    let ranks = if config.mpi.is_some() { case.ranks } else { 1 };
    let sp = speedup(kernel, case.threads, ranks, at_n.pair_checks, logical_cpus);
    let (step_s, energy_s) = match config.mpi {
        // Every rank integrates its own particles too.
        Some(_) => ((at_n.force_s + at_n.other_s) / sp, at_n.energy_s / sp),
        // Integration and walls run on one thread.
        None => (at_n.force_s / sp + at_n.other_s, at_n.energy_s / sp),
    };
    let step_s = step_s.max(1e-9);
    let mut wall_s = 0.0;
    let mut samples = 0;
    for round in first.min(m.rounds)..m.rounds {
        let k = samples_in_round(m.samples, m.rounds, round);
        samples += k;
        wall_s += match &config.mpi {
            Some(launch) => mpi_round_s(launch, at_n, step_s, energy_s),
            None => round_s(config, at_n, step_s, energy_s, k),
        };
    }
    CaseEstimate {
        case: case.clone(),
        rounds: m.rounds - first.min(m.rounds),
        samples,
        step_s,
        wall_s,
    }
}

/// One in-process round (`measure::measure`): the system and simulation (with its energy
/// probe), the energy probes at the start and end, a warm-up of at least one step, `samples`
/// samples of `k` whole steps (at least `min_sample_s`), each after its reference, and the
/// force error.
fn round_s(config: &SweepConfig, at_n: &Probe, step_s: f64, energy_s: f64, samples: usize) -> f64 {
    let m = &config.measure;
    let k = (m.min_sample_s / step_s).ceil().clamp(1.0, 1e6);
    let reference = if m.reference_s > 0.0 {
        m.reference_s.max(REFERENCE_MIN_S)
    } else {
        0.0
    };
    let error = match at_n.error_pair_s {
        Some(per_pair) if m.force_error_sample > 0 => {
            m.force_error_sample.min(at_n.n) as f64 * at_n.n as f64 * per_pair
        }
        _ => 0.0,
    };
    ROUND_OVERHEAD_S
        + at_n.build_s
        + 3.0 * energy_s
        // The warm-up takes at least the cold step and one more (`measure`).
        + m.warmup_s.max(2.0 * step_s)
        + samples as f64 * (k * step_s + reference)
        + error
}

/// One round under the MPI launcher (`launcher::measure_round`): a launch, the system and the
/// run's energy at the start and end on every rank, and the warm-up and timed steps.
fn mpi_round_s(launch: &MpiLaunch, at_n: &Probe, step_s: f64, energy_s: f64) -> f64 {
    MPI_LAUNCH_S
        + at_n.build_s
        + 2.0 * energy_s
        + (launch.steps + launch.warmup_steps) as f64 * step_s
}

/// The probes of a sweep's cases.
#[derive(Clone, Debug)]
pub struct Probed {
    /// Every case with the probe of its kernel set-up.
    pub cases: Vec<(Case, Probe)>,
    /// Distinct set-ups probed.
    pub setups: usize,
    /// Wall time of all the probes.
    pub seconds: f64,
}

/// Why probing a sweep's kernel set-ups failed.
#[derive(Debug, Error)]
pub enum ProbeError {
    /// rayon could not build the one-thread pool the probes run on.
    #[error("cannot start the estimate's one-thread pool: {0}")]
    Pool(rayon::ThreadPoolBuildError),
    /// A set-up's system or simulation could not be built at the probe's n.
    #[error("estimating the sweep: {what} at n = {n}: {source}")]
    Setup {
        /// The set-up, `scenario/kernel`.
        what: String,
        /// The particle count probed.
        n: usize,
        /// Why it could not be built.
        source: SetupError,
    },
    /// A set-up's probe steps (or its force-error check) failed.
    #[error("estimating the sweep: {what} at n = {n}: {source}")]
    Run {
        /// The set-up, `scenario/kernel`.
        what: String,
        /// The particle count probed.
        n: usize,
        /// Why the run failed.
        source: RunError,
    },
}

/// Probes each distinct set-up of `cases` once, on one thread, at the largest of its cases' n
/// up to [`PROBE_MAX_N`].
pub fn probe(config: &SweepConfig, cases: &[Case]) -> Result<Probed, ProbeError> {
    probe_with_error_sample(config.measure.force_error_sample, cases)
}

/// Expected wall time of a single `run` of `steps` steps of `case` (no sweep around it): the
/// system's build and energy probes, then the steps, threads counted as in [`speedup`].
pub fn run_seconds(case: &Case, steps: u64, logical_cpus: usize) -> Result<f64, ProbeError> {
    let probed = probe_with_error_sample(0, std::slice::from_ref(case))?;
    let (Some((_, probe)), Some(kernel)) = (probed.cases.first(), case.kernel.kernel()) else {
        return Ok(0.0);
    };
    let at_n = probe.at(kernel, case.n);
    let sp = speedup(kernel, case.threads, 1, at_n.pair_checks, logical_cpus);
    let step_s = at_n.force_s / sp + at_n.other_s;
    Ok(probed.seconds + at_n.build_s + 2.0 * at_n.energy_s / sp + steps as f64 * step_s)
}

fn probe_with_error_sample(error_sample: usize, cases: &[Case]) -> Result<Probed, ProbeError> {
    type Key = (
        ScenarioKind,
        KernelKind,
        Option<Precision>,
        Option<u64>,
        Multipole,
        Option<usize>,
    );
    // External programs are not probed (`None`).
    let key = |c: &Case| {
        Some((
            c.scenario,
            c.kernel.kernel()?,
            c.precision,
            c.theta.map(f64::to_bits),
            c.multipole,
            c.order,
        ))
    };
    let started = Instant::now();
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .map_err(ProbeError::Pool)?;
    let mut probes: Vec<(Key, Probe)> = Vec::new();
    for case in cases {
        let Some(this) = key(case) else {
            continue;
        };
        if probes.iter().any(|(k, _)| *k == this) {
            continue;
        }
        let same = cases.iter().filter(|c| key(c) == Some(this));
        let n = case
            .scenario
            .count_at_most(same.map(|c| c.n).max().unwrap_or(case.n).min(PROBE_MAX_N));
        let what = format!("{}/{}", case.scenario.name(), case.kernel.name());
        let mut setup = Setup::new(case.scenario);
        setup.n = Some(n);
        setup.seed = case.seed;
        setup.precision = case.precision;
        let params = case.kernel_params();
        let probe = pool
            .install(|| {
                let started = Instant::now();
                let sim = stepper(&setup, this.1, &params)?;
                Ok::<_, SetupError>(sim.and_then(|sim| probe_one(sim, started, error_sample)))
            })
            .map_err(|source| ProbeError::Setup {
                what: what.clone(),
                n,
                source,
            })?
            .map_err(|source| ProbeError::Run { what, n, source })?;
        probes.push((this, probe));
    }
    let cases = cases
        .iter()
        .filter_map(|c| {
            let this = key(c)?;
            let (_, p) = probes.iter().find(|(k, _)| *k == this)?;
            Some((c.clone(), *p))
        })
        .collect();
    Ok(Probed {
        cases,
        setups: probes.len(),
        seconds: started.elapsed().as_secs_f64(),
    })
}

/// Measures one set-up on its simulation (built after `started`).
fn probe_one(
    mut sim: Box<dyn Stepper>,
    started: Instant,
    error_sample: usize,
) -> Result<Probe, RunError> {
    let built_s = started.elapsed().as_secs_f64();
    let t = Instant::now();
    sim.probe();
    let energy_s = t.elapsed().as_secs_f64();
    // The first step allocates the kernel's scratch memory; later ones reuse it.
    sim.step()?;
    // (step, its force phase, its pair checks), each step timed alone: the median step
    // does not count a scheduler slice that another process took during one of them.
    let mut steps: Vec<(f64, f64, u64)> = Vec::new();
    let started = Instant::now();
    while steps.len() < PROBE_STEPS
        && (steps.is_empty() || started.elapsed().as_secs_f64() < PROBE_STEP_BUDGET_S)
    {
        let force0 = sim.phases().force_build + sim.phases().force_interact;
        let pairs0 = sim.work().pair_checks;
        let t = Instant::now();
        sim.step()?;
        steps.push((
            t.elapsed().as_secs_f64(),
            sim.phases().force_build + sim.phases().force_interact - force0,
            sim.work().pair_checks - pairs0,
        ));
    }
    steps.sort_by(|a, b| a.0.total_cmp(&b.0));
    let (per_step, force_s, pair_checks) = steps
        .get(steps.len().saturating_sub(1) / 2)
        .copied()
        .unwrap_or_default();
    let n = sim.len();
    let error_pair_s = (error_sample > 0).then(|| {
        let m = error_sample.min(n).min(PROBE_ERROR_SAMPLE);
        let t = Instant::now();
        sim.sampled_force_error(m, 0x5eed);
        t.elapsed().as_secs_f64() / (m * n).max(1) as f64
    });
    Ok(Probe {
        n,
        build_s: (built_s - energy_s).max(0.0),
        energy_s,
        force_s,
        other_s: (per_step - force_s).max(0.0),
        pair_checks: pair_checks as f64,
        error_pair_s,
    })
}

#[cfg(test)]
mod tests;
