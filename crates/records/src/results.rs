//! The results file of a sweep: schema, metadata, calibration, and every case with its raw
//! samples and summaries. Written atomically after every measured round.

use super::config::SweepConfig;
use super::plan::Case;
use super::round::RoundOutcome;
use super::vet::Rejected;
use nbody_calibrate::Calibration;
use nbody_engine::engine::PhaseTimes;
use nbody_engine::kernels::WorkCounters;
use nbody_engine::output::provenance::{git_state, host_name, utc_now};
use nbody_engine::stats::{
    BOOTSTRAP_RESAMPLES, StepHistogram, StepPercentiles, bootstrap_median_ci, mad, median,
};
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};
use thiserror::Error;

/// The `schema` value of results files this version writes and reads; any other is refused.
pub const RESULTS_SCHEMA: &str = "nbody-bench/results/v1";

/// A sweep's `results.json`: everything needed to analyse it again without re-running.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct ResultsFile {
    /// Always [`RESULTS_SCHEMA`] in a file this version loads.
    pub schema: String,
    /// The build and machine that produced the results.
    pub metadata: Metadata,
    /// The config as parsed, and verbatim as written.
    pub config: SweepConfig,
    /// The config file's text as read, comments included.
    pub config_text: String,
    /// The machine's calibration before and after the cases.
    pub calibration: Calibrations,
    /// Every planned case, measured or not yet, each key once.
    pub cases: Vec<CaseRecord>,
}

/// The machine calibrations of a sweep; see [`Calibrations::for_analysis`] for the one read.
#[derive(Clone, Debug, Default, Serialize, Deserialize)]
pub struct Calibrations {
    /// Taken before the first case; `None` when calibration was off or its batch job ended
    /// without a result.
    pub start: Option<Calibration>,
    /// Taken after the last case; `None` likewise, or while the sweep is unfinished.
    pub end: Option<Calibration>,
}

impl Calibrations {
    /// The calibration an analysis reads: the start one (else the end one), with each parallel
    /// ceiling the larger of the start and end measurements. The ceiling is what the hardware
    /// can do; another process or the hypervisor taking a core during one measurement only
    /// lowers it (a start calibration once read 1.01x at two threads between two readings of
    /// 1.98x), so the larger reading is the better estimate.
    pub fn for_analysis(&self) -> Option<Calibration> {
        match (&self.start, &self.end) {
            (Some(start), Some(end)) => Some(start.clone().with_larger_ceilings(end)),
            (start, end) => start.clone().or_else(|| end.clone()),
        }
    }
}

/// Where and how the results were produced, so that a result can be reproduced and compared
/// only with results of the same machine and build.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Metadata {
    /// The nbody-bench version (`CARGO_PKG_VERSION`) that wrote the file.
    pub tool_version: String,
    /// `git rev-parse HEAD` where the sweep ran; "unknown" outside a git checkout.
    pub git_commit: String,
    /// Tracked files differed from that commit (results and REPORT.md aside).
    pub git_dirty: bool,
    /// The compiler that built the binary (`rustc --version`).
    pub rustc_version: String,
    /// Instruction set the pair loops ran with, and the target features compiled in.
    pub simd: String,
    /// SIMD target features enabled at compile time, then `runtime-dispatch:<level>`.
    pub target_features: Vec<String>,
    /// The build's cargo features that change what it measures (`mpi`, `test-slowdown`).
    pub cargo_features: Vec<String>,
    /// "release" or "debug" (a debug build's timings are not comparable).
    pub profile: String,
    /// Host name from `/etc/hostname`, "unknown" when unreadable.
    pub host: String,
    /// Operating system and architecture, e.g. "linux x86_64".
    pub os: String,
    /// UTC, ISO 8601, when the sweep started (the first run, not a resume).
    pub started: String,
    /// The file of bodies every case started from (`initial`), as it was read.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub initial: Option<InitialRecord>,
    /// The version line of each external program of the config (`[[external]]`).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub externals: Vec<super::external::ExternalVersion>,
}

