//! The `[[external]]` entries of a sweep config: another program measured next to (or instead
//! of) the built-in kernels. A config that declares one runs that program: it is code.

use super::placeholders::{self, CASE_PLACEHOLDERS, SWEEP_PLACEHOLDERS};
use nbody_engine::scenario::ScenarioKind;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;

crate::config_keys::documented_keys! {
    /// One external program.
    #[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
    #[serde(deny_unknown_fields)]
    pub struct External {
        /// The kernel name of its cases (keys, tables, figures).
        ///
        /// Accepts a plain name, such as name = "lammps".
        ///
        /// Example: `name = "other"`
        pub name: String,
        /// The program and its arguments, each token with placeholders; never a shell string.
        ///
        /// Accepts a list of strings (argv), such as ["lmp", "-in", "{config_dir}/in.lj"];
        /// placeholders {n} {threads} {ranks} {steps} {seed} {theta} {scenario} {workdir}
        /// {config_dir} {nbody_bench}.
        ///
        /// Example: `command = ["other", "{n}", "{threads}"]`
        pub command: Vec<String>,
        /// Run once per round before the samples, untimed and without the launcher.
        ///
        /// Accepts a list of strings (argv), such as ["lmp", "-in", "{config_dir}/in.lj"];
        /// placeholders {n} {threads} {ranks} {steps} {seed} {theta} {scenario} {workdir}
        /// {config_dir} {nbody_bench}.
        ///
        /// Example: `setup = ["prepare", "{workdir}"]`
        #[serde(default, skip_serializing_if = "Vec::is_empty")]
        pub setup: Vec<String>,
        /// Time steps of one run, the same at every n or fewer as n grows: a sample's time per step
        /// is its run's time divided by the run's steps.
        ///
        /// Accepts a whole number of at least 1, such as steps = 2000; or the cost of one run and
        /// how a step's cost grows with n, such as steps = { work = 4e8, grows = "n^2" } (work / n²
        /// steps, rounded, at least 1), grows = "n" | "n log n" | "n^2".
        ///
        /// Example: `steps = 100`
        pub steps: Steps,
        /// How a run is timed: the whole process, or the first group of the last match in its
        /// output.
        ///
        /// Accepts "wall" or { regex = '...([0-9.eE+-]+)...', unit = "s" | "ms" | "us" | "ns" }.
        ///
        /// Example: `time = { regex = 'took ([0-9.]+)', unit = "ms" }`
        pub time: TimeSource,
        /// Phases the program times itself, each the first group of the last match in its output
        /// (its total over the run): a phase table and figure, the Amdahl serial fraction from its
        /// serial phases, its communication share; a run whose output lacks one is an error.
        ///
        /// Accepts a table of phases by name, each { regex, unit = "s" | "ms" | "us" | "ns", kind =
        /// "parallel" (default) | "serial" | "comm" }, such as phases = { comm = { regex = 'phase
        /// comm ([0-9.]+)', unit = "s", kind = "comm" } }.
        ///
        /// Example: `phases = { comm = { regex = 'phase comm ([0-9.eE+-]+)', unit = "s", kind = "comm" } }`
        #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
        pub phases: BTreeMap<String, PhaseSource>,
        /// A regular expression the output must match, else the sample is an error.
        ///
        /// Accepts a regular expression, such as check = 'Total wall time'.
        ///
        /// Example: `check = 'done'`
        #[serde(default, skip_serializing_if = "Option::is_none")]
        pub check: Option<String>,
        /// A regular expression whose groups are the median (and largest) force error the program
        /// reports.
        ///
        /// Accepts a regular expression with one or two groups, such as force_error = 'median ([^
        /// ]+) max ([^ ]+)'.
        ///
        /// Example: `force_error = 'error ([^ ]+) ([^ ]+)'`
        #[serde(default, skip_serializing_if = "Option::is_none")]
        pub force_error: Option<String>,
        /// A regular expression whose group is the total energy the program prints: its first
        /// match in a run is the energy at the start, its last the energy at the end, and their
        /// relative change is the run's energy drift, checked against `measure.max_energy_drift`
        /// as the built-in kernels' (a run whose output matches it fewer than twice is an error).
        ///
        /// Accepts a regular expression with one group around the number, such as energy =
        /// 'total energy ([0-9.eE+-]+)'.
        ///
        /// Example: `energy = 'E = ([0-9.eE+-]+)'`
        #[serde(default, skip_serializing_if = "Option::is_none")]
        pub energy: Option<String>,
        /// Entries of one family are one code at several accuracy settings: their cases form one
        /// series of force error against cost, like a θ sweep.
        ///
        /// Accepts a plain name shared by the entries, such as family = "fmm3d"; needs force_error.
        ///
        /// Example: `family = "other"`
        #[serde(default, skip_serializing_if = "Option::is_none")]
        pub family: Option<String>,
        /// Environment variables set for the program (values with placeholders).
        ///
        /// Accepts a table of strings, such as env = { OMP_NUM_THREADS = "{threads}" }.
        ///
        /// Example: `env = { OMP_NUM_THREADS = "{threads}" }`
        #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
        pub env: BTreeMap<String, String>,
        /// A command whose first line of output names the program's version (results metadata).
        ///
        /// Accepts a list of strings (argv), with the placeholders {config_dir} and {nbody_bench}
        /// only.
        ///
        /// Example: `version = ["other", "--version"]`
        #[serde(default, skip_serializing_if = "Vec::is_empty")]
        pub version: Vec<String>,
        /// The empty run whose wall time is the launch overhead of wall timing (when left out:
        /// `true` under the same launcher).
        ///
        /// Accepts a list of strings (argv), such as ["lmp", "-in", "{config_dir}/in.lj"];
        /// placeholders {n} {threads} {ranks} {steps} {seed} {theta} {scenario} {workdir}
        /// {config_dir} {nbody_bench}.
        ///
        /// Example: `empty = ["other", "--empty"]`
        #[serde(default, skip_serializing_if = "Vec::is_empty")]
        pub empty: Vec<String>,
        /// A run taking longer is stopped (SIGTERM, then SIGKILL) and is an error.
        ///
        /// Accepts seconds above 0, at most 7 days, such as timeout_s = 600.
        ///
        /// Example: `timeout_s = 60`
        #[serde(default = "default_timeout")]
        pub timeout_s: f64,
        /// Untimed runs before each round's samples.
        ///
        /// Accepts a whole number of at least 0, such as warmup_runs = 1.
        ///
        /// Example: `warmup_runs = 1`
        #[serde(default)]
        pub warmup_runs: usize,
        /// The scenarios its cases stand for (when left out: the config's).
        ///
        /// Accepts a list of scenario names, such as scenarios = ["lj-box"].
        ///
        /// Example: `scenarios = ["lj-box"]`
        #[serde(default, skip_serializing_if = "Option::is_none")]
        pub scenarios: Option<Vec<ScenarioKind>>,
        /// The particle counts of its cases (when left out: the config's); not in a weak study.
        ///
        /// Accepts a list of counts of at least 1, such as n = [500, 1000, 2000].
        ///
        /// Example: `n = [1000]`
        #[serde(default, skip_serializing_if = "Option::is_none")]
        pub n: Option<Vec<usize>>,
        /// Thread counts (when left out: the config's).
        ///
        /// Accepts a list of thread counts of at least 1, such as threads = [1, 2].
        ///
        /// Example: `threads = [1]`
        #[serde(default, skip_serializing_if = "Option::is_none")]
        pub threads: Option<Vec<usize>>,
        /// Rank counts (when left out: the `[mpi]` table's, else 1).
        ///
        /// Accepts a list of rank counts of at least 1, such as ranks = [1, 2].
        ///
        /// Example: `ranks = [1]`
        #[serde(default, skip_serializing_if = "Option::is_none")]
        pub ranks: Option<Vec<usize>>,
    }
}

