//! Starting one external process: argv and environment as given (no shell), standard output
//! and error to files in the case's work directory, wall time from start to exit, and a kill
//! (SIGTERM, then SIGKILL) at the timeout.

use std::path::{Path, PathBuf};
use std::process::{Command, ExitStatus, Stdio};
use std::time::{Duration, Instant};
use wait_timeout::ChildExt;

/// Seconds between SIGTERM and SIGKILL for a program past its timeout (an MPI launcher
/// forwards SIGTERM to its ranks).
const KILL_GRACE_S: f64 = 2.0;
/// Lines of output kept with a failed sample.
pub const TAIL_LINES: usize = 20;
/// At most this much of a run's output is read back.
const MAX_OUTPUT_BYTES: u64 = 16 << 20;

/// A process that ran, or was killed at its timeout.
#[derive(Debug)]
pub struct Finished {
    pub wall_s: f64,
    /// `None` when killed at the timeout.
    pub status: Option<ExitStatus>,
    pub stdout: String,
    pub stderr: String,
}

impl Finished {
    /// The last lines of standard error, else of standard output.
    pub fn tail(&self) -> Vec<String> {
        let text = if self.stderr.trim().is_empty() {
            &self.stdout
        } else {
            &self.stderr
        };
        let lines: Vec<&str> = text.lines().collect();
        lines[lines.len().saturating_sub(TAIL_LINES)..]
            .iter()
            .map(|l| l.to_string())
            .collect()
    }
}

/// A command ready to start.
#[derive(Clone, Debug, PartialEq)]
pub struct Launch {
    pub argv: Vec<String>,
    pub env: Vec<(String, String)>,
}

impl Launch {
    /// The command as a person would type it (for messages only; it never runs this way).
    pub fn display(&self) -> String {
        self.argv
            .iter()
            .map(|a| {
                if !a.is_empty()
                    && a.chars()
                        .all(|c| c.is_ascii_alphanumeric() || "-_./=:,+@".contains(c))
                {
                    a.clone()
                } else {
                    format!("'{}'", a.replace('\'', "'\\''"))
                }
            })
            .collect::<Vec<_>>()
            .join(" ")
    }
}

/// Runs `launch` in `dir`, its output into `dir/stdout.txt` and `dir/stderr.txt`.
pub fn run(launch: &Launch, dir: &Path, timeout_s: f64) -> std::io::Result<Finished> {
    let out_path = dir.join("stdout.txt");
    let err_path = dir.join("stderr.txt");
    let stdout = std::fs::File::create(&out_path)?;
    let stderr = std::fs::File::create(&err_path)?;
    // The config refuses an empty command; a launch built otherwise is an error, not a panic.
    let Some((program, args)) = launch.argv.split_first() else {
        return Err(std::io::Error::new(
            std::io::ErrorKind::InvalidInput,
            "an external command needs at least the program to run",
        ));
    };
    let mut command = Command::new(program);
    command
        .args(args)
        .envs(launch.env.iter().map(|(k, v)| (k, v)))
        .current_dir(dir)
        .stdin(Stdio::null())
        .stdout(stdout)
        .stderr(stderr);
    let start = Instant::now();
    let mut child = command.spawn()?;
    let status = child.wait_timeout(Duration::from_secs_f64(timeout_s))?;
    let wall_s = start.elapsed().as_secs_f64();
    let status = match status {
        Some(s) => Some(s),
        None => {
            terminate(&mut child);
            None
        }
    };
    Ok(Finished {
        wall_s,
        status,
        stdout: read_lossy(&out_path),
        stderr: read_lossy(&err_path),
    })
}

/// SIGTERM, a grace period, then SIGKILL; always reaps the child.
fn terminate(child: &mut std::process::Child) {
    if let Ok(pid) = i32::try_from(child.id()) {
        // SAFETY: kill(2) with the pid of our own child, which has not been reaped yet.
        unsafe {
            libc::kill(pid, libc::SIGTERM);
        }
    }
    if let Ok(Some(_)) = child.wait_timeout(Duration::from_secs_f64(KILL_GRACE_S)) {
        return;
    }
    let _ = child.kill();
    let _ = child.wait();
}

fn read_lossy(path: &Path) -> String {
    use std::io::Read;
    let mut bytes = Vec::new();
    if let Ok(f) = std::fs::File::open(path) {
        let _ = f.take(MAX_OUTPUT_BYTES).read_to_end(&mut bytes);
    }
    String::from_utf8_lossy(&bytes).into_owned()
}

/// Where `program` would be found: a path as given, or the first executable of that name on
/// PATH. `None` if there is none.
pub fn find_program(program: &str) -> Option<PathBuf> {
    use std::os::unix::fs::PermissionsExt;
    let executable = |p: &Path| {
        p.metadata()
            .is_ok_and(|m| m.is_file() && m.permissions().mode() & 0o111 != 0)
    };
    if program.contains('/') {
        let p = PathBuf::from(program);
        return executable(&p).then_some(p);
    }
    let path = std::env::var_os("PATH")?;
    std::env::split_paths(&path)
        .map(|d| d.join(program))
        .find(|p| executable(p))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn arguments_reach_the_program_literally_and_timeouts_kill() {
        let dir = tempfile::tempdir().unwrap();
        let odd = "a b;c|d $(echo x) `y` 'q' \"r\" *";
        let launch = Launch {
            argv: vec!["printf".into(), "%s\\n".into(), odd.into()],
            env: vec![],
        };
        let done = run(&launch, dir.path(), 30.0).unwrap();
        assert!(done.status.unwrap().success());
        assert_eq!(done.stdout, format!("{odd}\n"));
        let sleep = Launch {
            argv: vec!["sleep".into(), "30".into()],
            env: vec![],
        };
        let killed = run(&sleep, dir.path(), 0.2).unwrap();
        assert!(killed.status.is_none());
        assert!(killed.wall_s < 25.0, "{}", killed.wall_s);
        assert!(find_program("sh").is_some());
        assert!(find_program("surely-no-such-program-here").is_none());
    }
}
