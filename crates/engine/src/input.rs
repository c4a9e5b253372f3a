//! Reading the files a user names as inputs (configs, results, CSV tables, bench files), with
//! limits: a device such as `/dev/zero` or a pipe that never ends would otherwise be read until
//! memory runs out.

use std::io::Read;
use std::path::Path;

/// The largest input read: far above any results file or table the tool writes (a long sweep's
/// results are a few MB).
pub(crate) const MAX_INPUT_BYTES: u64 = 1 << 30;

/// How long a pipe may stay silent before reading it is given up, unless
/// [`PIPE_WAIT_ENV`] says otherwise: a named pipe nobody writes to would block forever.
pub(crate) const PIPE_WAIT_S: f64 = 60.0;
/// The environment variable that sets that wait, in seconds.
pub const PIPE_WAIT_ENV: &str = "NBODY_BENCH_PIPE_WAIT_S";

/// Whether `path` names something [`read_text`] reads: a regular file or a pipe (a named pipe,
/// or `/dev/fd/N` from a shell's process substitution `<(...)`). Commands that look an input
/// up (a path, else a name) ask this rather than "is it a file", which a pipe is not.
pub fn is_readable(path: &Path) -> bool {
    use std::os::unix::fs::FileTypeExt;
    std::fs::metadata(path).is_ok_and(|m| m.is_file() || m.file_type().is_fifo())
}

/// Whether `path` is a pipe: readable once, with no directory of its own.
pub fn is_pipe(path: &Path) -> bool {
    use std::os::unix::fs::FileTypeExt;
    std::fs::metadata(path).is_ok_and(|m| m.file_type().is_fifo())
}

/// The text of `path`: a regular file, or a pipe (process substitution, a named pipe) that
/// ends within [`MAX_INPUT_BYTES`] and never stays silent for longer than the pipe wait.
/// Devices are refused.
pub fn read_text(path: &Path) -> std::io::Result<String> {
    utf8(read(path, Pipes::Read)?)
}

/// The bytes of `path`, read as [`read_text`] reads them, for readers that take a file apart
/// before decoding it (a JSON Lines file, where a line that is not UTF-8 costs that line).
pub fn read_bytes(path: &Path) -> std::io::Result<Vec<u8>> {
    read(path, Pipes::Read)
}

/// The text of `path`, a regular file of at most [`MAX_INPUT_BYTES`]: for the files a
/// command finds by name or next to others (a history file in its folder, REPORT.md beside
/// its figures), which a pipe cannot stand for. Pipes and devices are refused without
/// waiting.
pub fn read_file_text(path: &Path) -> std::io::Result<String> {
    utf8(read(path, Pipes::Refused)?)
}

/// The bytes of `path`, read as [`read_file_text`] reads them (a regular file only).
pub fn read_file_bytes(path: &Path) -> std::io::Result<Vec<u8>> {
    read(path, Pipes::Refused)
}

fn utf8(bytes: Vec<u8>) -> std::io::Result<String> {
    String::from_utf8(bytes).map_err(|_| {
        std::io::Error::new(
            std::io::ErrorKind::InvalidData,
            "stream did not contain valid UTF-8",
        )
    })
}

/// Whether a reader takes a pipe.
#[derive(Clone, Copy, PartialEq)]
enum Pipes {
    Read,
    Refused,
}

fn read(path: &Path, pipes: Pipes) -> std::io::Result<Vec<u8>> {
    use std::os::unix::fs::FileTypeExt;
    let invalid = |m: String| std::io::Error::new(std::io::ErrorKind::InvalidInput, m);
    let kind = std::fs::metadata(path)?.file_type();
    if kind.is_char_device() || kind.is_block_device() || kind.is_socket() {
        return Err(invalid(
            "is a device or socket, not a file: name a file".to_string(),
        ));
    }
    if kind.is_dir() {
        return Err(invalid("is a directory: name a file".to_string()));
    }
    if kind.is_fifo() && pipes == Pipes::Refused {
        return Err(invalid(
            "is a pipe, not a file: this input is read from a regular file".to_string(),
        ));
    }
    let mut bytes = Vec::new();
    if kind.is_fifo() {
        read_pipe(path, pipe_wait_s()?, &mut bytes)?;
    } else {
        std::fs::File::open(path)?
            .take(MAX_INPUT_BYTES + 1)
            .read_to_end(&mut bytes)?;
    }
    if bytes.len() as u64 > MAX_INPUT_BYTES {
        return Err(invalid(format!(
            "is larger than {} GiB, more than any input this tool reads",
            MAX_INPUT_BYTES >> 30
        )));
    }
    Ok(bytes)
}

/// The pipe wait: [`PIPE_WAIT_ENV`] if set (a number of seconds > 0, at most a day), else
/// [`PIPE_WAIT_S`].
fn pipe_wait_s() -> std::io::Result<f64> {
    let Some(v) = std::env::var_os(PIPE_WAIT_ENV) else {
        return Ok(PIPE_WAIT_S);
    };
    v.to_str()
        .and_then(|v| v.trim().parse::<f64>().ok())
        .filter(|s| s.is_finite() && *s > 0.0 && *s <= 86_400.0)
        .ok_or_else(|| {
            std::io::Error::new(
                std::io::ErrorKind::InvalidInput,
                format!(
                    "{PIPE_WAIT_ENV}={} must be a number of seconds > 0 and at most 86400",
                    v.to_string_lossy()
                ),
            )
        })
}

