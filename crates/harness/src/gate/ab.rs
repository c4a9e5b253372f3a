//! The A/B gate: two builds measured in one run on one machine, interleaved case by case.
//!
//! Two sweeps of the same build taken 30 s apart differ by up to a third on a shared 2-vCPU
//! machine (its speed drifts), and no normalisation cancels all of that. So each case is
//! measured by both builds back to back, the order alternating (A B, B A, ...) and the case
//! order reversed every round, until each build has `rounds` rounds of the case; each sample
//! is still paired with the reference workload timed right before it. Both builds run their
//! own `sweep` command on a one-case, one-round config, so any revision that has `sweep`
//! can be the base. The rounds of each build are then merged into one results file per build
//! and judged by [`super::compare`] like any two results files.

use super::base_build::BaseBinary;
use super::duet::Sides;
use crate::children::supervised::{self as child, ChildError};
use nbody_records::config::SweepConfig;
use nbody_records::plan::{Case, cases};
use nbody_records::results::{CaseRecord, ResultsFile};
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Duration;
use thiserror::Error;

/// Most rounds of every case per build: 4 are the default and were enough for the error rates
/// of docs/explanation/gate.md; 100 rounds of `configs/ci.toml` already take about half an hour.
pub const MAX_ROUNDS: usize = 100;

/// Whether `rounds` rounds per build can be measured: an even number from 2 to
/// [`MAX_ROUNDS`].
pub fn check_rounds(rounds: usize) -> Result<(), AbError> {
    if rounds < 2 || !rounds.is_multiple_of(2) || rounds > MAX_ROUNDS {
        return Err(AbError::Rounds(rounds));
    }
    Ok(())
}

/// Why an A/B run cannot be prepared or measured.
#[derive(Debug, Error)]
pub enum AbError {
    /// The config has a form the A/B gate cannot run: MPI, weak-by-time cases, a text that is
    /// not a TOML table, or a one-case config that does not parse back to its case.
    #[error("the A/B gate cannot run config `{name}`: {why}")]
    Unsupported {
        /// The config's `name`.
        name: String,
        /// What in it the A/B form cannot run, with what to do instead.
        why: String,
    },
    /// `--rounds` is odd, below 2 or above [`MAX_ROUNDS`].
    #[error(
        "--rounds must be an even number from 2 to {max} (got {0}): each build must go first \
         as often as the other, and {max} rounds of every case are already far more than the \
         noise of the gate needs",
        max = MAX_ROUNDS
    )]
    Rounds(usize),
    /// A build's sweep past its time limit.
    #[error(transparent)]
    Stuck(ChildError),
    /// A build did not answer `sweep --help` in time, asked whether its sweep takes `--yes`.
    #[error("the base build at {path} cannot be asked for its options: {source}")]
    Probe {
        /// The binary asked.
        path: PathBuf,
        /// How it failed: past its time limit, or waiting for it failed.
        source: ChildError,
    },
    /// A build's one-case sweep could not start, failed, or wrote no results for the case.
    #[error(
        "the {side} build failed to measure {key} (round {round}); its output ends with:\n{tail}"
    )]
    Side {
        /// Which build: "base" or "current".
        side: &'static str,
        /// The case's key.
        key: String,
        /// The A/B round it failed in, counted from 0.
        round: usize,
        /// The last lines of its standard error and output, or why it could not start.
        tail: String,
    },
    /// A one-case sweep's directory or config could not be written.
    #[error("cannot write {path}: {source}")]
    Io {
        /// The directory or file.
        path: PathBuf,
        /// The underlying error.
        source: std::io::Error,
    },
    /// A one-case sweep's results file could not be loaded.
    #[error(transparent)]
    Results(#[from] nbody_records::results::ResultsError),
}

/// The two builds, A (the base) and B (this one).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Side {
    /// The base revision's build (A).
    Base,
    /// This build (B).
    Current,
}

impl Side {
    /// "base" or "current", as named in progress lines, errors and scratch directories.
    pub fn name(self) -> &'static str {
        match self {
            Side::Base => "base",
            Side::Current => "current",
        }
    }
}