/// The time steps of one run of an external program.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(untagged)]
pub enum Steps {
    /// The same at every n.
    Fixed(u64),
    /// About `work` units of the program's cost per run, a step costing `grows`(n): fewer
    /// steps at larger n, so that a direct O(n²) code runs long enough at small n without
    /// running for hours at large n.
    Scaled(ScaledSteps),
}

/// A step count that falls as n grows: `work / grows(n)` steps per run (`steps = { work, grows }`).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ScaledSteps {
    /// The cost of one run, in the units of `grows` (pair interactions for `"n^2"`).
    pub work: f64,
    /// How one step's cost grows with n, written "n", "n log n" or "n^2".
    pub grows: Growth,
}

/// How the cost of one step grows with n.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum Growth {
    /// `"n"`: a step costs n units (a cell list, a particle-mesh code).
    #[serde(rename = "n")]
    Linear,
    /// `"n log n"`: a step costs n·log₂ n units (a tree code); log₂ n is taken as at least 1.
    #[serde(rename = "n log n")]
    NLogN,
    /// `"n^2"`: a step costs n² units, the pair interactions of a direct code.
    #[serde(rename = "n^2")]
    Quadratic,
}

/// The most steps one run may be asked for: a scaled rule at a small n stays a run, not a
/// lifetime.
pub const MAX_STEPS: u64 = 1 << 40;

