//! Programs run to their end under a time limit (every process the gate starts: git, cargo,
//! rustc, both builds' sweeps; a sweep's MPI launches): a child that hangs becomes an error
//! naming it and its limit, never a command that waits forever.
//!
//! Each child runs in a process group of its own ([`super::spawn`], as external programs
//! do), so that at its limit the whole group is signalled (SIGTERM, a grace period, then
//! SIGKILL): a shell script's `sleep`, or the compilers cargo started, go with it; and the
//! interrupt handler stops the groups still running before the gate exits.

use std::io::Read;
use std::process::{Child, Command, ExitStatus, Output, Stdio};
use std::sync::mpsc;
use std::time::Duration;
use thiserror::Error;
use wait_timeout::ChildExt;

/// How long the output of a finished or killed child is still waited for: a grandchild that
/// left the group may hold the pipe open, and the gate must not wait for it.
const DRAIN_WAIT: Duration = Duration::from_secs(2);
/// At most this much of each output stream is kept (the end of it: error messages come last).
const KEPT_OUTPUT_BYTES: usize = 1 << 20;

/// Why a supervised child gave no exit status; each variant names the child as the caller does.
#[derive(Debug, Error)]
pub enum ChildError {
    /// The program could not be spawned (not found, not executable).
    #[error("{what} cannot be started: {source}")]
    Start {
        /// The child as messages name it, e.g. "rustc -vV".
        what: String,
        /// The error of the spawn.
        source: std::io::Error,
    },
    /// The child ran past its limit; its process group was terminated.
    #[error(
        "{what} did not finish within {limit} and was stopped{hint}",
        hint = if hint.is_empty() { String::new() } else { format!("; {hint}") }
    )]
    TimedOut {
        /// The child as messages name it.
        what: String,
        /// The limit, e.g. "120 s" or "0.3 s".
        limit: String,
        /// What the user can do about it, appended after "; "; empty for none.
        hint: String,
    },
    /// Waiting for the child's exit failed (an operating-system error).
    #[error("waiting for {what} failed: {source}")]
    Wait {
        /// The child as messages name it.
        what: String,
        /// The error of the wait.
        source: std::io::Error,
    },
}

/// A started child, its process group registered until it has been reaped.
struct Running {
    child: Child,
    group: super::Group,
}

impl Running {
    fn start(command: &mut Command, what: &str) -> Result<Running, ChildError> {
        let (child, group) = super::spawn(command).map_err(|source| ChildError::Start {
            what: what.to_string(),
            source,
        })?;
        Ok(Running { child, group })
    }

    /// Waits up to `limit`; `None` when the child was stopped at the limit.
    fn wait(&mut self, limit: Duration, what: &str) -> Result<Option<ExitStatus>, ChildError> {
        let waited = self
            .child
            .wait_timeout(limit)
            .map_err(|source| ChildError::Wait {
                what: what.to_string(),
                source,
            })?;
        if waited.is_some() {
            return Ok(waited);
        }
        self.group.terminate(&mut self.child);
        Ok(None)
    }
}

impl Drop for Running {
    fn drop(&mut self) {
        // Whatever happened, no child outlives its supervision (a no-op once it has exited);
        // the group's own drop then clears what is left of the group.
        if matches!(self.child.try_wait(), Ok(None)) {
            self.group.signal(libc::SIGKILL);
            let _ = self.child.wait();
        }
    }
}

/// Runs `command` (its standard output and error already set, e.g. to a log file; standard
/// input is closed) for at most `limit`; its exit status.
pub fn status(
    command: &mut Command,
    limit: Duration,
    what: &str,
    hint: &str,
) -> Result<ExitStatus, ChildError> {
    command.stdin(Stdio::null());
    let mut child = Running::start(command, what)?;
    child
        .wait(limit, what)?
        .ok_or_else(|| timed_out(what, limit, hint))
}

