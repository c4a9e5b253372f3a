//! REPORT.md's comparison with the source documents, generated from the sweeps that redo their
//! studies: the Barnes-Hut report's strong scaling over MPI processes at 2000 bodies and its two
//! weak-scaling studies (`seeds-mpi-strong`, `seeds-weak`, `seeds-weak-time`), the LJ-box
//! assignment's codes as a function of n and p (`course-codes`, the course's C codes beside our
//! kernels, and `seeds`), and the Coulomb tutorial's split of communication and computation (its
//! code in `course-codes`). Every number comes from those results files.

use super::Sweep;
use super::keep::region;
use crate::analysis::Analysis;
use crate::render::tables;
use crate::units::Percent;
use nbody_engine::output::neutral::markdown::code;
use nbody_records::external::PhaseKind;
use std::fmt::Write;

/// The sweeps this section shows; the other sections leave them to it.
const SOURCE_STUDIES: [&str; 5] = [
    "course-codes",
    "seeds",
    "seeds-weak",
    "seeds-weak-time",
    "seeds-mpi-strong",
];

pub(crate) fn redoes_a_source_study(a: &Analysis) -> bool {
    SOURCE_STUDIES.contains(&a.name.as_str())
}

/// The sweeps of a section: not those that redo a source document's study (the comparison with
/// the source documents shows them).
pub(crate) fn own(sweeps: &[Sweep]) -> impl Iterator<Item = &Sweep> {
    sweeps
        .iter()
        .filter(|s| !redoes_a_source_study(&s.analysis))
}

fn named<'a>(sweeps: &'a [Sweep], name: &str) -> Option<&'a Sweep> {
    sweeps.iter().find(|s| s.analysis.name == name)
}

pub(crate) fn section(md: &mut String, sweeps: &[Sweep], no_notes: &str) {
    md.push_str("\n## Comparison with the source documents\n\n");
    md.push_str(
        "The studies of the three source documents, redone at this machine's scale by the sweeps \
         named below (`docs/explanation/sources.md` says what each document does, what the harness \
         takes from it and what its code gets wrong).\n",
    );
    barnes_hut(md, sweeps);
    lj_box(md, sweeps);
    coulomb(md, sweeps);
    md.push_str(&region("sources", no_notes));
}

fn missing(md: &mut String, config: &str) {
    let _ = writeln!(
        md,
        "Not measured yet: `{config}` has no results in this report's results directory \
         (`scripts/report.sh` runs it).\n"
    );
}

fn barnes_hut(md: &mut String, sweeps: &[Sweep]) {
    md.push_str(
        "\n### The Barnes-Hut report: 2000 bodies over MPI processes, and weak scaling\n\n",
    );
    match named(sweeps, "seeds-mpi-strong").filter(|s| !s.analysis.strong.is_empty()) {
        None => missing(md, "configs/seeds-mpi-strong.toml"),
        Some(s) => {
            let a = &s.analysis;
            let _ = writeln!(
                md,
                "Strong scaling of the galaxy at 2000 bodies over MPI ranks, split by the report's \
                 octants and by locally essential trees, from {}. Speedup T(1)/T(p) with 95% CI; \
                 * = more ranks than logical CPUs (left out of the fits). The report times its \
                 sequential phases to estimate the serial fraction; the harness does the same with its \
                 phase timers and sets the result beside the fraction fitted to the speedups:\n",
                code(&a.source)
            );
            md.push_str(&tables::strong(a));
            md.push_str(&tables::after_table(&tables::strong_notes(a)));
            md.push('\n');
            md.push_str(&tables::serial_comparisons(a));
            md.push('\n');
            s.figure_links(md, "speedup-");
        }
    }
    for (name, what) in [
        (
            "seeds-weak",
            "the bodies doubled with the workers (2000 per worker)",
        ),
        (
            "seeds-weak-time",
            "2000 bodies, the simulated time doubled with the workers",
        ),
    ] {
        match named(sweeps, name).filter(|s| !s.analysis.weak.is_empty()) {
            None => missing(md, &format!("configs/{name}.toml")),
            Some(s) => {
                let a = &s.analysis;
                let _ = writeln!(
                    md,
                    "Weak scaling, {what}, from {}: efficiency T(1)/T(p) with 95% CI and \
                     Gustafson's serial fraction.\n",
                    code(&a.source)
                );
                md.push_str(&tables::weak(a));
                md.push_str(&tables::after_table(&tables::weak_notes(a)));
                md.push('\n');
            }
        }
    }
}

