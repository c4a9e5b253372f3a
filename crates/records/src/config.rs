//! Sweep configurations: TOML files, typed, unknown keys rejected, validated before anything
//! runs. Every error names the file, the key and what is allowed.

use nbody_engine::decomp::Decomposition;
use nbody_engine::kernels::KernelKind;
use nbody_engine::scenario::{Precision, ScenarioKind};
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};
use thiserror::Error;

/// What a sweep varies and how its results are read.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Study {
    /// Fixed n, varying threads: speedup and efficiency (threads must include 1).
    Strong,
    /// Work per thread held constant: n (or simulated time) grows with the threads.
    Weak,
    /// Kernels over n on one thread: cost growth and crossovers.
    Complexity,
    /// Every combination of the lists, no particular reading.
    Cartesian,
}

/// How a weak-scaling sweep grows the problem with the thread count p.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum WeakRule {
    /// From the kernel's cost model: n·p for O(n) kernels, n·√p for O(n²) ones, and
    /// n log n = p · n₀ log n₀ for the octree.
    CostModel,
    /// n = n₀ · p whatever the kernel.
    Linear,
    /// n = n₀ · √p whatever the kernel.
    Sqrt,
    /// n fixed, steps × p: the simulated time grows instead (the Barnes-Hut report's second study).
    Time,
}

/// The particle counts: an explicit list or a geometric range.
#[derive(Clone, Debug, PartialEq, Serialize)]
#[serde(untagged)]
pub enum Counts {
    /// The counts as written, such as `n = [1000, 2000]`.
    List(Vec<usize>),
    /// A geometric range, such as `n = { from = 1000, to = 32000, factor = 2 }`.
    Range(CountRange),
}

impl<'de> Deserialize<'de> for Counts {
    /// As the two forms, with a message that names the key and both forms (serde's own for an
    /// untagged enum, "data did not match any variant", names neither).
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        #[derive(Deserialize)]
        #[serde(untagged)]
        enum Form {
            List(Vec<usize>),
            Range(CountRange),
        }
        match Form::deserialize(d) {
            Ok(Form::List(v)) => Ok(Counts::List(v)),
            Ok(Form::Range(r)) => Ok(Counts::Range(r)),
            Err(_) => Err(serde::de::Error::custom(format!(
                "must be {}",
                super::config_keys::forms_of(SweepConfig::KEYS, "n")
            ))),
        }
    }
}

/// Particle counts from `from` to `to`, each `factor` times the last (rounded); validation
/// requires 1 <= from <= to and factor > 1.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CountRange {
    /// First (smallest) particle count.
    pub from: usize,
    /// Upper bound on the counts (inclusive; reached only if the factor lands on it).
    pub to: usize,
    /// Ratio between consecutive counts (> 1).
    pub factor: f64,
}

/// The most counts a range of n may give: far more cases than any sweep can measure.
pub const MAX_RANGE_COUNTS: usize = 10_000;

/// The most multiplications by the factor a range may take: a factor barely above 1 gives the
/// same rounded count over and over before the next, and would otherwise run for ever.
const MAX_RANGE_STEPS: usize = 1_000_000;

impl CountRange {
    /// The counts of the range, or why it cannot be expanded: more than [`MAX_RANGE_COUNTS`]
    /// of them, or a factor so close to 1 that reaching `to` takes more than a million steps.
    /// Validation refuses such a range, so a parsed config's range always expands.
    pub fn counts(&self) -> Result<Vec<usize>, String> {
        let too_many = || {
            format!(
                "{{ from = {}, to = {}, factor = {} }} gives more than {MAX_RANGE_COUNTS} counts, \
                 the most a range may give: raise the factor, narrow from..to, or list the counts",
                self.from, self.to, self.factor
            )
        };
        let mut out = Vec::new();
        let mut x = self.from as f64;
        let mut steps = 0;
        // Compared as floats: a count past usize::MAX would saturate and never end the loop.
        while x.round() <= self.to as f64 {
            let n = x.round() as usize;
            if out.last() != Some(&n) {
                if out.len() == MAX_RANGE_COUNTS {
                    return Err(too_many());
                }
                out.push(n);
            }
            x *= self.factor;
            steps += 1;
            if steps == MAX_RANGE_STEPS {
                return Err(format!(
                    "{{ from = {}, to = {}, factor = {} }}: the factor is so close to 1 that \
                     the range takes more than {MAX_RANGE_STEPS} steps to reach `to`: raise the \
                     factor, or list the counts",
                    self.from, self.to, self.factor
                ));
            }
        }
        Ok(out)
    }
}

