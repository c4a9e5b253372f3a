//! The study's blocks judged as gate decisions, under each candidate rule and threshold, and
//! the tallies the study file keeps: false alarms of unchanged code, and power against each
//! slowdown, per mode, with exact binomial intervals.
//!
//! An A/B decision is replayed look by look as the gate takes it ([`crate::gate::sequential`]):
//! at each look every case is cut to the rounds the gate would have measured by then, the
//! cases decided earlier are kept as decided, and the decision ends when no case is open or at
//! the last look. [`needs`] asks the same replays, during the measurement, which cases a
//! decision would measure further, so that the study measures exactly those.

use super::{Block, RawStudy, SLOWDOWNS};
use crate::gate::family::clopper_pearson;
use crate::gate::paired::Pairing;
use crate::gate::sequential::{Look, schedule, still_open};
use crate::gate::{GateOptions, GateReport, Judged, Verdict, compare};
use nbody_records::kernel_or_program::KernelOrProgram;
use nbody_records::results::{CaseRecord, ResultsFile};
use serde::{Deserialize, Serialize};

/// How a decision is measured.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Mode {
    /// Both sides in the same run, interleaved.
    Ab,
    /// This run against the class's baseline file.
    Fast,
    /// The A/B decision the earlier rule made of the same measurements: each side's first 4
    /// rounds, all samples pooled, a bootstrap of the ratio of medians, Holm over the cases.
    AbMedians,
}

/// The modes a study judges, in the order its tables show them.
pub const MODES: [Mode; 3] = [Mode::Ab, Mode::AbMedians, Mode::Fast];

impl Mode {
    /// The mode as the study's tables name it: "A/B" or "fast path".
    pub fn name(self) -> &'static str {
        match self {
            Mode::Ab => "A/B",
            Mode::Fast => "fast path",
            Mode::AbMedians => "A/B, earlier rule (same rounds)",
        }
    }

    /// The thresholds the study judges each decision at.
    pub fn candidates(self) -> &'static [f64] {
        match self {
            Mode::Ab | Mode::AbMedians => &[0.02, 0.03, 0.05],
            Mode::Fast => &[0.05, 0.07, 0.10, 0.15],
        }
    }

    /// The rules the study judges each decision under: every rule on the fast path (one look,
    /// no extra measurement); in A/B the gate's own, since every rule and threshold replayed
    /// there asks for rounds of its own undecided cases.
    pub fn rules(self) -> &'static [Judged] {
        match self {
            Mode::Ab | Mode::AbMedians => &[crate::gate::AB_JUDGE],
            Mode::Fast => &RULES,
        }
    }
}

/// The rules a case can be judged on.
pub const RULES: [Judged; 3] = [Judged::Normalized, Judged::Raw, Judged::Both];

/// The rounds per side after each look of the study's A/B decisions: the gate's defaults.
pub fn looks() -> Vec<usize> {
    schedule(crate::gate::AB_ROUNDS, crate::gate::AB_MAX_ROUNDS)
}

/// Decisions of one kind, counted.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Tally {
    /// How the decisions were measured.
    pub mode: Mode,
    /// The ratio the cases were judged on.
    pub rule: Judged,
    /// Threshold the cases were judged at (0.05 = 5%), one of [`Mode::candidates`].
    pub threshold: f64,
    /// The slowed kernel's factor; 1 for unchanged code (A/A).
    pub slowdown: f64,
    /// Decisions made (those the gate could not make are not counted).
    pub decisions: usize,
    /// Decisions that flagged some case as regressed.
    pub any_flagged: usize,
    /// Decisions that flagged every case of the slowed kernel and no other.
    pub exactly_slowed: usize,
    /// Decisions that flagged a case of another kernel.
    pub other_flagged: usize,
    /// Decisions that left some case unknown (neither flagged nor shown unchanged).
    #[serde(default)]
    pub undecided: usize,
    /// Rounds per side summed over the decisions' cases: the measuring each decision took.
    #[serde(default)]
    pub case_rounds: usize,
}

