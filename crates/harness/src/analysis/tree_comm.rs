//! The communication of the distributed Barnes-Hut trees for a weak-scaling series of the
//! galaxy (n = n₀·p): the bytes per step per rank of replicated data, the source's octants and
//! the locally essential trees, counted on the scenario's own cloud out to 128 ranks
//! (`decomp::model`, MPI-free), turned into seconds by the α-β fit of each transport's
//! `mpi-bench`, next to what the weak-scaling sweep measured under that transport.
//!
//! The counts are of the initial cloud (the step's migration is left out: a small fraction of
//! the bodies at the galaxy's time step), with the octants of the root cube and a bisection of
//! unit weights, as the drivers start. Latencies per step (each all-to-all counted as p − 1
//! messages, each collective as ⌈log2 p⌉): allgather ⌈log2 p⌉; octants 3⌈log2 p⌉ + 3(p − 1)
//! (status, top-node sizes and nodes; migration, requests, answers); tree ⌈log2 p⌉ + 2(p − 1)
//! (status; migration, essential trees).

use super::comm_model::{PREDICTED_RANKS, fit_ping_pong, in_sweep_dir, predict};
use super::groups::Point;
use super::{Analysis, Fitted};
use crate::fit::AlphaBetaFit;
use nbody_engine::decomp::octants::{Octants, root_cube};
use nbody_engine::decomp::orb::Orb;
use nbody_engine::decomp::{Decomposition, Domains, model};
use nbody_engine::kernels::Multipole;
use nbody_engine::scenario::ScenarioKind;
use nbody_engine::scenario::galaxy::galaxy;
use nbody_mpi::ranks::bench_file::MpiBenchFile;
use rayon::prelude::*;
use serde::Serialize;
use std::path::PathBuf;

/// Levels of top nodes the octant driver shares (`mpi::tree::octants::TOP_LEVELS`).
pub const TOP_LEVELS: u32 = 3;

/// The three decompositions a galaxy can run under.
pub(crate) const TREE_DECOMPS: [Decomposition; 3] = [
    Decomposition::Allgather,
    Decomposition::Octants,
    Decomposition::Tree,
];

/// Counted bytes per step of one decomposition at one rank count.
#[derive(Clone, Debug, Serialize)]
pub struct Counted {
    /// The rank count p.
    pub ranks: usize,
    /// The galaxy's bodies, `n_per_rank · p`.
    pub n: usize,
    /// The decomposition counted (allgather, octants or tree).
    pub decomp: Decomposition,
    /// Mean and largest over the ranks of the bytes sent per step.
    pub(crate) bytes_mean: f64,
    pub(crate) bytes_max: f64,
    /// Messages (latencies) per step per rank, from [`messages`].
    pub messages: f64,
    /// Max over mean of the bodies per rank (the load imbalance of the concentrated cloud).
    pub(crate) bodies_imbalance: f64,
}

/// One transport: its α-β fit, and per decomposition and rank count the predicted seconds
/// next to the measured ones.
#[derive(Clone, Debug, Serialize)]
pub(crate) struct Transport {
    pub name: String,
    pub bench: String,
    pub(crate) alpha_beta: Fitted<AlphaBetaFit>,
    pub sweep: Option<String>,
    pub rows: Vec<Row>,
}

/// One decomposition at one rank count under one transport: predicted next to measured.
#[derive(Clone, Debug, Serialize)]
pub struct Row {
    /// The rank count p.
    pub ranks: usize,
    /// The galaxy's bodies at p ranks.
    pub n: usize,
    /// The decomposition (allgather, octants or tree).
    pub decomp: Decomposition,
    pub(crate) predicted_bytes: f64,
    pub(crate) predicted_s: f64,
    pub(crate) predicted_ci95: [f64; 2],
    /// Measured by the sweep under this transport (mean over ranks, per step): bytes sent, time
    /// inside MPI, and of it the transfer (without the estimated wait for slower ranks), which
    /// is what the α-β model predicts.
    pub(crate) measured_bytes: Option<f64>,
    pub(crate) measured_s: Option<f64>,
    pub(crate) measured_transfer_s: Option<f64>,
    /// The measured case's mean over rounds of max/mean over ranks of the compute time;
    /// `None` when the sweep has no such case.
    pub compute_imbalance: Option<f64>,
    /// The measured case ran more workers than logical CPUs (false without a measured case).
    pub oversubscribed: bool,
}

