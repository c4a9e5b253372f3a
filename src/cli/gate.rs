//! `gate`: compare two results files, or measure this build and judge it (against the
//! baseline file on its machine class, else A/B against the baseline's revision).

use crate::cli::args::GateArgs;
use nbody_bench::experiment::config::SweepConfig;
use nbody_bench::experiment::locate;
use nbody_bench::experiment::results::{ResultsFile, utc_now};
use nbody_bench::experiment::runner::{SweepOptions, run_sweep_wall};
use nbody_bench::gate::ab::{self, AbPlan};
use nbody_bench::gate::baselines;
use nbody_bench::gate::{
    AB_THRESHOLD, FILE_THRESHOLD, GateOptions, GateReport, RunInfo, base_build, compare, render,
};
use std::path::{Path, PathBuf};

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
        let keys: Vec<&str> = report.missing.iter().map(|m| m.key.as_str()).collect();
        eprintln!(
            "error: {} baseline case(s) could not be compared: {}; run the baseline's config to \
             completion (sweep --resume), or refresh the baseline if the cases were removed on \
             purpose",
            keys.len(),
            keys.join(", ")
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
        test_slowdown: None,
    }
}

/// A folder of per-machine-class baselines (`results/baseline/`), not one results file or a
/// run directory.
fn is_baseline_folder(path: &Path) -> bool {
    path.is_dir() && !path.join("results.json").is_file()
}

/// `--save-baseline RESULTS`: keeps RESULTS in the baseline folder under its machine class's
/// name, replacing that class's earlier file, once it compares cleanly with itself (schema,
/// calibration, config) and was measured on a quiet machine; the other classes' files stay.
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
    let out = match &args.out {
        Some(dir) => {
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
            std::fs::create_dir_all(dir)
                .map_err(|e| anyhow::anyhow!("cannot create {}: {e}", dir.display()))?;
            dir.clone()
        }
        None => locate::new_run_dir(Path::new("results"), "gate", &utc_now())?,
    };
    let baseline = baseline.as_ref().map(|(path, file)| (path.as_path(), file));
    let judged = judge(args, baseline, &config, &config_text, &out);
    if judged.is_err() {
        // A gate that failed before measuring leaves no empty run directory behind.
        let _ = std::fs::remove_dir(&out);
    }
    judged
}

/// Chooses the fast path or A/B, and runs it.
fn judge(
    args: &GateArgs,
    baseline: Option<(&Path, &ResultsFile)>,
    config: &SweepConfig,
    config_text: &str,
    out: &Path,
) -> anyhow::Result<i32> {
    let against = match (&args.against, baseline) {
        (Some(rev), _) => rev.clone(),
        (None, Some((path, b))) => match RunInfo::of(b).machine_class_differs(&this_machine()) {
            None => return fast_path(args, path, b, config, config_text, out),
            Some(why) => {
                eprintln!(
                    "gate: the baseline {} comes from another machine class ({why}); measuring \
                     its revision {} and this build side by side here (A/B); \
                     `gate --save-baseline` on this machine's own sweep gives it the fast path",
                    path.display(),
                    short(&b.metadata.git_commit)
                );
                b.metadata.git_commit.clone()
            }
        },
        (None, None) => anyhow::bail!(
            "no baseline to judge against: {} is missing; pass --baseline FILE or --against REV",
            args.baseline.display()
        ),
    };
    a_b(args, &against, config, config_text, out)
}

/// The baseline file comes from this machine class: sweep this build and compare.
fn fast_path(
    args: &GateArgs,
    path: &Path,
    baseline: &ResultsFile,
    config: &SweepConfig,
    text: &str,
    out: &Path,
) -> anyhow::Result<i32> {
    eprintln!(
        "gate: sweeping {} with this build, to compare with {} (same machine class)",
        config.name,
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
    let judged = compare(baseline, &current, &options(args, FILE_THRESHOLD))?;
    eprintln!("gate: results kept in {}", out.display());
    finish(&judged, args, Some(out))
}

/// Builds `rev` (or takes it from the cache), measures both builds interleaved, and judges.
fn a_b(
    args: &GateArgs,
    rev: &str,
    config: &SweepConfig,
    text: &str,
    out: &Path,
) -> anyhow::Result<i32> {
    let started = std::time::Instant::now();
    let repo = base_build::repository_root(&std::env::current_dir()?)?;
    let commit = base_build::resolve(&repo, rev)?;
    let mut say = |line: &str| eprintln!("gate: {line}");
    let base = base_build::base_binary(&repo, &commit, &mut say)?;
    if base.built {
        say(&format!("base built in {:.0} s", base.build_s));
    }
    let current: PathBuf = std::env::current_exe()
        .map_err(|e| anyhow::anyhow!("cannot find this program's binary: {e}"))?;
    say("calibrating the machine...");
    let calibration = nbody_bench::calibrate::calibrate(&[1]);
    // Scratch of this process only: nothing else in `out` is removed.
    let work = out.join(format!(".scratch-{}", std::process::id()));
    let plan = AbPlan {
        config,
        config_text: text,
        base: &base,
        current: &current,
        rounds: args.rounds,
        work: &work,
    };
    let mut results = ab::measure(&plan, &mut say)?;
    let _ = std::fs::remove_dir_all(&work);
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
        short(&commit),
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
