//! Runs a sweep: plans the cases, measures them in interleaved rounds, saves the results
//! file after every round of every case, and resumes an interrupted sweep.

use super::case_round::{case_setup, measure_case};
use super::lock::WriterLock;
use super::measure::{RoundSpec, samples_in_round};
use super::slowdown::{SLOWDOWN_ENV, TestSlowdown};
use super::slurm;
use nbody_engine::clock::Clock;
use nbody_engine::scenario::initial::InitialBodies;
use nbody_records::config::SweepConfig;
use nbody_records::plan::{Case, cases};
use nbody_records::results::{
    CaseRecord, InitialRecord, Metadata, RESULTS_SCHEMA, ResultsError, ResultsFile,
};
use std::path::{Path, PathBuf};
use std::sync::Arc;
use thiserror::Error;

/// How a sweep starts.
#[derive(Clone, Debug, Default)]
pub struct SweepOptions {
    /// Continue an existing results file instead of refusing to touch it.
    pub resume: bool,
    /// Resume even if the config or the commit differ from the file's.
    pub force: bool,
    /// Start over: an existing results file is kept under a `.bak` name.
    pub fresh: bool,
    /// Output directory instead of the config's `out`: results go to `<out>/<name>/`.
    pub out: Option<PathBuf>,
    /// The directory of the results file itself (a user's run directory); wins over `out`.
    pub run_dir: Option<PathBuf>,
    /// Calibrate the machine at the start and end (tests turn it off).
    pub calibrate: bool,
    /// `{config_dir}` of external commands [default: the current directory].
    pub config_dir: Option<PathBuf>,
    /// `{nbody_bench}` of external commands [default: this program].
    pub nbody_bench: Option<PathBuf>,
}

/// Follows a sweep's progress (terminal bar, log lines, or nothing).
pub trait Observer {
    /// Called once before measuring: rounds of every case in all, and how many of them a
    /// resumed file already holds.
    fn start(&mut self, _total_rounds: usize, _done_rounds: usize) {}
    /// Called after each round is measured and saved: the case's record with it, and the
    /// round's 0-based index.
    fn round_done(&mut self, _record: &CaseRecord, _round: usize) {}
    /// A line for the user: a warning, a calibration summary, why the sweep stopped.
    fn message(&mut self, _text: &str) {}
    /// Called once when the sweep returns without an error, after the end calibration.
    fn finish(&mut self) {}
    /// Asked before each round: `false` stops the sweep there, as an interrupt would (what
    /// was measured is saved; `--resume` continues). The tests of resuming stop this way.
    fn keep_going(&mut self) -> bool {
        true
    }
}

/// Observes nothing.
pub struct Silent;
impl Observer for Silent {}

