//! Other people's files and arguments through the binary: a commit that looks like an option
//! never reaches git as one, a machine class cannot lead out of the history folder, a pipe or
//! a device in place of a history file or a report is refused without a wait, and text from
//! those files is neutralised for each output it reaches: no `javascript:` link on the page, no
//! code span a case key can close in Markdown, no spreadsheet formula in CSV or JSON lines, no
//! control character on the terminal.

use super::{bin, finish, refused, text};
use nbody_harness::history::store::{self, Build, HISTORY_SCHEMA, Normalized, Record};
use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};

/// A copy of the committed baseline with its `git_commit` set to `commit`, at `dir/name`.
fn results_at(dir: &Path, name: &str, commit: &str) -> PathBuf {
    let mut v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(crate::committed_baseline()).unwrap())
            .unwrap();
    v["metadata"]["git_commit"] = commit.into();
    let path = dir.join(name);
    std::fs::write(&path, serde_json::to_string(&v).unwrap()).unwrap();
    path
}

/// A git repository at `dir` with one commit.
fn repository(dir: &Path) {
    for args in [
        &["init", "-q"][..],
        &["commit", "-q", "--allow-empty", "-m", "start"],
    ] {
        let o = Command::new("git")
            .current_dir(dir)
            .args(["-c", "user.name=test", "-c", "user.email=test@localhost"])
            .args(args)
            .output()
            .unwrap();
        assert!(o.status.success(), "git {args:?}: {}", text(&o.stderr));
    }
}

/// Runs the binary in `dir` with `args`, failing the test if it hangs.
fn run(dir: &Path, args: &[&str], env: &[(&str, &str)]) -> Output {
    let child = bin()
        .current_dir(dir)
        .args(args)
        .envs(env.iter().copied())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    finish(child, &format!("{args:?}"))
}

/// A config the A/B gate reads before it asks git for the base revision.
const TINY: &str = r#"
name = "tiny"
study = "cartesian"
scenarios = ["lj-box"]
kernels = ["naive"]
n = [200]
threads = [1]

[measure]
warmup_s = 0.0
samples = 6
rounds = 2
min_sample_s = 0.001
"#;

#[test]
fn a_commit_that_looks_like_an_option_never_reaches_git_as_one() {
    let dir = tempfile::tempdir().unwrap();
    repository(dir.path());
    let victim = dir.path().join("victim");
    let kept = dir.path().join("kept");
    std::fs::write(&kept, "mine\n").unwrap();
    for target in [&victim, &kept] {
        let commit = format!("--output={}", target.display());
        let file = results_at(dir.path(), "evil.json", &commit);
        // `history record` and `gate --current FILE --record` both ask git about the commit.
        let recorded = run(
            dir.path(),
            &["history", "record", file.to_str().unwrap(), "--dir", "hist"],
            &[],
        );
        assert!(recorded.status.success(), "{}", text(&recorded.stderr));
        assert!(
            text(&recorded.stderr).contains("is not a commit hash"),
            "{}",
            text(&recorded.stderr)
        );
        let base = results_at(dir.path(), "base.json", "abc1234");
        let gated = run(
            dir.path(),
            &[
                "gate",
                "--baseline",
                base.to_str().unwrap(),
                "--current",
                file.to_str().unwrap(),
                "--record",
                "hist",
            ],
            &[],
        );
        assert!(
            matches!(gated.status.code(), Some(0 | 1)),
            "{}",
            text(&gated.stderr)
        );
        assert!(
            text(&gated.stderr).contains("is not a commit hash"),
            "{}",
            text(&gated.stderr)
        );
        assert!(!victim.exists(), "git wrote the file the commit named");
        assert_eq!(std::fs::read_to_string(&kept).unwrap(), "mine\n");
    }
    // The records are kept, with no commit date git could not give.
    let class = std::fs::read_dir(dir.path().join("hist"))
        .unwrap()
        .flatten()
        .map(|e| e.path())
        .find(|p| p.to_string_lossy().ends_with("cpu.jsonl"))
        .unwrap();
    let first: serde_json::Value = serde_json::from_str(
        std::fs::read_to_string(class)
            .unwrap()
            .lines()
            .next()
            .unwrap(),
    )
    .unwrap();
    assert!(first["commit"].as_str().unwrap().starts_with("--output="));
    assert!(first["commit_date"].is_null(), "{first}");
    // A revision typed by a user is refused the same way, before git sees it.
    let base = format!("--base=--output={}", victim.display());
    refused(
        &run(
            dir.path(),
            &["publish", "--dir", "hist", "--markdown", &base],
            &[],
        ),
        "is not a revision",
    );
    std::fs::write(dir.path().join("tiny.toml"), TINY).unwrap();
    let against = format!("--against=--output={}", victim.display());
    refused(
        &run(
            dir.path(),
            &["gate", &against, "--config", "tiny.toml"],
            &[],
        ),
        "is not a revision",
    );
    assert!(!victim.exists());
}