impl Tally {
    /// The false-alarm rate (A/A) or the power (slowdown) with its 95% Clopper–Pearson
    /// interval: `any_flagged` for unchanged code, `exactly_slowed` for a slowdown.
    pub fn rate(&self) -> (f64, [f64; 2]) {
        let k = if self.slowdown == 1.0 {
            self.any_flagged
        } else {
            self.exactly_slowed
        };
        let n = self.decisions.max(1);
        (k as f64 / n as f64, clopper_pearson(k, self.decisions))
    }
}

/// The median widths of A/A decisions' per-case 95% intervals of the ratio.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Widths {
    /// How the decisions were measured.
    pub mode: Mode,
    /// Median width of the normalised ratio's interval, relative to the ratio (0.02 = ±1%).
    pub normalized: f64,
    /// Median width of the raw ratio's interval, relative to the raw ratio.
    pub raw: f64,
}

/// What a slowdown of the force computation made of the slowed kernel's whole step: the median
/// over decisions and cases of the ratio the gate saw (the step also builds, integrates and
/// applies the walls, which the knob leaves alone).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct StepRatio {
    /// How the decisions were measured.
    pub mode: Mode,
    /// The factor the knob slowed the kernel's force computation by, one of [`super::SLOWDOWNS`].
    pub slowdown: f64,
    /// Median normalised ratio of the slowed kernel's cases.
    pub normalized: f64,
    /// Median raw ratio of the slowed kernel's cases.
    pub raw: f64,
}

/// Every tally of a measured study; `baseline` is the class's baseline file for the fast
/// path (none: no fast-path decisions).
pub fn tally(
    raw: &RawStudy,
    baseline: Option<&ResultsFile>,
) -> (Vec<Tally>, Vec<Widths>, Vec<StepRatio>) {
    let mut tallies: Vec<Tally> = Vec::new();
    let mut widths: Vec<(Mode, Vec<f64>, Vec<f64>)> = Vec::new();
    let mut steps: Vec<(Mode, f64, Vec<f64>, Vec<f64>)> = Vec::new();
    let judged: Vec<Vec<Outcome>> = {
        use rayon::prelude::*;
        raw.blocks
            .par_iter()
            .map(|block| judge_block(raw, block, baseline))
            .collect()
    };
    for outcome in judged.into_iter().flatten() {
        if outcome.slowdown != 1.0 && !outcome.slowed.0.is_empty() {
            let (mode, level) = (outcome.mode, outcome.slowdown);
            match steps.iter_mut().find(|s| s.0 == mode && s.1 == level) {
                Some(s) => {
                    s.2.extend(&outcome.slowed.0);
                    s.3.extend(&outcome.slowed.1)
                }
                None => steps.push((mode, level, outcome.slowed.0, outcome.slowed.1)),
            }
        }
        if outcome.slowdown == 1.0 && !outcome.widths.0.is_empty() {
            match widths.iter_mut().find(|w| w.0 == outcome.mode) {
                Some(w) => {
                    w.1.extend(&outcome.widths.0);
                    w.2.extend(&outcome.widths.1)
                }
                None => widths.push((outcome.mode, outcome.widths.0, outcome.widths.1)),
            }
        }
        for judged in outcome.flags {
            let found = tallies.iter().position(|t| {
                t.mode == outcome.mode
                    && t.rule == judged.rule
                    && t.threshold == judged.threshold
                    && t.slowdown == outcome.slowdown
            });
            let index = found.unwrap_or_else(|| {
                tallies.push(Tally {
                    mode: outcome.mode,
                    rule: judged.rule,
                    threshold: judged.threshold,
                    slowdown: outcome.slowdown,
                    decisions: 0,
                    any_flagged: 0,
                    exactly_slowed: 0,
                    other_flagged: 0,
                    undecided: 0,
                    case_rounds: 0,
                });
                tallies.len() - 1
            });
            let t = &mut tallies[index];
            let flags = &judged.cases;
            t.decisions += 1;
            let flagged =
                |target: bool| flags.iter().any(|&(is_target, f)| f && is_target == target);
            t.any_flagged += usize::from(flags.iter().any(|&(_, f)| f));
            t.other_flagged += usize::from(flagged(false));
            let all_targets = flags.iter().filter(|f| f.0).all(|f| f.1);
            t.exactly_slowed += usize::from(all_targets && !flagged(false) && flagged(true));
            t.undecided += usize::from(judged.undecided);
            t.case_rounds += judged.case_rounds;
        }
    }
    let median = |v: &[f64]| nbody_engine::stats::median(v).unwrap_or(f64::NAN);
    let widths = widths
        .into_iter()
        .map(|(mode, n, r)| Widths {
            mode,
            normalized: median(&n),
            raw: median(&r),
        })
        .collect();
    let steps = steps
        .into_iter()
        .map(|(mode, slowdown, n, r)| StepRatio {
            mode,
            slowdown,
            normalized: median(&n),
            raw: median(&r),
        })
        .collect();
    (tallies, widths, steps)
}

