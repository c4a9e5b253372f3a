//! The report's communication section: the Coulomb MPI tutorial's computation/communication split of the
//! MPI runs, the α-β fit and its prediction beyond this machine.

use super::Sweep;
use super::keep::region;
use crate::analysis::comm_model::{CommModel, Prediction};
use crate::plot::figures::{self as fig, CommTimes, Curve, Measured};
use crate::plot::{Axis, Unit};
use crate::render::analysis_figures::Figure;
use crate::render::tables::{self, Table};
use crate::units::{Duration, Plain, WithCi};
use nbody_engine::decomp::Decomposition;
use nbody_engine::output::neutral::markdown::{self, code};
use std::fmt::Write;
use std::path::Path;

/// The fitted model and where its figures are, relative to the report.
pub struct Comm {
    pub model: CommModel,
    pub(crate) figures_dir: String,
    pub figures: Vec<Figure>,
}

/// Measured communication per step of `decomp` at each rank count of the MPI sweep.
fn measured(weak_mpi: Option<&Sweep>, decomp: Decomposition) -> Vec<Measured> {
    let Some(s) = weak_mpi else { return Vec::new() };
    s.analysis
        .cases
        .iter()
        .filter(|c| c.decomp == Some(decomp) && c.ranks > 1)
        .filter_map(|c| {
            Some(Measured::new(c.ranks as f64, c.comm_s_per_step?).oversubscribed(c.oversubscribed))
        })
        .collect()
}

fn curve(label: &str, points: &[Prediction]) -> Curve {
    let pts: Vec<_> = points.iter().filter(|p| p.ranks > 1).collect();
    Curve::new(
        label,
        pts.iter().map(|p| (p.ranks as f64, p.seconds)).collect(),
    )
    .with_band(
        pts.iter()
            .map(|p| (p.ranks as f64, p.ci95[0], p.ci95[1]))
            .collect(),
    )
}

/// Draws measured vs predicted communication for both decompositions into `dir`.
pub(crate) fn comm_figures(
    model: &CommModel,
    weak_mpi: Option<&Sweep>,
    dir: &Path,
) -> (Vec<Figure>, Vec<String>) {
    let caption = weak_mpi
        .map(|s| crate::render::analysis_figures::caption(&s.analysis))
        .unwrap_or_else(|| model.source.clone());
    let mut figures = Vec::new();
    let mut errors = Vec::new();
    for (decomp, points) in [
        (Decomposition::Allgather, &model.allgather),
        (Decomposition::Domain, &model.domain),
    ] {
        if points.is_empty() {
            continue;
        }
        let comm = CommTimes {
            x: Axis::log("MPI ranks p (n = n₀·p)").unit(Unit::Count),
            measured: measured(weak_mpi, decomp),
            predicted: curve(&format!("α-β prediction ({})", decomp.name()), points),
        };
        let mut chart = fig::comm_time(&comm, &caption);
        chart.title = format!(
            "Communication per step, {}: measured vs predicted",
            decomp.name()
        );
        let stem = format!("comm-{}", decomp.name());
        match crate::plot::draw(&chart, dir, &stem) {
            Ok(_) => figures.push(Figure {
                stem,
                title: chart.title.clone(),
            }),
            Err(e) => errors.push(format!("{stem}: {e}")),
        }
    }
    (figures, errors)
}

pub fn section(md: &mut String, sweeps: &[Sweep], comm: Option<&Comm>, no_notes: &str) {
    md.push_str("\n## Communication vs computation (MPI)\n\n");
    let mpi: Vec<&Sweep> = sweeps
        .iter()
        .filter(|s| s.analysis.cases.iter().any(|c| c.decomp.is_some()))
        .collect();
    if mpi.is_empty() && comm.is_none() {
        md.push_str("No MPI sweep or mpi-bench file (configs/weak-mpi.toml, `mpirun -n 2 nbody-bench mpi-bench`).\n\n");
    }
    for s in &mpi {
        let _ = writeln!(
            md,
            "From {}: per step, the mean over ranks of the time inside MPI calls (the Coulomb MPI tutorial's communication \
             time) and of the bytes sent, next to the step time. * = oversubscribed (more ranks than logical CPUs).\n",
            code(&s.analysis.source)
        );
        let mut table = Table::new([
            "decomposition",
            "ranks",
            "n",
            "time/step",
            "communication/step",
            "share",
            "bytes sent/step/rank",
        ]);
        for c in s.analysis.cases.iter().filter(|c| c.decomp.is_some()) {
            let comm_s = c.comm_s_per_step.unwrap_or(0.0);
            table.row([
                c.decomp.map_or("", |d| d.name()).to_string(),
                format!("{}{}", c.ranks, tables::over(c.oversubscribed)),
                c.n.to_string(),
                Duration(c.median_s).to_string(),
                Duration(comm_s).to_string(),
                format!("{:.1}%", 100.0 * comm_s / c.median_s.max(f64::MIN_POSITIVE)),
                format!("{:.0}", c.bytes_per_step.unwrap_or(0.0)),
            ]);
        }
        md.push_str(&table.markdown());
        md.push('\n');
    }
    if let Some(c) = comm {
        let m = &c.model;
        match &m.alpha_beta.fit {
            Some(f) => {
                let _ = writeln!(
                    md,
                    "α-β fit of the ping-pong in {} ({} ranks{}): latency α = {:.3} µs, inverse bandwidth β = {:.4} ns/byte \
                     (bootstrap 95% CIs). **Prediction** (not measured) for a weak-scaling series of lj-box with \
                     n = {}·p, f32: replicated data moves every position each step (⌈log2 p⌉ latencies + the gathered \
                     bytes), the spatial decomposition only ghosts within rc of the region borders.\n",
                    code(&m.source),
                    m.bench_ranks,
                    if m.bench_oversubscribed {
                        ", oversubscribed"
                    } else {
                        ""
                    },
                    WithCi::of(&f.alpha.map(|a| a * 1e6), Plain),
                    WithCi::of(&f.beta.map(|b| b * 1e9), Plain),
                    m.n_per_rank
                );
                let mut table = Table::new([
                    "ranks",
                    "n",
                    "allgather bytes/rank",
                    "allgather predicted",
                    "domain bytes/rank",
                    "domain predicted",
                ]);
                for (a, d) in m.allgather.iter().zip(&m.domain) {
                    table.row([
                        a.ranks.to_string(),
                        a.n.to_string(),
                        format!("{:.0}", a.bytes_per_rank),
                        WithCi::new(a.seconds, a.ci95, Duration).to_string(),
                        format!("{:.0}", d.bytes_per_rank),
                        WithCi::new(d.seconds, d.ci95, Duration).to_string(),
                    ]);
                }
                md.push_str(&table.markdown());
                md.push('\n');
            }
            None => {
                let _ = writeln!(
                    md,
                    "The α-β fit of {} failed: {}\n",
                    code(&m.source),
                    markdown::text(m.alpha_beta.error.as_deref().unwrap_or(""))
                );
            }
        }
        for f in &c.figures {
            let _ = writeln!(md, "![{}]({}/{}.svg)\n", f.title, c.figures_dir, f.stem);
        }
    }
    md.push_str(&region("communication", no_notes));
}