/// Why a sweep did not start or stopped with an error (what was measured before is saved).
#[derive(Debug, Error)]
pub enum SweepError {
    /// The results file (given) exists and neither `--resume` nor `--fresh` was passed.
    #[error(
        "{0} already exists; pass --resume to continue that sweep, or --fresh to start over \
         (the existing file is kept as a .bak copy)"
    )]
    Exists(PathBuf),
    /// Resuming without `--force` a file made with another config, commit or file of bodies.
    #[error(
        "{path} was produced by a different {what} ({detail}); refusing to mix results — \
         pass --force to resume anyway or --fresh to start over"
    )]
    Mismatch {
        /// The results file.
        path: PathBuf,
        /// What differs: "config", "commit" or "file of bodies".
        what: &'static str,
        /// How it differs, e.g. the file's commit and the current one.
        detail: String,
    },
    /// The dry run's trial of an external program failed.
    #[error(transparent)]
    Trial(#[from] super::external::trial::TrialError),
    /// Loading or saving the results file failed.
    #[error(transparent)]
    Results(#[from] ResultsError),
    /// A case failed its checks before the sweep (invalid set-up, too little memory) or failed
    /// while being measured.
    #[error("case {key}")]
    Case {
        /// The case's key.
        key: String,
        /// What went wrong.
        #[source]
        source: Box<dyn std::error::Error + Send + Sync>,
    },
    /// `NBODY_BENCH_TEST_SLOWDOWN` (test builds only) is set but is not `KERNEL:K`; the
    /// message says what is wrong.
    #[error("{0}")]
    Slowdown(String),
    /// The config runs kernels under an MPI launcher but this build lacks the `mpi` feature.
    #[error(
        "config `{config}` runs cases under MPI: {}",
        nbody_engine::decomp::WITHOUT_MPI
    )]
    WithoutMpi {
        /// The config's name.
        config: String,
    },
    /// An external program could not be found or checked before the sweep.
    #[error(transparent)]
    External(#[from] super::external::ExternalError),
    /// The path of this executable, for external commands' `{nbody_bench}`, is unknown.
    #[error("cannot find this program for {{nbody_bench}}: {0}")]
    Exe(std::io::Error),
    /// The config's cases could not be planned (e.g. two cases with the same key); the message
    /// says why.
    #[error("{0}")]
    Plan(String),
    /// The config's file of bodies (`initial`) could not be read or parsed.
    #[error("config key `initial`: {source}")]
    Initial {
        /// Why.
        source: nbody_engine::scenario::initial::InitialError,
    },
    /// The sweep's own copy of the file of bodies, beside the results, could not be written.
    #[error("cannot keep the sweep's copy of the file of bodies: {source}")]
    InitialCopy {
        /// Why.
        source: nbody_engine::output::WriteError,
    },
    /// Another process is writing the same results file, or its lock could not be taken.
    #[error(transparent)]
    Lock(#[from] super::lock::LockError),
    /// The `[scheduler]` (Slurm) is unavailable or one of its jobs failed.
    #[error(transparent)]
    Slurm(#[from] super::slurm::SlurmError),
    /// `--fresh` could not rename the existing results file (or its `jobs` directory) to a
    /// `.bak` name.
    #[error("cannot keep {path} as a backup: {source}")]
    Backup {
        /// The file or directory being kept.
        path: PathBuf,
        /// The system's error.
        source: std::io::Error,
    },
    /// The results directory (or its `initial/` subdirectory) could not be created.
    #[error("cannot create {path}: {source}")]
    Dir {
        /// The directory.
        path: PathBuf,
        /// The system's error.
        source: std::io::Error,
    },
}

/// What a sweep did.
#[derive(Debug)]
pub struct SweepReport {
    /// The results file written.
    pub path: PathBuf,
    /// Rounds measured by this invocation (not those a resumed file already held).
    pub rounds_measured: usize,
    /// Cases in the results file.
    pub cases: usize,
    /// Cases not complete (budget reached or stopped).
    pub incomplete: usize,
}

/// The results path of a config: `<out>/<name>/results.json`.
pub fn results_path(config: &SweepConfig, out: Option<&Path>) -> PathBuf {
    out.unwrap_or(&config.out)
        .join(&config.name)
        .join("results.json")
}

/// [`run_sweep`] timed by the wall clock, as `nbody-bench sweep` and `gate` run it. Not generic
/// on purpose: the measurement of every system type is instantiated here, once, and not again
/// in each crate that runs a sweep.
pub fn run_sweep_wall(
    config: &SweepConfig,
    config_text: &str,
    options: &SweepOptions,
    observer: &mut dyn Observer,
) -> Result<SweepReport, SweepError> {
    run_sweep(
        config,
        config_text,
        options,
        &nbody_engine::clock::WallClock::new(),
        observer,
    )
}

/// Runs the sweep of `config` (whose TOML text `config_text` is kept in the results) with
/// `clock` timing every sample: plans, calibrates, measures the rounds still to do, saving after
/// each, and reports to `observer`.
pub fn run_sweep<C: Clock>(
    config: &SweepConfig,
    config_text: &str,
    options: &SweepOptions,
    clock: &C,
    observer: &mut dyn Observer,
) -> Result<SweepReport, SweepError> {
    if config.mpi.is_some() && !config.kernels.is_empty() && !cfg!(feature = "mpi") {
        // The launcher starts this program, which must have the MPI drivers.
        return Err(SweepError::WithoutMpi {
            config: config.name.clone(),
        });
    }
    let path = match &options.run_dir {
        Some(dir) => dir.join("results.json"),
        None => results_path(config, options.out.as_deref()),
    };
    let (initial, mut context) = preflight(config, options, &path)?;
    if config.scheduler.is_some() {
        slurm::check_available()?;
    }
    let slowdown = TestSlowdown::from_env().map_err(SweepError::Slowdown)?;
    if let Some(dir) = path.parent() {
        nbody_engine::output::create_dir_all(dir).map_err(|source| SweepError::Dir {
            path: dir.into(),
            source,
        })?;
    }
    // Held until the sweep returns: nobody else reads, backs up or saves this file meanwhile.
    let _writer = WriterLock::acquire(&path)?;
    let mut results = open(config, config_text, options, &path)?;
    if let Some(initial) = initial {
        context.initial = Some(adopt_initial(&mut results, initial, &path, options.force)?);
    }
    if let Some(s) = slowdown {
        observer.message(&format!(
            "warning: {SLOWDOWN_ENV}={s} is set: {} runs {} times per step (test-only)",
            s.kernel.name(),
            s.factor
        ));
    }
    add_cases(config, &mut results, observer);
    let thread_counts = thread_counts(&results);
    let sweep = Sweep {
        config,
        options,
        clock,
        path: &path,
        context: &context,
        slowdown,
    };
    sweep.prepare(&mut results, &thread_counts, observer)?;
    let (measured, stopped) = sweep.measure_rounds(&mut results, observer)?;
    if options.calibrate && !stopped {
        results.calibration.end = sweep.calibrate("end", &thread_counts, observer)?;
        results.save(&path)?;
    }
    observer.finish();
    Ok(SweepReport {
        path,
        rounds_measured: measured,
        cases: results.cases.len(),
        incomplete: results.cases.iter().filter(|c| !c.is_complete()).count(),
    })
}

/// Takes the config's file of bodies into the results and keeps the sweep's own copy of it;
/// the copy's path. A resumed sweep goes on from the same bodies, or not at all (unless
/// `force`).
fn adopt_initial(
    results: &mut ResultsFile,
    initial: Initial,
    path: &Path,
    force: bool,
) -> Result<PathBuf, SweepError> {
    if let Some(before) = results.metadata.initial.as_ref()
        && before.fnv1a != initial.record.fnv1a
        && !force
    {
        return Err(SweepError::Mismatch {
            path: path.into(),
            what: "file of bodies",
            detail: format!(
                "{} had fingerprint {}, now {}",
                initial.record.path, before.fnv1a, initial.record.fnv1a
            ),
        });
    }
    let copy = keep_initial(path, &initial)?;
    results.metadata.initial = Some(initial.record);
    Ok(copy)
}

/// Adds the planned cases the results do not hold yet (a resumed file has the others), and
/// warns about the cases that use more threads than the machine has logical CPUs.
fn add_cases(config: &SweepConfig, results: &mut ResultsFile, observer: &mut dyn Observer) {
    let logical = nbody_engine::run::logical_cpus();
    let rounds = config.measure.rounds;
    for case in cases(config) {
        if results.record_mut(&case.key()).is_none() {
            results.cases.push(CaseRecord::new(case, rounds, logical));
        }
    }
    let oversubscribed: Vec<&str> = results
        .cases
        .iter()
        .filter(|c| c.oversubscribed)
        .map(|c| c.key.as_str())
        .collect();
    if !oversubscribed.is_empty() {
        observer.message(&format!(
            "warning: {} case(s) use more threads than the {logical} logical CPUs; they are marked oversubscribed",
            oversubscribed.len()
        ));
    }
}

/// The cases' thread counts, each once and in increasing order: what the calibrations measure.
fn thread_counts(results: &ResultsFile) -> Vec<usize> {
    let mut t: Vec<usize> = results.cases.iter().map(|c| c.case.threads).collect();
    t.sort_unstable();
    t.dedup();
    t
}

/// A sweep whose results file is open and locked: what its calibrations and rounds read.
struct Sweep<'a, C: Clock> {
    config: &'a SweepConfig,
    options: &'a SweepOptions,
    clock: &'a C,
    /// The results file.
    path: &'a Path,
    context: &'a super::external::Context,
    slowdown: Option<TestSlowdown>,
}

impl<C: Clock> Sweep<'_, C> {
    /// [`calibrate`] for this sweep, at its start or end (`when`).
    fn calibrate(
        &self,
        when: &str,
        threads: &[usize],
        observer: &mut dyn Observer,
    ) -> Result<Option<nbody_calibrate::Calibration>, SweepError> {
        calibrate(
            self.config,
            self.context,
            self.path,
            when,
            threads,
            self.options.resume,
            observer,
        )
    }

    /// Readies the results for the first round: the calibration at the start (unless the file
    /// has one) and the external programs' versions, saved before anything is measured.
    fn prepare(
        &self,
        results: &mut ResultsFile,
        thread_counts: &[usize],
        observer: &mut dyn Observer,
    ) -> Result<(), SweepError> {
        if self.options.calibrate && results.calibration.start.is_none() {
            observer.message("calibrating the machine...");
            let cal = self.calibrate("start", thread_counts, observer)?;
            if let Some(cal) = &cal {
                observer.message(&cal.summary());
            }
            results.calibration.start = cal;
        }
        if results.metadata.externals.is_empty() && !self.config.external.is_empty() {
            results.metadata.externals = self
                .config
                .external
                .iter()
                .map(|e| super::external::version_line(e, self.context))
                .collect();
        }
        results.save(self.path)?;
        Ok(())
    }

    /// Measures the rounds not measured yet, case after case in interleaved rounds, saving the
    /// results after each; the rounds measured, and whether the sweep stopped before the end
    /// (its time budget reached, or the observer stopped it).
    fn measure_rounds(
        &self,
        results: &mut ResultsFile,
        observer: &mut dyn Observer,
    ) -> Result<(usize, bool), SweepError> {
        let rounds = self.config.measure.rounds;
        let total: usize = results.cases.len() * rounds;
        let done: usize = results
            .cases
            .iter()
            .map(|c| c.rounds_done.min(rounds))
            .sum();
        observer.start(total, done);
        let started = self.clock.now();
        let mut measured = 0;
        let mut watch = super::repeated_failure::FailureWatch::default();
        for round in 0..rounds {
            // Alternate the direction of each round so no case always runs first or last.
            let mut order: Vec<usize> = (0..results.cases.len()).collect();
            if round % 2 == 1 {
                order.reverse();
            }
            for i in order {
                if results.cases[i].rounds_done > round {
                    continue;
                }
                let budget = self.config.measure.budget_s;
                if budget > 0.0 && (self.clock.now() - started).as_secs_f64() >= budget {
                    observer.message(
                        "time budget reached; run again with --resume to measure the remaining cases",
                    );
                    return Ok((measured, true));
                }
                if !observer.keep_going() {
                    return Ok((measured, true));
                }
                let record = &results.cases[i];
                let program = (record.case.kernel.is_external())
                    .then(|| record.case.kernel.name().to_string());
                if program.as_deref().is_some_and(|p| watch.stopped(p)) {
                    continue;
                }
                let outcome = self.measure_round(record, round, observer)?;
                report_external(&record.key, &outcome, observer);
                let stopped = program.and_then(|p| Some((watch.note(&p, &outcome)?, p)));
                let record = &mut results.cases[i];
                record.add_round(outcome, self.config.measure.max_energy_drift);
                results.save(self.path)?;
                measured += 1;
                observer.round_done(&results.cases[i], round);
                if let Some((why, program)) = stopped {
                    say_stopped(&program, &why, results, rounds, observer);
                }
            }
        }
        Ok((measured, false))
    }

    /// Measures one round of a case: in this process, or as a batch job with a `[scheduler]`.
    fn measure_round(
        &self,
        record: &CaseRecord,
        round: usize,
        observer: &mut dyn Observer,
    ) -> Result<nbody_records::round::RoundOutcome, SweepError> {
        let spec = self.round_spec(record, round);
        match &self.config.scheduler {
            Some(scheduler) => {
                let job = JobRound {
                    scheduler,
                    results: self.path,
                    config: self.config,
                    context: self.context,
                    resume: self.options.resume,
                };
                job.measure(&record.case, round, &spec, observer)
            }
            None => measure_case(&record.case, &spec, self.clock, self.config, self.context)
                .map_err(|source| SweepError::Case {
                    key: record.key.clone(),
                    source,
                }),
        }
    }

    /// How a round of the case is measured: its share of the samples, and the steps per
    /// sample the case's earlier rounds chose.
    fn round_spec(&self, record: &CaseRecord, round: usize) -> RoundSpec {
        let measure = &self.config.measure;
        RoundSpec {
            samples: samples_in_round(measure.samples, measure.rounds, round),
            warmup_s: measure.warmup_s,
            min_sample_s: measure.min_sample_s,
            // A round no job measured chose nothing.
            steps_per_sample: (record.rounds_done > 0 && record.steps_per_sample > 0)
                .then_some(record.steps_per_sample),
            force_error_sample: measure.force_error_sample,
            reference_s: measure.reference_s,
            slowdown: self.slowdown,
        }
    }
}

