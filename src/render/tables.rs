//! The tables of an analysis, as Markdown: cost vs n, strong scaling, weak scaling, octree
//! accuracy and the energy checks. `summary.md` and REPORT.md both print these, so a number, a
//! marker or a word reads the same in both: an oversubscribed case is marked `*`, an unbounded
//! speedup is `∞`, a missing value `–`.

use crate::analysis::groups::Point;
use crate::analysis::{Analysis, Fitted};
use crate::physics::LawKind;
use crate::units::{Duration, Percent, Plain, WithCi};
use std::fmt::Write;

/// What a cell shows when there is no value.
const NONE: &str = "–";

/// The marker of a case that ran more workers than logical CPUs.
fn over(oversubscribed: bool) -> &'static str {
    if oversubscribed { "*" } else { "" }
}

fn not_fitted<T>(f: &Fitted<T>) -> String {
    format!("not fitted: {}", f.error.as_deref().unwrap_or("unknown"))
}

/// The sentence that explains the peak column.
pub fn peak_note() -> String {
    format!(
        "\"Peak\" is the pair rate as a share of the calibrated FMA peak of the threads used, at a nominal \
         {} / {} / {} flops per LJ / gravity / Coulomb pair (f64 at half the f32 rate).",
        LawKind::LennardJones.flops_per_pair(),
        LawKind::Gravity.flops_per_pair(),
        LawKind::Coulomb.flops_per_pair()
    )
}

/// Cost vs n: per series, the n range, the time at the largest n, the rates, the fitted
/// exponent and the class chosen by cross-validation.
pub fn complexity(a: &Analysis) -> String {
    let mut md = String::from(
        "| scenario | kernel | n | time/step | ns/particle-step | pair-evals/s | peak | k [95% CI] | class (LOO SMAPE) |\n\
         |---|---|---|---|---|---|---|---|---|\n",
    );
    for c in &a.complexity {
        let (Some(first), Some(last)) = (c.points.first(), c.points.last()) else {
            continue;
        };
        let (k, class) = match &c.fit.fit {
            Some(f) => (
                format!("{:.2}", WithCi::of(&f.exponent, Plain)),
                format!("{} ({:.1}%)", f.class.name(), f.selected.loo_smape_percent),
            ),
            None => (NONE.into(), not_fitted(&c.fit)),
        };
        let peak = a
            .peak_share(last, c.series.scenario.law(), c.series.precision)
            .map_or(NONE.to_string(), |s| format!("{:.0}", Percent(s)));
        let _ = writeln!(
            md,
            "| {} | {} | {}–{} | {} | {:.1} | {:.2e} | {peak} | {k} | {class} |",
            c.series.scenario.name(),
            c.label,
            first.n,
            last.n,
            Duration(last.median_s),
            last.ns_per_particle_step,
            last.pair_evals_per_s,
        );
    }
    md
}

/// The crossovers of the fitted cost curves, one line each.
pub fn crossovers(a: &Analysis) -> String {
    let mut md = String::new();
    for x in &a.crossovers {
        let _ = writeln!(md, "- {}", crate::analysis::crossover_sentence(x));
    }
    md
}

fn oversubscribed_at(points: &[Point], p: f64) -> bool {
    points.iter().any(|c| c.has_workers(p) && c.oversubscribed)
}

/// Strong scaling: the speedup at each p (and over the calibrated ceiling), the Amdahl fit, its
/// bound, the Karp-Flatt trend and the serial fraction the phase timers measured.
pub fn strong(a: &Analysis) -> String {
    let mut md = String::from(
        "| scenario | kernel | n | speedup by p (÷ ceiling) | Amdahl f [95% CI] | 1/f | Karp-Flatt | f from phase timers |\n\
         |---|---|---|---|---|---|---|---|\n",
    );
    for st in &a.strong {
        let head = format!(
            "| {} | {} | {} |",
            st.series.scenario.name(),
            st.label,
            st.series.n.unwrap_or(0)
        );
        let Some(f) = &st.fit.fit else {
            let _ = writeln!(md, "{head} {} | | | | |", not_fitted(&st.fit));
            continue;
        };
        let cells: Vec<String> = st
            .measured
            .iter()
            .filter(|p| p.p > 1.0)
            .map(|p| {
                let rel = p
                    .speedup_vs_ceiling
                    .as_ref()
                    .map(|e| format!(" (÷ {:.2})", e.estimate))
                    .unwrap_or_default();
                format!(
                    "{}{}: {:.2}{rel}",
                    p.p,
                    over(oversubscribed_at(&st.points, p.p)),
                    WithCi::of(&p.speedup, Plain)
                )
            })
            .collect();
        let bound = if f.max_speedup.estimate.is_finite() {
            format!("{:.1}", f.max_speedup.estimate)
        } else {
            "∞".into()
        };
        let timed = st
            .timed_serial
            .as_ref()
            .map_or(NONE.to_string(), |t| format!("{:.2}", Percent(t.fraction)));
        let _ = writeln!(
            md,
            "{head} {} | {} | {bound} | {} | {timed} |",
            cells.join("<br>"),
            WithCi::of(&f.serial_fraction, Percent),
            f.karp_flatt_trend.verdict.name(),
        );
    }
    md
}

