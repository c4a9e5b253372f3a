//! Starting one external process: argv and environment as given (no shell), standard output
//! and error to files in the case's work directory, wall time from start to exit, and a kill
//! of its whole process group (SIGTERM, then SIGKILL) at the timeout.

use crate::units::Bytes;
use std::path::{Path, PathBuf};
use std::process::{Command, ExitStatus, Stdio};
use std::time::{Duration, Instant};
use wait_timeout::ChildExt;

use nbody_records::external::MAX_TIMEOUT_S;
/// Lines of output kept with a failed sample.
pub(crate) const TAIL_LINES: usize = 20;
/// At most this much of a run's output is read back.
pub(crate) const MAX_OUTPUT_BYTES: u64 = 16 << 20;
/// The end of an output longer than that, read for its last lines.
const TAIL_BYTES: u64 = 64 << 10;

/// A process that ran, or was killed at its timeout.
#[derive(Debug)]
pub struct Finished {
    /// Wall time from start to exit (or to the kill at the timeout), seconds.
    pub wall_s: f64,
    /// `None` when killed at the timeout.
    pub status: Option<ExitStatus>,
    /// What it wrote to standard output (`stdout.txt`), as read back.
    pub stdout: Output,
    /// What it wrote to standard error (`stderr.txt`), as read back.
    pub stderr: Output,
}

impl Finished {
    /// The last lines of standard error, else of standard output.
    pub fn tail(&self) -> Vec<String> {
        if self.stderr.text.trim().is_empty() {
            self.stdout.last_lines()
        } else {
            self.stderr.last_lines()
        }
    }

    /// Why the output cannot be searched by the config's regular expressions, if it cannot:
    /// only its first [`MAX_OUTPUT_BYTES`] are read back, and a time printed after them would
    /// be missed without a word.
    pub(crate) fn too_long(&self) -> Option<String> {
        let (name, o) = [
            ("standard output", &self.stdout),
            ("standard error", &self.stderr),
        ]
        .into_iter()
        .find(|(_, o)| !o.complete())?;
        Some(format!(
            "its {name} is {:.1}, more than the {:.0} read back for the `check`, `time` and \
             `force_error` regular expressions; make it print less (e.g. a quieter log level, \
             or its log into a file of its own)",
            Bytes(o.bytes as f64),
            Bytes(MAX_OUTPUT_BYTES as f64)
        ))
    }
}