impl Growth {
    /// How the config writes it: "n", "n log n" or "n^2".
    pub fn name(self) -> &'static str {
        match self {
            Growth::Linear => "n",
            Growth::NLogN => "n log n",
            Growth::Quadratic => "n^2",
        }
    }

    /// The cost of one step at `n`, in the rule's units.
    pub fn cost(self, n: usize) -> f64 {
        let n = n.max(1) as f64;
        match self {
            Growth::Linear => n,
            Growth::NLogN => n * n.log2().max(1.0),
            Growth::Quadratic => n * n,
        }
    }
}

impl Steps {
    /// The steps of one run at `n`: at least 1.
    pub fn at(self, n: usize) -> u64 {
        match self {
            Steps::Fixed(s) => s,
            Steps::Scaled(r) => (r.work / r.grows.cost(n))
                .round()
                .clamp(1.0, MAX_STEPS as f64) as u64,
        }
    }

    /// For a person: "100", or "about 4e8 / n^2 (at least 1)".
    pub fn describe(self) -> String {
        match self {
            Steps::Fixed(s) => s.to_string(),
            Steps::Scaled(r) => format!("{:e} / {} (at least 1)", r.work, r.grows.name()),
        }
    }
}

/// Letters, digits, '-', '_' and '.', not empty and not starting with '-': what names a case
/// or a family (a name starting with '-' would read as an option where a command names it).
pub fn plain_name(name: &str) -> bool {
    !name.is_empty()
        && !name.starts_with('-')
        && name
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || "-_.".contains(c))
}

fn default_timeout() -> f64 {
    600.0
}

/// How an external run is timed.
#[derive(Clone, Debug, PartialEq, Serialize)]
#[serde(untagged)]
pub enum TimeSource {
    /// The wall time of the whole process, from start to exit.
    Wall(WallTag),
    /// The number the program prints, found by a regular expression's first group.
    Regex(TimeRegex),
}

/// The string `"wall"` of `time = "wall"` (its only value).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum WallTag {
    /// `"wall"`: time the whole process.
    Wall,
}

/// `time = { regex, unit }`: the run's time is the number the program prints.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TimeRegex {
    /// Its first group is the time; the last match in the output counts.
    pub regex: String,
    /// The unit of the printed number.
    pub unit: TimeUnit,
}

/// The unit of a number an external program prints: `"s"`, `"ms"`, `"us"` or `"ns"`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum TimeUnit {
    /// Seconds (`"s"`).
    S,
    /// Milliseconds (`"ms"`).
    Ms,
    /// Microseconds (`"us"`).
    Us,
    /// Nanoseconds (`"ns"`).
    Ns,
}

impl TimeUnit {
    /// Seconds in one of this unit: a printed number times this is seconds.
    pub fn seconds(self) -> f64 {
        match self {
            TimeUnit::S => 1.0,
            TimeUnit::Ms => 1e-3,
            TimeUnit::Us => 1e-6,
            TimeUnit::Ns => 1e-9,
        }
    }
}

/// One phase an external program times and prints.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PhaseSource {
    /// Its first group is the phase's time over the whole run.
    pub regex: String,
    /// The unit of the printed number.
    pub unit: TimeUnit,
    /// How the analysis reads it; parallel when the config says nothing.
    #[serde(default)]
    pub kind: PhaseKind,
}

/// How the analysis reads a phase of an external program.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum PhaseKind {
    /// Work the program spreads over its workers.
    #[default]
    Parallel,
    /// Work done by one worker whatever the count: the timed Amdahl serial part.
    Serial,
    /// Communication between ranks; the other phases are computation.
    Comm,
}

