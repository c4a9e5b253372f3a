//! `report`: regenerate REPORT.md from the results directory.

use crate::cli::args::ReportArgs;

pub fn report(args: ReportArgs) -> anyhow::Result<i32> {
    // The report is read (its kept regions) and then replaced: it must be a regular file and
    // none of the results it is made from (`--out /dev/full` would be read without end).
    let inputs = nbody_harness::report::find_results(&args.results)?;
    let inputs: Vec<(&str, &std::path::Path)> =
        inputs.iter().map(|p| ("--results", p.as_path())).collect();
    nbody_engine::output::check_outputs(&[("--out", &args.out)], &inputs)?;
    let generated = nbody_harness::report::generate(&args.results, &args.out)?;
    outln!(
        "{}: {} sweeps, {} figures",
        generated.path.display(),
        generated.sweeps,
        generated.figures
    );
    for line in &generated.taken_out {
        eprintln!("warning: {line}");
    }
    for e in &generated.figure_errors {
        eprintln!("warning: figure not drawn: {e}");
    }
    for (region, figures) in &generated.kept_figures {
        eprintln!(
            "warning: the kept region `{region}` holds figures written by hand ({}); a number \
             belongs in a generated section, where it follows the results",
            figures.join(" ")
        );
    }
    Ok(0)
}
