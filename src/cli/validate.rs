use super::{kernel_params, setup};
use crate::cli::args::ValidateArgs;
use nbody_engine::kernels::{KernelKind, KernelParams};
use nbody_engine::scenario::ScenarioKind;
use nbody_engine::validate::{ScenarioCheck, ValidateJob, validate_setup};
use nbody_harness::units::WallTime;
use std::path::PathBuf;

pub fn validate(args: ValidateArgs) -> anyhow::Result<i32> {
    let scenarios: Vec<ScenarioKind> = match args.scenario {
        Some(s) => vec![s],
        None => ScenarioKind::ALL.to_vec(),
    };
    if let Some(dump) = &args.dump {
        let paths: Vec<PathBuf> = scenarios
            .iter()
            .map(|&s| dump_file(dump, scenarios.len(), s))
            .collect();
        nbody_engine::output::check_derived("--dump", dump, &paths)?;
    }
    super::no_auto_skin(&args.kernel_args, "validate")?;
    let params = kernel_params(&args.kernel_args, None)?;
    let mut results: Vec<ScenarioCheck> = Vec::new();
    for &scenario in &scenarios {
        results.push(check_scenario(&args, scenario, scenarios.len(), params)?);
    }
    print_verdict(&args, &results)
}

/// One scenario's check of every kernel against the reference, with its memory and time
/// guards, its forces dumped with `--dump`; `count` is the number of scenarios checked.
fn check_scenario(
    args: &ValidateArgs,
    scenario: ScenarioKind,
    count: usize,
    params: KernelParams,
) -> anyhow::Result<ScenarioCheck> {
    let mut s = setup(scenario, &args.system);
    if args.scenario.is_none()
        && args.system.density.is_some()
        && scenario.defaults().density.is_none()
    {
        // --density applies to the scenarios that have one.
        s.density = None;
    }
    if let Some(n) = args.system.n.filter(|_| args.scenario.is_none()) {
        // -n for every scenario: the melt is checked at the largest lattice of at most n.
        let lattice = scenario.count_at_most(n);
        if lattice != n {
            eprintln!(
                "{}: n = {n} is not a lattice of this scenario; checked at n = {lattice}",
                scenario.name()
            );
            s.n = Some(lattice);
        }
    }
    s.validate()?;
    // The trees and the Verlet list hold the most memory of the kernels checked, the O(n²)
    // direct sums take the time: the f64 reference and the three quadratic kernels, one
    // force computation each.
    for kernel in [
        KernelKind::Octree,
        KernelKind::Fmm,
        KernelKind::Verlet,
        KernelKind::PerThread,
    ] {
        nbody_engine::run::check_memory(&s, kernel, &params, args.kernel_args.threads, 1)?;
    }
    if !args.yes {
        refuse_long_check(&s, params, args.kernel_args.threads)?;
    }
    let job = ValidateJob {
        params,
        threads: args.kernel_args.threads,
        want_dump: args.dump.is_some(),
    };
    let check = validate_setup(&s, job)??;
    if let (Some(path), Some(text)) = (&args.dump, &check.dump) {
        let path = dump_file(path, count, scenario);
        nbody_engine::output::write_atomic(&path, text.as_bytes())?;
        if !args.json {
            outln!("forces written to {}", path.display());
        }
    }
    if !args.json {
        print_check(&check);
    }
    Ok(check)
}

/// The kernels that failed or were skipped, as JSON or a line; the exit status.
fn print_verdict(args: &ValidateArgs, results: &[ScenarioCheck]) -> anyhow::Result<i32> {
    let failed: Vec<String> = results
        .iter()
        .flat_map(|c| {
            c.kernels
                .iter()
                .filter(|k| !k.passed && !k.skipped)
                .map(move |k| format!("{}/{}", c.scenario, k.kernel))
        })
        .collect();
    let skipped: Vec<String> = results
        .iter()
        .flat_map(|c| {
            c.kernels
                .iter()
                .filter(|k| k.skipped)
                .map(move |k| format!("{}/{}", c.scenario, k.kernel))
        })
        .collect();
    if args.json {
        outln!("{}", serde_json::to_string_pretty(&results)?);
    } else if failed.is_empty() && skipped.is_empty() {
        outln!("all kernels agree with the reference");
    } else if failed.is_empty() {
        outln!(
            "all kernels checked agree with the reference; skipped: {}",
            skipped.join(", ")
        );
    } else {
        outln!("FAILED: {}", failed.join(", "));
    }
    Ok(if failed.is_empty() { 0 } else { 1 })
}

/// Checks up to this many particles need no estimate (well under a second).
const PROBE_N: usize = 1000;

/// Refuses a check estimated at more than an hour unless `--yes` is given: the same check at
/// [`PROBE_N`] particles, timed, carried to n as n² (its direct sums dominate).
fn refuse_long_check(
    setup: &nbody_engine::scenario::Setup,
    params: nbody_engine::kernels::KernelParams,
    threads: usize,
) -> anyhow::Result<()> {
    let n = setup.n();
    if n <= PROBE_N {
        return Ok(());
    }
    let mut probe = setup.clone();
    // The largest count the scenario builds at the probe's size (the melt's lattices).
    let probe_n = setup.scenario.count_at_most(PROBE_N);
    probe.n = Some(probe_n);
    let job = ValidateJob {
        params,
        threads,
        want_dump: false,
    };
    let started = std::time::Instant::now();
    validate_setup(&probe, job)??;
    let ratio = n as f64 / probe_n as f64;
    let wall_s = started.elapsed().as_secs_f64() * ratio * ratio;
    let limit = super::dry_run::LONG_SWEEP_S;
    if wall_s > limit {
        anyhow::bail!(
            "checking {} at n = {n} is estimated at {} (the check at n = {probe_n}, carried as n²); \
             it is refused above {}: lower -n, or pass --yes to run it anyway",
            setup.scenario.name(),
            WallTime(wall_s),
            WallTime(limit),
        );
    }
    Ok(())
}

/// The dump of one scenario: `path` itself, or `path.<scenario>` when several are checked.
fn dump_file(path: &std::path::Path, scenarios: usize, scenario: ScenarioKind) -> PathBuf {
    if scenarios == 1 {
        return path.to_path_buf();
    }
    dump_path(path, scenario)
}

fn dump_path(path: &std::path::Path, scenario: ScenarioKind) -> PathBuf {
    let mut p = path.as_os_str().to_owned();
    p.push(format!(".{}", scenario.name()));
    PathBuf::from(p)
}

fn print_check(c: &ScenarioCheck) {
    outln!(
        "{}: n = {}, {}, reference = naive in f64, theta = {}",
        c.scenario,
        c.n,
        c.precision,
        c.theta
    );
    outln!(
        "  {:<12} {:>12} {:>12}  {:<6} criterion",
        "kernel",
        "max rel err",
        "median",
        "result"
    );
    for k in &c.kernels {
        if k.skipped {
            outln!(
                "  {:<12} {:>12} {:>12}  {:<6} {}",
                k.kernel,
                "-",
                "-",
                "skip",
                k.criterion
            );
            continue;
        }
        outln!(
            "  {:<12} {:>12.3e} {:>12.3e}  {:<6} {}",
            k.kernel,
            k.max_rel_error,
            k.median_rel_error,
            if k.passed { "ok" } else { "FAIL" },
            k.criterion
        );
    }
}
