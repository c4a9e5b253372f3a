//! The O(n²) family side by side: `naive` (every pair from both ends, n(n−1) pair evaluations
//! per step), `symmetric` (each pair once with Newton's third law, n(n−1)/2, one thread) and
//! `per-thread` (symmetric's pairs split over threads with private force buffers). One
//! comparison per scenario, precision and n: naive and symmetric on one thread, per-thread at
//! every thread count measured, the Newton-3 gain naive ÷ symmetric and per-thread's speedup
//! over symmetric on one thread beside the calibrated ceiling. Pure data from the measured
//! cases; `render::family_tables` writes it out.

use super::forking::{self, OneThread};
use super::groups::Point;
use crate::fit::Estimate;
use nbody_calibrate::Calibration;
use nbody_engine::kernels::KernelKind;
use nbody_engine::scenario::{Precision, ScenarioKind};
use nbody_engine::stats::{BOOTSTRAP_RESAMPLES, bootstrap_ratio_ci};
use serde::Serialize;

/// Seed of the ratios' bootstraps, so the same results always give the same intervals.
const SEED: u64 = 0xFA31;

/// The family's kernels in the order of their rows.
pub const KERNELS: [KernelKind; 3] = [
    KernelKind::Naive,
    KernelKind::Symmetric,
    KernelKind::PerThread,
];

/// The family at one scenario, precision and n.
#[derive(Clone, Debug, Serialize)]
pub struct Family {
    /// The scenario simulated.
    pub scenario: ScenarioKind,
    /// Its precision (the scenario's default when the case set none).
    pub precision: Precision,
    /// Particles.
    pub n: usize,
    /// Naive and symmetric on one thread, then per-thread at one thread and every other
    /// thread count measured, in increasing threads.
    pub rows: Vec<FamilyRow>,
    /// Naive's median time ÷ symmetric's, one thread each (2 is the ideal: half the pair
    /// evaluations); `None` when either is not measured.
    pub newton3_gain: Option<Estimate>,
}

/// One kernel at one thread count, measured or not.
#[derive(Clone, Debug, Serialize)]
pub struct FamilyRow {
    /// The kernel.
    pub kernel: KernelKind,
    /// Threads.
    pub threads: usize,
    /// The measurement; `None` when the results hold no such case.
    pub case: Option<FamilyCase>,
}

/// A measured member of the family.
#[derive(Clone, Debug, Serialize)]
pub struct FamilyCase {
    /// The case's key in the results file.
    pub key: String,
    /// Median time per step and its bootstrap 95% CI, seconds.
    pub median_s: f64,
    /// `[low, high]` of that median, seconds.
    pub ci95_s: [f64; 2],
    /// Pair evaluations per step as the work counters recorded them.
    pub pair_checks_per_step: Option<f64>,
    /// Those per second at the median.
    pub pair_evals_per_s: Option<f64>,
    /// Per-thread only: symmetric's median on one thread ÷ this one; `None` without symmetric.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub speedup_over_symmetric: Option<Estimate>,
    /// Per-thread only: the calibrated parallel ceiling at these threads (1 on one thread, its
    /// reference);
    /// `None` without a calibration that measured it.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub ceiling: Option<f64>,
    /// Why the case ran on one thread although given several; `None` when it did not.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub one_thread: Option<OneThread>,
    /// More threads than logical CPUs.
    pub oversubscribed: bool,
}