/// One round of a case as a batch job: where its job directory goes and what it needs.
struct JobRound<'a> {
    scheduler: &'a nbody_records::scheduler::Scheduler,
    results: &'a Path,
    config: &'a SweepConfig,
    context: &'a super::external::Context,
    /// `--resume`: a job an earlier sweep submitted for the round is waited for, not submitted
    /// again. Without it nothing found in the job's directory is used.
    resume: bool,
}

impl JobRound<'_> {
    /// Submits (or picks up) the round's job, waits for it and reads its round; a job that
    /// ended without one gives a round without samples that keeps the job's output.
    fn measure(
        &self,
        case: &Case,
        round: usize,
        spec: &RoundSpec,
        observer: &mut dyn Observer,
    ) -> Result<nbody_records::round::RoundOutcome, SweepError> {
        let key = case.key();
        let what = format!("{key} round {}", round + 1);
        let dir = slurm::job_dir(self.results, &format!("round-{}-{key}", round + 1));
        let work = slurm::Work::Round {
            case: case.clone(),
            spec: spec.clone(),
        };
        let task = slurm::Task::new(self.config, self.context, work);
        let resources = slurm::Resources {
            tasks: case.ranks,
            cpus_per_task: case.threads,
        };
        let mut say = |m: &str| observer.message(m);
        let ended = slurm::run(
            self.scheduler,
            &dir,
            &task,
            resources,
            &what,
            self.resume,
            &mut say,
        )?;
        let measured = ended.result.and_then(|r| Some((r.round?, r.step_ns)));
        Ok(match measured {
            Some((mut outcome, step_ns)) => {
                outcome.step_ns = step_ns;
                outcome.job = Some(ended.record);
                outcome
            }
            None => {
                if let Some(e) = &ended.record.error {
                    let last = e.output_tail.last().map(|l| format!("; last line: {l}"));
                    observer.message(&format!(
                        "error: {what}: {}{}",
                        e.what,
                        last.unwrap_or_default()
                    ));
                }
                slurm::unmeasured_round(case, spec, ended.record)
            }
        })
    }
}

