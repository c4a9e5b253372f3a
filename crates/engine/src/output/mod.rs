//! Files the engine writes: trajectories (NBView), state dumps, and the atomic-write helper
//! every output goes through so that a failed run never leaves a partial file behind.

mod dir;
pub mod dump;
pub mod nbview;
pub mod neutral;
pub mod provenance;
mod temporary_dir;

pub use dir::{create_dir_all, not_a_directory};
pub use temporary_dir::TemporaryDir;

use std::fs::{self, File};
use std::io::{self, BufWriter, Write};
use std::path::{Path, PathBuf};
use thiserror::Error;

/// A file that could not be written, with the I/O error.
#[derive(Debug, Error)]
#[error("cannot write {path}: {source}")]
pub struct WriteError {
    /// The file.
    pub path: PathBuf,
    /// The I/O error.
    #[source]
    pub source: io::Error,
}

/// Why an output path cannot be written; found before any work starts.
#[derive(Debug, Error)]
pub enum OutputError {
    /// The path names a directory.
    #[error("{flag} {path}: is a directory; name a file")]
    Directory {
        /// The option that named the path, as typed.
        flag: String,
        /// The path as given.
        path: PathBuf,
    },
    /// The path names a device, pipe or socket, which the atomic rename would replace.
    #[error(
        "{flag} {path}: is not a regular file (a device, pipe or socket); results are written \
         under a temporary name and renamed into place, which would replace it: name a file"
    )]
    Special {
        /// The option that named the path, as typed.
        flag: String,
        /// The path as given.
        path: PathBuf,
    },
    /// The path's directory does not exist.
    #[error("{flag} {path}: its directory {dir} does not exist; create it first")]
    NoDirectory {
        /// The option that named the path, as typed.
        flag: String,
        /// The path as given.
        path: PathBuf,
        /// The missing directory.
        dir: PathBuf,
    },
    /// A part of the path's directory is a file (or another thing that is no directory).
    #[error("{flag} {path}: {part} is {what}, where a directory is expected")]
    NotADirectory {
        /// The option that named the path, as typed.
        flag: String,
        /// The path as given.
        path: PathBuf,
        /// The part of its directory that exists and is no directory.
        part: PathBuf,
        /// "a file", or "not a directory" for anything else.
        what: &'static str,
    },
    /// The path is one of the command's inputs (or the same file by another path).
    #[error("{flag} {path}: is also an input of this command ({input}); it would be overwritten")]
    IsInput {
        /// The option that named the path, as typed.
        flag: String,
        /// The path as given.
        path: PathBuf,
        /// The option that named the input it would overwrite.
        input: String,
    },
    /// The path is a symbolic link whose target is missing or that loops.
    #[error(
        "{flag} {path}: is a symbolic link that leads nowhere (its target is missing, or the \
         links loop); writing it would replace the link: fix or remove the link, or name a file"
    )]
    BrokenLink {
        /// The option that named the path, as typed.
        flag: String,
        /// The path as given.
        path: PathBuf,
    },
    /// Two outputs of the command name the same file.
    #[error(
        "{flag} and {other} both name {path}; one output would be lost: give each its own file"
    )]
    Twice {
        /// The option that named the path, as typed.
        flag: String,
        /// The earlier output's option that names the same file.
        other: String,
        /// The path as given.
        path: PathBuf,
    },
}

/// The real location of a path: a symbolic link is written through, to the file it points at
/// (so a link stays a link); a path that does not exist yet is its absolute form.
fn real(path: &Path) -> PathBuf {
    if let Ok(p) = fs::canonicalize(path) {
        return p;
    }
    let parent = path.parent().filter(|p| !p.as_os_str().is_empty());
    let dir = parent.map_or_else(|| fs::canonicalize("."), fs::canonicalize);
    match (dir, path.file_name()) {
        (Ok(dir), Some(name)) => dir.join(name),
        _ => path.to_path_buf(),
    }
}

/// The inputs of this command (flag, real path): no output may replace one, whether its path
/// was typed or derived (a figure's name, a file inside `--out`). Every file is written
/// through [`AtomicFile::create`], which checks it against these.
static INPUTS: std::sync::Mutex<Vec<(String, PathBuf)>> = std::sync::Mutex::new(Vec::new());

fn inputs() -> std::sync::MutexGuard<'static, Vec<(String, PathBuf)>> {
    INPUTS.lock().unwrap_or_else(|e| e.into_inner())
}

