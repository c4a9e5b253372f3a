//! REPORT.md's section on the 3-D periodic benchmark the field quotes (LAMMPS's `bench/in.lj`,
//! our `lj-melt`): for each sweep that ran it beside other codes, one row per code and one
//! column per n and worker count, each code's fastest run against our fastest kernel
//! ([`crate::analysis::each_program`]). Each code then reads off where it stands against a
//! target of its own, where the peers table sets each of our kernels against the fastest of
//! all of them.

use super::Sweep;
use super::keep::region;
use crate::analysis::each_program::{self, System};
use crate::render::tables::{Table, over};
use crate::units::{Plain, WithCi};
use nbody_engine::output::neutral::markdown::code;
use std::fmt::Write;

pub(crate) fn section(md: &mut String, sweeps: &[Sweep], no_notes: &str) {
    md.push_str("\n## The 3-D periodic melt: LAMMPS's `in.lj` against every code\n\n");
    let shown: Vec<(&Sweep, Vec<System>)> = sweeps
        .iter()
        .filter_map(|s| {
            let systems: Vec<System> = each_program::systems(&s.analysis.cases)
                .into_iter()
                .filter(|sys| sys.scenario.dim() == 3 && sys.scenario.periodic())
                .collect();
            (!systems.is_empty()).then_some((s, systems))
        })
        .collect();
    if shown.is_empty() {
        md.push_str(
            "No sweep ran a 3-D periodic scenario beside other codes \
             (configs/vs-lammps-melt.toml does).\n\n",
        );
    } else {
        md.push_str(
            "The benchmark molecular-dynamics codes quote: a Lennard-Jones melt on an fcc lattice \
             at density 0.8442, T = 1.44, cutoff 2.5σ, skin 0.3σ, time step 0.005τ, in a periodic \
             cube, every code from the same exported atoms. Each column is one n and worker \
             count; the first row is our fastest kernel there, each other row one code at its \
             fastest run of that column (its threads or ranks named) with theirs ÷ ours and its \
             bootstrap 95% CI (above 1: ours is faster). How each code ran, and its slower runs, \
             are under \"Against established codes\". * = oversubscribed.\n\n",
        );
    }
    for (s, systems) in shown {
        let _ = writeln!(md, "From {}.\n", code(&s.analysis.source));
        md.push_str(&table(&systems));
        md.push('\n');
    }
    md.push_str(&region("melt", no_notes));
}

/// One row per code, one column per system.
fn table(systems: &[System]) -> String {
    let mut header = vec!["code".to_string()];
    header.extend(systems.iter().map(|s| {
        format!(
            "{} n = {}, {} worker{}",
            s.scenario.name(),
            s.n,
            s.workers,
            if s.workers == 1 { "" } else { "s" }
        )
    }));
    let mut table = Table::new(header);
    let mut row = vec!["ours (fastest kernel): ns/particle-step [95% CI]".to_string()];
    row.extend(systems.iter().map(|s| {
        format!(
            "{}: {:.1}",
            s.ours,
            WithCi::new(s.ours_ns, s.ours_ci_ns, Plain)
        )
    }));
    table.row(row);
    let mut names: Vec<&str> = Vec::new();
    for p in systems.iter().flat_map(|s| &s.programs) {
        if !names.contains(&p.name.as_str()) {
            names.push(&p.name);
        }
    }
    for name in names {
        let mut row = vec![format!("{name}: theirs ÷ ours [95% CI] (ns/particle-step)")];
        row.extend(systems.iter().map(|s| {
            match s.programs.iter().find(|p| p.name == name) {
                None => "–".to_string(),
                Some(p) => {
                    let ratio = match p.speedup_ci {
                        Some(ci) => format!("{:.2}", WithCi::new(p.speedup, ci, Plain)),
                        None => format!("{:.2}", p.speedup),
                    };
                    // The label past the name: how the workers were split, if not one.
                    let split = p.label.strip_prefix(name).unwrap_or("");
                    format!("{ratio}{} ({:.1}{split})", over(p.oversubscribed), p.ns)
                }
            }
        }));
        table.row(row);
    }
    table.markdown()
}
