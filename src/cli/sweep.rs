use crate::cli::args::SweepArgs;
use nbody_engine::output::provenance::utc_now;
use nbody_harness::experiment::progress;
use nbody_harness::experiment::runner::{self, SweepOptions, SweepReport, run_sweep_wall};
use nbody_harness::render::sweep_tables;
use nbody_records::config::SweepConfig;
use nbody_records::locate;
use nbody_records::results::ResultsFile;
use std::path::{Path, PathBuf};

pub fn sweep(args: SweepArgs) -> anyhow::Result<i32> {
    if let Some(Some(run)) = &args.resume
        && nbody_engine::input::is_pipe(run)
    {
        anyhow::bail!(
            "--resume {}: is a pipe; a resumed run is written back in place: pass its run \
             directory",
            run.display()
        );
    }
    let config_path = locate::find_config(&args.config)?;
    let (config, text) = SweepConfig::load(&config_path)?;
    // A config read from a pipe has no directory: its {config_dir} is the current one.
    let from_pipe = nbody_engine::input::is_pipe(&config_path);
    let config_dir = config_path
        .parent()
        .filter(|p| !p.as_os_str().is_empty() && !from_pipe)
        .map(Path::to_path_buf);
    let target = where_to_write(&args, &config)?;
    if let Some(history) = &args.record {
        super::history::check_record_dir("--record", history)?;
    }
    if let Some(code) = dry_run(&args, &config, &target, &config_dir)? {
        return Ok(code);
    }
    let options = options(&args, &config, target, config_dir)?;
    let mut observer = progress::for_stderr();
    let report = run_sweep_wall(&config, &text, &options, observer.as_mut()).inspect_err(|_| {
        // A new run directory that never received results is not a run: leave nothing.
        if let Some(dir) = &options.run_dir
            && !options.resume
        {
            let _ = std::fs::remove_dir(dir);
        }
    })?;
    let results = ResultsFile::load(&report.path)?;
    outln!("{}", sweep_tables::cases(&results).text().trim_end());
    let speedups = sweep_tables::speedups(&results);
    if !speedups.is_empty() {
        outln!(
            "\n{}",
            sweep_tables::speedups_table(&speedups).text().trim_end()
        );
    }
    outln!(
        "\n{} cases, {} rounds measured in this run; results in {}",
        report.cases,
        report.rounds_measured,
        report.path.display()
    );
    analyze_and_record(&args, &results, &report.path)?;
    Ok(report_failures(&args, &results, &report))
}

/// The checks a dry run makes before printing the plan (what the sweep checks before its
/// first case: a program that cannot start, an `initial` file that cannot be read or lacks an
/// n; and each external program run once at its smallest case), and the plan itself;
/// `Some(exit code)` when the command ends there.
fn dry_run(
    args: &SweepArgs,
    config: &SweepConfig,
    target: &Target,
    config_dir: &Option<PathBuf>,
) -> anyhow::Result<Option<i32>> {
    let existing = match target {
        Target::Out => Some(runner::results_path(config, args.out.as_deref())),
        Target::Existing(dir) => Some(dir.join("results.json")),
        Target::New => None,
    };
    let trials = if args.dry_run {
        let options = SweepOptions {
            out: args.out.clone(),
            config_dir: config_dir.clone(),
            ..Default::default()
        };
        runner::try_before_running(config, &options)?
    } else {
        Vec::new()
    };
    super::dry_run::before_sweep(args, config, existing.as_deref(), &trials)
}

/// The runner's options: where the results go (a new run directory is claimed here) and
/// what the arguments ask for.
fn options(
    args: &SweepArgs,
    config: &SweepConfig,
    target: Target,
    config_dir: Option<PathBuf>,
) -> anyhow::Result<SweepOptions> {
    let (resume, run_dir) = match target {
        Target::Out => (args.resume.is_some(), None),
        Target::Existing(dir) => {
            eprintln!("resuming {}", dir.display());
            (true, Some(dir))
        }
        Target::New => {
            let dir = locate::new_run_dir(&config.out, &config.name, &utc_now())?;
            (false, Some(dir))
        }
    };
    Ok(SweepOptions {
        resume,
        force: args.force,
        fresh: args.fresh,
        out: args.out.clone(),
        run_dir,
        calibrate: !args.no_calibration,
        config_dir,
        nbody_bench: None,
    })
}

