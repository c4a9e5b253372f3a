//! Measuring one case for one round: warm-up, adaptive steps per sample, timed samples,
//! phase timers, work counters and physics sanity.

use super::reference::time_reference;
use super::slowdown::{self, TestSlowdown};
use nbody_engine::clock::{Clock, clock_cost};
use nbody_engine::run::RunError;
use nbody_engine::scenario::{Setup, SetupError};
use nbody_engine::stepper::Stepper;
use nbody_records::plan::Case;
use nbody_records::round::RoundOutcome;

/// The most steps a sample takes when the round chooses (from the warm-up's step times).
pub(crate) const MAX_STEPS_PER_SAMPLE: u64 = 1_000_000;
/// The most warm-up steps a round takes, however short its steps.
pub(crate) const MAX_WARMUP_STEPS: u64 = 1_000_000;

/// How one round of a case is measured (a batch job reads it from its task file).
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub(crate) struct RoundSpec {
    pub samples: usize,
    pub warmup_s: f64,
    pub min_sample_s: f64,
    /// Steps per sample to use (a later round reuses the first round's choice); `None` to
    /// choose from the warm-up.
    pub steps_per_sample: Option<u64>,
    pub force_error_sample: usize,
    /// Seconds of the reference workload to time before each sample (0 = none).
    pub reference_s: f64,
    /// The test-only slowdown knob, if set (see `experiment::slowdown`).
    #[serde(skip)]
    pub slowdown: Option<TestSlowdown>,
}

impl RoundSpec {
    /// `samples` samples and nothing else: no warm-up, no minimum length, steps chosen, no
    /// force error or reference (the unit tests' round, and the dry run's trial of a program).
    pub(crate) fn bare(samples: usize) -> RoundSpec {
        RoundSpec {
            samples,
            warmup_s: 0.0,
            min_sample_s: 0.0,
            steps_per_sample: None,
            force_error_sample: 0,
            reference_s: 0.0,
            slowdown: None,
        }
    }
}

/// Measures one round of `case` (a built-in kernel's: external programs are measured by
/// `experiment::external`) on the system of `setup`.
pub(crate) fn measure_round<C: Clock>(
    setup: &Setup,
    case: &Case,
    kernel: nbody_engine::kernels::KernelKind,
    spec: &RoundSpec,
    clock: &C,
) -> Result<Result<RoundOutcome, RunError>, SetupError> {
    let params = case.kernel_params();
    let built = slowdown::stepper(spec.slowdown, setup, kernel, &params);
    Ok(built?.and_then(|mut sim| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(case.threads)
            .build()
            .map_err(|source| RunError::Pool {
                threads: case.threads,
                source,
            })?;
        pool.install(|| measure(spec, clock, sim.as_mut()))
    }))
}

fn measure<C: Clock>(
    spec: &RoundSpec,
    clock: &C,
    sim: &mut dyn Stepper,
) -> Result<RoundOutcome, RunError> {
    let n = sim.len();
    let e0 = sim.probe().total();
    let initial_work = sim.probe_work();
    // Warm-up: untimed for the results, but its step times choose the sample length. The
    // first step is cold (lists and trees built, caches empty) and can take many times a
    // usual one: when the round chooses the sample length, at least one step after it is
    // taken, and the cold one is left out of the choice, even with `warmup_s = 0`.
    let least = if spec.steps_per_sample.is_none() {
        2
    } else {
        1
    };
    let warm_start = clock.now();
    let mut warm = Vec::new();
    loop {
        let t = clock.now();
        sim.step()?;
        warm.push((clock.now() - t).as_secs_f64());
        if ((clock.now() - warm_start).as_secs_f64() >= spec.warmup_s && warm.len() >= least)
            || warm.len() as u64 >= MAX_WARMUP_STEPS
        {
            break;
        }
    }
    let after_cold = if warm.len() > 1 {
        &warm[1..]
    } else {
        &warm[..]
    };
    let typical = nbody_engine::stats::median(after_cold)
        .unwrap_or(0.0)
        .max(1e-9);
    let k = spec.steps_per_sample.unwrap_or_else(|| {
        ((spec.min_sample_s / typical).ceil() as u64).clamp(1, MAX_STEPS_PER_SAMPLE)
    });
    let (phases0, work0, steps0) = (sim.phases(), sim.work(), sim.steps());
    let mut samples = Vec::with_capacity(spec.samples);
    let mut reference = Vec::new();
    let mut step_ns = Vec::with_capacity(spec.samples * k as usize);
    for _ in 0..spec.samples {
        if spec.reference_s > 0.0 {
            reference.push(time_reference(clock, spec.reference_s));
        }
        let mut sum = 0u64;
        for _ in 0..k {
            let t = clock.now();
            sim.step()?;
            let dt = (clock.now() - t).as_nanos() as u64;
            step_ns.push(dt);
            sum += dt;
        }
        samples.push(sum as f64 * 1e-9 / k as f64);
    }
    let steps = sim.steps() - steps0;
    let e1 = sim.probe().finite_after(sim.steps())?.total();
    // No trajectory is written while measuring: the output phase stays zero.
    let phases = (sim.phases() - phases0).per_step(steps);
    let work = sim.work() - work0;
    let force_error = (spec.force_error_sample > 0).then(|| {
        let (median, max) = sim.sampled_force_error(spec.force_error_sample, 0x5eed);
        [median, max]
    });
    let clock_cost = clock_cost(clock);
    let median_step = nbody_engine::stats::median(&samples).unwrap_or(0.0);
    Ok(RoundOutcome {
        steps_per_sample: k,
        samples_s: samples,
        step_ns,
        steps,
        warmup_steps: warm.len() as u64,
        phases: Some(phases),
        work: Some(work),
        pairs_interacting: Some(sim.probe_work().pairs_interacting),
        // Relative to nothing when the initial energy is zero: not measured, as the MPI
        // drivers record it.
        energy_drift: (e0 != 0.0).then(|| (e1 - e0) / e0.abs()),
        force_error,
        n,
        clock_overhead: if median_step > 0.0 {
            2.0 * clock_cost / median_step
        } else {
            0.0
        },
        reference_s: reference,
        initial_work: Some(initial_work),
        mpi: None,
        external: None,
        job: None,
    })
}

/// The share of `samples` taken in `round`: equal parts, the remainder in the first rounds.
pub(crate) fn samples_in_round(samples: usize, rounds: usize, round: usize) -> usize {
    samples / rounds + usize::from(round < samples % rounds)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn samples_are_shared_between_rounds() {
        assert_eq!(
            (0..3)
                .map(|r| samples_in_round(10, 3, r))
                .collect::<Vec<_>>(),
            vec![4, 3, 3]
        );
        assert_eq!((0..2).map(|r| samples_in_round(4, 2, r)).sum::<usize>(), 4);
    }
}
