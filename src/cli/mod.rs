//! The command line: its arguments ([`args`]) and one module per subcommand. Each returns the
//! process exit code or an error (reported with exit code 2). It lives in the binary crate, so
//! the library never depends on it.

pub mod args;

mod analyze;
mod bisect;
mod dry_run;
mod export;
mod export_results;
mod fit;
mod gate;
mod gate_save;
mod gate_study;
mod hint;
mod history;
mod init;
mod list;
mod mpi;
mod publish;
mod reference;
mod report;
mod run;
mod summary;
mod sweep;
mod validate;
mod values;

use crate::cli::args::{Cli, Command, KernelArgs, SkinArg, StartArgs, SystemArgs};
use nbody_engine::kernels::{KernelKind, KernelParams};
use nbody_engine::scenario::{ScenarioKind, Setup};

/// Runs the parsed command line.
pub fn dispatch(cli: Cli) -> anyhow::Result<i32> {
    match cli.command {
        Command::List => list::list(),
        Command::Run(args) => run::run(args),
        Command::Validate(args) => validate::validate(args),
        Command::Sweep(args) => sweep::sweep(args),
        Command::Analyze(args) => analyze::analyze(args),
        Command::Report(args) => report::report(args),
        Command::Fit(args) => fit::fit(args),
        Command::Gate(args) => gate::gate(args),
        Command::GateStudy(args) => gate_study::gate_study(args),
        Command::MpiBench(args) => mpi::bench(args),
        Command::MpiCheck(args) => mpi::check(args),
        Command::Export(args) => export::export(args),
        Command::ExportResults(args) => export_results::export_results(args),
        Command::Init(args) => init::init(args),
        Command::History(args) => history::history(args),
        Command::Bisect(args) => bisect::bisect(args),
        Command::Publish(args) => publish::publish(args),
        Command::Reference(args) => reference::reference(args),
        Command::Job(args) => {
            nbody_harness::experiment::slurm::job_main(&args.dir)
                .map_err(|e| anyhow::anyhow!("job {}: {e}", args.dir.display()))?;
            Ok(0)
        }
    }
}

/// The file of bodies a command starts from (`--initial`), as an input no output may replace.
fn initial_input(start: &StartArgs) -> Vec<(&'static str, &std::path::Path)> {
    start
        .initial
        .as_deref()
        .map(|path| ("--initial", path))
        .into_iter()
        .collect()
}

/// An error and its causes on one line, `outer: cause: root cause`, leaving out a cause whose
/// text the message already carries (an error type that prints its source in its own
/// message, as most of ours do, would otherwise show it twice).
pub fn error_chain(err: &anyhow::Error) -> String {
    let mut line = String::new();
    for cause in err.chain() {
        let text = cause.to_string();
        if line.contains(&text) {
            continue;
        }
        if !line.is_empty() {
            line.push_str(": ");
        }
        line.push_str(&text);
    }
    line
}

fn setup(scenario: ScenarioKind, args: &SystemArgs) -> Setup {
    Setup {
        scenario,
        n: args.n,
        seed: args.seed,
        dt: args.dt,
        density: args.density,
        precision: args.precision,
        allow_fewer: args.allow_fewer,
        initial: None,
        lj: Default::default(),
    }
}

/// The set-up of `run` and `export`: the system options, the Lennard-Jones parameters and the
/// bodies of `--initial`, read and checked against the scenario here, before anything runs.
fn start_setup(
    scenario: ScenarioKind,
    system: &SystemArgs,
    start: &StartArgs,
) -> anyhow::Result<Setup> {
    let mut setup = setup(scenario, system);
    setup.lj = start.lj.overrides();
    if let Some(path) = &start.initial {
        let bodies = nbody_engine::scenario::initial::read(path)?;
        if let Some(from) = bodies
            .exported_from
            .as_deref()
            .filter(|&f| f != scenario.name())
        {
            eprintln!(
                "note: {} was exported from scenario {from}; it starts {} here, with that \
                 scenario's law, box and field",
                path.display(),
                scenario.name()
            );
        }
        setup.initial = Some(std::sync::Arc::new(bodies));
    }
    setup.validate()?;
    Ok(setup)
}