impl Row {
    /// measured / predicted − 1 of the transfer time.
    pub fn error(&self) -> Option<f64> {
        let m = self.measured_transfer_s?;
        (self.predicted_s > 0.0).then(|| m / self.predicted_s - 1.0)
    }
}

#[derive(Clone, Debug, Serialize)]
pub(crate) struct TreeComm {
    pub(crate) n_per_rank: usize,
    pub theta: f64,
    pub leaf_size: usize,
    pub counted: Vec<Counted>,
    pub(crate) transports: Vec<Transport>,
}

fn log2_ceil(p: usize) -> f64 {
    (p as f64).log2().ceil()
}

/// Latencies per step (module doc).
pub fn messages(decomp: Decomposition, p: usize) -> f64 {
    if p <= 1 {
        return 0.0;
    }
    let all_to_all = (p - 1) as f64;
    match decomp {
        Decomposition::Allgather => log2_ceil(p),
        Decomposition::Octants => 3.0 * log2_ceil(p) + 3.0 * all_to_all,
        Decomposition::Tree => log2_ceil(p) + 2.0 * all_to_all,
        Decomposition::Domain => 0.0,
    }
}

/// Counts the three decompositions on the galaxy of `n_per_rank · p` bodies, for every `p`.
pub fn count(
    ranks: &[usize],
    n_per_rank: usize,
    seed: u64,
    theta: f64,
    leaf: usize,
) -> Vec<Counted> {
    ranks
        .par_iter()
        .flat_map_iter(|&p| count_one(p, n_per_rank * p, seed, theta, leaf))
        .collect()
}

/// The three decompositions counted on the galaxy of `n` bodies (in the scenario's f64) over
/// `p` ranks.
fn count_one(p: usize, n: usize, seed: u64, theta: f64, leaf: usize) -> Vec<Counted> {
    if n == 0 {
        return Vec::new();
    }
    let state = galaxy::<f64>(n, seed);
    let s = &state;
    let w = std::mem::size_of::<f64>();
    let summary = |decomp, bytes: Vec<f64>, counts: Vec<usize>| Counted {
        ranks: p,
        n,
        decomp,
        bytes_mean: bytes.iter().sum::<f64>() / bytes.len().max(1) as f64,
        bytes_max: bytes.iter().copied().fold(0.0, f64::max),
        messages: messages(decomp, p),
        bodies_imbalance: nbody_engine::decomp::stats::MinMeanMax::of(
            counts.iter().map(|&c| c as f64),
        )
        .imbalance(),
    };
    let mut out = Vec::new();
    let all = model::allgather_bytes_per_rank(n, p, 3, w);
    out.push(summary(Decomposition::Allgather, vec![all], vec![n / p; p]));
    let (lo, side) = root_cube(&s.pos);
    if let Ok(oct) = Octants::new(lo, side, p, &s.pos) {
        let bytes = model::octants_bytes_of_cloud(s, &oct, theta, leaf, TOP_LEVELS);
        out.push(summary(Decomposition::Octants, bytes, oct.counts(&s.pos)));
    }
    if let Ok(orb) = Orb::over(p, &s.pos, &vec![1.0; n]) {
        let bytes = model::tree_bytes_of_cloud(s, &orb, theta, leaf, Multipole::Monopole);
        out.push(summary(Decomposition::Tree, bytes, orb.counts(&s.pos)));
    }
    out
}

/// The distributed-tree model of `sweeps`, when one of them ran the galaxy under MPI: counted
/// at its smallest n per rank and its θ, with the α-β of every transport an mpi-bench file in
/// the directory of such a sweep (the same machine) was measured on.
pub(crate) fn choose(
    benches: &[(PathBuf, MpiBenchFile)],
    sweeps: &[&Analysis],
) -> Option<TreeComm> {
    let galaxy: Vec<&Analysis> = sweeps
        .iter()
        .copied()
        .filter(|a| {
            a.cases
                .iter()
                .any(|c| c.decomp.is_some() && c.case.scenario == ScenarioKind::Galaxy)
        })
        .collect();
    let cases = &galaxy.first()?.cases;
    let n_per_rank = cases
        .iter()
        .filter(|c| c.ranks > 0)
        .map(|c| c.n / c.ranks)
        .min()?;
    let defaults = nbody_engine::kernels::KernelParams::default();
    let theta = cases.iter().find_map(|c| c.theta).unwrap_or(defaults.theta);
    let names: Vec<&str> = galaxy.iter().map(|a| a.name.as_str()).collect();
    let benches: Vec<(String, &MpiBenchFile)> = benches
        .iter()
        .filter(|(p, _)| in_sweep_dir(p, &names))
        .map(|(p, b)| (p.to_string_lossy().replace('\\', "/"), b))
        .collect();
    let series: Vec<(String, &[Point])> = galaxy
        .iter()
        .map(|a| (a.name.clone(), a.cases.as_slice()))
        .collect();
    Some(tree_comm(
        n_per_rank,
        theta,
        defaults.leaf_size,
        &benches,
        &series,
    ))
}