/// Calibrates the machine, or with a `[scheduler]` the node of a job (`None` if that job
/// ended without a result: the sweep goes on without this calibration).
fn calibrate(
    config: &SweepConfig,
    context: &super::external::Context,
    results: &Path,
    when: &str,
    threads: &[usize],
    resume: bool,
    observer: &mut dyn Observer,
) -> Result<Option<nbody_calibrate::Calibration>, SweepError> {
    let Some(scheduler) = &config.scheduler else {
        return Ok(Some(nbody_calibrate::calibrate(threads)));
    };
    let dir = slurm::job_dir(results, &format!("calibrate-{when}"));
    let work = slurm::Work::Calibrate {
        threads: threads.to_vec(),
    };
    let task = slurm::Task::new(config, context, work);
    let resources = slurm::Resources {
        tasks: 1,
        cpus_per_task: threads.iter().copied().max().unwrap_or(1),
    };
    let what = format!("calibration ({when})");
    let mut say = |m: &str| observer.message(m);
    let ended = slurm::run(scheduler, &dir, &task, resources, &what, resume, &mut say)?;
    let calibration = ended.result.and_then(|r| r.calibration);
    if calibration.is_none() {
        let why = ended.record.error.map(|e| e.what);
        observer.message(&format!(
            "warning: {what}: {}; the sweep goes on without it",
            why.as_deref().unwrap_or("the job ended without a result")
        ));
    }
    Ok(calibration)
}

