//! REPORT.md's section on the O(n²) family: the tables of `render::family_tables` for the
//! sweeps that compare the whole family over threads. Each sweep's `summary.md` has every
//! family it measured; the report keeps to those that answer both questions (what Newton's
//! third law gains, and what per-thread's threads gain over it).

use super::Sweep;
use super::keep::region;
use crate::analysis::family::Family;
use crate::render::family_tables;
use nbody_engine::kernels::KernelKind;
use nbody_engine::output::neutral::markdown::code;
use std::fmt::Write;

pub(crate) fn section(md: &mut String, sweeps: &[Sweep], no_notes: &str) {
    md.push_str("\n## The O(n²) family: naive, symmetric and per-thread side by side\n\n");
    let shown: Vec<(&Sweep, Vec<Family>)> = super::sources_section::own(sweeps)
        .filter_map(|s| {
            let families: Vec<Family> = s
                .analysis
                .family
                .iter()
                .filter(|f| compares_threads(f))
                .cloned()
                .collect();
            (!families.is_empty()).then_some((s, families))
        })
        .collect();
    if shown.is_empty() {
        md.push_str(
            "No sweep measured symmetric on one thread and per-thread on several at the same n \
             (configs/quick.toml does).\n\n",
        );
    } else {
        let _ = writeln!(
            md,
            "{} Shown for each sweep that measured symmetric on one thread and per-thread on \
             several thread counts at the same scenario and n; each sweep's `summary.md` has \
             every family it measured.\n",
            family_tables::note()
        );
    }
    for (s, families) in shown {
        let _ = writeln!(md, "From {}.\n", code(&s.analysis.source));
        md.push_str(&family_tables::markdown(&families));
    }
    md.push_str(&region("family", no_notes));
}

/// Symmetric measured on one thread and per-thread on more than one thread count.
fn compares_threads(f: &Family) -> bool {
    let measured = |k: KernelKind| {
        f.rows
            .iter()
            .filter(move |r| r.kernel == k && r.case.is_some())
    };
    measured(KernelKind::Symmetric).count() == 1 && measured(KernelKind::PerThread).count() >= 2
}
