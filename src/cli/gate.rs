//! `gate`: compare two results files, or measure this build and judge it (against the
//! baseline file on its machine class, else A/B against the baseline's revision).

use crate::cli::args::GateArgs;
use nbody_bench::experiment::estimate::{self, Done};
use nbody_bench::experiment::runner::{SweepOptions, run_sweep_wall};
use nbody_bench::gate::ab::{self, AbPlan};
use nbody_bench::gate::baselines;
use nbody_bench::gate::{
    AB_THRESHOLD, FILE_THRESHOLD, GateOptions, GateReport, RunInfo, base_build, compare, render,
};
use nbody_bench::records::config::SweepConfig;
use nbody_bench::records::locate;
use nbody_bench::records::plan::Case;
use nbody_bench::records::results::{ResultsFile, utc_now};
use nbody_bench::units::WallTime;
use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::time::Duration;

/// How far the two builds' reference workload may differ (median over all samples) before the
/// A/B gate stops normalising by it. In 20 A/B runs of `configs/ci.toml` on the 2-vCPU AMD EPYC
/// of 2026-12-01 (same reference code on both sides) the ratio stayed within 0.998-1.005.
const REFERENCE_TOLERANCE: f64 = 0.05;

pub fn gate(args: GateArgs) -> anyhow::Result<i32> {
    match &args.current {
        Some(current) => {
            let root = Path::new("results");
            let current = ResultsFile::load(&locate::find_results(current, root)?)?;
            let baseline = if is_baseline_folder(&args.baseline) {
                baselines::choose(&args.baseline, &RunInfo::of(&current))?.file
            } else {
                ResultsFile::load(&locate::find_results(&args.baseline, root)?)?
            };
            let report = compare(&baseline, &current, &options(&args, 0.10))?;
            Ok(finish(&report, &args, None)?)
        }
        None => measure_and_judge(&args),
    }
}

fn options(args: &GateArgs, default_threshold: f64) -> GateOptions {
    GateOptions {
        threshold: args.threshold.unwrap_or(default_threshold),
        force: args.force,
        normalization: args.normalize,
        fail_on_work_change: args.fail_on_work_change,
        ..GateOptions::default()
    }
}

/// Prints the report (and keeps it as `gate.json` in `dir`); the exit code.
fn finish(report: &GateReport, args: &GateArgs, dir: Option<&Path>) -> anyhow::Result<i32> {
    out!("{}", render(report, args.format));
    if let Some(dir) = dir {
        let json = render(report, nbody_bench::gate::Format::Json);
        nbody_bench::output::write_atomic(&dir.join("gate.json"), json.as_bytes())?;
    }
    if !report.missing.is_empty() {
        let why: Vec<String> = report
            .missing
            .iter()
            .map(|m| format!("{} ({})", m.key, m.reason))
            .collect();
        eprintln!(
            "error: {} baseline case(s) could not be compared, which is not a pass: {}; run \
             the baseline's config to completion (sweep --resume), or refresh the baseline if \
             the cases were removed on purpose",
            why.len(),
            listed(&why)
        );
    }
    if report.cases.is_empty() {
        anyhow::bail!("the gate compared no case: nothing was judged, which is not a pass");
    }
    Ok(report.exit_code())
}

/// The machine this process runs on, as a gate sees a results file's.
fn this_machine() -> RunInfo {
    RunInfo {
        git_commit: String::new(),
        git_dirty: false,
        started: String::new(),
        host: String::new(),
        cpu_model: Some(nbody_bench::calibrate::cpu_model()),
        cpu_signature: nbody_bench::calibrate::cpu_signature(),
        logical_cpus: Some(nbody_bench::run::logical_cpus()),
    }
}

/// A folder of per-machine-class baselines (`results/baseline/`), not one results file or a
/// run directory.
fn is_baseline_folder(path: &Path) -> bool {
    path.is_dir() && !path.join("results.json").is_file()
}

