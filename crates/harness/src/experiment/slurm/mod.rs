//! Case rounds and calibrations as Slurm jobs (a config's `[scheduler] kind = "slurm"`).
//!
//! Each piece of work gets a directory under the results, `jobs/<name>/`: the sweep writes
//! what to do (`task.json`, with a random token) and a job script (`job.sh`, which runs
//! `nbody-bench job DIR`), submits it with `sbatch --parsable`, keeps the job id (`job-id`),
//! and polls `squeue` until the job has left the queue (`queue`). The job measures on its
//! compute node and writes `result.json` (atomically, carrying the task's token) next to its
//! output (`job.out`) (`job`). A result is taken only if it answers its task (`check`): the
//! token, the case, the particles, samples and steps asked, counts that can be; anything else,
//! and a job that ends without a result (it failed, hit its time limit, was cancelled), gives
//! a round without samples that keeps the job's state, the reason and its last lines of output.
//! The sweep waits for one job at a time, so the rounds interleave as they do on one machine;
//! an interrupted sweep leaves its job queued, and `--resume` (only) waits for that job, or
//! reads its result, instead of submitting it again.

mod check;
mod job;
mod queue;

pub use job::job_main;
pub use queue::GRACE_ENV;

use super::external::Context;
use super::measure::RoundSpec;
use crate::children::supervised;
use nbody_calibrate::Calibration;
use nbody_records::config::SweepConfig;
use nbody_records::plan::Case;
use nbody_records::round::RoundOutcome;
use nbody_records::scheduler::{JobError, JobRecord, Scheduler};
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Duration;
use thiserror::Error;

/// How long one call of `sbatch`, `squeue` or `scontrol` may take.
const CALL_LIMIT: Duration = Duration::from_secs(120);
/// Failed looks at the queue in a row before the sweep gives up on it (it can be resumed).
const QUEUE_FAILURES: usize = 5;

/// Why work could not be run as a Slurm job, or waited for.
#[derive(Debug, Error)]
pub enum SlurmError {
    /// A job directory could not be created, or a stale file in it removed.
    #[error("cannot prepare the job directory {path}: {source}")]
    Dir {
        /// The directory or the stale file.
        path: PathBuf,
        /// The system's error.
        source: std::io::Error,
    },
    /// A file of the job (`task.json`, `job.sh`, `job-id`) could not be serialized or written.
    #[error("cannot write {path}: {detail}")]
    Write {
        /// The file.
        path: PathBuf,
        /// The error's message.
        detail: String,
    },
    /// `sbatch`, `squeue` or `scontrol` could not be run or failed (Slurm missing or its
    /// controller unreachable); the message says which call and how.
    #[error("{0}; is Slurm installed and its controller reachable (`sinfo`)?")]
    Call(String),
    /// `sbatch` failed or printed no job id.
    #[error("`sbatch` refused the job of {what}: {message}")]
    Refused {
        /// The work, e.g. `KEY round 2` or `calibration (start)`.
        what: String,
        /// The last line of `sbatch`'s error output (else its output).
        message: String,
    },
    /// `squeue` failed several times in a row while waiting for a job; the job is left as it
    /// is, for `--resume`.
    #[error(
        "the queue could not be read {QUEUE_FAILURES} times in a row while waiting for job \
         {id} ({last}); the job is left as it is: run the sweep again with --resume to pick it up"
    )]
    Queue {
        /// The Slurm job id.
        id: String,
        /// The last line of the last failed `squeue`'s error output.
        last: String,
    },
    /// A job has run (or shown no state) for longer than its time limit plus the grace
    /// margin; it is left in the queue for `--resume`.
    #[error(
        "job {id} ({what}) {seen} for {waited} s, longer than its time limit ({limit}) plus a \
         margin of {grace_s} s ({} sets it); the job is left as it is: check it with \
         `squeue -j {id}`, then run the sweep again with --resume to wait for it again",
        queue::GRACE_ENV
    )]
    Overdue {
        /// The Slurm job id.
        id: String,
        /// The work, e.g. `KEY round 2` or `calibration (start)`.
        what: String,
        /// What was seen of the job: that it ran, or no state at all.
        seen: String,
        /// Seconds waited since the job was seen running (or last seen queued).
        waited: u64,
        /// The `[scheduler]`'s `time_limit`, as the config writes it (e.g. `10:00`).
        limit: String,
        /// The margin past the time limit, seconds.
        grace_s: u64,
    },
    /// [`GRACE_ENV`], the margin past a job's time limit, is set but is not a number of
    /// seconds in (0, 604800].
    #[error("{0}")]
    Grace(String),
}

