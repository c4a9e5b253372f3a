//! The commands a message suggests: a path in them is written so that the command works when
//! pasted into a shell as it is printed, whatever the path holds.

use std::path::Path;

/// `path` as one shell word that `nbody-bench` reads back as the same path: a relative path
/// that starts with '-' (which the command line would take for an option) gets `./` before
/// it, and a path with characters a shell treats specially is single-quoted.
pub fn arg(path: &Path) -> String {
    let text = path.to_string_lossy();
    let text = if text.starts_with('-') {
        format!("./{text}")
    } else {
        text.into_owned()
    };
    let plain = !text.is_empty()
        && text
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || "-_./=:,+@%".contains(c));
    if plain {
        text
    } else {
        format!("'{}'", text.replace('\'', "'\\''"))
    }
}

#[cfg(test)]
mod tests {
    use super::arg;
    use std::path::Path;

    #[test]
    fn a_path_is_one_word_that_is_no_option() {
        assert_eq!(arg(Path::new("configs/quick.toml")), "configs/quick.toml");
        assert_eq!(arg(Path::new("-x.toml")), "./-x.toml");
        assert_eq!(arg(Path::new("my runs/a.toml")), "'my runs/a.toml'");
        assert_eq!(arg(Path::new("it's.toml")), "'it'\\''s.toml'");
        assert_eq!(arg(Path::new("$HOME")), "'$HOME'");
    }
}
