//! `publish`: the page of a small fixture history (two machine classes, three cases, steps
//! placed on known commits) opened in headless Chromium, with every case's charts and every
//! step in the DOM after the page's script ran; the Markdown summary for a pull request; the
//! same bytes from the same history; the refusals; and the committed page, which must be what
//! the generator makes of the committed history.
//!
//! The browser test keeps its screenshot at `target/test-artifacts/publish.png` (beside the
//! tests' `target/tmp`). It needs Chromium (`chromium` on the PATH, or the program named by
//! `NBODY_BENCH_CHROMIUM`); `scripts/test.sh` installs it. Without one the test fails and says
//! so.
//!
//! `NBODY_BENCH_UPDATE_DOCS=1 cargo test --test suite publish` rewrites the committed page
//! (`results/history/page/index.html`) from the committed history.

use super::{bin, refused, text};
use nbody_harness::gate::Verdict;
use nbody_harness::history::publish;
use nbody_harness::history::store::{self, Build, HISTORY_SCHEMA, Normalized, Record};
use nbody_harness::history::verdicts::{self, CaseVerdict, GateRun, VERDICTS_SCHEMA};
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Duration;
use wait_timeout::ChildExt;

const ALPHA: &str = "Alpha-1-2-3-2cpu";
const BETA: &str = "Beta-4-5-6-4cpu";
const NAIVE: &str = "lj-box/naive/n=1000/p=1/r=1/seed=1";
const SYMMETRIC: &str = "galaxy/symmetric/n=1000/p=2/r=1/seed=1";
const CELLS: &str = "lj-box/cell-list/n=4000/p=1/r=1/seed=1";
const COMMITS: usize = 14;

/// The fixture's i-th commit: 40 hex digits, `a000000`, `a000001`, ... in short.
fn commit(i: usize) -> String {
    format!("{:07x}{}", 0xa00_0000 + i, "0".repeat(33))
}

fn record(class: &str, case: &str, i: usize, level: f64, normalized: bool) -> Record {
    // A little noise of fixed pattern, so that each series has a scale.
    let v = level * (1.0 + 0.004 * ((i * 7 % 5) as f64 - 2.0));
    Record {
        schema: HISTORY_SCHEMA.into(),
        commit: commit(i),
        parent: (i > 0).then(|| commit(i - 1)),
        commit_date: Some(format!("2026-11-{:02}T10:00:00Z", i + 1)),
        dirty: false,
        measured: format!("2026-12-01T10:{:02}:00Z", i),
        class: class.into(),
        build: Build {
            tool_version: "0.1.0".into(),
            profile: "release".into(),
            simd: "avx2".into(),
            features: vec![],
        },
        config: "backfill".into(),
        source: "backfill".into(),
        case: case.into(),
        n: 1000,
        median_s: v * 1e-4,
        ci95_s: [v * 0.98e-4, v * 1.02e-4],
        normalized: normalized.then_some(Normalized {
            median: v,
            ci95: [v * 0.98, v * 1.02],
        }),
        samples: 16,
        work: None,
    }
}

/// The fixture history in `dir`: on Alpha the naive kernel 30% slower from commit 7 on; on
/// Beta the symmetric one 20% faster from commit 6 on (in seconds: no reference timing);
/// the cell list flat on both. One gate run on Alpha.
fn fixture(dir: &Path) {
    let mut records = Vec::new();
    for i in 0..COMMITS {
        let step = |at: usize, ratio: f64| if i >= at { ratio } else { 1.0 };
        records.push(record(ALPHA, NAIVE, i, 1.3 * step(7, 1.3), true));
        records.push(record(ALPHA, SYMMETRIC, i, 0.8, true));
        records.push(record(ALPHA, CELLS, i, 0.2, true));
        records.push(record(BETA, NAIVE, i, 1.1, true));
        records.push(record(BETA, SYMMETRIC, i, 0.7 * step(6, 0.8), false));
        records.push(record(BETA, CELLS, i, 0.25, true));
    }
    store::append(dir, &records).unwrap();
    let run = GateRun {
        schema: VERDICTS_SCHEMA.into(),
        measured: "2026-12-01T11:00:00Z".into(),
        class: ALPHA.into(),
        base: commit(6),
        base_dirty: false,
        current: commit(7),
        current_dirty: false,
        threshold: 0.03,
        judged_on: nbody_harness::gate::Judged::Raw,
        cases: vec![CaseVerdict {
            key: NAIVE.into(),
            verdict: Verdict::Regressed,
            ratio: 1.3,
            ci95: [1.27, 1.33],
        }],
        missing: vec![],
        acceptance: None,
    };
    verdicts::append(dir, &[run]).unwrap();
}

fn publish(cwd: &Path, args: &[&str]) -> std::process::Output {
    bin()
        .current_dir(cwd)
        .arg("publish")
        .args(args)
        .output()
        .unwrap()
}