/// One case: what it is, every raw value, and summaries recomputed from them.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct CaseRecord {
    /// The case's key ([`Case::key`]), unique in the file: what tables, plots and resumes match on.
    pub key: String,
    /// The configuration measured.
    pub case: Case,
    /// Particles simulated.
    pub n: usize,
    /// Threads × ranks exceed the machine's logical CPUs.
    pub oversubscribed: bool,
    /// Rounds measured so far; the case is complete at `rounds_planned`.
    pub rounds_done: usize,
    /// Rounds the config asks for (`measure.rounds`).
    pub rounds_planned: usize,
    /// Timed steps per sample, as the last round used (later rounds keep the first's); 0 before any.
    pub steps_per_sample: u64,
    /// Each round as measured (samples in seconds per step, phases, counters, sanity).
    pub rounds: Vec<RoundOutcome>,
    /// Step-time histogram (HDR, ns): (value, count) of every recorded bucket.
    pub step_histogram: Vec<[u64; 2]>,
    /// Values taken out of the rounds as impossible (non-finite, zero or negative times...),
    /// with the reason.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub rejected: Vec<Rejected>,
    /// Recomputed from the raw values whenever they change or are loaded; `None` while the
    /// case has no successful sample (not measured yet, or every sample failed).
    pub summary: Option<Summary>,
}

/// Statistics over all rounds of a case.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Summary {
    /// Median over samples of the time per step, seconds, with a bootstrap 95% CI.
    pub median_s: f64,
    /// Bootstrap 95% confidence interval of that median, seconds per step ([low, high]).
    pub ci95_s: [f64; 2],
    /// Median absolute deviation of the samples, seconds per step.
    pub mad_s: f64,
    pub(crate) min_s: f64,
    pub(crate) mean_s: f64,
    /// Samples over all rounds, the rejected ones left out.
    pub samples: usize,
    /// Per-step percentiles from the histogram, nanoseconds; `None` when no step was timed
    /// alone (an external program is timed per run).
    pub step_ns: Option<StepPercentiles>,
    /// Median step time per particle, nanoseconds.
    pub ns_per_particle_step: f64,
    /// Throughput at the median: particles advanced one step per second.
    pub particle_steps_per_s: f64,
    /// `None` when the code counted no pair (an external program).
    pub pair_evals_per_s: Option<f64>,
    /// Seconds per step in each phase, averaged over the rounds that timed them; `None` when
    /// none did (an external program).
    pub phases: Option<PhaseTimes>,
    /// Work per step, over the rounds that counted it; `None` when none did (an external
    /// program).
    pub pair_checks_per_step: Option<f64>,
    pub(crate) cells_visited_per_step: Option<f64>,
    pub(crate) nodes_opened_per_step: Option<f64>,
    pub(crate) nodes_accepted_per_step: Option<f64>,
    /// Verlet list: rebuilds and list entries per step.
    #[serde(default)]
    pub(crate) rebuilds_per_step: Option<f64>,
    #[serde(default)]
    pub(crate) list_entries_per_step: Option<f64>,
    /// `None` when the code counted no pair (an external program).
    pub pairs_interacting: Option<u64>,
    /// Largest |energy drift| of any round, and whether it stayed within the config's limit;
    /// `None` when no round measured a drift (an external program).
    pub max_energy_drift: Option<f64>,
    /// That drift is within `measure.max_energy_drift`; `None` when there is no drift.
    pub sanity_ok: Option<bool>,
    /// Median and largest relative force error of the last round that measured it.
    pub force_error: Option<[f64; 2]>,
    /// Largest timing overhead (clock readings) relative to the median step.
    pub(crate) clock_overhead: f64,
}

/// Why a results file could not be loaded or saved; every variant but `Write` names the file.
#[derive(Debug, Error)]
pub enum ResultsError {
    /// The file could not be read (missing, unreadable, not UTF-8).
    #[error("cannot read {path}: {source}")]
    Read {
        /// The results file.
        path: PathBuf,
        /// The I/O error reading it.
        source: std::io::Error,
    },
    /// The text is not JSON, or not the shape of a results file.
    #[error(
        "{path} is not a valid results file ({detail}); it may be truncated or from another tool"
    )]
    Corrupt {
        /// The results file.
        path: PathBuf,
        /// The JSON parser's message, with its line and column.
        detail: String,
    },
    /// The file's `schema` is not [`RESULTS_SCHEMA`] ("(none)" when it has none).
    #[error("{path} has schema `{found}`, this version reads `{RESULTS_SCHEMA}`")]
    Schema {
        /// The results file.
        path: PathBuf,
        /// The schema it declares.
        found: String,
    },
    /// Two cases of the file have the same key.
    #[error(
        "{path} lists case `{key}` twice; a case key is unique in a results file: remove one \
         of the copies (or measure the case again in a new run)"
    )]
    Duplicate {
        /// The results file.
        path: PathBuf,
        /// The repeated case key.
        key: String,
    },
    /// Saving was refused because the serialized text would not load back; nothing was written.
    #[error(
        "not saving {path}: the results would not read back ({detail}); the file on disk is \
         unchanged"
    )]
    Unreadable {
        /// The results file that was to be written.
        path: PathBuf,
        /// Why the text does not read back.
        detail: String,
    },
    /// Writing the file atomically failed.
    #[error(transparent)]
    Write(#[from] nbody_engine::output::WriteError),
}

