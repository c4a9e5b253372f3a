//! A gate run from start to verdict: compare two files, or measure this build along the
//! decided [`route`](super::route) and judge it. The command line parses its arguments into a
//! [`Request`], calls [`run`], prints the [`Outcome`].

use super::ab::{self, AbPlan};
use super::route::{self, Route, short};
use super::{
    AB_JUDGE, AB_THRESHOLD, FILE_JUDGE, FILE_THRESHOLD, GateOptions, GateReport, Judged,
    NormalizationChoice, base_build, compare,
};
use crate::experiment::estimate::{self, Done};
use crate::experiment::runner::{SweepOptions, run_sweep_wall};
use crate::units::WallTime;
use nbody_engine::output::provenance::utc_now;
use nbody_records::config::SweepConfig;
use nbody_records::locate;
use nbody_records::plan::Case;
use nbody_records::results::ResultsFile;
use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::time::Duration;

/// How far the two builds' reference workload may differ (median over all samples) before the
/// A/B gate stops normalising by it. In 20 A/B runs of `configs/ci.toml` on the 2-vCPU AMD EPYC
/// of 2026-12-01 (same reference code on both sides) the ratio stayed within 0.998-1.005.
const REFERENCE_TOLERANCE: f64 = 0.05;

/// What a gate run is asked to do (the command's options).
#[derive(Clone, Debug)]
pub struct Request {
    /// The reference run: a results file, or a folder of baselines, one per machine class.
    pub baseline: PathBuf,
    /// Results to judge as they are (`--current`); `None` makes the gate measure this build.
    pub current: Option<PathBuf>,
    /// Revision to measure side by side with this build (A/B); `None`: the baseline decides.
    pub against: Option<String>,
    /// Config to measure (a file or a config name); `None` sweeps the baseline's own config.
    pub config: Option<PathBuf>,
    /// Rounds of every case per build in an A/B run's first look: even, from 2 to
    /// [`ab::MAX_ROUNDS`].
    pub rounds: usize,
    /// Most rounds per build a case undecided after the first look is measured to, in looks of
    /// `rounds` more each ([`super::sequential::schedule`]); `rounds` itself judges once.
    pub max_rounds: usize,
    /// How an A/B run's builds share the machine; `None`: duet where two CPUs are free
    /// ([`super::duet::choose`]).
    pub sides: Option<super::duet::Sides>,
    /// Longest one build's sweep of one case may take in an A/B run, seconds; `None`: from the
    /// case's estimate ([`ab::child_limit`]).
    pub timeout: Option<f64>,
    /// Where a measuring gate keeps what it measured; `None`: a new run directory under
    /// `results/runs/gate/`.
    pub out: Option<PathBuf>,
    /// Relative change a case must exceed (0.10 = 10%); `None` takes the mode's default.
    pub threshold: Option<f64>,
    /// What the times are divided by before comparing.
    pub normalize: NormalizationChoice,
    /// The ratio cases are judged on [default: each mode's, `AB_JUDGE` or `FILE_JUDGE`].
    pub judge: Option<Judged>,
    /// Compare results from another machine, build or config anyway (with warnings).
    pub force: bool,
    /// A change of the deterministic work counters fails the gate too (exit 1).
    pub fail_on_work_change: bool,
}

/// A gate run's report and where its measurements were kept.
pub struct Outcome {
    /// The comparison of every case, also written to `gate.json`.
    pub report: GateReport,
    /// Directory holding `gate.json` and the measured results; `None` when two files were
    /// compared.
    pub kept_in: Option<PathBuf>,
}

impl Outcome {
    /// 1 for a regression, 2 for an incomplete comparison, else 0 ([`GateReport::exit_code`]).
    pub fn exit_code(&self) -> i32 {
        self.report.exit_code()
    }