impl Counts {
    /// The counts in increasing order of appearance (none for a range validation refuses).
    pub fn values(&self) -> Vec<usize> {
        match self {
            Counts::List(v) => v.clone(),
            Counts::Range(r) => r.counts().unwrap_or_default(),
        }
    }
}

crate::config_keys::documented_keys! {
    /// How each case is measured (docs/explanation/statistics.md).
    #[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
    #[serde(deny_unknown_fields, default)]
    pub struct Measure {
        /// Untimed stepping before the samples.
        ///
        /// Accepts seconds of at least 0, such as warmup_s = 0.05.
        ///
        /// Example: `warmup_s = 0.1`
        pub warmup_s: f64,
        /// Samples per case, shared between the rounds.
        ///
        /// Accepts a whole number of at least 1, such as samples = 10.
        ///
        /// Example: `samples = 6`
        pub samples: usize,
        /// A sample lasts at least this long (its step count adapts).
        ///
        /// Accepts seconds above 0, such as min_sample_s = 0.01.
        ///
        /// Example: `min_sample_s = 0.02`
        pub min_sample_s: f64,
        /// Interleaved rounds over all cases.
        ///
        /// Accepts a whole number of at least 1, such as rounds = 2.
        ///
        /// Example: `rounds = 3`
        pub rounds: usize,
        /// Stop starting cases after this many seconds (0 = no limit); the rest is left for
        /// `--resume`.
        ///
        /// Accepts seconds of at least 0 (0 = no budget), such as budget_s = 600.
        ///
        /// Example: `budget_s = 60`
        pub budget_s: f64,
        /// Flag a case whose relative energy drift exceeds this.
        ///
        /// Accepts a relative drift above 0, such as max_energy_drift = 0.05.
        ///
        /// Example: `max_energy_drift = 0.1`
        pub max_energy_drift: f64,
        /// Also measure the force error against an f64 direct sum on this many particles.
        ///
        /// Accepts a whole number of particles of at least 0 (0 = off), such as force_error_sample
        /// = 200.
        ///
        /// Example: `force_error_sample = 100`
        pub force_error_sample: usize,
        /// Seconds of the reference workload before each sample, for `gate` (0 = off).
        ///
        /// Accepts seconds of at least 0 (0 = off), such as reference_s = 0.01.
        ///
        /// Example: `reference_s = 0.02`
        pub reference_s: f64,
    }
}

impl Default for Measure {
    fn default() -> Self {
        Measure {
            warmup_s: 0.05,
            samples: 10,
            min_sample_s: 0.01,
            rounds: 2,
            budget_s: 0.0,
            max_energy_drift: 0.05,
            force_error_sample: 0,
            reference_s: 0.0,
        }
    }
}

crate::config_keys::documented_keys! {
    /// Weak-scaling settings.
    #[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
    #[serde(deny_unknown_fields)]
    pub struct Weak {
        /// How n grows with the workers. cost-model: n grows by each kernel's cost model; linear: n0·p; sqrt: n0·√p; time: n
        /// fixed, steps × p.
        ///
        /// Accepts one of "cost-model", "linear", "sqrt", "time".
        ///
        /// Example: `rule = "linear"`
        pub rule: WeakRule,
        /// The n at one worker.
        ///
        /// Accepts a whole number of particles of at least 1, such as base_n = 10000.
        ///
        /// Example: `base_n = 1000`
        pub base_n: usize,
    }
}

