//! How each external program of a sweep was run, said from its `[[external]]` entry in the
//! sweep's config (as the results file keeps it) and the cases it measured, never from what a
//! config is expected to hold: a comparison names exactly what it compares against.

use super::tables;
use crate::analysis::Analysis;
use crate::analysis::groups::Point;
use crate::units::{Duration, Percent};
use nbody_engine::output::neutral::markdown::{self, code};
use nbody_records::external::config::TimeUnit;
use nbody_records::external::{External, TimeSource};
use std::fmt::Write;

/// A Markdown list with one item per external program of the sweep: its version, command line
/// (under the config's `[mpi]` launcher when it has one), environment, workers, steps per run, how it was timed and its untimed setup. Empty when the
/// sweep declared none.
pub fn external_runs(a: &Analysis) -> String {
    if a.external_runs.is_empty() {
        return String::new();
    }
    let mut md = String::from(
        "How each program ran, from its `[[external]]` entry in the sweep's config (`{…}` is filled in \
         for each case: `{threads}` and `{ranks}` with its workers, `{steps}` with the steps of one run, \
         `{n}`, `{seed}`, `{scenario}` and `{theta}` with the case's, `{workdir}` with its directory, \
         `{config_dir}` with the config's and `{nbody_bench}` with this program):\n\n",
    );
    for e in &a.external_runs {
        let version = a
            .metadata
            .externals
            .iter()
            .find(|v| v.name == e.name)
            .map_or(String::new(), |v| {
                format!(" ({})", markdown::text(&v.version))
            });
        let _ = write!(
            md,
            "- {}{version}: {}",
            code(&e.name),
            code(&command_line(
                &[&a.external_launcher[..], &e.command[..]].concat()
            ))
        );
        if !e.env.is_empty() {
            let env: Vec<String> = e.env.iter().map(|(k, v)| format!("{k}={v}")).collect();
            let _ = write!(md, ", environment {}", code(&command_line(&env)));
        }
        let _ = write!(md, "; {}", workers(a, &e.name));
        let _ = write!(md, "; {} steps per run, {}", e.steps.describe(), timing(e));
        if e.warmup_runs > 0 {
            let _ = write!(md, ", after {} untimed runs each round", e.warmup_runs);
        }
        if !e.setup.is_empty() {
            let _ = write!(
                md,
                "; set up (untimed) by {}",
                code(&command_line(&e.setup))
            );
        }
        md.push_str(".\n");
    }
    md
}

/// The workers of the program's measured cases, e.g. "threads × ranks 1 × 1, 1 × 2".
fn workers(a: &Analysis, name: &str) -> String {
    let mut seen: Vec<(usize, usize)> = a
        .cases
        .iter()
        .filter(|p| p.case.kernel.name() == name)
        .map(|p| (p.threads, p.ranks))
        .collect();
    seen.sort_unstable();
    seen.dedup();
    if seen.is_empty() {
        return "no case measured".into();
    }
    let pairs: Vec<String> = seen.iter().map(|(t, r)| format!("{t} × {r}")).collect();
    format!("threads × ranks {}", pairs.join(", "))
}

fn timing(e: &External) -> String {
    match &e.time {
        TimeSource::Wall(_) => "timed by its wall time from start to exit".into(),
        TimeSource::Regex(r) => {
            let unit = match r.unit {
                TimeUnit::S => "seconds",
                TimeUnit::Ms => "milliseconds",
                TimeUnit::Us => "microseconds",
                TimeUnit::Ns => "nanoseconds",
            };
            format!(
                "timed by the number it prints ({}, in {unit})",
                code(&r.regex)
            )
        }
    }
}

/// Tokens as a shell would need them: a token with anything but plain characters in single
/// quotes (placeholders stay as they are), so that the line reads as the argv it was.
pub(crate) fn command_line(tokens: &[String]) -> String {
    let plain = |c: char| c.is_ascii_alphanumeric() || "-_./{}=:,+@%".contains(c);
    tokens
        .iter()
        .map(|t| {
            if !t.is_empty() && t.chars().all(plain) {
                t.clone()
            } else {
                format!("'{}'", t.replace('\'', "'\\''"))
            }
        })
        .collect::<Vec<_>>()
        .join(" ")
}

/// The phases external programs timed themselves, case by case: each phase per step with its
/// share of the step, then the serial and the communication shares. Empty when no case has any.
pub fn external_phases(a: &Analysis) -> String {
    use nbody_records::external::PhaseKind;
    let cases: Vec<&Point> = a
        .cases
        .iter()
        .filter(|c| !c.named_phases.is_empty())
        .collect();
    if cases.is_empty() {
        return String::new();
    }
    let mut t = tables::Table::new([
        "scenario",
        "case",
        "time per step (mean)",
        "phases per step (share of the step)",
        "serial share",
        "communication share",
    ])
    .aligned([
        tables::Align::Default,
        tables::Align::Default,
        tables::Align::Right,
        tables::Align::Default,
        tables::Align::Right,
        tables::Align::Right,
    ]);
    for c in cases {
        // The phases are means over the case's runs: their shares are of the mean step time
        // of the same runs, not of the median.
        let mean = c.mean_step_s();
        let step = mean.max(f64::MIN_POSITIVE);
        let share_of = |kind: PhaseKind| -> Option<f64> {
            let of: Vec<f64> = c
                .named_phases
                .iter()
                .filter(|p| p.kind == kind)
                .map(|p| p.s_per_step)
                .collect();
            (!of.is_empty()).then(|| of.iter().sum::<f64>() / step)
        };
        let phases: Vec<String> = c
            .named_phases
            .iter()
            .map(|p| {
                let kind = match p.kind {
                    PhaseKind::Parallel => String::new(),
                    k => format!(" ({})", k.name()),
                };
                format!(
                    "{}{kind}: {} ({})",
                    markdown::text(&p.name),
                    Duration(p.s_per_step),
                    Percent(p.s_per_step / step)
                )
            })
            .collect();
        let share = |s: Option<f64>| s.map_or(tables::NONE.to_string(), |s| Percent(s).to_string());
        t.row([
            c.case.scenario.name().to_string(),
            format!(
                "{}{}",
                crate::render::analysis_figures::case_label(c),
                tables::over(c.oversubscribed)
            ),
            Duration(mean).to_string(),
            phases.join("<br>"),
            share(share_of(PhaseKind::Serial)),
            share(share_of(PhaseKind::Comm)),
        ]);
    }
    t.markdown()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_command_line_quotes_only_what_a_shell_would_split() {
        let argv: Vec<String> = [
            "lmp",
            "-sf",
            "opt",
            "-var",
            "data",
            "{workdir}/state.data",
            "a b",
            "it's",
            "",
        ]
        .iter()
        .map(|s| s.to_string())
        .collect();
        assert_eq!(
            command_line(&argv),
            "lmp -sf opt -var data {workdir}/state.data 'a b' 'it'\\''s' ''"
        );
        assert_eq!(code("x`y"), "``x`y``");
    }
}