    /// Why the comparison is incomplete, for the error stream: `None` when it is complete.
    pub fn incomplete(&self) -> Option<String> {
        if self.report.missing.is_empty() {
            return None;
        }
        let why: Vec<String> = self
            .report
            .missing
            .iter()
            .map(|m| format!("{} ({})", m.key, m.reason))
            .collect();
        Some(format!(
            "{} baseline case(s) could not be compared, which is not a pass: {}; run the \
             baseline's config to completion (sweep --resume), or refresh the baseline if the \
             cases were removed on purpose",
            why.len(),
            super::listed(&why)
        ))
    }
}

/// Runs the gate `request` asks for; `say` gets its progress lines.
pub fn run(request: &Request, say: &mut dyn FnMut(&str)) -> anyhow::Result<Outcome> {
    let outcome = match &request.current {
        Some(current) => compare_files(request, current)?,
        None => measure_and_judge(request, say)?,
    };
    if outcome.report.cases.is_empty() {
        anyhow::bail!("the gate {}", nothing_judged(&outcome.report));
    }
    Ok(outcome)
}

/// Why a run judged no case, which is not a pass: the reasons its cases could not be compared
/// (too few samples, none measured, ...), not only that nothing was judged.
fn nothing_judged(report: &GateReport) -> String {
    if report.missing.is_empty() {
        return "compared no case: the baseline has none, so nothing was judged, which is not a \
                pass"
            .to_string();
    }
    let why: Vec<String> = report
        .missing
        .iter()
        .map(|m| format!("{} ({})", m.key, m.reason))
        .collect();
    format!(
        "could judge none of its {} case(s), which is not a pass: {}",
        why.len(),
        super::listed(&why)
    )
}

fn options(request: &Request, default_threshold: f64, default_judge: Judged) -> GateOptions {
    GateOptions {
        threshold: request.threshold.unwrap_or(default_threshold),
        force: request.force,
        normalization: request.normalize,
        fail_on_work_change: request.fail_on_work_change,
        judge: request.judge.unwrap_or(default_judge),
        ..GateOptions::default()
    }
}

/// `--current`: two files, judged as they are.
fn compare_files(request: &Request, current: &Path) -> anyhow::Result<Outcome> {
    let root = Path::new("results");
    let current = ResultsFile::load(&locate::find_results(current, root)?)?;
    let baseline = if route::is_baseline_folder(&request.baseline) {
        let here = super::RunInfo::of(&current);
        let chosen = super::baselines::choose(&request.baseline, &here)?;
        ResultsFile::load(&chosen.path)?
    } else {
        ResultsFile::load(&locate::find_results(&request.baseline, root)?)?
    };
    Ok(Outcome {
        report: compare(
            &baseline,
            &current,
            &options(request, FILE_THRESHOLD, FILE_JUDGE),
        )?,
        kept_in: None,
    })
}

fn measure_and_judge(request: &Request, say: &mut dyn FnMut(&str)) -> anyhow::Result<Outcome> {
    let reference = route::find_reference(&request.baseline, request.against.as_deref())?;
    let (config, text) = route::config_to_sweep(request.config.as_deref(), &reference, say)?;
    let out = checked_out_dir(request)?;
    // Every refusal comes before anything long: the route, and what it needs, is checked
    // before a sweep or a build starts.
    let route = route::route(request.against.as_deref(), reference, say)?;
    let planned = match route {
        Route::Fast { path, baseline } => {
            fast_path_fits(&config)?;
            Planned::Fast { path, baseline }
        }
        Route::AB { rev } => Planned::AB(prepare_a_b(request, &rev, &config, &text, say)?),
    };
    let out = created_out_dir(out)?;
    let judged = match planned {
        Planned::AB(prepared) => a_b(request, &prepared, &config, &text, &out, say),
        Planned::Fast { path, baseline } => {
            fast_path(request, &path, &baseline, &config, &text, &out, say)
        }
    };
    kept(judged, out)
}