/// The kernel parameters given, over the defaults; `--theta`, `--multipole`, `--order`,
/// `--leaf-size` and `--skin` are refused for a kernel that ignores them (as `--density` is
/// for a scenario without a box), so that nobody believes a setting that changed nothing.
/// `--leaf-size` sets the leaf size of the kernel run (the octree's or the fmm's, which
/// default differently), and of both trees when no kernel is named (`validate`).
/// Refuses `--skin auto` outside `run`, which alone times the candidates.
fn no_auto_skin(args: &KernelArgs, command: &str) -> anyhow::Result<()> {
    if args.skin == Some(SkinArg::Auto) {
        anyhow::bail!("--skin auto is for `run` only; {command} needs a skin length (or none)");
    }
    Ok(())
}

fn kernel_params(args: &KernelArgs, kernel: Option<KernelKind>) -> anyhow::Result<KernelParams> {
    if let Some(kernel) =
        kernel.filter(|&k| !matches!(k, KernelKind::Verlet | KernelKind::ClusterPair))
        && args.skin.is_some()
    {
        anyhow::bail!(
            "--skin applies to the verlet and cluster-pair kernels only; `{}` does not use it: \
             drop it, or pass --kernel verlet",
            kernel.name()
        );
    }
    let trees = [KernelKind::Octree, KernelKind::Fmm, KernelKind::FmmHarmonic];
    if let Some(kernel) = kernel {
        for (flag, given, users) in [
            ("--theta", args.theta.is_some(), &trees[..]),
            ("--leaf-size", args.leaf_size.is_some(), &trees[..]),
            ("--multipole", args.multipole.is_some(), &trees[..1]),
            ("--order", args.order.is_some(), &trees[1..]),
        ] {
            if given && !users.contains(&kernel) {
                let names: Vec<&str> = users.iter().map(|k| k.name()).collect();
                let listed = match names.split_last() {
                    Some((last, rest)) if !rest.is_empty() => {
                        format!("{} and {last}", rest.join(", "))
                    }
                    _ => names.join(""),
                };
                anyhow::bail!(
                    "{flag} applies to the {listed} kernel{} only; `{}` does not use it: drop it, \
                     or pass --kernel {}",
                    if names.len() > 1 { "s" } else { "" },
                    kernel.name(),
                    names[0]
                );
            }
        }
    }
    let defaults = KernelParams::default();
    let fmm_only = kernel.is_some_and(KernelKind::is_fmm);
    let octree_only = kernel.is_some() && !fmm_only;
    Ok(KernelParams {
        theta: args.theta.unwrap_or(defaults.theta),
        leaf_size: args
            .leaf_size
            .filter(|_| !fmm_only)
            .unwrap_or(defaults.leaf_size),
        skin: match args.skin {
            Some(SkinArg::Length(skin)) => skin,
            // `run` times the candidates around the default before it starts.
            Some(SkinArg::Auto) | None => defaults.skin,
        },
        multipole: args.multipole.unwrap_or(defaults.multipole),
        order: args.order.unwrap_or(defaults.order),
        fmm_leaf_size: args
            .leaf_size
            .filter(|_| !octree_only)
            .unwrap_or(defaults.fmm_leaf_size),
    })
}

#[cfg(test)]
mod tests {
    use super::error_chain;

    #[derive(Debug, thiserror::Error)]
    #[error("cannot read config {path}: {source}")]
    struct ReadError {
        path: String,
        source: std::io::Error,
    }

    #[test]
    fn a_cause_is_printed_once() {
        let io = std::io::Error::new(std::io::ErrorKind::NotFound, "No such file or directory");
        let err = anyhow::Error::from(ReadError {
            path: "strong.toml".into(),
            source: io,
        });
        assert_eq!(
            error_chain(&err),
            "cannot read config strong.toml: No such file or directory"
        );
        let wrapped = err.context("sweep");
        assert_eq!(
            error_chain(&wrapped),
            "sweep: cannot read config strong.toml: No such file or directory"
        );
    }

    #[test]
    fn distinct_causes_are_all_kept() {
        let err = anyhow::anyhow!("root").context("middle").context("top");
        assert_eq!(error_chain(&err), "top: middle: root");
    }
}