/// Checks everything that can be known before the first case, as `sweep --dry-run` does too:
/// every case's system can be built (a box its precision cannot resolve, too many particles,
/// an n the `initial` file does not have) and every external program can be started. Otherwise
/// a case would fail only when its turn comes, after the cases before it ran, and again at
/// every --resume. Writes nothing.
pub fn check_before_running(
    config: &SweepConfig,
    options: &SweepOptions,
) -> Result<(), SweepError> {
    let path = match &options.run_dir {
        Some(dir) => dir.join("results.json"),
        None => results_path(config, options.out.as_deref()),
    };
    preflight(config, options, &path).map(|_| ())
}

/// [`check_before_running`], then every external program tried once at its smallest case
/// (in a temporary work directory): the dry run's checks. The trials, for the estimate.
pub fn try_before_running(
    config: &SweepConfig,
    options: &SweepOptions,
) -> Result<Vec<super::external::trial::Trial>, SweepError> {
    let path = match &options.run_dir {
        Some(dir) => dir.join("results.json"),
        None => results_path(config, options.out.as_deref()),
    };
    let (_, context) = preflight(config, options, &path)?;
    let planned = nbody_records::plan::unique_cases(config).map_err(SweepError::Plan)?;
    Ok(super::external::trial::try_all(config, &planned, &context)?)
}

