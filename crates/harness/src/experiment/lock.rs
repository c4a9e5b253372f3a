//! One writer per results file: a sweep holds an advisory lock (`flock`) on `.<name>.lock`
//! beside its results file from before it reads the file until it ends, so that a second sweep
//! or resume of the same file is refused instead of both saving and one losing the other's
//! rounds. The results file itself cannot carry the lock: every save renames a new file over
//! it. The lock goes with the process, so a sweep killed with -9 leaves no stale lock, only an
//! unlocked file that the next sweep takes over.

use std::fs::{self, File, OpenOptions};
use std::io::{Read, Write};
use std::os::unix::fs::MetadataExt;
use std::os::unix::io::AsRawFd;
use std::path::{Path, PathBuf};
use thiserror::Error;

/// Why a sweep could not take the writer lock of its results file.
#[derive(Debug, Error)]
pub enum LockError {
    /// Another live process (a second sweep or resume) holds the lock.
    #[error(
        "{results} is being written by another sweep ({holder}); wait for it to end or stop it, \
         or write elsewhere with --out"
    )]
    Held {
        /// The results file both want to write.
        results: PathBuf,
        /// Who holds it, as the holder wrote into the lock file: `pid P on HOST, since TIME`.
        holder: String,
    },
    /// Opening, locking or writing the lock file failed.
    #[error("cannot lock {path}: {source}")]
    Io {
        /// The lock file, `.<name>.lock` beside the results file.
        path: PathBuf,
        /// The system's error.
        source: std::io::Error,
    },
}

/// The lock on one results file, released (and its file removed) when dropped.
#[derive(Debug)]
pub(crate) struct WriterLock {
    path: PathBuf,
    file: File,
}

/// `dir/.results.json.lock` for `dir/results.json`.
pub(crate) fn lock_path(results: &Path) -> PathBuf {
    let name = results
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    results.with_file_name(format!(".{name}.lock"))
}

impl WriterLock {
    /// Takes the lock of `results` (whose directory must exist), or says who holds it.
    pub(crate) fn acquire(results: &Path) -> Result<WriterLock, LockError> {
        let path = lock_path(results);
        let io = |source| LockError::Io {
            path: path.clone(),
            source,
        };
        loop {
            let mut file = OpenOptions::new()
                .read(true)
                .write(true)
                .create(true)
                .truncate(false)
                .open(&path)
                .map_err(io)?;
            // SAFETY: flock(2) on a descriptor this function owns.
            if unsafe { libc::flock(file.as_raw_fd(), libc::LOCK_EX | libc::LOCK_NB) } != 0 {
                let e = std::io::Error::last_os_error();
                if e.raw_os_error() != Some(libc::EWOULDBLOCK) {
                    return Err(io(e));
                }
                let mut holder = String::new();
                let _ = file.read_to_string(&mut holder);
                let holder = holder.trim();
                return Err(LockError::Held {
                    results: results.to_path_buf(),
                    holder: if holder.is_empty() {
                        "a process that has not said who it is yet".into()
                    } else {
                        holder.to_string()
                    },
                });
            }
            // The holder before us may have removed the file between our open and our lock:
            // then we hold a lock nobody else can see, and must lock the file now at the path.
            let same = match (fs::metadata(&path), file.metadata()) {
                (Ok(a), Ok(b)) => a.ino() == b.ino() && a.dev() == b.dev(),
                _ => false,
            };
            if !same {
                continue;
            }
            file.set_len(0).map_err(io)?;
            let _ = write!(
                file,
                "pid {} on {}, since {}",
                std::process::id(),
                nbody_engine::output::provenance::host_name().unwrap_or_else(|| "this host".into()),
                nbody_engine::output::provenance::utc_now()
            );
            return Ok(WriterLock { path, file });
        }
    }
}

impl Drop for WriterLock {
    fn drop(&mut self) {
        // Removed while still locked, so that nobody locks the old file after we let go.
        let _ = fs::remove_file(&self.path);
        // SAFETY: flock(2) on the descriptor this lock owns.
        unsafe {
            libc::flock(self.file.as_raw_fd(), libc::LOCK_UN);
        }
    }
}

/// Keeps `path` under a new `.bak` name beside it, `<name>.<stamp>.bak` (`-2`, `-3`, ... when
/// taken): a backup never replaces another. Returns the backup's path.
pub(crate) fn back_up(path: &Path, stamp: &str) -> std::io::Result<PathBuf> {
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    for attempt in 1u32.. {
        let suffix = if attempt == 1 {
            String::new()
        } else {
            format!("-{attempt}")
        };
        let backup = path.with_file_name(format!("{name}.{stamp}{suffix}.bak"));
        // A hard link is created only where no file is: the check and the creation are one
        // step, unlike an exists-then-rename.
        match fs::hard_link(path, &backup) {
            Ok(()) => {
                fs::remove_file(path)?;
                return Ok(backup);
            }
            Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => continue,
            Err(e) => return Err(e),
        }
    }
    unreachable!("a free backup name is found")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_second_writer_is_refused_until_the_first_ends() {
        let dir = tempfile::tempdir().unwrap();
        let results = dir.path().join("results.json");
        let first = WriterLock::acquire(&results).unwrap();
        let e = WriterLock::acquire(&results).unwrap_err().to_string();
        assert!(e.contains("being written by another sweep"), "{e}");
        assert!(e.contains(&format!("pid {}", std::process::id())), "{e}");
        drop(first);
        assert!(!lock_path(&results).exists(), "the lock file is removed");
        let again = WriterLock::acquire(&results).unwrap();
        drop(again);
    }

    #[test]
    fn backups_never_replace_each_other() {
        let dir = tempfile::tempdir().unwrap();
        let results = dir.path().join("results.json");
        let mut backups = Vec::new();
        for content in ["one", "two", "three"] {
            fs::write(&results, content).unwrap();
            backups.push(back_up(&results, "20261203T101010Z").unwrap());
            assert!(!results.exists());
        }
        let kept: Vec<String> = backups
            .iter()
            .map(|b| fs::read_to_string(b).unwrap())
            .collect();
        assert_eq!(kept, ["one", "two", "three"]);
        assert!(backups[1].ends_with("results.json.20261203T101010Z-2.bak"));
    }
}