/// The JSON of the file at `path`, for [`ResultsFile::from_value`] and readers that look at a
/// file this version may not load whole (an old baseline).
pub fn read_json(path: &Path) -> Result<serde_json::Value, ResultsError> {
    let text = nbody_engine::input::read_text(path).map_err(|source| ResultsError::Read {
        path: path.into(),
        source,
    })?;
    serde_json::from_str(&text).map_err(|e| ResultsError::Corrupt {
        path: path.into(),
        detail: e.to_string(),
    })
}

impl ResultsFile {
    /// Reads a results file and checks it ([`ResultsFile::from_value`]), summaries recomputed.
    pub fn load(path: &Path) -> Result<ResultsFile, ResultsError> {
        ResultsFile::from_value(path, read_json(path)?)
    }

    /// A results file from its JSON `value`, read from `path` (named in errors): the schema,
    /// the fields, unique case keys, the summaries recomputed from the samples.
    pub fn from_value(path: &Path, value: serde_json::Value) -> Result<ResultsFile, ResultsError> {
        let schema = value
            .get("schema")
            .and_then(|s| s.as_str())
            .unwrap_or("(none)");
        if schema != RESULTS_SCHEMA {
            return Err(ResultsError::Schema {
                path: path.into(),
                found: schema.to_string(),
            });
        }
        let mut file: ResultsFile =
            serde_json::from_value(value).map_err(|e| ResultsError::Corrupt {
                path: path.into(),
                detail: e.to_string(),
            })?;
        let mut keys = std::collections::HashSet::new();
        if let Some(dup) = file.cases.iter().find(|c| !keys.insert(c.key.as_str())) {
            return Err(ResultsError::Duplicate {
                path: path.into(),
                key: dup.key.clone(),
            });
        }
        // A stored summary is never trusted: an edited file, or one written by an older
        // version, could disagree with its own samples.
        let max_drift = file.config.measure.max_energy_drift;
        for case in &mut file.cases {
            case.recompute(max_drift);
        }
        Ok(file)
    }

    /// Writes the whole file atomically (temporary file + rename), after checking that the
    /// text reads back: a file that was readable before a save is readable after it.
    pub fn save(&self, path: &Path) -> Result<(), ResultsError> {
        let text = serde_json::to_string_pretty(self).expect("results serialize");
        if let Err(e) = serde_json::from_str::<ResultsFile>(&text) {
            return Err(ResultsError::Unreadable {
                path: path.into(),
                detail: e.to_string(),
            });
        }
        nbody_engine::output::write_atomic(path, text.as_bytes())?;
        Ok(())
    }

    /// One line for each case some of whose raw values were taken out as impossible (a time
    /// of zero or less, not a finite number: [`super::vet`]), saying which, why, and what the
    /// case's figures are then of. Readers that analyse a file print them, so that a value
    /// left out is never left out silently.
    pub fn taken_out(&self) -> Vec<String> {
        self.cases
            .iter()
            .filter_map(|c| {
                let first = c.rejected.first()?;
                let more = match c.rejected.len() {
                    1 => String::new(),
                    n => format!(" and {} more", n - 1),
                };
                let figures = match &c.summary {
                    Some(s) => format!("its median is of the other {} samples", s.samples),
                    None => "it has no sample left, so no figure".to_string(),
                };
                Some(format!(
                    "case {}: round {} {} = {}: {}{more}, taken out; {figures}",
                    c.key, first.round, first.what, first.value, first.reason
                ))
            })
            .collect()
    }

    /// The record of the case with this key, `None` if the file has no such case.
    pub fn record_mut(&mut self, key: &str) -> Option<&mut CaseRecord> {
        self.cases.iter_mut().find(|c| c.key == key)
    }
}

