//! The communication model: the α-β (latency-bandwidth) fit of `mpi-bench`'s ping-pong and its
//! prediction of the communication time per step of the two MPI decompositions at rank counts
//! beyond the machine, for a weak-scaling series of the 2-D LJ gas (n = n₀·p).

use super::{Analysis, Fitted};
use crate::fit::{self, AlphaBetaFit, Samples};
use nbody_engine::decomp::model;
use nbody_engine::scenario::ScenarioKind;
use nbody_mpi::ranks::bench_file::MpiBenchFile;
use serde::Serialize;
use std::path::{Path, PathBuf};

/// Particles per rank the model predicts for when no sweep ran the LJ gas under MPI: those of
/// `configs/weak-mpi.toml`, the weak-scaling study the model accompanies.
pub const DEFAULT_N_PER_RANK: usize = 20_000;

/// The LJ model of a set of sweeps, with where it comes from.
pub(crate) struct Chosen<'a> {
    pub(crate) model: CommModel,
    /// The mpi-bench file fitted.
    pub(crate) bench: &'a Path,
    /// The sweep that ran the LJ gas under MPI, if any (its n per rank is the model's).
    pub(crate) weak_mpi: Option<&'a Analysis>,
}

/// The LJ communication model of `sweeps`, from one of `benches` (mpi-bench files with their
/// paths): of those measured over the MPI library's own transport (a TCP run is the tree
/// model's), the ones in the directory of the sweep that ran the LJ gas under MPI (the same
/// machine) when there are any, else all; of those, the one with the most ranks that still had
/// a CPU each, else the first. `None` without a benchmark.
pub(crate) fn choose<'a>(
    benches: &'a [(PathBuf, MpiBenchFile)],
    sweeps: &[&'a Analysis],
) -> Option<Chosen<'a>> {
    let weak_mpi = sweeps.iter().copied().find(|a| {
        a.cases
            .iter()
            .any(|c| c.decomp.is_some() && c.case.scenario != ScenarioKind::Galaxy)
    });
    let native: Vec<&(PathBuf, MpiBenchFile)> =
        benches.iter().filter(|(_, b)| !b.over_tcp()).collect();
    let own: Vec<_> = match weak_mpi {
        Some(a) => native
            .iter()
            .copied()
            .filter(|(p, _)| in_sweep_dir(p, &[a.name.as_str()]))
            .collect(),
        None => Vec::new(),
    };
    let pool = if own.is_empty() { native } else { own };
    let (path, bench) = pool
        .iter()
        .copied()
        .filter(|(_, b)| !b.oversubscribed)
        .max_by_key(|(_, b)| b.ranks)
        .or(pool.first().copied())?;
    let n_per_rank = weak_mpi
        .and_then(|a| a.cases.iter().find(|c| c.ranks == 1).map(|c| c.n))
        .unwrap_or(DEFAULT_N_PER_RANK);
    let model = comm_model(
        bench,
        &path.to_string_lossy().replace('\\', "/"),
        n_per_rank,
        nbody_engine::scenario::LJ_GAS_DENSITY,
        nbody_engine::scenario::LJ_CUTOFF,
    );
    Some(Chosen {
        model,
        bench: path,
        weak_mpi,
    })
}

/// Whether `path` is a file directly in the results directory of one of the sweeps `names`.
pub(crate) fn in_sweep_dir(path: &Path, names: &[&str]) -> bool {
    path.parent()
        .and_then(|d| d.file_name())
        .is_some_and(|d| names.iter().any(|n| d == *n))
}

/// One predicted point: communication seconds per step with the 95% band of the fit.
#[derive(Clone, Debug, Serialize)]
pub(crate) struct Prediction {
    pub ranks: usize,
    pub n: usize,
    pub(crate) bytes_per_rank: f64,
    pub(crate) messages_per_rank: f64,
    pub seconds: f64,
    pub ci95: [f64; 2],
}

#[derive(Clone, Debug, Serialize)]
pub(crate) struct CommModel {
    pub source: String,
    /// Ranks and oversubscription of the benchmark the fit comes from.
    pub(crate) bench_ranks: usize,
    pub(crate) bench_oversubscribed: bool,
    pub(crate) alpha_beta: Fitted<AlphaBetaFit>,
    /// The workload predicted: particles per rank, dimension, bytes per value, density, cutoff.
    pub(crate) n_per_rank: usize,
    pub density: f64,
    pub cutoff: f64,
    pub allgather: Vec<Prediction>,
    pub domain: Vec<Prediction>,
}