/// The Chromium to test with, or a failure saying how to get one.
fn chromium() -> PathBuf {
    if let Some(p) = std::env::var_os("NBODY_BENCH_CHROMIUM") {
        return p.into();
    }
    for name in ["chromium", "chromium-browser", "google-chrome"] {
        let found = std::env::var_os("PATH").and_then(|paths| {
            std::env::split_paths(&paths)
                .map(|d| d.join(name))
                .find(|p| p.is_file())
        });
        if let Some(p) = found {
            return p;
        }
    }
    panic!(
        "the page's browser test needs Chromium, and none was found: install it \
         (`apt-get install -y chromium`; scripts/test.sh does as root) or name one with \
         NBODY_BENCH_CHROMIUM"
    );
}

/// Runs headless Chromium on `page` with `args`, for at most a minute (its whole process
/// group is killed after that: a hung browser fails the test, never hangs it); its stdout.
fn browse(page: &Path, args: &[String]) -> String {
    use std::os::unix::process::CommandExt;
    let profile = tempfile::tempdir().unwrap();
    let mut child = Command::new(chromium())
        .args([
            "--headless",
            "--no-sandbox",
            "--disable-gpu",
            "--hide-scrollbars",
        ])
        .arg(format!("--user-data-dir={}", profile.path().display()))
        .arg("--virtual-time-budget=5000")
        .args(args)
        .arg(format!("file://{}", page.display()))
        .stdin(std::process::Stdio::null())
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::null())
        .process_group(0)
        .spawn()
        .expect("Chromium starts");
    let pid = child.id() as i32;
    let out = std::thread::spawn({
        let mut stdout = child.stdout.take().unwrap();
        move || {
            let mut s = String::new();
            std::io::Read::read_to_string(&mut stdout, &mut s).unwrap();
            s
        }
    });
    match child.wait_timeout(Duration::from_secs(60)).unwrap() {
        Some(status) => assert!(status.success(), "Chromium failed: {status}"),
        None => {
            // SAFETY: kill(2) on the group this test started.
            unsafe { libc::kill(-pid, libc::SIGKILL) };
            let _ = child.wait();
            panic!("Chromium still running after 60 s: killed");
        }
    }
    out.join().unwrap()
}

