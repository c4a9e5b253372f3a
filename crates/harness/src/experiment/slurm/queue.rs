//! Waiting for a job: `squeue` is asked for its state until it has left the queue. Only lines
//! that are Slurm job states count (a site's banner or notice around them is passed over), and
//! the wait is bounded: once the job is seen running, by its time limit and a margin; while its
//! state cannot be told at all, by the same from the start of the wait. A job waiting in the
//! queue (pending, held, suspended) is waited for as long as it waits: the sweep says so.

use super::{CALL_LIMIT, QUEUE_FAILURES, SlurmError, last_line};
use crate::children::supervised;
use nbody_records::scheduler::Scheduler;
use std::process::Command;
use std::time::{Duration, Instant};

/// The environment variable that sets the margin past a job's time limit, in seconds.
pub const GRACE_ENV: &str = "NBODY_BENCH_JOB_GRACE_S";
/// The margin past a job's time limit before the sweep stops waiting for it: Slurm stops a job
/// some time after its limit (the site's `OverTimeLimit`, `KillWait`, the epilog), and the
/// controller may be slow to answer.
const GRACE_S: f64 = 600.0;

/// Where a job is, as far as its time limit goes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Phase {
    /// Not started, or stopped for now: its time limit is not running.
    Waiting,
    /// Started: its time limit runs.
    Running,
    /// Done: it has left, or is leaving, the queue.
    Ended,
}

/// Slurm's job states (the long names of `squeue -o %T` and `scontrol`'s `JobState=`).
const STATES: [(&str, Phase); 24] = [
    ("PENDING", Phase::Waiting),
    ("CONFIGURING", Phase::Waiting),
    ("REQUEUED", Phase::Waiting),
    ("REQUEUE_FED", Phase::Waiting),
    ("REQUEUE_HOLD", Phase::Waiting),
    ("RESV_DEL_HOLD", Phase::Waiting),
    ("SPECIAL_EXIT", Phase::Waiting),
    ("SUSPENDED", Phase::Waiting),
    ("STOPPED", Phase::Waiting),
    ("RUNNING", Phase::Running),
    ("COMPLETING", Phase::Running),
    ("SIGNALING", Phase::Running),
    ("STAGE_OUT", Phase::Running),
    ("RESIZING", Phase::Running),
    ("COMPLETED", Phase::Ended),
    ("CANCELLED", Phase::Ended),
    ("FAILED", Phase::Ended),
    ("TIMEOUT", Phase::Ended),
    ("NODE_FAIL", Phase::Ended),
    ("BOOT_FAIL", Phase::Ended),
    ("DEADLINE", Phase::Ended),
    ("OUT_OF_MEMORY", Phase::Ended),
    ("PREEMPTED", Phase::Ended),
    ("REVOKED", Phase::Ended),
];

/// The state named by `text` (one word, as Slurm prints it), if it is one.
fn state(text: &str) -> Option<(&'static str, Phase)> {
    let text = text.trim();
    STATES.iter().copied().find(|(name, _)| *name == text)
}

/// What one look at the queue told.
#[derive(Debug, PartialEq, Eq)]
enum Look {
    /// The job is not listed (or the controller has forgotten it): it has left the queue.
    Gone,
    /// Its state.
    State(&'static str, Phase),
    /// Something was printed, but no job state.
    Unknown,
}

/// Reads `squeue -h -j ID -o %T`'s output: only lines that are job states count.
fn look(stdout: &str) -> Look {
    if let Some((name, phase)) = stdout.lines().find_map(state) {
        return Look::State(name, phase);
    }
    if stdout.trim().is_empty() {
        Look::Gone
    } else {
        Look::Unknown
    }
}

/// The margin past a job's time limit: [`GRACE_ENV`] if set (seconds > 0, at most a week), else
/// [`GRACE_S`].
pub(crate) fn check_grace() -> Result<Duration, SlurmError> {
    let Some(v) = std::env::var_os(GRACE_ENV) else {
        return Ok(Duration::from_secs_f64(GRACE_S));
    };
    v.to_str()
        .and_then(|v| v.trim().parse::<f64>().ok())
        .filter(|s| s.is_finite() && *s > 0.0 && *s <= 7.0 * 86_400.0)
        .map(Duration::from_secs_f64)
        .ok_or_else(|| {
            SlurmError::Grace(format!(
                "{GRACE_ENV}={} must be a number of seconds above 0 and at most 604800",
                v.to_string_lossy()
            ))
        })
}

/// The bound of a wait: the time limit and margin, counted from `from`.
struct Bound {
    limit: Duration,
    grace: Duration,
    /// When the job was seen running; else the last time it was seen waiting in the queue;
    /// else the start of the wait.
    from: Instant,
    running: bool,
}

impl Bound {
    fn new(limit: Duration, grace: Duration, now: Instant) -> Bound {
        Bound {
            limit,
            grace,
            from: now,
            running: false,
        }
    }

