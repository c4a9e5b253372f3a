use super::dry_run::refuse_long_run;
use super::summary::print_summary;
use super::{kernel_params, start_setup};
use crate::cli::args::{RunArgs, SkinArg};
use anyhow::Context;
use nbody_engine::run::{RunSpec, TrajectorySpec, logical_cpus, run_setup};

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
    nbody_engine::output::check_outputs(&outputs, &super::initial_input(&args.start))?;
    let auto_skin = args.kernel_args.skin == Some(SkinArg::Auto);
    if let Some(decomp) = args.decomp {
        if auto_skin {
            anyhow::bail!(
                "--skin auto times candidate skins on one process; with --decomp give the skin \
                 (find it with `run --skin auto` on the same system first)"
            );
        }
        return super::mpi::run(args, decomp);
    }
    let setup = start_setup(args.scenario, &args.system, &args.start)?;
    let params = kernel_params(&args.kernel_args, Some(args.kernel))?;
    nbody_engine::run::check_memory(&setup, args.kernel, &params, args.kernel_args.threads, 1)?;
    if !args.yes {
        refuse_long_run(&setup, args.kernel, &args.kernel_args, args.steps as u64)?;
    }
    let mut spec = RunSpec {
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
    if auto_skin {
        spec.params.skin = choose_skin(&setup, &spec)?;
    }
    let outcome = run_setup(&setup, &spec)??;
    print_summary(&outcome);
    if let Some(path) = &args.json {
        let text = serde_json::to_string_pretty(&outcome).context("serializing the result")?;
        nbody_engine::output::write_atomic(path, text.as_bytes())?;
        outln!("result written to {}", path.display());
    }
    Ok(0)
}

/// `--skin auto`: every candidate skin timed on the run's system and threads, the table on the
/// error stream, the fastest returned.
fn choose_skin(setup: &nbody_engine::scenario::Setup, spec: &RunSpec) -> anyhow::Result<f64> {
    use nbody_harness::experiment::skin::{TRIAL_STEPS, fastest, tune};
    eprintln!(
        "--skin auto: timing {} skins, {TRIAL_STEPS} steps each on {} thread(s)",
        nbody_harness::experiment::skin::SKIN_FACTORS.len(),
        spec.threads
    );
    let trials = tune(setup, spec.kernel, &spec.params, spec.threads, TRIAL_STEPS)?;
    for t in &trials {
        eprintln!(
            "  skin {:<8} {:>8.2} ns per particle-step, {}",
            t.skin,
            t.ns_per_particle_step,
            t.steps_per_rebuild
                .map_or("no rebuild".to_string(), |s| format!(
                    "a rebuild every {s:.1} steps"
                ))
        );
    }
    let best = fastest(&trials).context("no skin could be timed")?;
    eprintln!(
        "  chosen: skin {} (recorded in the run's kernel parameters)",
        best.skin
    );
    Ok(best.skin)
}