/// The family of every scenario, precision and n where the results hold at least two of its
/// kernels (one kernel alone compares with nothing), by scenario in first-seen order, then n.
pub fn families(cases: &[Point], calibration: Option<&Calibration>) -> Vec<Family> {
    let members: Vec<&Point> = cases.iter().filter(|p| is_member(p)).collect();
    let mut keys: Vec<(ScenarioKind, Precision, usize)> = Vec::new();
    for p in &members {
        let key = (p.case.scenario, precision(p), p.n);
        if !keys.contains(&key) {
            keys.push(key);
        }
    }
    let scenarios: Vec<ScenarioKind> = keys.iter().map(|k| k.0).fold(Vec::new(), |mut v, s| {
        if !v.contains(&s) {
            v.push(s);
        }
        v
    });
    keys.sort_by_key(|k| (scenarios.iter().position(|s| *s == k.0), k.2));
    keys.into_iter()
        .filter_map(|(scenario, precision_, n)| {
            let same: Vec<&Point> = members
                .iter()
                .copied()
                .filter(|p| p.case.scenario == scenario && precision(p) == precision_ && p.n == n)
                .collect();
            family(scenario, precision_, n, &same, calibration)
        })
        .collect()
}

/// A case of the family on threads alone (no MPI ranks, no weak-by-time factor).
fn is_member(p: &Point) -> bool {
    let kernel = p.case.kernel.kernel();
    kernel.is_some_and(|k| KERNELS.contains(&k)) && p.ranks == 1 && p.case.time_factor == 1
}

fn precision(p: &Point) -> Precision {
    p.case
        .precision
        .unwrap_or(p.case.scenario.defaults().precision)
}

fn family(
    scenario: ScenarioKind,
    precision: Precision,
    n: usize,
    same: &[&Point],
    calibration: Option<&Calibration>,
) -> Option<Family> {
    let kernels = KERNELS
        .iter()
        .filter(|k| same.iter().any(|p| kernel_of(p) == **k));
    if kernels.count() < 2 {
        return None;
    }
    // Of several seeds, the first measured stands for all (one case per row).
    let find = |k: KernelKind, t: usize| {
        same.iter()
            .copied()
            .find(|p| kernel_of(p) == k && p.threads == t)
    };
    let symmetric = find(KernelKind::Symmetric, 1);
    let mut threads: Vec<usize> = same
        .iter()
        .filter(|p| kernel_of(p) == KernelKind::PerThread)
        .map(|p| p.threads)
        .chain([1])
        .collect();
    threads.sort_unstable();
    threads.dedup();
    let rows = [(KernelKind::Naive, 1), (KernelKind::Symmetric, 1)]
        .into_iter()
        .chain(threads.iter().map(|&t| (KernelKind::PerThread, t)))
        .map(|(kernel, t)| FamilyRow {
            kernel,
            threads: t,
            case: find(kernel, t).map(|p| case(p, symmetric, calibration)),
        })
        .collect();
    let newton3_gain = match (find(KernelKind::Naive, 1), symmetric) {
        (Some(naive), Some(sym)) => Some(ratio(sym, naive)),
        _ => None,
    };
    Some(Family {
        scenario,
        precision,
        n,
        rows,
        newton3_gain,
    })
}

fn kernel_of(p: &Point) -> KernelKind {
    p.case
        .kernel
        .kernel()
        .expect("a member is a built-in kernel")
}

fn case(p: &Point, symmetric: Option<&Point>, calibration: Option<&Calibration>) -> FamilyCase {
    let per_thread = kernel_of(p) == KernelKind::PerThread;
    FamilyCase {
        key: p.key.clone(),
        median_s: p.median_s,
        ci95_s: p.ci95_s,
        pair_checks_per_step: p.pair_checks_per_step,
        pair_evals_per_s: p.pair_evals_per_s,
        speedup_over_symmetric: symmetric.filter(|_| per_thread).map(|s| ratio(p, s)),
        // One thread is the ceiling's reference by definition (as in the strong analysis).
        ceiling: calibration
            .filter(|_| per_thread)
            .and_then(|c| match p.threads {
                1 => Some(1.0),
                t => c.ceiling(t),
            }),
        one_thread: forking::of_point(p),
        oversubscribed: p.oversubscribed,
    }
}