/// A command ready to start.
#[derive(Clone, Debug, PartialEq)]
pub struct Launch {
    /// The program and its arguments, run without a shell; the program is found by [`resolve`].
    pub argv: Vec<String>,
    /// Variables set on top of the sweep's own environment, in order.
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

/// Runs `launch` in `dir`, its output into `dir/stdout.txt` and `dir/stderr.txt`. The program
/// is the one [`resolve`] finds with the launch's environment, started as the leader of a
/// process group of its own: at the timeout the whole group is stopped (SIGTERM, a grace
/// period, SIGKILL), and whatever it left running is killed when it ends.
pub fn run(launch: &Launch, dir: &Path, timeout_s: f64) -> std::io::Result<Finished> {
    // The config refuses an empty command; a launch built otherwise is an error, not a panic.
    let Some((program, args)) = launch.argv.split_first() else {
        return Err(std::io::Error::new(
            std::io::ErrorKind::InvalidInput,
            "an external command needs at least the program to run",
        ));
    };
    let program = resolve(program, path_of(&launch.env))
        .map_err(|why| std::io::Error::new(std::io::ErrorKind::NotFound, why))?;
    // The config bounds timeout_s; this keeps Duration from panicking whatever a caller passes.
    let timeout = Duration::try_from_secs_f64(timeout_s.min(MAX_TIMEOUT_S)).map_err(|_| {
        std::io::Error::new(
            std::io::ErrorKind::InvalidInput,
            format!("the timeout {timeout_s} s is not a duration"),
        )
    })?;
    let out_path = dir.join("stdout.txt");
    let err_path = dir.join("stderr.txt");
    let stdout = std::fs::File::create(&out_path)?;
    let stderr = std::fs::File::create(&err_path)?;
    let mut command = Command::new(program);
    command
        .args(args)
        .envs(launch.env.iter().map(|(k, v)| (k, v)))
        .current_dir(dir)
        .stdin(Stdio::null())
        .stdout(stdout)
        .stderr(stderr);
    let start = Instant::now();
    let (mut child, group) = crate::children::spawn(&mut command)?;
    let status = child.wait_timeout(timeout);
    let wall_s = start.elapsed().as_secs_f64();
    let status = match status {
        Ok(Some(s)) => Some(s),
        Ok(None) => {
            group.terminate(&mut child);
            None
        }
        Err(e) => {
            group.terminate(&mut child);
            return Err(e);
        }
    };
    // Members of the group still running (a background child of a shell) are killed here,
    // before the output is read: nothing of the run outlives it.
    drop(group);
    Ok(Finished {
        wall_s,
        status,
        stdout: Output::read(&out_path),
        stderr: Output::read(&err_path),
    })
}

/// The `PATH` an environment sets, if it sets one.
pub(crate) fn path_of(env: &[(String, String)]) -> Option<&str> {
    env.iter()
        .find(|(k, _)| k == "PATH")
        .map(|(_, v)| v.as_str())
}

/// The executable file `program` names, as an absolute path, or why there is none. This is
/// the one rule for both the check before a sweep and every launch:
/// - a name with a `/` is a path; a relative one is taken from the directory the sweep was
///   started in (not the case's work directory the program runs in);
/// - a bare name is looked up on `path` (the `PATH` the program's `env` sets), else on this
///   process's `PATH`; relative entries of it are taken from the sweep's directory too.
pub fn resolve(program: &str, path: Option<&str>) -> Result<PathBuf, String> {
    use std::os::unix::fs::PermissionsExt;
    if program.contains('\0') {
        return Err("it contains a NUL byte".into());
    }
    if program.is_empty() {
        return Err("the program name is empty".into());
    }
    let base = std::env::current_dir()
        .map_err(|e| format!("the current directory is unreadable ({e})"))?;
    let executable = |p: &Path| {
        p.metadata()
            .is_ok_and(|m| m.is_file() && m.permissions().mode() & 0o111 != 0)
    };
    if program.contains('/') {
        let p = base.join(program);
        return if executable(&p) {
            Ok(p)
        } else if p.exists() {
            Err(format!("{} is not an executable file", p.display()))
        } else if Path::new(program).is_relative() {
            Err(format!(
                "there is no {} (a relative program path is taken from the directory the \
                 sweep is started in, {})",
                p.display(),
                base.display()
            ))
        } else {
            Err(format!("there is no {}", p.display()))
        };
    }
    let (dirs, whose) = match path {
        Some(p) => (std::ffi::OsString::from(p), "the PATH its env sets"),
        None => (std::env::var_os("PATH").unwrap_or_default(), "PATH"),
    };
    if dirs.is_empty() {
        return Err(format!(
            "{whose} is empty, so no program can be found by name"
        ));
    }
    std::env::split_paths(&dirs)
        .map(|d| base.join(d).join(program))
        .find(|p| executable(p))
        .ok_or_else(|| {
            format!(
                "no executable `{program}` on {whose} ({})",
                dirs.to_string_lossy()
            )
        })
}

/// The last [`TAIL_LINES`] lines of the output written to `path` (none if it cannot be read),
/// read as a run's output is: at most [`MAX_OUTPUT_BYTES`] from the start, and its end.
pub(crate) fn last_lines_of(path: &Path) -> Vec<String> {
    Output::read(path).last_lines()
}

/// One output stream of a finished run: its text up to [`MAX_OUTPUT_BYTES`], and its size.
#[derive(Debug, Default)]
pub struct Output {
    /// All of it, or its first [`MAX_OUTPUT_BYTES`] when longer.
    pub text: String,
    /// Its size in bytes.
    pub bytes: u64,
    /// Its last lines when the text is not all of it.
    end: Option<String>,
}

impl Output {
    fn read(path: &Path) -> Output {
        use std::io::{Read, Seek, SeekFrom};
        let Ok(mut f) = std::fs::File::open(path) else {
            return Output::default();
        };
        let bytes = f.metadata().map_or(0, |m| m.len());
        let mut text = Vec::new();
        let _ = (&mut f).take(MAX_OUTPUT_BYTES).read_to_end(&mut text);
        let mut end = None;
        if bytes > MAX_OUTPUT_BYTES && f.seek(SeekFrom::End(-(TAIL_BYTES as i64))).is_ok() {
            let mut last = Vec::new();
            let _ = f.take(TAIL_BYTES).read_to_end(&mut last);
            end = Some(String::from_utf8_lossy(&last).into_owned());
        }
        Output {
            text: String::from_utf8_lossy(&text).into_owned(),
            bytes,
            end,
        }
    }