/// Each strong series' timed serial fraction next to the fitted one, one line each.
pub fn serial_comparisons(a: &Analysis) -> String {
    let mut md = String::new();
    for st in &a.strong {
        if let Some(c) = &st.serial_comparison {
            let _ = writeln!(
                md,
                "- {} {} n={}: {}",
                st.series.scenario.name(),
                st.label,
                st.series.n.unwrap_or(0),
                c.explanation
            );
        }
    }
    md
}

/// Weak scaling: n and the efficiency at each p, and Gustafson's serial fraction.
pub fn weak(a: &Analysis) -> String {
    let mut md =
        String::from("| scenario | kernel | p: n, efficiency | Gustafson α |\n|---|---|---|---|\n");
    for w in &a.weak {
        let head = format!("| {} | {} |", w.series.scenario.name(), w.label);
        let Some(f) = &w.fit.fit else {
            let _ = writeln!(md, "{head} {} | |", not_fitted(&w.fit));
            continue;
        };
        let cells: Vec<String> = w
            .measured
            .iter()
            .map(|e| {
                let c = w.points.iter().find(|c| c.has_workers(e.p));
                format!(
                    "{}{}: n={}, {:.2}",
                    e.p,
                    over(c.is_some_and(|c| c.oversubscribed)),
                    c.map_or(0, |c| c.n),
                    WithCi::of(&e.e, Plain)
                )
            })
            .collect();
        let _ = writeln!(
            md,
            "{head} {} | {} |",
            cells.join("<br>"),
            WithCi::of(&f.serial_fraction, Percent)
        );
    }
    md
}

/// θ of an octree or fmm case, with the expansion order when it is not the octree's
/// default monopole (the fmm's order always).
fn theta_cell(p: &crate::analysis::groups::Point) -> String {
    let theta = p.theta.map_or(NONE.to_string(), |t| t.to_string());
    match (p.case.multipole, p.case.order) {
        (_, Some(order)) => format!("{theta} (order {order})"),
        (crate::kernels::Multipole::Monopole, None) => theta,
        (m, None) => format!("{theta} ({})", m.name()),
    }
}

/// The octree over θ (one series per expansion order): time and the force error against an
/// f64 direct sum.
pub fn theta(a: &Analysis) -> String {
    let mut md = String::from(
        "| scenario | code | n | θ | time/step | µs/particle-step | median / max relative force error |\n\
         |---|---|---|---|---|---|---|\n",
    );
    for t in &a.theta {
        for p in &t.points {
            let error = p.force_error.map_or("not measured".to_string(), |[m, x]| {
                format!("{m:.2e} / {x:.2e}")
            });
            let _ = writeln!(
                md,
                "| {} | {} | {} | {} | {} | {:.2} | {error} |",
                t.series.scenario.name(),
                t.series.kernel.name(),
                p.n,
                theta_cell(p),
                Duration(p.median_s),
                p.ns_per_particle_step * 1e-3,
            );
        }
    }
    md
}

/// The energy check per scenario and kernel: cases, the largest drift, the cases flagged.
/// Rows only; `sweep` names the sweep in the first column when given.
pub fn sanity_rows(a: &Analysis, sweep: Option<&str>) -> String {
    let mut rows: Vec<(&Point, usize, f64, usize)> = Vec::new();
    for c in &a.cases {
        let same = |r: &&mut (&Point, usize, f64, usize)| {
            r.0.case.scenario == c.case.scenario && r.0.case.kernel == c.case.kernel
        };
        match rows.iter_mut().find(same) {
            Some(r) => {
                r.1 += 1;
                r.2 = r.2.max(c.max_energy_drift);
                r.3 += usize::from(!c.sanity_ok);
            }
            None => rows.push((c, 1, c.max_energy_drift, usize::from(!c.sanity_ok))),
        }
    }
    let mut md = String::new();
    for (c, cases, drift, flagged) in rows {
        let lead = sweep.map(|s| format!("| {s} ")).unwrap_or_default();
        let _ = writeln!(
            md,
            "{lead}| {} | {} | {cases} | {drift:.1e} | {flagged} |",
            c.case.scenario.name(),
            c.case.kernel.name()
        );
    }
    md
}

