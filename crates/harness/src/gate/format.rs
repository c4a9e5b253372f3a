//! Renderings of a [`GateReport`]: a terminal table, Markdown for a CI job summary
//! (`>> $GITHUB_STEP_SUMMARY`), and JSON (schema `nbody-bench/gate/v1`).

use super::checks::short;
use super::{CaseComparison, GateReport, Normalization, Verdict};
use crate::render::tables::{Align, Table};
use crate::units::Duration;
use nbody_engine::output::neutral::control;
use nbody_engine::output::neutral::markdown::{self, cell_code, code};
use std::fmt::Write;

/// How a gate report is printed (`--format`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Format {
    /// Plain text for a terminal: the verdict, both runs' origins and a table of the cases.
    Text,
    /// Markdown made for a CI job summary (`>> $GITHUB_STEP_SUMMARY`).
    Markdown,
    /// Pretty-printed JSON of the whole report (schema `nbody-bench/gate/v1`), newline-terminated.
    Json,
}

/// The report rendered in `format`.
pub fn formatted(report: &GateReport, format: Format) -> String {
    match format {
        // Keys and machine names come from the results files: no control character of theirs
        // reaches the terminal.
        Format::Text => control::visible_lines(&text(report)).into_owned(),
        Format::Markdown => markdown(report),
        Format::Json => {
            serde_json::to_string_pretty(report).expect("gate report serializes") + "\n"
        }
    }
}

/// "3 cases: 1 regressed, 0 improved, 2 unchanged, 0 unknown (threshold ±10%)".
fn headline(report: &GateReport) -> String {
    let mut s = format!(
        "{} cases: {} regressed, {} improved, {} unchanged, {} unknown (threshold ±{}%)",
        report.cases.len(),
        report.count(Verdict::Regressed),
        report.count(Verdict::Improved),
        report.count(Verdict::Unchanged),
        report.count(Verdict::Unknown),
        percent(report.threshold)
    );
    if !report.missing.is_empty() {
        s += &format!(", {} missing", report.missing.len());
    }
    if report.work_changed() > 0 {
        s += &format!(", work changed in {}", report.work_changed());
    }
    s
}

/// The normalisations used, e.g. "the reference workload timed around each case".
fn normalizations(report: &GateReport) -> String {
    let mut used: Vec<Normalization> = Vec::new();
    for c in &report.cases {
        if !used.contains(&c.normalization) {
            used.push(c.normalization);
        }
    }
    if used.is_empty() {
        return "-".to_string();
    }
    used.iter()
        .map(|n| n.describe())
        .collect::<Vec<_>>()
        .join("; ")
}

/// Which ratio the verdicts come from, in words.
fn judged_on(judged: super::Judged) -> &'static str {
    match judged {
        super::Judged::Normalized => "the normalised ratio",
        super::Judged::Raw => "the raw ratio",
        super::Judged::Both => "each of the normalised and the raw ratio",
    }
}

fn percent(fraction: f64) -> String {
    let p = format!("{:.2}", fraction * 100.0);
    p.trim_end_matches('0').trim_end_matches('.').to_string()
}

fn origin(info: &super::RunInfo) -> String {
    format!(
        "{}{} ({}, {})",
        short(&info.git_commit),
        if info.git_dirty { "+dirty" } else { "" },
        info.started,
        info.cpu_model.as_deref().unwrap_or("unknown CPU")
    )
}

fn text(report: &GateReport) -> String {
    let mut s = String::new();
    let verdict = if report.failed() {
        "FAIL"
    } else if !report.missing.is_empty() {
        "INCOMPLETE"
    } else {
        "ok"
    };
    let _ = writeln!(s, "gate {verdict}: {}", headline(report));
    let _ = writeln!(s, "baseline {}", origin(&report.baseline));
    let _ = writeln!(s, "current  {}", origin(&report.current));
    let _ = writeln!(s, "times normalised by {}", normalizations(report));
    let _ = writeln!(s, "{}\n", rule(report));
    let r = Align::Right;
    let header = [
        "case",
        "baseline",
        "current",
        "ratio",
        "family CI",
        "raw",
        "raw family CI",
        "adj. p",
        "rounds",
        "verdict",
    ];
    let mut table =
        Table::new(header).aligned([Align::Default, r, r, r, r, r, r, r, r, Align::Default]);
    for c in &report.cases {
        let verdict = match c.verdict {
            Verdict::Regressed => verdict_word(c).to_uppercase(),
            _ => verdict_word(c),
        };
        table.row([
            c.key.clone(),
            Duration(c.baseline_median_s).to_string(),
            Duration(c.current_median_s).to_string(),
            format!("{:.3}", c.ratio),
            interval(c.family_ci),
            format!("{:.3}", c.raw_ratio),
            interval(c.raw_family_ci),
            adjusted(c.adjusted_p),
            units(report, c),
            verdict + &notes(c).map(|n| format!("  ({n})")).unwrap_or_default(),
        ]);
    }
    s += &table.text();
    for line in findings(report) {
        let _ = writeln!(s, "{line}");
    }
    s
}