crate::config_keys::documented_keys! {
    /// A sweep, as written in a TOML file.
    #[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
    #[serde(deny_unknown_fields)]
    pub struct SweepConfig {
        /// Names the results: `<out>/runs/<name>/<UTC time>/`, or `DIR/<name>/` with `--out DIR`.
        ///
        /// Accepts a plain file name (letters, digits, `-`, `_`, `.`; not starting with `.`), such
        /// as name = "strong".
        ///
        /// Example: `name = "every-key"`
        pub name: String,
        /// How the sweep is read: threads at fixed n (strong), work per thread held (weak), kernels
        /// over n (complexity), every combination (cartesian).
        ///
        /// Accepts one of "strong", "weak", "complexity", "cartesian".
        ///
        /// Example: `study = "weak"`
        pub study: Study,
        /// The scenarios measured.
        ///
        /// Accepts a list of scenario names, such as scenarios = ["lj-box", "galaxy"] (`nbody-bench
        /// list` shows them).
        ///
        /// Example: `scenarios = ["lj-box"]`
        pub scenarios: Vec<ScenarioKind>,
        /// The built-in kernels measured (may be empty when `[[external]]` lists programs).
        ///
        /// Accepts a list of kernel names, such as kernels = ["naive", "cell-list"] (`nbody-bench
        /// list` shows them).
        ///
        /// Example: `kernels = ["naive"]`
        #[serde(default)]
        pub kernels: Vec<KernelKind>,
        /// Particle counts; required except in weak studies, which use `weak.base_n` instead.
        ///
        /// Accepts a list of whole numbers, such as n = [1000, 2000], or a geometric range, such as
        /// n = { from = 1000, to = 32000, factor = 2 }: each count `factor` times the last,
        /// rounded, up to `to`, at most 10000 counts (a range that would give more is refused).
        ///
        /// Example: `n = [1000]`
        #[serde(default)]
        pub n: Option<Counts>,
        /// Thread counts; a strong study must include 1.
        ///
        /// Accepts a list of thread counts of at least 1, such as threads = [1, 2].
        ///
        /// Example: `threads = [1, 2]`
        #[serde(default = "one_thread")]
        pub threads: Vec<usize>,
        /// Seeds of the initial state; each is a case of its own.
        ///
        /// Accepts a list of whole numbers of at least 0, such as seeds = [1, 2, 3].
        ///
        /// Example: `seeds = [2]`
        #[serde(default = "one_seed")]
        pub seeds: Vec<u64>,
        /// Opening angles, octree and fmm cases only (the fmms take those below 1).
        ///
        /// Accepts a list of opening angles of at least 0, such as theta = [0.5, 0.7].
        ///
        /// Example: `theta = [0.7]`
        #[serde(default = "default_theta")]
        pub theta: Vec<f64>,
        /// Expansion orders of the octree's nodes, octree cases only.
        ///
        /// Accepts a list of expansion orders, such as multipole = ["monopole", "quadrupole"].
        ///
        /// Example: `multipole = ["monopole"]`
        #[serde(default = "default_multipole")]
        pub multipole: Vec<nbody_engine::kernels::Multipole>,
        /// Expansion orders of the fmm's cells, fmm and fmm-harmonic cases only (the fmm takes
        /// those up to 8, its Cartesian expansions' limit).
        ///
        /// Accepts a list of expansion orders from 1 to 20, such as order = [3, 4, 6].
        ///
        /// Example: `order = [6]`
        #[serde(default = "default_order")]
        pub order: Vec<usize>,
        /// Neighbour-list skins in the scenario's length unit, verlet and cluster-pair cases only
        /// (left out: each kernel's default, 0.3 sigma of the LJ scenarios; `run --skin auto` finds
        /// the fastest).
        ///
        /// Accepts a non-empty list of lengths above 0 in the scenario's unit, such as
        /// skin = [0.003, 0.012].
        ///
        /// Example: `skin = [0.004]`
        #[serde(default, skip_serializing_if = "Option::is_none")]
        pub skin: Option<Vec<f64>>,
        /// Overrides each scenario's precision (when left out: each scenario's own).
        ///
        /// Accepts "f32" or "f64".
        ///
        /// Example: `precision = "f64"`
        #[serde(default)]
        pub precision: Option<Precision>,
        /// Every case starts from the bodies in this file (relative to the config's directory)
        /// instead of the seeded placement: the built-in kernels, in this process or under [mpi];
        /// read once at the start (launched runs read the sweep's copy, initial/ beside the
        /// results).
        ///
        /// Accepts a file, as a string, such as initial = "bodies.txt": `nbody-bench export
        /// --format text` output, or one body a line `m x y z vx vy vz` (3-D, # comments); not with
        /// [[external]], [scheduler] or a weak study, and `n` must be the file's.
        ///
        /// Example: `initial = "bodies.txt"`
        #[serde(default, skip_serializing_if = "Option::is_none")]
        pub initial: Option<PathBuf>,
        /// The results directory.
        ///
        /// Accepts a directory, as a string, such as out = "results".
        ///
        /// Example: `out = "elsewhere"`
        #[serde(default = "default_out")]
        pub out: PathBuf,
        /// How each case is measured.
        #[serde(default)]
        pub measure: Measure,
        /// Weak studies only: how n grows with the workers.
        #[serde(default)]
        pub weak: Option<Weak>,
        /// Run every case under an MPI launcher (`mpirun -n R nbody-bench run --decomp ...`).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        pub mpi: Option<MpiLaunch>,
        /// Other programs measured as cases of the sweep.
        #[serde(default, skip_serializing_if = "Vec::is_empty")]
        pub external: Vec<super::external::External>,
        /// Run each case round, and the calibrations, as a batch job on a cluster (Slurm).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        pub scheduler: Option<super::scheduler::Scheduler>,
    }
}