/// Measures this build and revision `rev` side by side on `config` (its TOML `text`) and
/// judges them as an A/B gate run does, for a caller that chose the route and the config
/// itself: `gate --save-baseline` against the commit of the baseline it replaces. The
/// request's rounds, timeout, out, threshold, normalisation and judge apply; its baseline,
/// current, against and config do not.
pub fn a_b_run(
    request: &Request,
    rev: &str,
    config: &SweepConfig,
    text: &str,
    say: &mut dyn FnMut(&str),
) -> anyhow::Result<Outcome> {
    let out = checked_out_dir(request)?;
    let prepared = prepare_a_b(request, rev, config, text, say)?;
    let out = created_out_dir(out)?;
    let judged = a_b(request, &prepared, config, text, &out, say);
    let outcome = kept(judged, out)?;
    if outcome.report.cases.is_empty() {
        anyhow::bail!("the A/B run {}", nothing_judged(&outcome.report));
    }
    Ok(outcome)
}

/// `--out DIR` created, or a new run directory under `results/runs/gate/`.
fn created_out_dir(out: Option<PathBuf>) -> anyhow::Result<PathBuf> {
    match out {
        Some(dir) => {
            nbody_engine::output::create_dir_all(&dir)
                .map_err(|e| anyhow::anyhow!("cannot create {}: {e}", dir.display()))?;
            Ok(dir)
        }
        None => Ok(locate::new_run_dir(
            Path::new("results"),
            "gate",
            &utc_now(),
        )?),
    }
}

/// The judged report written to `out/gate.json`; on an error, `out` removed if it is empty.
fn kept(judged: anyhow::Result<GateReport>, out: PathBuf) -> anyhow::Result<Outcome> {
    match judged {
        Ok(report) => {
            let json = super::formatted(&report, super::Format::Json);
            nbody_engine::output::write_atomic(&out.join("gate.json"), json.as_bytes())?;
            Ok(Outcome {
                report,
                kept_in: Some(out),
            })
        }
        Err(e) => {
            // A gate that failed before measuring leaves no empty run directory behind.
            let _ = std::fs::remove_dir(&out);
            Err(e)
        }
    }
}

/// `--out DIR`, refused when it holds an earlier gate's files (`None`: a new run directory).
fn checked_out_dir(request: &Request) -> anyhow::Result<Option<PathBuf>> {
    let Some(dir) = &request.out else {
        return Ok(None);
    };
    // What a gate keeps is never overwritten: each run needs its own directory.
    if let Some(kept) = ["gate.json", "base.json", "current.json", "results.json"]
        .iter()
        .map(|f| dir.join(f))
        .find(|f| f.exists())
    {
        anyhow::bail!(
            "--out {}: {} is there from an earlier gate run; name a new directory",
            dir.display(),
            kept.display()
        );
    }
    Ok(Some(dir.clone()))
}

/// The fast path compares the config's own samples: refused up front when they are too few
/// for a CI (an A/B run takes enough of its own).
fn fast_path_fits(config: &SweepConfig) -> anyhow::Result<()> {
    let min = super::MIN_CI_SAMPLES;
    if config.measure.samples < min {
        anyhow::bail!(
            "config `{}` takes {} samples per case, and the gate judges a case on at least {min} \
             per side (fewer cannot support a 95% CI); raise measure.samples",
            config.name,
            config.measure.samples
        );
    }
    Ok(())
}

/// A route with everything it needs checked.
enum Planned {
    Fast {
        path: PathBuf,
        baseline: Box<ResultsFile>,
    },
    AB(PreparedAB),
}

/// An A/B run checked and planned before anything is built.
struct PreparedAB {
    repo: PathBuf,
    rev: String,
    commit: String,
    cases: Vec<ab::OneCase>,
    /// Estimated seconds of one build's one round of each case, by case key.
    round_s: HashMap<String, f64>,
}

