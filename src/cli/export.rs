//! `nbody-bench export`: a scenario's initial state for another code (see `nbody_bench::export`).

use crate::cli::args::SystemArgs;
use clap::Args;
use nbody_bench::export::{ExportFormat, ExportJob};
use nbody_bench::scenario::ScenarioKind;
use std::path::PathBuf;

#[derive(Debug, Args)]
pub struct ExportArgs {
    /// Scenario whose initial state is written.
    #[arg(long, value_enum)]
    pub scenario: ScenarioKind,
    #[command(flatten)]
    pub system: SystemArgs,
    /// lammps-data: a LAMMPS data file in LJ reduced units (atom style atomic, the walls as the
    /// box; Lennard-Jones scenarios only); text: positions, velocities, mass and strength per
    /// particle with the law's parameters in the header; npy: the same columns as float64.
    #[arg(long, value_enum)]
    pub format: ExportFormat,
    /// The file to write (atomically).
    #[arg(long, value_name = "FILE")]
    pub out: PathBuf,
}

pub fn export(args: ExportArgs) -> anyhow::Result<i32> {
    nbody_bench::output::check_outputs(&[("--out", args.out.as_path())], &[])?;
    let setup = super::setup(args.scenario, &args.system);
    setup.validate()?;
    let bytes = setup.dispatch(ExportJob {
        format: args.format,
    })??;
    nbody_bench::output::write_atomic(&args.out, &bytes)?;
    eprintln!(
        "wrote {} ({} particles of {})",
        args.out.display(),
        setup.n(),
        args.scenario.name()
    );
    Ok(0)
}