/// What an A/B run needs.
pub struct AbPlan<'a> {
    /// The sweep config both builds measure.
    pub config: &'a SweepConfig,
    /// Its text, copied into the merged results files.
    pub config_text: &'a str,
    /// Every case with its one-case config, from [`prepare`].
    pub cases: &'a [OneCase],
    /// The base revision's binary.
    pub base: &'a BaseBinary,
    /// This build's binary.
    pub current: &'a Path,
    /// Rounds of every case per build.
    pub rounds: usize,
    /// Scratch directory for the one-case sweeps.
    pub work: &'a Path,
    /// The longest one build's one-case sweep of a case may take, by case; see
    /// [`child_limit`].
    pub limit: &'a (dyn Fn(&Case) -> Duration + Sync),
    /// Whether a round's two builds run at once, one per CPU, or take turns.
    pub sides: Sides,
}

/// One case of an A/B run and the config text both builds sweep it with.
#[derive(Clone, Debug)]
pub struct OneCase {
    /// The case, as this build plans it.
    pub case: Case,
    /// TOML config that plans exactly this case, for one round.
    pub text: String,
}

/// Everything about an A/B run of `config` that can be refused without the base build, so
/// that no refusal comes after minutes of compiling: the rounds, the kinds of config the A/B
/// form cannot run, and every case's one-case config, which must parse back (with this
/// build's parser) to exactly that case.
pub fn prepare(
    config: &SweepConfig,
    config_text: &str,
    rounds: usize,
) -> Result<Vec<OneCase>, AbError> {
    let unsupported = |why: String| AbError::Unsupported {
        name: config.name.clone(),
        why,
    };
    check_rounds(rounds)?;
    if config.mpi.is_some() {
        return Err(unsupported(
            "it runs cases under MPI; gate a config without [mpi]".into(),
        ));
    }
    let planned = cases(config);
    if planned.iter().any(|c| c.time_factor != 1) {
        return Err(unsupported(
            "its weak-by-time cases have no one-case config form".into(),
        ));
    }
    let table: toml::Table = toml::from_str(config_text).map_err(|e| {
        unsupported(format!(
            "its text does not parse as a TOML table ({}; a TOML table holds integers up \
             to {})",
            e.message().trim(),
            i64::MAX
        ))
    })?;
    let samples = samples_per_round(config, rounds);
    planned
        .into_iter()
        .map(|case| {
            let text = one_case_config(&table, &case, samples)
                .map_err(|e| unsupported(format!("case {}: {e}", case.key())))?;
            let parsed = SweepConfig::parse(&text, Path::new("ab.toml")).map_err(|e| {
                unsupported(format!(
                    "the one-case config of {} does not parse ({e})",
                    case.key()
                ))
            })?;
            let keys: Vec<String> = cases(&parsed).iter().map(Case::key).collect();
            if keys != [case.key()] {
                return Err(unsupported(format!(
                    "the one-case config of {} plans [{}] instead",
                    case.key(),
                    keys.join(", ")
                )));
            }
            Ok(OneCase { case, text })
        })
        .collect()
}

/// Floor of a child's time limit: starting a sweep, building its system and its energy
/// probes take seconds even for a tiny case, on a machine busy with other work too.
pub(crate) const CHILD_FLOOR: Duration = Duration::from_secs(120);
/// A child's limit is this many times its estimate (the estimate is a rule of thumb from a
/// probe at small n; a shared 2-vCPU machine runs the same code up to 3x slower under load).
pub(crate) const CHILD_ESTIMATE_FACTOR: f64 = 10.0;
/// Runs of an external program in one round besides its samples: the set-up, the empty runs
/// that measure the launch overhead, and slack for its warm-up runs.
const EXTERNAL_EXTRA_RUNS: usize = 12;
/// No limit is longer than a week (an external's `timeout_s` may be huge).
const LONGEST_LIMIT: Duration = Duration::from_secs(7 * 24 * 3600);

