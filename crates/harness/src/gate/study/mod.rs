//! The gate's noise study: many gate decisions on unchanged code (A/A) and with one kernel
//! made slower on purpose, on this machine, so that the gate's false-alarm rate and power are
//! measured figures of its own machine class rather than claims.
//!
//! One long interleaved run is cut into disjoint blocks; each block holds, for every case of
//! the gate's config, the rounds one gate decision takes of two sides measured alike (A and
//! B: the same code) and of the slowed kernel's cases at each slowdown (the test-only knob).
//! From a block come an A/B decision (A against B, or against B with the slowed kernel's
//! cases replaced) and a fast-path decision (B, or B slowed, against this class's committed
//! baseline, measured in another process at another time, as CI's sweep is). Both sides are
//! measured in this process, one round of a case after the other in alternating order, as the
//! A/B driver alternates its two builds' child processes. [`decide`] judges every block under
//! each candidate rule and threshold; the summary is written per machine class to
//! `results/gate-study/`, and docs/explanation/gate.md's table is generated from it.

pub mod decide;
mod measure;
pub mod run;
pub mod table;

pub use measure::measure_blocks;

use clap::ValueEnum;
use nbody_calibrate::Calibration;
use nbody_engine::kernels::KernelKind;
use nbody_records::results::{CaseRecord, Metadata};
use serde::{Deserialize, Serialize};

/// Schema of a study file.
pub const STUDY_SCHEMA: &str = "nbody-bench/gate-study/v1";

/// The slowdowns the study measures (factors of the slowed kernel's force computation).
pub const SLOWDOWNS: [f64; 3] = [1.05, 1.10, 1.25];

/// What else runs on the machine while the study measures.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, ValueEnum)]
#[serde(rename_all = "kebab-case")]
pub enum Load {
    /// Nothing of the study's own.
    Quiet,
    /// A second process spinning on one CPU for the whole run.
    Spin,
}

/// How a run's decisions were judged.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Method {
    /// The rule before paired decisions: a fixed 4 rounds, a bootstrap of all samples' medians.
    #[default]
    BootstrapMedians,
    /// Paired rounds (A/B) or the samples' logs (fast path) with t intervals, A/B in looks
    /// ([`crate::gate::sequential`]).
    PairedSequential,
}

/// What one block measured: per case, the rounds of each side.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Block {
    /// Wall time the block took, seconds.
    pub wall_s: f64,
    /// Side A's and B's records of every case, in the config's case order.
    pub a: Vec<CaseRecord>,
    /// Side B's records of every case, likewise (the same code as A).
    pub b: Vec<CaseRecord>,
    /// For each slowdown of [`SLOWDOWNS`], the slowed kernel's cases' records (the others are
    /// B's: the knob changes nothing else).
    pub slowed: Vec<Vec<CaseRecord>>,
    /// In a duet, for each slowdown, the slowed kernel's cases' A records measured at the same
    /// moment as that slowdown's rounds: the slowdown's decisions pair those (empty when the
    /// sides took turns, whose slowdown decisions pair with A).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub partners: Vec<Vec<CaseRecord>>,
}

/// One measuring run of the study: its conditions and raw blocks (kept in the run
/// directory; the study file keeps the summary).
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct RawStudy {
    /// Schema of the raw file, [`STUDY_SCHEMA`].
    pub schema: String,
    /// The build and host the run measured with.
    pub metadata: Metadata,
    /// The machine's calibration taken before the blocks.
    pub calibration: Calibration,
    /// What else ran on the machine meanwhile.
    pub load: Load,
    /// Both sides measured at the same moment, one per CPU.
    pub duet: bool,
    /// The kernel whose force computation the slowed sides made slower.
    pub slowed_kernel: KernelKind,
    /// The gate's config the blocks measured (the class's baseline's).
    pub config: nbody_records::config::SweepConfig,
    /// Rounds of every case per side in a block: one gate decision's, [`crate::gate::AB_ROUNDS`].
    pub rounds: usize,
    /// Samples of every case in each round.
    pub samples_per_round: usize,
    /// The blocks measured, in order; each gives one decision per mode and slowdown.
    pub blocks: Vec<Block>,
}

/// The study file of one machine class (`results/gate-study/<class>.json`): what the gate's
/// noise study measured there, run by run, summarised.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct StudyFile {
    /// Schema of the study file, [`STUDY_SCHEMA`].
    pub schema: String,
    /// CPU model of the machine class, from the calibration.
    pub cpu_model: String,
    /// Vendor, family, model and stepping of the class; `None` when not recorded.
    pub cpu_signature: Option<String>,
    /// Logical CPUs of the machine class.
    pub logical_cpus: usize,
    /// The SIMD level the kernels ran with.
    pub simd: String,
    /// The gate's config the decisions were made on, and the baseline file the fast-path
    /// decisions compared with (none: no fast-path decisions).
    pub config_name: String,
    /// File name of that baseline in the baseline folder; `None`: no fast-path decisions.
    pub baseline: Option<String>,
    /// The study's runs, at most one per load and mode (duet or not).
    pub runs: Vec<StudyRun>,
}