/// The model and the measured side by side: `benches` are (path, file) of `mpi-bench` runs,
/// `sweeps` (name, points) of weak-scaling sweeps of the galaxy; a TCP bench goes with the
/// sweep whose name ends in `-tcp`, the other with the rest.
pub(crate) fn tree_comm(
    n_per_rank: usize,
    theta: f64,
    leaf_size: usize,
    benches: &[(String, &MpiBenchFile)],
    sweeps: &[(String, &[Point])],
) -> TreeComm {
    let counted = count(&PREDICTED_RANKS, n_per_rank, 1, theta, leaf_size);
    let mut transports = Vec::new();
    for tcp in [false, true] {
        let Some((bench_path, bench)) = benches
            .iter()
            .filter(|(_, b)| b.over_tcp() == tcp && !b.oversubscribed)
            .max_by_key(|(_, b)| b.ranks)
        else {
            continue;
        };
        let sweep = sweeps
            .iter()
            .find(|(name, _)| name.ends_with("-tcp") == tcp);
        let fit = fit_ping_pong(bench);
        let rows = counted
            .iter()
            .map(|c| {
                let (s, ci) = match &fit {
                    Ok(f) => predict(f, c.messages, c.bytes_mean),
                    Err(_) => (f64::NAN, [f64::NAN; 2]),
                };
                let point = sweep.and_then(|(_, pts)| {
                    pts.iter()
                        .find(|pt| pt.decomp == Some(c.decomp) && pt.ranks == c.ranks)
                });
                Row {
                    ranks: c.ranks,
                    n: c.n,
                    decomp: c.decomp,
                    predicted_bytes: c.bytes_mean,
                    predicted_s: s,
                    predicted_ci95: ci,
                    measured_bytes: point.and_then(|pt| pt.bytes_per_step),
                    measured_s: point.and_then(|pt| pt.comm_s_per_step),
                    measured_transfer_s: point.and_then(|pt| pt.transfer_s_per_step),
                    compute_imbalance: point.and_then(|pt| pt.compute_imbalance),
                    oversubscribed: point.is_some_and(|pt| pt.oversubscribed),
                }
            })
            .collect();
        transports.push(Transport {
            name: if tcp {
                "TCP over loopback (--mca btl tcp,self)".into()
            } else {
                "shared memory (Open MPI's default on one node)".into()
            },
            bench: bench_path.clone(),
            alpha_beta: Fitted::of(fit),
            sweep: sweep.map(|(name, _)| name.clone()),
            rows,
        });
    }
    TreeComm {
        n_per_rank,
        theta,
        leaf_size,
        counted,
        transports,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_tree_moves_less_than_replicated_data_and_grows_slower() {
        let c = count(&[1, 2, 8], 2000, 1, 0.5, 8);
        let get = |d, p| {
            c.iter()
                .find(|x| x.decomp == d && x.ranks == p)
                .unwrap_or_else(|| panic!("{d:?} at {p}"))
        };
        for d in TREE_DECOMPS {
            assert_eq!(get(d, 1).bytes_mean, 0.0, "{d:?}");
            assert_eq!(get(d, 1).messages, 0.0);
        }
        for p in [2, 8] {
            let (all, tree) = (
                get(Decomposition::Allgather, p),
                get(Decomposition::Tree, p),
            );
            assert!(
                tree.bytes_mean < all.bytes_mean,
                "p = {p}: {tree:?} vs {all:?}"
            );
            assert!(get(Decomposition::Octants, p).bytes_mean > 0.0);
            // The bisection balances the bodies; the octants of a concentrated cloud do not.
            assert!(tree.bodies_imbalance < 1.01, "{tree:?}");
        }
        assert!(get(Decomposition::Octants, 8).bodies_imbalance > 1.5);
        assert_eq!(messages(Decomposition::Tree, 4), 2.0 + 6.0);
        assert_eq!(messages(Decomposition::Octants, 2), 3.0 + 3.0);
    }
}