crate::config_keys::documented_keys! {
    /// How a sweep starts MPI cases (the `[mpi]` table). Each round of a case is one launch; its
    /// timed steps are split into the round's samples.
    #[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
    #[serde(deny_unknown_fields)]
    pub struct MpiLaunch {
        /// The launcher program.
        ///
        /// Accepts a program name, as a string, such as launcher = "mpirun".
        ///
        /// Example: `launcher = "mpiexec"`
        #[serde(default = "default_launcher")]
        pub launcher: String,
        /// Rank counts; each case runs at every one.
        ///
        /// Accepts a list of rank counts of at least 1, such as ranks = [1, 2, 4].
        ///
        /// Example: `ranks = [1, 2]`
        pub ranks: Vec<usize>,
        /// Launcher arguments before the rank count.
        ///
        /// Accepts a list of strings, such as args = ["--oversubscribe"].
        ///
        /// Example: `args = ["--oversubscribe"]`
        #[serde(default)]
        pub args: Vec<String>,
        /// The launcher's option that takes the rank count.
        ///
        /// Accepts the launcher's option for the rank count, as a string, such as rank_flag = "-n".
        ///
        /// Example: `rank_flag = "-np"`
        #[serde(default = "default_rank_flag")]
        pub rank_flag: String,
        /// Decompositions; each kernel runs with those that support it.
        ///
        /// Accepts a list of decompositions, such as decomp = ["allgather", "domain"].
        ///
        /// Example: `decomp = ["domain"]`
        #[serde(default = "default_decomp")]
        pub decomp: Vec<Decomposition>,
        /// Timed steps per launch, split into the round's samples.
        ///
        /// Accepts a whole number of timed steps per launch, such as steps = 100.
        ///
        /// Example: `steps = 50`
        #[serde(default = "default_mpi_steps")]
        pub steps: usize,
        /// Untimed steps before them.
        ///
        /// Accepts a whole number of untimed steps, such as warmup_steps = 10.
        ///
        /// Example: `warmup_steps = 5`
        #[serde(default = "default_mpi_warmup")]
        pub warmup_steps: usize,
    }
}

fn default_launcher() -> String {
    "mpirun".into()
}
fn default_rank_flag() -> String {
    "-n".into()
}
fn default_decomp() -> Vec<Decomposition> {
    vec![Decomposition::Allgather]
}
fn default_mpi_steps() -> usize {
    100
}
fn default_mpi_warmup() -> usize {
    10
}

fn one_thread() -> Vec<usize> {
    vec![1]
}
fn one_seed() -> Vec<u64> {
    vec![1]
}
fn default_theta() -> Vec<f64> {
    vec![0.5]
}
fn default_multipole() -> Vec<nbody_engine::kernels::Multipole> {
    vec![nbody_engine::kernels::KernelParams::default().multipole]
}
fn default_order() -> Vec<usize> {
    vec![nbody_engine::kernels::KernelParams::default().order]
}
fn default_out() -> PathBuf {
    PathBuf::from("results")
}

/// Why a sweep config could not be loaded; every variant names the file.
#[derive(Debug, Error)]
pub enum ConfigError {
    /// The file could not be read (missing, unreadable, not UTF-8).
    #[error("cannot read config {path}: {source}")]
    Read {
        /// The config file.
        path: PathBuf,
        /// The I/O error reading it.
        source: std::io::Error,
    },
    /// The text is not valid TOML or does not fit the config's shape (unknown key, wrong type).
    #[error("config {path}: {message}")]
    Parse {
        /// The config file.
        path: PathBuf,
        /// What is wrong, naming the key and what it accepts.
        message: String,
    },
    /// The config parsed but a value breaks a rule (range, combination of keys).
    #[error("config {path}: `{key}` {problem}")]
    Invalid {
        /// The config file.
        path: PathBuf,
        /// The offending key, dotted for a table's (`weak.base_n`).
        key: String,
        /// What is wrong with it and what is allowed.
        problem: String,
    },
}