/// Checks everything an A/B run of `rev` needs that does not take the base build (the rounds,
/// the config's one-case forms, the revision's presence), estimates it and says how long it
/// will take.
fn prepare_a_b(
    request: &Request,
    rev: &str,
    config: &SweepConfig,
    text: &str,
    say: &mut dyn FnMut(&str),
) -> anyhow::Result<PreparedAB> {
    let cases = ab::prepare(config, text, request.rounds)?;
    if request.max_rounds < request.rounds {
        anyhow::bail!(
            "--max-rounds {} is below --rounds {}: the first look already takes --rounds \
             rounds; give --max-rounds at least that (equal judges once)",
            request.max_rounds,
            request.rounds
        );
    }
    let repo = base_build::repository_root(&std::env::current_dir()?)?;
    let commit = base_build::resolve(&repo, rev)?;
    // The estimate of the interleaved run: the config with the A/B run's rounds and samples.
    let mut measured = config.clone();
    measured.measure.rounds = request.rounds;
    measured.measure.samples = ab::samples_per_round(config, request.rounds) * request.rounds;
    let planned: Vec<Case> = cases.iter().map(|c| c.case.clone()).collect();
    let probed = estimate::probe(&measured, &planned)?;
    let logical = nbody_engine::run::logical_cpus();
    let est = estimate::estimate(&measured, &probed.cases, &Done::default(), false, logical);
    let round_s: HashMap<String, f64> = est
        .cases
        .iter()
        .map(|c| (c.case.key(), c.wall_s / request.rounds as f64))
        .collect();
    let build = if base_build::is_cached(&repo, &commit) {
        "the base binary is cached".to_string()
    } else {
        format!(
            "a release build of the base revision comes first (minutes; stopped after {})",
            crate::children::supervised::seconds(base_build::BUILD_LIMIT)
        )
    };
    let unestimated = cases.len().saturating_sub(est.cases.len());
    say(&format!(
        "A/B against {rev} ({}): {} cases x {} rounds x 2 builds, estimated {} of \
         measurement{}; {build}",
        short(&commit),
        cases.len(),
        request.rounds,
        WallTime(2.0 * est.total_s + estimate::calibration_s(1)),
        if unestimated > 0 {
            format!(" besides {unestimated} external program case(s)")
        } else {
            String::new()
        }
    ));
    Ok(PreparedAB {
        repo,
        rev: rev.to_string(),
        commit,
        cases,
        round_s,
    })
}

/// The baseline file comes from this machine class: sweep this build and compare. If the
/// sweep's own calibrations find the machine's speed too far from the baseline's, the sweep
/// is not judged against it: A/B instead.
fn fast_path(
    request: &Request,
    path: &Path,
    baseline: &ResultsFile,
    config: &SweepConfig,
    text: &str,
    out: &Path,
    say: &mut dyn FnMut(&str),
) -> anyhow::Result<GateReport> {
    let planned = nbody_records::plan::cases(config);
    let probed = estimate::probe(config, &planned)?;
    let logical = nbody_engine::run::logical_cpus();
    let est = estimate::estimate(config, &probed.cases, &Done::default(), true, logical);
    say(&format!(
        "sweeping {} with this build (estimated {}), to compare with {} (same machine class)",
        config.name,
        WallTime(est.total_s),
        path.display()
    ));
    let sweep = SweepOptions {
        run_dir: Some(out.to_path_buf()),
        calibrate: true,
        ..Default::default()
    };
    let mut quiet = crate::experiment::runner::Silent;
    let report = run_sweep_wall(config, text, &sweep, &mut quiet)?;
    let current = ResultsFile::load(&report.path)?;
    let rates = (
        super::calibrated_rate(baseline),
        super::calibrated_rate(&current),
    );
    if let (Some(b), Some(c)) = rates
        && let Some(why) = super::rates_differ(b, c)
    {
        let rev = baseline.metadata.git_commit.clone();
        say(&format!(
            "during the sweep, {why}; measuring the baseline's revision {} and this build side \
             by side (A/B) instead (the sweep stays in {})",
            short(&rev),
            out.display()
        ));
        let prepared = prepare_a_b(request, &rev, config, text, say)?;
        return a_b(request, &prepared, config, text, out, say);
    }
    let judged = compare(
        baseline,
        &current,
        &options(request, FILE_THRESHOLD, FILE_JUDGE),
    )?;
    say(&format!("results kept in {}", out.display()));
    Ok(judged)
}