/// `over`'s median time ÷ `under`'s, with the bootstrap 95% CI of that ratio of medians.
fn ratio(under: &Point, over: &Point) -> Estimate {
    let estimate = over.median_s / under.median_s;
    let ci95 = bootstrap_ratio_ci(&under.samples, &over.samples, BOOTSTRAP_RESAMPLES, SEED)
        .unwrap_or([estimate, estimate]);
    Estimate { estimate, ci95 }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use nbody_records::kernel_or_program::KernelOrProgram;
    use nbody_records::plan::Case;

    /// A complete case of `kernel` with samples tightly around `median_s`.
    pub(crate) fn point(kernel: KernelKind, n: usize, threads: usize, median_s: f64) -> Point {
        let pairs = (n * (n - 1)) as f64
            / if kernel == KernelKind::Naive {
                1.0
            } else {
                2.0
            };
        let case = Case {
            scenario: ScenarioKind::LjBox,
            kernel: KernelOrProgram::Kernel(kernel),
            n,
            threads,
            ranks: 1,
            theta: None,
            multipole: Default::default(),
            order: None,
            skin: None,
            seed: 1,
            precision: None,
            time_factor: 1,
            decomp: None,
        };
        Point {
            key: case.key(),
            case,
            n,
            threads,
            ranks: 1,
            time_factor: 1,
            theta: None,
            decomp: None,
            comm_s_per_step: None,
            bytes_per_step: None,
            transfer_s_per_step: None,
            compute_imbalance: None,
            samples: vec![median_s * 0.99, median_s, median_s * 1.01],
            median_s,
            ci95_s: [median_s * 0.99, median_s * 1.01],
            oversubscribed: false,
            ns_per_particle_step: median_s * 1e9 / n as f64,
            pair_evals_per_s: Some(pairs / median_s),
            pair_checks_per_step: Some(pairs),
            phases: Default::default(),
            named_phases: Vec::new(),
            step_ns: None,
            force_error: None,
            max_energy_drift: None,
            sanity_ok: None,
        }
    }

    #[test]
    fn gain_and_speedup_are_ratios_of_medians() {
        let cases = [
            point(KernelKind::Naive, 2000, 1, 2.0e-3),
            point(KernelKind::Symmetric, 2000, 1, 1.0e-3),
            point(KernelKind::PerThread, 2000, 2, 0.55e-3),
        ];
        let f = &families(&cases, None)[0];
        let gain = f.newton3_gain.as_ref().unwrap();
        assert!((gain.estimate - 2.0).abs() < 1e-12);
        assert!(gain.contains(2.0));
        // Per-thread on one thread is not measured: its row is there, empty.
        let rows: Vec<(KernelKind, usize, bool)> = f
            .rows
            .iter()
            .map(|r| (r.kernel, r.threads, r.case.is_some()))
            .collect();
        assert_eq!(
            rows,
            [
                (KernelKind::Naive, 1, true),
                (KernelKind::Symmetric, 1, true),
                (KernelKind::PerThread, 1, false),
                (KernelKind::PerThread, 2, true),
            ]
        );
        let pt = f.rows[3].case.as_ref().unwrap();
        let speedup = pt.speedup_over_symmetric.as_ref().unwrap().estimate;
        assert_eq!(format!("{speedup:.2}"), "1.82");
        assert_eq!(pt.one_thread, None, "2000 particles fork");
    }

    #[test]
    fn one_kernel_alone_or_other_kernels_make_no_family() {
        let alone = [point(KernelKind::PerThread, 500, 1, 1e-3)];
        assert!(families(&alone, None).is_empty());
        let others = [
            point(KernelKind::CellList, 500, 1, 1e-3),
            point(KernelKind::Verlet, 500, 1, 1e-3),
        ];
        assert!(families(&others, None).is_empty());
        // Without symmetric there is no gain and no speedup over it; small steps are labelled.
        let two = [
            point(KernelKind::Naive, 500, 1, 1e-3),
            point(KernelKind::PerThread, 500, 2, 1e-3),
        ];
        let f = &families(&two, None)[0];
        assert!(f.newton3_gain.is_none());
        let pt = f.rows[3].case.as_ref().unwrap();
        assert!(pt.speedup_over_symmetric.is_none());
        assert_eq!(pt.one_thread, Some(OneThread::TooSmall));
    }
}
