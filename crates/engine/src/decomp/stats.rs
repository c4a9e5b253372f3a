//! Per-rank statistics of a distributed run, their reduction over ranks, and the `mpi` block
//! of the `run --json` result (documented in `docs/howto/run-mpi-studies.md`).
//!
//! Time is split three ways on every rank: *compute* (everything outside MPI calls: forces,
//! integration, walls, packing), *communication* (time inside MPI calls, the Coulomb MPI tutorial's
//! "communication time"), and, within communication, *waiting*: the time a rank spends in a
//! call because another rank is still computing. Waiting is not observable inside one call,
//! so it is derived from the per-step compute times of all ranks: in a step where the slowest
//! rank computes for `max_r c_r`, rank `i` waits about `max_r c_r − c_i`. The rest of the
//! communication time (`transfer_s`) is moving data and MPI overhead.

use super::Decomposition;
use serde::{Deserialize, Serialize};

/// What one rank measured over the timed steps.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct RankStats {
    /// The rank's number in the communicator, from 0.
    pub rank: usize,
    /// Particles owned at the end, and the mean over the timed steps.
    pub particles: u64,
    /// Particles owned, averaged over the timed steps.
    pub particles_mean: f64,
    /// Seconds outside MPI calls (forces, integration, walls, packing), summed over steps.
    pub compute_s: f64,
    /// Of `compute_s`, the force computation.
    pub force_s: f64,
    /// Seconds inside MPI calls, including waiting for other ranks.
    pub comm_s: f64,
    /// Of `comm_s`, the estimated wait for slower ranks (load imbalance).
    pub wait_s: f64,
    /// `comm_s − wait_s`, at least 0: moving data and MPI overhead.
    pub transfer_s: f64,
    /// Payload bytes and messages this rank sent (collectives: see `docs/explanation/mpi.md`).
    pub bytes_sent: u64,
    /// Messages this rank sent (how collectives count: `docs/explanation/mpi.md`).
    pub messages_sent: u64,
    /// Collective calls made.
    pub collectives: u64,
    /// Ghost particles received, summed over steps (domain decomposition).
    pub ghosts_received: u64,
    /// Particles that left this rank's region, summed over steps (domain decomposition).
    pub migrated_out: u64,
    /// Pair distance evaluations this rank's force computations made.
    pub pair_checks: u64,
}

/// Minimum, mean and maximum of a quantity over the ranks.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct MinMeanMax {
    /// Smallest value over the ranks.
    pub min: f64,
    /// Mean over the ranks.
    pub mean: f64,
    /// Largest value over the ranks.
    pub max: f64,
}

impl MinMeanMax {
    /// The minimum, mean and maximum of `values`; all 0 when there are none.
    pub fn of(values: impl IntoIterator<Item = f64>) -> MinMeanMax {
        let (mut min, mut max, mut sum, mut k) = (f64::INFINITY, f64::NEG_INFINITY, 0.0, 0);
        for v in values {
            min = min.min(v);
            max = max.max(v);
            sum += v;
            k += 1;
        }
        if k == 0 {
            return MinMeanMax::default();
        }
        MinMeanMax {
            min,
            mean: sum / k as f64,
            max,
        }
    }

    /// Max over mean: the load imbalance of a per-rank quantity (1 when the mean is 0).
    pub fn imbalance(&self) -> f64 {
        if self.mean > 0.0 {
            self.max / self.mean
        } else {
            1.0
        }
    }
}

/// The per-rank statistics reduced over the ranks.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct ReducedStats {
    /// Particles owned at the end of the run.
    pub particles: MinMeanMax,
    /// Seconds outside MPI calls, summed over the steps.
    pub compute_s: MinMeanMax,
    /// Seconds of force computation, summed over the steps.
    pub force_s: MinMeanMax,
    /// Seconds inside MPI calls, summed over the steps.
    pub comm_s: MinMeanMax,
    /// Estimated seconds waiting for slower ranks.
    pub wait_s: MinMeanMax,
    /// Seconds inside MPI calls not spent waiting: moving data and MPI overhead.
    pub transfer_s: MinMeanMax,
    /// Payload bytes sent.
    pub bytes_sent: MinMeanMax,
    /// Messages sent.
    pub messages_sent: MinMeanMax,
    /// Collective calls this rank took part in (absent from files written before they were
    /// reported).
    #[serde(default)]
    pub collectives: MinMeanMax,
    /// Ghost particles received, summed over the steps.
    pub ghosts_received: MinMeanMax,
    /// Particles that left the rank's region, summed over the steps.
    pub migrated_out: MinMeanMax,
    /// Slowest rank's compute time over the mean (1 = perfectly balanced).
    pub compute_imbalance: f64,
    /// Mean communication time over mean (compute + communication) time.
    pub comm_fraction: f64,
}

/// Reduces per-rank statistics to min/mean/max over the ranks.
pub fn reduce(per_rank: &[RankStats]) -> ReducedStats {
    let of = |f: &dyn Fn(&RankStats) -> f64| MinMeanMax::of(per_rank.iter().map(f));
    let compute = of(&|r| r.compute_s);
    let comm = of(&|r| r.comm_s);
    ReducedStats {
        particles: of(&|r| r.particles as f64),
        compute_s: compute,
        force_s: of(&|r| r.force_s),
        comm_s: comm,
        wait_s: of(&|r| r.wait_s),
        transfer_s: of(&|r| r.transfer_s),
        bytes_sent: of(&|r| r.bytes_sent as f64),
        messages_sent: of(&|r| r.messages_sent as f64),
        collectives: of(&|r| r.collectives as f64),
        ghosts_received: of(&|r| r.ghosts_received as f64),
        migrated_out: of(&|r| r.migrated_out as f64),
        compute_imbalance: compute.imbalance(),
        comm_fraction: if compute.mean + comm.mean > 0.0 {
            comm.mean / (compute.mean + comm.mean)
        } else {
            0.0
        },
    }
}