/// Declares `inputs` (flag, path) as inputs of this command for every later output check.
pub fn protect_inputs(list: &[(&str, &Path)]) {
    let mut known = inputs();
    for &(flag, path) in list {
        let entry = (flag.to_string(), real(path));
        if !known.contains(&entry) {
            known.push(entry);
        }
    }
}

/// Checks every output of a command before it starts working: each names a regular file (or
/// one to create) in an existing directory, none is one of the command's inputs (these and
/// every one declared before, see [`protect_inputs`]), no two are the same. `outputs` and
/// `inputs` are (flag, path) pairs, the flag as the user typed it.
pub fn check_outputs(
    outputs: &[(&str, &Path)],
    inputs_now: &[(&str, &Path)],
) -> Result<(), OutputError> {
    protect_inputs(inputs_now);
    let protected = inputs().clone();
    for (i, &(flag, path)) in outputs.iter().enumerate() {
        let bad = |path: &Path| (flag.to_string(), path.to_path_buf());
        let is_link = fs::symlink_metadata(path).is_ok_and(|m| m.file_type().is_symlink());
        if is_link && fs::metadata(path).is_err() {
            let (flag, path) = bad(path);
            return Err(OutputError::BrokenLink { flag, path });
        }
        let target = real(path);
        if let Ok(meta) = fs::metadata(&target) {
            let (flag, path) = bad(path);
            if meta.is_dir() {
                return Err(OutputError::Directory { flag, path });
            }
            if !meta.is_file() {
                return Err(OutputError::Special { flag, path });
            }
        } else if let Some(dir) = target.parent().filter(|d| !d.is_dir()) {
            if let Some(part) = not_a_directory(dir) {
                let (flag, path) = bad(path);
                return Err(OutputError::NotADirectory {
                    flag,
                    path,
                    what: if part.is_file() {
                        "a file"
                    } else {
                        "not a directory"
                    },
                    part: part.to_path_buf(),
                });
            }
            let (flag, path) = bad(path);
            return Err(OutputError::NoDirectory {
                flag,
                path,
                dir: dir.to_path_buf(),
            });
        }
        if let Some((input, _)) = protected.iter().find(|(_, p)| *p == target) {
            let (flag, path) = bad(path);
            return Err(OutputError::IsInput {
                flag,
                path,
                input: input.clone(),
            });
        }
        if let Some(&(other, _)) = outputs[..i].iter().find(|(_, p)| real(p) == target) {
            let (flag, path) = bad(path);
            return Err(OutputError::Twice {
                flag,
                other: other.to_string(),
                path,
            });
        }
    }
    Ok(())
}

/// Temporary files being written now (and private temporary directories), removed by [`remove_temporaries`] when the process is
/// interrupted (SIGINT, SIGTERM), so that an interrupted run leaves nothing behind.
static TEMPORARIES: std::sync::Mutex<Vec<PathBuf>> = std::sync::Mutex::new(Vec::new());

fn temporaries() -> std::sync::MutexGuard<'static, Vec<PathBuf>> {
    TEMPORARIES.lock().unwrap_or_else(|e| e.into_inner())
}

/// Removes every temporary file still open and ends the process with `code`; for the
/// interrupt handler. The registry stays locked until the end, so that no new temporary can
/// be created between the clean-up and the exit.
pub fn remove_temporaries_and_exit(code: i32) -> ! {
    let mut open = temporaries();
    for tmp in open.drain(..) {
        // A private directory ([`TemporaryDir`]) goes with its contents.
        let _ = fs::remove_file(&tmp).or_else(|_| fs::remove_dir_all(&tmp));
    }
    std::process::exit(code)
}

/// A file written under a temporary name and renamed into place by [`AtomicFile::commit`];
/// dropped without commit, or if the commit fails, the temporary file is removed and `path`
/// is untouched. A symbolic link is written through: the file it points at is replaced.
///
/// The temporary beside the target has an unpredictable name and is created exclusively
/// (`O_CREAT | O_EXCL | O_NOFOLLOW`): in a directory others can write to, nobody can plant a
/// link under the name a write is about to use and have the write land in another file.
pub(crate) struct AtomicFile {
    path: PathBuf,
    tmp: PathBuf,
    out: Option<BufWriter<File>>,
}

impl AtomicFile {
    pub fn create(path: &Path) -> Result<Self, WriteError> {
        let err = |source| WriteError {
            path: path.to_path_buf(),
            source,
        };
        if let Err(e) = check_outputs(&[("output", path)], &[]) {
            return Err(err(io::Error::other(e.to_string())));
        }
        let target = real(path);
        let name = target
            .file_name()
            .ok_or_else(|| err(io::Error::other("not a file name")))?;
        let (tmp, file) = create_temporary(&target, name).map_err(err)?;
        Ok(AtomicFile {
            path: target,
            tmp,
            out: Some(BufWriter::new(file)),
        })
    }

