use super::dry_run::refuse_long_run;
use super::summary::print_summary;
use super::{kernel_params, start_setup};
use crate::cli::args::RunArgs;
use anyhow::Context;
use nbody_bench::run::{RunSpec, TrajectorySpec, logical_cpus, run_setup};

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
    nbody_bench::output::check_outputs(&outputs, &super::initial_input(&args.start))?;
    if let Some(decomp) = args.decomp {
        return super::mpi::run(args, decomp);
    }
    let setup = start_setup(args.scenario, &args.system, &args.start)?;
    let params = kernel_params(&args.kernel_args, Some(args.kernel))?;
    nbody_bench::run::check_memory(&setup, args.kernel, &params, args.kernel_args.threads, 1)?;
    if !args.yes {
        refuse_long_run(&setup, args.kernel, &args.kernel_args, args.steps as u64)?;
    }
    let spec = RunSpec {
        kernel: args.kernel,
        params,
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
    let outcome = run_setup(&setup, &spec)??;
    print_summary(&outcome);
    if let Some(path) = &args.json {
        let text = serde_json::to_string_pretty(&outcome).context("serializing the result")?;
        nbody_bench::output::write_atomic(path, text.as_bytes())?;
        outln!("result written to {}", path.display());
    }
    Ok(0)
}