/// Per case of a decision: (is the slowed kernel's, flagged as regressed).
type CaseFlags = Vec<(bool, bool)>;

/// One decision under one rule and threshold.
struct Judgement {
    rule: Judged,
    threshold: f64,
    cases: CaseFlags,
    /// Some case ended unknown.
    undecided: bool,
    /// Rounds per side, summed over the cases, the decision measured.
    case_rounds: usize,
}

/// One decision judged under every rule and threshold.
struct Outcome {
    mode: Mode,
    slowdown: f64,
    flags: Vec<Judgement>,
    /// Per-case interval widths, normalised and raw (A/A decisions).
    widths: (Vec<f64>, Vec<f64>),
    /// The slowed kernel's cases' ratios, normalised and raw (slowdown decisions).
    slowed: (Vec<f64>, Vec<f64>),
}

/// The slowdowns a block can be judged at: 1 (A/A), and each of [`SLOWDOWNS`] the block
/// measured (none in duet runs from before duets measured slowdowns).
fn levels(block: &Block) -> Vec<f64> {
    std::iter::once(1.0)
        .chain(SLOWDOWNS.iter().copied().take(block.slowed.len()))
        .collect()
}

fn options(rule: Judged, threshold: f64, pairing: Pairing) -> GateOptions {
    GateOptions {
        threshold,
        judge: rule,
        pairing,
        ..GateOptions::default()
    }
}

fn judge_block(raw: &RawStudy, block: &Block, baseline: Option<&ResultsFile>) -> Vec<Outcome> {
    let mut out = Vec::new();
    for (level_index, &slowdown) in levels(block).iter().enumerate() {
        let base = base_of(raw, block, level_index.checked_sub(1));
        let current = with_slowed(raw, block, level_index.checked_sub(1));
        let target = format!("/{}/", raw.slowed_kernel.name());
        for mode in MODES {
            let mut flags = Vec::new();
            let mut widths = (Vec::new(), Vec::new());
            let mut slowed = (Vec::new(), Vec::new());
            for &threshold in mode.candidates() {
                for &rule in mode.rules() {
                    let report = match (mode, baseline) {
                        (Mode::Ab, _) => replay(raw, &base, &current, rule, threshold).0,
                        (Mode::AbMedians, _) => {
                            let first = looks()[0];
                            let (a, b) = (
                                truncated(&base, first, None),
                                truncated(&current, first, None),
                            );
                            medians_rule(&file(raw, a), &file(raw, b), threshold)
                        }
                        // CI's sweep runs alone: a duet's sides, each measured beside the
                        // other, stand for no fast-path run.
                        (Mode::Fast, _) if raw.duet => None,
                        (Mode::Fast, Some(base)) => {
                            // CI's sweep: the first look's rounds of this side alone.
                            let first = truncated(&current, looks()[0], None);
                            let options = options(rule, threshold, Pairing::Independent);
                            compare(base, &file(raw, first), &options).ok()
                        }
                        (Mode::Fast, None) => None,
                    };
                    // A decision the gate could not make (another config, too few samples) is
                    // not counted at all: the study measures the decisions the gate makes.
                    let Some(report) = report.filter(|r| r.missing.is_empty()) else {
                        continue;
                    };
                    // The earlier rule's intervals were bootstrap ones: its widths are the
                    // study files' of that time, not these.
                    if widths.0.is_empty() && slowed.0.is_empty() && mode != Mode::AbMedians {
                        for c in &report.cases {
                            if slowdown == 1.0 {
                                widths.0.push((c.ci95[1] - c.ci95[0]) / c.ratio);
                                widths.1.push((c.raw_ci95[1] - c.raw_ci95[0]) / c.raw_ratio);
                            } else if c.key.contains(&target) {
                                slowed.0.push(c.ratio);
                                slowed.1.push(c.raw_ratio);
                            }
                        }
                    }
                    flags.push(Judgement {
                        rule,
                        threshold,
                        cases: report
                            .cases
                            .iter()
                            .map(|c| (c.key.contains(&target), c.verdict == Verdict::Regressed))
                            .collect(),
                        undecided: report.cases.iter().any(|c| c.verdict == Verdict::Unknown),
                        case_rounds: report
                            .cases
                            .iter()
                            .map(|c| looks()[c.look.clamp(1, looks().len()) - 1])
                            .sum(),
                    });
                }
            }
            if !flags.is_empty() {
                out.push(Outcome {
                    mode,
                    slowdown,
                    flags,
                    widths,
                    slowed,
                });
            }
        }
    }
    out
}

