//! `nbody-bench export`: a scenario's initial state for another code (see `nbody_engine::export`).

use crate::cli::args::ExportArgs;
use nbody_engine::export::export_setup;

pub fn export(args: ExportArgs) -> anyhow::Result<i32> {
    nbody_engine::output::check_outputs(
        &[("--out", args.out.as_path())],
        &super::initial_input(&args.start),
    )?;
    let setup = super::start_setup(args.scenario, &args.system, &args.start)?;
    let bytes = export_setup(&setup, args.format)??;
    nbody_engine::output::write_atomic(&args.out, &bytes)?;
    eprintln!(
        "wrote {} ({} particles of {})",
        args.out.display(),
        setup.n(),
        args.scenario.name()
    );
    Ok(0)
}
