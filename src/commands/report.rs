//! `report`: regenerate REPORT.md from the results directory.

use crate::cli::ReportArgs;

pub fn report(args: ReportArgs) -> anyhow::Result<i32> {
    let generated = crate::report::generate(&args.results, &args.out)?;
    outln!(
        "{}: {} sweeps, {} figures",
        generated.path.display(),
        generated.sweeps,
        generated.figures
    );
    for e in &generated.figure_errors {
        eprintln!("warning: figure not drawn: {e}");
    }
    Ok(0)
}
