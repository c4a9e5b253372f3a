//! The regression gate: two sweep results files in, a typed verdict per case out.
//!
//! [`compare`] is a pure function from a baseline and a current [`ResultsFile`] to a
//! [`GateReport`]; [`formatted`] turns the report into text, Markdown (for a CI job summary) or
//! JSON. The rules:
//!
//! - cases are matched by their key; a baseline case the current run did not measure is
//!   reported as missing (and the gate exits 2), a case only in the current run as extra;
//! - times are normalised by a measurement of the machine taken in the same run (see
//!   [`Normalization`]), so a uniformly slower machine is not a slower kernel;
//! - the statistic is the ratio current / baseline of the normalised medians (and of the raw
//!   ones), with a bootstrap 95% CI from the raw samples and one-sided p-values against
//!   `1 ± threshold` from the same replicates; a case regressed only when its p-value passes
//!   Holm's step-down over all the cases ([`family`]), improved by the same rule below, else
//!   it is unchanged;
//! - the deterministic work counters of the initial state are compared exactly, and a change
//!   is reported as such;
//! - results from another machine (CPU model, logical CPUs), build (SIMD level, profile) or
//!   config are refused unless forced.

pub mod ab;
pub mod base_build;
pub mod baselines;
mod checks;
mod compare;
pub mod drive;
pub mod duet;
pub mod family;
mod format;
pub mod guard;
pub mod paired;
pub mod route;
pub mod save;
pub mod sequential;
pub mod study;
#[cfg(test)]
mod tests;

pub use checks::{
    BUSY_BASELINE_CPUS, RATE_TOLERANCE, background_cpus, calibrated_rate, prefix, rates_differ,
};
#[cfg(test)]
pub(crate) use compare::judged_case;
pub use compare::{check_threshold, compare, judge_pair};
pub use family::Tails;
pub use format::{Format, formatted};

use nbody_records::results::ResultsFile;
use serde::Serialize;
use thiserror::Error;

/// Default threshold of an A/B run (both builds interleaved in one run): the paired rounds
/// ([`paired`]) measured in looks ([`sequential`]) resolve a 5% slowdown at 2% (the gate's
/// noise study, docs/explanation/gate.md, results/gate-study/); a change of code layout alone
/// can move a kernel by that much, which is then reported as what it is.
pub const AB_THRESHOLD: f64 = 0.02;
/// The ratio an A/B run judges by default: the raw one, fair since both builds run interleaved
/// (the reference workload only adds its own noise to a pair of adjacent rounds).
pub const AB_JUDGE: Judged = Judged::Raw;
/// Default threshold against a baseline file measured at another time, and the ratio it
/// judges: the raw ratio alone gave false alarms beside a spinning process, the normalised
/// and the raw one both none; 0.10 leaves room for the drift between days the study could not
/// see.
pub const FILE_THRESHOLD: f64 = 0.10;
/// The ratio judged against a baseline file by default: a change counts only if both show it.
pub const FILE_JUDGE: Judged = Judged::Both;
/// Default rounds of every case per build in an A/B run's first look (even: each build goes
/// first as often).
pub const AB_ROUNDS: usize = 4;
/// Default most rounds per build of a case an A/B run's first look left undecided: up to four
/// looks of [`AB_ROUNDS`] ([`sequential`]).
pub const AB_MAX_ROUNDS: usize = 16;

/// Largest `--threshold`: 1.0 flags a case only once it is surely more than twice the
/// baseline (and no improvement can be claimed, 1 − 1 = 0); a larger one judges nothing.
pub const MAX_THRESHOLD: f64 = 1.0;

/// Fewest positive samples per side a case's 95% CI is judged on. The bootstrap resamples
/// each side's samples; with n samples the resampled median is the smallest sample in
/// P(Binomial(n, 1/n) > n/2) of the resamples: 26% for n = 3, 5% for n = 4 or 5, 0.9% for
/// n = 6. Only from 6 on does the 2.5% tail fall inside the data, so that the interval comes
/// from the spread of the samples rather than being pinned to their extremes (with one
/// sample per side it is the single ratio, e.g. [1.500, 1.500]).
pub const MIN_CI_SAMPLES: usize = 6;

/// Schema of the JSON rendering of a [`GateReport`].
pub(crate) const GATE_SCHEMA: &str = "nbody-bench/gate/v1";

