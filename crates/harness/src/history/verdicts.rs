//! The gate's verdicts kept beside the history: one JSON Lines file per machine class,
//! `<dir>/<class>.gate.jsonl`, one line per gate run (when, which two commits, the threshold,
//! and each case's verdict with the ratio it was judged on). A gate run's folder is not kept
//! in git; these lines are, so that the published page can show the latest verdicts. Written
//! the way the history is ([`super::store`]): appended whole lines under a lock, and read
//! line by line, a bad line named by its number and the rest read.

use super::lines::{BadLine, Line, parse_lines, read_lines};
use super::store::{HistoryError, append_text};
use crate::gate::baselines::class_name;
use crate::gate::guard::Regression;
use crate::gate::{GateReport, Judged, RunInfo, Verdict};
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// The schema tag of every line.
pub const VERDICTS_SCHEMA: &str = "nbody-bench-gate-verdicts/1";

/// The schema tag of a gate report (`gate --format json`, a kept run's `gate.json`).
pub const GATE_REPORT_SCHEMA: &str = crate::gate::GATE_SCHEMA;

/// One gate run.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct GateRun {
    /// Schema tag, [`VERDICTS_SCHEMA`]; a line with another is not read as a run.
    pub schema: String,
    /// UTC, when the run's later side started measuring.
    pub measured: String,
    /// The machine class, as the gate's baselines name it.
    pub class: String,
    /// The baseline's commit and this build's, each with whether it had uncommitted changes.
    pub base: String,
    /// Whether the baseline's build had uncommitted changes.
    pub base_dirty: bool,
    /// This build's commit.
    pub current: String,
    /// Whether this build had uncommitted changes.
    pub current_dirty: bool,
    /// Relative change a case had to exceed to count (0.10 = 10%).
    pub threshold: f64,
    /// Which ratio the verdicts come from; each case's `ratio` is that one.
    pub judged_on: Judged,
    /// Every compared case's verdict, in the baseline's order.
    pub cases: Vec<CaseVerdict>,
    /// Baseline cases that could not be compared.
    #[serde(default)]
    pub missing: Vec<String>,
    /// Set on the A/B run of a `gate --save-baseline` whose regressions the user accepted:
    /// the new baseline was saved with them. Absent from every other run, and from files
    /// written before it existed (a reader that does not know the field reads the run as any
    /// other).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub acceptance: Option<Acceptance>,
}

/// Regressions accepted into a machine class's baseline (`gate --save-baseline --accept CASE...
/// --reason TEXT`): what a later reader needs to know that the baseline absorbed them on
/// purpose.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Acceptance {
    /// UTC, ISO 8601, when the new baseline was saved.
    pub accepted: String,
    /// The machine class whose baseline was replaced, as the baselines name it.
    pub class: String,
    /// The commit of the baseline replaced (the A/B run's base).
    pub replaced_commit: String,
    /// The commit the new baseline's results were measured at.
    pub new_commit: String,
    /// Why the slowdown is intended, as the user gave it.
    pub reason: String,
    /// The accepted cases with the ratios the A/B run found.
    pub cases: Vec<AcceptedCase>,
}

/// One accepted regression.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct AcceptedCase {
    /// The case key.
    pub key: String,
    /// This build / the replaced baseline's commit, the ratio the verdict was judged on.
    pub ratio: f64,
    /// Bootstrap 95% interval of that ratio ([low, high]).
    pub ci95: [f64; 2],
}

/// One case's verdict.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct CaseVerdict {
    /// The case key.
    pub key: String,
    /// The gate's verdict on the case.
    pub verdict: Verdict,
    /// current / base, and its bootstrap 95% interval.
    pub ratio: f64,
    /// Bootstrap 95% interval of that ratio ([low, high]).
    pub ci95: [f64; 2],
}

impl GateRun {
    /// The verdicts of `report`; `machine` names the class when neither side recorded its CPU
    /// (the run was measured here).
    pub fn of(report: &GateReport, machine: &RunInfo) -> GateRun {
        let raw = report.judged_on == Judged::Raw;
        GateRun {
            schema: VERDICTS_SCHEMA.to_string(),
            measured: later(&report.baseline.started, &report.current.started),
            class: class_of(&report.current, &report.baseline, machine),
            base: report.baseline.git_commit.clone(),
            base_dirty: report.baseline.git_dirty,
            current: report.current.git_commit.clone(),
            current_dirty: report.current.git_dirty,
            threshold: report.threshold,
            judged_on: report.judged_on,
            cases: report
                .cases
                .iter()
                .map(|c| CaseVerdict {
                    key: c.key.clone(),
                    verdict: c.verdict,
                    ratio: if raw { c.raw_ratio } else { c.ratio },
                    ci95: if raw { c.raw_ci95 } else { c.ci95 },
                })
                .collect(),
            missing: report.missing.iter().map(|m| m.key.clone()).collect(),
            acceptance: None,
        }
    }

