//! The subcommands. Each returns the process exit code or an error (reported with exit code 2).

mod analyze;
mod dry_run;
mod fit;
mod fit_tables;
mod gate;
mod list;
mod mpi;
mod report;
mod run;
mod sweep;
mod validate;

pub use run::fmt_ns;

use crate::cli::{Cli, Command, KernelArgs, SystemArgs};
use crate::kernels::KernelParams;
use crate::scenario::{ScenarioKind, Setup};

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
        Command::MpiBench(args) => mpi::bench(args),
        Command::MpiCheck(args) => mpi::check(args),
    }
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
    }
}

fn kernel_params(args: &KernelArgs) -> KernelParams {
    KernelParams {
        theta: args.theta,
        leaf_size: args.leaf_size,
    }
}