/// Rank counts the prediction covers (beyond this machine's).
pub(crate) const PREDICTED_RANKS: [usize; 8] = [1, 2, 4, 8, 16, 32, 64, 128];

/// Regions per axis of a 2-D rank grid as square as the rank count allows.
fn grid(p: usize) -> Vec<usize> {
    let a = (1..=p)
        .filter(|&a| p.is_multiple_of(a) && a * a <= p)
        .max()
        .unwrap_or(1);
    vec![p / a, a]
}

fn log2_ceil(p: usize) -> f64 {
    (p as f64).log2().ceil()
}

/// The α-β time of `msgs` latencies and `bytes` bytes, with the 95% band of the fit's
/// bootstrap replicates.
pub(crate) fn predict(f: &AlphaBetaFit, msgs: f64, bytes: f64) -> (f64, [f64; 2]) {
    let at = |a: f64, b: f64| msgs * a + bytes * b;
    let mut reps: Vec<f64> = f.replicates().iter().map(|r| at(r[0], r[1])).collect();
    reps.sort_by(f64::total_cmp);
    let q = |x: f64| reps[((x * reps.len() as f64) as usize).min(reps.len() - 1)];
    let mid = at(f.alpha.estimate, f.beta.estimate);
    if reps.is_empty() {
        (mid, [mid, mid])
    } else {
        (mid, [q(0.025), q(0.975)])
    }
}

/// The α-β fit of the ping-pong of `bench`.
pub(crate) fn fit_ping_pong(bench: &MpiBenchFile) -> Result<AlphaBetaFit, fit::FitError> {
    let samples: Vec<Samples> = bench
        .ping_pong
        .points
        .iter()
        .map(|p| Samples::new(p.bytes as f64, p.seconds.clone()))
        .collect();
    fit::fit_alpha_beta(&samples, fit::DEFAULT_SEED)
}

/// Fits the ping-pong of `bench` and predicts both decompositions for n = `n_per_rank`·p
/// particles of a 2-D f32 system at `density` with cutoff `cutoff`.
pub(crate) fn comm_model(
    bench: &MpiBenchFile,
    source: &str,
    n_per_rank: usize,
    density: f64,
    cutoff: f64,
) -> CommModel {
    let ab = fit_ping_pong(bench);
    let (dim, value_bytes) = (2, 4);
    let mut allgather = Vec::new();
    let mut domain = Vec::new();
    if let Ok(f) = &ab {
        let time = |msgs: f64, bytes: f64| predict(f, msgs, bytes);
        for &p in &PREDICTED_RANKS {
            let n = n_per_rank * p;
            // Replicated data: an Allgatherv of every position, ⌈log2 p⌉ latencies.
            let bytes = model::allgather_bytes_per_rank(n, p, dim, value_bytes);
            let msgs = log2_ceil(p);
            let (s, ci) = time(msgs, bytes);
            allgather.push(Prediction {
                ranks: p,
                n,
                bytes_per_rank: bytes,
                messages_per_rank: msgs,
                seconds: s,
                ci95: ci,
            });
            // Spatial decomposition: ghosts from neighbours plus the status collective.
            let dims = grid(p);
            let bytes = if p > 1 {
                model::domain_bytes_per_rank(n, density, cutoff, &dims, value_bytes)
            } else {
                0.0
            };
            let msgs = if p > 1 {
                model::domain_messages_per_rank(&dims) + log2_ceil(p)
            } else {
                0.0
            };
            let (s, ci) = time(msgs, bytes);
            domain.push(Prediction {
                ranks: p,
                n,
                bytes_per_rank: bytes,
                messages_per_rank: msgs,
                seconds: s,
                ci95: ci,
            });
        }
    }
    CommModel {
        source: source.to_string(),
        bench_ranks: bench.ranks,
        bench_oversubscribed: bench.oversubscribed,
        alpha_beta: Fitted::of(ab),
        n_per_rank,
        density,
        cutoff,
        allgather,
        domain,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rank_grids_are_as_square_as_possible() {
        assert_eq!(grid(1), vec![1, 1]);
        assert_eq!(grid(2), vec![2, 1]);
        assert_eq!(grid(4), vec![2, 2]);
        assert_eq!(grid(8), vec![4, 2]);
        assert_eq!(grid(16), vec![4, 4]);
    }
}
