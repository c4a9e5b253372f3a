//! Reading the files a user names as inputs (configs, results, CSV tables, bench files), with
//! limits: a device such as `/dev/zero` or a pipe that never ends would otherwise be read until
//! memory runs out.

use std::io::Read;
use std::path::Path;

/// The largest input read: far above any results file or table the tool writes (a long sweep's
/// results are a few MB).
pub const MAX_INPUT_BYTES: u64 = 1 << 30;

/// The text of `path`: a regular file, or a pipe (process substitution) that ends within
/// [`MAX_INPUT_BYTES`]. Devices are refused.
pub fn read_text(path: &Path) -> std::io::Result<String> {
    use std::os::unix::fs::FileTypeExt;
    let invalid = |m: String| std::io::Error::new(std::io::ErrorKind::InvalidInput, m);
    let kind = std::fs::metadata(path)?.file_type();
    if kind.is_char_device() || kind.is_block_device() || kind.is_socket() {
        return Err(invalid(
            "is a device or socket, not a file: name a file".to_string(),
        ));
    }
    let mut text = String::new();
    std::fs::File::open(path)?
        .take(MAX_INPUT_BYTES + 1)
        .read_to_string(&mut text)?;
    if text.len() as u64 > MAX_INPUT_BYTES {
        return Err(invalid(format!(
            "is larger than {} GiB, more than any input this tool reads",
            MAX_INPUT_BYTES >> 30
        )));
    }
    Ok(text)
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
    }
}