/// The analysis beside the results, and with `--record` the history's new records.
fn analyze_and_record(args: &SweepArgs, results: &ResultsFile, path: &Path) -> anyhow::Result<()> {
    // The analysis is a convenience on top of the measurements: if it fails, the results
    // are already saved and `analyze` can be run again.
    let dir = super::analyze::default_dir(path);
    match super::analyze::run(results, path, &dir) {
        Ok(written) => super::analyze::print_written(&written),
        // Nothing to analyse yet: the failed and unfinished cases are reported next, with
        // the command that finishes this run when one would.
        Err(e)
            if e.downcast_ref::<nbody_harness::analysis::AnalysisError>()
                .is_some() => {}
        Err(e) => eprintln!(
            "warning: analysis failed ({}); the results are saved, retry with `nbody-bench analyze {}`",
            super::error_chain(&e),
            super::hint::arg(path)
        ),
    }
    if let Some(history) = &args.record {
        let appended = super::history::append_results(history, results, "sweep");
        let appended = anyhow::Context::with_context(appended, || {
            format!(
                "the results are saved in {}; record them with `nbody-bench history record {}`",
                path.display(),
                super::hint::arg(path)
            )
        })?;
        for (to, count) in appended {
            eprintln!("{count} records appended to {}", to.display());
        }
    }
    Ok(())
}

/// The failed and unfinished cases, said with what to do; the exit status.
fn report_failures(args: &SweepArgs, results: &ResultsFile, report: &SweepReport) -> i32 {
    let failed: Vec<_> = results.cases.iter().filter(|c| c.failed()).collect();
    for c in &failed {
        let reasons = c.failures();
        eprintln!(
            "error: case {}: no sample succeeded{}",
            c.key,
            reasons
                .first()
                .map(|r| format!(" ({r}{})", more(reasons.len())))
                .unwrap_or_default()
        );
    }
    if report.incomplete > 0 {
        outln!(
            "{} cases are not complete; run `{}` to finish them",
            report.incomplete,
            resume_command(args, &report.path)
        );
    }
    if failed.is_empty() {
        return 0;
    }
    eprintln!(
        "{} of {} cases failed; every failure is kept in {}",
        failed.len(),
        results.cases.len(),
        report.path.display()
    );
    FAILED_CASES
}

/// The command that resumes the run whose results are `results`, pasted as printed: the
/// config as the user gave it, and the run itself (not "the latest unfinished one", which a
/// newer run could change).
fn resume_command(args: &SweepArgs, results: &Path) -> String {
    let run = match &args.out {
        Some(out) => format!("--out {} --resume", super::hint::arg(out)),
        None => format!(
            "--resume {}",
            super::hint::arg(results.parent().unwrap_or(Path::new(".")))
        ),
    };
    format!(
        "nbody-bench sweep --config {} {run}",
        super::hint::arg(&args.config)
    )
}

/// The exit status of a sweep with a case whose every sample failed.
pub const FAILED_CASES: i32 = 1;

fn more(count: usize) -> String {
    match count {
        0 | 1 => String::new(),
        n => format!("; and {} more", n - 1),
    }
}

/// Where a sweep writes.
enum Target {
    /// `<out>/<name>/results.json`, with --out (resuming it with --resume).
    Out,
    /// The run directory to resume.
    Existing(PathBuf),
    /// A new run directory `<out>/runs/<name>/<UTC time>/`, claimed when the sweep starts.
    New,
}

/// Where to write, without touching anything yet.
///
/// Without --out every sweep gets a new run directory, so the same command can be typed again
/// and never touches the committed reference results; `--resume` continues the latest
/// unfinished run of the config, `--resume RUN` the one given.
fn where_to_write(args: &SweepArgs, config: &SweepConfig) -> anyhow::Result<Target> {
    let root = &config.out;
    match (&args.resume, &args.out) {
        (Some(Some(_)), Some(_)) => anyhow::bail!(
            "--resume RUN names the run itself; drop --out, or pass --resume without a value to \
             resume DIR/{}/",
            config.name
        ),
        (_, Some(_)) => Ok(Target::Out),
        (Some(Some(run)), None) => {
            let dir = if run.is_dir() {
                run.clone()
            } else if run.file_name().is_some_and(|n| n == "results.json") {
                run.parent().unwrap_or(Path::new(".")).to_path_buf()
            } else {
                // A run is a directory whose results are `results.json`; resuming another
                // file would write that one instead.
                anyhow::bail!(
                    "--resume {}: not a run directory or its results.json; a sweep resumes \
                     DIR/results.json only: pass the run directory",
                    run.display()
                );
            };
            if !dir.join("results.json").is_file() {
                anyhow::bail!(
                    "--resume {}: no results.json there; pass a run directory such as {}/<UTC time>",
                    run.display(),
                    locate::runs_dir(root, &config.name).display()
                );
            }
            Ok(Target::Existing(dir))
        }
        (Some(None), None) => match locate::latest_unfinished(root, &config.name) {
            Ok(dir) => Ok(Target::Existing(dir)),
            Err(e @ locate::LocateError::NothingToResume { .. }) => anyhow::bail!(
                "{e}; a new run: `nbody-bench sweep --config {}`",
                super::hint::arg(&args.config)
            ),
            Err(e) => Err(e.into()),
        },
        (None, None) => {
            if let Ok(dir) = locate::latest_unfinished(root, &config.name) {
                eprintln!(
                    "note: {} is an unfinished run of this config; `--resume` continues it",
                    dir.display()
                );
            }
            Ok(Target::New)
        }
    }
}