#[test]
fn a_machine_class_that_leads_out_of_the_history_folder_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::create_dir_all(dir.path().join("hist/sub")).unwrap();
    let file = results_at(dir.path(), "r.json", "abc1234");
    let o = run(
        dir.path(),
        &["history", "record", file.to_str().unwrap(), "--dir", "hist"],
        &[],
    );
    assert!(o.status.success(), "{}", text(&o.stderr));
    // Histories outside the folder, or below it, that a class name could reach.
    let recorded = std::fs::read_dir(dir.path().join("hist"))
        .unwrap()
        .flatten()
        .map(|e| e.path())
        .find(|p| p.is_file())
        .unwrap();
    std::fs::copy(&recorded, dir.path().join("x.jsonl")).unwrap();
    std::fs::copy(&recorded, dir.path().join("hist/sub/y.jsonl")).unwrap();
    for class in ["../x", "sub/y", "", ".", "a\u{1b}b"] {
        let o = run(
            dir.path(),
            &["history", "--dir", "hist", "--class", class],
            &[],
        );
        refused(&o, "is not a machine class");
        assert!(!text(&o.stderr).contains('\u{1b}'), "{}", text(&o.stderr));
        assert!(o.stdout.is_empty(), "{}", text(&o.stdout));
    }
}

/// A named pipe at `path` that nobody writes to.
fn fifo(path: &Path) {
    let o = Command::new("mkfifo").arg(path).output().unwrap();
    assert!(o.status.success(), "mkfifo: {}", text(&o.stderr));
}

#[test]
fn a_pipe_or_a_device_in_place_of_a_history_or_a_report_is_refused_without_waiting() {
    let dir = tempfile::tempdir().unwrap();
    let file = results_at(dir.path(), "r.json", "abc1234");
    let o = run(
        dir.path(),
        &["history", "record", file.to_str().unwrap(), "--dir", "hist"],
        &[],
    );
    assert!(o.status.success(), "{}", text(&o.stderr));
    fifo(&dir.path().join("pipe"));
    std::os::unix::fs::symlink("/dev/zero", dir.path().join("zero.json")).unwrap();
    // A pipe or device where a file is read: refused at once, whatever the pipe wait says.
    let wait = [("NBODY_BENCH_PIPE_WAIT_S", "86400")];
    refused(
        &run(
            dir.path(),
            &[
                "publish", "--dir", "hist", "--report", "pipe", "--out", "page",
            ],
            &wait,
        ),
        "is a pipe",
    );
    refused(
        &run(
            dir.path(),
            &["publish", "--dir", "hist", "--report", "/dev/zero"],
            &wait,
        ),
        "is a device",
    );
    refused(
        &run(dir.path(), &["history", "record", "zero.json"], &wait),
        "is a device",
    );
    // A results file read from a pipe nobody writes to: given up after the pipe wait.
    refused(
        &run(
            dir.path(),
            &["history", "record", "pipe", "--dir", "hist"],
            &[("NBODY_BENCH_PIPE_WAIT_S", "0.5")],
        ),
        "no program wrote to this pipe",
    );
    // A pipe as a history file of the folder: refused by `history` and `publish` alike.
    fifo(&dir.path().join("hist/Pipe-1cpu.jsonl"));
    refused(
        &run(
            dir.path(),
            &["history", "--dir", "hist", "--class", "Pipe-1cpu"],
            &wait,
        ),
        "is a pipe",
    );
    refused(
        &run(
            dir.path(),
            &["publish", "--dir", "hist", "--markdown"],
            &wait,
        ),
        "is a pipe",
    );
}

const CLASS: &str = "Alpha-1-2-3-2cpu";

/// A history at `dir/hist` of `case` over 14 commits, 30% slower from commit 7 on.
fn history_of(dir: &Path, case: &str) {
    let records: Vec<Record> = (0..14)
        .map(|i| {
            let level = if i >= 7 { 1.3 } else { 1.0 };
            let v = level * (1.0 + 0.004 * ((i * 7 % 5) as f64 - 2.0));
            Record {
                schema: HISTORY_SCHEMA.into(),
                commit: format!("{:07x}{}", 0xa00_0000 + i, "0".repeat(33)),
                parent: None,
                commit_date: Some(format!("2026-11-{:02}T10:00:00Z", i + 1)),
                dirty: false,
                measured: format!("2026-12-01T10:{i:02}:00Z"),
                class: CLASS.into(),
                build: Build {
                    tool_version: "0.1.0".into(),
                    profile: "release".into(),
                    simd: "avx2".into(),
                    features: vec![],
                },
                config: "ci".into(),
                source: "sweep".into(),
                case: case.into(),
                n: 1000,
                median_s: v * 1e-4,
                ci95_s: [v * 0.98e-4, v * 1.02e-4],
                normalized: Some(Normalized {
                    median: v,
                    ci95: [v * 0.98, v * 1.02],
                }),
                samples: 16,
                work: None,
            }
        })
        .collect();
    store::append(&dir.join("hist"), &records).unwrap();
}

