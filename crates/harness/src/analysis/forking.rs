//! Whether a multi-thread case really ran on its threads. A kernel forks a step only when the
//! step pays for it (`kernels::worth_parallel`), and `symmetric` never forks: a 2-thread case
//! of such a step times one thread twice, so its speedup of about 1 must read "ran on 1
//! thread", not 50% efficiency. The rule is the engine's ([`KernelKind::forks_at`], which the
//! sweep's estimate applies too) on the pair checks the results recorded, for the kernels whose
//! decision those counters give exactly ([`KernelKind::forks_on_pair_checks`]); for the others
//! nothing is claimed.

use super::groups::Point;
use nbody_engine::kernels::{KernelKind, MIN_PARALLEL_PAIRS};
use serde::Serialize;

/// Why a case given several threads ran its force loop on one.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum OneThread {
    /// The step had fewer pair evaluations than pay for a fork ([`MIN_PARALLEL_PAIRS`]).
    TooSmall,
    /// The kernel runs on one thread whatever the pool (`symmetric`).
    SerialKernel,
}

impl OneThread {
    /// Both reasons, in the order their notes are written.
    pub const ALL: [OneThread; 2] = [OneThread::TooSmall, OneThread::SerialKernel];

    /// The words beside a row of a terminal table.
    pub fn label(self) -> &'static str {
        match self {
            OneThread::TooSmall => "ran on 1 thread (too small to fork)",
            OneThread::SerialKernel => "ran on 1 thread (serial kernel)",
        }
    }

    /// The mark after the worker count in a Markdown table's cell (as `*` marks an
    /// oversubscribed case).
    pub fn marker(self) -> &'static str {
        match self {
            OneThread::TooSmall => "†",
            OneThread::SerialKernel => "‡",
        }
    }

    /// The sentence that explains the marker under a table.
    pub fn note(self) -> String {
        match self {
            OneThread::TooSmall => format!(
                "{} = ran on 1 thread: the kernel judged the step too small to pay for a fork \
                 (under {MIN_PARALLEL_PAIRS} pair evaluations), so its speedup is not a parallel \
                 one and its efficiency not a loss.",
                self.marker()
            ),
            OneThread::SerialKernel => format!(
                "{} = ran on 1 thread: the kernel never forks (symmetric), so its speedup is not \
                 a parallel one and its efficiency not a loss.",
                self.marker()
            ),
        }
    }
}

/// Why a case of `kernel` on `threads` threads per rank, `ranks` ranks, whose steps checked
/// `pair_checks_per_step` pairs, ran on one thread per rank; `None` when it forked, had one
/// thread, or the counters cannot tell (see the module's note).
pub fn one_thread(
    kernel: KernelKind,
    threads: usize,
    ranks: usize,
    pair_checks_per_step: f64,
) -> Option<OneThread> {
    if threads < 2 || !kernel.forks_on_pair_checks() {
        return None;
    }
    if !kernel.uses_threads() {
        return Some(OneThread::SerialKernel);
    }
    // Each rank weighs its own share of the pairs, as the estimate does.
    let per_rank = pair_checks_per_step / ranks.max(1) as f64;
    (!kernel.forks_at(per_rank)).then_some(OneThread::TooSmall)
}

/// [`one_thread`] for a measured case; `None` for an external program or without pair counts.
pub fn of_point(p: &Point) -> Option<OneThread> {
    one_thread(
        p.case.kernel.kernel()?,
        p.threads,
        p.ranks,
        p.pair_checks_per_step?,
    )
}

/// [`of_point`] for the case of `points` with `p` workers (as a fit gives p back).
pub fn at_workers(points: &[Point], p: f64) -> Option<OneThread> {
    points
        .iter()
        .filter(|c| c.has_workers(p))
        .find_map(of_point)
}

/// The notes of the reasons in `found`, one paragraph each in [`OneThread::ALL`] order;
/// empty when nothing was found, so a table without a marked case reads as before.
pub fn notes(found: impl IntoIterator<Item = OneThread>) -> String {
    let found: Vec<OneThread> = found.into_iter().collect();
    OneThread::ALL
        .iter()
        .filter(|r| found.contains(r))
        .map(|r| format!("{}\n\n", r.note()))
        .collect()
}

/// The legend text of a figure's crossed markers for the reasons in `found`; `None` when
/// nothing was found.
pub fn legend(found: impl IntoIterator<Item = OneThread>) -> Option<String> {
    let found: Vec<OneThread> = found.into_iter().collect();
    let has = |r| found.contains(&r);
    match (has(OneThread::TooSmall), has(OneThread::SerialKernel)) {
        (false, false) => None,
        (true, false) => Some("crossed: ran on 1 thread (too small to fork)".into()),
        (false, true) => Some("crossed: ran on 1 thread (serial kernel)".into()),
        (true, true) => {
            Some("crossed: ran on 1 thread (too small to fork, or a serial kernel)".into())
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_step_under_the_threshold_runs_on_one_thread() {
        // Quick's n = 500: naive checks n(n-1), per-thread half of that; n = 2000 forks.
        let naive = |n: f64| one_thread(KernelKind::Naive, 2, 1, n * (n - 1.0));
        assert_eq!(naive(500.0), Some(OneThread::TooSmall));
        assert_eq!(naive(2000.0), None);
        let half = 2000.0 * 1999.0 / 2.0;
        assert_eq!(one_thread(KernelKind::PerThread, 2, 1, half), None);
        assert_eq!(
            one_thread(KernelKind::PerThread, 2, 1, 124_750.0),
            Some(OneThread::TooSmall)
        );
        // One thread is never labelled; ranks share the pairs before the rule applies.
        assert_eq!(one_thread(KernelKind::Naive, 1, 1, 10.0), None);
        assert_eq!(
            one_thread(KernelKind::Naive, 2, 4, 1.0e6),
            Some(OneThread::TooSmall)
        );
    }

    #[test]
    fn symmetric_never_forks_and_other_counters_claim_nothing() {
        assert_eq!(
            one_thread(KernelKind::Symmetric, 2, 1, 1e9),
            Some(OneThread::SerialKernel)
        );
        // The cell list weighs a cost per particle beside its few pair checks.
        assert_eq!(one_thread(KernelKind::CellList, 2, 1, 5_000.0), None);
        assert_eq!(
            one_thread(KernelKind::Octree, 2, 1, 2e5),
            Some(OneThread::TooSmall)
        );
    }

    #[test]
    fn notes_and_legend_name_only_the_reasons_found() {
        assert_eq!(notes([]), "");
        let both = notes([OneThread::SerialKernel, OneThread::TooSmall]);
        assert!(both.starts_with("† = ran on 1 thread"), "{both}");
        assert!(both.contains("\n\n‡ = ran on 1 thread"), "{both}");
        assert_eq!(legend([]), None);
        assert_eq!(
            legend([OneThread::TooSmall]).as_deref(),
            Some("crossed: ran on 1 thread (too small to fork)")
        );
    }
}