/// The first few of `items`, "; "-separated, with how many more there are.
pub fn listed(items: &[String]) -> String {
    const SHOWN: usize = 5;
    let mut text = items
        .iter()
        .take(SHOWN)
        .cloned()
        .collect::<Vec<_>>()
        .join("; ");
    if items.len() > SHOWN {
        text += &format!("; and {} more", items.len() - SHOWN);
    }
    text
}

/// How to compare.
#[derive(Clone, Debug, PartialEq)]
pub struct GateOptions {
    /// Relative change a case must exceed, at the family-wise confidence, to count (0.10 = 10%).
    pub threshold: f64,
    /// Compare results from another machine, build or config anyway (with warnings).
    pub force: bool,
    /// Which machine measurement the case times are divided by before comparing.
    pub normalization: NormalizationChoice,
    /// A change of the work counters makes the gate fail too (exit 1).
    pub fail_on_work_change: bool,
    /// Which ratio a case is judged on.
    pub judge: Judged,
    /// Bootstrap resamples per case, and the seed they start from (with the case key mixed in).
    pub resamples: usize,
    /// Seed of the bootstrap resampling; each case mixes its key's hash into it.
    pub seed: u64,
    /// Whether round r of both runs was measured back to back (A/B) or the runs apart.
    pub pairing: paired::Pairing,
    /// Which look of a sequential run this is ([`sequential`]); a single one by default.
    pub look: sequential::Look,
    /// Cases decided at an earlier look, with their comparisons as then: kept as they were.
    pub closed: Vec<CaseComparison>,
}

impl Default for GateOptions {
    fn default() -> Self {
        GateOptions {
            threshold: 0.10,
            force: false,
            normalization: NormalizationChoice::Auto,
            fail_on_work_change: false,
            judge: Judged::Both,
            resamples: 4000,
            seed: 0x9a7e,
            pairing: paired::Pairing::Independent,
            look: sequential::Look::SINGLE,
            closed: Vec::new(),
        }
    }
}

/// Which normalisation to use; `Auto` takes the best one both files have.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, clap::ValueEnum)]
#[serde(rename_all = "kebab-case")]
pub enum NormalizationChoice {
    /// The reference workload if both runs timed it for the case, else the calibration, else none.
    Auto,
    /// Divide each sample by the reference workload timed before it; an error if a run lacks it.
    Reference,
    /// Divide by the time of the sweep's calibrated FMA rate; an error if a run has none.
    Calibration,
    /// Raw seconds per step, not normalised.
    None,
}

/// The ratio a case is judged on. The normalised ratio cancels the machine's speed and
/// load, but the reference workload can speed up more than the kernels (a run on a quieter
/// machine than its baseline's then reads slower); the raw ratio is fair only between runs
/// measured side by side. `Both` claims a change only when both ratios show it (an
/// intersection-union test, at the same level): the rule the gate's noise study chose
/// (docs/explanation/gate.md).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, serde::Deserialize, clap::ValueEnum)]
#[serde(rename_all = "kebab-case")]
pub enum Judged {
    /// The ratio of the normalised medians alone.
    Normalized,
    /// The ratio of the raw medians (seconds per step) alone.
    Raw,
    /// Both ratios: a change is claimed only when each of them shows it.
    Both,
}

/// What the case's times were divided by before comparing.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Normalization {
    /// Each sample by the reference workload timed right before it, on the same threads, for
    /// about as long (`measure.reference_s`): tracks the share of the machine the case got.
    Reference,
    /// Every sample by the time of the sweep's calibrated FMA rate (mean of the start and end
    /// calibrations): tracks the machine's speed at the start and end of the sweep only.
    Calibration,
    /// Raw seconds per step.
    None,
}

impl Normalization {
    /// What the times were divided by, as a phrase for the report ("the sweep's calibrated ...").
    pub fn describe(self) -> &'static str {
        match self {
            Normalization::Reference => "the reference workload timed before each sample",
            Normalization::Calibration => "the sweep's calibrated FMA rate",
            Normalization::None => "nothing (raw times)",
        }
    }
}

