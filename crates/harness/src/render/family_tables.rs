//! The O(n²) family's tables ([`crate::analysis::family`]): one per scenario, precision and n,
//! a row per kernel and thread count, in `summary.md` and REPORT.md alike.

use super::tables::{Align, NONE, Table};
use crate::analysis::family::{Family, FamilyCase, FamilyRow};
use crate::units::{Duration, Plain, WithCi};
use nbody_engine::kernels::KernelKind;
use std::fmt::Write;

/// The paragraph that says what the family's tables show.
pub fn note() -> &'static str {
    "`naive` evaluates every pair from both ends (n(n−1) pair evaluations per step), `symmetric` \
     each pair once and applies the reaction by Newton's third law (n(n−1)/2, on one thread), \
     `per-thread` splits symmetric's pairs over threads, each with a private force buffer, and \
     sums the buffers. Pair evaluations per step are the work counters the results recorded. \
     Newton-3 gain = naive's time ÷ symmetric's, one thread each: **2 is the ideal** (half the \
     pair evaluations); below 2, writing the reactions costs part of what the halved pairs save. \
     Speedup = symmetric's time on one thread ÷ per-thread's on p threads, beside the calibrated \
     p-thread ceiling (the throughput ratio of an embarrassingly parallel loop); ÷ ceiling is the \
     share of that ceiling reached. Medians with bootstrap 95% CIs; – = not measured."
}

/// Every family of `families`, each under a bold line naming its scenario, precision and n;
/// empty without any.
pub fn markdown(families: &[Family]) -> String {
    let mut md = String::new();
    for f in families {
        let _ = writeln!(
            md,
            "**{}, {}, n = {}**\n\n{}",
            f.scenario.name(),
            f.precision.name(),
            f.n,
            table(f).markdown()
        );
    }
    md
}

/// One family as a table: naive and symmetric on one thread, then per-thread by threads.
pub fn table(f: &Family) -> Table {
    let r = Align::Right;
    let mut t = Table::new([
        "kernel",
        "threads",
        "time/step [95% CI]",
        "pair evals/step",
        "pair evals/s",
        "Newton-3 gain (ideal 2)",
        "speedup over symmetric",
        "÷ ceiling",
        "ceiling",
        "note",
    ])
    .aligned([Align::Default, r, r, r, r, r, r, r, r, Align::Default]);
    for row in &f.rows {
        t.row(cells(f, row));
    }
    t
}

fn cells(f: &Family, row: &FamilyRow) -> Vec<String> {
    let gain = match row.kernel {
        KernelKind::Symmetric => f
            .newton3_gain
            .as_ref()
            .map_or(NONE.to_string(), |g| format!("{:.2}", WithCi::of(g, Plain))),
        _ => String::new(),
    };
    let head = [row.kernel.name().to_string(), row.threads.to_string()];
    let Some(c) = &row.case else {
        let ratios = ratio_cells(row.kernel, None);
        let missing = [NONE, NONE, NONE].map(String::from);
        return head
            .into_iter()
            .chain(missing)
            .chain([gain])
            .chain(ratios)
            .chain([String::new()])
            .collect();
    };
    let measured = [
        WithCi::new(c.median_s, c.ci95_s, Duration).to_string(),
        c.pair_checks_per_step
            .map_or(NONE.to_string(), |p| format!("{p:.0}")),
        c.pair_evals_per_s
            .map_or(NONE.to_string(), |r| format!("{r:.2e}")),
    ];
    head.into_iter()
        .chain(measured)
        .chain([gain])
        .chain(ratio_cells(row.kernel, Some(c)))
        .chain([row_note(c)])
        .collect()
}

/// Per-thread's speedup over symmetric, that over the ceiling, and the ceiling; blank for the
/// other kernels, `–` where a value is missing.
fn ratio_cells(kernel: KernelKind, c: Option<&FamilyCase>) -> [String; 3] {
    if kernel != KernelKind::PerThread {
        return Default::default();
    }
    let speedup = c.and_then(|c| c.speedup_over_symmetric.as_ref());
    let ceiling = c.and_then(|c| c.ceiling).filter(|h| *h > 0.0);
    [
        speedup.map_or(NONE.to_string(), |s| format!("{:.2}", WithCi::of(s, Plain))),
        match (speedup, ceiling) {
            (Some(s), Some(h)) => format!("{:.2}", s.estimate / h),
            _ => NONE.to_string(),
        },
        ceiling.map_or(NONE.to_string(), |h| format!("{h:.2}x")),
    ]
}