/// Builds the prepared revision (or takes it from the cache), measures both builds
/// interleaved, and judges.
fn a_b(
    request: &Request,
    prepared: &PreparedAB,
    config: &SweepConfig,
    text: &str,
    out: &Path,
    say: &mut dyn FnMut(&str),
) -> anyhow::Result<GateReport> {
    let started = std::time::Instant::now();
    let (rev, commit) = (&prepared.rev, &prepared.commit);
    let base = base_build::base_binary(&prepared.repo, commit, say)?;
    if base.built {
        say(&format!("base built in {:.0} s", base.build_s));
    }
    let current: PathBuf = std::env::current_exe()
        .map_err(|e| anyhow::anyhow!("cannot find this program's binary: {e}"))?;
    say("calibrating the machine...");
    let calibration = nbody_calibrate::calibrate(&[1]);
    // Scratch of this process only: nothing else in `out` is removed.
    let work = out.join(format!(".scratch-{}", std::process::id()));
    let limit = |case: &Case| match request.timeout {
        Some(s) => Duration::from_secs_f64(s),
        None => ab::child_limit(
            config,
            case,
            request.rounds,
            prepared.round_s.get(&case.key()).copied(),
        ),
    };
    let (sides, why) = super::duet::choose(request.sides, calibration.background_cpus);
    say(&match (sides, why) {
        (_, Some(why)) => why,
        (super::duet::Sides::Duet, None) => {
            let alone = prepared
                .cases
                .iter()
                .filter(|c| !super::duet::suits(&c.case))
                .count();
            format!(
                "the builds measure each round at the same moment, one per CPU (duet){}",
                if alone > 0 {
                    format!(
                        "; {alone} case(s) of several threads or ranks, or of an external \
                         program, take turns"
                    )
                } else {
                    String::new()
                }
            )
        }
        (super::duet::Sides::Turns, None) => "the builds take turns in each round".to_string(),
    });
    let plan = AbPlan {
        config,
        config_text: text,
        cases: &prepared.cases,
        base: &base,
        current: &current,
        rounds: request.rounds,
        work: &work,
        limit: &limit,
        sides,
    };
    let judged = judge_in_looks(request, &plan, &calibration, say);
    let _ = std::fs::remove_dir_all(&work);
    let (mut report, results, reference) = judged?;
    report.sides = Some(sides);
    results.base.save(&out.join("base.json"))?;
    results.current.save(&out.join("current.json"))?;
    if let Some(moved) = reference {
        report.warnings.push(format!(
            "the reference workload itself takes {moved:.3}x as long in this build as in the \
             base, so the builds differ in more than their kernels; the cases are judged on raw \
             times (both builds measured interleaved)"
        ));
    }
    for (file, which) in [(&results.base, "base"), (&results.current, "current")] {
        if file.metadata.rustc_version != results.current.metadata.rustc_version {
            report.warnings.push(format!(
                "the {which} build was compiled by `{}`, this one by `{}`",
                file.metadata.rustc_version, results.current.metadata.rustc_version
            ));
        }
    }
    // Both builds share the one calibration, so the warning about a baseline measured under
    // more load than the current run does not apply; the load itself is still worth a word.
    report
        .warnings
        .retain(|w| !w.starts_with("the baseline was measured while other processes"));
    if let Some(busy) = calibration
        .background_cpus
        .filter(|&b| b >= super::BUSY_BASELINE_CPUS)
    {
        report.warnings.push(format!(
            "other processes used {busy:.1} CPUs while the gate calibrated; both builds were \
             measured under that load, interleaved"
        ));
    }
    say(&format!(
        "A/B against {} ({}): {} look(s), {} case-rounds per build, measured in {:.0} s, {:.0} s \
         in all; results kept in {}",
        rev,
        short(commit),
        report.cases.iter().map(|c| c.look).max().unwrap_or(1),
        results
            .current
            .cases
            .iter()
            .map(|c| c.rounds_done)
            .sum::<usize>(),
        results.measure_s,
        started.elapsed().as_secs_f64(),
        out.display()
    ));
    Ok(report)
}