/// An A/B decision of `current` against `base` replayed look by look under `rule` and
/// `threshold`: the report of its last look, and the keys of the cases it would measure
/// further but whose rounds the records do not hold yet (none once the decision is complete).
pub fn replay(
    raw: &RawStudy,
    base: &[CaseRecord],
    current: &[CaseRecord],
    rule: Judged,
    threshold: f64,
) -> (Option<GateReport>, Vec<String>) {
    let looks = looks();
    let mut options = options(rule, threshold, Pairing::Rounds);
    let mut last = None;
    for (index, &rounds) in looks.iter().enumerate() {
        options.look = Look {
            index,
            count: looks.len(),
        };
        let measured = |records: &[CaseRecord], key: &str| {
            records
                .iter()
                .find(|r| r.key == key)
                .map_or(0, |r| r.rounds.len())
        };
        let open: Vec<String> = current
            .iter()
            .map(|c| c.key.clone())
            .filter(|k| !options.closed.iter().any(|c| &c.key == k))
            .collect();
        let short: Vec<String> = open
            .iter()
            .filter(|k| measured(base, k).min(measured(current, k)) < rounds)
            .cloned()
            .collect();
        if !short.is_empty() {
            return (last, short);
        }
        let (b, c) = (
            truncated(base, rounds, None),
            truncated(current, rounds, None),
        );
        let Ok(report) = compare(&file(raw, b), &file(raw, c), &options) else {
            return (None, Vec::new());
        };
        options.closed = report
            .cases
            .iter()
            .filter(|c| !still_open(c))
            .cloned()
            .collect();
        let done = report.cases.iter().all(|c| !still_open(c));
        last = Some(report);
        if done {
            break;
        }
    }
    (last, Vec::new())
}

/// The earlier rule's A/B decision: per case a seeded bootstrap of the ratio of the raw
/// samples' medians, one-sided p-values against the threshold, Holm over the cases. Its
/// verdicts only (regressed or unchanged), as a report.
fn medians_rule(base: &ResultsFile, current: &ResultsFile, threshold: f64) -> Option<GateReport> {
    let options = options(Judged::Raw, threshold, Pairing::Rounds);
    let mut report = compare(base, current, &options).ok()?;
    let samples = |file: &ResultsFile, key: &str| -> Vec<f64> {
        file.cases
            .iter()
            .filter(|c| c.key == key)
            .flat_map(|c| c.rounds.iter().flat_map(|r| r.samples_s.iter().copied()))
            .filter(|s| s.is_finite() && *s > 0.0)
            .collect()
    };
    let p: Vec<f64> = report
        .cases
        .iter()
        .map(|c| {
            let seed = options.seed ^ nbody_records::results::fnv1a(c.key.as_bytes());
            let (b, x) = (samples(base, &c.key), samples(current, &c.key));
            crate::gate::compare::ratio_interval(&b, &x, options.resamples, seed, threshold)
                .1
                .regressed
        })
        .collect();
    let flagged = crate::gate::family::holm(&p, crate::gate::family::FAMILY_ALPHA);
    for (c, f) in report.cases.iter_mut().zip(flagged) {
        c.verdict = if f {
            Verdict::Regressed
        } else {
            Verdict::Unchanged
        };
        c.look = 1;
    }
    Some(report)
}

