//! Standard output that never panics: every table and line a command prints goes through
//! [`outln!`] / [`out!`].
//!
//! `println!` panics when stdout fails, so `nbody-bench fit ... | head -1` used to die with
//! "failed printing to stdout: Broken pipe", and a sweep that printed into a closed pipe after
//! its last round skipped its analysis. Here a failed write is remembered and every later
//! write is dropped, so the command's work (a sweep's results, its analysis) goes on untouched:
//!
//! - a closed pipe (`EPIPE`) ends the output quietly, like any Unix tool;
//! - any other failure (a full disk, `>/dev/full`) is reported once when the command ends,
//!   by [`finish`], which makes the exit code 2.

use std::io::Write;
use std::sync::Mutex;

/// What has happened to stdout so far.
#[derive(Clone, Debug, PartialEq, Eq)]
enum Stdout {
    Open,
    /// The reader went away: stop writing, say nothing.
    Closed,
    /// A write failed otherwise: stop writing, report it at the end.
    Failed(String),
}

static STATE: Mutex<Stdout> = Mutex::new(Stdout::Open);

fn state() -> std::sync::MutexGuard<'static, Stdout> {
    STATE.lock().unwrap_or_else(|e| e.into_inner())
}

fn record(error: std::io::Error, state: &mut Stdout) {
    *state = if error.kind() == std::io::ErrorKind::BrokenPipe {
        Stdout::Closed
    } else {
        Stdout::Failed(error.to_string())
    };
}

/// Writes to stdout unless an earlier write failed; never panics.
pub fn write_fmt(args: std::fmt::Arguments<'_>) {
    let mut state = state();
    if *state != Stdout::Open {
        return;
    }
    let mut out = std::io::stdout().lock();
    if let Err(e) = out.write_fmt(args) {
        record(e, &mut state);
    }
}

/// Prints `error: {message}` and a newline to stderr in one write. Under mpirun the ranks
/// share one stream, and `eprintln!` writes a formatted line piece by piece, so two ranks'
/// messages could come out interleaved mid-sentence; one write of a line shorter than the
/// pipe's atomic size stays whole.
///
/// An error quotes what it refuses (a case key, a commit, a line of someone else's file):
/// its control characters are shown escaped, so that none of them acts on the terminal; the
/// message's own line breaks are kept.
pub fn print_error(message: impl std::fmt::Display) {
    let message = message.to_string();
    let shown = nbody_engine::output::neutral::control::visible_lines(&message);
    let line = format!("error: {shown}\n");
    let _ = std::io::stderr().lock().write_all(line.as_bytes());
}

/// Flushes stdout and turns a failed write into an error for the exit code: `Ok` when all was
/// written or the reader closed the pipe.
pub fn finish() -> Result<(), String> {
    let mut state = state();
    if *state == Stdout::Open
        && let Err(e) = std::io::stdout().lock().flush()
    {
        record(e, &mut state);
    }
    match &*state {
        Stdout::Failed(why) => Err(format!(
            "cannot write to standard output: {why}; the output is incomplete (files the \
             command wrote are whole)"
        )),
        _ => Ok(()),
    }
}

/// `println!` through [`write_fmt`].
#[macro_export]
macro_rules! outln {
    () => {
        $crate::console::write_fmt(format_args!("\n"))
    };
    ($($arg:tt)*) => {
        $crate::console::write_fmt(format_args!("{}\n", format_args!($($arg)*)))
    };
}

/// `print!` through [`write_fmt`].
#[macro_export]
macro_rules! out {
    ($($arg:tt)*) => {
        $crate::console::write_fmt(format_args!($($arg)*))
    };
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_closed_pipe_is_quiet_and_other_failures_are_kept() {
        let mut s = Stdout::Open;
        record(std::io::Error::from(std::io::ErrorKind::BrokenPipe), &mut s);
        assert_eq!(s, Stdout::Closed);
        let mut s = Stdout::Open;
        record(std::io::Error::other("No space left on device"), &mut s);
        assert_eq!(s, Stdout::Failed("No space left on device".into()));
    }
}