/// One measuring run of the study, summarised.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct StudyRun {
    /// UTC, ISO 8601, when the run started.
    pub started: String,
    /// Commit the measuring build came from.
    pub git_commit: String,
    /// Whether that build had uncommitted changes.
    pub git_dirty: bool,
    /// What else ran on the machine meanwhile.
    pub load: Load,
    /// Both sides were measured at the same moment, one per CPU (A/A decisions only).
    pub duet: bool,
    /// The kernel made slower for the power decisions.
    pub slowed_kernel: KernelKind,
    /// How the decisions were judged (runs before paired decisions: a bootstrap of medians).
    #[serde(default)]
    pub method: Method,
    /// Most rounds per side of an A/B decision's case (= `rounds` for runs that judged once).
    #[serde(default)]
    pub max_rounds: usize,
    /// Blocks measured, each one decision per mode and slowdown.
    pub blocks: usize,
    /// Cases of the config each decision judged.
    #[serde(default)]
    pub cases: usize,
    /// Rounds of every case per side in a block.
    pub rounds: usize,
    /// Samples of every case in each round.
    pub samples_per_round: usize,
    /// Median wall time of one block (all its sides), seconds.
    pub block_wall_s: f64,
    /// Median wall time of measuring one decision's two sides (A and B), seconds: for paired
    /// sequential runs, the block's time times the share of its rounds the gate's own A/A
    /// decision took.
    pub decision_measure_s: f64,
    /// Decisions counted per mode, rule, threshold and slowdown.
    pub tallies: Vec<decide::Tally>,
    /// Median relative widths of the A/A decisions' per-case intervals, per mode.
    pub widths: Vec<decide::Widths>,
    /// What each slowdown of the force computation made of the slowed kernel's step.
    #[serde(default)]
    pub step_ratios: Vec<decide::StepRatio>,
}

impl StudyRun {
    /// The summary of a measured run.
    pub fn of(raw: &RawStudy, baseline: Option<&nbody_records::results::ResultsFile>) -> Self {
        let (tallies, widths, step_ratios) = decide::tally(raw, baseline);
        let walls: Vec<f64> = raw.blocks.iter().map(|b| b.wall_s).collect();
        let block_wall_s = nbody_engine::stats::median(&walls).unwrap_or(f64::NAN);
        // A block also measures rounds for the slowed sides and for the candidate thresholds:
        // the gate's own A/A decision takes the share of its rounds in the block's.
        let share = |b: &Block| {
            let rounds =
                |records: &[CaseRecord]| -> usize { records.iter().map(|r| r.rounds.len()).sum() };
            let all =
                rounds(&b.a) + rounds(&b.b) + b.slowed.iter().map(|s| rounds(s)).sum::<usize>();
            let (report, _) = decide::replay(
                raw,
                &b.a,
                &b.b,
                crate::gate::AB_JUDGE,
                crate::gate::AB_THRESHOLD,
            );
            let looks = decide::looks();
            let own: usize = report.map_or(0, |r| {
                r.cases
                    .iter()
                    .map(|c| 2 * looks[c.look.clamp(1, looks.len()) - 1])
                    .sum()
            });
            own as f64 / all.max(1) as f64
        };
        let decision: Vec<f64> = raw.blocks.iter().map(|b| b.wall_s * share(b)).collect();
        StudyRun {
            started: raw.metadata.started.clone(),
            git_commit: raw.metadata.git_commit.clone(),
            git_dirty: raw.metadata.git_dirty,
            load: raw.load,
            duet: raw.duet,
            slowed_kernel: raw.slowed_kernel,
            method: Method::PairedSequential,
            max_rounds: crate::gate::AB_MAX_ROUNDS,
            blocks: raw.blocks.len(),
            cases: raw.blocks.first().map_or(0, |b| b.a.len()),
            rounds: raw.rounds,
            samples_per_round: raw.samples_per_round,
            block_wall_s,
            decision_measure_s: nbody_engine::stats::median(&decision).unwrap_or(f64::NAN),
            tallies,
            widths,
            step_ratios,
        }
    }

    /// The median step ratio of the slowed kernel's cases at `slowdown` (A/B, normalised).
    pub fn step_ratio(&self, slowdown: f64) -> Option<f64> {
        self.step_ratios
            .iter()
            .find(|s| s.mode == decide::Mode::Ab && s.slowdown == slowdown)
            .map(|s| s.normalized)
    }

    /// Its tally of `mode`, `rule`, `threshold` and `slowdown`.
    pub fn tally(
        &self,
        mode: decide::Mode,
        rule: crate::gate::Judged,
        threshold: f64,
        slowdown: f64,
    ) -> Option<&decide::Tally> {
        self.tallies.iter().find(|t| {
            t.mode == mode && t.rule == rule && t.threshold == threshold && t.slowdown == slowdown
        })
    }
}

impl StudyFile {
    /// Reads a study file; an error names the path and what is wrong.
    pub fn load(path: &std::path::Path) -> Result<StudyFile, String> {
        let text =
            nbody_engine::input::read_text(path).map_err(|e| format!("{}: {e}", path.display()))?;
        let file: StudyFile =
            serde_json::from_str(&text).map_err(|e| format!("{}: {e}", path.display()))?;
        if file.schema != STUDY_SCHEMA {
            return Err(format!(
                "{}: schema `{}`, this build reads `{STUDY_SCHEMA}`",
                path.display(),
                file.schema
            ));
        }
        Ok(file)
    }

    /// The class's name as the baseline files spell it, e.g. `AuthenticAMD-26-2-1-2cpu`.
    pub fn class(&self) -> String {
        crate::gate::baselines::class_name(self.cpu_signature.as_deref(), Some(self.logical_cpus))
    }

    /// Adds `run`, replacing an earlier run of the same load and mode (duet or not).
    pub fn put(&mut self, run: StudyRun) {
        self.runs
            .retain(|r| !(r.load == run.load && r.duet == run.duet));
        self.runs.push(run);
        self.runs.sort_by_key(|r| (r.duet, r.load == Load::Spin));
    }
}