impl CaseRecord {
    /// A record of `case` with no round measured yet; `logical_cpus` decides `oversubscribed`.
    pub fn new(case: Case, rounds_planned: usize, logical_cpus: usize) -> Self {
        CaseRecord {
            key: case.key(),
            n: case.n,
            oversubscribed: case.threads * case.ranks > logical_cpus,
            case,
            rounds_done: 0,
            rounds_planned,
            steps_per_sample: 0,
            rounds: Vec::new(),
            step_histogram: Vec::new(),
            rejected: Vec::new(),
            summary: None,
        }
    }

    /// All `rounds_planned` rounds are recorded (a round without a successful sample counts).
    pub fn is_complete(&self) -> bool {
        self.rounds_done >= self.rounds_planned
    }

    /// Adds a measured round and recomputes the summary from all raw values.
    pub fn add_round(&mut self, round: RoundOutcome, max_drift: f64) {
        let mut hist = StepHistogram::from_counts(&self.step_histogram);
        for &ns in &round.step_ns {
            hist.record(ns);
        }
        self.push_rounds(hist, [round], max_drift);
    }

    /// Adds every round of `other`, the same case measured by another sweep (an A/B gate's
    /// one-case runs), with its step-time histogram.
    pub fn absorb(&mut self, other: CaseRecord, max_drift: f64) {
        let mut hist = StepHistogram::from_counts(&self.step_histogram);
        for &[value, count] in &other.step_histogram {
            hist.record_n(value, count);
        }
        self.push_rounds(hist, other.rounds, max_drift);
    }

    /// Stores `hist` (this record's histogram with the new steps in it), appends `rounds` and
    /// recomputes the summary from all raw values.
    fn push_rounds(
        &mut self,
        hist: StepHistogram,
        rounds: impl IntoIterator<Item = RoundOutcome>,
        max_drift: f64,
    ) {
        self.step_histogram = hist.counts();
        for mut round in rounds {
            let index = self.rounds.len();
            self.rejected.extend(super::vet::round(index, &mut round));
            self.n = round.n;
            self.steps_per_sample = round.steps_per_sample;
            self.rounds.push(round);
            self.rounds_done += 1;
        }
        self.summary = self.summarize(&hist, max_drift);
    }

    /// Checks the raw values again and recomputes everything derived from them (a loaded
    /// file's summary, rounds done).
    fn recompute(&mut self, max_drift: f64) {
        for (index, round) in self.rounds.iter_mut().enumerate() {
            let taken = super::vet::round(index, round);
            self.rejected.extend(taken);
        }
        self.rounds_done = self.rounds.len();
        let hist = StepHistogram::from_counts(&self.step_histogram);
        self.summary = self.summarize(&hist, max_drift);
    }

    /// Rounds were measured but not one sample succeeded.
    pub fn failed(&self) -> bool {
        self.rounds_done > 0 && self.summary.is_none()
    }

    /// Why the samples of a failed case failed: the first reasons recorded.
    pub fn failures(&self) -> Vec<String> {
        let external = self.rounds.iter().filter_map(|r| r.external.as_ref());
        let errors = external.flat_map(|e| {
            e.setup_error
                .iter()
                .chain(e.runs.iter().filter_map(|r| r.error.as_ref()))
                .map(|e| format!("`{}` {}", e.command, e.what))
        });
        let rejected = self
            .rejected
            .iter()
            .map(|r| format!("{} = {}: {}", r.what, r.value, r.reason));
        let mut all: Vec<String> = errors.chain(rejected).collect();
        all.dedup();
        all
    }

