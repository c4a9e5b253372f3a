//! Case rounds and calibrations as Slurm jobs (a config's `[scheduler] kind = "slurm"`).
//!
//! Each piece of work gets a directory under the results, `jobs/<name>/`: the sweep writes
//! what to do (`task.json`) and a job script (`job.sh`, which runs `nbody-bench job DIR`),
//! submits it with `sbatch --parsable`, keeps the job id (`job-id`), and polls `squeue` until
//! the job has left the queue. The job measures on its compute node and writes `result.json`
//! (atomically) next to its output (`job.out`). A job that ends without a result (it failed,
//! hit its time limit, was cancelled) gives a round without samples that keeps the job's state
//! and last lines of output. The sweep waits for one job at a time, so the rounds interleave as
//! they do on one machine; an interrupted sweep leaves its job queued, and `--resume` waits for
//! that job (or reads its result) instead of submitting it again.

use super::external::Context;
use super::measure::RoundSpec;
use crate::calibrate::Calibration;
use crate::children::supervised;
use crate::records::config::SweepConfig;
use crate::records::plan::Case;
use crate::records::round::RoundOutcome;
use crate::records::scheduler::{JobError, JobRecord, Scheduler};
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Duration;
use thiserror::Error;

/// How long one call of `sbatch`, `squeue` or `scontrol` may take.
const CALL_LIMIT: Duration = Duration::from_secs(120);
/// Failed looks at the queue in a row before the sweep gives up on it (it can be resumed).
const QUEUE_FAILURES: usize = 5;

#[derive(Debug, Error)]
pub enum SlurmError {
    #[error("cannot prepare the job directory {path}: {source}")]
    Dir {
        path: PathBuf,
        source: std::io::Error,
    },
    #[error("cannot write {path}: {detail}")]
    Write { path: PathBuf, detail: String },
    #[error("{0}; is Slurm installed and its controller reachable (`sinfo`)?")]
    Call(String),
    #[error("`sbatch` refused the job of {what}: {message}")]
    Refused { what: String, message: String },
    #[error(
        "the queue could not be read {QUEUE_FAILURES} times in a row while waiting for job \
         {id} ({last}); the job is left as it is: run the sweep again with --resume to pick it up"
    )]
    Queue { id: String, last: String },
}

