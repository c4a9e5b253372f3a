//! `gate --save-baseline`: a sweep of the baseline's config kept as its machine class's
//! baseline, once it is fit to be one and, when it replaces that class's earlier baseline, once
//! an A/B run of this build against the earlier baseline's commit found no regression the user
//! did not accept ([`super::guard`]).

use super::drive::{self, Outcome};
use super::guard::{self, Acceptance, Decision, Regression};
use super::listed;
use super::{BUSY_BASELINE_CPUS, GateOptions, RunInfo, background_cpus, baselines, compare};
use nbody_records::config::SweepConfig;
use nbody_records::locate;
use nbody_records::plan::{Case, cases};
use nbody_records::results::{ResultsFile, read_json};
use std::path::{Path, PathBuf};

/// What `gate --save-baseline` is asked to do.
pub struct SaveRequest {
    /// The folder of baselines, one file per machine class (`--baseline`).
    pub folder: PathBuf,
    /// The results to keep (a results.json, a run directory or a config name).
    pub results: PathBuf,
    /// The regressions the user accepts in advance, with the reason.
    pub accept: Acceptance,
    /// How the A/B run against the replaced baseline's commit is measured and judged (its
    /// rounds, timeout, out, threshold, normalisation and judge; see [`drive::a_b_run`]).
    pub a_b: drive::Request,
}

/// A results file found fit to be its class's baseline, not yet kept.
pub struct Candidate {
    /// The results file, resolved.
    pub source: PathBuf,
    /// Where it comes from: its commit and machine class.
    pub info: RunInfo,
    /// Its class's file in the folder, which it would replace if present.
    pub target: PathBuf,
    /// Its stored config, as this build reproduces it: what the A/B run measures.
    config: SweepConfig,
    /// That config as TOML text.
    text: String,
    /// Its case keys, in its order.
    pub cases: Vec<String>,
}

/// The baseline a candidate replaces, and what the A/B run against its commit found.
pub struct Replaced {
    /// The commit the replaced baseline was measured at (the A/B run's base).
    pub commit: String,
    /// The A/B run: its report and where its measurements are kept.
    pub outcome: Outcome,
    /// The regressions the user accepted (empty when nothing regressed).
    pub accepted: Vec<Regression>,
    /// The reason given for them (`None` when nothing was accepted).
    pub reason: Option<String>,
}

/// A save that may go ahead: the caller records any acceptance, then calls [`Pending::keep`].
pub struct Pending {
    /// The results to keep.
    pub candidate: Candidate,
    /// The baseline it replaces; `None` when the class has none yet (nothing was compared).
    pub replaced: Option<Replaced>,
}

/// A save refused because of unaccepted regressions: the old baseline stays as it was.
pub struct Refusal {
    /// The A/B run that found them.
    pub outcome: Outcome,
    /// What to tell the user: every regressed case with its ratio and CI, and how to accept.
    pub message: String,
}

/// Whether the save goes ahead.
pub enum Judgement {
    /// Nothing regressed unaccepted (or nothing was compared): keep it.
    Ready(Box<Pending>),
    /// A regression was not accepted.
    Refused(Box<Refusal>),
}

/// Checks the results ([`check`]) and the acceptance (before anything is measured), then, if
/// the class already has a baseline, measures this build against its commit (A/B, the gate's
/// usual rule) and decides ([`guard::decide`]). Bad input is an error; nothing is written here.
pub fn judge_save(request: &SaveRequest, say: &mut dyn FnMut(&str)) -> anyhow::Result<Judgement> {
    let candidate = check(&request.folder, &request.results)?;
    if !candidate.target.exists() {
        request.accept.check(&candidate.cases)?;
        if !request.accept.is_empty() {
            return Err(guard::GuardError::NothingToCompare.into());
        }
        say(&format!(
            "no baseline of this machine class yet ({} does not exist): nothing to compare the \
             new one against, so it is saved unchecked",
            candidate.target.display()
        ));
        return Ok(Judgement::Ready(Box::new(Pending {
            candidate,
            replaced: None,
        })));
    }
    let old = RunInfo::from_json(&read_json(&candidate.target)?).ok_or_else(|| {
        anyhow::anyhow!(
            "{} records no commit, so the baseline it holds cannot be measured against this \
             build; if the file is broken, restore it from git",
            candidate.target.display()
        )
    })?;
    if old.git_dirty {
        say(&format!(
            "the baseline {} was measured with uncommitted changes: its commit {} is measured, \
             which may differ from it",
            candidate.target.display(),
            super::prefix(&old.git_commit, 12)
        ));
    }
    // The replaced baseline's own cases are the ones its commit can run and the ones a
    // regression would hide in; the candidate's config (which may name newer kernels or other
    // sizes) only when this build cannot reproduce the old one.
    let replaced_config = baselines::examine(&candidate.target)?.fitness;
    let (config, text, whose) = match replaced_config {
        baselines::Fitness::Reproducible(r) => (r.config, r.text, "that baseline's cases"),
        baselines::Fitness::Stale(_) => (
            candidate.config.clone(),
            candidate.text.clone(),
            "the new baseline's cases (this build cannot reproduce the old one's config)",
        ),
    };
    say(&format!(
        "{} replaces {}: measuring this build and that baseline's commit {} side by side (A/B) \
         on {whose} first, so that no regression goes into the baseline unseen",
        candidate.source.display(),
        candidate.target.display(),
        super::prefix(&old.git_commit, 12)
    ));
    let measured: Vec<String> = cases(&config).iter().map(Case::key).collect();
    let reason = request.accept.check(&measured)?;
    let outcome = drive::a_b_run(&request.a_b, &old.git_commit, &config, &text, say)?;
    match guard::decide(&outcome.report, &request.accept.cases)? {
        Decision::Save { accepted } => Ok(Judgement::Ready(Box::new(Pending {
            replaced: Some(Replaced {
                commit: old.git_commit,
                outcome,
                reason: (!accepted.is_empty()).then_some(reason).flatten(),
                accepted,
            }),
            candidate,
        }))),
        Decision::Refuse {
            regressed,
            unaccepted,
        } => Ok(Judgement::Refused(Box::new(Refusal {
            message: guard::refusal(&regressed, &unaccepted, &candidate.target, &old.git_commit),
            outcome,
        }))),
    }
}

