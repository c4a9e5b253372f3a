//! Case-by-case comparison: normalisation, the estimate of the ratio from the runs' rounds
//! ([`super::paired`]), the verdicts ([`super::sequential`]), and the exact comparison of the
//! work counters.

use super::checks::{calibrated_rate, check_comparable};
use super::family::{FAMILY_ALPHA, Tails};
use super::paired::{LogRatio, Pairing, round_level};
use super::sequential::{EQUIVALENCE, EQUIVALENCE_TAIL, decide};
use super::{
    CaseComparison, GATE_SCHEMA, GateError, GateOptions, GateReport, Judged, MAX_THRESHOLD,
    MIN_CI_SAMPLES, MissingCase, Normalization, NormalizationChoice, RunInfo, Verdict, WorkChange,
};
use nbody_engine::kernels::WorkCounters;
use nbody_engine::stats::{bootstrap_medians, interval95, median};
use nbody_records::results::{CaseRecord, ResultsFile};

/// Compares `current` against `baseline`; see the module documentation for the rules.
pub fn compare(
    baseline: &ResultsFile,
    current: &ResultsFile,
    options: &GateOptions,
) -> Result<GateReport, GateError> {
    check_threshold(options.threshold)?;
    let warnings = check_comparable(baseline, current, options.force)?;
    let mut report = GateReport {
        schema: GATE_SCHEMA.to_string(),
        threshold: options.threshold,
        fail_on_work_change: options.fail_on_work_change,
        baseline: RunInfo::of(baseline),
        current: RunInfo::of(current),
        cases: Vec::new(),
        missing: Vec::new(),
        extra: Vec::new(),
        warnings,
        judged_on: options.judge,
        family_alpha: FAMILY_ALPHA,
        pairing: options.pairing,
        looks: options.look.count.max(1),
        sides: None,
    };
    for base in &baseline.cases {
        let missing = |reason: &str| MissingCase {
            key: base.key.clone(),
            reason: reason.to_string(),
        };
        // A case decided at an earlier look is kept as it was decided.
        if let Some(closed) = options.closed.iter().find(|c| c.key == base.key) {
            report.cases.push(closed.clone());
            continue;
        }
        let Some(cur) = current.cases.iter().find(|c| c.key == base.key) else {
            report.missing.push(missing("not in the current results"));
            continue;
        };
        let (nb, nc) = (samples(base).len(), samples(cur).len());
        if nb == 0 {
            report.missing.push(missing("no samples in the baseline"));
        } else if nc == 0 {
            report
                .missing
                .push(missing("not measured in the current run"));
        } else if nb.min(nc) < MIN_CI_SAMPLES {
            // Judged on so few samples, the CI would be the extreme samples themselves.
            report.missing.push(missing(&format!(
                "{nb} successful sample(s) in the baseline and {nc} in the current run: a 95% \
                 CI of the ratio needs at least {MIN_CI_SAMPLES} per side, so no verdict"
            )));
        } else {
            let Some(case) = compare_case(baseline, base, current, cur, options)? else {
                report.missing.push(missing(
                    "its rounds give no estimate (fewer than two usable rounds or samples on \
                     a side), so no verdict",
                ));
                continue;
            };
            if options.fail_on_work_change && !case.work_compared {
                report.missing.push(missing(
                    "its work counters could not be compared (a file has no initial_work: \
                     swept by an older version), and --fail-on-work-change asks for them",
                ));
            }
            report.cases.push(case);
        }
    }
    let open: Vec<bool> = report
        .cases
        .iter()
        .map(|c| !options.closed.iter().any(|d| d.key == c.key))
        .collect();
    let m = report.cases.len().max(1);
    let tail = options.look.alpha(FAMILY_ALPHA) / m as f64;
    for case in report.cases.iter_mut().zip(&open).filter(|(_, o)| **o) {
        case.0.family_ci = case.0.estimates.0.interval(tail);
        case.0.raw_family_ci = case.0.estimates.1.interval(tail);
    }
    decide(&mut report.cases, &open, options.look, FAMILY_ALPHA);
    report.extra = current
        .cases
        .iter()
        .filter(|c| !baseline.cases.iter().any(|b| b.key == c.key))
        .map(|c| c.key.clone())
        .collect();
    Ok(report)
}