/// Why a results file cannot be a baseline: every check the gate makes against it must be
/// able to compare something, so a file with no case, a case with no measured round, an
/// unfinished case, or fewer successful samples than a CI needs is refused.
fn unfit_as_baseline(file: &ResultsFile) -> Option<String> {
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

/// The first few of `items`, "; "-separated, with how many more there are.
fn listed(items: &[String]) -> String {
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

/// `--save-baseline RESULTS`: keeps RESULTS in the baseline folder under its machine class's
/// name, replacing that class's earlier file, once it compares cleanly with itself (schema,
/// calibration, config, every case judgeable) and was measured on a quiet machine; the other
/// classes' files stay. Every refusal leaves the folder as it was.
fn save_baseline(folder: &Path, results: &Path) -> anyhow::Result<i32> {
    let source = locate::find_results(results, Path::new("results"))?;
    if nbody_bench::input::is_pipe(&source) {
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
    let busy = nbody_bench::gate::background_cpus(&file)
        .filter(|&b| b >= nbody_bench::gate::BUSY_BASELINE_CPUS);
    if let Some(busy) = busy {
        // The reference workload slows down more than the kernels under load: every later
        // run on a quiet machine would read as a regression.
        anyhow::bail!(
            "{} was measured while other processes used {busy:.2} CPUs (at most {} for a \
             baseline): every later run would be judged against a slowed reference; wait for \
             the other work to end and run scripts/refresh-baseline.sh again",
            source.display(),
            nbody_bench::gate::BUSY_BASELINE_CPUS
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
    if folder.is_file() {
        anyhow::bail!(
            "--baseline {} is a file; --save-baseline needs the folder of baselines \
             (results/baseline)",
            folder.display()
        );
    }
    std::fs::create_dir_all(folder)
        .map_err(|e| anyhow::anyhow!("cannot create {}: {e}", folder.display()))?;
    let info = RunInfo::of(&file);
    let target = folder.join(baselines::file_name(&info));
    let text = nbody_bench::input::read_text(&source)
        .map_err(|e| anyhow::anyhow!("cannot read {}: {e}", source.display()))?;
    nbody_bench::output::write_atomic(&target, text.as_bytes())?;
    eprintln!(
        "gate: {} kept as the baseline of {} ({} logical CPUs): {}",
        source.display(),
        info.cpu_signature.as_deref().unwrap_or("an unknown CPU"),
        info.logical_cpus.map_or("?".into(), |n| n.to_string()),
        target.display()
    );
    Ok(0)
}

/// How a measuring gate judges this build.
enum Route {
    /// Sweep the config with this build and compare with the baseline file (same class).
    Fast,
    /// Measure revision `rev` and this build side by side.
    AB { rev: String },
}

fn measure_and_judge(args: &GateArgs) -> anyhow::Result<i32> {
    if let Some(results) = &args.save_baseline {
        return save_baseline(&args.baseline, results);
    }
    let baseline = if is_baseline_folder(&args.baseline) {
        let chosen = baselines::choose(&args.baseline, &this_machine())?;
        Some((chosen.path, chosen.file))
    } else if nbody_bench::input::is_readable(&args.baseline) || args.against.is_none() {
        Some((args.baseline.clone(), ResultsFile::load(&args.baseline)?))
    } else {
        None
    };
    let (config_path, config_text) = match (&args.config, &baseline) {
        (Some(name), _) => {
            let path = locate::find_config(name)?;
            let text = nbody_bench::input::read_text(&path)
                .map_err(|e| anyhow::anyhow!("cannot read config {}: {e}", path.display()))?;
            (path, text)
        }
        (None, Some((path, b))) => (path.clone(), b.config_text.clone()),
        (None, None) => {
            let path = locate::find_config(Path::new("ci"))?;
            let text = nbody_bench::input::read_text(&path)
                .map_err(|e| anyhow::anyhow!("cannot read config {}: {e}", path.display()))?;
            (path, text)
        }
    };
    let config = SweepConfig::parse(&config_text, &config_path)?;
    let out = checked_out_dir(args)?;
    let baseline = baseline.as_ref().map(|(path, file)| (path.as_path(), file));
    // Every refusal comes before anything long: the route, and what it needs, is checked
    // before a sweep or a build starts.
    let route = route(args, baseline)?;
    let prepared = match &route {
        Route::Fast => {
            fast_path_fits(&config)?;
            None
        }
        Route::AB { rev } => Some(prepare_a_b(args, rev, &config, &config_text)?),
    };
    let out = match out {
        Some(dir) => {
            std::fs::create_dir_all(&dir)
                .map_err(|e| anyhow::anyhow!("cannot create {}: {e}", dir.display()))?;
            dir
        }
        None => locate::new_run_dir(Path::new("results"), "gate", &utc_now())?,
    };
    let judged = match (prepared, baseline) {
        (Some(prepared), _) => a_b(args, &prepared, &config, &config_text, &out),
        (None, Some((path, file))) => fast_path(args, path, file, &config, &config_text, &out),
        (None, None) => Err(anyhow::anyhow!("no baseline to judge against")),
    };
    if judged.is_err() {
        // A gate that failed before measuring leaves no empty run directory behind.
        let _ = std::fs::remove_dir(&out);
    }
    judged
}

/// `--out DIR`, refused when it holds an earlier gate's files (`None`: a new run directory).
fn checked_out_dir(args: &GateArgs) -> anyhow::Result<Option<PathBuf>> {
    let Some(dir) = &args.out else {
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

/// Fast path or A/B. A baseline of this machine class gets the fast path, unless the
/// machine's calibrated FMA rate now is too far from the baseline's for the reference
/// normalisation ([`nbody_bench::gate::RATE_TOLERANCE`]): then A/B against its commit.
fn route(args: &GateArgs, baseline: Option<(&Path, &ResultsFile)>) -> anyhow::Result<Route> {
    let (path, b) = match (&args.against, baseline) {
        (Some(rev), _) => return Ok(Route::AB { rev: rev.clone() }),
        (None, Some(found)) => found,
        (None, None) => anyhow::bail!(
            "no baseline to judge against: {} is missing; pass --baseline FILE or --against REV",
            args.baseline.display()
        ),
    };
    let commit = b.metadata.git_commit.clone();
    if let Some(why) = RunInfo::of(b).machine_class_differs(&this_machine()) {
        eprintln!(
            "gate: the baseline {} comes from another machine class ({why}); measuring \
             its revision {} and this build side by side here (A/B); \
             `gate --save-baseline` on this machine's own sweep gives it the fast path",
            path.display(),
            short(&commit)
        );
        return Ok(Route::AB { rev: commit });
    }
    let Some(rate) = nbody_bench::gate::calibrated_rate(b) else {
        return Ok(Route::Fast);
    };
    let here = nbody_bench::calibrate::calibrate(&[1]).fma_gflops_1t;
    match nbody_bench::gate::rates_differ(rate, here) {
        Some(why) => {
            eprintln!(
                "gate: {why}; measuring the baseline's revision {} and this build side by \
                 side here (A/B) instead of comparing with {}",
                short(&commit),
                path.display()
            );
            Ok(Route::AB { rev: commit })
        }
        None => {
            eprintln!(
                "gate: calibrated FMA rate {here:.1} GFLOP/s, the baseline's {rate:.1} \
                 ({:.2}x, within {:.0}%)",
                here / rate,
                nbody_bench::gate::RATE_TOLERANCE * 100.0
            );
            Ok(Route::Fast)
        }
    }
}

/// The fast path compares the config's own samples: refused up front when they are too few
/// for a CI (an A/B run takes enough of its own).
fn fast_path_fits(config: &SweepConfig) -> anyhow::Result<()> {
    let min = nbody_bench::gate::MIN_CI_SAMPLES;
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
    args: &GateArgs,
    rev: &str,
    config: &SweepConfig,
    text: &str,
) -> anyhow::Result<PreparedAB> {
    let cases = ab::prepare(config, text, args.rounds)?;
    let repo = base_build::repository_root(&std::env::current_dir()?)?;
    let commit = base_build::resolve(&repo, rev)?;
    // The estimate of the interleaved run: the config with the A/B run's rounds and samples.
    let mut measured = config.clone();
    measured.measure.rounds = args.rounds;
    measured.measure.samples = ab::samples_per_round(config, args.rounds) * args.rounds;
    let planned: Vec<Case> = cases.iter().map(|c| c.case.clone()).collect();
    let probed = estimate::probe(&measured, &planned)?;
    let logical = nbody_bench::run::logical_cpus();
    let est = estimate::estimate(&measured, &probed.cases, &Done::default(), false, logical);
    let round_s: HashMap<String, f64> = est
        .cases
        .iter()
        .map(|c| (c.case.key(), c.wall_s / args.rounds as f64))
        .collect();
    let build = if base_build::is_cached(&repo, &commit) {
        "the base binary is cached".to_string()
    } else {
        format!(
            "a release build of the base revision comes first (minutes; stopped after {})",
            nbody_bench::children::supervised::seconds(base_build::BUILD_LIMIT)
        )
    };
    let unestimated = cases.len().saturating_sub(est.cases.len());
    eprintln!(
        "gate: A/B against {rev} ({}): {} cases x {} rounds x 2 builds, estimated {} of \
         measurement{}; {build}",
        short(&commit),
        cases.len(),
        args.rounds,
        WallTime(2.0 * est.total_s + estimate::calibration_s(1)),
        if unestimated > 0 {
            format!(" besides {unestimated} external program case(s)")
        } else {
            String::new()
        }
    );
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
    args: &GateArgs,
    path: &Path,
    baseline: &ResultsFile,
    config: &SweepConfig,
    text: &str,
    out: &Path,
) -> anyhow::Result<i32> {
    let planned = nbody_bench::records::plan::cases(config);
    let probed = estimate::probe(config, &planned)?;
    let logical = nbody_bench::run::logical_cpus();
    let est = estimate::estimate(config, &probed.cases, &Done::default(), true, logical);
    eprintln!(
        "gate: sweeping {} with this build (estimated {}), to compare with {} (same machine \
         class)",
        config.name,
        WallTime(est.total_s),
        path.display()
    );
    let sweep = SweepOptions {
        run_dir: Some(out.to_path_buf()),
        calibrate: true,
        ..Default::default()
    };
    let mut quiet = nbody_bench::experiment::runner::Silent;
    let report = run_sweep_wall(config, text, &sweep, &mut quiet)?;
    let current = ResultsFile::load(&report.path)?;
    let rates = (
        nbody_bench::gate::calibrated_rate(baseline),
        nbody_bench::gate::calibrated_rate(&current),
    );
    if let (Some(b), Some(c)) = rates
        && let Some(why) = nbody_bench::gate::rates_differ(b, c)
    {
        let rev = baseline.metadata.git_commit.clone();
        eprintln!(
            "gate: during the sweep, {why}; measuring the baseline's revision {} and this \
             build side by side (A/B) instead (the sweep stays in {})",
            short(&rev),
            out.display()
        );
        let prepared = prepare_a_b(args, &rev, config, text)?;
        return a_b(args, &prepared, config, text, out);
    }
    let judged = compare(baseline, &current, &options(args, FILE_THRESHOLD))?;
    eprintln!("gate: results kept in {}", out.display());
    finish(&judged, args, Some(out))
}

/// Builds the prepared revision (or takes it from the cache), measures both builds
/// interleaved, and judges.
fn a_b(
    args: &GateArgs,
    prepared: &PreparedAB,
    config: &SweepConfig,
    text: &str,
    out: &Path,
) -> anyhow::Result<i32> {
    let started = std::time::Instant::now();
    let (rev, commit) = (&prepared.rev, &prepared.commit);
    let mut say = |line: &str| eprintln!("gate: {line}");
    let base = base_build::base_binary(&prepared.repo, commit, &mut say)?;
    if base.built {
        say(&format!("base built in {:.0} s", base.build_s));
    }
    let current: PathBuf = std::env::current_exe()
        .map_err(|e| anyhow::anyhow!("cannot find this program's binary: {e}"))?;
    say("calibrating the machine...");
    let calibration = nbody_bench::calibrate::calibrate(&[1]);
    // Scratch of this process only: nothing else in `out` is removed.
    let work = out.join(format!(".scratch-{}", std::process::id()));
    let limit = |case: &Case| match args.timeout {
        Some(s) => Duration::from_secs_f64(s),
        None => ab::child_limit(
            config,
            case,
            args.rounds,
            prepared.round_s.get(&case.key()).copied(),
        ),
    };
    let plan = AbPlan {
        config,
        config_text: text,
        cases: &prepared.cases,
        base: &base,
        current: &current,
        rounds: args.rounds,
        work: &work,
        limit: &limit,
    };
    let measured = ab::measure(&plan, &mut say);
    let _ = std::fs::remove_dir_all(&work);
    let mut results = measured?;
    for file in [&mut results.base, &mut results.current] {
        file.calibration.start = Some(calibration.clone());
    }
    results.base.save(&out.join("base.json"))?;
    results.current.save(&out.join("current.json"))?;
    let mut opts = options(args, AB_THRESHOLD);
    // Each build times its own copy of the reference workload. If that copy itself got faster
    // or slower (another compiler, profile or SIMD dispatch), dividing by it would hide or
    // invent a change of the kernels: then judge raw times, which interleaving keeps fair.
    let (rb, rc) = (
        ab::median_reference(&results.base),
        ab::median_reference(&results.current),
    );
    let reference_moved = match (rb, rc) {
        (Some(b), Some(c)) if b > 0.0 => ((c / b) - 1.0).abs() > REFERENCE_TOLERANCE,
        _ => false,
    };
    if reference_moved && opts.normalization == nbody_bench::gate::NormalizationChoice::Auto {
        opts.normalization = nbody_bench::gate::NormalizationChoice::None;
    }
    let mut report = compare(&results.base, &results.current, &opts)?;
    if reference_moved {
        report.warnings.push(format!(
            "the reference workload itself takes {:.3}x as long in this build as in the base, \
             so the builds differ in more than their kernels; the cases are judged on raw \
             times (both builds measured interleaved)",
            rc.unwrap_or(0.0) / rb.unwrap_or(1.0)
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
    if let Some(busy) = calibration.background_cpus.filter(|&b| b >= 0.25) {
        report.warnings.push(format!(
            "other processes used {busy:.1} CPUs while the gate calibrated; both builds were \
             measured under that load, interleaved"
        ));
    }
    say(&format!(
        "A/B against {} ({}): {} rounds per build, measured in {:.0} s, {:.0} s in all; \
         results kept in {}",
        rev,
        short(commit),
        args.rounds,
        results.measure_s,
        started.elapsed().as_secs_f64(),
        out.display()
    ));
    finish(&report, args, Some(out))
}

fn short(commit: &str) -> &str {
    nbody_bench::gate::prefix(commit, 12)
}
