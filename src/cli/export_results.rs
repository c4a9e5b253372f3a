//! `nbody-bench export-results`: a results file as a tidy table, one row per sample, for
//! notebooks (the rows: `nbody_bench::records::tidy::samples`).

use crate::cli::args::ExportResultsArgs;
use nbody_bench::records::locate;
use nbody_bench::records::results::ResultsFile;
use nbody_bench::records::tidy;
use std::path::Path;

pub fn export_results(args: ExportResultsArgs) -> anyhow::Result<i32> {
    let path = locate::find_results(&args.results, Path::new("results"))?;
    if path != args.results {
        eprintln!("exporting {}", path.display());
    }
    // The output is checked before anything is read: never the results file (through a
    // link either), never a directory or a device.
    if let Some(out) = &args.out {
        nbody_bench::output::check_outputs(&[("--out", out)], &[("RESULTS", &path)])?;
    }
    let results = ResultsFile::load(&path)?;
    let table = tidy::samples(&results);
    if table.rows.is_empty() {
        eprintln!(
            "warning: {} has no successful sample: the table has no rows",
            path.display()
        );
    }
    let text = args.format.write(&table);
    match &args.out {
        Some(out) => {
            nbody_bench::output::write_atomic(out, text.as_bytes())?;
            eprintln!(
                "wrote {} ({} samples of {} cases)",
                out.display(),
                table.rows.len(),
                results.cases.len()
            );
        }
        None => out!("{text}"),
    }
    Ok(0)
}
