//! After failures the harness says what happened and what works next: a resume hint only when
//! a resume would measure something (and a command that does), the failed cases in summary.md
//! with their reasons, `analyze NAME` on the newest run that has results (named), a program
//! that fails the same way stopped after its first rounds, and a dry run that tries each
//! program once. The "program" is a shell script whose behaviour a file beside it chooses.

use crate::{bin, refused, text};
use std::path::Path;

/// Fails (exit 3, "boom" on stderr) while `fail` exists beside it, else prints its time.
const PROGRAM: &str = "#!/bin/sh\n\
    if [ -e \"$(dirname \"$0\")/fail\" ]; then echo boom >&2; exit 3; fi\n\
    echo \"elapsed 2.5 ms\"\n";

fn config(kernels: &str) -> String {
    format!(
        "name = \"ext\"\nstudy = \"cartesian\"\nscenarios = [\"lj-box\"]\nn = [50, 100, 200]\n\
         kernels = [{kernels}]\n\
         [[external]]\nname = \"prog\"\ncommand = [\"{{config_dir}}/prog\", \"{{n}}\"]\n\
         steps = 10\ntime = {{ regex = 'elapsed ([0-9.]+) ms', unit = \"ms\" }}\n\
         [measure]\nwarmup_s = 0.0\nsamples = 2\nrounds = 2\nmin_sample_s = 0.001\n"
    )
}

/// A directory with the program and `ext.toml`; `fail` makes the program fail.
fn setup(kernels: &str, fail: bool) -> tempfile::TempDir {
    use std::os::unix::fs::PermissionsExt;
    let dir = tempfile::tempdir().unwrap();
    let prog = dir.path().join("prog");
    std::fs::write(&prog, PROGRAM).unwrap();
    std::fs::set_permissions(&prog, std::fs::Permissions::from_mode(0o755)).unwrap();
    std::fs::write(dir.path().join("ext.toml"), config(kernels)).unwrap();
    if fail {
        std::fs::write(dir.path().join("fail"), "").unwrap();
    }
    dir
}

fn sweep(dir: &Path, args: &[&str]) -> std::process::Output {
    bin()
        .current_dir(dir)
        .args(["sweep", "--config", "ext.toml", "--no-calibration", "--yes"])
        .args(args)
        .output()
        .unwrap()
}

/// Every `nbody-bench ...` command between backticks in the lines of `said`.
fn suggested(said: &str) -> Vec<Vec<String>> {
    said.lines()
        .flat_map(|line| line.split('`').skip(1).step_by(2))
        .filter_map(|c| c.strip_prefix("nbody-bench "))
        .map(|c| c.split_whitespace().map(str::to_string).collect())
        .collect()
}

#[test]
fn a_program_that_fails_the_same_way_is_stopped_and_the_resume_it_suggests_works() {
    let dir = setup("", true);
    let o = sweep(dir.path(), &[]);
    let said = text(&o.stderr) + &text(&o.stdout);
    assert_eq!(o.status.code(), Some(1), "{said}");
    assert!(
        said.contains("external `prog` failed the same way in its first 2 rounds")
            && said.contains("exit status: 3")
            && said.contains("other 4 round(s) are not run"),
        "{said}"
    );
    // Two rounds were run, not six.
    assert_eq!(said.matches("last line: boom").count(), 3, "{said}");
    // The hint names this run, and resuming it works once the program does.
    let hint = said
        .lines()
        .find(|l| l.contains("to finish them"))
        .unwrap_or_else(|| panic!("no resume hint in: {said}"));
    let resume = suggested(hint).pop().unwrap();
    assert!(resume.contains(&"--resume".to_string()), "{hint}");
    std::fs::remove_file(dir.path().join("fail")).unwrap();
    let o = bin()
        .current_dir(dir.path())
        .args(&resume)
        .args(["--no-calibration", "--yes"])
        .output()
        .unwrap();
    assert!(o.status.success(), "{resume:?}: {}", text(&o.stderr));
}

