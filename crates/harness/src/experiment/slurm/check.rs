//! Whether a job's result answers its task. A result file is whatever was found in the job's
//! directory when the job left the queue: an earlier sweep's, an earlier job's of the same
//! round, or a file that claims what no run of the task can give. It is taken only if it
//! carries the task's token and its round is one the task could have measured: the case asked,
//! its particles, no more samples than asked, the steps its kind of case takes, and counts of
//! pairs no kernel can exceed. The reason for a refusal goes into the round's job record.

use super::{JobResult, Task, Work};
use crate::experiment::measure::RoundSpec;
use crate::experiment::measure::{MAX_STEPS_PER_SAMPLE, MAX_WARMUP_STEPS};
use nbody_records::config::SweepConfig;
use nbody_records::kernel_or_program::KernelOrProgram;
use nbody_records::plan::Case;
use nbody_records::round::RoundOutcome;

/// Periodic images of one pair a kernel may look at in one step (a box under three cutoffs
/// wide): the bound of the pair counts is this many times n² per step.
const IMAGES: u128 = 27;

/// `Ok` if `result` answers `task`, else why not.
pub(super) fn answers(task: &Task, result: &JobResult) -> Result<(), String> {
    if result.token != task.token {
        return Err(
            "it does not carry this job's token: it was left by another job (an earlier sweep's, \
             or an earlier submission of this round)"
                .into(),
        );
    }
    match &task.work {
        Work::Calibrate { .. } => match result.calibration {
            Some(_) => Ok(()),
            None => Err("it holds no calibration".into()),
        },
        Work::Round { case, spec } => {
            let key = case.key();
            if result.key.as_deref() != Some(key.as_str()) {
                return Err(format!(
                    "it is a round of case `{}`, not of `{key}`",
                    result.key.as_deref().unwrap_or("(none)")
                ));
            }
            let round = result.round.as_ref().ok_or("it holds no round")?;
            plausible(case, spec, &task.config, round, result.step_ns.len())
        }
    }
}

/// How a case's round is measured, for what its steps can be.
enum Kind<'a> {
    /// A built-in kernel in the job's process: every sample asked, its steps chosen (or given).
    InProcess,
    /// A built-in kernel under the MPI launcher: the launcher's steps.
    Launched(&'a nbody_records::config::MpiLaunch),
    /// An external program: a sample per successful run of its steps.
    External(&'a nbody_records::external::config::External),
}

/// Checks `round` against the case and the round asked.
fn plausible(
    case: &Case,
    spec: &RoundSpec,
    config: &SweepConfig,
    round: &RoundOutcome,
    step_ns: usize,
) -> Result<(), String> {
    if round.n != case.n {
        return Err(format!(
            "it claims n = {}, the case has n = {}",
            round.n, case.n
        ));
    }
    let kind = kind_of(case, config)?;
    let samples = round.samples_s.len() as u128;
    let asked = spec.samples as u128;
    let exact = !matches!(kind, Kind::External(_));
    if samples > asked || (exact && samples != asked) {
        return Err(format!("it has {samples} samples where {asked} were asked"));
    }
    let k = round.steps_per_sample as u128;
    let (steps, warmup) = (round.steps as u128, round.warmup_steps as u128);
    if samples > 0 && k == 0 {
        return Err("its samples have no steps".into());
    }
    if k * samples > steps {
        return Err(format!(
            "its {samples} samples of {k} steps are more than the {steps} steps it claims"
        ));
    }
    let expected = expected_steps(&kind, case, spec, k, samples, warmup)?;
    if steps != expected.0 || expected.1.is_some_and(|w| w != warmup) {
        return Err(format!(
            "it claims {steps} steps after {warmup} warm-up steps where the round takes {}{}",
            expected.0,
            expected
                .1
                .map(|w| format!(" after {w}"))
                .unwrap_or_default()
        ));
    }
    if step_ns as u128 > steps {
        return Err(format!(
            "it times {step_ns} steps, more than the {steps} steps it claims"
        ));
    }
    within_pair_bounds(case, round, steps, warmup)
}

/// How the config measures `case`: in process, under its MPI launcher, or as its external
/// program (which must be one the config declares).
fn kind_of<'a>(case: &Case, config: &'a SweepConfig) -> Result<Kind<'a>, String> {
    Ok(match &case.kernel {
        KernelOrProgram::External(name) => Kind::External(
            config
                .external
                .iter()
                .find(|e| &e.name == name)
                .ok_or_else(|| format!("the config has no [[external]] entry named `{name}`"))?,
        ),
        KernelOrProgram::Kernel(_) => match &config.mpi {
            Some(launch) => Kind::Launched(launch),
            None => Kind::InProcess,
        },
    })
}

/// The timed steps and (if the kind fixes them) warm-up steps a round of `kind` takes, given
/// its `k` steps per sample over `samples` samples; refuses step counts the kind cannot give.
fn expected_steps(
    kind: &Kind,
    case: &Case,
    spec: &RoundSpec,
    k: u128,
    samples: u128,
    warmup: u128,
) -> Result<(u128, Option<u128>), String> {
    Ok(match kind {
        Kind::InProcess => {
            let chosen = spec.steps_per_sample.map(u128::from);
            if chosen.is_some_and(|c| c != k) || k > MAX_STEPS_PER_SAMPLE as u128 {
                return Err(format!(
                    "it claims {k} steps per sample where {} were asked",
                    chosen.map_or(format!("at most {MAX_STEPS_PER_SAMPLE}"), |c| c.to_string())
                ));
            }
            if warmup > MAX_WARMUP_STEPS as u128 {
                return Err(format!(
                    "it claims {warmup} warm-up steps, more than the {MAX_WARMUP_STEPS} a round takes"
                ));
            }
            (k * samples, None)
        }
        Kind::Launched(launch) => (launch.steps as u128, Some(launch.warmup_steps as u128)),
        Kind::External(ext) => {
            let per_run = crate::experiment::external::run::steps(ext, case) as u128;
            if k != per_run {
                return Err(format!(
                    "it claims {k} steps per sample where each run takes {per_run}"
                ));
            }
            (k * samples, Some(per_run * ext.warmup_runs as u128))
        }
    })
}