fn lj_box(md: &mut String, sweeps: &[Sweep]) {
    md.push_str("\n### The LJ-box assignment: every code as a function of n and p\n\n");
    let Some(s) = named(sweeps, "course-codes") else {
        return missing(md, "configs/course-codes.toml");
    };
    let a = &s.analysis;
    let _ = writeln!(
        md,
        "The course's codes, written anew in C (`examples/course-codes/`: serial, OpenMP with \
         per-thread buffers, MPI with Allgatherv, and the Coulomb tutorial's MPI code), measured \
         beside our kernels in the same rounds, from {}. Each C code times its own phases; the \
         table gives them per step.\n",
        code(&a.source)
    );
    md.push_str(&crate::render::runs::external_phases(a));
    md.push_str(
        "\nEach of our kernels against the fastest C code at the same scenario, n and workers \
         (threads for ours, threads or ranks for theirs): \"theirs ÷ ours\" above 1 means ours is \
         faster.\n\n",
    );
    md.push_str(&tables::peers(a));
    md.push('\n');
    if !a.strong.is_empty() {
        md.push_str("Every code over its workers (÷ the calibrated ceiling for threads):\n\n");
        md.push_str(&tables::strong(a));
        md.push_str(&tables::after_table(&tables::strong_notes(a)));
        md.push('\n');
    }
    if !a.complexity.is_empty() {
        md.push_str("Growth with n, every code:\n\n");
        md.push_str(&tables::complexity(a));
        let notes = tables::complexity_notes(a);
        if !notes.is_empty() {
            let _ = write!(md, "\nWhat the fits cannot tell:\n\n{notes}");
        }
        md.push('\n');
    }
    s.figure_links(md, "phases-");
    if named(sweeps, "seeds").is_some_and(|s| !s.analysis.complexity.is_empty()) {
        md.push_str(
            "`results/seeds` measures our kernels alone over the same range on all three systems \
             (its summary.md has the tables).\n\n",
        );
    }
}

fn coulomb(md: &mut String, sweeps: &[Sweep]) {
    md.push_str("\n### The Coulomb tutorial: communication against computation\n\n");
    let Some(s) = named(sweeps, "course-codes") else {
        return missing(md, "configs/course-codes.toml");
    };
    let mut lines = Vec::new();
    let mut cases: Vec<_> = s
        .analysis
        .cases
        .iter()
        .filter(|c| c.case.kernel.name() == "coulomb_mpi" && c.ranks > 1)
        .collect();
    cases.sort_by_key(|c| (c.ranks, c.n));
    for c in cases {
        let comm: f64 = c
            .named_phases
            .iter()
            .filter(|p| p.kind == PhaseKind::Comm)
            .map(|p| p.s_per_step)
            .sum();
        let step = c.mean_step_s();
        if step <= 0.0 {
            continue;
        }
        lines.push(format!(
            "- n = {}, {} ranks{}: communication {} of the step (the Allgatherv, the wait for \
             slower ranks included, as the mean over ranks), computation the rest",
            c.n,
            c.ranks,
            tables::over(c.oversubscribed),
            Percent(comm / step),
        ));
    }
    if lines.is_empty() {
        md.push_str("No run of `coulomb_mpi` on more than one rank in `course-codes`.\n\n");
        return;
    }
    let _ = writeln!(
        md,
        "The tutorial times communication and computation apart; its code, written anew \
         (`coulomb_mpi`), does the same, from {}:\n",
        code(&s.analysis.source)
    );
    md.push_str(&lines.join("\n"));
    md.push_str("\n\n");
}