/// The verdict on one case.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Verdict {
    /// Slower by more than the threshold, with the family-wise error of [`family`]: the
    /// case's p-value for "at most 1 + threshold" passed Holm's step-down over the cases.
    Regressed,
    /// Faster by more than the threshold, by the same rule below 1 − threshold.
    Improved,
    /// Within the threshold: its 90% interval lies within ±2 × threshold
    /// ([`sequential::EQUIVALENCE`]).
    Unchanged,
    /// Neither shown changed at the family-wise confidence nor shown unchanged: the
    /// measurement was too noisy to tell. Not a failure; the report says how to measure more.
    Unknown,
}

impl Verdict {
    /// The verdict as written in reports and JSON: "regressed", "improved" or "unchanged".
    pub fn name(self) -> &'static str {
        match self {
            Verdict::Regressed => "regressed",
            Verdict::Improved => "improved",
            Verdict::Unchanged => "unchanged",
            Verdict::Unknown => "unknown",
        }
    }
}

/// One case measured in both runs.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct CaseComparison {
    /// The case's key in the results files, shared by both runs.
    pub key: String,
    /// Set across all cases by Holm's step-down once every case has its p-values.
    pub verdict: Verdict,
    /// What the case's times were divided by, chosen per case from what both runs measured.
    pub normalization: Normalization,
    /// Raw median seconds per step in each run.
    pub(crate) baseline_median_s: f64,
    pub(crate) current_median_s: f64,
    /// Ratio of the raw medians, for reference.
    pub(crate) raw_ratio: f64,
    /// Ratio current / baseline of the normalised round levels ([`paired`]): the statistic.
    pub ratio: f64,
    /// 95% confidence interval of `ratio`, of the case alone.
    pub ci95: [f64; 2],
    /// 95% confidence interval of `raw_ratio`, of the case alone.
    pub raw_ci95: [f64; 2],
    /// Interval of `ratio` at the level the verdicts were decided at (each side α / (K m) for
    /// K looks and m cases): wholly past a margin, the case is flagged at the family-wise error.
    pub family_ci: [f64; 2],
    /// The same interval of `raw_ratio`.
    pub raw_family_ci: [f64; 2],
    /// Holm-adjusted p-value of the verdict's test (of "slower" unless the case improved), on
    /// the family's scale: a change is claimed when it is at most the family-wise error.
    pub adjusted_p: f64,
    /// Independent units per side the estimate used: rounds (pairs in an A/B run), or samples.
    pub units: [usize; 2],
    /// The look (from 1) that decided the case.
    pub look: usize,
    /// Whether its 90% interval lies within ±2 × threshold: unchanged, unless flagged.
    #[serde(skip)]
    pub(crate) equivalent: bool,
    /// The normalised and the raw estimate the intervals and p-values come from.
    #[serde(skip)]
    pub(crate) estimates: (paired::LogRatio, paired::LogRatio),
    /// One-sided p-values the verdict comes from (of the ratio the gate judges on).
    pub p: family::Tails,
    /// Those of the normalised ratio and of the raw ratio alone.
    pub p_normalized: family::Tails,
    /// Those of the raw ratio alone.
    pub p_raw: family::Tails,
    /// Samples in each run.
    pub samples: [usize; 2],
    /// Deterministic work counters that differ between the runs.
    pub work_changes: Vec<WorkChange>,
    /// Whether the kernels' work counters were compared (both runs recorded them).
    pub(crate) work_compared: bool,
    /// Anything that weakens the comparison (incomplete case, failed sanity check, ...).
    pub notes: Vec<String>,
}

/// A work counter of the initial state that differs.
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct WorkChange {
    /// Name of the counter, e.g. `particles`, `pair_checks` or `nodes_opened`.
    pub counter: String,
    /// Its value in the baseline run.
    pub baseline: u64,
    /// Its value in the current run.
    pub current: u64,
}

/// A baseline case that could not be compared, or a check of it that could compare nothing
/// (too few samples for a CI, work counters asked for but absent): the gate exits 2.
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct MissingCase {
    /// The baseline case's key.
    pub key: String,
    /// Why it was not compared, as a sentence for the report.
    pub reason: String,
}