/// What the numbers of a row do not say: it ran on one thread, or time-shared the CPUs.
fn row_note(c: &FamilyCase) -> String {
    let mut notes: Vec<&str> = c.one_thread.iter().map(|o| o.label()).collect();
    if c.oversubscribed {
        notes.push("oversubscribed");
    }
    notes.join("; ")
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::analysis::family::{families, tests::point};
    use nbody_records::results::ResultsFile;

    #[test]
    fn synthetic_family_reads_gain_speedup_and_ceiling() {
        let cases = [
            point(KernelKind::Naive, 2000, 1, 2.0e-3),
            point(KernelKind::Symmetric, 2000, 1, 1.0e-3),
            point(KernelKind::PerThread, 2000, 1, 1.0e-3),
            point(KernelKind::PerThread, 2000, 2, 0.55e-3),
        ];
        let mut f = families(&cases, None).remove(0);
        f.rows[3].case.as_mut().unwrap().ceiling = Some(1.95);
        let md = table(&f).markdown();
        let lines: Vec<&str> = md.lines().collect();
        assert_eq!(lines.len(), 2 + 4, "{md}");
        assert!(lines[0].contains("Newton-3 gain (ideal 2)"), "{md}");
        // Naive: n(n-1) pair evaluations; symmetric: half, and the gain of 2.00.
        assert!(lines[2].starts_with("| naive | 1 | 2.000 ms"), "{md}");
        assert!(lines[2].contains("| 3998000 |"), "{md}");
        assert!(lines[3].contains("| 1999000 |"), "{md}");
        assert!(lines[3].contains("| 2.00 ["), "{md}");
        // Per-thread on 2 threads: 1.82 over symmetric, 0.93 of the 1.95 ceiling.
        assert!(lines[5].contains("| 1.82 ["), "{md}");
        assert!(lines[5].contains("| 0.93 | 1.95x |"), "{md}");
        // Without a calibration the one-thread row has no ceiling: a dash, never 0.
        assert!(lines[4].ends_with("| – | – | |"), "{md}");
    }

    #[test]
    fn a_missing_case_is_a_dash_and_a_small_step_is_labelled() {
        let cases = [
            point(KernelKind::Naive, 500, 1, 2.0e-4),
            point(KernelKind::PerThread, 500, 2, 1.0e-4),
        ];
        let md = markdown(&families(&cases, None));
        assert!(md.starts_with("**lj-box, f32, n = 500**\n\n"), "{md}");
        let symmetric = md.lines().find(|l| l.starts_with("| symmetric")).unwrap();
        assert_eq!(symmetric, "| symmetric | 1 | – | – | – | – | | | | |");
        let two = md
            .lines()
            .find(|l| l.starts_with("| per-thread | 2"))
            .unwrap();
        assert!(
            two.ends_with("| – | – | – | ran on 1 thread (too small to fork) |"),
            "{two}"
        );
        assert!(!md.contains("| 0 |"), "{md}");
    }

    #[test]
    fn the_quick_sweep_has_a_family_per_scenario_and_n() {
        let path = concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../../results/quick/results.json"
        );
        let results = ResultsFile::load(std::path::Path::new(path)).unwrap();
        let a = crate::analysis::analyze(&results, std::path::Path::new(path)).unwrap();
        let md = markdown(&a.family);
        for head in [
            "**lj-box, f32, n = 2000**",
            "**lj-box, f32, n = 8000**",
            "**galaxy, f64, n = 2000**",
            "**galaxy, f64, n = 8000**",
        ] {
            assert!(md.contains(head), "{head} missing:\n{md}");
        }
        // Every table: naive, symmetric, per-thread on 1 and 2 threads, all measured.
        assert_eq!(a.family.len(), 4);
        for f in &a.family {
            assert_eq!(f.rows.len(), 4);
            assert!(f.rows.iter().all(|r| r.case.is_some()));
            let gain = f.newton3_gain.as_ref().unwrap().estimate;
            assert!(gain > 0.5 && gain < 3.0, "{gain}");
            // The work counters: naive evaluates twice the pairs of symmetric.
            let pairs = |i: usize| f.rows[i].case.as_ref().unwrap().pair_checks_per_step;
            assert_eq!(pairs(0), pairs(1).map(|p| 2.0 * p));
        }
        // Quick's n are above the fork threshold: per-thread's 2-thread rows fork.
        assert_eq!(md.matches("ran on 1 thread (too small to fork)").count(), 0);
    }
}