    /// Takes in one look at the job at `now`.
    fn saw(&mut self, look: &Look, now: Instant) {
        match look {
            Look::State(_, Phase::Running) if !self.running => {
                self.running = true;
                self.from = now;
            }
            // Its limit has not started: a job waits in the queue as long as the queue says.
            Look::State(_, Phase::Waiting) if !self.running => self.from = now,
            _ => {}
        }
    }

    /// Whether the wait is over at `now`.
    fn passed(&self, now: Instant) -> bool {
        now.duration_since(self.from) > self.limit + self.grace
    }
}

/// Polls the queue until job `id` is no longer in it, at most until its [`Bound`].
pub(super) fn wait(
    scheduler: &Scheduler,
    id: &str,
    what: &str,
    say: &mut dyn FnMut(&str),
) -> Result<(), SlurmError> {
    let grace = check_grace()?;
    // A limit the config check let through always parses; a day if one did not.
    let limit = scheduler
        .time_limit()
        .unwrap_or(Duration::from_secs(86_400));
    let start = Instant::now();
    let mut bound = Bound::new(limit, grace, start);
    let mut failures = 0;
    let mut last_state = "";
    loop {
        let mut squeue = Command::new("squeue");
        squeue.args(["-h", "-j", id, "-o", "%T"]);
        let out = supervised::output(&mut squeue, CALL_LIMIT, "`squeue`", "")
            .map_err(|e| SlurmError::Call(e.to_string()))?;
        if out.status.success() {
            failures = 0;
            let mut seen = look(&String::from_utf8_lossy(&out.stdout));
            if seen == Look::Unknown {
                // Not a state squeue's answer shows (a wrapper's banner only): the controller's
                // record of the job may tell.
                if let Some((name, phase)) = final_state(id).as_deref().and_then(state) {
                    seen = Look::State(name, phase);
                }
            }
            match seen {
                Look::Gone | Look::State(_, Phase::Ended) => return Ok(()),
                Look::State(name, _) if name != last_state => {
                    if name == "PENDING" {
                        say(&format!("{what}: job {id} is waiting in the queue"));
                    }
                    last_state = name;
                }
                _ => {}
            }
            bound.saw(&seen, Instant::now());
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
        let now = Instant::now();
        if bound.passed(now) {
            return Err(SlurmError::Overdue {
                id: id.to_string(),
                what: what.to_string(),
                seen: if bound.running {
                    "has been running".into()
                } else {
                    "has had no state `squeue` or `scontrol` could tell".into()
                },
                waited: now.duration_since(bound.from).as_secs(),
                limit: scheduler.time_limit.clone(),
                grace_s: grace.as_secs(),
            });
        }
        std::thread::sleep(Duration::from_secs_f64(scheduler.poll_s));
    }
}

/// The job's state from `scontrol` (kept by the controller for a while after the end), if it
/// gives one in Slurm's form (an upper-case word).
pub(super) fn final_state(id: &str) -> Option<String> {
    let mut scontrol = Command::new("scontrol");
    scontrol.args(["show", "job", id, "-o"]);
    let out = supervised::output(&mut scontrol, CALL_LIMIT, "`scontrol`", "").ok()?;
    let text = String::from_utf8_lossy(&out.stdout);
    text.split_whitespace()
        .find_map(|field| field.strip_prefix("JobState="))
        .filter(|s| {
            (1..=32).contains(&s.len()) && s.bytes().all(|b| b.is_ascii_uppercase() || b == b'_')
        })
        .map(str::to_string)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn only_job_states_are_read_from_the_queue() {
        assert_eq!(look(""), Look::Gone);
        assert_eq!(look("\n  \n"), Look::Gone);
        assert_eq!(look("RUNNING\n"), Look::State("RUNNING", Phase::Running));
        assert_eq!(
            look("Welcome to the cluster: maintenance on Monday\nPENDING\n"),
            Look::State("PENDING", Phase::Waiting)
        );
        assert_eq!(look("Welcome to the cluster\n"), Look::Unknown);
        assert_eq!(look("RUNNING BUT NOT\n"), Look::Unknown);
        assert_eq!(look("COMPLETED"), Look::State("COMPLETED", Phase::Ended));
    }

    #[test]
    fn the_wait_is_bounded_from_the_start_of_running_or_of_the_wait() {
        let t0 = Instant::now();
        let s = |x: u64| Duration::from_secs(x);
        let limit = s(60);
        let grace = s(10);
        // Never told: from the start.
        let mut b = Bound::new(limit, grace, t0);
        b.saw(&Look::Unknown, t0 + s(30));
        assert!(!b.passed(t0 + s(70)) && b.passed(t0 + s(71)));
        // Pending for an hour, then running: from when it was seen running.
        let mut b = Bound::new(limit, grace, t0);
        b.saw(&Look::State("PENDING", Phase::Waiting), t0 + s(3600));
        b.saw(&Look::State("RUNNING", Phase::Running), t0 + s(3601));
        b.saw(&Look::Unknown, t0 + s(3610));
        b.saw(&Look::State("PENDING", Phase::Waiting), t0 + s(3620));
        assert!(!b.passed(t0 + s(3671)) && b.passed(t0 + s(3672)));
    }
}