    pub fn writer(&mut self) -> &mut BufWriter<File> {
        self.out.as_mut().expect("writer present until commit")
    }

    /// Flushes, syncs and renames the file into place.
    pub fn commit(mut self) -> Result<(), WriteError> {
        let err = |source| WriteError {
            path: self.path.clone(),
            source,
        };
        let out = self.out.take().expect("writer present until commit");
        let result = out
            .into_inner()
            .map_err(|e| e.into_error())
            .and_then(|file| file.sync_all())
            .and_then(|()| fs::rename(&self.tmp, &self.path));
        if result.is_err() {
            let _ = fs::remove_file(&self.tmp);
        }
        temporaries().retain(|t| *t != self.tmp);
        result.map_err(err)
    }

    /// Maps an I/O error from writing to this file into a [`WriteError`] naming it.
    pub fn error(&self, source: io::Error) -> WriteError {
        WriteError {
            path: self.path.clone(),
            source,
        }
    }
}

impl Drop for AtomicFile {
    fn drop(&mut self) {
        if self.out.is_some() {
            let _ = fs::remove_file(&self.tmp);
            temporaries().retain(|t| *t != self.tmp);
        }
    }
}

/// Creates `.<name>.<random>.tmp` beside `target`, never opening an existing file or link, and
/// registers it for removal on an interrupt. Mode 0666 less the umask, as `File::create`.
fn create_temporary(target: &Path, name: &std::ffi::OsStr) -> io::Result<(PathBuf, File)> {
    use std::os::unix::fs::OpenOptionsExt;
    let mut last = None;
    for _ in 0..16 {
        let mut tmp_name = std::ffi::OsString::from(".");
        tmp_name.push(name);
        tmp_name.push(format!(".{:016x}.tmp", rand::random::<u64>()));
        let tmp = target.with_file_name(tmp_name);
        let mut registry = temporaries();
        let opened = fs::OpenOptions::new()
            .write(true)
            .create_new(true)
            .mode(0o666)
            .custom_flags(libc::O_NOFOLLOW)
            .open(&tmp);
        match opened {
            Ok(file) => {
                registry.push(tmp.clone());
                return Ok((tmp, file));
            }
            // Someone's file or link under that name: another name, never that one.
            Err(e) if e.kind() == io::ErrorKind::AlreadyExists => last = Some(e),
            Err(e) => return Err(e),
        }
    }
    Err(last.unwrap_or_else(|| io::Error::other("no free temporary name")))
}

/// Checks an output whose name is derived from the path the user typed (`--dump out` writing
/// `out.lj-box`, ...): the typed path must itself be a possible output (not a device, pipe,
/// directory or broken link, which it would otherwise escape by a suffix), and so must each
/// derived path.
pub fn check_derived(flag: &str, typed: &Path, derived: &[PathBuf]) -> Result<(), OutputError> {
    check_outputs(&[(flag, typed)], &[])?;
    let outputs: Vec<(&str, &Path)> = derived.iter().map(|p| (flag, p.as_path())).collect();
    check_outputs(&outputs, &[])
}

/// Checks that `path` can be written the way [`write_atomic`] writes it, before the work that
/// makes its contents: the checks of [`check_outputs`], then an exclusive temporary created
/// beside it and removed (a directory that cannot be written to fails here, not after).
pub fn check_writable(path: &Path) -> Result<(), WriteError> {
    AtomicFile::create(path).map(drop)
}