/// Each rank's wait for slower ranks, from every rank's compute seconds per step
/// (`compute[rank][step]`, all of one length): `Σ_step (max_r compute[r][step] − compute[i][step])`.
pub fn waits(compute: &[Vec<f64>]) -> Vec<f64> {
    let steps = compute.iter().map(Vec::len).min().unwrap_or(0);
    let slowest: Vec<f64> = (0..steps)
        .map(|s| compute.iter().map(|c| c[s]).fold(0.0, f64::max))
        .collect();
    compute
        .iter()
        .map(|c| (0..steps).map(|s| slowest[s] - c[s]).sum())
        .collect()
}

/// Fills in `wait_s` and `transfer_s` of every rank from the per-step compute times.
pub fn attribute_waits(per_rank: &mut [RankStats], compute: &[Vec<f64>]) {
    for (stats, wait) in per_rank.iter_mut().zip(waits(compute)) {
        // The estimate cannot exceed the time actually spent inside MPI calls.
        stats.wait_s = wait.min(stats.comm_s);
        stats.transfer_s = (stats.comm_s - stats.wait_s).max(0.0);
    }
}

/// The Coulomb MPI tutorial's closing summary, as its master rank prints it.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct MasterSummary {
    /// Rank 0's seconds inside MPI calls over the timed steps.
    pub communication_s: f64,
    /// Rank 0's wall time of the timed steps minus its communication time.
    pub computation_s: f64,
    /// Pair interactions evaluated by all ranks over the timed steps.
    pub interactions: u64,
}

/// The `mpi` block of a distributed run's result.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct MpiReport {
    /// Number of MPI processes.
    pub ranks: usize,
    /// How the work was split among the ranks.
    pub decomposition: Decomposition,
    /// Threads of each rank's pool.
    pub threads_per_rank: usize,
    /// Regions per axis (domain decomposition).
    pub rank_grid: Option<Vec<usize>>,
    /// The MPI library's version string.
    pub library: String,
    /// Processor name of every rank.
    pub hosts: Vec<String>,
    /// Untimed steps before the timed ones.
    pub warmup_steps: u64,
    /// Times the domain boundaries moved to rebalance particle counts.
    pub rebalances: u64,
    /// Each rank's statistics, in rank order.
    pub per_rank: Vec<RankStats>,
    /// The per-rank statistics reduced to min/mean/max over the ranks.
    pub reduced: ReducedStats,
    /// Older files call it `source_004`; both names are read.
    #[serde(alias = "source_004")]
    pub master_summary: MasterSummary,
    /// Wall time of every timed step, nanoseconds: the slowest rank's. Dropped from sweep
    /// results, whose samples carry the same information.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub step_ns: Vec<u64>,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn waits_are_the_gaps_to_the_slowest_rank() {
        let compute = vec![
            vec![1.0, 2.0, 3.0],
            vec![2.0, 2.0, 1.0],
            vec![0.5, 1.0, 1.0],
        ];
        assert_eq!(waits(&compute), vec![1.0, 2.0, 4.5]);
        let mut stats = vec![
            RankStats {
                comm_s: 2.0,
                ..Default::default()
            },
            RankStats {
                comm_s: 1.0,
                ..Default::default()
            },
            RankStats {
                comm_s: 5.0,
                ..Default::default()
            },
        ];
        attribute_waits(&mut stats, &compute);
        assert_eq!(
            stats
                .iter()
                .map(|s| (s.wait_s, s.transfer_s))
                .collect::<Vec<_>>(),
            vec![(1.0, 1.0), (1.0, 0.0), (4.5, 0.5)]
        );
    }

    #[test]
    fn reduction_gives_min_mean_max_and_ratios() {
        let ranks: Vec<RankStats> = (0..4)
            .map(|r| RankStats {
                rank: r,
                particles: 100 + r as u64,
                compute_s: 1.0 + r as f64,
                comm_s: 1.0,
                bytes_sent: 10 * r as u64,
                collectives: 2 + r as u64,
                ..Default::default()
            })
            .collect();
        let red = reduce(&ranks);
        assert_eq!(
            red.particles,
            MinMeanMax {
                min: 100.0,
                mean: 101.5,
                max: 103.0
            }
        );
        assert_eq!(red.compute_s.mean, 2.5);
        assert_eq!(red.compute_imbalance, 4.0 / 2.5);
        assert_eq!(MinMeanMax::of([0.0, 0.0]).imbalance(), 1.0);
        assert_eq!(MinMeanMax::of([100.0, 300.0]).imbalance(), 1.5);
        assert_eq!(red.comm_fraction, 1.0 / 3.5);
        assert_eq!(red.bytes_sent.max, 30.0);
        assert_eq!(red.collectives.mean, 3.5);
        assert_eq!(MinMeanMax::of([]), MinMeanMax::default());
    }
}
