//! The communication model: the α-β (latency-bandwidth) fit of `mpi-bench`'s ping-pong and its
//! prediction of the communication time per step of the two MPI decompositions at rank counts
//! beyond the machine, for a weak-scaling series of the 2-D LJ gas (n = n₀·p).

use super::Fitted;
use crate::decomp::model;
use crate::fit::{self, AlphaBetaFit, Samples};
use crate::ranks::bench_file::MpiBenchFile;
use serde::Serialize;

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
