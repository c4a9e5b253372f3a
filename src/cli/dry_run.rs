//! What `sweep` does before it measures anything: `--dry-run` prints the planned cases and the
//! estimated wall time and stops, and a real sweep estimated at more than an hour without a
//! time budget asks first (or, without a terminal, refuses unless `--yes` is given). Nothing
//! here keeps a file or a directory (the dry run tries each external program once, in a
//! temporary directory it removes).

use crate::cli::args::SweepArgs;
use nbody_harness::experiment::estimate::{self, Done, Estimate, PROBE_MAX_N, Probed};
use nbody_harness::experiment::external::trial::Trial;
use nbody_harness::render::sweep_tables;
use nbody_harness::units::WallTime;
use nbody_records::config::SweepConfig;
use nbody_records::results::ResultsFile;
use std::io::{BufRead, IsTerminal, Write};
use std::path::Path;

/// A sweep estimated above this many seconds (an hour) needs `--yes` or a `measure.budget_s`.
pub const LONG_SWEEP_S: f64 = 3600.0;

/// Runs the dry run or the guard. `path` is the results file the sweep would continue or
/// overwrite (`None`: a new run directory). `Some(code)`: stop with this exit code; `None`: go
/// on and measure.
pub fn before_sweep(
    args: &SweepArgs,
    config: &SweepConfig,
    path: Option<&Path>,
    trials: &[Trial],
) -> anyhow::Result<Option<i32>> {
    if args.yes && !args.dry_run {
        // Nothing to ask, so nothing to estimate.
        return Ok(None);
    }
    let exists = path.is_some_and(Path::exists);
    let refused = (exists && args.resume.is_none() && !args.fresh)
        || (config.mpi.is_some() && !config.kernels.is_empty() && !cfg!(feature = "mpi"));
    if !args.dry_run && refused {
        // The runner refuses this sweep with its own message; no need to estimate it.
        return Ok(None);
    }
    // With --resume, only the rounds the file does not hold yet are left to run.
    // A file the real resume would refuse is refused here too, dry run or not.
    let done = match (args.resume.is_some(), path) {
        (true, Some(path)) if path.exists() => done_in(ResultsFile::load(path)?),
        _ => Done::default(),
    };
    let planned = nbody_records::plan::unique_cases(config).map_err(anyhow::Error::msg)?;
    let probed = estimate::probe(config, &planned)?;
    let calibrate = !args.no_calibration;
    let logical = nbody_engine::run::logical_cpus();
    let est = estimate::estimate(config, &probed.cases, &done, calibrate, logical);
    let est = estimate::with_trials(est, config, &planned, trials, &done);
    if args.dry_run {
        print_plan(args, config, &est, &probed, trials, logical, path);
        return Ok(Some(0));
    }
    eprintln!(
        "estimated wall time: {} (probe took {:.2} s; `--dry-run` lists the cases)",
        WallTime(est.total_s),
        probed.seconds
    );
    if est.total_s <= LONG_SWEEP_S || config.measure.budget_s > 0.0 || args.yes {
        return Ok(None);
    }
    let mut longest: Vec<_> = est.cases.iter().collect();
    longest.sort_by(|a, b| b.wall_s.total_cmp(&a.wall_s));
    for c in longest.iter().take(3) {
        eprintln!("  {:<52} {}", c.case.key(), WallTime(c.wall_s));
    }
    if std::io::stdin().is_terminal() {
        eprint!(
            "sweep `{}` is estimated at {}, more than an hour; continue? [y/N] ",
            config.name,
            WallTime(est.total_s)
        );
        std::io::stderr().flush()?;
        let mut answer = String::new();
        std::io::stdin().lock().read_line(&mut answer)?;
        if matches!(answer.trim().to_ascii_lowercase().as_str(), "y" | "yes") {
            return Ok(None);
        }
        anyhow::bail!("sweep not started; pass --yes to start it without the question");
    }
    anyhow::bail!(
        "sweep `{}` is estimated at {} (estimate_s: {:.0}), more than an hour, and \
         measure.budget_s is 0; pass --yes to start it anyway, or set measure.budget_s in {} to \
         stop starting cases after that many seconds (`--resume` continues later)",
        config.name,
        WallTime(est.total_s),
        est.total_s,
        args.config.display()
    )
}

/// The rounds already measured in a results file.
fn done_in(results: ResultsFile) -> Done {
    Done {
        rounds: results
            .cases
            .iter()
            .map(|c| (c.key.clone(), c.rounds_done))
            .collect(),
        calibrated: results.calibration.start.is_some(),
    }
}