impl PhaseKind {
    /// How the config and the reports write it: "parallel", "serial" or "comm".
    pub fn name(self) -> &'static str {
        match self {
            PhaseKind::Parallel => "parallel",
            PhaseKind::Serial => "serial",
            PhaseKind::Comm => "comm",
        }
    }
}

/// A regex that is valid and has a group around the number; the problem otherwise.
fn number_regex(re: &str, example: &str) -> Result<(), String> {
    match regex::Regex::new(re) {
        Err(e) => Err(format!("is not a regular expression: {e}")),
        Ok(r) if r.captures_len() < 2 => {
            Err(format!("needs a group around the number, e.g. '{example}'"))
        }
        Ok(_) => Ok(()),
    }
}

/// The placeholders a case's commands and environment may use: the case's and the sweep's.
fn case_placeholders() -> Vec<&'static str> {
    let mut case_known: Vec<&str> = CASE_PLACEHOLDERS.to_vec();
    case_known.extend(SWEEP_PLACEHOLDERS);
    case_known
}

impl<'de> Deserialize<'de> for TimeSource {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        #[derive(Deserialize)]
        #[serde(untagged)]
        enum Form {
            Wall(WallTag),
            Regex(TimeRegex),
        }
        match Form::deserialize(d) {
            Ok(Form::Wall(w)) => Ok(TimeSource::Wall(w)),
            Ok(Form::Regex(r)) => Ok(TimeSource::Regex(r)),
            Err(_) => Err(serde::de::Error::custom(format!(
                "must be {}",
                crate::config_keys::forms_of(External::KEYS, "time")
            ))),
        }
    }
}

impl External {
    /// Whether any command or environment value of a case uses `{name}`.
    pub fn uses(&self, name: &str) -> bool {
        let needle = format!("{{{name}}}");
        self.command
            .iter()
            .chain(&self.setup)
            .chain(self.env.values())
            .any(|t| t.replace("{{", "").contains(&needle))
    }

    /// Checks everything that can be checked before a run; `(key, problem)` on failure.
    pub fn validate(&self) -> Result<(), (String, String)> {
        self.validate_name()?;
        self.validate_commands()?;
        self.validate_env()?;
        self.validate_run()?;
        self.validate_regexes()?;
        self.validate_family()?;
        self.validate_case_lists()
    }

    /// The failure for this entry's key `k` (`external.<name>.<k>`).
    fn invalid(&self, k: &str, problem: String) -> Result<(), (String, String)> {
        Err((format!("external.{}.{k}", self.name), problem))
    }

    /// The name names the cases: a plain name, and not a built-in kernel's.
    fn validate_name(&self) -> Result<(), (String, String)> {
        if !plain_name(&self.name) {
            return Err((
                "external.name".into(),
                format!(
                    "is `{}`: it must be letters, digits, '-', '_' and '.', not starting with \
                     '-' (it names the cases)",
                    self.name
                ),
            ));
        }
        if nbody_engine::kernels::KernelKind::ALL
            .iter()
            .any(|k| k.name() == self.name)
        {
            return Err((
                "external.name".into(),
                format!(
                    "`{}` is a built-in kernel's name; choose another",
                    self.name
                ),
            ));
        }
        Ok(())
    }

    /// The commands: a program name first, no NUL byte, only the placeholders each one gets.
    fn validate_commands(&self) -> Result<(), (String, String)> {
        let case_known = case_placeholders();
        for (field, tokens, known) in [
            ("command", &self.command, &case_known[..]),
            ("setup", &self.setup, &case_known[..]),
            ("empty", &self.empty, &case_known[..]),
            ("version", &self.version, &SWEEP_PLACEHOLDERS[..]),
        ] {
            if field == "command" && tokens.is_empty() {
                return self.invalid(
                    field,
                    "must name a program: [\"program\", \"arg\", ...]".into(),
                );
            }
            if tokens.first().is_some_and(|p| p.trim().is_empty()) {
                return self.invalid(field, "starts with an empty program name".into());
            }
            for (i, t) in tokens.iter().enumerate() {
                // No argument of a program can hold a NUL byte: refused here, not at every run.
                if t.contains('\0') {
                    return self.invalid(
                        field,
                        format!(
                            "has a NUL byte in its token {} (`{}`)",
                            i + 1,
                            t.escape_default()
                        ),
                    );
                }
                if let Err(e) = placeholders::check(t, known) {
                    return self.invalid(field, e.to_string());
                }
            }
        }
        Ok(())
    }