/// Every key of a sweep config, from the doc comments of its fields (`config_keys`): the top
/// level's, then each table's.
pub fn keys() -> Vec<super::config_keys::Key> {
    super::config_keys::Tables {
        top: SweepConfig::KEYS,
        nested: &[
            ("measure", Measure::KEYS, false),
            ("weak", Weak::KEYS, false),
            ("mpi", MpiLaunch::KEYS, false),
            ("scheduler", super::scheduler::Scheduler::KEYS, false),
            ("external", super::external::External::KEYS, true),
        ],
    }
    .keys()
}

/// A config error of the file at `path`: `key` and what is wrong with it.
fn invalid(path: &Path) -> impl Fn(&str, String) -> ConfigError + '_ {
    move |key, problem| ConfigError::Invalid {
        path: path.into(),
        key: key.into(),
        problem,
    }
}

impl SweepConfig {
    /// Reads, parses and validates a config file.
    pub fn load(path: &Path) -> Result<(SweepConfig, String), ConfigError> {
        let text = nbody_engine::input::read_text(path).map_err(|source| ConfigError::Read {
            path: path.into(),
            source,
        })?;
        let config = Self::parse(&text, path)?;
        Ok((config, text))
    }

    /// Parses and validates config text; `path` is only used in messages.
    pub fn parse(text: &str, path: &Path) -> Result<SweepConfig, ConfigError> {
        let config: SweepConfig = toml::from_str(text).map_err(|e| ConfigError::Parse {
            path: path.into(),
            message: super::config_keys::describe(&keys(), text, e.message(), e.span()),
        })?;
        config.validate(path)?;
        Ok(config)
    }

    /// Checks the config theme by theme; the order of the steps decides which problem is
    /// reported when there are several.
    fn validate(&self, path: &Path) -> Result<(), ConfigError> {
        self.validate_name(path)?;
        self.validate_subjects(path)?;
        self.validate_external(path)?;
        if self.initial.is_some() {
            self.validate_initial(path)?;
        }
        self.validate_coverage(path)?;
        self.validate_lists(path)?;
        self.validate_sizes(path)?;
        if let Some(mpi) = &self.mpi {
            self.validate_mpi(mpi, path)?;
        }
        if let Some(s) = &self.scheduler {
            let bad = invalid(path);
            s.validate().map_err(|(key, problem)| bad(&key, problem))?;
        }
        self.validate_measure(path)?;
        self.validate_unique(path)
    }

    /// The name becomes a directory name under the output directory: a plain file name,
    /// never `.`, `..` or a hidden name that would escape or hide from `--out`.
    fn validate_name(&self, path: &Path) -> Result<(), ConfigError> {
        if self.name.is_empty()
            || self.name.starts_with('.')
            || !self
                .name
                .chars()
                .all(|c| c.is_ascii_alphanumeric() || "-_.".contains(c))
        {
            return Err(invalid(path)(
                "name",
                format!(
                    "is `{}`: it must be a plain file name of letters, digits, '-', '_' and '.', \
                     not starting with '.'",
                    self.name
                ),
            ));
        }
        Ok(())
    }

    /// Something to measure: at least one scenario, and a kernel or an external program.
    fn validate_subjects(&self, path: &Path) -> Result<(), ConfigError> {
        let bad = invalid(path);
        if self.scenarios.is_empty() {
            return Err(bad(
                "scenarios",
                "is empty; list at least one of lj-box, lj-liquid, coulomb, galaxy".into(),
            ));
        }
        if self.kernels.is_empty() && self.external.is_empty() {
            return Err(bad(
                "kernels",
                "is empty; list at least one of naive, symmetric, per-thread, cell-list, octree, \
                 verlet, or declare an [[external]] program"
                    .into(),
            ));
        }
        Ok(())
    }

    /// Every scenario has a kernel (or an external program) to run it, and every kernel a
    /// scenario it applies to.
    fn validate_coverage(&self, path: &Path) -> Result<(), ConfigError> {
        let bad = invalid(path);
        for &s in &self.scenarios {
            let external = self
                .external
                .iter()
                .any(|e| e.scenarios.as_ref().is_none_or(|list| list.contains(&s)));
            if !external && !self.kernels.iter().any(|k| k.supports(s.law())) {
                return Err(bad(
                    "kernels",
                    format!(
                        "has no kernel for scenario `{}`; kernels for {}: {}",
                        s.name(),
                        s.law().name(),
                        nbody_engine::kernels::supported_for(s.law())
                    ),
                ));
            }
        }
        for &k in &self.kernels {
            if !self.scenarios.iter().any(|s| k.supports(s.law())) {
                return Err(bad(
                    "kernels",
                    format!("`{}` applies to none of the listed scenarios", k.name()),
                ));
            }
        }
        Ok(())
    }