    /// The verdicts of a gate report's JSON (schema [`GATE_REPORT_SCHEMA`]).
    pub fn from_report_json(text: &str, machine: &RunInfo) -> Result<GateRun, String> {
        let r: ReportJson = serde_json::from_str(text).map_err(|e| e.to_string())?;
        if r.schema != GATE_REPORT_SCHEMA {
            return Err(format!(
                "schema `{}`, not a gate report (`{GATE_REPORT_SCHEMA}`)",
                r.schema
            ));
        }
        let raw = r.judged_on == Judged::Raw;
        let (base, current) = (r.baseline.info(), r.current.info());
        Ok(GateRun {
            schema: VERDICTS_SCHEMA.to_string(),
            measured: later(&base.started, &current.started),
            class: class_of(&current, &base, machine),
            base: base.git_commit,
            base_dirty: base.git_dirty,
            current: current.git_commit,
            current_dirty: current.git_dirty,
            threshold: r.threshold,
            judged_on: r.judged_on,
            cases: r
                .cases
                .into_iter()
                .map(|c| CaseVerdict {
                    key: c.key,
                    verdict: c.verdict,
                    ratio: if raw { c.raw_ratio } else { c.ratio },
                    ci95: if raw { c.raw_ci95 } else { c.ci95 },
                })
                .collect(),
            missing: r.missing.into_iter().map(|m| m.key).collect(),
            acceptance: None,
        })
    }

    /// The verdicts of a `gate --save-baseline` A/B run whose regressions `accepted` the user
    /// accepted for `reason`, at `when` (UTC), into the baseline of machine class `class` (as
    /// the baselines name it), of results measured at `new_commit`.
    pub fn accepted(
        report: &GateReport,
        machine: &RunInfo,
        class: &str,
        accepted: &[Regression],
        reason: &str,
        new_commit: &str,
        when: &str,
    ) -> GateRun {
        let mut run = GateRun::of(report, machine);
        run.acceptance = Some(Acceptance {
            accepted: when.to_string(),
            class: class.to_string(),
            replaced_commit: run.base.clone(),
            new_commit: new_commit.to_string(),
            reason: reason.to_string(),
            cases: accepted
                .iter()
                .map(|r| AcceptedCase {
                    key: r.key.clone(),
                    ratio: r.ratio,
                    ci95: r.ci95,
                })
                .collect(),
        });
        run
    }

    /// The verdict on `key`, if the run judged it.
    pub fn case(&self, key: &str) -> Option<&CaseVerdict> {
        self.cases.iter().find(|c| c.key == key)
    }
}

/// The later of two ISO 8601 UTC times (they order as text).
fn later(a: &str, b: &str) -> String {
    a.max(b).to_string()
}

fn class_of(current: &RunInfo, base: &RunInfo, machine: &RunInfo) -> String {
    let info = [current, base, machine]
        .into_iter()
        .find(|i| i.cpu_signature.is_some())
        .unwrap_or(machine);
    class_name(info.cpu_signature.as_deref(), info.logical_cpus)
}

/// The fields of a gate report's JSON the verdicts need (the report type only serialises).
#[derive(Deserialize)]
struct ReportJson {
    schema: String,
    threshold: f64,
    baseline: RunJson,
    current: RunJson,
    cases: Vec<CaseJson>,
    #[serde(default)]
    missing: Vec<MissingJson>,
    judged_on: Judged,
}

#[derive(Deserialize)]
struct RunJson {
    git_commit: String,
    #[serde(default)]
    git_dirty: bool,
    #[serde(default)]
    started: String,
    cpu_signature: Option<String>,
    logical_cpus: Option<usize>,
}

impl RunJson {
    fn info(self) -> RunInfo {
        RunInfo {
            git_commit: self.git_commit,
            git_dirty: self.git_dirty,
            started: self.started,
            host: String::new(),
            cpu_model: None,
            cpu_signature: self.cpu_signature,
            logical_cpus: self.logical_cpus,
        }
    }
}

#[derive(Deserialize)]
struct CaseJson {
    key: String,
    verdict: Verdict,
    ratio: f64,
    ci95: [f64; 2],
    raw_ratio: f64,
    raw_ci95: [f64; 2],
}

#[derive(Deserialize)]
struct MissingJson {
    key: String,
}

/// `dir/<class>.gate.jsonl`, the gate runs of one machine class.
pub fn file_of(dir: &Path, class: &str) -> PathBuf {
    dir.join(format!("{class}.gate.jsonl"))
}