fn markdown(report: &GateReport) -> String {
    let mut s = String::new();
    let status = if report.failed() {
        "regression found"
    } else if !report.missing.is_empty() {
        "incomplete"
    } else {
        "no regression"
    };
    let _ = writeln!(s, "### Performance gate: {status}\n");
    let _ = writeln!(s, "{}.\n", headline(report));
    let _ = writeln!(
        s,
        "Baseline {}, current {}; times normalised by {}. {}\n",
        code(&origin(&report.baseline)),
        code(&origin(&report.current)),
        normalizations(report),
        markdown::text(&rule(report))
    );
    // Numbers line up on their last digit; the case and the verdict are words.
    let (word, number) = (Align::Default, Align::Right);
    let mut table = Table::new([
        "case",
        "baseline",
        "current",
        "ratio",
        "family CI",
        "raw ratio",
        "raw family CI",
        "adj. p",
        "rounds",
        "verdict",
    ])
    .aligned([
        word, number, number, number, number, number, number, number, number, word,
    ]);
    for c in &report.cases {
        let word = verdict_word(c);
        let verdict = match c.verdict {
            Verdict::Regressed => format!("**{word}**"),
            _ => word.to_string(),
        };
        table.row([
            cell_code(&c.key),
            Duration(c.baseline_median_s).to_string(),
            Duration(c.current_median_s).to_string(),
            format!("{:.3}", c.ratio),
            interval(c.family_ci),
            format!("{:.3}", c.raw_ratio),
            interval(c.raw_family_ci),
            adjusted(c.adjusted_p),
            units(report, c),
            format!(
                "{verdict}{}",
                notes(c)
                    .map(|n| format!(" ({})", markdown::text(&n)))
                    .unwrap_or_default()
            ),
        ]);
    }
    s += &table.markdown();
    let lines = findings(report);
    if !lines.is_empty() {
        s += "\n";
        // Keys, reasons and warnings quote the results files: text, never markup.
        for line in lines {
            let _ = writeln!(s, "- {}", markdown::text(&line));
        }
    }
    s
}

/// How verdicts were reached, as one sentence for the report's head.
fn rule(report: &GateReport) -> String {
    let looks = if report.looks > 1 {
        format!(
            " in up to {} looks (each at {}%, undecided cases measured further)",
            report.looks,
            percent(report.family_alpha / report.looks as f64)
        )
    } else {
        String::new()
    };
    format!(
        "A case regresses when {} lies above {:.2}, at a family-wise error of {}% over the \
         cases{looks} (Holm's step-down on one-sided t p-values from {}); it is unchanged when \
         its 90% interval lies within ±{}%, unknown when neither. The family CI is the interval \
         at the level the verdicts used: wholly past a margin, the case is flagged.",
        judged_on(report.judged_on),
        1.0 + report.threshold,
        percent(report.family_alpha),
        match (report.pairing, report.sides) {
            (super::paired::Pairing::Rounds, Some(super::duet::Sides::Duet)) => {
                "pairs of rounds measured at the same moment, one build per CPU"
            }
            (super::paired::Pairing::Rounds, _) => "pairs of back-to-back rounds",
            (super::paired::Pairing::Independent, _) => "the two runs' samples",
        },
        percent(super::sequential::EQUIVALENCE * report.threshold),
    )
}

fn interval([lo, hi]: [f64; 2]) -> String {
    if lo.is_finite() && hi.is_finite() {
        format!("[{lo:.3}, {hi:.3}]")
    } else {
        "–".to_string()
    }
}

fn adjusted(p: f64) -> String {
    if p < 1e-4 {
        "<0.0001".to_string()
    } else {
        format!("{p:.4}")
    }
}

/// Rounds (or samples) per side the case was judged on, with its look when several.
fn units(report: &GateReport, c: &CaseComparison) -> String {
    let n = if c.units[0] == c.units[1] {
        c.units[0].to_string()
    } else {
        format!("{}/{}", c.units[0], c.units[1])
    };
    if report.looks > 1 {
        format!("{n} (look {})", c.look)
    } else {
        n
    }
}

/// "regressed", or "unchanged, work changed" when the counters differ.
fn verdict_word(c: &CaseComparison) -> String {
    let mut w = c.verdict.name().to_string();
    if !c.work_changes.is_empty() {
        w += ", work changed";
    }
    w
}

fn notes(c: &CaseComparison) -> Option<String> {
    (!c.notes.is_empty()).then(|| c.notes.join("; "))
}

/// Lines after the table: missing and extra cases, work changes, warnings.
fn findings(report: &GateReport) -> Vec<String> {
    let mut out = Vec::new();
    for m in &report.missing {
        out.push(format!("missing: {} ({})", m.key, m.reason));
    }
    for key in &report.extra {
        out.push(format!("extra (no baseline): {key}"));
    }
    for c in &report.cases {
        for w in &c.work_changes {
            out.push(format!(
                "work changed: {} {}: {} -> {}",
                c.key, w.counter, w.baseline, w.current
            ));
        }
    }
    let unknown: Vec<String> = report
        .cases
        .iter()
        .filter(|c| c.verdict == Verdict::Unknown)
        .map(|c| c.key.clone())
        .collect();
    if !unknown.is_empty() {
        let how = match report.pairing {
            super::paired::Pairing::Independent => {
                // The commit comes from the baseline file: only a commit id is offered as part
                // of a command to run.
                let commit = short(&report.baseline.git_commit);
                if !commit.is_empty() && commit.bytes().all(|b| b.is_ascii_hexdigit()) {
                    format!(
                        "measure them side by side with the baseline's revision: `nbody-bench \
                         gate --against {commit}`"
                    )
                } else {
                    "measure them side by side with the baseline's revision (`nbody-bench gate \
                     --against REV`)"
                        .to_string()
                }
            }
            super::paired::Pairing::Rounds => {
                "measure more rounds (`--max-rounds`) or on a quieter machine".to_string()
            }
        };
        out.push(format!(
            "unknown: {} case(s) neither shown changed nor shown unchanged ({}); {how}",
            unknown.len(),
            super::listed(&unknown)
        ));
    }
    for w in &report.warnings {
        out.push(format!("warning: {w}"));
    }
    out
}