    /// The lists of case parameters: threads, seeds, theta, multipole, skin and order, each
    /// with values in range and, for theta and skin, a kernel that runs them.
    fn validate_lists(&self, path: &Path) -> Result<(), ConfigError> {
        let bad = invalid(path);
        if self.threads.is_empty()
            || self
                .threads
                .iter()
                .any(|&t| t == 0 || t > nbody_engine::run::MAX_THREADS)
        {
            return Err(bad(
                "threads",
                format!(
                    "must be a non-empty list of thread counts from 1 to {}",
                    nbody_engine::run::MAX_THREADS
                ),
            ));
        }
        if self.seeds.is_empty() {
            return Err(bad("seeds", "must list at least one seed".into()));
        }
        if self.theta.is_empty() || self.theta.iter().any(|t| !(t.is_finite() && *t >= 0.0)) {
            return Err(bad(
                "theta",
                "must be a non-empty list of finite values >= 0".into(),
            ));
        }
        if self.multipole.is_empty() {
            return Err(bad(
                "multipole",
                "must list at least one of \"monopole\", \"quadrupole\"".into(),
            ));
        }
        if self.kernels.iter().any(|k| k.is_fmm()) && !self.theta.iter().any(|&t| t < 1.0) {
            return Err(bad(
                "theta",
                "has no value below 1, and the fmm kernel runs only there (its expansions \
                 converge for theta < 1); add one, such as 0.5"
                    .into(),
            ));
        }
        // Left out, each kernel's default; given, the lengths to run, like every other list.
        let skin = self.skin.as_deref().unwrap_or_default();
        if self.skin.is_some() && skin.is_empty() {
            return Err(bad(
                "skin",
                "is empty; list at least one length above 0, or leave skin out for each \
                 kernel's default"
                    .into(),
            ));
        }
        if skin.iter().any(|s| !(s.is_finite() && *s > 0.0)) {
            return Err(bad("skin", "must list finite lengths above 0".into()));
        }
        if !skin.is_empty()
            && !self
                .kernels
                .iter()
                .any(|k| matches!(k, KernelKind::Verlet | KernelKind::ClusterPair))
        {
            return Err(bad(
                "skin",
                "applies to the verlet and cluster-pair kernels, and the config runs neither: \
                 remove it, or add one of them to kernels"
                    .into(),
            ));
        }
        let max_order = nbody_engine::kernels::MAX_FMM_HARMONIC_ORDER;
        if self.order.is_empty() || self.order.iter().any(|p| !(1..=max_order).contains(p)) {
            return Err(bad(
                "order",
                format!("must be a non-empty list of expansion orders from 1 to {max_order}"),
            ));
        }
        let cartesian = nbody_engine::kernels::MAX_FMM_ORDER;
        if self.kernels.contains(&KernelKind::Fmm) && !self.order.iter().any(|&p| p <= cartesian) {
            return Err(bad(
                "order",
                format!(
                    "has no value the fmm kernel runs (its Cartesian expansions go to order \
                     {cartesian}; fmm-harmonic's to {max_order}); add one, such as 4"
                ),
            ));
        }
        Ok(())
    }

    /// The sizes the study runs: `weak` for a weak study (which takes no `n`), valid counts
    /// `n` otherwise, and a strong study's reference of one thread.
    fn validate_sizes(&self, path: &Path) -> Result<(), ConfigError> {
        let bad = invalid(path);
        match (&self.study, &self.weak) {
            (Study::Weak, None) => {
                return Err(bad(
                    "weak",
                    "is required for study = \"weak\": set weak.rule and weak.base_n".into(),
                ));
            }
            (Study::Weak, Some(w)) if w.base_n == 0 => {
                return Err(bad("weak.base_n", "must be at least 1".into()));
            }
            (Study::Weak, Some(_)) if self.n.is_some() => {
                return Err(bad(
                    "n",
                    "does not apply to study = \"weak\": its sizes follow from weak.base_n and \
                     the workers; remove `n`"
                        .into(),
                ));
            }
            (Study::Weak, Some(_)) => {}
            (_, Some(_)) => return Err(bad("weak", "only applies to study = \"weak\"".into())),
            (_, None) => self.validate_counts(path)?,
        }
        if self.study == Study::Strong && !self.threads.contains(&1) {
            return Err(bad(
                "threads",
                "must include 1 for a strong-scaling study (speedups are relative to it)".into(),
            ));
        }
        Ok(())
    }