/// The time limit of one build's one-case round of `case`: [`CHILD_ESTIMATE_FACTOR`] times its
/// estimate `estimate_s` (seconds; `None` when the case was not estimated), at least
/// [`CHILD_FLOOR`]; an external program's case allows every one of its runs its own
/// `timeout_s` on top.
pub fn child_limit(
    config: &SweepConfig,
    case: &Case,
    rounds: usize,
    estimate_s: Option<f64>,
) -> Duration {
    let mut limit = CHILD_FLOOR
        .as_secs_f64()
        .max(estimate_s.unwrap_or(0.0) * CHILD_ESTIMATE_FACTOR);
    if let nbody_records::kernel_or_program::KernelOrProgram::External(name) = &case.kernel
        && let Some(ext) = config.external.iter().find(|e| &e.name == name)
    {
        let runs = samples_per_round(config, rounds) + ext.warmup_runs + EXTERNAL_EXTRA_RUNS;
        limit += runs as f64 * ext.timeout_s;
    }
    Duration::try_from_secs_f64(limit)
        .unwrap_or(LONGEST_LIMIT)
        .min(LONGEST_LIMIT)
}

/// Both builds' merged results.
pub struct AbResults {
    /// The base build's rounds of every case merged into one results file, its metadata naming
    /// the base commit (no calibration: the caller adds the one both sides share).
    pub base: ResultsFile,
    /// This build's rounds of every case, merged likewise.
    pub current: ResultsFile,
    /// Wall time of the interleaved measurement, seconds.
    pub measure_s: f64,
}

/// The order of the two builds for one case in one round: A B, then B A, alternating over
/// cases and rounds, so that neither build is systematically first after a case switch.
pub fn order(round: usize, case: usize) -> [Side; 2] {
    if (round + case).is_multiple_of(2) {
        [Side::Base, Side::Current]
    } else {
        [Side::Current, Side::Base]
    }
}

/// Samples per one-case round: the config's samples spread over the A/B rounds, at least 2,
/// and at least [`super::MIN_CI_SAMPLES`] per build in all (the fewest a CI is judged on).
pub fn samples_per_round(config: &SweepConfig, rounds: usize) -> usize {
    let rounds = rounds.max(1);
    config
        .measure
        .samples
        .max(super::MIN_CI_SAMPLES)
        .div_ceil(rounds)
        .max(2)
}

/// Measures every case of the plan with both builds, interleaved, `plan.rounds` rounds each.
pub fn measure(plan: &AbPlan<'_>, progress: &mut dyn FnMut(&str)) -> Result<AbResults, AbError> {
    let mut run = AbRun::start(plan)?;
    let all: Vec<usize> = (0..plan.cases.len()).collect();
    run.extend(plan, &all, plan.rounds, progress)?;
    Ok(run.results(plan))
}

/// An A/B run in progress: both builds' rounds of every case so far, so that the cases a look
/// left undecided can be measured further ([`super::sequential`]).
pub struct AbRun {
    merged: [Vec<CaseRecord>; 2],
    metadata: [Option<nbody_records::results::Metadata>; 2],
    takes_yes: [bool; 2],
    started: std::time::Instant,
}

impl AbRun {
    /// Asks both builds how their sweep is started; nothing is measured yet.
    pub fn start(plan: &AbPlan<'_>) -> Result<AbRun, AbError> {
        // A base that estimates a sweep's length before starting it (as this build does) is
        // told not to, like this build, so that neither side does extra work before its samples.
        let probe_limit = plan
            .cases
            .first()
            .map_or(CHILD_FLOOR, |c| (plan.limit)(&c.case));
        // Either side may be an older build (a bisection measures two of them): each is asked.
        let takes_yes = [
            takes_yes(&plan.base.path, probe_limit)?,
            takes_yes(plan.current, probe_limit)?,
        ];
        let logical = nbody_engine::run::logical_cpus();
        let records = || -> Vec<CaseRecord> {
            plan.cases
                .iter()
                .map(|c| CaseRecord::new(c.case.clone(), 0, logical))
                .collect()
        };
        Ok(AbRun {
            merged: [records(), records()],
            metadata: [None, None],
            takes_yes,
            started: std::time::Instant::now(),
        })
    }

    /// Rounds per build measured so far of case `index`.
    pub fn rounds_of(&self, index: usize) -> usize {
        self.merged[0][index].rounds.len()
    }