/// [`check_before_running`], keeping the bodies it read and the externals' context.
fn preflight(
    config: &SweepConfig,
    options: &SweepOptions,
    path: &Path,
) -> Result<(Option<Initial>, super::external::Context), SweepError> {
    let planned = nbody_records::plan::unique_cases(config).map_err(SweepError::Plan)?;
    let initial = initial_bodies(config, options)?;
    for case in planned {
        let setup = case_setup(&case, initial.as_ref().map(|i| i.bodies.clone()));
        let copies = match case.decomp {
            // Every rank holds all the particles.
            Some(nbody_engine::decomp::Decomposition::Allgather) => case.ranks,
            _ => 1,
        };
        let checked = setup
            .validate()
            .map_err(|e| Box::new(e) as Box<dyn std::error::Error + Send + Sync>)
            .and_then(|()| match case.kernel.kernel() {
                Some(kernel) => {
                    let params = case.kernel_params();
                    nbody_engine::run::check_memory(&setup, kernel, &params, case.threads, copies)
                }
                .map_err(|e| Box::new(e) as _),
                None => Ok(()),
            });
        checked.map_err(|source| SweepError::Case {
            key: case.key(),
            source,
        })?;
    }
    let mut context = external_context(options, path)?;
    // `context.initial`, the file launched runs read, is the sweep's own copy (made when the
    // sweep starts measuring).
    context.bodies = initial.as_ref().map(|i| i.bodies.clone());
    for ext in &config.external {
        let launcher = config.mpi.as_ref().map(|m| m.launcher.as_str());
        super::external::check_programs(ext, launcher, &context)?;
    }
    Ok((initial, context))
}

/// The config's file of bodies (`initial`), as read once before anything runs.
struct Initial {
    /// For the results metadata (the path made absolute).
    record: InitialRecord,
    bodies: Arc<InitialBodies>,
    /// The text its fingerprint is of.
    text: String,
}

/// Reads the config's file of bodies (`initial`), if it has one.
fn initial_bodies(
    config: &SweepConfig,
    options: &SweepOptions,
) -> Result<Option<Initial>, SweepError> {
    let Some(file) = &config.initial else {
        return Ok(None);
    };
    let dir = options.config_dir.as_deref().unwrap_or(Path::new("."));
    let path = dir.join(file);
    let path = std::path::absolute(&path).unwrap_or(path);
    let text = nbody_engine::input::read_text(&path).map_err(|source| SweepError::Initial {
        source: nbody_engine::scenario::initial::InitialError::Read {
            path: path.clone(),
            source,
        },
    })?;
    let bodies = nbody_engine::scenario::initial::parse(&path, &text)
        .map_err(|source| SweepError::Initial { source })?;
    let record = InitialRecord {
        path: path.display().to_string(),
        format: bodies.format.name().to_string(),
        bodies: bodies.len(),
        fnv1a: format!("{:016x}", nbody_records::results::fnv1a(text.as_bytes())),
    };
    Ok(Some(Initial {
        record,
        bodies: Arc::new(bodies),
        text,
    }))
}

/// Writes the sweep's own copy of its file of bodies, `initial/<file name>` beside the results,
/// from the text read at the start; its absolute path. Runs launched later (each round under
/// an MPI launcher is a new process that reads the file) read this copy: the user's file may
/// be edited or replaced while the sweep runs, and every round must start from the bodies the
/// results' fingerprint names.
fn keep_initial(results: &Path, initial: &Initial) -> Result<PathBuf, SweepError> {
    let dir = results.parent().unwrap_or(Path::new(".")).join("initial");
    nbody_engine::output::create_dir_all(&dir).map_err(|source| SweepError::Dir {
        path: dir.clone(),
        source,
    })?;
    let name = Path::new(&initial.record.path)
        .file_name()
        .map_or_else(|| "bodies.txt".into(), |n| n.to_os_string());
    let copy = dir.join(name);
    let copy = std::path::absolute(&copy).unwrap_or(copy);
    nbody_engine::output::write_atomic(&copy, initial.text.as_bytes())
        .map_err(|source| SweepError::InitialCopy { source })?;
    Ok(copy)
}

