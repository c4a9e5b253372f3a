//! Private temporary directories: for files that another process writes back to this one (an
//! MPI round's result), where a predictable name in the shared temporary directory could be a
//! link planted by another user.

use std::io;
use std::path::Path;

/// A directory created exclusively, under a random name, with mode 0700, in the temporary
/// directory (`TMPDIR`); removed with its contents when dropped, and by the interrupt handler
/// ([`super::remove_temporaries_and_exit`]) if the process is stopped first.
pub struct TemporaryDir {
    dir: tempfile::TempDir,
}

impl TemporaryDir {
    /// Creates a fresh private directory whose name starts with `prefix`.
    pub fn new(prefix: &str) -> io::Result<Self> {
        let mut builder = tempfile::Builder::new();
        builder.prefix(prefix);
        #[cfg(unix)]
        {
            use std::os::unix::fs::PermissionsExt;
            builder.permissions(std::fs::Permissions::from_mode(0o700));
        }
        let dir = builder.tempdir()?;
        super::temporaries().push(dir.path().to_path_buf());
        Ok(TemporaryDir { dir })
    }

    /// Where the directory is.
    pub fn path(&self) -> &Path {
        self.dir.path()
    }
}

impl Drop for TemporaryDir {
    fn drop(&mut self) {
        // The TempDir field, dropped after this, removes the directory.
        super::temporaries().retain(|t| t != self.dir.path());
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_temporary_dir_is_private_fresh_and_removed_when_dropped() {
        let a = TemporaryDir::new("nbody-bench-test-").unwrap();
        let b = TemporaryDir::new("nbody-bench-test-").unwrap();
        assert_ne!(a.path(), b.path());
        #[cfg(unix)]
        {
            use std::os::unix::fs::PermissionsExt;
            let mode = std::fs::metadata(a.path()).unwrap().permissions().mode();
            assert_eq!(mode & 0o777, 0o700);
        }
        std::fs::write(a.path().join("f"), "x").unwrap();
        let path = a.path().to_path_buf();
        drop(a);
        assert!(!path.exists());
        assert!(b.path().is_dir());
    }
}