/// A verdict file's runs, in file order, and the lines that were not runs.
#[derive(Clone, Debug, Default)]
pub struct Verdicts {
    /// The readable runs, in file order.
    pub runs: Vec<GateRun>,
    /// The lines that were not runs, left out.
    pub bad: Vec<BadLine>,
}

impl Verdicts {
    /// The run measured last, by the instant of its time (of two at the same time, or
    /// without a time this version reads, the one later in the file).
    pub fn latest(&self) -> Option<&GateRun> {
        self.runs
            .iter()
            .enumerate()
            .max_by_key(|(i, r)| (super::instant::parse(&r.measured), *i))
            .map(|(_, r)| r)
    }
}

/// Appends each run to its class's file under `dir`, but a run the file already holds (the
/// same time, base and current: a gate report imported twice). Returns each file with the
/// number of runs appended to it.
pub fn append(dir: &Path, runs: &[GateRun]) -> Result<Vec<(PathBuf, usize)>, HistoryError> {
    let mut classes: Vec<&str> = runs.iter().map(|r| r.class.as_str()).collect();
    classes.sort_unstable();
    classes.dedup();
    let mut written = Vec::new();
    for class in classes {
        let path = file_of(dir, class);
        let fail = |source| HistoryError::Append {
            path: path.clone(),
            source,
        };
        let held = read(&path)?;
        let mut text = String::new();
        let mut count = 0;
        for r in runs.iter().filter(|r| r.class == class) {
            let same = |o: &GateRun| {
                o.measured == r.measured && o.base == r.base && o.current == r.current
            };
            if held.runs.iter().any(same) {
                continue;
            }
            let line = serde_json::to_string(r).map_err(|e| fail(std::io::Error::other(e)))?;
            text.push_str(&line);
            text.push('\n');
            count += 1;
        }
        if count > 0 {
            nbody_engine::output::create_dir_all(dir).map_err(fail)?;
            append_text(&path, &text).map_err(fail)?;
        }
        written.push((path.clone(), count));
    }
    Ok(written)
}

impl Line for GateRun {
    const SCHEMA: &'static str = VERDICTS_SCHEMA;
    const WHAT: &'static str = "a gate verdict line";
    const SUFFIX: &'static str = ".gate.jsonl";
    fn class(&self) -> &str {
        &self.class
    }
    fn problem(&self) -> Option<String> {
        None
    }
}

/// Reads a verdict file, read as the history is ([`super::lines`]): a run must name the class
/// the file is named after (`<class>.gate.jsonl`). A missing file holds no run.
pub fn read(path: &Path) -> Result<Verdicts, HistoryError> {
    let lines = read_lines(path).map_err(|source| HistoryError::Read {
        path: path.into(),
        source,
    })?;
    Ok(Verdicts {
        runs: lines.good,
        bad: lines.bad,
    })
}