/// Measures both builds in looks ([`super::sequential`]): every case to `request.rounds`
/// rounds, then only the undecided ones, `request.rounds` more at a time, up to
/// `request.max_rounds`. The last look's report (the cases decided earlier kept as then), both
/// builds' results, and how much longer this build's reference workload took when that stopped
/// the normalisation.
fn judge_in_looks(
    request: &Request,
    plan: &AbPlan<'_>,
    calibration: &nbody_calibrate::Calibration,
    say: &mut dyn FnMut(&str),
) -> anyhow::Result<(GateReport, ab::AbResults, Option<f64>)> {
    let schedule = super::sequential::schedule(request.rounds, request.max_rounds);
    let mut run = ab::AbRun::start(plan)?;
    let mut open: Vec<usize> = (0..plan.cases.len()).collect();
    let mut opts = options(request, AB_THRESHOLD, AB_JUDGE);
    opts.pairing = super::paired::Pairing::Rounds;
    let mut last = None;
    for (index, &until) in schedule.iter().enumerate() {
        run.extend(plan, &open, until, say)?;
        let mut results = run.results(plan);
        for file in [&mut results.base, &mut results.current] {
            file.calibration.start = Some(calibration.clone());
        }
        // Each build times its own copy of the reference workload. If that copy itself got
        // faster or slower (another compiler, profile or SIMD dispatch), dividing by it would
        // hide or invent a change of the kernels: then judge raw times, which interleaving
        // keeps fair.
        let moved = reference_moved(&results);
        let mut look = opts.clone();
        look.look = super::sequential::Look {
            index,
            count: schedule.len(),
        };
        if moved.is_some() && look.normalization == NormalizationChoice::Auto {
            look.normalization = NormalizationChoice::None;
        }
        let report = compare(&results.base, &results.current, &look)?;
        open = plan
            .cases
            .iter()
            .enumerate()
            .filter(|(_, c)| {
                let key = c.case.key();
                report
                    .cases
                    .iter()
                    .any(|r| r.key == key && super::sequential::still_open(r))
            })
            .map(|(i, _)| i)
            .collect();
        opts.closed = report
            .cases
            .iter()
            .filter(|c| !super::sequential::still_open(c))
            .cloned()
            .collect();
        let done = open.is_empty() || index + 1 == schedule.len();
        if !done {
            say(&format!(
                "look {}/{}: {} case(s) decided, {} undecided: measuring those to {} rounds",
                index + 1,
                schedule.len(),
                report.cases.len() - open.len(),
                open.len(),
                schedule[index + 1]
            ));
        }
        last = Some((report, results, moved));
        if done {
            break;
        }
    }
    last.ok_or_else(|| anyhow::anyhow!("the A/B run planned no look"))
}

/// This build's reference workload time over the base's (medians over all samples), when it
/// differs by more than [`REFERENCE_TOLERANCE`].
fn reference_moved(results: &ab::AbResults) -> Option<f64> {
    let (b, c) = (
        ab::median_reference(&results.base)?,
        ab::median_reference(&results.current)?,
    );
    (b > 0.0 && ((c / b) - 1.0).abs() > REFERENCE_TOLERANCE).then_some(c / b)
}