    /// The particle counts `n` of a study that is not weak: given, non-empty, without 0.
    fn validate_counts(&self, path: &Path) -> Result<(), ConfigError> {
        let bad = invalid(path);
        match &self.n {
            None => Err(bad(
                "n",
                "is required: a list such as [1000, 2000] or { from, to, factor }".into(),
            )),
            Some(Counts::List(v)) if v.is_empty() => {
                Err(bad("n", "is empty; list at least one count".into()))
            }
            Some(Counts::List(v)) if v.contains(&0) => Err(bad("n", "must not contain 0".into())),
            Some(Counts::Range(r))
                if r.from == 0 || r.to < r.from || !(r.factor > 1.0 && r.factor.is_finite()) =>
            {
                Err(bad(
                    "n",
                    "range needs 1 <= from <= to and factor > 1".into(),
                ))
            }
            Some(Counts::Range(r)) => r.counts().map(|_| ()).map_err(|why| bad("n", why)),
            Some(_) => Ok(()),
        }
    }

    /// The `[measure]` table: samples shared by the rounds, and durations and the energy
    /// drift in range.
    fn validate_measure(&self, path: &Path) -> Result<(), ConfigError> {
        let bad = invalid(path);
        let m = &self.measure;
        if m.samples == 0 || m.rounds == 0 || m.rounds > m.samples {
            return Err(bad(
                "measure",
                "needs samples >= 1 and 1 <= rounds <= samples".into(),
            ));
        }
        for (key, v) in [
            ("measure.warmup_s", m.warmup_s),
            ("measure.min_sample_s", m.min_sample_s),
            ("measure.budget_s", m.budget_s),
            ("measure.reference_s", m.reference_s),
        ] {
            if !(v.is_finite() && v >= 0.0) {
                return Err(bad(key, format!("must be a finite number >= 0 (got {v})")));
            }
        }
        if !(m.max_energy_drift.is_finite() && m.max_energy_drift > 0.0) {
            return Err(bad(
                "measure.max_energy_drift",
                "must be a finite number > 0".into(),
            ));
        }
        Ok(())
    }

    /// Every value of a list gives its own cases, so a value listed twice would plan one case
    /// twice (measured once, reported as two, resumed forever): refused, naming the value.
    /// The planned keys are checked once more by `plan::unique_cases`.
    fn validate_unique(&self, path: &Path) -> Result<(), ConfigError> {
        let bad = |key: &str, problem: String| ConfigError::Invalid {
            path: path.into(),
            key: key.into(),
            problem,
        };
        fn twice<T: std::fmt::Debug + PartialEq>(list: &[T]) -> Option<String> {
            let i = (1..list.len()).find(|&i| list[..i].contains(&list[i]))?;
            Some(format!("{:?}", list[i]))
        }
        let n = match &self.n {
            Some(Counts::List(v)) => v.clone(),
            _ => Vec::new(),
        };
        let names: Vec<&str> = self.external.iter().map(|e| e.name.as_str()).collect();
        let (ranks, decomp) = match &self.mpi {
            Some(m) => (m.ranks.clone(), twice(&m.decomp)),
            None => (Vec::new(), None),
        };
        for (key, dup) in [
            ("scenarios", twice(&self.scenarios)),
            ("kernels", twice(&self.kernels)),
            ("n", twice(&n)),
            ("threads", twice(&self.threads)),
            ("seeds", twice(&self.seeds)),
            ("theta", twice(&self.theta)),
            ("multipole", twice(&self.multipole)),
            ("order", twice(&self.order)),
            ("skin", twice(self.skin.as_deref().unwrap_or_default())),
            ("mpi.ranks", twice(&ranks)),
            ("mpi.decomp", decomp),
            ("external.name", twice(&names)),
        ] {
            if let Some(value) = dup {
                return Err(bad(
                    key,
                    format!("lists {value} twice; each value is one set of cases: remove the copy"),
                ));
            }
        }
        Ok(())
    }
}