/// What a job does: one round of one case, or a calibration of the node.
#[derive(Serialize, Deserialize)]
pub(crate) struct Task {
    /// Random, new for every submission: the job copies it into its result, so that a result
    /// is known to be this submission's (not one left in the directory by an earlier sweep or
    /// an earlier job of the same round).
    pub token: String,
    pub config: SweepConfig,
    pub context: Context,
    pub work: Work,
}

#[derive(Serialize, Deserialize)]
pub(crate) enum Work {
    Round { case: Case, spec: RoundSpec },
    Calibrate { threads: Vec<usize> },
}

/// What a job leaves behind.
#[derive(Serialize, Deserialize)]
pub(crate) struct JobResult {
    /// The token of the task the job did.
    #[serde(default)]
    pub token: String,
    /// The key of the case whose round it measured.
    #[serde(default)]
    pub key: Option<String>,
    pub node: Option<String>,
    #[serde(default)]
    pub round: Option<RoundOutcome>,
    /// The round's timed steps (not kept in a round itself, only in the case's histogram).
    #[serde(default)]
    pub step_ns: Vec<u64>,
    #[serde(default)]
    pub calibration: Option<Calibration>,
}

/// The CPUs a job asks for.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Resources {
    pub tasks: usize,
    pub cpus_per_task: usize,
}

/// A job that ended: its record, and its result if it wrote one that answers its task.
pub(crate) struct Ended {
    pub record: JobRecord,
    pub result: Option<JobResult>,
}

impl Task {
    /// A task with a new random token.
    pub(crate) fn new(config: &SweepConfig, context: &Context, work: Work) -> Task {
        Task {
            token: format!("{:032x}", rand::random::<u128>()),
            config: config.clone(),
            context: context.clone(),
            work,
        }
    }

    /// Whether `other` asks for the same work (its token aside).
    fn same_work(&self, other: &Task) -> bool {
        let value =
            |t: &Task| serde_json::to_value((&t.config, &t.context, &t.work)).unwrap_or_default();
        value(self) == value(other)
    }
}

/// Whether `sbatch` can be started here, before anything is submitted.
pub(crate) fn check_available() -> Result<(), SlurmError> {
    queue::check_grace()?;
    let mut sbatch = Command::new("sbatch");
    sbatch.arg("--version");
    match supervised::output(&mut sbatch, CALL_LIMIT, "`sbatch --version`", "") {
        Ok(out) if out.status.success() => Ok(()),
        Ok(out) => Err(SlurmError::Call(format!(
            "`sbatch --version` failed: {}",
            last_line(&out.stderr).unwrap_or_default()
        ))),
        Err(e) => Err(SlurmError::Call(e.to_string())),
    }
}

/// Runs `task` as a job in `dir`, waits until it has left the queue and reads what it left.
/// With `resume`, a job an earlier sweep submitted for the same work is waited for instead of
/// submitting it again; without, nothing found in `dir` is used. `say` tells the user what is
/// waited for.
pub(crate) fn run(
    scheduler: &Scheduler,
    dir: &Path,
    task: &Task,
    resources: Resources,
    what: &str,
    resume: bool,
    say: &mut dyn FnMut(&str),
) -> Result<Ended, SlurmError> {
    let adopted = if resume {
        submitted_before(dir, task, what, say)
    } else {
        None
    };
    let (id, task) = match &adopted {
        Some((id, old)) => {
            say(&format!(
                "{what}: job {id} was submitted before; waiting for it"
            ));
            (id.clone(), old)
        }
        None => {
            let id = submit(scheduler, dir, task, resources, what)?;
            say(&format!("{what}: submitted job {id}"));
            (id, task)
        }
    };
    queue::wait(scheduler, &id, what, say)?;
    let state = queue::final_state(&id);
    let (result, why) = match read_result(&dir.join("result.json")) {
        Ok(result) => match check::answers(task, &result) {
            Ok(()) => (Some(result), None),
            Err(reason) => (
                None,
                Some(format!("but its result.json is refused: {reason}")),
            ),
        },
        Err(why) => (None, Some(why)),
    };
    let error = why.map(|why| JobError {
        what: format!(
            "job {id} ended {} {why}",
            state.as_deref().unwrap_or("(state unknown)")
        ),
        output_tail: job_output_tail(&dir.join("job.out")),
    });
    Ok(Ended {
        record: JobRecord {
            id,
            node: result.as_ref().and_then(|r| r.node.clone()),
            state,
            error,
        },
        result,
    })
}