/// Where a results file comes from.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct RunInfo {
    /// Commit the run's binary was built from, as recorded in the file's metadata.
    pub git_commit: String,
    /// Whether that build had uncommitted changes.
    pub git_dirty: bool,
    /// UTC, ISO 8601, when the sweep started (empty when not recorded).
    pub started: String,
    /// Host name the run was measured on (empty when not recorded).
    pub host: String,
    /// CPU model of the calibration; `None` when the run was swept without calibration.
    pub cpu_model: Option<String>,
    /// Vendor, family, model and stepping (e.g. `AuthenticAMD 26/2/1`); `None` when not recorded.
    pub cpu_signature: Option<String>,
    /// Logical CPUs the calibration saw; `None` when the run was swept without calibration.
    pub logical_cpus: Option<usize>,
}

impl RunInfo {
    /// Why the two runs are not known to come from one machine class (CPU model, CPU
    /// signature, logical CPU count), or `None` when they are. A run that did not record a
    /// CPU signature is of an unknown class: its timings cannot be trusted to match.
    pub fn machine_class_differs(&self, other: &RunInfo) -> Option<String> {
        let show = |v: &Option<String>| v.clone().unwrap_or_else(|| "not recorded".into());
        if self.cpu_model != other.cpu_model {
            return Some(format!(
                "CPU model `{}` there, `{}` here",
                show(&self.cpu_model),
                show(&other.cpu_model)
            ));
        }
        if self.cpu_signature.is_none() || self.cpu_signature != other.cpu_signature {
            return Some(format!(
                "CPU signature `{}` there, `{}` here",
                show(&self.cpu_signature),
                show(&other.cpu_signature)
            ));
        }
        if self.logical_cpus != other.logical_cpus {
            let show = |v: Option<usize>| v.map_or("not recorded".into(), |n| n.to_string());
            return Some(format!(
                "{} logical CPUs there, {} here",
                show(self.logical_cpus),
                show(other.logical_cpus)
            ));
        }
        None
    }

    /// From a results file's JSON, read field by field so that a file this build can no
    /// longer load still says where it comes from; `None` without a commit.
    pub fn from_json(value: &serde_json::Value) -> Option<RunInfo> {
        let text = |v: &serde_json::Value| v.as_str().map(str::to_string);
        let meta = &value["metadata"];
        let cal = [&value["calibration"]["start"], &value["calibration"]["end"]]
            .into_iter()
            .find(|c| c.is_object());
        let field = |name: &str| cal.and_then(|c| text(&c[name]));
        Some(RunInfo {
            git_commit: text(&meta["git_commit"])?,
            git_dirty: meta["git_dirty"].as_bool().unwrap_or(false),
            started: text(&meta["started"]).unwrap_or_default(),
            host: text(&meta["host"]).unwrap_or_default(),
            cpu_model: field("cpu_model"),
            cpu_signature: field("cpu_signature"),
            logical_cpus: cal
                .and_then(|c| c["logical_cpus"].as_u64())
                .map(|n| n as usize),
        })
    }

    /// Where a loaded results file comes from; the machine is that of its start calibration,
    /// else of its end one.
    pub fn of(file: &ResultsFile) -> RunInfo {
        let cal = file
            .calibration
            .start
            .as_ref()
            .or(file.calibration.end.as_ref());
        RunInfo {
            git_commit: file.metadata.git_commit.clone(),
            git_dirty: file.metadata.git_dirty,
            started: file.metadata.started.clone(),
            host: file.metadata.host.clone(),
            cpu_model: cal.map(|c| c.cpu_model.clone()),
            cpu_signature: cal.and_then(|c| c.cpu_signature.clone()),
            logical_cpus: cal.map(|c| c.logical_cpus),
        }
    }
}

/// The result of a gate run.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct GateReport {
    /// Schema of the report's JSON rendering (`nbody-bench/gate/v1`).
    pub schema: String,
    /// Relative change a case had to exceed to count (0.10 = 10%).
    pub threshold: f64,
    /// Whether a change of the work counters fails the gate too (exit 1).
    pub fail_on_work_change: bool,
    /// Where the baseline results come from.
    pub baseline: RunInfo,
    /// Where the current results come from.
    pub current: RunInfo,
    /// Cases measured in both runs, in the baseline's order.
    pub cases: Vec<CaseComparison>,
    /// Baseline cases that could not be compared: any makes the gate exit 2 (1 on a regression).
    pub missing: Vec<MissingCase>,
    /// Cases only the current run measured.
    pub extra: Vec<String>,
    /// Mismatches of machine, build or config that were forced through, and other caveats.
    pub warnings: Vec<String>,
    /// Which ratio the cases were judged on.
    pub judged_on: Judged,
    /// Family-wise error of the run's regressions (Holm's step-down over its cases).
    pub family_alpha: f64,
    /// How the runs' rounds were compared: pairs of back-to-back rounds, or two groups.
    pub pairing: paired::Pairing,
    /// Looks the run could take (1: judged once); each judged at `family_alpha` / looks.
    pub looks: usize,
    /// How an A/B run's two builds shared the machine in a round (none: not an A/B run).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub sides: Option<duet::Sides>,
}