impl Pending {
    /// Writes the candidate over its class's file (atomically: the old file stays whole until
    /// the new one replaces it). Returns the file written and the class it was kept for.
    pub fn keep(self) -> anyhow::Result<(PathBuf, RunInfo)> {
        let c = self.candidate;
        let text = nbody_engine::input::read_text(&c.source)
            .map_err(|e| anyhow::anyhow!("cannot read {}: {e}", c.source.display()))?;
        nbody_engine::output::write_atomic(&c.target, text.as_bytes())?;
        Ok((c.target, c.info))
    }
}

/// Whether `results` is fit to be kept in `folder` as its machine class's baseline: it
/// compares cleanly with itself (schema, calibration, config, every case judgeable), was
/// measured on a quiet machine, and plans again to its own cases with this build. Creates the
/// folder if needed, writes nothing else.
pub fn check(folder: &Path, results: &Path) -> anyhow::Result<Candidate> {
    let source = locate::find_results(results, Path::new("results"))?;
    if nbody_engine::input::is_pipe(&source) {
        // It is read twice: checked, then copied byte for byte.
        anyhow::bail!(
            "--save-baseline {}: is a pipe; a baseline is checked and then copied, so it must \
             be a file: write it to one first",
            source.display()
        );
    }
    let file = ResultsFile::load(&source)?;
    if file.calibration.start.is_none() && file.calibration.end.is_none() {
        anyhow::bail!(
            "{} was swept without calibration, so its machine class is unknown; sweep \
             configs/ci.toml again with calibration",
            source.display()
        );
    }
    if let Some(busy) = background_cpus(&file).filter(|&b| b >= BUSY_BASELINE_CPUS) {
        // The reference workload slows down more than the kernels under load: every later
        // run on a quiet machine would read as a regression.
        anyhow::bail!(
            "{} was measured while other processes used {busy:.2} CPUs (at most \
             {BUSY_BASELINE_CPUS} for a baseline): every later run would be judged against a \
             slowed reference; wait for the other work to end and run \
             scripts/refresh-baseline.sh again",
            source.display(),
        );
    }
    compare(&file, &file, &GateOptions::default())?;
    if let Some(why) = unfit_as_baseline(&file) {
        anyhow::bail!(
            "{} cannot be a baseline, since a gate could not judge against it: {why}; sweep \
             the config to completion (sweep --resume) and save that run",
            source.display()
        );
    }
    let reproducible = match baselines::examine(&source)?.fitness {
        baselines::Fitness::Stale(why) => anyhow::bail!(
            "{} cannot be a baseline: {why}; sweep the config again with this build",
            source.display()
        ),
        baselines::Fitness::Reproducible(r) => r,
    };
    if folder.is_file() {
        anyhow::bail!(
            "--baseline {} is a file; --save-baseline needs the folder of baselines \
             (results/baseline)",
            folder.display()
        );
    }
    nbody_engine::output::create_dir_all(folder)
        .map_err(|e| anyhow::anyhow!("cannot create {}: {e}", folder.display()))?;
    let info = RunInfo::of(&file);
    let target = folder.join(baselines::file_name(&info));
    Ok(Candidate {
        source,
        target,
        cases: file.cases.iter().map(|c| c.key.clone()).collect(),
        info,
        config: reproducible.config,
        text: reproducible.text,
    })
}

/// Why a results file cannot be a baseline: every check the gate makes against it must be
/// able to compare something, so a file with no case, a case with no measured round, an
/// unfinished case, or fewer successful samples than a CI needs is refused.
pub fn unfit_as_baseline(file: &ResultsFile) -> Option<String> {
    if file.cases.is_empty() {
        return Some("it holds no case".to_string());
    }
    let mut why: Vec<String> = file
        .cases
        .iter()
        .filter(|c| !c.is_complete())
        .map(|c| {
            format!(
                "{}: {}/{} rounds measured",
                c.key, c.rounds_done, c.rounds_planned
            )
        })
        .collect();
    // The file against itself: every case it could not judge is one a gate could not either.
    if let Ok(report) = compare(file, file, &GateOptions::default()) {
        for m in &report.missing {
            if !why.iter().any(|w| w.starts_with(&format!("{}:", m.key))) {
                why.push(format!("{}: {}", m.key, m.reason));
            }
        }
    }
    (!why.is_empty()).then(|| listed(&why))
}