impl SweepConfig {
    /// What a file of bodies can start: the built-in kernels' cases, at the file's one n.
    fn validate_initial(&self, path: &Path) -> Result<(), ConfigError> {
        let bad = |problem: &str| ConfigError::Invalid {
            path: path.into(),
            key: "initial".into(),
            problem: problem.into(),
        };
        if !self.external.is_empty() {
            return Err(bad(
                "starts the built-in kernels only: an [[external]] program reads a file of bodies \
                 through its own `setup` (e.g. `{nbody_bench} export --initial FILE --format \
                 lammps-data --out {workdir}/state.data`); drop one of the two",
            ));
        }
        if self.scheduler.is_some() {
            return Err(bad(
                "is not taken to batch jobs yet: drop it or the [scheduler] table",
            ));
        }
        if self.study == Study::Weak {
            return Err(bad(
                "holds one n, while a weak study grows n with the workers: use a cartesian or \
                 strong study",
            ));
        }
        if self.n.is_none() {
            return Err(bad(
                "needs `n` too: the file's number of bodies, written out (n = [N])",
            ));
        }
        Ok(())
    }

    fn validate_external(&self, path: &Path) -> Result<(), ConfigError> {
        let around = super::external::config::Around {
            threads: &self.threads,
            mpi_ranks: self.mpi.as_ref().map(|m| m.ranks.as_slice()),
            strong: self.study == Study::Strong,
            weak: self.study == Study::Weak,
            weak_cost_model: self
                .weak
                .as_ref()
                .is_some_and(|w| w.rule == WeakRule::CostModel),
        };
        super::external::config::validate_entries(&self.external, &around).map_err(
            |(key, problem)| ConfigError::Invalid {
                path: path.into(),
                key,
                problem,
            },
        )
    }

    fn validate_mpi(&self, mpi: &MpiLaunch, path: &Path) -> Result<(), ConfigError> {
        let bad = |key: &str, problem: String| ConfigError::Invalid {
            path: path.into(),
            key: key.into(),
            problem,
        };
        if mpi.launcher.trim().is_empty() {
            return Err(bad(
                "mpi.launcher",
                "must name a program such as mpirun".into(),
            ));
        }
        if mpi.ranks.is_empty() || mpi.ranks.contains(&0) {
            return Err(bad(
                "mpi.ranks",
                "must be a non-empty list of rank counts >= 1".into(),
            ));
        }
        if self.study == Study::Strong && !mpi.ranks.contains(&1) {
            return Err(bad(
                "mpi.ranks",
                "must include 1 for a strong-scaling study (speedups are relative to it)".into(),
            ));
        }
        if mpi.decomp.is_empty() {
            return Err(bad(
                "mpi.decomp",
                "must list at least one of allgather, domain".into(),
            ));
        }
        for &k in &self.kernels {
            if !mpi.decomp.iter().any(|d| d.supports(k)) {
                return Err(bad(
                    "mpi.decomp",
                    format!(
                        "has no decomposition for kernel `{}`; domain runs the cell list and the Verlet list only, allgather any kernel",
                        k.name()
                    ),
                ));
            }
        }
        let per_round = self.measure.samples.div_ceil(self.measure.rounds.max(1));
        if mpi.steps < per_round {
            return Err(bad(
                "mpi.steps",
                format!(
                    "must be at least the samples of a round ({per_round}): each launch's steps are split into them"
                ),
            ));
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn geometric_range_expands() {
        let r = Counts::Range(CountRange {
            from: 1000,
            to: 100_000,
            factor: 10.0,
        });
        assert_eq!(r.values(), vec![1000, 10_000, 100_000]);
        let r = Counts::Range(CountRange {
            from: 100,
            to: 400,
            factor: 2.0,
        });
        assert_eq!(r.values(), vec![100, 200, 400]);
    }

    #[test]
    fn a_range_of_too_many_counts_is_refused_not_cut() {
        let r = CountRange {
            from: 1,
            to: 1_000_000,
            factor: 1.0001,
        };
        let why = r.counts().unwrap_err();
        assert!(why.contains("more than 10000 counts"), "{why}");
        assert!(why.contains("raise the factor"), "{why}");
        // A factor so close to 1 that the count hardly moves: refused, not run for ever.
        let r = CountRange {
            from: 1000,
            to: usize::MAX,
            factor: 1.0 + f64::EPSILON,
        };
        assert!(r.counts().unwrap_err().contains("so close to 1"));
        // The end of the counts is no end of the loop: it stops past usize::MAX.
        let r = CountRange {
            from: 1 << 62,
            to: usize::MAX,
            factor: 2.0,
        };
        assert_eq!(r.counts().unwrap().len(), 3);
    }
}