    /// Measures the cases `open` (indices into the plan's cases) until each has `until`
    /// rounds per build: round by round, every open case by both builds back to back, the
    /// builds' order alternating and the cases' order reversed every round.
    pub fn extend(
        &mut self,
        plan: &AbPlan<'_>,
        open: &[usize],
        until: usize,
        progress: &mut dyn FnMut(&str),
    ) -> Result<(), AbError> {
        let from = open
            .iter()
            .map(|&i| self.rounds_of(i))
            .min()
            .unwrap_or(until);
        for round in from..until {
            let mut indices: Vec<usize> = open
                .iter()
                .copied()
                .filter(|&i| self.rounds_of(i) == round)
                .collect();
            progress(&format!(
                "A/B round {}/{until}: {} case(s), {} then {} first in turn ({:.0} s so far)",
                round + 1,
                indices.len(),
                Side::Base.name(),
                Side::Current.name(),
                self.started.elapsed().as_secs_f64()
            ));
            if round % 2 == 1 {
                indices.reverse();
            }
            for i in indices {
                let duet = plan.sides == Sides::Duet && super::duet::suits(&plan.cases[i].case);
                match (duet, super::duet::cpus()) {
                    (true, Some(cpus)) => self.duet_round(plan, cpus, i, round)?,
                    _ => {
                        for side in order(round, i) {
                            let file = self.run(plan, side, i, round, None)?;
                            self.absorb(plan, side, i, round, file)?;
                        }
                    }
                }
            }
        }
        for &i in open {
            for side in &mut self.merged {
                side[i].rounds_planned = side[i].rounds_done;
            }
        }
        Ok(())
    }

    /// Both builds' round `round` of case `i` at the same moment, each pinned to one of `cpus`,
    /// the CPUs swapped every round ([`super::duet::cpu_of`]).
    fn duet_round(
        &mut self,
        plan: &AbPlan<'_>,
        cpus: [usize; 2],
        i: usize,
        round: usize,
    ) -> Result<(), AbError> {
        let this: &AbRun = self;
        let [base, current] = std::thread::scope(|s| {
            [Side::Base, Side::Current]
                .map(|side| {
                    let cpu = cpus[super::duet::cpu_of(side as usize, round)];
                    s.spawn(move || this.run(plan, side, i, round, Some(cpu)))
                })
                .map(|h| h.join())
        });
        for (side, file) in [(Side::Base, base), (Side::Current, current)] {
            let file = file.map_err(|_| AbError::Side {
                side: side.name(),
                key: plan.cases[i].case.key(),
                round,
                tail: "the thread that ran it panicked".to_string(),
            })??;
            self.absorb(plan, side, i, round, file)?;
        }
        Ok(())
    }

    /// One build's round `round` of case `i` (on `cpu` only, if given); its results file.
    fn run(
        &self,
        plan: &AbPlan<'_>,
        side: Side,
        i: usize,
        round: usize,
        cpu: Option<usize>,
    ) -> Result<ResultsFile, AbError> {
        let dir = plan
            .work
            .join(side.name())
            .join(format!("case{i}-round{round}"));
        let file = run_side(
            plan,
            side,
            &plan.cases[i].text,
            &dir,
            &plan.cases[i].case,
            round,
            self.takes_yes[side as usize],
            cpu,
        );
        // The one-case sweep's files are merged next; keep the scratch small.
        let _ = std::fs::remove_dir_all(&dir);
        file
    }

    /// Merges one build's one-case results file into that build's record of case `i`.
    fn absorb(
        &mut self,
        plan: &AbPlan<'_>,
        side: Side,
        i: usize,
        round: usize,
        file: ResultsFile,
    ) -> Result<(), AbError> {
        let case = &plan.cases[i].case;
        let slot = side as usize;
        self.metadata[slot].get_or_insert_with(|| file.metadata.clone());
        let record = file
            .cases
            .into_iter()
            .find(|c| c.key == case.key())
            .ok_or_else(|| AbError::Side {
                side: side.name(),
                key: case.key(),
                round,
                tail: "its results file has no such case".to_string(),
            })?;
        self.merged[slot][i].absorb(record, plan.config.measure.max_energy_drift);
        Ok(())
    }