/// The dry run's output: the plan's heading and table, then what the estimate rests on and
/// what a real run would do.
fn print_plan(
    args: &SweepArgs,
    config: &SweepConfig,
    est: &Estimate,
    probed: &Probed,
    trials: &[Trial],
    logical: usize,
    path: Option<&Path>,
) {
    let m = &config.measure;
    let external = sweep_tables::external_cases(config).len();
    let all = est.cases.len() + external;
    outln!(
        "dry run of sweep `{}` ({}): {all} case{}{}, {} rounds of {} samples in all; nothing is \
         measured or kept",
        config.name,
        args.config.display(),
        if all == 1 { "" } else { "s" },
        if external == 0 {
            String::new()
        } else {
            format!(
                " ({} of the built-in kernels, {external} of external programs)",
                est.cases.len()
            )
        },
        m.rounds,
        m.samples
    );
    outln!("{}", sweep_tables::plan(config, est).text().trim_end());
    for t in trials {
        outln!(
            "\nexternal `{}` tried once at {} (in a temporary directory, removed): {} a run; \
             its cases are estimated from it, by their steps and a step's cost growing as its \
             `steps` rule says (else as n²), no faster on more workers",
            t.case.kernel.name(),
            t.case.key(),
            nbody_harness::units::Duration(t.run_s)
        );
    }
    print_estimate(est, probed, logical);
    print_consequences(args, config, est, path);
}

/// What the estimate rests on (the probe) and what it comes to.
fn print_estimate(est: &Estimate, probed: &Probed, logical: usize) {
    outln!(
        "\nprobe took {:.2} s ({} kernel set-up{} on one thread at n <= {PROBE_MAX_N}, scaled to \
         each case's n by the kernel's complexity class and to its threads by +{:.1} per extra \
         thread up to {logical} logical CPUs)",
        probed.seconds,
        probed.setups,
        if probed.setups == 1 { "" } else { "s" },
        estimate::EXTRA_THREAD_GAIN
    );
    outln!(
        "estimated wall time: {} (cases {}, calibration {})",
        WallTime(est.total_s),
        WallTime(est.total_s - est.calibration_s),
        WallTime(est.calibration_s)
    );
}

/// What a real run would do: resume, stop at the budget, ask, and where it would write.
fn print_consequences(args: &SweepArgs, config: &SweepConfig, est: &Estimate, path: Option<&Path>) {
    let m = &config.measure;
    if let (Some(_), Some(path)) = (&args.resume, path) {
        outln!(
            "(--resume: only the rounds {} does not hold yet)",
            path.display()
        );
    }
    if m.budget_s > 0.0 && est.total_s - est.calibration_s > m.budget_s {
        outln!(
            "measure.budget_s = {}: the sweep stops starting cases after that; --resume continues",
            m.budget_s
        );
    } else if m.budget_s == 0.0 && est.total_s > LONG_SWEEP_S {
        outln!("more than an hour: a real run asks to confirm, or needs --yes without a terminal");
    }
    match path {
        Some(path) if path.exists() && args.resume.is_none() && !args.fresh => outln!(
            "{} exists: a real run needs --resume or --fresh",
            path.display()
        ),
        Some(path) => outln!("results would go to {}", path.display()),
        None => outln!(
            "results would go to a new run directory {}/<UTC time>/",
            nbody_records::locate::runs_dir(&config.out, &config.name).display()
        ),
    }
    outln!("estimate_s: {:.3}", est.total_s);
}

/// Runs this small need no estimate: even the naive kernel in f64 finishes them in minutes.
const SMALL_RUN_N: usize = nbody_harness::experiment::estimate::PROBE_MAX_N;
const SMALL_RUN_STEPS: u64 = 100_000;

/// Refuses a run estimated at more than an hour (the sweep's limit) unless `--yes` is given.
pub fn refuse_long_run(
    setup: &nbody_engine::scenario::Setup,
    kernel: nbody_engine::kernels::KernelKind,
    kernel_args: &crate::cli::args::KernelArgs,
    steps: u64,
) -> anyhow::Result<()> {
    let n = setup.n();
    if n <= SMALL_RUN_N && steps <= SMALL_RUN_STEPS {
        return Ok(());
    }
    let case = nbody_records::plan::Case {
        scenario: setup.scenario,
        kernel: kernel.into(),
        n,
        threads: kernel_args.threads,
        ranks: 1,
        theta: kernel_args.theta,
        multipole: kernel_args
            .multipole
            .unwrap_or(nbody_engine::kernels::KernelParams::default().multipole),
        order: kernel.is_fmm().then(|| {
            kernel_args
                .order
                .unwrap_or(nbody_engine::kernels::KernelParams::default().order)
        }),
        skin: match kernel_args.skin {
            Some(crate::cli::args::SkinArg::Length(s)) => Some(s),
            _ => None,
        },
        seed: setup.seed,
        precision: setup.precision,
        time_factor: 1,
        decomp: None,
    };
    let wall_s = nbody_harness::experiment::estimate::run_seconds(
        &case,
        steps,
        nbody_engine::run::logical_cpus(),
    )?;
    let limit = LONG_SWEEP_S;
    if wall_s > limit {
        anyhow::bail!(
            "this run is estimated at {} ({steps} step{} of {n} particles, from a probe at small n); \
             it is refused above {}: lower --steps or -n, or pass --yes to run it anyway",
            WallTime(wall_s),
            if steps == 1 { "" } else { "s" },
            WallTime(limit),
        );
    }
    Ok(())
}