/// Writes `contents` to `path` atomically.
pub fn write_atomic(path: &Path, contents: &[u8]) -> Result<(), WriteError> {
    let mut f = AtomicFile::create(path)?;
    f.writer().write_all(contents).map_err(|e| WriteError {
        path: path.to_path_buf(),
        source: e,
    })?;
    f.commit()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn uncommitted_file_leaves_nothing() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("out.json");
        fs::write(&path, "old").unwrap();
        {
            let mut f = AtomicFile::create(&path).unwrap();
            f.writer().write_all(b"partial").unwrap();
        }
        assert_eq!(fs::read_to_string(&path).unwrap(), "old");
        assert_eq!(fs::read_dir(dir.path()).unwrap().count(), 1);
        write_atomic(&path, b"new").unwrap();
        assert_eq!(fs::read_to_string(&path).unwrap(), "new");
    }

    #[test]
    fn a_writable_place_is_checked_without_leaving_anything() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("result.json");
        check_writable(&path).unwrap();
        assert_eq!(fs::read_dir(dir.path()).unwrap().count(), 0);
        fs::create_dir(&path).unwrap();
        let e = check_writable(&path).unwrap_err();
        assert!(e.to_string().contains("is a directory"), "{e}");
        let e = check_writable(&dir.path().join("missing/result.json")).unwrap_err();
        assert!(e.to_string().contains("does not exist"), "{e}");
    }

    /// A link planted beside the target, under any name the old scheme would have used, is
    /// never written through: the temporary's name is random and it is created exclusively.
    #[test]
    fn a_planted_link_beside_the_target_is_not_followed() {
        let dir = tempfile::tempdir().unwrap();
        let victim = dir.path().join("victim.txt");
        fs::write(&victim, "precious").unwrap();
        let path = dir.path().join("out.json");
        let planted = dir
            .path()
            .join(format!(".out.json.{}.tmp", std::process::id()));
        std::os::unix::fs::symlink(&victim, &planted).unwrap();
        write_atomic(&path, b"new").unwrap();
        assert_eq!(fs::read_to_string(&victim).unwrap(), "precious");
        assert_eq!(fs::read_to_string(&path).unwrap(), "new");
        assert!(
            !fs::symlink_metadata(&path)
                .unwrap()
                .file_type()
                .is_symlink()
        );
        // And an existing name is refused by the exclusive create itself.
        let e = fs::OpenOptions::new()
            .write(true)
            .create_new(true)
            .open(&planted)
            .unwrap_err();
        assert_eq!(e.kind(), io::ErrorKind::AlreadyExists);
    }

    #[test]
    fn outputs_are_checked_before_the_work() {
        let dir = tempfile::tempdir().unwrap();
        let input = dir.path().join("in.csv");
        fs::write(&input, "x").unwrap();
        let out = dir.path().join("out.json");
        assert!(check_outputs(&[("--json", &out)], &[("--csv", &input)]).is_ok());
        let e = check_outputs(&[("--json", dir.path())], &[]).unwrap_err();
        assert!(e.to_string().contains("is a directory"), "{e}");
        let e = check_outputs(&[("--json", Path::new("/dev/full"))], &[]).unwrap_err();
        assert!(e.to_string().contains("not a regular file"), "{e}");
        let e = check_outputs(&[("--json", &input)], &[("--csv", &input)]).unwrap_err();
        assert!(e.to_string().contains("also an input"), "{e}");
        let e = check_outputs(&[("--json", &out), ("--trajectory", &out)], &[]).unwrap_err();
        assert!(
            e.to_string().contains("--trajectory and --json both name"),
            "{e}"
        );
        let e = check_outputs(&[("--json", &dir.path().join("no/such.json"))], &[]).unwrap_err();
        assert!(e.to_string().contains("does not exist"), "{e}");
    }

    #[test]
    fn a_failed_commit_leaves_no_temporary_and_links_are_written_through() {
        let dir = tempfile::tempdir().unwrap();
        // The rename fails: the target became a non-empty directory after the check.
        let path = dir.path().join("x.json");
        let mut f = AtomicFile::create(&path).unwrap();
        f.writer().write_all(b"partial").unwrap();
        fs::create_dir(&path).unwrap();
        fs::write(path.join("inside"), "x").unwrap();
        assert!(f.commit().is_err());
        let names: Vec<_> = fs::read_dir(dir.path())
            .unwrap()
            .flatten()
            .map(|e| e.file_name())
            .collect();
        assert_eq!(
            names,
            vec![std::ffi::OsString::from("x.json")],
            "no temporary left"
        );
        // A symbolic link stays a link; the file it points at gets the contents.
        let real_file = dir.path().join("real.json");
        let link = dir.path().join("link.json");
        fs::write(&real_file, "old").unwrap();
        std::os::unix::fs::symlink(&real_file, &link).unwrap();
        write_atomic(&link, b"new").unwrap();
        assert!(
            fs::symlink_metadata(&link)
                .unwrap()
                .file_type()
                .is_symlink()
        );
        assert_eq!(fs::read_to_string(&real_file).unwrap(), "new");
    }

    #[test]
    fn unwritable_path_is_an_error_naming_it() {
        let err = write_atomic(Path::new("/nonexistent-dir/x.json"), b"x").unwrap_err();
        assert!(err.to_string().contains("/nonexistent-dir/x.json"));
    }
}