/// Where external programs find the sweep; their work directories go next to the results.
fn external_context(
    options: &SweepOptions,
    path: &Path,
) -> Result<super::external::Context, SweepError> {
    let nbody_bench = match &options.nbody_bench {
        Some(p) => p.clone(),
        None => std::env::current_exe().map_err(SweepError::Exe)?,
    };
    let config_dir = options
        .config_dir
        .clone()
        .unwrap_or_else(|| PathBuf::from("."));
    // Absolute, so that a program started in its work directory finds them.
    let absolute = |p: PathBuf| std::path::absolute(&p).unwrap_or(p);
    Ok(super::external::Context {
        config_dir: absolute(config_dir),
        nbody_bench: absolute(nbody_bench),
        work_root: absolute(path.parent().unwrap_or(Path::new(".")).join("work")),
        initial: None,
        bodies: None,
    })
}

/// Says that `program` is no longer run, why, and what is left for `--resume`.
fn say_stopped(
    program: &str,
    why: &str,
    results: &ResultsFile,
    rounds: usize,
    observer: &mut dyn Observer,
) {
    let left: usize = results
        .cases
        .iter()
        .filter(|c| c.case.kernel.is_external() && c.case.kernel.name() == program)
        .map(|c| rounds.saturating_sub(c.rounds_done))
        .sum();
    if left == 0 {
        // Its last round: nothing is left out, and its failures are reported case by case.
        return;
    }
    observer.message(&format!(
        "error: external `{program}` failed the same way in its first {} rounds ({why}); its \
         other {left} round(s) are not run: fix the program, then resume the run to measure them",
        super::repeated_failure::SAME_FAILURES
    ));
}

/// Tells the observer about an external round's failed samples and warnings.
fn report_external(
    key: &str,
    outcome: &nbody_records::round::RoundOutcome,
    observer: &mut dyn Observer,
) {
    let Some(ext) = &outcome.external else {
        return;
    };
    for w in &ext.warnings {
        observer.message(&format!("warning: {w}"));
    }
    let errors = ext.setup_error.iter().map(|e| ("set-up", e)).chain(
        ext.runs
            .iter()
            .filter_map(|r| Some(("sample", r.error.as_ref()?))),
    );
    for (what, e) in errors {
        observer.message(&format!(
            "error: {key}: {what} `{}` {}{}",
            e.command,
            e.what,
            e.output_tail
                .last()
                .map(|l| format!("; last line: {l}"))
                .unwrap_or_default()
        ));
    }
}

/// Opens the results file for this sweep: a new one, or an existing one to resume.
fn open(
    config: &SweepConfig,
    config_text: &str,
    options: &SweepOptions,
    path: &Path,
) -> Result<ResultsFile, SweepError> {
    let fresh = || ResultsFile {
        schema: RESULTS_SCHEMA.to_string(),
        metadata: Metadata::collect(&crate::experiment::cargo_features()),
        config: config.clone(),
        config_text: config_text.to_string(),
        calibration: Default::default(),
        cases: Vec::new(),
    };
    if !path.exists() {
        return Ok(fresh());
    }
    if options.fresh {
        let stamp = nbody_engine::output::provenance::utc_now().replace(':', "");
        super::lock::back_up(path, &stamp).map_err(|source| SweepError::Backup {
            path: path.into(),
            source,
        })?;
        // The jobs of the old results (a batch system's) go with them.
        let jobs = path.with_file_name("jobs");
        if jobs.exists() {
            let kept = path.with_file_name(format!("jobs.{stamp}.bak"));
            std::fs::rename(&jobs, &kept).map_err(|source| SweepError::Backup {
                path: jobs.clone(),
                source,
            })?;
        }
        return Ok(fresh());
    }
    if !options.resume {
        return Err(SweepError::Exists(path.into()));
    }
    let existing = ResultsFile::load(path)?;
    if !options.force {
        if existing.config != *config {
            return Err(SweepError::Mismatch {
                path: path.into(),
                what: "config",
                detail: "the config in the file differs from the one given".into(),
            });
        }
        let (commit, _) = nbody_engine::output::provenance::git_state();
        if existing.metadata.git_commit != commit {
            return Err(SweepError::Mismatch {
                path: path.into(),
                what: "commit",
                detail: format!("file: {}, now: {commit}", existing.metadata.git_commit),
            });
        }
    }
    Ok(existing)
}