/// A threshold is a fraction from 0 to [`MAX_THRESHOLD`].
pub fn check_threshold(threshold: f64) -> Result<(), GateError> {
    if (0.0..=MAX_THRESHOLD).contains(&threshold) {
        Ok(())
    } else {
        Err(GateError::BadThreshold(threshold))
    }
}

fn compare_case(
    baseline: &ResultsFile,
    base: &CaseRecord,
    current: &ResultsFile,
    cur: &CaseRecord,
    options: &GateOptions,
) -> Result<Option<CaseComparison>, GateError> {
    let normalization = choose_normalization(baseline, base, current, cur, options)?;
    let estimate = |how| {
        let levels = |file, record| round_levels(file, record, how);
        let (b, c) = (levels(baseline, base), levels(current, cur));
        match options.pairing {
            Pairing::Rounds if b.len() == c.len() => LogRatio::paired(&b, &c),
            _ => unpaired(
                &normalized(baseline, base, how),
                &normalized(current, cur, how),
            ),
        }
    };
    let (Some(norm), Some(raw)) = (estimate(normalization), estimate(Normalization::None)) else {
        return Ok(None);
    };
    let (b_raw, c_raw) = (samples(base), samples(cur));
    let mut case = judged_case(&base.key, normalization, norm, raw, options);
    let (work_changes, work_compared, mut notes) = compare_work(base, cur);
    for (record, which) in [(base, "baseline"), (cur, "current")] {
        if !record.is_complete() {
            notes.push(format!(
                "{which} incomplete ({}/{} rounds)",
                record.rounds_done, record.rounds_planned
            ));
        }
        if record
            .summary
            .as_ref()
            .is_some_and(|s| s.sanity_ok == Some(false))
        {
            notes.push(format!("{which} failed its energy-drift check"));
        }
    }
    if cur.oversubscribed {
        notes.push("oversubscribed".to_string());
    }
    case.baseline_median_s = median_of(&b_raw);
    case.current_median_s = median_of(&c_raw);
    case.samples = [b_raw.len(), c_raw.len()];
    case.work_changes = work_changes;
    case.work_compared = work_compared;
    case.notes = notes;
    Ok(Some(case))
}

/// A case's comparison from its normalised and raw estimates, before the verdict (which is
/// set across the cases): ratios, intervals, p-values and whether it lies within the margin.
/// Its medians, samples, work counters and notes are left for the caller.
pub(crate) fn judged_case(
    key: &str,
    normalization: Normalization,
    norm: LogRatio,
    raw: LogRatio,
    options: &GateOptions,
) -> CaseComparison {
    let t = options.threshold;
    let (tails, raw_tails) = (norm.tails(t), raw.tails(t));
    let p = match options.judge {
        Judged::Normalized => tails,
        Judged::Raw => raw_tails,
        Judged::Both => tails.both(raw_tails),
    };
    // Unchanged: the judged ratio's 90% interval within the margin (for both ratios, either
    // one suffices: a regression is claimed only when both show it).
    let margin = [1.0 - EQUIVALENCE * t, 1.0 + EQUIVALENCE * t];
    let within = |e: &LogRatio| {
        let [lo, hi] = e.interval(EQUIVALENCE_TAIL);
        margin[0] <= lo && hi <= margin[1]
    };
    let equivalent = match options.judge {
        Judged::Normalized => within(&norm),
        Judged::Raw => within(&raw),
        Judged::Both => within(&norm) || within(&raw),
    };
    CaseComparison {
        key: key.to_string(),
        normalization,
        baseline_median_s: f64::NAN,
        current_median_s: f64::NAN,
        raw_ratio: raw.ratio(),
        ratio: norm.ratio(),
        ci95: norm.interval(0.025),
        raw_ci95: raw.interval(0.025),
        // Set across cases, once every case has its estimate.
        family_ci: [f64::NAN; 2],
        raw_family_ci: [f64::NAN; 2],
        adjusted_p: 1.0,
        units: norm.units,
        look: options.look.index + 1,
        equivalent,
        estimates: (norm, raw),
        p,
        p_normalized: tails,
        p_raw: raw_tails,
        // Set across cases by the family-wise rule, once every case has its p-values.
        verdict: Verdict::Unknown,
        samples: [0, 0],
        work_changes: Vec::new(),
        work_compared: false,
        notes: Vec::new(),
    }
}

