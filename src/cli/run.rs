use super::{kernel_params, setup};
use crate::cli::args::RunArgs;
use nbody_bench::run::{RunJob, RunOutcome, RunSpec, TrajectorySpec, logical_cpus};
use nbody_bench::units::{Duration, WallTime};
use anyhow::Context;

pub fn run(args: RunArgs) -> anyhow::Result<i32> {
    // Every output is checked before the run starts: a result is never lost at the end.
    let outputs: Vec<(&str, &std::path::Path)> = [
        ("--json", args.json.as_deref()),
        ("--trajectory", args.trajectory.as_deref()),
        ("--dump-state", args.dump_state.as_deref()),
    ]
    .into_iter()
    .filter_map(|(flag, path)| Some((flag, path?)))
    .collect();
    nbody_bench::output::check_outputs(&outputs, &[])?;
    if let Some(decomp) = args.decomp {
        return super::mpi::run(args, decomp);
    }
    let setup = setup(args.scenario, &args.system);
    setup.validate()?;
    nbody_bench::run::check_memory(&setup, args.kernel, args.kernel_args.threads, 1)?;
    if !args.yes {
        refuse_long_run(&setup, args.kernel, &args.kernel_args, args.steps as u64)?;
    }
    let spec = RunSpec {
        kernel: args.kernel,
        params: kernel_params(&args.kernel_args, Some(args.kernel))?,
        steps: args.steps as u64,
        threads: args.kernel_args.threads,
        trajectory: args.trajectory.map(|path| TrajectorySpec {
            path,
            format: args.format,
            every: args.every as u64,
        }),
        dump_state: args.dump_state,
    };
    if spec.threads > logical_cpus() {
        eprintln!(
            "warning: {} threads on {} logical CPUs: oversubscribed; timings do not show real parallel speedup",
            spec.threads,
            logical_cpus()
        );
    }
    let outcome = setup.dispatch(RunJob(&spec))??;
    print_summary(&outcome);
    if let Some(path) = &args.json {
        let text = serde_json::to_string_pretty(&outcome).context("serializing the result")?;
        nbody_bench::output::write_atomic(path, text.as_bytes())?;
        outln!("result written to {}", path.display());
    }
    Ok(0)
}

/// Runs this small need no estimate: even the naive kernel in f64 finishes them in minutes.
const SMALL_RUN_N: usize = nbody_bench::experiment::estimate::PROBE_MAX_N;
const SMALL_RUN_STEPS: u64 = 100_000;

/// Refuses a run estimated at more than an hour (the sweep's limit) unless `--yes` is given.
pub(crate) fn refuse_long_run(
    setup: &nbody_bench::scenario::Setup,
    kernel: nbody_bench::kernels::KernelKind,
    kernel_args: &crate::cli::args::KernelArgs,
    steps: u64,
) -> anyhow::Result<()> {
    let n = setup.n();
    if n <= SMALL_RUN_N && steps <= SMALL_RUN_STEPS {
        return Ok(());
    }
    let case = nbody_bench::experiment::plan::Case {
        scenario: setup.scenario,
        kernel,
        n,
        threads: kernel_args.threads,
        ranks: 1,
        theta: kernel_args.theta,
        seed: setup.seed,
        precision: setup.precision,
        time_factor: 1,
        decomp: None,
    };
    let wall_s = nbody_bench::experiment::estimate::run_seconds(&case, steps, logical_cpus())?;
    let limit = super::dry_run::LONG_SWEEP_S;
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

pub(super) fn print_summary(r: &RunOutcome) {
    let t = &r.timing;
    outln!(
        "{} / {}: n = {}, {} steps, {} thread{}{}, {}-D {}, seed {}, simd {}",
        r.scenario,
        r.kernel,
        r.n,
        r.steps,
        r.threads,
        if r.threads == 1 { "" } else { "s" },
        if r.oversubscribed {
            " (oversubscribed)"
        } else {
            ""
        },
        r.dim,
        r.precision,
        r.seed,
        r.simd
    );
    if r.n < r.n_requested {
        outln!(
            "note: placed {} of the {} particles requested (--allow-fewer)",
            r.n,
            r.n_requested
        );
    }
    let p = &t.per_step_ns;
    outln!(
        "time per step     p50 {}  p90 {}  p99 {}  max {}",
        Duration::from_ns(p.p50 as f64),
        Duration::from_ns(p.p90 as f64),
        Duration::from_ns(p.p99 as f64),
        Duration::from_ns(p.max as f64)
    );
    outln!(
        "per particle-step {}",
        Duration::from_ns(t.ns_per_particle_step)
    );
    outln!(
        "throughput        {:.3e} particle-steps/s, {:.3e} pair-evaluations/s",
        r.throughput.particle_steps_per_s,
        r.throughput.pair_evals_per_s
    );
    let ph = &t.phases;
    let total = ph.total().max(f64::MIN_POSITIVE);
    let pct = |x: f64| 100.0 * x / total;
    outln!(
        "phases            force build {:.1}%  interact {:.1}%  integrate {:.1}%  boundary {:.1}%  output {:.1}%",
        pct(ph.force_build),
        pct(ph.force_interact),
        pct(ph.integrate),
        pct(ph.boundary),
        pct(ph.output)
    );
    let c = &r.counters;
    out!(
        "work per step     {:.4e} pair checks",
        c.pair_checks_per_step
    );
    let steps = r.steps.max(1) as f64;
    if c.total.nodes_opened > 0 {
        out!(
            ", {:.4e} nodes opened, {:.4e} accepted",
            c.total.nodes_opened as f64 / steps,
            c.total.nodes_accepted as f64 / steps
        );
    }
    if c.total.cells_visited > 0 {
        out!(
            ", {:.4e} cells visited",
            c.total.cells_visited as f64 / steps
        );
    }
    outln!(
        "; {} interacting pairs at the end",
        c.pairs_interacting_final
    );
    outln!(
        "energy            {:.6e} -> {:.6e}, relative drift {:+.3e}",
        r.energy.initial.total(),
        r.energy.last.total(),
        r.energy.rel_drift
    );
}
