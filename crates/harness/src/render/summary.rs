//! The Markdown summary of one analysis (`summary.md`): the tables of [`super::tables`], the
//! failed physics checks, then the figures.

use super::analysis_figures::Figure;
use super::tables;
use crate::analysis::Analysis;
use nbody_engine::output::neutral::markdown::code;
use std::fmt::Write;

/// The text of `summary.md` for `a`, linking `figures` as `<stem>.svg` beside it.
pub fn markdown(a: &Analysis, figures: &[Figure]) -> String {
    let mut md = String::new();
    let _ = writeln!(
        md,
        "# Analysis of sweep {} ({:?} study)\n",
        code(&a.name),
        a.study
    );
    let _ = writeln!(md, "{}\n", super::analysis_figures::caption(a));
    if let Some(c) = &a.calibration {
        let _ = writeln!(md, "Machine: {}\n", c.summary());
    }
    if !a.incomplete.is_empty() {
        let _ = writeln!(
            md,
            "{} case(s) not complete and left out (resume the sweep to finish them).\n",
            a.incomplete.len()
        );
    }
    md.push_str(&failed_cases(a));
    if !a.complexity.is_empty() {
        let _ = writeln!(
            md,
            "## Cost vs n\n\n{} {}\n\n{}",
            tables::complexity_note(),
            tables::peak_note(),
            tables::complexity(a)
        );
        let notes = tables::complexity_notes(a);
        if !notes.is_empty() {
            let _ = writeln!(md, "What the fits cannot tell:\n\n{notes}");
        }
    }
    if !a.crossovers.is_empty() {
        let _ = writeln!(md, "## Crossovers\n\n{}", tables::crossovers(a));
    }
    if !a.family.is_empty() {
        let _ = write!(
            md,
            "## The O(n²) family side by side\n\n{}\n\n{}",
            super::family_tables::note(),
            super::family_tables::markdown(&a.family)
        );
    }
    if !a.strong.is_empty() {
        let _ = writeln!(
            md,
            "## Strong scaling\n\n* = more workers than logical CPUs (oversubscribed).\n\n{}",
            tables::strong(a)
        );
        md.push_str(&tables::strong_notes(a));
        let comparisons = tables::serial_comparisons(a);
        if !comparisons.is_empty() {
            let _ = writeln!(md, "Timed vs fitted serial fraction:\n\n{comparisons}");
        }
    }
    if !a.weak.is_empty() {
        let _ = writeln!(
            md,
            "## Weak scaling\n\n* = oversubscribed.\n\n{}",
            tables::weak(a)
        );
        md.push_str(&tables::weak_notes(a));
    }
    let phases = super::runs::external_phases(a);
    if !phases.is_empty() {
        let _ = writeln!(
            md,
            "## Phases the programs timed\n\nEach program's own phase times (`phases` in its \
             [[external]] entry), per step: means over the successful runs, shares of their mean step \
             time. \
             * = oversubscribed.\n\n{phases}"
        );
    }
    if !a.theta.is_empty() {
        let _ = writeln!(md, "## Octree accuracy vs cost\n\n{}", tables::theta(a));
    }
    if !a.peers.is_empty() {
        let _ = writeln!(
            md,
            "## Against the external programs\n\n{}\n{}\n{}",
            super::runs::external_runs(a),
            tables::peers(a),
            tables::peers_equal_error(a)
        );
    }
    if !a.cases.is_empty() {
        let _ = writeln!(md, "## Energy checks\n\n{}", tables::sanity([a], false));
    }
    let flagged: Vec<_> = a
        .cases
        .iter()
        .filter_map(|c| Some((c, c.max_energy_drift?)).filter(|_| c.sanity_ok == Some(false)))
        .collect();
    if !flagged.is_empty() {
        md.push_str("## Physics checks that failed\n\n");
        for (c, drift) in flagged {
            let _ = writeln!(md, "- {}: energy drift {drift:.2e} over the limit", c.key);
        }
        md.push('\n');
    }
    if !figures.is_empty() {
        md.push_str("## Figures\n\n");
        for f in figures {
            let _ = writeln!(md, "![{}]({}.svg)\n", f.title, f.stem);
        }
    }
    md
}

/// The cases that failed, each with why: a summary that left them out silently would read as
/// if they had never been planned.
fn failed_cases(a: &Analysis) -> String {
    if a.failed.is_empty() {
        return String::new();
    }
    let mut md = format!(
        "## Failed cases\n\n{} case(s) have no successful sample and are left out of the \
         tables and figures:\n\n",
        a.failed.len()
    );
    for f in &a.failed {
        let why = match f.reasons.as_slice() {
            [] => "no reason recorded".to_string(),
            [one] => one.clone(),
            [first, rest @ ..] => format!("{first}; and {} more", rest.len()),
        };
        let _ = writeln!(md, "- `{}`: {}", f.key, why.replace('\n', " "));
    }
    md.push('\n');
    md
}
