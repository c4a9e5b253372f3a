//! The dry run's trial of each external program: one run at its smallest case, as a sample
//! is taken (set-up, command, the `time`, `check` and other patterns on its output), in a
//! temporary work directory that is removed after. A program that would fail every sample (a
//! wrong script behind an interpreter, a time pattern its output never matches) is found
//! before the sweep, and the run's time carries the program into the sweep's estimate.

use super::run::{measure_round, steps};
use super::{Context, ExternalError};
use crate::experiment::measure::RoundSpec;
use crate::experiment::measure::samples_in_round;
use nbody_records::config::SweepConfig;
use nbody_records::external::External;
use nbody_records::external::config::Steps;
use nbody_records::plan::Case;
use thiserror::Error;

/// One program's trial run.
#[derive(Clone, Debug, PartialEq)]
pub struct Trial {
    /// The case it ran: the program's smallest n (then fewest workers).
    pub case: Case,
    /// Wall time of the run, seconds.
    pub run_s: f64,
    /// Wall time of the rest of its round, seconds: the set-up command and, with wall timing,
    /// the empty runs; every round takes them again.
    pub round_overhead_s: f64,
}

/// Why a program's trial failed, or could not be made.
#[derive(Debug, Error)]
pub enum TrialError {
    /// The run (or its set-up) failed: every sample of the sweep would.
    #[error(
        "external `{name}` tried once at {key}: {what}; every sample of it would fail: fix \
         the program or its `[[external]]` entry"
    )]
    Failed {
        /// The `[[external]]` entry's name.
        name: String,
        /// The case tried.
        key: String,
        /// What went wrong, with the command and the program's last line.
        what: String,
    },
    /// The run could not be started.
    #[error(transparent)]
    External(#[from] ExternalError),
    /// The temporary work directory could not be made.
    #[error("cannot create a temporary work directory for the trial runs: {0}")]
    Workdir(std::io::Error),
}

/// Tries every external program of `config` once, in a temporary work directory under the
/// system's, at its smallest planned case.
pub fn try_all(
    config: &SweepConfig,
    cases: &[Case],
    context: &Context,
) -> Result<Vec<Trial>, TrialError> {
    if config.external.is_empty() {
        return Ok(Vec::new());
    }
    let root = nbody_engine::output::TemporaryDir::new("nbody-bench-trial")
        .map_err(TrialError::Workdir)?;
    let context = Context {
        work_root: root.path().to_path_buf(),
        ..context.clone()
    };
    let mut trials = Vec::new();
    for ext in &config.external {
        let Some(case) = cases
            .iter()
            .filter(|c| c.kernel.is_external() && c.kernel.name() == ext.name)
            .min_by_key(|c| (c.n, c.threads * c.ranks))
        else {
            continue;
        };
        trials.push(try_one(ext, case, config, &context)?);
    }
    Ok(trials)
}

fn try_one(
    ext: &External,
    case: &Case,
    config: &SweepConfig,
    context: &Context,
) -> Result<Trial, TrialError> {
    // One run, as a sample is taken: no warm-up runs, the set-up timed apart.
    let once = External {
        warmup_runs: 0,
        ..ext.clone()
    };
    let spec = RoundSpec::bare(1);
    let started = std::time::Instant::now();
    let outcome = measure_round(&once, case, &spec, config.mpi.as_ref(), context)?;
    let round_s = started.elapsed().as_secs_f64();
    let round = outcome.external.unwrap_or_default();
    let failed = |e: &nbody_records::external::SampleError, who: &str| TrialError::Failed {
        name: ext.name.clone(),
        key: case.key(),
        what: format!(
            "{who}`{}` {}{}",
            e.command,
            e.what,
            e.output_tail
                .last()
                .map(|l| format!("; last line: {l}"))
                .unwrap_or_default()
        ),
    };
    if let Some(e) = &round.setup_error {
        return Err(failed(e, "its set-up "));
    }
    let Some(run) = round.runs.first() else {
        return Err(TrialError::Failed {
            name: ext.name.clone(),
            key: case.key(),
            what: "no run was made".into(),
        });
    };
    if let Some(e) = &run.error {
        return Err(failed(e, ""));
    }
    Ok(Trial {
        case: case.clone(),
        run_s: run.wall_s,
        round_overhead_s: (round_s - run.wall_s).max(0.0),
    })
}

/// Wall time of the remaining rounds of `case`, an external program's, from its trial: each
/// round its set-up (and empty runs), warm-up runs and samples, each run as long as the trial's carried to the
/// case's steps and n (a step's cost by the entry's `grows` when its steps scale, else as n²,
/// the direct sum: an unknown program is not assumed to be cheap), no faster on more workers.
pub fn case_s(
    config: &SweepConfig,
    ext: &External,
    trial: &Trial,
    case: &Case,
    first: usize,
) -> f64 {
    let run_s = run_s(ext, trial, case);
    let m = &config.measure;
    (first.min(m.rounds)..m.rounds)
        .map(|round| {
            let runs = samples_in_round(m.samples, m.rounds, round) + ext.warmup_runs;
            trial.round_overhead_s + runs as f64 * run_s
        })
        .sum()
}

/// One run of `case` from the trial's: its time carried by the steps and by a step's cost at
/// each n (see [`case_s`]).
pub fn run_s(ext: &External, trial: &Trial, case: &Case) -> f64 {
    let cost = |n: usize| match ext.steps {
        Steps::Scaled(r) => r.grows.cost(n),
        Steps::Fixed(_) => (n.max(1) as f64).powi(2),
    };
    let work = |c: &Case| steps(ext, c) as f64 * cost(c.n);
    trial.run_s * work(case) / work(&trial.case).max(f64::MIN_POSITIVE)
}