    /// Both builds' rounds so far, each merged into one results file.
    pub fn results(&self, plan: &AbPlan<'_>) -> AbResults {
        let file = |cases: Vec<CaseRecord>, meta: Option<_>| ResultsFile {
            schema: nbody_records::results::RESULTS_SCHEMA.to_string(),
            metadata: meta.unwrap_or_else(|| {
                nbody_records::results::Metadata::collect(&crate::experiment::cargo_features())
            }),
            config: plan.config.clone(),
            config_text: plan.config_text.to_string(),
            calibration: Default::default(),
            cases,
        };
        let [base_cases, current_cases] = self.merged.clone();
        let [base_meta, current_meta] = self.metadata.clone();
        let mut base = file(base_cases, base_meta);
        // The base binary reads the commit from the checkout it runs in, which is this one.
        base.metadata.git_commit = plan.base.commit.clone();
        base.metadata.git_dirty = false;
        AbResults {
            base,
            current: file(current_cases, current_meta),
            measure_s: self.started.elapsed().as_secs_f64(),
        }
    }
}

/// Whether a binary's `sweep` has the `--yes` flag; a binary that does not answer within
/// `limit` is an error (it would hang every sweep too).
fn takes_yes(binary: &Path, limit: Duration) -> Result<bool, AbError> {
    let what = format!("`{} sweep --help`", binary.display());
    match child::output(
        Command::new(binary).args(["sweep", "--help"]),
        limit,
        &what,
        "",
    ) {
        Ok(o) => Ok(String::from_utf8_lossy(&o.stdout).contains("--yes")),
        // A binary that cannot start fails its first sweep with the reason.
        Err(ChildError::Start { .. }) => Ok(false),
        Err(source) => Err(AbError::Probe {
            path: binary.to_path_buf(),
            source,
        }),
    }
}

/// The median of every reference-workload time of a results file, seconds.
pub fn median_reference(file: &ResultsFile) -> Option<f64> {
    let all: Vec<f64> = file
        .cases
        .iter()
        .flat_map(|c| c.rounds.iter().flat_map(|r| r.reference_s.iter().copied()))
        .collect();
    nbody_engine::stats::median(&all)
}

/// The config text of one case for one round: the config's own text with the lists narrowed
/// to the case, one round of `samples` samples, no budget. A value TOML cannot carry (a seed
/// above `i64::MAX`) is an error naming it.
fn one_case_config(table: &toml::Table, case: &Case, samples: usize) -> Result<String, String> {
    let int = |what: &str, v: u64| {
        i64::try_from(v).map_err(|_| {
            format!(
                "its {what} {v} is above {}, the largest integer a TOML config can hold, so \
                 the builds cannot be given its one-case config; use a smaller {what}",
                i64::MAX
            )
        })
    };
    let seed = int("seed", case.seed)?;
    let n = int("n", case.n as u64)?;
    let mut t = table.clone();
    let list = |v: toml::Value| toml::Value::Array(vec![v]);
    t.insert("name".into(), "ab".into());
    t.insert("study".into(), "cartesian".into());
    t.remove("weak");
    t.remove("out");
    t.insert("scenarios".into(), list(case.scenario.name().into()));
    match &case.kernel {
        nbody_records::kernel_or_program::KernelOrProgram::Kernel(k) => {
            t.insert("kernels".into(), list(k.name().into()));
            t.remove("external");
        }
        nbody_records::kernel_or_program::KernelOrProgram::External(name) => {
            // The one `[[external]]` entry of the case, narrowed to its threads and ranks.
            t.insert("kernels".into(), toml::Value::Array(Vec::new()));
            if let Some(toml::Value::Array(entries)) = t.get_mut("external") {
                entries.retain(|e| e.get("name").and_then(|n| n.as_str()) == Some(name));
                for e in entries.iter_mut().filter_map(toml::Value::as_table_mut) {
                    e.insert("threads".into(), list((case.threads as i64).into()));
                    e.insert("ranks".into(), list((case.ranks as i64).into()));
                    e.remove("scenarios");
                }
            }
        }
    }
    t.insert("n".into(), list(n.into()));
    t.insert("threads".into(), list((case.threads as i64).into()));
    t.insert("seeds".into(), list(seed.into()));
    match case.theta {
        Some(theta) => t.insert("theta".into(), list(theta.into())),
        None => t.remove("theta"),
    };
    // A skin only where the case has one, so that a build older than the key reads the rest.
    match case.skin {
        Some(skin) => t.insert("skin".into(), list(skin.into())),
        None => t.remove("skin"),
    };
    // The expansion is the octree's alone: another kernel's config does not name it, so that
    // a build older than the key (a backfilled commit) reads the config too.
    if case.kernel == nbody_engine::kernels::KernelKind::Octree {
        t.insert("multipole".into(), list(case.multipole.name().into()));
    } else {
        t.remove("multipole");
    }
    match case.order {
        Some(p) => t.insert("order".into(), list((p as i64).into())),
        None => t.remove("order"),
    };
    if let Some(p) = case.precision {
        t.insert("precision".into(), p.name().into());
    }
    let measure = t
        .entry("measure")
        .or_insert_with(|| toml::Value::Table(Default::default()));
    if let toml::Value::Table(m) = measure {
        m.insert("rounds".into(), 1.into());
        m.insert("samples".into(), (samples as i64).into());
        m.remove("budget_s");
    }
    toml::to_string(&t).map_err(|e| format!("its one-case form does not serialize ({e})"))
}