/// The cases each side still needs rounds of, by key: what the A/B decisions of every
/// slowdown, under each candidate threshold of the gate's rule, would measure next.
pub fn needs(raw: &RawStudy, block: &Block) -> Vec<(String, Side)> {
    let mut need: Vec<(String, Side)> = Vec::new();
    for (level_index, _) in levels(block).iter().enumerate() {
        let slowed = level_index.checked_sub(1);
        let base = base_of(raw, block, slowed);
        let current = with_slowed(raw, block, slowed);
        for &threshold in Mode::Ab.candidates() {
            for &rule in Mode::Ab.rules() {
                for key in replay(raw, &base, &current, rule, threshold).1 {
                    let is_slowed = block
                        .slowed
                        .first()
                        .is_some_and(|s| s.iter().any(|r| r.key == key));
                    let sides = match slowed {
                        Some(k) if is_slowed && raw.duet => [Side::Partner(k), Side::Slowed(k)],
                        Some(k) if is_slowed => [Side::A, Side::Slowed(k)],
                        _ => [Side::A, Side::B],
                    };
                    for s in sides {
                        if !need.iter().any(|(k, x)| k == &key && *x == s) {
                            need.push((key.clone(), s));
                        }
                    }
                }
            }
        }
    }
    need
}

/// Which measurement a round belongs to.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Side {
    /// Side A (the base of every A/B decision).
    A,
    /// Side B, the same code as A.
    B,
    /// The slowed kernel at `SLOWDOWNS[i]`.
    Slowed(usize),
    /// In a duet, A measured at the same moment as `Slowed(i)`.
    Partner(usize),
}

/// The records with each case cut to its first `rounds` rounds (`keep`: only those keys).
fn truncated(records: &[CaseRecord], rounds: usize, keep: Option<&[String]>) -> Vec<CaseRecord> {
    records
        .iter()
        .filter(|r| keep.is_none_or(|k| k.contains(&r.key)))
        .map(|r| {
            let mut r = r.clone();
            r.rounds.truncate(rounds);
            r.rounds_done = r.rounds.len();
            r.rounds_planned = r.rounds.len();
            r
        })
        .collect()
}

/// B's records with the slowed kernel's cases at slowdown `level` (none: B as it is).
fn with_slowed(raw: &RawStudy, block: &Block, level: Option<usize>) -> Vec<CaseRecord> {
    match level {
        Some(level) => replaced(raw, &block.b, &block.slowed[level]),
        None => block.b.clone(),
    }
}

/// The base a decision at slowdown `level` pairs with: A, or in a duet the A rounds measured
/// beside that slowdown's.
fn base_of(raw: &RawStudy, block: &Block, level: Option<usize>) -> Vec<CaseRecord> {
    match level.and_then(|l| block.partners.get(l)) {
        Some(partners) if raw.duet => replaced(raw, &block.a, partners),
        _ => block.a.clone(),
    }
}

/// `records` with the slowed kernel's cases taken from `slowed`, in order.
fn replaced(raw: &RawStudy, records: &[CaseRecord], slowed: &[CaseRecord]) -> Vec<CaseRecord> {
    let mut slowed = slowed.iter();
    records
        .iter()
        .map(|record| {
            if record.case.kernel == KernelOrProgram::Kernel(raw.slowed_kernel) {
                slowed.next().cloned().unwrap_or_else(|| record.clone())
            } else {
                record.clone()
            }
        })
        .collect()
}

/// A results file of the study's records: the config they were measured with (the baseline's,
/// so that the gate compares them), this study's metadata and calibration.
fn file(raw: &RawStudy, cases: Vec<CaseRecord>) -> ResultsFile {
    ResultsFile {
        schema: nbody_records::results::RESULTS_SCHEMA.to_string(),
        metadata: raw.metadata.clone(),
        config: raw.config.clone(),
        config_text: String::new(),
        calibration: nbody_records::results::Calibrations {
            start: Some(raw.calibration.clone()),
            end: None,
        },
        cases,
    }
}
