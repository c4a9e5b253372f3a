//! The report's distributed-tree section: bytes per step of the three decompositions of a
//! galaxy counted out to 128 ranks, the α-β prediction of their communication time on each
//! transport next to what the weak-scaling sweeps measured there, and the load imbalance of
//! the centrally concentrated cloud.

use super::keep::region;
use crate::analysis::tree_comm::{TREE_DECOMPS, Transport, TreeComm};
use crate::render::tables::{self, Table};
use crate::units::{Bytes, Duration, WithCi};
use nbody_engine::output::neutral::markdown::{self, code};
use std::fmt::Write;

pub fn section(md: &mut String, tree: Option<&TreeComm>, no_notes: &str) {
    md.push_str(
        "\n## Distributed Barnes-Hut: replicated data, octants, locally essential trees\n\n",
    );
    let Some(t) = tree else {
        md.push_str(
            "No weak-scaling sweep of the galaxy over MPI (configs/weak-mpi-tree.toml) and no \
             mpi-bench file to predict it with.\n\n",
        );
        md.push_str(&region("distributed-tree", no_notes));
        return;
    };
    let _ = writeln!(
        md,
        "Bytes sent per step per rank, **counted** (not measured) on the galaxy's initial cloud of \
         n = {}·p bodies at θ = {}, leaf size {}, by running each decomposition's selection without \
         MPI (`decomp::model`): allgather sends every owned position to every rank; octants sends its \
         top nodes to every rank and each group of bodies whose walk of another rank's top nodes must \
         open a node to that rank, which answers with its forces; tree sends each rank the nodes and \
         bodies of its tree that the rank's domain needs. Body imbalance = max/mean bodies per rank \
         (octants keeps the octants of the root cube, the bisection balances).\n",
        t.n_per_rank, t.theta, t.leaf_size
    );
    md.push_str(&counted_table(t).markdown());
    md.push('\n');
    for tr in &t.transports {
        transport(md, tr);
    }
    md.push_str(&region("distributed-tree", no_notes));
}

/// Counted bytes per step per rank count: allgather, octants (mean and max, with the body
/// imbalance) and tree, and tree's share of allgather's bytes. A rank count missing one of the
/// decompositions is left out.
fn counted_table(t: &TreeComm) -> Table {
    let mut table = Table::new([
        "ranks",
        "n",
        "allgather bytes",
        "octants bytes (max)",
        "octants body imbalance",
        "tree bytes (max)",
        "tree ÷ allgather",
    ]);
    let mut ranks: Vec<usize> = t.counted.iter().map(|c| c.ranks).collect();
    ranks.dedup();
    for p in ranks {
        let get = |d| t.counted.iter().find(|c| c.ranks == p && c.decomp == d);
        let [Some(a), Some(o), Some(tr)] = TREE_DECOMPS.map(get) else {
            continue;
        };
        table.row([
            p.to_string(),
            a.n.to_string(),
            Bytes(a.bytes_mean).to_string(),
            format!("{} ({})", Bytes(o.bytes_mean), Bytes(o.bytes_max)),
            format!("{:.2}", o.bodies_imbalance),
            format!("{} ({})", Bytes(tr.bytes_mean), Bytes(tr.bytes_max)),
            if a.bytes_mean > 0.0 {
                format!("{:.3}", tr.bytes_mean / a.bytes_mean)
            } else {
                "–".into()
            },
        ]);
    }
    table
}

/// One transport: its α-β fit and the table of predicted against measured communication, or
/// why the fit failed (then no table).
fn transport(md: &mut String, tr: &Transport) {
    let _ = write!(
        md,
        "**{}**, α-β from the ping-pong of {}",
        markdown::text(&tr.name),
        code(&tr.bench)
    );
    match &tr.alpha_beta.fit {
        Some(f) => {
            let _ = writeln!(
                md,
                ": α = {:.3} [{:.3}, {:.3}] µs, β = {:.4} [{:.4}, {:.4}] ns/byte. Predicted \
                 transfer per step (latencies × α + counted bytes × β, 95% band of the fit) next \
                 to the sweep `{}` run on the same transport: per step, the mean over ranks of \
                 the bytes sent, of the time inside MPI, and of its transfer part (that time \
                 less the estimated wait for slower ranks, which the model does not predict); \
                 error = measured transfer ÷ predicted − 1. * = oversubscribed: every time \
                 then includes waiting for a CPU.\n",
                f.alpha.estimate * 1e6,
                f.alpha.ci95[0] * 1e6,
                f.alpha.ci95[1] * 1e6,
                f.beta.estimate * 1e9,
                f.beta.ci95[0] * 1e9,
                f.beta.ci95[1] * 1e9,
                tr.sweep.as_deref().unwrap_or("(none)")
            );
        }
        None => {
            let _ = writeln!(
                md,
                ": the fit failed ({}).\n",
                tr.alpha_beta.error.as_deref().unwrap_or("")
            );
            return;
        }
    }
    md.push_str(&transport_table(tr).markdown());
    md.push('\n');
}

/// Per decomposition and rank count above one: counted and measured bytes, predicted and
/// measured time, the error and the compute imbalance. Unmeasured rank counts above 8 are
/// left out except 128, to keep the table short.
fn transport_table(tr: &Transport) -> Table {
    let mut table = Table::new([
        "decomposition",
        "ranks",
        "bytes counted",
        "bytes measured",
        "predicted transfer/step",
        "measured in MPI/step",
        "of it transfer",
        "error",
        "compute imbalance",
    ]);
    for d in TREE_DECOMPS {
        for r in tr.rows.iter().filter(|r| r.decomp == d && r.ranks > 1) {
            let measured = r.measured_s.is_some();
            if !measured && r.ranks > 8 && r.ranks != 128 {
                continue;
            }
            table.row([
                d.name().to_string(),
                format!("{}{}", r.ranks, tables::over(r.oversubscribed)),
                Bytes(r.predicted_bytes).to_string(),
                r.measured_bytes
                    .map_or("–".into(), |b| Bytes(b).to_string()),
                WithCi::new(r.predicted_s, r.predicted_ci95, Duration).to_string(),
                r.measured_s.map_or("–".into(), |s| Duration(s).to_string()),
                r.measured_transfer_s
                    .map_or("–".into(), |s| Duration(s).to_string()),
                r.error()
                    .map_or("–".into(), |e| format!("{:+.0}%", 100.0 * e)),
                r.compute_imbalance
                    .map_or("–".into(), |i| format!("{i:.3}")),
            ]);
        }
    }
    table
}