/// One build's one-case sweep (on `cpu` only, if given); its results file.
#[allow(clippy::too_many_arguments)]
fn run_side(
    plan: &AbPlan<'_>,
    side: Side,
    config_text: &str,
    dir: &Path,
    case: &Case,
    round: usize,
    takes_yes: bool,
    cpu: Option<usize>,
) -> Result<ResultsFile, AbError> {
    let io = |path: &Path| {
        let path = path.to_path_buf();
        move |source| AbError::Io { path, source }
    };
    nbody_engine::output::create_dir_all(dir).map_err(io(dir))?;
    let config = dir.join("ab.toml");
    std::fs::write(&config, config_text).map_err(io(&config))?;
    let binary = match side {
        Side::Base => plan.base.path.as_path(),
        Side::Current => plan.current,
    };
    let mut command = Command::new(binary);
    command
        .arg("sweep")
        .arg("--config")
        .arg(&config)
        .arg("--out")
        .arg(dir)
        .arg("--no-calibration");
    // A one-case round needs no length estimate (older bases have no such step, nor the flag).
    if takes_yes {
        command.arg("--yes");
    }
    if let Some(cpu) = cpu {
        super::duet::pin_command(&mut command, cpu);
    }
    if side == Side::Base {
        // The test-only slowdown knob is meant for this build only (a base revision from before
        // the knob became a test feature reads it in every build).
        command.env_remove("NBODY_BENCH_TEST_SLOWDOWN");
    }
    let what = format!(
        "the {} build's sweep of {} (round {round})",
        side.name(),
        case.key()
    );
    let hint = "pass --timeout SECONDS if the case really takes that long";
    let output = match child::output(&mut command, (plan.limit)(case), &what, hint) {
        Ok(output) => output,
        Err(ChildError::Start { source, .. }) => {
            return Err(AbError::Side {
                side: side.name(),
                key: case.key(),
                round,
                tail: format!("{} cannot be started: {source}", binary.display()),
            });
        }
        Err(stuck) => return Err(AbError::Stuck(stuck)),
    };
    let results = dir.join("ab").join("results.json");
    if !output.status.success() || !results.is_file() {
        let text = String::from_utf8_lossy(&output.stderr).to_string()
            + &String::from_utf8_lossy(&output.stdout);
        let lines: Vec<&str> = text.lines().collect();
        return Err(AbError::Side {
            side: side.name(),
            key: case.key(),
            round,
            tail: lines[lines.len().saturating_sub(12)..].join("\n"),
        });
    }
    Ok(ResultsFile::load(&results)?)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::Path;

    #[test]
    fn the_builds_take_turns() {
        let firsts: Vec<Side> = (0..4).map(|r| order(r, 0)[0]).collect();
        assert_eq!(
            firsts,
            [Side::Base, Side::Current, Side::Base, Side::Current]
        );
        assert_eq!(order(0, 1), [Side::Current, Side::Base]);
        for r in 0..3 {
            for c in 0..3 {
                let o = order(r, c);
                assert_ne!(o[0], o[1]);
            }
        }
    }

    #[test]
    fn one_case_configs_parse_to_that_case() {
        let text = std::fs::read_to_string(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../../configs/ci.toml"
        ))
        .unwrap();
        let config = SweepConfig::parse(&text, Path::new("configs/ci.toml")).unwrap();
        let table: toml::Table = toml::from_str(&text).unwrap();
        let all = cases(&config);
        assert!(all.len() > 4);
        for case in &all {
            let one = one_case_config(&table, case, 5).unwrap();
            let parsed = SweepConfig::parse(&one, Path::new("ab.toml")).unwrap();
            let planned = cases(&parsed);
            assert_eq!(planned.len(), 1, "{one}");
            assert_eq!(planned[0].key(), case.key());
            assert_eq!(parsed.measure.rounds, 1);
            assert_eq!(parsed.measure.samples, 5);
            assert_eq!(parsed.measure.reference_s, config.measure.reference_s);
        }
    }

    fn ci_config() -> (String, SweepConfig) {
        let text = std::fs::read_to_string(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../../configs/ci.toml"
        ))
        .unwrap();
        let config = SweepConfig::parse(&text, Path::new("configs/ci.toml")).unwrap();
        (text, config)
    }

    #[test]
    fn what_would_fail_after_the_build_is_refused_before_it() {
        let (text, config) = ci_config();
        let prepared = prepare(&config, &text, 4).unwrap();
        assert_eq!(prepared.len(), cases(&config).len());
        for bad in [0, 1, 3, 101, 1_000_000_000] {
            let e = prepare(&config, &text, bad).unwrap_err().to_string();
            assert!(e.contains("even number from 2 to 100"), "{bad}: {e}");
        }
        assert!(check_rounds(MAX_ROUNDS).is_ok() && check_rounds(2).is_ok());
        // A seed TOML cannot write back (the config parser takes u64, a TOML table i64).
        let big = text.replace("seeds = [", "seeds = [18446744073709551615, ");
        let big = if big == text {
            format!("seeds = [18446744073709551615]\n{text}")
        } else {
            big
        };
        let parsed = SweepConfig::parse(&big, Path::new("big.toml")).unwrap();
        let e = prepare(&parsed, &big, 4).unwrap_err().to_string();
        assert!(e.contains("9223372036854775807"), "{e}");
        // MPI configs have no one-case form.
        let mpi = std::fs::read_to_string(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../../configs/weak-mpi.toml"
        ))
        .unwrap();
        let config = SweepConfig::parse(&mpi, Path::new("configs/weak-mpi.toml")).unwrap();
        let e = prepare(&config, &mpi, 4).unwrap_err().to_string();
        assert!(e.contains("under MPI"), "{e}");
    }

    #[test]
    fn child_limits_follow_the_estimate_with_a_floor() {
        let (_, config) = ci_config();
        let case = &cases(&config)[0];
        assert_eq!(child_limit(&config, case, 4, None), CHILD_FLOOR);
        assert_eq!(child_limit(&config, case, 4, Some(0.5)), CHILD_FLOOR);
        assert_eq!(
            child_limit(&config, case, 4, Some(100.0)),
            Duration::from_secs(1000)
        );
        assert_eq!(
            child_limit(&config, case, 4, Some(f64::INFINITY)),
            LONGEST_LIMIT
        );
    }

    #[test]
    fn samples_are_spread_over_the_rounds() {
        let text = std::fs::read_to_string(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../../configs/ci.toml"
        ))
        .unwrap();
        let config = SweepConfig::parse(&text, Path::new("configs/ci.toml")).unwrap();
        assert_eq!(
            samples_per_round(&config, 3),
            config.measure.samples.div_ceil(3)
        );
        assert_eq!(samples_per_round(&config, 1000), 2);
        // However few samples the config takes, each build has enough for a CI.
        let mut few = config.clone();
        few.measure.samples = 1;
        for rounds in [2, 4, 6, 8] {
            assert!(samples_per_round(&few, rounds) * rounds >= crate::gate::MIN_CI_SAMPLES);
        }
    }
}
