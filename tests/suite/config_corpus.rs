//! Every config in tests/configs/good and configs/ parses; every config in tests/configs/bad
//! fails with the message on its first line (`#^ expected text`).

use nbody_records::config::SweepConfig;
use std::path::Path;

fn tomls(dir: &str) -> Vec<std::path::PathBuf> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join(dir);
    let mut files: Vec<_> = std::fs::read_dir(&dir)
        .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "toml"))
        .collect();
    files.sort();
    files
}

#[test]
fn good_and_shipped_configs_parse() {
    let files: Vec<_> = tomls("tests/configs/good")
        .into_iter()
        .chain(tomls("configs"))
        .collect();
    assert!(files.len() >= 10);
    for f in files {
        if let Err(e) = SweepConfig::load(&f) {
            panic!("{}: {e}", f.display());
        }
    }
}

#[test]
fn bad_configs_fail_with_their_message() {
    let files = tomls("tests/configs/bad");
    assert!(files.len() >= 8);
    for f in files {
        let text = std::fs::read_to_string(&f).unwrap();
        let expected = text
            .lines()
            .next()
            .and_then(|l| l.strip_prefix("#^ "))
            .expect("first line is `#^ message`");
        match SweepConfig::load(&f) {
            Ok(_) => panic!("{} parsed but should fail with `{expected}`", f.display()),
            Err(e) => {
                let msg = e.to_string();
                assert!(
                    msg.contains(expected),
                    "{}: expected `{expected}` in `{msg}`",
                    f.display()
                );
                assert!(
                    msg.contains(&f.display().to_string()),
                    "{}: message must name the file: {msg}",
                    f.display()
                );
            }
        }
    }
}