/// Checks the round's counts of pairs against the most its `steps + warmup` steps over the
/// case's n particles can look at.
fn within_pair_bounds(
    case: &Case,
    round: &RoundOutcome,
    steps: u128,
    warmup: u128,
) -> Result<(), String> {
    // Pairs looked at: at most every ordered pair, in every image, in every step.
    let n = case.n as u128;
    let per_step = IMAGES.saturating_mul(n.saturating_mul(n));
    let over_steps = per_step.saturating_mul((steps + warmup).max(1));
    // Counts the round does not have (nothing of ours counted them) claim nothing.
    let w = round.work.unwrap_or_default();
    for (what, value, bound) in [
        ("pair checks", w.pair_checks, over_steps),
        ("interacting pairs", w.pairs_interacting, over_steps),
        ("neighbour-list entries", w.list_entries, over_steps),
        (
            "interacting pairs in the final state",
            round.pairs_interacting.unwrap_or(0),
            per_step,
        ),
    ] {
        if value as u128 > bound {
            return Err(format!(
                "it claims {value} {what}, more than {IMAGES} images of the n² pairs of its \
                 {} steps allow ({bound})",
                if bound == per_step {
                    1
                } else {
                    (steps + warmup).max(1)
                }
            ));
        }
    }
    if let Some(initial) = &round.initial_work
        && initial.pair_checks as u128 > per_step
    {
        return Err(format!(
            "it claims {} pair checks in one force computation, more than {IMAGES} images of \
             the n² pairs allow ({per_step})",
            initial.pair_checks
        ));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use nbody_engine::kernels::{KernelKind, WorkCounters};
    use nbody_engine::scenario::ScenarioKind;

    fn case() -> Case {
        Case {
            scenario: ScenarioKind::LjBox,
            kernel: KernelKind::Naive.into(),
            n: 100,
            threads: 1,
            ranks: 1,
            theta: None,
            multipole: Default::default(),
            order: None,
            skin: None,
            seed: 1,
            precision: None,
            time_factor: 1,
            decomp: None,
        }
    }

    fn spec(samples: usize) -> RoundSpec {
        RoundSpec::bare(samples)
    }

    fn config() -> SweepConfig {
        SweepConfig::parse(
            "name = \"c\"\nstudy = \"cartesian\"\nscenarios = [\"lj-box\"]\nkernels = \
             [\"naive\"]\nn = [100]\n",
            std::path::Path::new("c.toml"),
        )
        .unwrap()
    }

    /// A round as a job in this process would measure it: 2 samples of 5 steps.
    fn round() -> RoundOutcome {
        let mut r = crate::experiment::slurm::unmeasured_round(
            &case(),
            &spec(2),
            nbody_records::scheduler::JobRecord {
                id: "1".into(),
                node: None,
                state: None,
                error: None,
            },
        );
        r.job = None;
        r.samples_s = vec![1e-3, 1e-3];
        r.steps_per_sample = 5;
        r.steps = 10;
        r.warmup_steps = 3;
        r.work = Some(WorkCounters {
            pair_checks: 10 * 100 * 99,
            ..Default::default()
        });
        r.pairs_interacting = Some(400);
        r
    }

    fn why(change: impl FnOnce(&mut RoundOutcome)) -> String {
        let mut r = round();
        change(&mut r);
        plausible(&case(), &spec(2), &config(), &r, 10).unwrap_err()
    }

    #[test]
    fn a_round_the_task_could_give_is_taken_and_others_are_named() {
        plausible(&case(), &spec(2), &config(), &round(), 10).unwrap();
        assert!(why(|r| r.n = 1_000_000).contains("n = 1000000"));
        assert!(why(|r| r.samples_s = vec![1e-3; 100_000]).contains("100000 samples"));
        assert!(why(|r| r.samples_s = vec![1e-3]).contains("1 samples where 2"));
        assert!(why(|r| r.work.as_mut().unwrap().pair_checks = u64::MAX).contains("pair checks"));
        assert!(why(|r| r.pairs_interacting = Some(u64::MAX)).contains("final state"));
        assert!(why(|r| r.steps = u64::MAX).contains("steps"));
        assert!(why(|r| r.steps_per_sample = 0).contains("no steps"));
        assert!(why(|r| r.warmup_steps = u64::MAX).contains("warm-up"));
        let mut fixed = spec(2);
        fixed.steps_per_sample = Some(4);
        let e = plausible(&case(), &fixed, &config(), &round(), 10).unwrap_err();
        assert!(e.contains("5 steps per sample where 4"), "{e}");
        let e = plausible(&case(), &spec(2), &config(), &round(), 11).unwrap_err();
        assert!(e.contains("times 11 steps"), "{e}");
    }
}
