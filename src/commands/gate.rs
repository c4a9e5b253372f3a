use crate::cli::GateArgs;
use crate::experiment::results::ResultsFile;
use crate::gate::{GateOptions, compare, render};

/// Compares a current sweep with a baseline: exit 0 when nothing regressed, 1 when something
/// did, 2 for bad input (including baseline cases the current run did not measure).
pub fn gate(args: GateArgs) -> anyhow::Result<i32> {
    let baseline = ResultsFile::load(&args.baseline)?;
    let current = ResultsFile::load(&args.current)?;
    let options = GateOptions {
        threshold: args.threshold,
        force: args.force,
        normalization: args.normalize,
        fail_on_work_change: args.fail_on_work_change,
        ..GateOptions::default()
    };
    let report = compare(&baseline, &current, &options)?;
    print!("{}", render(&report, args.format));
    if !report.missing.is_empty() {
        let keys: Vec<&str> = report.missing.iter().map(|m| m.key.as_str()).collect();
        eprintln!(
            "error: {} baseline case(s) could not be compared: {}; run the baseline's config to \
             completion (sweep --resume), or refresh the baseline if the cases were removed on \
             purpose",
            keys.len(),
            keys.join(", ")
        );
    }
    Ok(report.exit_code())
}