/// Reads a pipe to its end (at most one byte past [`MAX_INPUT_BYTES`]). It is opened without
/// blocking (opening a named pipe waits for a writer, possibly forever) and every wait for
/// data is bounded by `wait_s`.
fn read_pipe(path: &Path, wait_s: f64, bytes: &mut Vec<u8>) -> std::io::Result<()> {
    use std::os::fd::AsRawFd;
    use std::os::unix::fs::OpenOptionsExt;
    let mut file = std::fs::OpenOptions::new()
        .read(true)
        .custom_flags(libc::O_NONBLOCK)
        .open(path)?;
    let wait_ms = (wait_s * 1e3).ceil() as i32;
    let mut chunk = vec![0u8; 1 << 16];
    let mut wrote = false;
    loop {
        let mut poll = libc::pollfd {
            fd: file.as_raw_fd(),
            events: libc::POLLIN,
            revents: 0,
        };
        // SAFETY: one valid pollfd for an open descriptor, for the duration of the call. On
        // Linux a named pipe that has never had a writer reports nothing (not a hang-up), so
        // this waits for the first writer too.
        let ready = unsafe { libc::poll(&mut poll, 1, wait_ms) };
        if ready < 0 {
            let e = std::io::Error::last_os_error();
            if e.kind() == std::io::ErrorKind::Interrupted {
                continue;
            }
            return Err(e);
        }
        if ready == 0 {
            let what = if wrote {
                "the program writing to this pipe wrote nothing more"
            } else {
                "no program wrote to this pipe"
            };
            return Err(std::io::Error::new(
                std::io::ErrorKind::TimedOut,
                format!("{what} within {wait_s} s ({PIPE_WAIT_ENV} sets the wait)"),
            ));
        }
        match file.read(&mut chunk) {
            Ok(0) => return Ok(()),
            Ok(n) => {
                wrote = true;
                bytes.extend_from_slice(&chunk[..n]);
                if bytes.len() as u64 > MAX_INPUT_BYTES {
                    return Ok(());
                }
            }
            Err(e)
                if matches!(
                    e.kind(),
                    std::io::ErrorKind::WouldBlock | std::io::ErrorKind::Interrupted
                ) => {}
            Err(e) => return Err(e),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn devices_are_refused_and_files_read() {
        let e = read_text(Path::new("/dev/zero")).unwrap_err();
        assert_eq!(e.kind(), std::io::ErrorKind::InvalidInput);
        assert!(e.to_string().contains("device"), "{e}");
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("a.csv");
        std::fs::write(&p, "p,time\n").unwrap();
        assert_eq!(read_text(&p).unwrap(), "p,time\n");
        assert!(read_text(&dir.path().join("missing")).is_err());
        assert!(is_readable(&p) && !is_pipe(&p) && !is_readable(dir.path()));
        assert_eq!(read_file_text(&p).unwrap(), "p,time\n");
        let e = read_file_text(Path::new("/dev/zero")).unwrap_err();
        assert!(e.to_string().contains("device"), "{e}");
    }

    #[test]
    fn a_pipe_is_refused_where_a_file_is_read_without_waiting() {
        let dir = tempfile::tempdir().unwrap();
        let p = fifo(dir.path());
        let e = read_file_text(&p).unwrap_err();
        assert_eq!(e.kind(), std::io::ErrorKind::InvalidInput);
        assert!(e.to_string().contains("is a pipe"), "{e}");
    }

    fn fifo(dir: &Path) -> std::path::PathBuf {
        let p = dir.join("fifo");
        let c = std::ffi::CString::new(p.to_str().unwrap()).unwrap();
        // SAFETY: a valid NUL-terminated path.
        assert_eq!(unsafe { libc::mkfifo(c.as_ptr(), 0o600) }, 0);
        p
    }

    #[test]
    fn pipes_are_read_and_a_silent_one_is_given_up() {
        use std::io::Write;
        let dir = tempfile::tempdir().unwrap();
        let p = fifo(dir.path());
        assert!(is_readable(&p) && is_pipe(&p));
        let writer = {
            let p = p.clone();
            std::thread::spawn(move || {
                let mut f = std::fs::OpenOptions::new().write(true).open(p).unwrap();
                f.write_all(b"p,time\n").unwrap();
                std::thread::sleep(std::time::Duration::from_millis(50));
                f.write_all(b"1,2\n").unwrap();
            })
        };
        let mut text = Vec::new();
        read_pipe(&p, 30.0, &mut text).unwrap();
        writer.join().unwrap();
        assert_eq!(text, b"p,time\n1,2\n");
        // Nobody writes: an error after the wait, not a hang.
        let e = read_pipe(&p, 0.2, &mut Vec::new()).unwrap_err();
        assert_eq!(e.kind(), std::io::ErrorKind::TimedOut);
        assert!(e.to_string().contains("no program wrote"), "{e}");
    }
}
