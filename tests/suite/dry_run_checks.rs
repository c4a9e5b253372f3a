//! `sweep --dry-run` checks what the sweep checks before its first case, and refuses the same
//! way (exit 2, the path or program named, nothing written): a program that cannot start, an
//! `initial` file that is missing, empty, a directory or a device, and an n it does not have.

use super::{bin, refused};
use std::path::Path;

fn dry_run(dir: &Path, config: &str) -> std::process::Output {
    std::fs::write(dir.join("c.toml"), config).unwrap();
    bin()
        .current_dir(dir)
        .args(["sweep", "--config", "c.toml", "--dry-run", "--out", "out"])
        .output()
        .unwrap()
}

#[test]
fn a_missing_program_is_refused_before_the_plan() {
    let dir = tempfile::tempdir().unwrap();
    let config = r#"
name = "c"
study = "cartesian"
scenarios = ["lj-box"]
n = [100]
[[external]]
name = "mine"
command = ["{config_dir}/not-built-yet", "{n}"]
steps = 10
time = "wall"
"#;
    let o = dry_run(dir.path(), config);
    refused(&o, "program");
    refused(&o, "not-built-yet");
    refused(&o, "not found");
    assert!(!dir.path().join("out").exists());
}

#[test]
fn an_initial_file_that_cannot_start_the_sweep_is_refused_by_the_dry_run() {
    let dir = tempfile::tempdir().unwrap();
    let export = bin()
        .current_dir(dir.path())
        .args([
            "export",
            "--format",
            "text",
            "--out",
            "bodies.txt",
            "--scenario",
            "galaxy",
        ])
        .args(["-n", "64"])
        .output()
        .unwrap();
    assert!(export.status.success());
    let config = |file: &str, n: usize| {
        format!(
            "name = \"c\"\nstudy = \"cartesian\"\nscenarios = [\"galaxy\"]\nkernels = [\"naive\"]\n\
             n = [{n}]\ninitial = \"{file}\"\n"
        )
    };
    // The file as it is: the plan, exit 0.
    let o = dry_run(dir.path(), &config("bodies.txt", 64));
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    // An n the file does not have.
    refused(&dry_run(dir.path(), &config("bodies.txt", 100)), "64");
    // Missing, empty, a directory, a device.
    refused(
        &dry_run(dir.path(), &config("missing.txt", 64)),
        "missing.txt",
    );
    std::fs::write(dir.path().join("empty.txt"), "").unwrap();
    refused(&dry_run(dir.path(), &config("empty.txt", 64)), "empty.txt");
    std::fs::create_dir(dir.path().join("folder")).unwrap();
    refused(&dry_run(dir.path(), &config("folder", 64)), "folder");
    std::os::unix::fs::symlink("/dev/zero", dir.path().join("zero.txt")).unwrap();
    refused(&dry_run(dir.path(), &config("zero.txt", 64)), "zero.txt");
    assert!(!dir.path().join("out").exists());
}