/// The job an earlier sweep submitted in `dir` for the same work as `task`, with the task it
/// was given (whose token its result must carry); `None` if there is none, or it was given
/// other work (then it is left alone and the round is submitted again).
fn submitted_before(
    dir: &Path,
    task: &Task,
    what: &str,
    say: &mut dyn FnMut(&str),
) -> Option<(String, Task)> {
    let id = nbody_engine::input::read_text(&dir.join("job-id")).ok()?;
    let id = id.trim();
    if id.is_empty() || id.len() > 40 || !id.bytes().all(|b| b.is_ascii_digit()) {
        return None;
    }
    let old = nbody_engine::input::read_text(&dir.join("task.json"))
        .ok()
        .and_then(|text| serde_json::from_str::<Task>(&text).ok());
    match old {
        Some(old) if old.same_work(task) => Some((id.to_string(), old)),
        _ => {
            say(&format!(
                "{what}: job {id} was submitted before for other work (or its task.json is \
                 gone); submitting the round again"
            ));
            None
        }
    }
}

/// The job's result, or why there is none to take ("without a result", "but its result.json
/// cannot be read: ..."). Read with the limits of every input: a pipe or a device left in its
/// place neither hangs the sweep nor fills its memory.
fn read_result(path: &Path) -> Result<JobResult, String> {
    if let Err(e) = std::fs::symlink_metadata(path)
        && e.kind() == std::io::ErrorKind::NotFound
    {
        return Err("without a result".into());
    }
    let text = nbody_engine::input::read_text(path)
        .map_err(|e| format!("but its result.json cannot be read: {e}"))?;
    serde_json::from_str(&text)
        .map_err(|e| format!("but its result.json is not a job's result: {e}"))
}

/// The last lines of the job's output, if it is a file (a pipe in its place would block).
fn job_output_tail(path: &Path) -> Vec<String> {
    match std::fs::metadata(path) {
        Ok(m) if m.is_file() => super::external::process::last_lines_of(path),
        _ => Vec::new(),
    }
}

/// Writes the task and its script into `dir` and submits it; the job id. Whatever an earlier
/// job left in `dir` is removed first, so nothing of it can pass for this job's.
fn submit(
    scheduler: &Scheduler,
    dir: &Path,
    task: &Task,
    resources: Resources,
    what: &str,
) -> Result<String, SlurmError> {
    nbody_engine::output::create_dir_all(dir).map_err(|source| SlurmError::Dir {
        path: dir.into(),
        source,
    })?;
    for stale in ["job-id", "result.json", "job.out"] {
        let path = dir.join(stale);
        match std::fs::remove_file(&path) {
            Err(e) if e.kind() != std::io::ErrorKind::NotFound => {
                return Err(SlurmError::Dir { path, source: e });
            }
            _ => {}
        }
    }
    let text = serde_json::to_vec_pretty(task).map_err(|e| SlurmError::Write {
        path: dir.join("task.json"),
        detail: e.to_string(),
    })?;
    write(&dir.join("task.json"), &text)?;
    let script = format!(
        "#!/bin/sh\n# Written by nbody-bench: {what}. Submitted with sbatch; runs on the compute \
         node and writes result.json here.\nexec {} job {}\n",
        shell_quote(&task.context.nbody_bench.display().to_string()),
        shell_quote(&dir.display().to_string())
    );
    write(&dir.join("job.sh"), script.as_bytes())?;
    let mut sbatch = Command::new("sbatch");
    sbatch.args(sbatch_args(scheduler, dir, &task.config.name, resources));
    sbatch.arg(dir.join("job.sh"));
    let out = supervised::output(&mut sbatch, CALL_LIMIT, "`sbatch`", "")
        .map_err(|e| SlurmError::Call(e.to_string()))?;
    let stdout = String::from_utf8_lossy(&out.stdout);
    // `--parsable` prints "id" or "id;cluster".
    let id = stdout
        .lines()
        .next()
        .unwrap_or("")
        .split(';')
        .next()
        .unwrap_or("")
        .trim();
    if !out.status.success() || id.is_empty() || !id.bytes().all(|b| b.is_ascii_digit()) {
        return Err(SlurmError::Refused {
            what: what.to_string(),
            message: last_line(&out.stderr).unwrap_or_else(|| stdout.trim().to_string()),
        });
    }
    write(&dir.join("job-id"), id.as_bytes())?;
    Ok(id.to_string())
}