/// The runs of a verdict file's text, whatever their class (see [`read`]).
pub fn parse(text: &str) -> Verdicts {
    let lines = parse_lines(text.as_bytes(), None);
    Verdicts {
        runs: lines.good,
        bad: lines.bad,
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// A gate run of class `Test-1-2-3-2cpu` at `measured`, `base` → `current`, one verdict
    /// per `(key, verdict, ratio)`.
    pub(crate) fn run(
        measured: &str,
        base: &str,
        current: &str,
        cases: &[(&str, Verdict, f64)],
    ) -> GateRun {
        GateRun {
            schema: VERDICTS_SCHEMA.into(),
            measured: measured.into(),
            class: "Test-1-2-3-2cpu".into(),
            base: base.into(),
            base_dirty: false,
            current: current.into(),
            current_dirty: false,
            threshold: 0.03,
            judged_on: Judged::Raw,
            cases: cases
                .iter()
                .map(|&(key, verdict, ratio)| CaseVerdict {
                    key: key.into(),
                    verdict,
                    ratio,
                    ci95: [ratio * 0.99, ratio * 1.01],
                })
                .collect(),
            missing: vec![],
            acceptance: None,
        }
    }

    #[test]
    fn runs_round_trip_once_each_and_a_bad_line_costs_that_line_only() {
        let dir = tempfile::tempdir().unwrap();
        let a = run(
            "2026-12-05T10:00:00Z",
            "aaa",
            "bbb",
            &[("c", Verdict::Regressed, 1.2)],
        );
        let b = run(
            "2026-12-06T10:00:00Z",
            "bbb",
            "ccc",
            &[("c", Verdict::Unchanged, 1.0)],
        );
        let path = file_of(dir.path(), &a.class);
        assert_eq!(
            append(dir.path(), std::slice::from_ref(&a)).unwrap()[0].1,
            1
        );
        std::fs::write(
            &path,
            std::fs::read_to_string(&path).unwrap() + "{\"schema\": \"nbody-bench-gate-verd",
        )
        .unwrap();
        // The same run again is not a second line; a new one is, after the damage.
        assert_eq!(append(dir.path(), &[a.clone(), b.clone()]).unwrap()[0].1, 1);
        let v = read(&path).unwrap();
        assert_eq!(v.runs, [a, b.clone()]);
        assert_eq!(v.bad.len(), 1);
        assert_eq!(v.bad[0].line, 2);
        assert!(v.bad[0].problem.contains("not a gate verdict line"));
        assert_eq!(v.latest(), Some(&b));
    }

    #[test]
    fn an_acceptance_round_trips_and_files_without_one_still_load() {
        let dir = tempfile::tempdir().unwrap();
        let mut accepted = run(
            "2026-12-07T10:00:00Z",
            "aaa",
            "bbb",
            &[
                ("c", Verdict::Regressed, 1.4),
                ("d", Verdict::Unchanged, 1.0),
            ],
        );
        accepted.acceptance = Some(Acceptance {
            accepted: "2026-12-07T10:05:00Z".into(),
            class: accepted.class.clone(),
            replaced_commit: "aaa".into(),
            new_commit: "bbb".into(),
            reason: "the exact kernel is slower on purpose".into(),
            cases: vec![AcceptedCase {
                key: "c".into(),
                ratio: 1.4,
                ci95: [1.3, 1.5],
            }],
        });
        let plain = run("2026-12-06T10:00:00Z", "aaa", "aaa", &[]);
        append(dir.path(), &[plain.clone(), accepted.clone()]).unwrap();
        let path = file_of(dir.path(), &plain.class);
        let text = std::fs::read_to_string(&path).unwrap();
        // A run without an acceptance is written as before the field existed.
        assert!(
            !text.lines().next().unwrap().contains("acceptance"),
            "{text}"
        );
        let v = read(&path).unwrap();
        assert!(v.bad.is_empty(), "{:?}", v.bad);
        assert_eq!(v.runs, [plain, accepted]);
        // Readers ignore fields they do not know, so an older reader takes the line for the
        // run it is; and a field added later is ignored here the same way.
        let later = text
            .lines()
            .nth(1)
            .unwrap()
            .replacen('{', "{\"added_later\":1,", 1);
        assert_eq!(parse(&later).runs.len(), 1);
    }

    /// Every verdict file committed in results/history loads whole: CI on every machine class
    /// reads them.
    #[test]
    fn the_committed_verdict_files_load() {
        let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../results/history");
        let mut seen = 0;
        for entry in std::fs::read_dir(&dir).unwrap().flatten() {
            let path = entry.path();
            if path.to_string_lossy().ends_with(".gate.jsonl") {
                let v = read(&path).unwrap();
                assert!(v.bad.is_empty(), "{}: {:?}", path.display(), v.bad);
                assert!(!v.runs.is_empty(), "{}", path.display());
                seen += 1;
            }
        }
        assert!(seen > 0, "no verdict file in {}", dir.display());
    }

    #[test]
    fn a_gate_report_gives_the_ratio_it_was_judged_on() {
        let json = serde_json::json!({
            "schema": GATE_REPORT_SCHEMA, "threshold": 0.03, "judged_on": "raw",
            "baseline": {"git_commit": "aaa", "git_dirty": false, "started": "2026-12-05T12:00:00Z",
                         "cpu_signature": "GenuineIntel 6/106/6", "logical_cpus": 4},
            "current": {"git_commit": "bbb", "git_dirty": true, "started": "2026-12-05T12:00:01Z",
                        "cpu_signature": "GenuineIntel 6/106/6", "logical_cpus": 4},
            "cases": [{"key": "k", "verdict": "improved", "ratio": 0.70, "ci95": [0.69, 0.71],
                       "raw_ratio": 0.73, "raw_ci95": [0.72, 0.74], "notes": []}],
            "missing": [{"key": "gone", "reason": "not measured"}], "extra": [], "warnings": []
        })
        .to_string();
        let here = crate::gate::route::this_machine();
        let r = GateRun::from_report_json(&json, &here).unwrap();
        assert_eq!(r.class, "GenuineIntel-6-106-6-4cpu");
        assert_eq!((r.base.as_str(), r.current.as_str()), ("aaa", "bbb"));
        assert!(r.current_dirty && !r.base_dirty);
        assert_eq!(r.measured, "2026-12-05T12:00:01Z");
        assert_eq!(r.cases[0].ratio, 0.73);
        assert_eq!(r.cases[0].ci95, [0.72, 0.74]);
        assert_eq!(r.cases[0].verdict, Verdict::Improved);
        assert_eq!(r.missing, ["gone"]);
        let other = json.replace(GATE_REPORT_SCHEMA, "nbody-bench/gate/v9");
        assert!(
            GateRun::from_report_json(&other, &here)
                .unwrap_err()
                .contains("gate/v9")
        );
    }
}