/// The estimate of two runs measured apart: their samples' logs as two independent groups
/// (each sample already paired with the reference workload timed beside it when normalised).
fn unpaired(base: &[f64], current: &[f64]) -> Option<LogRatio> {
    let logs = |v: &[f64]| v.iter().map(|x| x.ln()).collect::<Vec<f64>>();
    LogRatio::independent(&logs(base), &logs(current))
}

/// Each round's level (log of its median sample, normalised as `how` says); `None` for a round
/// without a usable sample, so that rounds stay aligned for pairing.
fn round_levels(file: &ResultsFile, record: &CaseRecord, how: Normalization) -> Vec<Option<f64>> {
    let rate = calibrated_rate(file).unwrap_or(1.0);
    record
        .rounds
        .iter()
        .map(|r| match how {
            Normalization::None => round_level(r.samples_s.iter().copied()),
            Normalization::Calibration => round_level(r.samples_s.iter().map(|s| s * rate)),
            Normalization::Reference => {
                round_level(r.samples_s.iter().zip(&r.reference_s).map(|(s, x)| s / x))
            }
        })
        .collect()
}

/// One pair of sample sets judged alone, as the gate judges one case: the ratio of the medians
/// current / baseline, its bootstrap 95% interval, and the verdict at [`FAMILY_ALPHA`] against
/// `1 ± threshold` (with a single hypothesis, Holm's rule is the plain test). For a caller that
/// compares builds one pair at a time (the bisection) with the gate's statistics.
pub fn judge_pair(
    baseline: &[f64],
    current: &[f64],
    threshold: f64,
    seed: u64,
) -> (f64, [f64; 2], Verdict) {
    let clean = |v: &[f64]| -> Vec<f64> {
        v.iter()
            .copied()
            .filter(|s| s.is_finite() && *s > 0.0)
            .collect()
    };
    let (b, c) = (clean(baseline), clean(current));
    let ratio = median_of(&c) / median_of(&b);
    if b.len().min(c.len()) < MIN_CI_SAMPLES {
        return (ratio, [f64::NAN; 2], Verdict::Unchanged);
    }
    let resamples = GateOptions::default().resamples;
    let (ci, tails) = ratio_interval(&b, &c, resamples, seed, threshold);
    let verdict = if tails.regressed <= FAMILY_ALPHA {
        Verdict::Regressed
    } else if tails.improved <= FAMILY_ALPHA {
        Verdict::Improved
    } else {
        Verdict::Unchanged
    };
    (ratio, ci, verdict)
}

/// The bootstrap 95% interval of median(current) / median(baseline) and its one-sided
/// p-values against the threshold's margins (NaN and no claim when a side is empty).
pub(super) fn ratio_interval(
    baseline: &[f64],
    current: &[f64],
    resamples: usize,
    seed: u64,
    threshold: f64,
) -> ([f64; 2], Tails) {
    if baseline.is_empty() || current.is_empty() {
        return ([f64::NAN; 2], Tails::NONE);
    }
    let replicates =
        bootstrap_medians(&[baseline, current], resamples, seed, |m| Some(m[1] / m[0]));
    let ci = interval95(replicates.iter().copied()).unwrap_or([f64::NAN; 2]);
    (ci, Tails::of(&replicates, threshold))
}

/// Every raw sample of a case (seconds per step), in round order.
fn samples(record: &CaseRecord) -> Vec<f64> {
    record
        .rounds
        .iter()
        .flat_map(|r| r.samples_s.iter().copied())
        .filter(|s| s.is_finite() && *s > 0.0)
        .collect()
}

fn median_of(values: &[f64]) -> f64 {
    median(values).unwrap_or(f64::NAN)
}

/// Whether every sample of the case has its reference measurement.
fn has_reference(record: &CaseRecord) -> bool {
    record.rounds.iter().all(|r| {
        r.reference_s.len() == r.samples_s.len()
            && r.reference_s.iter().all(|x| x.is_finite() && *x > 0.0)
    })
}