    fn summarize(&self, hist: &StepHistogram, max_drift: f64) -> Option<Summary> {
        let samples: Vec<f64> = self
            .rounds
            .iter()
            .flat_map(|r| r.samples_s.iter().copied())
            .collect();
        let med = median(&samples)?;
        // Rounds that measured something (a batch job may end without measuring its round).
        let measured = || self.rounds.iter().filter(|r| !r.samples_s.is_empty());
        // The rounds that timed phases, and those that counted work: none of an external
        // program's, and then the figure is "not measured", never zero.
        let timed: Vec<&PhaseTimes> = measured().filter_map(|r| r.phases.as_ref()).collect();
        let phase_mean = |f: &dyn Fn(&PhaseTimes) -> f64| {
            timed.iter().map(|p| f(p)).sum::<f64>() / timed.len() as f64
        };
        let phases = (!timed.is_empty()).then(|| PhaseTimes {
            force_build: phase_mean(&|p| p.force_build),
            force_interact: phase_mean(&|p| p.force_interact),
            integrate: phase_mean(&|p| p.integrate),
            boundary: phase_mean(&|p| p.boundary),
            output: 0.0,
        });
        let counted_rounds = || self.rounds.iter().filter(|r| r.work.is_some());
        let steps: u64 = counted_rounds().map(|r| r.steps).sum();
        let counted = counted_rounds().next().is_some();
        let per_step = |f: &dyn Fn(&WorkCounters) -> u64| {
            counted.then(|| {
                counted_rounds()
                    .filter_map(|r| r.work.as_ref())
                    .map(|w| f(w) as f64)
                    .sum::<f64>()
                    / steps.max(1) as f64
            })
        };
        let pair_checks = per_step(&|w| w.pair_checks);
        let drift = self
            .rounds
            .iter()
            .filter_map(|r| r.energy_drift)
            .map(f64::abs)
            .reduce(f64::max);
        let n = self.n.max(1) as f64;
        Some(Summary {
            median_s: med,
            ci95_s: bootstrap_median_ci(&samples, BOOTSTRAP_RESAMPLES, 0x5eed)
                .unwrap_or([med, med]),
            mad_s: mad(&samples).unwrap_or(0.0),
            min_s: samples.iter().copied().fold(f64::INFINITY, f64::min),
            mean_s: samples.iter().sum::<f64>() / samples.len() as f64,
            samples: samples.len(),
            step_ns: hist.percentiles(),
            ns_per_particle_step: med * 1e9 / n,
            // Vetted samples take more than zero time.
            particle_steps_per_s: n / med,
            pair_evals_per_s: pair_checks.filter(|&p| p > 0.0).map(|p| p / med),
            phases,
            pair_checks_per_step: pair_checks,
            cells_visited_per_step: per_step(&|w| w.cells_visited),
            nodes_opened_per_step: per_step(&|w| w.nodes_opened),
            nodes_accepted_per_step: per_step(&|w| w.nodes_accepted),
            rebuilds_per_step: per_step(&|w| w.rebuilds),
            list_entries_per_step: per_step(&|w| w.list_entries),
            pairs_interacting: self
                .rounds
                .iter()
                .rfind(|r| !r.samples_s.is_empty())
                .and_then(|r| r.pairs_interacting),
            max_energy_drift: drift,
            sanity_ok: drift.map(|d| d <= max_drift),
            force_error: self.rounds.iter().filter_map(|r| r.force_error).next_back(),
            clock_overhead: self
                .rounds
                .iter()
                .map(|r| r.clock_overhead)
                .fold(0.0, f64::max),
        })
    }
}

impl Metadata {
    /// Describes this build and machine now; `cargo_features` are the build's features that
    /// change what it measures (the caller's crate knows them, this one does not).
    pub fn collect(cargo_features: &[&str]) -> Metadata {
        let (git_commit, git_dirty) = git_state();
        Metadata {
            tool_version: env!("CARGO_PKG_VERSION").to_string(),
            git_commit,
            git_dirty,
            rustc_version: nbody_engine::RUSTC_VERSION.to_string(),
            simd: nbody_engine::simd::level().name().to_string(),
            target_features: compiled_features(),
            cargo_features: cargo_features.iter().map(|f| f.to_string()).collect(),
            profile: if cfg!(debug_assertions) {
                "debug"
            } else {
                "release"
            }
            .to_string(),
            host: host_name().unwrap_or_else(|| "unknown".into()),
            os: format!("{} {}", std::env::consts::OS, std::env::consts::ARCH),
            started: utc_now(),
            externals: Vec::new(),
            initial: None,
        }
    }
}

/// The file of bodies a sweep's cases started from: where, what, and a fingerprint of its
/// content (a file changed between two sweeps shows here).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct InitialRecord {
    /// The file's absolute path (the config's `initial`, resolved against the config's directory).
    pub path: String,
    /// The format it was read as: "export" or "barnes-hut".
    pub format: String,
    /// Bodies it holds.
    pub bodies: usize,
    /// FNV-1a of the file's bytes, 16 hex digits.
    pub fnv1a: String,
}

/// FNV-1a, 64 bits: a fingerprint of `bytes` (not a cryptographic hash).
pub fn fnv1a(bytes: &[u8]) -> u64 {
    bytes.iter().fold(0xcbf2_9ce4_8422_2325, |h, &b| {
        (h ^ b as u64).wrapping_mul(0x0100_0000_01b3)
    })
}