#[test]
fn a_run_with_nothing_left_to_measure_suggests_no_resume() {
    let dir = setup("", true);
    // Two rounds of one size: both fail, and nothing is left.
    std::fs::write(
        dir.path().join("ext.toml"),
        config("").replace("n = [50, 100, 200]", "n = [50]"),
    )
    .unwrap();
    let o = sweep(dir.path(), &[]);
    let said = text(&o.stderr) + &text(&o.stdout);
    assert_eq!(o.status.code(), Some(1), "{said}");
    assert!(said.contains("no sample succeeded"), "{said}");
    assert!(!said.contains("--resume"), "{said}");
    // Asked anyway, the answer suggests a command that works from here.
    let o = sweep(dir.path(), &["--resume"]);
    refused(&o, "no unfinished run of `ext`");
    let new = suggested(&text(&o.stderr))
        .pop()
        .unwrap_or_else(|| panic!("no suggestion in: {}", text(&o.stderr)));
    assert_eq!(
        new,
        ["sweep", "--config", "ext.toml"],
        "{}",
        text(&o.stderr)
    );
}

#[test]
fn the_summary_lists_the_failed_cases_with_their_reason() {
    let dir = setup("\"naive\"", true);
    std::fs::write(
        dir.path().join("ext.toml"),
        config("\"naive\"").replace("n = [50, 100, 200]", "n = [50]"),
    )
    .unwrap();
    let o = sweep(dir.path(), &["--out", "out"]);
    assert_eq!(o.status.code(), Some(1), "{}", text(&o.stderr));
    let summary = std::fs::read_to_string(dir.path().join("out/ext/analysis/summary.md")).unwrap();
    assert!(summary.contains("## Failed cases"), "{summary}");
    assert!(
        summary.contains("`lj-box/prog/n=50/p=1/r=1/seed=1`") && summary.contains("exit status: 3"),
        "{summary}"
    );
}

#[test]
fn analyze_by_name_takes_the_newest_run_with_results_and_says_which() {
    let dir = setup("", false);
    let one_size = config("").replace("n = [50, 100, 200]", "n = [50]");
    std::fs::write(dir.path().join("ext.toml"), &one_size).unwrap();
    let o = sweep(dir.path(), &[]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    std::fs::write(dir.path().join("fail"), "").unwrap();
    let o = sweep(dir.path(), &[]);
    assert_eq!(o.status.code(), Some(1), "{}", text(&o.stderr));
    let mut runs: Vec<_> = std::fs::read_dir(dir.path().join("results/runs/ext"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    runs.sort();
    assert_eq!(runs.len(), 2);
    let o = bin()
        .current_dir(dir.path())
        .args(["analyze", "ext"])
        .output()
        .unwrap();
    let said = text(&o.stderr);
    assert!(o.status.success(), "{said}");
    let (good, failed) = (runs[0].file_name().unwrap(), runs[1].file_name().unwrap());
    assert!(
        said.contains("the newest run with a successful case")
            && said.contains(&*good.to_string_lossy())
            && said.contains(&*failed.to_string_lossy()),
        "{said}"
    );
    assert!(runs[0].join("analysis/summary.md").is_file());
}

#[test]
fn the_dry_run_tries_each_program_once_and_estimates_it() {
    let dir = setup("", false);
    let dry = |dir: &Path| {
        bin()
            .current_dir(dir)
            .args(["sweep", "--config", "ext.toml", "--dry-run"])
            .output()
            .unwrap()
    };
    let o = dry(dir.path());
    let out = text(&o.stdout);
    assert!(o.status.success(), "{}", text(&o.stderr));
    assert!(
        out.contains("external `prog` tried once at lj-box/prog/n=50/p=1/r=1/seed=1"),
        "{out}"
    );
    let row = out
        .lines()
        .find(|l| l.starts_with("lj-box/prog/n=200/"))
        .unwrap_or_else(|| panic!("no row in {out}"));
    assert!(!row.contains("external"), "{row}");
    // A script behind an interpreter that is not there: the interpreter starts, the run fails.
    std::fs::write(
        dir.path().join("ext.toml"),
        config("").replace(
            "[\"{config_dir}/prog\", \"{n}\"]",
            "[\"sh\", \"{config_dir}/no-such-script.sh\", \"{n}\"]",
        ),
    )
    .unwrap();
    refused(&dry(dir.path()), "external `prog` tried once at");
    // Output that does not match the time pattern.
    std::fs::write(
        dir.path().join("ext.toml"),
        config("").replace("'elapsed ([0-9.]+) ms'", "'took ([0-9.]+) ms'"),
    )
    .unwrap();
    refused(&dry(dir.path()), "does not match the time regex");
    // Nothing is kept.
    assert!(!dir.path().join("results").exists());
}
