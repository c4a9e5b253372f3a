//! The study's blocks judged as gate decisions, under each candidate rule and threshold, and
//! the tallies the study file keeps: false alarms of unchanged code, and power against each
//! slowdown, per mode, with exact binomial intervals.

use super::{Block, RawStudy, SLOWDOWNS};
use crate::gate::family::{FAMILY_ALPHA, clopper_pearson, holm};
use crate::gate::{CaseComparison, GateOptions, Judged, compare};
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
}

impl Mode {
    /// The mode as the study's tables name it: "A/B" or "fast path".
    pub fn name(self) -> &'static str {
        match self {
            Mode::Ab => "A/B",
            Mode::Fast => "fast path",
        }
    }

    /// The thresholds the study judges each decision at.
    pub fn candidates(self) -> &'static [f64] {
        match self {
            Mode::Ab => &[0.02, 0.03, 0.05, 0.10],
            Mode::Fast => &[0.05, 0.10, 0.15, 0.25],
        }
    }
}

/// The rules a case can be judged on.
pub const RULES: [Judged; 3] = [Judged::Normalized, Judged::Raw, Judged::Both];

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
    let levels: Vec<f64> = std::iter::once(1.0)
        .chain(if raw.duet {
            Vec::new()
        } else {
            SLOWDOWNS.to_vec()
        })
        .collect();
    let judged: Vec<Vec<Outcome>> = {
        use rayon::prelude::*;
        raw.blocks
            .par_iter()
            .map(|block| judge_block(raw, block, baseline, &levels))
            .collect()
    };
    for outcome in judged.into_iter().flatten() {
        if outcome.slowdown != 1.0 {
            let (mode, level) = (outcome.mode, outcome.slowdown);
            match steps.iter_mut().find(|s| s.0 == mode && s.1 == level) {
                Some(s) => {
                    s.2.extend(&outcome.slowed.0);
                    s.3.extend(&outcome.slowed.1)
                }
                None => steps.push((mode, level, outcome.slowed.0, outcome.slowed.1)),
            }
        }
        if outcome.slowdown == 1.0 {
            match widths.iter_mut().find(|w| w.0 == outcome.mode) {
                Some(w) => {
                    w.1.extend(&outcome.widths.0);
                    w.2.extend(&outcome.widths.1)
                }
                None => widths.push((outcome.mode, outcome.widths.0, outcome.widths.1)),
            }
        }
        for (rule, threshold, flags) in outcome.flags {
            let found = tallies.iter().position(|t| {
                t.mode == outcome.mode
                    && t.rule == rule
                    && t.threshold == threshold
                    && t.slowdown == outcome.slowdown
            });
            let index = found.unwrap_or_else(|| {
                tallies.push(Tally {
                    mode: outcome.mode,
                    rule,
                    threshold,
                    slowdown: outcome.slowdown,
                    decisions: 0,
                    any_flagged: 0,
                    exactly_slowed: 0,
                    other_flagged: 0,
                });
                tallies.len() - 1
            });
            let t = &mut tallies[index];
            t.decisions += 1;
            let flagged =
                |target: bool| flags.iter().any(|&(is_target, f)| f && is_target == target);
            t.any_flagged += usize::from(flags.iter().any(|&(_, f)| f));
            t.other_flagged += usize::from(flagged(false));
            let all_targets = flags.iter().filter(|f| f.0).all(|f| f.1);
            t.exactly_slowed += usize::from(all_targets && !flagged(false) && flagged(true));
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

/// One decision judged under every rule and threshold.
struct Outcome {
    mode: Mode,
    slowdown: f64,
    /// (rule, threshold, the cases' flags).
    flags: Vec<(Judged, f64, CaseFlags)>,
    /// Per-case interval widths, normalised and raw (A/A decisions).
    widths: (Vec<f64>, Vec<f64>),
    /// The slowed kernel's cases' ratios, normalised and raw (slowdown decisions).
    slowed: (Vec<f64>, Vec<f64>),
}

fn judge_block(
    raw: &RawStudy,
    block: &Block,
    baseline: Option<&ResultsFile>,
    levels: &[f64],
) -> Vec<Outcome> {
    let mut out = Vec::new();
    for (level_index, &slowdown) in levels.iter().enumerate() {
        let current = with_slowed(raw, block, level_index.checked_sub(1));
        let a = file(raw, block.a.clone());
        let b = file(raw, current);
        let mut pairs = vec![(Mode::Ab, a)];
        if let Some(base) = baseline {
            pairs.push((Mode::Fast, base.clone()));
        }
        for (mode, base) in pairs {
            let mut flags = Vec::new();
            let mut widths = (Vec::new(), Vec::new());
            let mut slowed = (Vec::new(), Vec::new());
            for &threshold in mode.candidates() {
                let options = GateOptions {
                    threshold,
                    ..GateOptions::default()
                };
                // A decision the gate could not make (another config, too few samples) is not
                // counted at all: the study measures the decisions the gate makes.
                let Ok(report) = compare(&base, &b, &options) else {
                    continue;
                };
                if !report.missing.is_empty() {
                    continue;
                }
                if widths.0.is_empty() && slowed.0.is_empty() {
                    let target = format!("/{}/", raw.slowed_kernel.name());
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
                for rule in RULES {
                    flags.push((rule, threshold, flagged(raw, &report.cases, rule)));
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

/// Holm's step-down over the cases' p-values of `rule`: (is the slowed kernel's case,
/// regressed) per case.
fn flagged(raw: &RawStudy, cases: &[CaseComparison], rule: Judged) -> CaseFlags {
    let p: Vec<f64> = cases
        .iter()
        .map(|c| match rule {
            Judged::Normalized => c.p_normalized.regressed,
            Judged::Raw => c.p_raw.regressed,
            Judged::Both => c.p_normalized.both(c.p_raw).regressed,
        })
        .collect();
    let rejected = holm(&p, FAMILY_ALPHA);
    let target = format!("/{}/", raw.slowed_kernel.name());
    cases
        .iter()
        .zip(rejected)
        .map(|(c, r)| (c.key.contains(&target), r))
        .collect()
}

/// B's records with the slowed kernel's cases at slowdown `level` (none: B as it is).
fn with_slowed(raw: &RawStudy, block: &Block, level: Option<usize>) -> Vec<CaseRecord> {
    let Some(level) = level else {
        return block.b.clone();
    };
    let mut slowed = block.slowed[level].iter();
    block
        .b
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