#[test]
fn a_case_key_cannot_close_its_code_span_in_a_markdown_summary() {
    let dir = tempfile::tempdir().unwrap();
    let key = "lj-box`<img src=x onerror=alert(1)>`|x";
    history_of(dir.path(), key);
    let o = run(dir.path(), &["publish", "--dir", "hist", "--markdown"], &[]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let md = text(&o.stdout);
    // The step's row: the key in a span of two backticks, its `|` escaped for the table.
    assert!(
        md.contains("| ``lj-box`<img src=x onerror=alert(1)>`\\|x`` |"),
        "{md}"
    );
    assert!(!md.contains("| `lj-box`<img"), "{md}");
    // The gate's job summary writes the keys of the results files the same way.
    let file = results_at(dir.path(), "r.json", "abc1234");
    let mut v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&file).unwrap()).unwrap();
    v["cases"][0]["key"] = key.into();
    std::fs::write(&file, serde_json::to_string(&v).unwrap()).unwrap();
    let f = file.to_str().unwrap();
    let o = run(
        dir.path(),
        &[
            "gate",
            "--baseline",
            f,
            "--current",
            f,
            "--format",
            "markdown",
        ],
        &[],
    );
    assert!(o.status.success(), "{}", text(&o.stderr));
    let md = text(&o.stdout);
    assert!(
        md.contains("| ``lj-box`<img src=x onerror=alert(1)>`\\|x`` |"),
        "{md}"
    );
}

#[test]
fn a_link_that_is_not_to_a_document_is_shown_on_the_page_not_linked() {
    let dir = tempfile::tempdir().unwrap();
    history_of(dir.path(), "lj-box/naive/n=1000/p=1/r=1/seed=1");
    // The report and the page in one folder, beside a file the link's path names.
    let site = dir.path().join("site");
    std::fs::create_dir_all(&site).unwrap();
    std::fs::write(site.join("javascript:alert"), "").unwrap();
    std::fs::write(site.join("t.svg"), "<svg/>").unwrap();
    std::fs::write(
        site.join("REPORT.md"),
        "# R\n![trap](javascript:alert)\n![time](t.svg)\n",
    )
    .unwrap();
    let o = run(
        dir.path(),
        &[
            "publish",
            "--dir",
            "hist",
            "--report",
            "site/REPORT.md",
            "--out",
            "site",
        ],
        &[],
    );
    assert!(o.status.success(), "{}", text(&o.stderr));
    let page = std::fs::read_to_string(site.join("index.html")).unwrap();
    assert!(!page.contains("href=\"javascript:"), "a javascript: link");
    assert!(
        page.contains("<li>trap <code>javascript:alert</code></li>"),
        "{page}"
    );
    assert!(page.contains("<a href=\"t.svg\">time</a>"));
}

#[test]
fn table_cells_that_start_like_a_formula_are_text_and_numbers_stay_numbers() {
    let dir = tempfile::tempdir().unwrap();
    history_of(dir.path(), "=HYPERLINK(\"http://x\",\"y\")");
    let out = |format: &str| {
        let o = run(
            dir.path(),
            &["export-results", "hist", "--format", format],
            &[],
        );
        assert!(o.status.success(), "{}", text(&o.stderr));
        text(&o.stdout)
    };
    let csv = out("csv");
    let row = csv.lines().nth(1).unwrap();
    assert!(
        row.contains("\"'=HYPERLINK(\"\"http://x\"\",\"\"y\"\")\""),
        "{row}"
    );
    assert!(!csv.contains(",=") && !csv.contains(",\"="), "{csv}");
    let jsonl = out("jsonl");
    let first: serde_json::Value = serde_json::from_str(jsonl.lines().next().unwrap()).unwrap();
    let texts: Vec<&str> = first
        .as_object()
        .unwrap()
        .values()
        .filter_map(|v| v.as_str())
        .collect();
    assert!(
        texts.contains(&"'=HYPERLINK(\"http://x\",\"y\")"),
        "{first}"
    );
    // Numbers, negative ones too, are numbers still.
    assert!(
        first.as_object().unwrap().values().any(|v| v.is_f64()),
        "{first}"
    );
}

#[test]
fn control_characters_from_a_history_never_reach_the_terminal() {
    let dir = tempfile::tempdir().unwrap();
    history_of(
        dir.path(),
        "lj-box\u{1b}]0;owned\u{7}\u{1b}[2J/naive\u{9b}31m",
    );
    let o = run(
        dir.path(),
        &["history", "--dir", "hist", "--class", CLASS],
        &[],
    );
    assert!(o.status.success(), "{}", text(&o.stderr));
    let shown = text(&o.stdout);
    assert!(
        shown.contains("lj-box\\u{1b}]0;owned\\u{7}\\u{1b}[2J/naive\\u{9b}31m"),
        "{shown}"
    );
    assert!(
        !shown.chars().any(|c| c.is_control() && c != '\n'),
        "{shown:?}"
    );
    // An error quoting the file shows its control characters escaped too.
    let o = run(
        dir.path(),
        &[
            "history",
            "--dir",
            "hist",
            "--class",
            CLASS,
            "--case",
            "x\u{1b}[2J",
        ],
        &[],
    );
    refused(&o, "x\\u{1b}[2J");
    assert!(!text(&o.stderr).contains('\u{1b}'));
}