#[test]
fn the_page_shows_every_case_chart_and_step_in_a_browser() {
    let dir = tempfile::tempdir().unwrap();
    let hist = dir.path().join("hist");
    fixture(&hist);
    let o = publish(dir.path(), &["--dir", "hist", "--out", "page"]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let page = dir.path().join("page/index.html");
    assert_eq!(text(&o.stdout).trim(), "page/index.html");
    let html = std::fs::read_to_string(&page).unwrap();
    // Nothing leaves the file: no URL of any kind.
    assert!(!html.contains("http://") && !html.contains("https://") && !html.contains("//cdn"));

    let dom = browse(&page, &["--dump-dom".to_string()]);
    assert!(
        dom.contains("data-script=\"ran\""),
        "the script did not run"
    );
    let (built, _) = publish::build(&hist, Path::new("REPORT.md"), dir.path()).unwrap();
    for case in [NAIVE, SYMMETRIC, CELLS] {
        let start = dom
            .find(&format!("<section class=\"case\" data-case=\"{case}\""))
            .unwrap_or_else(|| panic!("no section of {case}"));
        let section = &dom[start..start + dom[start..].find("</section>").unwrap()];
        for class in [ALPHA, BETA] {
            assert!(
                section.contains(&format!("<svg class=\"chart\" data-class=\"{class}\"")),
                "no chart of {case} on {class}"
            );
        }
    }
    // The steps placed, and every step the detector finds, each marked in its chart.
    let mut steps = Vec::new();
    for chart in built.charts() {
        for s in &chart.steps {
            steps.push(format!("{}..{}", &s.between[0][..7], &s.between[1][..7]));
        }
    }
    assert!(steps.contains(&"a000006..a000007".to_string()), "{steps:?}");
    assert!(steps.contains(&"a000005..a000006".to_string()), "{steps:?}");
    assert_eq!(steps.len(), 2, "{steps:?}");
    for between in &steps {
        assert!(
            dom.contains(&format!("data-between=\"{between}\"")),
            "no marker of the step {between}"
        );
    }
    assert_eq!(dom.matches("<g class=\"change").count(), steps.len());
    assert!(dom.contains("<span class=\"regressed\">regressed</span>"));

    let artifacts = Path::new(env!("CARGO_TARGET_TMPDIR"))
        .parent()
        .unwrap()
        .join("test-artifacts");
    std::fs::create_dir_all(&artifacts).unwrap();
    let shot = artifacts.join("publish.png");
    let _ = std::fs::remove_file(&shot);
    browse(
        &page,
        &[
            format!("--screenshot={}", shot.display()),
            "--window-size=1320,1800".to_string(),
        ],
    );
    let png = std::fs::read(&shot).expect("the screenshot was written");
    assert!(
        png.starts_with(b"\x89PNG") && png.len() > 10_000,
        "{}",
        shot.display()
    );
}

#[test]
fn the_summary_names_the_changes_since_the_base() {
    let dir = tempfile::tempdir().unwrap();
    fixture(&dir.path().join("hist"));
    let md = |args: &[&str]| {
        let mut all = vec!["--dir", "hist", "--markdown"];
        all.extend_from_slice(args);
        let o = publish(dir.path(), &all);
        assert!(o.status.success(), "{}", text(&o.stderr));
        text(&o.stdout)
    };
    // From commit 5: Beta's step (5..6) and Alpha's (6..7), with their sizes.
    let since = md(&["--base", "a000005"]);
    assert!(since.contains("since `a000005`"), "{since}");
    let row = since
        .lines()
        .find(|l| l.contains(NAIVE) && l.contains("`a000006..a000007`"))
        .unwrap_or_else(|| panic!("{since}"));
    let size: f64 = row
        .split('|')
        .nth(4)
        .and_then(|c| c.trim().split('%').next())
        .and_then(|p| p.parse().ok())
        .unwrap_or_else(|| panic!("{row}"));
    assert!((28.0..32.0).contains(&size), "{row}");
    assert!(row.contains("slower"), "{row}");
    assert!(
        since.contains(&format!("`{SYMMETRIC}` | `a000005..a000006`")),
        "{since}"
    );
    assert!(since.contains("faster"), "{since}");
    assert!(
        since.contains("1 regressed, 0 improved, 0 unchanged"),
        "{since}"
    );
    // From commit 6 on Beta's step is before the base; from the last commit nothing is after.
    let later = md(&["--base", "a000006"]);
    assert!(later.contains("a000006..a000007") && !later.contains("a000005..a000006"));
    let none = md(&["--base", "a00000d"]);
    assert!(none.contains("No change since `a00000d`"), "{none}");
    // Outside a repository there is no default base: every step, said plainly.
    let all = md(&[]);
    assert!(all.contains("every step of the history is listed"), "{all}");
    assert!(all.contains("a000005..a000006") && all.contains("a000006..a000007"));
    let o = publish(
        dir.path(),
        &["--dir", "hist", "--markdown", "--base", "fffffff"],
    );
    refused(&o, "--base fffffff");
}

#[test]
fn the_same_history_gives_the_same_bytes() {
    let dir = tempfile::tempdir().unwrap();
    fixture(&dir.path().join("hist"));
    for out in ["one", "two"] {
        let o = publish(dir.path(), &["--dir", "hist", "--out", out]);
        assert!(o.status.success(), "{}", text(&o.stderr));
    }
    let one = std::fs::read(dir.path().join("one/index.html")).unwrap();
    let two = std::fs::read(dir.path().join("two/index.html")).unwrap();
    assert!(one == two, "two pages of one history differ");
}

#[test]
fn bad_input_is_refused_or_named() {
    let dir = tempfile::tempdir().unwrap();
    refused(
        &publish(dir.path(), &["--dir", "nowhere"]),
        "nowhere does not exist",
    );
    std::fs::create_dir(dir.path().join("empty")).unwrap();
    refused(
        &publish(dir.path(), &["--dir", "empty"]),
        "holds no history record",
    );
    let hist = dir.path().join("hist");
    fixture(&hist);
    std::fs::write(dir.path().join("file"), "").unwrap();
    refused(
        &publish(dir.path(), &["--dir", "hist", "--out", "file/page"]),
        "--out",
    );
    // A damaged line: named, and the page made of the rest.
    let path = hist.join(format!("{ALPHA}.jsonl"));
    let mut damaged = std::fs::read_to_string(&path).unwrap();
    damaged.insert_str(0, "{not json\n");
    std::fs::write(&path, damaged).unwrap();
    let gate = verdicts::file_of(&hist, ALPHA);
    let mut v = std::fs::read_to_string(&gate).unwrap();
    v.push_str("{\"schema\": \"nbody-bench-gate-verdicts/1\"}\n");
    std::fs::write(&gate, v).unwrap();
    let o = publish(dir.path(), &["--dir", "hist", "--out", "page"]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let err = text(&o.stderr);
    assert!(
        err.contains(&format!("{ALPHA}.jsonl line 1: not a history record")),
        "{err}"
    );
    assert!(
        err.contains(&format!(
            "{ALPHA}.gate.jsonl line 2: not a gate verdict line"
        )),
        "{err}"
    );
    assert!(!err.contains("panicked"), "{err}");
}

#[test]
fn the_committed_page_is_what_the_committed_history_makes() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let out = root.join("results/history/page");
    let (page, warnings) =
        publish::build(&root.join("results/history"), &root.join("REPORT.md"), &out).unwrap();
    assert!(warnings.is_empty(), "{warnings:?}");
    assert!(page.classes.iter().all(|c| c.latest_gate.is_some()));
    let generated = publish::html(&page);
    let path = out.join(publish::PAGE_FILE);
    if std::env::var("NBODY_BENCH_UPDATE_DOCS").as_deref() == Ok("1") {
        publish::write(&page, &out).unwrap();
        return;
    }
    let committed = std::fs::read_to_string(&path).unwrap_or_default();
    assert!(
        committed == generated,
        "{} is stale: regenerate it with `nbody-bench publish` (or \
         `NBODY_BENCH_UPDATE_DOCS=1 cargo test --test suite publish`) and commit it",
        path.display()
    );
}
