//! The Markdown summary of an analysis: tables of the fits, then the figures.

use super::figures::Figure;
use super::{Analysis, Fitted};
use crate::commands::fmt_ns;
use crate::fit::Estimate;
use std::fmt::Write;

/// `0.123 [0.101, 0.150]` with `digits` decimals.
pub fn est(e: &Estimate, digits: usize) -> String {
    format!(
        "{:.d$} [{:.d$}, {:.d$}]",
        e.estimate,
        e.ci95[0],
        e.ci95[1],
        d = digits
    )
}

/// A percentage estimate, e.g. `3.1% [2.4%, 3.9%]`.
pub fn est_percent(e: &Estimate) -> String {
    format!(
        "{:.1}% [{:.1}%, {:.1}%]",
        100.0 * e.estimate,
        100.0 * e.ci95[0],
        100.0 * e.ci95[1]
    )
}

fn failed<T>(f: &Fitted<T>) -> String {
    format!("not fitted: {}", f.error.as_deref().unwrap_or("unknown"))
}

/// Seconds as a readable duration.
pub fn secs(s: f64) -> String {
    fmt_ns(s * 1e9)
}

pub fn markdown(a: &Analysis, figures: &[Figure]) -> String {
    let mut md = String::new();
    let _ = writeln!(
        md,
        "# Analysis of sweep `{}` ({:?} study)\n",
        a.name, a.study
    );
    let _ = writeln!(md, "{}\n", super::figures::caption(a));
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
    if !a.complexity.is_empty() {
        md.push_str("## Cost vs n\n\n| series | scenario | exponent k [95% CI] | class (LOO SMAPE) | largest n: time/step | ns/particle-step |\n|---|---|---|---|---|---|\n");
        for c in &a.complexity {
            let Some(last) = c.points.last() else {
                continue;
            };
            let fit = match &c.fit.fit {
                Some(f) => format!(
                    "{} | {} ({:.1}%)",
                    est(&f.exponent, 2),
                    f.class.name(),
                    f.selected.loo_smape_percent
                ),
                None => format!("{} | –", failed(&c.fit)),
            };
            let _ = writeln!(
                md,
                "| {} | {} | {fit} | n={}: {} | {:.1} |",
                c.label,
                c.series.scenario.name(),
                last.n,
                secs(last.median_s),
                last.ns_per_particle_step
            );
        }
        md.push('\n');
    }
    if !a.crossovers.is_empty() {
        md.push_str("## Crossovers\n\n");
        for x in &a.crossovers {
            let _ = writeln!(md, "- {}", super::crossover_sentence(x));
        }
        md.push('\n');
    }
    if !a.strong.is_empty() {
        md.push_str("## Strong scaling\n\n| scenario | series | n | p | speedup [95% CI] | efficiency | vs hardware ceiling |\n|---|---|---|---|---|---|---|\n");
        for s in &a.strong {
            if s.measured.is_empty() {
                let _ = writeln!(
                    md,
                    "| {} | {} | – | – | {} | | |",
                    s.series.scenario.name(),
                    s.label,
                    failed(&s.fit)
                );
                continue;
            }
            for p in &s.measured {
                let over = s
                    .points
                    .iter()
                    .any(|c| c.p() as f64 == p.p && c.oversubscribed);
                let _ = writeln!(
                    md,
                    "| {} | {} | {} | {}{} | {} | {:.2} | {} |",
                    s.series.scenario.name(),
                    s.label,
                    s.series.n.unwrap_or(0),
                    p.p,
                    if over { " (oversubscribed)" } else { "" },
                    est(&p.speedup, 2),
                    p.efficiency.estimate,
                    p.speedup_vs_ceiling
                        .as_ref()
                        .map(|e| format!("{:.2}", e.estimate))
                        .unwrap_or_else(|| "–".into())
                );
            }
        }
        md.push_str("\n| scenario | series | n | Amdahl f [95% CI] | max speedup 1/f | Karp-Flatt trend | f from phase timers |\n|---|---|---|---|---|---|---|\n");
        for s in &a.strong {
            let Some(f) = &s.fit.fit else { continue };
            let timed = s
                .timed_serial
                .as_ref()
                .map(|t| format!("{:.2}%", 100.0 * t.fraction))
                .unwrap_or_else(|| "–".into());
            let max = if f.max_speedup.estimate.is_finite() {
                format!("{:.1}", f.max_speedup.estimate)
            } else {
                "unbounded".into()
            };
            let _ = writeln!(
                md,
                "| {} | {} | {} | {} | {max} | {} | {timed} |",
                s.series.scenario.name(),
                s.label,
                s.series.n.unwrap_or(0),
                est_percent(&f.serial_fraction),
                f.karp_flatt_trend.verdict.name()
            );
        }
        md.push('\n');
    }
    if !a.weak.is_empty() {
        md.push_str("## Weak scaling\n\n| series | p: n, efficiency [95% CI] | Gustafson serial fraction α |\n|---|---|---|\n");
        for w in &a.weak {
            let Some(f) = &w.fit.fit else {
                let _ = writeln!(md, "| {} | {} | |", w.label, failed(&w.fit));
                continue;
            };
            let cells: Vec<String> = w
                .measured
                .iter()
                .map(|e| {
                    let n = w
                        .points
                        .iter()
                        .find(|c| c.p() as f64 == e.p)
                        .map(|c| c.n)
                        .unwrap_or(0);
                    format!("p={} n={n}: {}", e.p, est(&e.e, 2))
                })
                .collect();
            let _ = writeln!(
                md,
                "| {} | {} | {} |",
                w.label,
                cells.join("; "),
                est_percent(&f.serial_fraction)
            );
        }
        md.push('\n');
    }
    if !a.theta.is_empty() {
        md.push_str("## Octree accuracy vs cost\n\n| series | θ | time/step | median / max relative force error |\n|---|---|---|---|\n");
        for t in &a.theta {
            for p in &t.points {
                let err = p
                    .force_error
                    .map(|[m, x]| format!("{m:.2e} / {x:.2e}"))
                    .unwrap_or_else(|| "not measured".into());
                let _ = writeln!(
                    md,
                    "| {} | {} | {} | {err} |",
                    t.label,
                    p.theta.unwrap_or(f64::NAN),
                    secs(p.median_s)
                );
            }
        }
        md.push('\n');
    }
    let flagged: Vec<_> = a.cases.iter().filter(|c| !c.sanity_ok).collect();
    if !flagged.is_empty() {
        md.push_str("## Physics checks that failed\n\n");
        for c in flagged {
            let _ = writeln!(
                md,
                "- {}: energy drift {:.2e} over the limit",
                c.key, c.max_energy_drift
            );
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