/// The header of the energy-check table, with or without the sweep column.
pub fn sanity_header(with_sweep: bool) -> &'static str {
    if with_sweep {
        "| sweep | scenario | kernel | cases | largest drift | flagged |\n|---|---|---|---|---|---|\n"
    } else {
        "| scenario | kernel | cases | largest drift | flagged |\n|---|---|---|---|---|\n"
    }
}

fn with_ci(estimate: f64, ci: [f64; 2]) -> WithCi<Plain> {
    WithCi {
        estimate: Plain(estimate),
        low: Plain(ci[0]),
        high: Plain(ci[1]),
    }
}

fn error_cell(e: Option<f64>) -> String {
    e.map_or(NONE.to_string(), |e| format!("{e:.2e}"))
}

/// Our kernels next to the external programs of the sweep: each of our cases against the
/// fastest external case of the same system and workers, time per particle-step of each with
/// its CI, the ratio theirs ÷ ours with its CI (above 1: ours is faster), the force errors where
/// measured and, when a peer ran in several ways, the slower runs beside it. Empty when the
/// sweep ran no external program next to a kernel.
pub fn peers(a: &Analysis) -> String {
    if a.peers.is_empty() {
        return String::new();
    }
    let errors = a
        .peers
        .iter()
        .any(|r| r.ours_error.is_some() || r.theirs_error.is_some());
    let others = a.peers.iter().any(|r| !r.others.is_empty());
    let mut md = format!(
        "| scenario | n | workers | ours | ns/particle-step [95% CI] | {} | ns/particle-step [95% CI] | theirs ÷ ours [95% CI] |",
        if others {
            "theirs (the fastest run)"
        } else {
            "theirs"
        }
    );
    let mut columns = 8;
    if errors {
        md.push_str(" median force error (ours / theirs) |");
        columns += 1;
    }
    if others {
        md.push_str(" their other runs: ns/particle-step (theirs ÷ ours) |");
        columns += 1;
    }
    md.push_str("\n|");
    md.push_str(&"---|".repeat(columns));
    md.push('\n');
    for r in &a.peers {
        let ratio = match r.speedup_ci {
            Some(ci) => format!("{:.2}", with_ci(r.speedup, ci)),
            None => format!("{:.2}", r.speedup),
        };
        let _ = write!(
            md,
            "| {} | {} | {}{} | {} | {:.1} | {} | {:.1} | {ratio} |",
            r.scenario,
            r.n,
            r.workers,
            over(r.oversubscribed),
            r.ours,
            with_ci(r.ours_ns, r.ours_ci_ns),
            r.theirs,
            with_ci(r.theirs_ns, r.theirs_ci_ns),
        );
        if errors {
            let _ = write!(
                md,
                " {} / {} |",
                error_cell(r.ours_error),
                error_cell(r.theirs_error)
            );
        }
        if others {
            let cell: Vec<String> = r
                .others
                .iter()
                .map(|o| {
                    format!(
                        "{}{}: {:.1} ({:.2})",
                        o.theirs,
                        over(o.oversubscribed),
                        o.theirs_ns,
                        o.speedup
                    )
                })
                .collect();
            let cell = if cell.is_empty() {
                NONE.to_string()
            } else {
                cell.join("; ")
            };
            let _ = write!(md, " {cell} |");
        }
        md.push('\n');
    }
    md
}

/// Tree codes at equal median force error: each code's time per step interpolated to it on
/// its sweep over θ, and the ratio. Empty when the sweep has no such pair of series.
pub fn peers_equal_error(a: &Analysis) -> String {
    if a.peers_equal_error.is_empty() {
        return String::new();
    }
    let mut md = String::from(
        "| scenario | n | workers | median error | ours | time/step | theirs | time/step | theirs ÷ ours |\n\
         |---|---|---|---|---|---|---|---|---|\n",
    );
    let cost = |s: Option<f64>, range: [f64; 2]| match s {
        Some(s) => Duration(s).to_string(),
        None => format!("outside the measured {:.1e}–{:.1e}", range[0], range[1]),
    };
    for r in &a.peers_equal_error {
        let _ = writeln!(
            md,
            "| {} | {} | {} | {:.0e} | {} | {} | {} | {} | {} |",
            r.scenario,
            r.n,
            r.workers,
            r.error,
            r.ours,
            cost(r.ours_s, r.ours_errors),
            r.theirs,
            cost(r.theirs_s, r.theirs_errors),
            r.speedup.map_or(NONE.to_string(), |s| format!("{s:.2}")),
        );
    }
    md
}