impl GateReport {
    /// How many of the compared cases got `verdict`.
    pub fn count(&self, verdict: Verdict) -> usize {
        self.cases.iter().filter(|c| c.verdict == verdict).count()
    }

    pub(crate) fn work_changed(&self) -> usize {
        self.cases
            .iter()
            .filter(|c| !c.work_changes.is_empty())
            .count()
    }

    /// Whether the gate fails on this report's findings (regressions, and work changes when
    /// asked), ignoring missing cases.
    pub fn failed(&self) -> bool {
        self.count(Verdict::Regressed) > 0 || (self.fail_on_work_change && self.work_changed() > 0)
    }

    /// 1 when something regressed (whatever else the run found: a regression is never
    /// hidden behind another exit code), else 2 when baseline cases could not be compared
    /// (an incomplete comparison is not a pass), else 0.
    pub fn exit_code(&self) -> i32 {
        if self.failed() {
            1
        } else if !self.missing.is_empty() {
            2
        } else {
            0
        }
    }
}

/// Why two results files cannot be compared, or the options are invalid.
#[derive(Debug, Error)]
pub enum GateError {
    /// `--threshold` is not a number from 0 to [`MAX_THRESHOLD`].
    #[error(
        "--threshold must be a number from 0 to {max} (got {0:?}); 0.10 means 10%, {max} a \
         doubling",
        max = MAX_THRESHOLD
    )]
    BadThreshold(f64),
    /// A file has no machine calibration (swept with `--no-calibration`), and no `--force`.
    #[error(
        "the {which} results have no machine calibration (swept with --no-calibration), so \
         the machine cannot be checked; sweep again with calibration, or pass --force"
    )]
    UnknownMachine {
        /// Which file: "baseline" or "current".
        which: &'static str,
    },
    /// The files come from different machine classes (CPU model, signature or logical CPU count).
    #[error(
        "the baseline comes from another machine: {what} `{baseline}` there, `{current}` here; \
         timings are only comparable on the same machine class. Run the gate without --current \
         to measure the baseline's revision and this build side by side here (A/B), refresh the \
         baseline on this machine (scripts/refresh-baseline.sh), or pass --force to compare \
         anyway"
    )]
    OtherMachine {
        /// What differs: "CPU model", "CPU signature" or "logical CPU count".
        what: &'static str,
        /// Its value in the baseline.
        baseline: String,
        /// Its value in the current run.
        current: String,
    },
    /// The files come from builds with a different SIMD level or profile.
    #[error(
        "the baseline was built differently: {what} `{baseline}` in the baseline, `{current}` \
         now; rebuild the same way, refresh the baseline, or pass --force"
    )]
    OtherBuild {
        /// What differs: "SIMD level" or "profile".
        what: &'static str,
        /// Its value in the baseline.
        baseline: String,
        /// Its value in the current run.
        current: String,
    },
    /// The two runs swept different configs.
    #[error(
        "the two runs used different configs (they differ in {differences}); sweep the \
         baseline's config (its text is in the file's config_text), refresh the baseline, or \
         pass --force to compare the cases they share"
    )]
    OtherConfig {
        /// The config keys whose values differ, e.g. "n, measure.samples".
        differences: String,
    },
    /// The normalisation asked for with `--normalize` is missing from a run for a case.
    #[error(
        "case {key}: normalisation `{wanted}` is not available in both files ({why}); use \
         --normalize auto"
    )]
    NormalizationUnavailable {
        /// Key of the first case it is missing for.
        key: String,
        /// The normalisation asked for: "reference" or "calibration".
        wanted: &'static str,
        /// What a run lacks, with how to get it.
        why: &'static str,
    },
}