    /// Whether [`Output::text`] is all of the output.
    pub fn complete(&self) -> bool {
        self.bytes <= MAX_OUTPUT_BYTES
    }

    fn last_lines(&self) -> Vec<String> {
        let text = self.end.as_deref().unwrap_or(&self.text);
        let lines: Vec<&str> = text.lines().collect();
        lines[lines.len().saturating_sub(TAIL_LINES)..]
            .iter()
            .map(|l| l.to_string())
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn launch(argv: &[&str]) -> Launch {
        Launch {
            argv: argv.iter().map(|a| a.to_string()).collect(),
            env: vec![],
        }
    }

    #[test]
    fn arguments_reach_the_program_literally_and_timeouts_kill() {
        let dir = tempfile::tempdir().unwrap();
        let odd = "a b;c|d $(echo x) `y` 'q' \"r\" *";
        let done = run(&launch(&["printf", "%s\\n", odd]), dir.path(), 30.0).unwrap();
        assert!(done.status.unwrap().success());
        assert_eq!(done.stdout.text, format!("{odd}\n"));
        assert!(done.too_long().is_none());
        let killed = run(&launch(&["sleep", "30"]), dir.path(), 0.2).unwrap();
        assert!(killed.status.is_none());
        assert!(killed.wall_s < 25.0, "{}", killed.wall_s);
        // A timeout no Duration can hold is not a panic.
        assert!(run(&launch(&["true"]), dir.path(), 1e20).is_ok());
        assert!(run(&launch(&["true"]), dir.path(), -1.0).is_err());
    }

    #[test]
    fn a_timed_out_shell_takes_its_children_with_it() {
        let dir = tempfile::tempdir().unwrap();
        let killed = run(
            &launch(&["sh", "-c", "echo $$; sleep 43; echo"]),
            dir.path(),
            0.3,
        )
        .unwrap();
        assert!(killed.status.is_none());
        let group: i32 = killed.stdout.text.trim().parse().unwrap();
        assert_eq!(crate::children::members_left(group), Vec::<i32>::new());
    }

    #[test]
    fn output_past_the_limit_is_reported_not_cut() {
        let dir = tempfile::tempdir().unwrap();
        let script = format!(
            "head -c {} /dev/zero | tr '\\0' x; echo; echo 'time 7 s'",
            MAX_OUTPUT_BYTES + (1 << 20)
        );
        let done = run(&launch(&["sh", "-c", &script]), dir.path(), 60.0).unwrap();
        assert!(!done.stdout.complete());
        let why = done.too_long().unwrap();
        assert!(
            why.contains("16 MiB") && why.contains("standard output"),
            "{why}"
        );
        assert_eq!(done.tail().last().map(String::as_str), Some("time 7 s"));
    }

    #[test]
    fn programs_resolve_by_one_rule() {
        use std::os::unix::fs::PermissionsExt;
        assert!(resolve("sh", None).unwrap().is_absolute());
        assert!(resolve("surely-no-such-program-here", None).is_err());
        let e = resolve("sh", Some("")).unwrap_err();
        assert!(e.contains("PATH its env sets is empty"), "{e}");
        assert!(resolve("sh", Some("/nonexistent-dir")).is_err());
        assert!(resolve("s\0h", None).unwrap_err().contains("NUL"));
        let dir = tempfile::tempdir().unwrap();
        let prog = dir.path().join("prog");
        std::fs::write(&prog, "#!/bin/sh\n").unwrap();
        std::fs::set_permissions(&prog, std::fs::Permissions::from_mode(0o755)).unwrap();
        let found = resolve("prog", Some(dir.path().to_str().unwrap())).unwrap();
        assert_eq!(found, prog);
        // Relative to the directory the sweep runs in, never the case's work directory.
        let cwd = std::env::current_dir().unwrap();
        let e = resolve("./surely/not/here.sh", None).unwrap_err();
        assert!(e.contains(&cwd.display().to_string()), "{e}");
        assert_eq!(
            resolve("src/../Cargo.toml", None).unwrap_err(),
            format!(
                "{} is not an executable file",
                cwd.join("src/../Cargo.toml").display()
            )
        );
    }
}