fn choose_normalization(
    baseline: &ResultsFile,
    base: &CaseRecord,
    current: &ResultsFile,
    cur: &CaseRecord,
    options: &GateOptions,
) -> Result<Normalization, GateError> {
    let reference = has_reference(base) && has_reference(cur);
    let calibration = calibrated_rate(baseline).is_some() && calibrated_rate(current).is_some();
    let unavailable = |wanted, why| GateError::NormalizationUnavailable {
        key: base.key.clone(),
        wanted,
        why,
    };
    Ok(match options.normalization {
        NormalizationChoice::Auto if reference => Normalization::Reference,
        NormalizationChoice::Auto if calibration => Normalization::Calibration,
        NormalizationChoice::Auto | NormalizationChoice::None => Normalization::None,
        NormalizationChoice::Reference if reference => Normalization::Reference,
        NormalizationChoice::Reference => {
            return Err(unavailable(
                "reference",
                "a run did not time the reference workload: set measure.reference_s",
            ));
        }
        NormalizationChoice::Calibration if calibration => Normalization::Calibration,
        NormalizationChoice::Calibration => {
            return Err(unavailable(
                "calibration",
                "a run was swept with --no-calibration",
            ));
        }
    })
}

/// The case's samples divided by the machine measurement `how` chooses: each sample by the
/// reference timed right before it (dimensionless), or by the time of a GFLOP at the
/// calibrated rate, or nothing (seconds).
fn normalized(file: &ResultsFile, record: &CaseRecord, how: Normalization) -> Vec<f64> {
    match how {
        Normalization::None => samples(record),
        Normalization::Calibration => {
            let rate = calibrated_rate(file).unwrap_or(1.0);
            samples(record).into_iter().map(|s| s * rate).collect()
        }
        Normalization::Reference => record
            .rounds
            .iter()
            .flat_map(|r| r.samples_s.iter().zip(&r.reference_s).map(|(s, r)| s / r))
            .filter(|s| s.is_finite() && *s > 0.0)
            .collect(),
    }
}

/// The work of one force computation on the initial state, from the first round that has it.
fn initial_work(record: &CaseRecord) -> Option<WorkCounters> {
    record.rounds.iter().find_map(|r| r.initial_work)
}

/// Exact comparison of the deterministic counters: (changes, whether the kernels' counters
/// were compared at all, notes).
fn compare_work(base: &CaseRecord, cur: &CaseRecord) -> (Vec<WorkChange>, bool, Vec<String>) {
    let mut changes = Vec::new();
    let mut notes = Vec::new();
    let mut check = |counter: &str, b: u64, c: u64| {
        if b != c {
            changes.push(WorkChange {
                counter: counter.to_string(),
                baseline: b,
                current: c,
            });
        }
    };
    check("particles", base.n as u64, cur.n as u64);
    let compared = initial_work(base).is_some() && initial_work(cur).is_some();
    match (initial_work(base), initial_work(cur)) {
        (Some(b), Some(c)) => {
            check("pair_checks", b.pair_checks, c.pair_checks);
            check(
                "pairs_interacting",
                b.pairs_interacting,
                c.pairs_interacting,
            );
            check("cells_visited", b.cells_visited, c.cells_visited);
            check("nodes_opened", b.nodes_opened, c.nodes_opened);
            check("nodes_accepted", b.nodes_accepted, c.nodes_accepted);
            check("rebuilds", b.rebuilds, c.rebuilds);
            check("list_entries", b.list_entries, c.list_entries);
        }
        _ => notes.push(
            "work counters not compared (a file has no initial_work: swept by an older version)"
                .to_string(),
        ),
    }
    // Every round starts from the same seed, so its initial work must be the same too.
    for (record, which) in [(base, "baseline"), (cur, "current")] {
        let first = initial_work(record);
        if record
            .rounds
            .iter()
            .any(|r| r.initial_work.is_some() && r.initial_work != first)
        {
            notes.push(format!(
                "{which}: the initial work differs between rounds of one run (nondeterministic kernel?)"
            ));
        }
    }
    (changes, compared, notes)
}
