//! The directories commands make for their outputs: when one cannot be made because part of
//! its path is a file, the error says so, instead of the system's bare "File exists" or "Not a
//! directory", which name neither the part nor what was expected.

use std::fs;
use std::io;
use std::path::Path;

/// Creates `path` and its missing parents, as [`fs::create_dir_all`] does; an error caused by
/// a part of the path that is not a directory names that part.
pub fn create_dir_all(path: impl AsRef<Path>) -> io::Result<()> {
    let path = path.as_ref();
    fs::create_dir_all(path).map_err(|e| match not_a_directory(path) {
        Some(part) => io::Error::new(
            e.kind(),
            format!(
                "{} is {}, where a directory is expected",
                part.display(),
                if part.is_file() {
                    "a file"
                } else {
                    "not a directory"
                }
            ),
        ),
        None => e,
    })
}

/// The part of `path` (itself, or the nearest of its parents) that exists and is not a
/// directory: what stops a directory from being made there.
pub fn not_a_directory(path: &Path) -> Option<&Path> {
    path.ancestors()
        .filter(|a| !a.as_os_str().is_empty())
        .find(|a| fs::metadata(a).is_ok_and(|m| !m.is_dir()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_file_in_the_way_is_named() {
        let dir = tempfile::tempdir().unwrap();
        let file = dir.path().join("a-file");
        fs::write(&file, "").unwrap();
        for path in [file.clone(), file.join("sub/deeper")] {
            let e = create_dir_all(&path).unwrap_err().to_string();
            assert_eq!(
                e,
                format!(
                    "{} is a file, where a directory is expected",
                    file.display()
                )
            );
        }
        let fine = dir.path().join("new/sub");
        create_dir_all(&fine).unwrap();
        assert!(fine.is_dir());
        assert_eq!(not_a_directory(&fine), None);
    }
}