/// What a job does: one round of one case, or a calibration of the node.
#[derive(Serialize, Deserialize)]
pub(crate) struct Task {
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

/// A job that ended: its record, and its result if it wrote one.
pub(crate) struct Ended {
    pub record: JobRecord,
    pub result: Option<JobResult>,
}

impl Task {
    pub(crate) fn new(config: &SweepConfig, context: &Context, work: Work) -> Task {
        Task {
            config: config.clone(),
            context: context.clone(),
            work,
        }
    }
}

/// Whether `sbatch` can be started here, before anything is submitted.
pub(crate) fn check_available() -> Result<(), SlurmError> {
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

/// Runs `task` as a job in `dir` (submitting it unless an earlier sweep already did), waits
/// until it has left the queue and reads what it left. `say` tells the user what is waited for.
pub(crate) fn run(
    scheduler: &Scheduler,
    dir: &Path,
    task: &Task,
    resources: Resources,
    what: &str,
    say: &mut dyn FnMut(&str),
) -> Result<Ended, SlurmError> {
    let id_file = dir.join("job-id");
    let id = match std::fs::read_to_string(&id_file) {
        Ok(id) if !id.trim().is_empty() => {
            say(&format!(
                "{what}: job {} was submitted before; waiting for it",
                id.trim()
            ));
            id.trim().to_string()
        }
        _ => {
            let id = submit(scheduler, dir, task, resources, what)?;
            write(&id_file, id.as_bytes())?;
            say(&format!("{what}: submitted job {id}"));
            id
        }
    };
    wait(scheduler, &id, what, say)?;
    let state = final_state(&id);
    let result = std::fs::read(dir.join("result.json"))
        .ok()
        .and_then(|bytes| serde_json::from_slice::<JobResult>(&bytes).ok());
    let error = match &result {
        Some(_) => None,
        None => Some(JobError {
            what: format!(
                "job {id} ended {} without a result",
                state.as_deref().unwrap_or("(state unknown)")
            ),
            output_tail: super::external::process::last_lines_of(&dir.join("job.out")),
        }),
    };
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

/// Writes the task and its script into `dir` and submits it; the job id.
fn submit(
    scheduler: &Scheduler,
    dir: &Path,
    task: &Task,
    resources: Resources,
    what: &str,
) -> Result<String, SlurmError> {
    std::fs::create_dir_all(dir).map_err(|source| SlurmError::Dir {
        path: dir.into(),
        source,
    })?;
    let _ = std::fs::remove_file(dir.join("result.json"));
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

/// Polls the queue until job `id` is no longer in it.
fn wait(
    scheduler: &Scheduler,
    id: &str,
    what: &str,
    say: &mut dyn FnMut(&str),
) -> Result<(), SlurmError> {
    let mut failures = 0;
    let mut last_state = String::new();
    loop {
        let mut squeue = Command::new("squeue");
        squeue.args(["-h", "-j", id, "-o", "%T"]);
        let out = supervised::output(&mut squeue, CALL_LIMIT, "`squeue`", "")
            .map_err(|e| SlurmError::Call(e.to_string()))?;
        let stdout = String::from_utf8_lossy(&out.stdout);
        let state = stdout.trim();
        if out.status.success() {
            failures = 0;
            if state.is_empty() {
                return Ok(());
            }
            if state != last_state {
                if state == "PENDING" {
                    say(&format!("{what}: job {id} is waiting in the queue"));
                }
                last_state = state.to_string();
            }
        } else {
            let message = last_line(&out.stderr).unwrap_or_default();
            // A job that ended long enough ago is forgotten by the controller.
            if message.contains("Invalid job id") {
                return Ok(());
            }
            failures += 1;
            if failures >= QUEUE_FAILURES {
                return Err(SlurmError::Queue {
                    id: id.to_string(),
                    last: message,
                });
            }
        }
        std::thread::sleep(Duration::from_secs_f64(scheduler.poll_s));
    }
}

/// The job's final state from `scontrol` (kept by the controller for a while after the end).
fn final_state(id: &str) -> Option<String> {
    let mut scontrol = Command::new("scontrol");
    scontrol.args(["show", "job", id, "-o"]);
    let out = supervised::output(&mut scontrol, CALL_LIMIT, "`scontrol`", "").ok()?;
    let text = String::from_utf8_lossy(&out.stdout);
    text.split_whitespace()
        .find_map(|field| field.strip_prefix("JobState="))
        .map(str::to_string)
}

/// Inside the job: does the task in `dir` and writes `result.json`.
pub fn job_main(dir: &Path) -> Result<(), Box<dyn std::error::Error + Send + Sync>> {
    let bytes = std::fs::read(dir.join("task.json"))
        .map_err(|e| format!("cannot read {}: {e}", dir.join("task.json").display()))?;
    let task: Task = serde_json::from_slice(&bytes)
        .map_err(|e| format!("{}: {e}", dir.join("task.json").display()))?;
    let node = node_name();
    let result = match &task.work {
        Work::Round { case, spec } => {
            let clock = crate::clock::WallClock::new();
            let outcome =
                super::case_round::measure_case(case, spec, &clock, &task.config, &task.context)?;
            JobResult {
                node,
                step_ns: outcome.step_ns.clone(),
                round: Some(outcome),
                calibration: None,
            }
        }
        Work::Calibrate { threads } => JobResult {
            node,
            round: None,
            step_ns: Vec::new(),
            calibration: Some(crate::calibrate::calibrate(threads)),
        },
    };
    let text = serde_json::to_vec(&result)?;
    crate::output::write_atomic(&dir.join("result.json"), &text)?;
    Ok(())
}

/// The node a job runs on: Slurm's name for it, else the host name.
fn node_name() -> Option<String> {
    std::env::var("SLURMD_NODENAME")
        .ok()
        .filter(|s| !s.trim().is_empty())
        .or_else(crate::records::results::host_name)
}

/// A round that no job measured: no samples, the job's record.
pub(crate) fn unmeasured_round(case: &Case, spec: &RoundSpec, job: JobRecord) -> RoundOutcome {
    RoundOutcome {
        steps_per_sample: spec.steps_per_sample.unwrap_or(0),
        samples_s: Vec::new(),
        step_ns: Vec::new(),
        steps: 0,
        warmup_steps: 0,
        phases: Default::default(),
        work: Default::default(),
        pairs_interacting: 0,
        energy_drift: 0.0,
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
    crate::output::write_atomic(path, bytes).map_err(|e| SlurmError::Write {
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
    use crate::records::scheduler::SchedulerKind;

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