    /// The environment: valid variable names, values without NUL bytes or unknown placeholders.
    fn validate_env(&self) -> Result<(), (String, String)> {
        let case_known = case_placeholders();
        for (name, value) in &self.env {
            if name.is_empty() || name.contains('=') || name.contains('\0') {
                return self.invalid("env", format!("has an invalid variable name `{name}`"));
            }
            if value.contains('\0') {
                return self.invalid(
                    &format!("env.{name}"),
                    "has a NUL byte, which no environment value can hold".into(),
                );
            }
            if let Err(e) = placeholders::check(value, &case_known) {
                return self.invalid(&format!("env.{name}"), e.to_string());
            }
        }
        Ok(())
    }

    /// What one run is given: its steps, its particle counts and its timeout.
    fn validate_run(&self) -> Result<(), (String, String)> {
        match self.steps {
            Steps::Fixed(s) if s == 0 || s > MAX_STEPS => {
                return self.invalid(
                    "steps",
                    format!("must be at least 1 (and at most {MAX_STEPS})"),
                );
            }
            Steps::Scaled(r) if !(r.work.is_finite() && r.work >= 1.0) => {
                return self.invalid(
                    "steps.work",
                    format!(
                        "is {}: it must be a finite cost of one run, at least 1",
                        r.work
                    ),
                );
            }
            _ => {}
        }
        if let Some(n) = &self.n
            && (n.is_empty() || n.contains(&0))
        {
            return self.invalid(
                "n",
                "must be a non-empty list of particle counts >= 1".into(),
            );
        }
        if !(self.timeout_s.is_finite()
            && self.timeout_s > 0.0
            && self.timeout_s <= super::MAX_TIMEOUT_S)
        {
            return self.invalid(
                "timeout_s",
                format!(
                    "is {}: it must be a number of seconds > 0 and at most {} (7 days)",
                    self.timeout_s,
                    super::MAX_TIMEOUT_S
                ),
            );
        }
        Ok(())
    }

    /// The regular expressions that read the output: valid, with the groups each one needs.
    fn validate_regexes(&self) -> Result<(), (String, String)> {
        if let TimeSource::Regex(t) = &self.time
            && let Err(e) = number_regex(&t.regex, "Loop time of ([0-9.eE+-]+)")
        {
            return self.invalid("time.regex", e);
        }
        for (name, phase) in &self.phases {
            if !plain_name(name) {
                return self.invalid(
                    "phases",
                    format!(
                        "has a phase named `{name}`: use letters, digits, '-', '_' and '.', not \
                         starting with '-'"
                    ),
                );
            }
            if let Err(e) = number_regex(&phase.regex, "phase comm ([0-9.eE+-]+)") {
                return self.invalid(&format!("phases.{name}.regex"), e);
            }
        }
        if let Some(e) = &self.energy
            && let Err(e) = number_regex(e, "total energy ([0-9.eE+-]+)")
        {
            return self.invalid("energy", e);
        }
        if let Some(c) = &self.check
            && let Err(e) = regex::Regex::new(c)
        {
            return self.invalid("check", format!("is not a regular expression: {e}"));
        }
        if let Some(f) = &self.force_error {
            match regex::Regex::new(f) {
                Err(e) => {
                    return self
                        .invalid("force_error", format!("is not a regular expression: {e}"));
                }
                Ok(r) if !(2..=3).contains(&r.captures_len()) => {
                    return self.invalid(
                        "force_error",
                        "needs one group (the median error) or two (median and largest)".into(),
                    );
                }
                Ok(_) => {}
            }
        }
        Ok(())
    }

    /// The family, if any: a plain name, not a built-in kernel's, and with a force error to
    /// join its entries by.
    fn validate_family(&self) -> Result<(), (String, String)> {
        let Some(f) = &self.family else {
            return Ok(());
        };
        if !plain_name(f) {
            return self.invalid(
                "family",
                format!(
                    "is `{f}`: it must be letters, digits, '-', '_' and '.', not starting with '-'"
                ),
            );
        }
        // A family names a series in tables and figures beside the built-in kernels' own.
        if nbody_engine::kernels::KernelKind::ALL
            .iter()
            .any(|k| k.name() == f)
        {
            return self.invalid(
                "family",
                format!(
                    "is `{f}`, a built-in kernel's name: its series would read as that \
                     kernel's; choose another"
                ),
            );
        }
        if self.force_error.is_none() {
            return self.invalid(
                "family",
                "joins entries by their force error against cost: give `force_error` too".into(),
            );
        }
        Ok(())
    }