/// The arguments of `sbatch` for one job (the script's path comes last).
pub(crate) fn sbatch_args(
    scheduler: &Scheduler,
    dir: &Path,
    sweep: &str,
    resources: Resources,
) -> Vec<String> {
    let mut a = vec![
        "--parsable".to_string(),
        format!("--job-name=nbody-{sweep}"),
        format!("--output={}", dir.join("job.out").display()),
        format!("--ntasks={}", resources.tasks),
        format!("--cpus-per-task={}", resources.cpus_per_task),
        format!("--time={}", scheduler.time_limit),
    ];
    if let Some(p) = &scheduler.partition {
        a.push(format!("--partition={p}"));
    }
    if let Some(acc) = &scheduler.account {
        a.push(format!("--account={acc}"));
    }
    a.extend(scheduler.sbatch_args.iter().cloned());
    a
}

/// A round that no job measured: no samples, the job's record.
pub(crate) fn unmeasured_round(case: &Case, spec: &RoundSpec, job: JobRecord) -> RoundOutcome {
    RoundOutcome {
        steps_per_sample: spec.steps_per_sample.unwrap_or(0),
        samples_s: Vec::new(),
        step_ns: Vec::new(),
        steps: 0,
        warmup_steps: 0,
        phases: None,
        work: None,
        pairs_interacting: None,
        energy_drift: None,
        force_error: None,
        n: case.n,
        clock_overhead: 0.0,
        reference_s: Vec::new(),
        initial_work: None,
        mpi: None,
        external: None,
        job: Some(job),
    }
}

/// `jobs/<what>` under the results directory, e.g. `jobs/round-2-lj-box-naive-n=1000-...`.
pub(crate) fn job_dir(results: &Path, name: &str) -> PathBuf {
    let slug: String = name
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || "-_.=".contains(c) {
                c
            } else {
                '-'
            }
        })
        .collect();
    results
        .parent()
        .unwrap_or(Path::new("."))
        .join("jobs")
        .join(slug)
}

fn write(path: &Path, bytes: &[u8]) -> Result<(), SlurmError> {
    nbody_engine::output::write_atomic(path, bytes).map_err(|e| SlurmError::Write {
        path: path.into(),
        detail: e.to_string(),
    })
}

fn last_line(bytes: &[u8]) -> Option<String> {
    String::from_utf8_lossy(bytes)
        .lines()
        .rev()
        .find(|l| !l.trim().is_empty())
        .map(|l| l.trim().to_string())
}

/// `'text'` for sh, with embedded quotes escaped.
fn shell_quote(text: &str) -> String {
    format!("'{}'", text.replace('\'', "'\\''"))
}

#[cfg(test)]
mod tests {
    use super::*;
    use nbody_records::scheduler::SchedulerKind;

    #[test]
    fn sbatch_asks_for_the_cases_cpus_and_the_configs_limits() {
        let s = Scheduler {
            kind: SchedulerKind::Slurm,
            partition: Some("short".into()),
            account: None,
            time_limit: "10:00".into(),
            sbatch_args: vec!["--qos=test".into()],
            poll_s: 1.0,
        };
        let args = sbatch_args(
            &s,
            Path::new("/r/jobs/x"),
            "weak",
            Resources {
                tasks: 4,
                cpus_per_task: 2,
            },
        );
        assert_eq!(
            args,
            [
                "--parsable",
                "--job-name=nbody-weak",
                "--output=/r/jobs/x/job.out",
                "--ntasks=4",
                "--cpus-per-task=2",
                "--time=10:00",
                "--partition=short",
                "--qos=test",
            ]
        );
    }

    #[test]
    fn job_directories_and_scripts_are_safe_names() {
        let d = job_dir(
            Path::new("/r/sweep/results.json"),
            "round-1 lj-box/naive/n=1000/p=1",
        );
        assert_eq!(
            d,
            Path::new("/r/sweep/jobs/round-1-lj-box-naive-n=1000-p=1")
        );
        assert_eq!(shell_quote("/a b/it's"), "'/a b/it'\\''s'");
    }
}