fn compiled_features() -> Vec<String> {
    let mut f = Vec::new();
    macro_rules! feature {
        ($($name:literal),*) => {$( if cfg!(target_feature = $name) { f.push($name.to_string()); } )*};
    }
    feature!("sse2", "sse4.2", "avx", "avx2", "fma", "avx512f");
    f.push(format!(
        "runtime-dispatch:{}",
        nbody_engine::simd::level().name()
    ));
    f
}

#[cfg(test)]
mod tests {
    use super::*;

    fn calibration(two_threads: f64) -> Calibration {
        serde_json::from_value(serde_json::json!({
            "cpu_model": "x", "logical_cpus": 2, "simd": "avx512", "fma_gflops_1t": 100.0,
            "parallel_ceiling": [
                {"threads": 1, "ratio": 1.0, "oversubscribed": false},
                {"threads": 2, "ratio": two_threads, "oversubscribed": false}
            ],
            "fork_join_us": 30.0, "fork_join_hot_us": 1.0, "fork_join_threads": 2,
            "memory_bandwidth_gbs": 30.0, "duration_s": 1.0, "background_cpus": 0.0,
            "warnings": []
        }))
        .unwrap()
    }

    #[test]
    fn the_analysis_reads_the_larger_ceiling() {
        let both = Calibrations {
            start: Some(calibration(1.01)),
            end: Some(calibration(1.98)),
        };
        assert_eq!(both.for_analysis().unwrap().ceiling(2), Some(1.98));
        let start_only = Calibrations {
            start: Some(calibration(1.9)),
            end: None,
        };
        assert_eq!(start_only.for_analysis().unwrap().ceiling(2), Some(1.9));
        let end_only = Calibrations {
            start: None,
            end: Some(calibration(1.7)),
        };
        assert_eq!(end_only.for_analysis().unwrap().ceiling(2), Some(1.7));
        assert!(Calibrations::default().for_analysis().is_none());
    }

    /// Any value a sample, force error or drift can take (NaN, ±inf, zero, negative, huge)
    /// recorded into a results file leaves a file that loads, whose summaries are those of
    /// its raw samples.
    mod any_samples {
        use super::super::*;
        use proptest::prelude::*;

        fn value() -> impl Strategy<Value = f64> {
            prop_oneof![
                Just(f64::NAN),
                Just(f64::INFINITY),
                Just(f64::NEG_INFINITY),
                Just(0.0),
                Just(-1e-3),
                Just(1e300),
                1e-9..1e-1f64,
                any::<f64>(),
            ]
        }

        fn fixture() -> ResultsFile {
            let path = concat!(
                env!("CARGO_MANIFEST_DIR"),
                "/../../results/quick/results.json"
            );
            let mut file = ResultsFile::load(Path::new(path)).unwrap();
            file.cases.truncate(1);
            file
        }

        proptest! {
            #![proptest_config(ProptestConfig::with_cases(24))]
            #[test]
            fn leave_a_file_that_loads_with_the_summaries_of_its_samples(
                rounds in prop::collection::vec(prop::collection::vec(value(), 0..6), 1..4),
                error in prop::option::of((value(), value())),
                drift in value(),
            ) {
                let mut file = fixture();
                let max_drift = file.config.measure.max_energy_drift;
                let template = file.cases[0].rounds[0].clone();
                let mut record = CaseRecord::new(file.cases[0].case.clone(), rounds.len(), 2);
                for samples in &rounds {
                    let mut round = template.clone();
                    round.reference_s = samples.clone();
                    round.samples_s = samples.clone();
                    round.force_error = error.map(|(a, b)| [a, b]);
                    round.energy_drift = Some(drift);
                    record.add_round(round, max_drift);
                }
                file.cases[0] = record;
                let dir = tempfile::tempdir().unwrap();
                let path = dir.path().join("results.json");
                file.save(&path).unwrap();
                let loaded = ResultsFile::load(&path).unwrap();
                let case = &loaded.cases[0];
                prop_assert_eq!(&case.summary, &file.cases[0].summary);
                let kept: Vec<f64> =
                    case.rounds.iter().flat_map(|r| r.samples_s.clone()).collect();
                prop_assert!(kept.iter().all(|s| s.is_finite() && *s > 0.0));
                let given = rounds.iter().map(Vec::len).sum::<usize>();
                prop_assert!(case.rejected.len() >= given - kept.len());
                match &case.summary {
                    None => prop_assert!(kept.is_empty()),
                    Some(s) => {
                        prop_assert_eq!(s.median_s, median(&kept).unwrap());
                        prop_assert_eq!(s.samples, kept.len());
                    }
                }
            }
        }
    }
}