    /// The entry's own threads, ranks and scenarios, where given: non-empty lists of valid values.
    fn validate_case_lists(&self) -> Result<(), (String, String)> {
        if let Some(t) = &self.threads
            && (t.is_empty()
                || t.iter()
                    .any(|&t| t == 0 || t > nbody_engine::run::MAX_THREADS))
        {
            return self.invalid(
                "threads",
                format!(
                    "must be a non-empty list of thread counts from 1 to {}",
                    nbody_engine::run::MAX_THREADS
                ),
            );
        }
        if let Some(r) = &self.ranks
            && (r.is_empty() || r.contains(&0))
        {
            return self.invalid(
                "ranks",
                "must be a non-empty list of rank counts >= 1".into(),
            );
        }
        if self.scenarios.as_ref().is_some_and(Vec::is_empty) {
            return self.invalid(
                "scenarios",
                "is empty; leave it out to use the config's".into(),
            );
        }
        Ok(())
    }

    /// Checks that cases differing in threads or ranks differ in what the program is told.
    pub(crate) fn check_told(
        &self,
        threads: &[usize],
        ranks: &[usize],
        mpi: bool,
    ) -> Result<(), (String, String)> {
        let key = |k: &str| format!("external.{}.{k}", self.name);
        if threads.iter().any(|&t| t != 1) && !self.uses("threads") {
            return Err((
                key("threads"),
                format!(
                    "are {threads:?} but neither the command nor env uses {{threads}}: every \
                     thread count would run the same program (e.g. env = {{ OMP_NUM_THREADS = \"{{threads}}\" }})"
                ),
            ));
        }
        if ranks.iter().any(|&r| r != 1) && !mpi && !self.uses("ranks") {
            return Err((
                key("ranks"),
                format!(
                    "are {ranks:?} but there is no [mpi] launcher and the command does not use \
                     {{ranks}}: add an [mpi] table or start the launcher in the command \
                     ([\"mpirun\", \"-n\", \"{{ranks}}\", ...])"
                ),
            ));
        }
        Ok(())
    }
}

/// What the rest of a sweep config says that the `[[external]]` entries depend on.
pub(crate) struct Around<'a> {
    pub threads: &'a [usize],
    /// The `[mpi]` table's rank counts, if it has one.
    pub(crate) mpi_ranks: Option<&'a [usize]>,
    pub strong: bool,
    pub(crate) weak: bool,
    /// A weak study whose rule is the kernels' cost model.
    pub(crate) weak_cost_model: bool,
}

/// Checks the `[[external]]` entries against each other and the rest of the config;
/// `(key, problem)` on failure.
pub(crate) fn validate_entries(
    entries: &[External],
    around: &Around,
) -> Result<(), (String, String)> {
    for (i, e) in entries.iter().enumerate() {
        e.validate()?;
        if entries[..i].iter().any(|o| o.name == e.name) {
            return Err((
                "external.name".into(),
                format!("`{}` names two [[external]] entries", e.name),
            ));
        }
        let threads = e.threads.as_deref().unwrap_or(around.threads);
        let ranks = e.ranks.as_deref().or(around.mpi_ranks).unwrap_or(&[1]);
        e.check_told(threads, ranks, around.mpi_ranks.is_some())?;
        if around.strong && !(threads.contains(&1) && ranks.contains(&1)) {
            return Err((
                format!("external.{}.threads", e.name),
                "must include 1 thread and 1 rank for a strong-scaling study".into(),
            ));
        }
        if around.weak && e.n.is_some() {
            return Err((
                format!("external.{}.n", e.name),
                "does not apply to study = \"weak\": its sizes follow from weak.base_n and the \
                 workers; remove `n`"
                    .into(),
            ));
        }
        if around.weak_cost_model {
            return Err((
                "weak.rule".into(),
                format!(
                    "is cost-model, which external `{}` has none of; use linear, sqrt or time",
                    e.name
                ),
            ));
        }
    }
    Ok(())
}
