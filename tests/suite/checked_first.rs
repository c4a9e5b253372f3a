//! Arguments and configs are checked before anything is built or measured: a count that means
//! nothing, a history destination that cannot be written, an empty list, a program name that
//! reads as an option are refused at the start, not after the work; and a round with no
//! warm-up still sizes its samples on a step that is not the cold first one.

use super::{bin, refused, text};
use std::path::Path;

const TINY: &str = "name = \"tiny\"\nstudy = \"cartesian\"\nscenarios = [\"lj-box\"]\n\
    kernels = [\"naive\"]\nn = [60]\nthreads = [1]\n[measure]\nwarmup_s = 0.0\nsamples = 2\n\
    rounds = 1\nmin_sample_s = 0.001\n";

fn sweep(dir: &Path, config: &str, args: &[&str]) -> std::process::Output {
    std::fs::write(dir.join("tiny.toml"), config).unwrap();
    bin()
        .current_dir(dir)
        .args(["sweep", "--config", "tiny.toml", "--out", "out"])
        .args(["--no-calibration", "--yes"])
        .args(args)
        .output()
        .unwrap()
}

#[test]
fn backfill_refuses_a_zero_step_and_rounds_the_gate_refuses_before_building() {
    let dir = tempfile::tempdir().unwrap();
    let backfill = |args: &[&str]| {
        bin()
            .current_dir(dir.path())
            .args(["history", "backfill", "HEAD~2..HEAD", "--runs", "runs"])
            .args(args)
            .output()
            .unwrap()
    };
    refused(&backfill(&["--every", "0"]), "--every");
    for rounds in ["0", "3", "102"] {
        let o = backfill(&["--rounds", rounds]);
        refused(&o, "--rounds");
        assert!(text(&o.stderr).contains("even"), "{}", text(&o.stderr));
    }
    // Refused before anything was built or kept.
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
}

#[test]
fn a_record_destination_that_cannot_be_written_is_refused_before_measuring() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("a-file"), "").unwrap();
    let o = sweep(dir.path(), TINY, &["--record", "/proc/no-history-here"]);
    refused(
        &o,
        "--record /proc/no-history-here: the history cannot be written",
    );
    let o = sweep(dir.path(), TINY, &["--record", "a-file"]);
    refused(&o, "a-file is a file, where a directory is expected");
    let o = sweep(dir.path(), TINY, &["--record", "a-file/sub"]);
    refused(&o, "a-file is a file, where a directory is expected");
    assert!(
        !text(&o.stderr).contains("os error 17"),
        "{}",
        text(&o.stderr)
    );
    // Nothing was measured: no results were written.
    assert!(!dir.path().join("out").exists());
    // `history record` checks the same way before it reads anything.
    let o = bin()
        .current_dir(dir.path())
        .args(["history", "record", "missing.json", "--dir", "a-file"])
        .output()
        .unwrap();
    refused(
        &o,
        "--dir a-file: a-file is a file, where a directory is expected",
    );
}

#[test]
fn an_empty_skin_list_is_refused_like_every_other_list() {
    let dir = tempfile::tempdir().unwrap();
    let config = TINY
        .replace("\"naive\"", "\"verlet\"")
        .replace("threads = [1]", "threads = [1]\nskin = []");
    let o = sweep(dir.path(), &config, &["--dry-run"]);
    refused(&o, "`skin` is empty");
    let given = config.replace("skin = []", "skin = [0.004]");
    let o = sweep(dir.path(), &given, &["--dry-run"]);
    assert!(o.status.success(), "{}", text(&o.stderr));
}

#[test]
fn init_refuses_a_name_that_reads_as_an_option_and_prints_commands_that_work() {
    let dir = tempfile::tempdir().unwrap();
    let init = |args: &[&str]| {
        bin()
            .current_dir(dir.path())
            .arg("init")
            .args(args)
            .output()
            .unwrap()
    };
    refused(&init(&["--external=-x"]), "not starting with '-'");
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
    // A config file whose name starts with '-': the printed next step names it so that the
    // command line does not read it as an option.
    let o = init(&["--external", "mine", "--lang", "python", "--out=-mine.toml"]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let said = text(&o.stderr);
    let step = said
        .lines()
        .map(str::trim)
        .find(|l| l.starts_with("nbody-bench sweep") && l.ends_with("--dry-run"))
        .unwrap_or_else(|| panic!("no dry-run step in: {said}"));
    assert!(step.contains("--config ./-mine.toml"), "{step}");
    let args: Vec<&str> = step.split_whitespace().skip(1).collect();
    let o = bin().current_dir(dir.path()).args(&args).output().unwrap();
    assert!(o.status.success(), "{step}: {}", text(&o.stderr));
}

#[test]
fn with_no_warm_up_the_sample_length_is_chosen_after_an_untimed_step() {
    let dir = tempfile::tempdir().unwrap();
    let o = sweep(dir.path(), TINY, &[]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let results: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(dir.path().join("out/tiny/results.json")).unwrap(),
    )
    .unwrap();
    let round = &results["cases"][0]["rounds"][0];
    // The cold first step and at least one more before the samples.
    assert!(
        round["warmup_steps"].as_u64().unwrap() >= 2,
        "{}",
        round["warmup_steps"]
    );
}