/// Runs `command` for at most `limit` and collects its output (the last
/// [`KEPT_OUTPUT_BYTES`] of each stream); standard input is closed.
pub fn output(
    command: &mut Command,
    limit: Duration,
    what: &str,
    hint: &str,
) -> Result<Output, ChildError> {
    command
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped());
    let mut child = Running::start(command, what)?;
    // Both pipes are read while the child runs, so that a chatty child never blocks on a full
    // pipe; the readers report through a channel, so that none is waited for forever.
    let readers = [
        child.child.stdout.take().map(drain),
        child.child.stderr.take().map(drain),
    ];
    let status = child.wait(limit, what)?;
    let [stdout, stderr] = readers.map(|r| {
        r.and_then(|rx| rx.recv_timeout(DRAIN_WAIT).ok())
            .unwrap_or_default()
    });
    match status {
        Some(status) => Ok(Output {
            status,
            stdout,
            stderr,
        }),
        None => Err(timed_out(what, limit, hint)),
    }
}

fn timed_out(what: &str, limit: Duration, hint: &str) -> ChildError {
    ChildError::TimedOut {
        what: what.to_string(),
        limit: seconds(limit),
        hint: hint.to_string(),
    }
}

/// "120 s", "2.5 s", "0.3 s".
pub fn seconds(d: Duration) -> String {
    let s = d.as_secs_f64();
    if s >= 10.0 || s.fract() == 0.0 {
        format!("{s:.0} s")
    } else {
        format!("{s:.1} s")
    }
}

/// Reads `stream` to its end on a thread of its own; the last bytes arrive on the channel.
fn drain(mut stream: impl Read + Send + 'static) -> mpsc::Receiver<Vec<u8>> {
    let (tx, rx) = mpsc::channel();
    std::thread::spawn(move || {
        let mut kept = Vec::new();
        let mut buf = [0u8; 8192];
        loop {
            match stream.read(&mut buf) {
                Ok(0) | Err(_) => break,
                Ok(k) => {
                    kept.extend_from_slice(&buf[..k]);
                    if kept.len() > 2 * KEPT_OUTPUT_BYTES {
                        kept.drain(..kept.len() - KEPT_OUTPUT_BYTES);
                    }
                }
            }
        }
        if kept.len() > KEPT_OUTPUT_BYTES {
            kept.drain(..kept.len() - KEPT_OUTPUT_BYTES);
        }
        let _ = tx.send(kept);
    });
    rx
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::time::Instant;

    #[test]
    fn a_child_that_finishes_gives_its_output() {
        let o = output(
            Command::new("sh").args(["-c", "echo out; echo err >&2; exit 3"]),
            Duration::from_secs(30),
            "the test shell",
            "",
        )
        .unwrap();
        assert_eq!(o.status.code(), Some(3));
        assert_eq!(String::from_utf8_lossy(&o.stdout), "out\n");
        assert_eq!(String::from_utf8_lossy(&o.stderr), "err\n");
    }

    #[test]
    fn a_hanging_child_and_its_own_children_are_stopped_at_the_limit() {
        let started = Instant::now();
        // The shell's `sleep` holds the output pipe: stopping the shell alone would leave the
        // gate waiting for the pipe's end.
        let err = output(
            Command::new("sh").args(["-c", "sleep 60; echo never"]),
            Duration::from_millis(300),
            "the test shell",
            "a hint",
        )
        .unwrap_err()
        .to_string();
        assert!(
            err.contains("the test shell did not finish within 0.3 s and was stopped; a hint"),
            "{err}"
        );
        // Not a timing assertion: a bound far above the limit, so that a hang fails the test.
        assert!(started.elapsed() < Duration::from_secs(30));
        let err = status(
            Command::new("sh")
                .args(["-c", "sleep 60"])
                .stdout(Stdio::null()),
            Duration::from_millis(300),
            "the second shell",
            "",
        )
        .unwrap_err()
        .to_string();
        assert!(err.ends_with("was stopped"), "{err}");
    }

    #[test]
    fn a_program_that_does_not_exist_is_an_error() {
        let err = output(
            &mut Command::new("/nonexistent/program"),
            Duration::from_secs(5),
            "the base build's binary",
            "",
        )
        .unwrap_err()
        .to_string();
        assert!(
            err.contains("the base build's binary cannot be started"),
            "{err}"
        );
    }
}
